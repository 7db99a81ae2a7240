// `waxwork refine`: adapts a volume to its light within a tet budget, carrying every tet's material,
// and refuses absurd budgets and fractions with one-line errors naming the option.
#include "io/volume_file.h"
#include "scene/document.h"
#include "tetops/paint.h"
#include "solver/material.h"
#include "support/cli_run.h"
#include "tetops/connectivity.h"
#include "tetops/quality.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace waxwork {
namespace {

using testing::line_count;
using testing::run_waxwork;
using testing::scratch_dir;
namespace fs = std::filesystem;

TEST(RefineCommand, RefinesWithinTheBudgetAndKeepsEveryTetsMaterial) {
    const auto dir = scratch_dir("refine_command");
    TetMesh input = testing::make_cube_mesh(5);
    const std::vector<std::string> names = material_preset_names();
    for (size_t t = 0; t < input.tet_count(); ++t) input.materials.push_back(material_preset(names[(t / 11) % names.size()]));
    const fs::path in = dir / "in.vtu", out = dir / "out.vtu";
    write_volume(input, in);
    const size_t budget = 2 * input.tet_count();
    const auto r = run_waxwork("refine " + in.string() + " -o " + out.string() + " --max-tets " + std::to_string(budget) +
                               " --scale 10 --light dir:1,-0.8,-0.5");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json summary = nlohmann::json::parse(r.out);
    const TetMesh refined = read_volume(out);
    EXPECT_EQ(summary["tets_before"], input.tet_count());
    EXPECT_EQ(summary["tets_after"], refined.tet_count());
    EXPECT_EQ(summary["vertices_after"], refined.vertex_count());
    EXPECT_GT(refined.tet_count(), input.tet_count());
    EXPECT_LE(refined.tet_count(), budget);
    EXPECT_GE(summary["rounds"].get<int>(), 1);
    EXPECT_EQ(summary["min_dihedral_deg"].get<double>(), mesh_min_dihedral_deg(refined));
    EXPECT_GE(summary["min_dihedral_deg"].get<double>(), 0.5);
    EXPECT_TRUE(summary.contains("milliseconds"));
    EXPECT_NO_THROW(validate(refined));
    EXPECT_NO_THROW(build_connectivity(refined));
    EXPECT_NEAR(total_volume(refined), total_volume(input), 1e-12);
    // The input's original ids are its indices: each tet keeps its ancestor's material exactly.
    ASSERT_EQ(refined.materials.size(), refined.tet_count());
    for (size_t t = 0; t < refined.tet_count(); ++t)
        ASSERT_EQ(refined.materials[t], input.materials[refined.original_ids[t]]) << t;
}

// `paint --refine` is a refine edit around the stroke down to sigma, then the paint, as the Document
// applies them: bit for bit the same volume, with every tet the brush reaches at most sigma long.
TEST(RefineCommand, PaintRefinesUnderTheStrokeToSigmaFirst) {
    const auto dir = scratch_dir("paint_refine_command");
    const TetMesh input = testing::make_cube_mesh(4);
    const fs::path in = dir / "in.vtu", out = dir / "out.vtu";
    write_volume(input, in);
    const auto r = run_waxwork("paint " + in.string() + " -o " + out.string() +
                               " --at 0.5,0.5,0.5 --sigma 0.1 --material ketchup --refine --max-tets 100000");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json summary = nlohmann::json::parse(r.out);
    EXPECT_EQ(summary["tets_before"], input.tet_count());
    EXPECT_GT(summary["refined"]["bisections"].get<size_t>(), 0u);
    EXPECT_FALSE(summary["refined"]["budget_reached"].get<bool>());

    PaintOp paint;
    paint.points = {Eigen::Vector3d(0.5, 0.5, 0.5)};
    paint.material = material_preset("ketchup");
    paint.sigma = 0.1;
    PaintBrush brush;
    brush.sigma = paint.sigma;
    RefineOp refine;
    refine.points = paint.points;
    refine.radius = paint_radius(brush);
    refine.edge_length = paint.sigma;
    refine.max_tets = 100000;
    Document document(input, material_preset("marble"));
    document.apply(refine);
    document.apply(paint);
    const TetMesh refined = read_volume(out);
    EXPECT_TRUE(refined == document.mesh());
    EXPECT_EQ(summary["tets_after"], refined.tet_count());
    size_t reached = 0;
    for (size_t t = 0; t < refined.tet_count(); ++t) {
        const Tet& tet = refined.tets[t];
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        for (const int32_t v : tet) centroid += refined.positions[v] / 4;
        if ((centroid - paint.points[0]).norm() >= refine.radius) continue;
        ++reached;
        for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j)
                EXPECT_LE((refined.positions[tet[i]] - refined.positions[tet[j]]).norm(), paint.sigma) << t;
    }
    EXPECT_GT(reached, 100u);
}

TEST(RefineCommand, RefusesAbsurdOptionsWithOneLine) {
    const auto dir = scratch_dir("refine_command_errors");
    const fs::path in = dir / "in.vtu", out = dir / "out.vtu";
    write_volume(testing::make_cube_mesh(2), in);
    const auto error = [&](const std::string& args) {
        const auto r = run_waxwork("refine " + in.string() + " -o " + out.string() + " " + args);
        EXPECT_NE(r.exit_code, 0) << args;
        EXPECT_EQ(line_count(r.err), 1u) << r.err;
        EXPECT_FALSE(fs::exists(out)) << args;
        return r.err;
    };
    EXPECT_NE(error("--max-tets 0").find("--max-tets"), std::string::npos);
    EXPECT_NE(error("--max-tets 10").find("below the volume's 48 tets"), std::string::npos);
    EXPECT_NE(error("--max-tets 100000000000").find("--max-tets"), std::string::npos);
    EXPECT_NE(error("--fraction nan").find("--fraction"), std::string::npos);
    EXPECT_NE(error("--rounds 0").find("--rounds"), std::string::npos);
    const auto paint = run_waxwork("paint " + in.string() + " -o " + out.string() +
                                   " --at 0.5,0.5,0.5 --sigma 0.1 --material ketchup --max-tets 100");
    EXPECT_NE(paint.err.find("only with --refine"), std::string::npos) << paint.err;
    EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace waxwork
