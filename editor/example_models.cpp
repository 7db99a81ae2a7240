#include "editor/example_models.h"

#include "render/camera.h"

#include <cmath>
#include <cstdlib>
#include <system_error>

#ifndef WAXWORK_ASSET_DIR
#define WAXWORK_ASSET_DIR ""
#endif

namespace waxwork {

namespace fs = std::filesystem;

namespace {

struct Known {
    const char* name;
    const char* description;
    double front_yaw_degrees;  // the front's direction: +z turned by this about +y
};

// Each meshes in under 3 s at the default resolution (TetGen; the skull is remeshed first).
constexpr Known kKnown[] = {
    {"spot", "Keenan Crane's cow", 180},
    {"torus", "a ring to slice", 0},
    {"skull", "a human skull", 0},
    {"cube", "a cube to carve", 0},
};

}  // namespace

std::vector<ExampleModel> example_models(const fs::path& directory) {
    std::vector<ExampleModel> examples;
    const Eigen::Vector3d eye = CameraSettings{}.eye_direction;
    for (const Known& known : kKnown) {
        const fs::path file = directory / (std::string(known.name) + ".obj");
        std::error_code error;
        if (!fs::is_regular_file(file, error)) continue;
        const double a = known.front_yaw_degrees * 3.14159265358979323846 / 180;
        // Rotation about +y by a: (x, z) -> (x cos a + z sin a, -x sin a + z cos a).
        const Eigen::Vector3d turned(eye.x() * std::cos(a) + eye.z() * std::sin(a), eye.y(),
                                     -eye.x() * std::sin(a) + eye.z() * std::cos(a));
        examples.push_back({known.name, known.description, file, turned});
    }
    return examples;
}

fs::path example_directory() {
    const char* own = std::getenv("WAXWORK_ASSET_DIR");
    return fs::path(own && *own ? own : WAXWORK_ASSET_DIR) / "meshes";
}

}  // namespace waxwork
