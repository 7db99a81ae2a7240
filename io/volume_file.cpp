#include "io/volume_file.h"

#include "base/error.h"
#include "io/file_extension.h"
#include "io/gmsh_format.h"
#include "io/medit_format.h"
#include "io/tetgen_format.h"
#include "io/vtu_format.h"

#include <optional>
#include <string>

namespace waxwork {
namespace {

enum class VolumeFormat { Vtu, Gmsh, Medit, TetGen };

std::optional<VolumeFormat> format_named_by(const std::filesystem::path& path) {
    const std::string extension = lower_extension(path);
    if (extension == ".vtu") return VolumeFormat::Vtu;
    if (extension == ".msh") return VolumeFormat::Gmsh;
    if (extension == ".mesh") return VolumeFormat::Medit;
    if (extension == ".node" || extension == ".ele") return VolumeFormat::TetGen;
    return std::nullopt;
}

VolumeFormat format_of(const std::filesystem::path& path) {
    if (const std::optional<VolumeFormat> format = format_named_by(path)) return *format;
    throw FileError(path.string(), "unknown volume file extension '" + path.extension().string() +
                                       "' (expected .vtu, .msh, .mesh, .node or .ele)");
}

}  // namespace

bool is_volume_path(const std::filesystem::path& path) { return format_named_by(path).has_value(); }

TetMesh read_volume(const std::filesystem::path& path) { return read_volume_file(path).mesh; }

VolumeFile read_volume_file(const std::filesystem::path& path) {
    VolumeFile file;
    switch (format_of(path)) {
        case VolumeFormat::Vtu: file.mesh = read_vtu(path, &file.metadata); return file;
        case VolumeFormat::Gmsh: file.mesh = read_gmsh(path, &file.metadata); return file;
        case VolumeFormat::Medit: file.mesh = read_medit(path, &file.metadata); return file;
        case VolumeFormat::TetGen: file.mesh = read_tetgen(path, &file.metadata); return file;
    }
    throw FileError(path.string(), "unknown volume format");
}

void write_volume(const TetMesh& mesh, const std::filesystem::path& path, const VolumeMetadata& metadata) {
    const VolumeFormat format = format_of(path);
    try {
        validate(mesh);
    } catch (const InvalidMeshError& error) {
        throw InvalidMeshError(path.string() + ": not saved: " + error.what());
    }
    check_metadata(metadata, path.string());
    switch (format) {
        case VolumeFormat::Vtu: write_vtu(mesh, path, metadata); return;
        case VolumeFormat::Gmsh: write_gmsh(mesh, path, metadata); return;
        case VolumeFormat::Medit: write_medit(mesh, path, metadata); return;
        case VolumeFormat::TetGen: write_tetgen(mesh, path, metadata); return;
    }
}

}  // namespace waxwork
