// The example models the start screen offers: the surfaces bundled in assets/meshes, each with the
// direction its front faces.
//
// Which side is the front: models follow the glTF 2.0 convention (+y up, the front faces +z), which
// most OBJ exporters also write, and the default camera (render/camera.h: eye direction 0.7, 0.5, 1)
// looks at that front from the right and above, as `waxwork render` does. A model authored otherwise
// (spot.obj faces -z) gets the same view of its own front: the default eye direction turned by the
// rotation about +y that takes +z to its front.
#pragma once

#include <Eigen/Core>

#include <filesystem>
#include <string>
#include <vector>

namespace waxwork {

struct ExampleModel {
    std::string name;             // "spot": the file's stem
    std::string description;      // a few words for the start screen
    std::filesystem::path file;
    Eigen::Vector3d eye_direction;  // the first view: its front from the right and above
};

// The examples present in `directory` (assets/meshes), in a fixed order; none when it is missing.
std::vector<ExampleModel> example_models(const std::filesystem::path& directory);

// Where the bundled examples are: $WAXWORK_ASSET_DIR/meshes when set, else the source tree's assets
// the build was configured from.
std::filesystem::path example_directory();

}  // namespace waxwork
