// An optional ground under the model: a large horizontal plane at the model's lowest point (world +y
// is up), shaded as a grey diffuse surface by the scene's lights with the model's shadows, plus a fill
// light (the ambient term and the environment's mean radiance) darkened by ambient occlusion, which
// gives the soft contact shadow where the model meets the ground. The irradiance is computed on the
// CPU with shadow rays against the model's triangles (solver/ray_caster.h) into a texture around the
// model; the renderer draws the plane with it, exposed and tone-mapped like the surface, fading out
// towards its edge.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace waxwork {

struct SurfaceRenderInput;

// Diffuse reflectance of the ground: a mid grey, lighter than most models' shadowed sides.
inline constexpr float kGroundPlaneAlbedo = 0.5f;

struct GroundPlane {
    float height = 0;                          // y of the plane: the model's lowest point
    Eigen::Vector2f centre = Eigen::Vector2f::Zero();  // x, z of the model's bounding-box centre
    float extent = 0;                          // half the side of the square drawn
    float texture_extent = 0;                  // half the side of the square `irradiance` covers
    int resolution = 0;                        // texels per side
    // Irradiance (rgb, the unit of the lights' intensities) per texel, rows along +z, x fastest. Beyond
    // the texture the ground is as at its edge (clamped), far enough from the model to be unshadowed.
    std::vector<float> irradiance;
};

// The plane under `input`'s positions lit by its lights (area lights from their centres, as the
// highlights are), shadowed when input.lighting.shadows is set (4 rays per light over a 1.7-degree
// cone: a slight penumbra); the fill is occluded by the model up to twice its bounding radius away (16
// cosine-distributed rays per texel). Parallel over rows (TBB).
// An input without triangles gives a plane without irradiance (resolution 0).
GroundPlane ground_plane(const SurfaceRenderInput& input);

}  // namespace waxwork
