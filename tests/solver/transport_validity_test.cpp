// The regime where the live image can be trusted (solver/transport_validity.h): high-albedo presets
// are in it, low-albedo ones and a painted material below the threshold are named with their channel.
#include "solver/material.h"
#include "solver/transport_validity.h"

#include <gtest/gtest.h>

#include <vector>

namespace waxwork {
namespace {

TEST(TransportValidity, HighAlbedoPresetsAreTrustedLowAlbedoOnesNamed) {
    const std::vector<TetMaterial> marble(100, material_preset("marble"));
    EXPECT_GE(lowest_reduced_albedo(marble).reduced_albedo, kTrustedReducedAlbedo);
    EXPECT_EQ(diffusion_trust_warning(marble), "");
    EXPECT_EQ(diffusion_trust_warning({}), "");

    // Marble with a dab of ketchup: ketchup's blue (mu_a 0.061, mu_s' 0.19 per mm) sets the floor.
    std::vector<TetMaterial> dab = marble;
    dab[40] = material_preset("ketchup");
    const ReducedAlbedoFloor floor = lowest_reduced_albedo(dab);
    const TetMaterial& k = dab[40];
    EXPECT_EQ(floor.material, k);
    double expected = 1;
    int channel = 0;
    for (int c = 0; c < 3; ++c)
        if (k.musp[c] / (k.mua[c] + k.musp[c]) < expected) expected = k.musp[c] / (k.mua[c] + k.musp[c]), channel = c;
    EXPECT_DOUBLE_EQ(floor.reduced_albedo, expected);
    EXPECT_EQ(floor.channel, channel);
    const std::string warning = diffusion_trust_warning(dab);
    EXPECT_NE(warning.find("ketchup"), std::string::npos) << warning;
    EXPECT_NE(warning.find("docs/diffusion_vs_transport.md"), std::string::npos) << warning;

    // Just under the threshold in green, not a preset.
    TetMaterial painted = material_preset("marble");
    painted.musp[1] = 1.0;
    painted.mua[1] = 1.0 / 0.989 - 1.0;
    const std::vector<TetMaterial> one = {painted};
    EXPECT_NE(diffusion_trust_warning(one).find("a painted material scatters little in green"), std::string::npos)
        << diffusion_trust_warning(one);
    painted.mua[1] = 1.0 / 0.991 - 1.0;
    const std::vector<TetMaterial> above = {painted};
    EXPECT_EQ(diffusion_trust_warning(above), "");
}

}  // namespace
}  // namespace waxwork
