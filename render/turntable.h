// A turntable: the camera circling the model about its vertical axis, one frame per step. The light
// solve does not depend on the view (the exitant radiance factor E is per vertex; only F_t(theta_o)
// and the highlights change with it), so an orbit is one solve and N draws.
#pragma once

#include "render/camera.h"

#include <optional>
#include <string>

namespace waxwork {

// The camera of frame `index` of `frames`: `start` turned about its up vector (the model's vertical
// axis, through the box's centre, which frame_camera looks at) by 360 * index / frames degrees,
// counter-clockwise seen from above. With `elevation_degrees` (in (-90, 90)) the eye stands that far
// above the horizontal plane; else at the start's elevation. The framing distance depends on the
// box's bounding sphere only, so the model keeps its size across the orbit. Throws
// InvalidArgumentError for frames < 1, an index outside [0, frames), an elevation outside (-90, 90),
// or a start looking straight along its up vector without an elevation.
CameraSettings orbit_camera(const CameraSettings& start, int index, int frames,
                            std::optional<double> elevation_degrees = std::nullopt);

// One turn's length in a turntable's video, and the frames of the editor's turntable, unless asked
// otherwise.
inline constexpr double kDefaultSecondsPerTurn = 6;
inline constexpr int kDefaultTurntableFrames = 36;

// The frames' file names, frame_0000.png, ... (what io/video_encoder.h encode_mp4 reads).
std::string turntable_frame_name(int index);

}  // namespace waxwork
