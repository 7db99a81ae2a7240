// The volume a command-line edit works on, in the Document the editor and sessions edit through
// (scene/document.h), so the three cannot apply an operation differently. Nothing is undone on the
// command line: with no undo budget the document keeps no snapshot of the volume before an edit.
#pragma once

#include "io/volume_file.h"
#include "scene/document.h"
#include "scene/edit_operation.h"

#include <string>

namespace waxwork {

class EditedVolume {
public:
    // Reads `input`. The document gives every tet `base` when the file stores no materials; they are
    // written out only with `write_base`: a painted volume needs them, a cut or a fracture adds no
    // materials the input did not have.
    EditedVolume(const std::string& input, const TetMaterial& base, bool write_base);
    // The same for a volume already read from `input` (a command that needs its scale first).
    EditedVolume(const std::string& input, VolumeFile file, const TetMaterial& base, bool write_base);

    const TetMesh& mesh() const { return document_.mesh(); }

    // Errors name the volume (what it does not allow: a cut that leaves nothing, more pieces than tets).
    // `progress` as for Document::apply.
    ChangeReport apply(const EditOperation& op, Progress* progress = nullptr);

    // Atomically; keeps what the input stored beside the mesh (its scale).
    void write(const std::string& output) const;

private:
    std::string input_;
    bool keep_materials_;
    VolumeMetadata metadata_;
    Document document_;
};

}  // namespace waxwork
