// The size of a model in millimetres. Scattering coefficients are per millimetre, so every scene has
// a scale in millimetres per model unit, and no mesh file knows its units: the same spot is a 2.6 mm
// bead (white, opaque-looking: light diffuses across all of it) at 1 mm per unit and a 78 mm figurine
// at 30. Without a scale from the user or from a volume Waxwork saved, the model's bounding box picks
// one that puts it at hand size, where the measured materials look like themselves.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace waxwork {

// Between 1e-6 (a model in nanometres) and 1e6 (in kilometres): outside, lengths in mm over- or
// underflow the tet volumes of the diffusion matrix (a 1e308 scale made every tet "degenerate").
inline constexpr double kMinMmPerUnit = 1e-6;
inline constexpr double kMaxMmPerUnit = 1e6;

// What is wrong with `mm_per_unit` as a scale ("" when it is in the range above):
// "must be a length in mm per model unit between 1e-6 and 1e6 (got X)".
std::string mm_per_unit_problem(double mm_per_unit);

// The bounding-box diagonal the default scale aims at: hand-sized, as the papers' renders of the
// measured materials are (Jensen et al. 2001 light objects a few centimetres across).
inline constexpr double kDefaultDiagonalMm = 75.0;

// The default scale of a model whose bounding-box diagonal is `diagonal` model units: the value of
// 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 times a power of ten nearest (in ratio) to kDefaultDiagonalMm /
// diagonal, so the diagonal lands within about 61-92 mm and the number is one a user can repeat
// (spot: 30). Throws InvalidArgumentError when the diagonal is not positive and finite; clamped to
// [kMinMmPerUnit, kMaxMmPerUnit].
double default_mm_per_unit(double diagonal);

// Where a scene's scale came from, for saying what was chosen.
enum class ScaleSource {
    Given,      // the user's --scale or a session's "scale"
    Stored,     // the volume file's stored scale
    ModelSize,  // default_mm_per_unit of the model's bounding box
};

// "given", "stored", "model size": for reports.
const char* scale_source_name(ScaleSource source);

struct ModelScale {
    double mm_per_unit = 1.0;
    ScaleSource source = ScaleSource::ModelSize;
};

// The extent (max - min) of the points' bounding box; zero for no points.
Eigen::Vector3d bounding_extent(const std::vector<Eigen::Vector3d>& points);

// The first of: the given scale, the stored one, the model's default for a bounding box whose
// extent (max - min) is `extent`.
ModelScale choose_model_scale(const std::optional<double>& given, const std::optional<double>& stored,
                              const Eigen::Vector3d& extent);

// "30 mm per model unit (from the model's size): the model is 28 x 51 x 52 mm" (the source is
// omitted for ScaleSource::Given).
std::string describe_model_scale(const ModelScale& scale, const Eigen::Vector3d& extent);

// The extent in millimetres, as "28 x 51 x 52 mm" with three significant digits.
std::string size_in_mm(const Eigen::Vector3d& extent, double mm_per_unit);

}  // namespace waxwork
