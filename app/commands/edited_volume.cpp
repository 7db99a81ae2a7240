#include "app/commands/edited_volume.h"

#include "base/error.h"

#include <utility>

namespace waxwork {

EditedVolume::EditedVolume(const std::string& input, const TetMaterial& base, bool write_base)
    : EditedVolume(input, read_volume_file(input), base, write_base) {}

EditedVolume::EditedVolume(const std::string& input, VolumeFile file, const TetMaterial& base, bool write_base)
    : input_(input), keep_materials_(write_base || file.mesh.has_materials()), metadata_(file.metadata),
      document_(std::move(file.mesh), base, /*undo_budget_bytes=*/0) {}

ChangeReport EditedVolume::apply(const EditOperation& op, Progress* progress) {
    return naming_context(input_, [&] { return document_.apply(op, progress); });
}

void EditedVolume::write(const std::string& output) const {
    if (keep_materials_) return write_volume(document_.mesh(), output, metadata_);
    TetMesh mesh = document_.mesh();
    mesh.materials.clear();
    write_volume(mesh, output, metadata_);
}

}  // namespace waxwork
