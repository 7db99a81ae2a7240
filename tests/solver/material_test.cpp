#include "base/error.h"
#include "solver/material.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>

namespace waxwork {
namespace {

TEST(Material, DerivedQuantities) {
    EXPECT_DOUBLE_EQ(diffusion_coefficient(0.01, 1.0), 1.0 / 3.03);
    EXPECT_DOUBLE_EQ(effective_transport_coefficient(0.01, 1.0), std::sqrt(0.0303));
    EXPECT_DOUBLE_EQ(diffusion_length(0.01, 1.0), 1.0 / std::sqrt(0.0303));
    EXPECT_TRUE(std::isinf(diffusion_length(0.0, 1.0)));
    const double fdr = diffuse_fresnel_reflectance(1.3);
    EXPECT_NEAR(fdr, -1.440 / 1.69 + 0.710 / 1.3 + 0.668 + 0.0636 * 1.3, 1e-15);
    EXPECT_GT(fdr, 0.3);
    EXPECT_LT(fdr, 0.5);
    EXPECT_NEAR(boundary_reflection_parameter(1.3), (1 + fdr) / (1 - fdr), 1e-15);
    EXPECT_NEAR(diffuse_fresnel_reflectance(1.0), 0.0016, 1e-12);  // nearly no reflection at a matched index
}

TEST(Material, DiffuseReflectanceRanksMaterialsByHowMuchLightComesBack) {
    // Strong absorption (ketchup's green and blue) reflects less than weak absorption (its red).
    const auto ketchup = diffuse_reflectance(material_preset("ketchup"));
    EXPECT_GT(ketchup[0], ketchup[1]);
    EXPECT_GT(ketchup[0], ketchup[2]);
    // No absorption reflects everything (a semi-infinite slab keeps no energy), more than any
    // absorbing material.
    TetMaterial white = material_preset("marble");
    white.mua = {0, 0, 0};
    const auto rd = diffuse_reflectance(white);
    const auto marble = diffuse_reflectance(material_preset("marble"));
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(rd[c], marble[c]);
        EXPECT_NEAR(rd[c], 1.0, 1e-12);
        EXPECT_GT(marble[c], 0.0);
    }
}

TEST(Material, DiffuseReflectanceIsTheDipoleProfileIntegratedOverThePlane) {
    // R_d(r) of the dipole (Jensen et al. 2001): a real source at z_r = 1 / sigma_t' and a negative
    // virtual one at z_v = z_r (1 + 4A/3), integrated as 2 pi r R_d(r) dr by Simpson's rule.
    for (const char* name : {"marble", "ketchup", "skimmilk"}) {
        const TetMaterial m = material_preset(name);
        const double a = boundary_reflection_parameter(m.eta);
        const std::array<double, 3> closed = diffuse_reflectance(m);
        for (int c = 0; c < 3; ++c) {
            const double sigma_t = m.mua[c] + m.musp[c], albedo = m.musp[c] / sigma_t;
            const double sigma_tr = std::sqrt(3 * m.mua[c] * sigma_t);
            const double zr = 1 / sigma_t, zv = zr * (1 + 4 * a / 3);
            const auto pole = [&](double z, double r) {
                const double d = std::sqrt(r * r + z * z);
                return z * (sigma_tr * d + 1) * std::exp(-sigma_tr * d) / (d * d * d);
            };
            const auto integrand = [&](double r) {
                return 2 * std::numbers::pi * r * albedo / (4 * std::numbers::pi) * (pole(zr, r) + pole(zv, r));
            };
            const double end = 60 / sigma_tr + 60 * zv;  // the tail beyond is below e^-60
            const int n = 200000;
            const double h = end / n;
            double sum = integrand(0) + integrand(end);
            for (int i = 1; i < n; ++i) sum += (i % 2 ? 4 : 2) * integrand(i * h);
            EXPECT_NEAR(sum * h / 3, closed[c], 1e-9 * closed[c]) << name << " channel " << c;
        }
    }
}

TEST(Material, FresnelTransmittance) {
    const double eta = 1.5;
    EXPECT_NEAR(fresnel_transmittance(1.0, eta), 1.0 - std::pow((eta - 1) / (eta + 1), 2), 1e-14);
    EXPECT_NEAR(fresnel_transmittance(0.0, eta), 0.0, 1e-14);
    // Reciprocity: entering at theta_i equals leaving at the refracted angle.
    const double cos_i = std::cos(0.9);
    const double sin_t = std::sin(0.9) / eta, cos_t = std::sqrt(1 - sin_t * sin_t);
    EXPECT_NEAR(fresnel_transmittance(cos_i, eta), fresnel_transmittance(cos_t, 1 / eta), 1e-14);
    // Total internal reflection from inside beyond the critical angle asin(1/eta).
    EXPECT_EQ(fresnel_transmittance(std::cos(std::asin(1 / eta) + 0.01), 1 / eta), 0.0);
    EXPECT_GT(fresnel_transmittance(std::cos(std::asin(1 / eta) - 0.01), 1 / eta), 0.0);
    // Monotone in the angle, within [0, 1].
    double previous = 1;
    for (double c = 1; c >= 0; c -= 0.01) {
        const double t = fresnel_transmittance(c, 1.3);
        EXPECT_LE(t, previous + 1e-15);
        EXPECT_GE(t, 0);
        previous = t;
    }
}

TEST(Material, PresetsMatchTheJensenTable) {
    const auto names = material_preset_names();
    ASSERT_EQ(names.size(), 12u);
    const std::filesystem::path path = std::filesystem::path(WAXWORK_ASSET_DIR) / "jensen2001.json";
    if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " missing";
    std::ifstream in(path);
    const auto json = nlohmann::json::parse(in);
    ASSERT_EQ(json["materials"].size(), names.size());
    for (const auto& [name, entry] : json["materials"].items()) {
        const TetMaterial m = material_preset(name);
        for (int c = 0; c < 3; ++c) {
            EXPECT_DOUBLE_EQ(m.mua[c], entry["mu_a"][c].get<double>()) << name;
            EXPECT_DOUBLE_EQ(m.musp[c], entry["mu_s_prime"][c].get<double>()) << name;
        }
        EXPECT_DOUBLE_EQ(m.eta, entry["eta"].get<double>()) << name;
        EXPECT_NO_THROW(validate_material(m)) << name;
    }
}

TEST(Material, UnknownPresetNamesTheKnownOnes) {
    try {
        material_preset("jade");
        FAIL();
    } catch (const InvalidArgumentError& e) {
        EXPECT_NE(std::string(e.what()).find("jade"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("marble"), std::string::npos);
    }
}

TEST(Material, ScaleMustBeAFiniteLengthInRange) {
    for (double good : {kMinMmPerUnit, 1.0, 30.0, kMaxMmPerUnit}) EXPECT_NO_THROW(validate_mm_per_unit(good)) << good;
    for (double bad : {0.0, -3.0, 1e-7, 2e6, 1e308, std::numeric_limits<double>::infinity(),
                       std::numeric_limits<double>::quiet_NaN()}) {
        try {
            validate_mm_per_unit(bad, "--scale");
            ADD_FAILURE() << "accepted " << bad;
        } catch (const InvalidArgumentError& e) {
            EXPECT_EQ(std::string(e.what()).rfind("--scale must be a length in mm per model unit", 0), 0u) << e.what();
        }
    }
}

TEST(Material, ValidationRejectsBadCoefficients) {
    const TetMaterial good = material_preset("marble");
    auto expect_bad = [&](TetMaterial m, const std::string& fragment) {
        try {
            validate_material(m, "tet 3");
            ADD_FAILURE() << "accepted: " << fragment;
        } catch (const InvalidArgumentError& e) {
            EXPECT_NE(std::string(e.what()).find("tet 3"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
        }
    };
    TetMaterial m = good;
    m.mua[1] = std::numeric_limits<double>::quiet_NaN();
    expect_bad(m, "mu_a is not finite");
    m = good;
    m.mua[0] = -0.1;
    expect_bad(m, "negative");
    m = good;
    m.musp[2] = 0;
    expect_bad(m, "must be positive");
    m = good;
    m.eta = 0;
    expect_bad(m, "eta");
    m = good;
    m.eta = 40;
    expect_bad(m, "eta");
    m = good;
    m.eta = 1e308;
    expect_bad(m, "eta = 1e+308 is outside");  // not 309 digits
    m = good;
    m.mua[0] = -1e300;
    expect_bad(m, "mu_a = -1e+300 is negative");
    m = good;
    m.musp[0] = 1e7;
    expect_bad(m, "per millimetre");
    m = good;
    m.mua = {0, 0, 0};  // spectralon-like: allowed
    EXPECT_NO_THROW(validate_material(m));
}

// The name a comparison records (bench solvers) is that of the materials resolve_materials fills the
// tets with: the override (a preset by its name, other coefficients as "custom"), else the volume's
// own ("stored"), else the marble default.
TEST(ResolvedMaterials, AreNamedAsTheyAreChosen) {
    TetMesh mesh = testing::make_cube_mesh(2);
    const TetMaterial ketchup = material_preset("ketchup");
    EXPECT_EQ(resolve_materials(mesh, std::nullopt).front(), material_preset("marble"));
    EXPECT_EQ(resolved_materials_name(mesh, std::nullopt), "marble");
    EXPECT_EQ(resolved_materials_name(mesh, ketchup), "ketchup");
    TetMaterial custom = ketchup;
    custom.eta = 1.4;
    EXPECT_EQ(resolved_materials_name(mesh, custom), "custom");
    mesh.materials.assign(mesh.tet_count(), custom);
    EXPECT_EQ(resolve_materials(mesh, std::nullopt).front(), custom);
    EXPECT_EQ(resolved_materials_name(mesh, std::nullopt), "stored");
    EXPECT_EQ(resolve_materials(mesh, ketchup).front(), ketchup);
    EXPECT_EQ(resolved_materials_name(mesh, ketchup), "ketchup");
}

}  // namespace
}  // namespace waxwork
