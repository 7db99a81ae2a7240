#include "solver/material.h"

#include "base/error.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace waxwork {
namespace {

// Jensen, Marschner, Levoy, Hanrahan, "A Practical Model for Subsurface Light Transport",
// SIGGRAPH 2001, Fig. 5 (measured; per mm, rgb). Identical to assets/jensen2001.json, compiled in so
// that presets work without the asset directory. chicken1's red mu_a is the paper's 0.015.
struct Preset {
    std::string_view name;
    std::array<double, 3> musp;
    std::array<double, 3> mua;
    double eta;
};

constexpr std::array<Preset, 12> kJensen2001 = {{
    {"apple", {2.29, 2.39, 1.97}, {0.0030, 0.0034, 0.046}, 1.3},
    {"chicken1", {0.15, 0.21, 0.38}, {0.015, 0.077, 0.19}, 1.3},
    {"chicken2", {0.19, 0.25, 0.32}, {0.018, 0.088, 0.20}, 1.3},
    {"cream", {7.38, 5.47, 3.15}, {0.0002, 0.0028, 0.0163}, 1.3},
    {"ketchup", {0.18, 0.07, 0.03}, {0.061, 0.97, 1.45}, 1.3},
    {"marble", {2.19, 2.62, 3.00}, {0.0021, 0.0041, 0.0071}, 1.5},
    {"potato", {0.68, 0.70, 0.55}, {0.0024, 0.0090, 0.12}, 1.3},
    {"skimmilk", {0.70, 1.22, 1.90}, {0.0014, 0.0025, 0.0142}, 1.3},
    {"skin1", {0.74, 0.88, 1.01}, {0.032, 0.17, 0.48}, 1.3},
    {"skin2", {1.09, 1.59, 1.79}, {0.013, 0.070, 0.145}, 1.3},
    {"spectralon", {11.6, 20.4, 14.9}, {0.0, 0.0, 0.0}, 1.3},
    {"wholemilk", {2.55, 3.21, 3.77}, {0.0011, 0.0024, 0.014}, 1.3},
}};


}  // namespace

double diffusion_coefficient(double mua, double musp) { return 1.0 / (3.0 * (mua + musp)); }

double effective_transport_coefficient(double mua, double musp) { return std::sqrt(3.0 * mua * (mua + musp)); }

double diffusion_length(double mua, double musp) {
    const double sigma = effective_transport_coefficient(mua, musp);
    return sigma > 0 ? 1.0 / sigma : std::numeric_limits<double>::infinity();
}

double diffuse_fresnel_reflectance(double eta) { return -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta; }

double boundary_reflection_parameter(double eta) {
    const double fdr = diffuse_fresnel_reflectance(eta);
    return (1.0 + fdr) / (1.0 - fdr);
}

std::array<double, 3> diffuse_reflectance(const TetMaterial& material) {
    const double a = boundary_reflection_parameter(material.eta);
    std::array<double, 3> rd{};
    for (int c = 0; c < 3; ++c) {
        const double extinction = material.mua[c] + material.musp[c];
        const double albedo = extinction > 0 ? material.musp[c] / extinction : 0.0;
        // sigma_tr z_r of the real source; the virtual one lies (1 + 4A/3) times deeper.
        const double root = std::sqrt(3 * (1 - albedo));
        rd[c] = 0.5 * albedo * (1 + std::exp(-4.0 / 3.0 * a * root)) * std::exp(-root);
    }
    return rd;
}

double fresnel_transmittance(double cos_incident, double eta) {
    const double cos_i = std::clamp(cos_incident, 0.0, 1.0);
    const double sin_i2 = std::max(0.0, 1.0 - cos_i * cos_i);
    const double sin_t2 = sin_i2 / (eta * eta);  // Snell: sin_t = sin_i / eta
    if (sin_t2 >= 1.0) return 0.0;               // total internal reflection
    const double cos_t = std::sqrt(1.0 - sin_t2);
    // Amplitude coefficients for s and p polarisation; at grazing incidence (cos_i = 0) both reflect
    // fully and the formulas give exactly 1 without special-casing (denominators stay positive).
    const double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    const double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 1.0 - 0.5 * (rs * rs + rp * rp);
}

namespace {
// The common case, without building any message: assembly validates every tet of a 500K-tet volume.
bool material_is_valid(const TetMaterial& m) {
    for (int c = 0; c < 3; ++c)
        if (!(m.mua[c] >= 0 && m.mua[c] <= kMaxCoefficientPerMm && m.musp[c] > 0 && m.musp[c] <= kMaxCoefficientPerMm))
            return false;
    return m.eta >= kMinEta && m.eta <= kMaxEta;
}
}  // namespace

void validate_mm_per_unit(double mm_per_unit, std::string_view what) {
    const std::string problem = mm_per_unit_problem(mm_per_unit);
    if (!problem.empty()) throw InvalidArgumentError(std::string(what) + " " + problem);
}

void validate_material(const TetMaterial& m, std::string_view context) {
    if (material_is_valid(m)) return;
    throw InvalidArgumentError(std::string(context) + ": " + material_problem(m));
}

std::vector<std::string> material_preset_names() {
    std::vector<std::string> names;
    for (const Preset& p : kJensen2001) names.emplace_back(p.name);
    return names;
}

TetMaterial material_preset(std::string_view name) {
    for (const Preset& p : kJensen2001)
        if (p.name == name) return TetMaterial{p.mua, p.musp, p.eta};
    std::ostringstream known;
    for (size_t i = 0; i < kJensen2001.size(); ++i) known << (i ? ", " : "") << kJensen2001[i].name;
    throw InvalidArgumentError("unknown material '" + std::string(name) + "' (known: " + known.str() + ")");
}

std::string material_label(const TetMaterial& material) {
    for (const Preset& p : kJensen2001)
        if (TetMaterial{p.mua, p.musp, p.eta} == material) return std::string(p.name);
    return "custom";
}

std::string resolved_materials_name(const TetMesh& mesh, const std::optional<TetMaterial>& override) {
    if (override) return material_label(*override);
    return mesh.has_materials() ? "stored" : "marble";
}

std::vector<TetMaterial> resolve_materials(const TetMesh& mesh, const std::optional<TetMaterial>& override) {
    if (override) {
        validate_material(*override);
        return std::vector<TetMaterial>(mesh.tet_count(), *override);
    }
    if (!mesh.has_materials()) return std::vector<TetMaterial>(mesh.tet_count(), material_preset("marble"));
    if (mesh.materials.size() != mesh.tet_count()) {
        throw InvalidArgumentError("the volume stores " + std::to_string(mesh.materials.size()) + " materials for " +
                                   std::to_string(mesh.tet_count()) + " tets");
    }
    // Painted volumes hold few distinct materials in long runs: validate each run once.
    for (size_t t = 0; t < mesh.materials.size(); ++t) {
        if (t == 0 || !(mesh.materials[t] == mesh.materials[t - 1]))
            validate_material(mesh.materials[t], "stored material of tet " + std::to_string(t));
    }
    return mesh.materials;
}

}  // namespace waxwork
