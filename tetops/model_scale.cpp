#include "tetops/model_scale.h"

#include "base/error.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

namespace waxwork {

std::string mm_per_unit_problem(double mm_per_unit) {
    if (std::isfinite(mm_per_unit) && mm_per_unit >= kMinMmPerUnit && mm_per_unit <= kMaxMmPerUnit) return "";
    std::ostringstream text;
    text << "must be a length in mm per model unit between 1e-6 and 1e6 (got " << mm_per_unit << ")";
    return text.str();
}

double default_mm_per_unit(double diagonal) {
    if (!std::isfinite(diagonal) || diagonal <= 0)
        throw InvalidArgumentError("a model's default scale needs a positive, finite bounding-box diagonal");
    const double wanted = kDefaultDiagonalMm / diagonal;
    if (!std::isfinite(wanted)) return kMaxMmPerUnit;  // a subnormal diagonal
    // Steps of at most 1.5x: any wanted value is within a factor sqrt(1.5) ~ 1.22 of one of them.
    static constexpr std::array<double, 10> kMantissas = {1, 1.5, 2, 2.5, 3, 4, 5, 6, 8, 10};
    const double decade = std::pow(10.0, std::floor(std::log10(wanted)));
    double best = decade;
    for (const double m : kMantissas)
        if (std::abs(std::log(m * decade / wanted)) < std::abs(std::log(best / wanted))) best = m * decade;
    return std::clamp(best, kMinMmPerUnit, kMaxMmPerUnit);
}

const char* scale_source_name(ScaleSource source) {
    switch (source) {
        case ScaleSource::Given: return "given";
        case ScaleSource::Stored: return "stored";
        case ScaleSource::ModelSize: return "model size";
    }
    return "unknown";
}

Eigen::Vector3d bounding_extent(const std::vector<Eigen::Vector3d>& points) {
    if (points.empty()) return Eigen::Vector3d::Zero();
    Eigen::Vector3d low = points.front(), high = points.front();
    for (const Eigen::Vector3d& p : points) {
        low = low.cwiseMin(p);
        high = high.cwiseMax(p);
    }
    return high - low;
}

ModelScale choose_model_scale(const std::optional<double>& given, const std::optional<double>& stored,
                              const Eigen::Vector3d& extent) {
    if (given) return {*given, ScaleSource::Given};
    if (stored) return {*stored, ScaleSource::Stored};
    return {default_mm_per_unit(extent.norm()), ScaleSource::ModelSize};
}

std::string size_in_mm(const Eigen::Vector3d& extent, double mm_per_unit) {
    std::ostringstream text;
    text.precision(3);
    text << extent.x() * mm_per_unit << " x " << extent.y() * mm_per_unit << " x " << extent.z() * mm_per_unit << " mm";
    return text.str();
}

std::string describe_model_scale(const ModelScale& scale, const Eigen::Vector3d& extent) {
    std::ostringstream text;
    text << scale.mm_per_unit << " mm per model unit";
    if (scale.source == ScaleSource::Stored) text << " (stored in the volume)";
    if (scale.source == ScaleSource::ModelSize) text << " (chosen from the model's size; --scale sets it)";
    text << ": the model is " << size_in_mm(extent, scale.mm_per_unit);
    return text.str();
}

}  // namespace waxwork
