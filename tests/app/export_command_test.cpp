// `waxwork export` end to end: a meshed, fractured cube out as PLY, OBJ and STL, read back exactly;
// the baked colours against `render --fields` with the same light; bad input as one-line errors.
#include "io/volume_file.h"
#include "render/srgb.h"
#include "support/cli_run.h"
#include "support/exported_surface.h"
#include "support/fields_table.h"
#include "tetops/boundary_shells.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <numeric>
#include <set>

namespace waxwork {
namespace {

using namespace testing;
namespace fs = std::filesystem;

// The cube meshed and broken into pieces once for all tests (a few seconds).
class Export : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        dir_ = new fs::path(scratch_dir("export_cli"));
        const auto cube = *dir_ / "cube.vtu";
        auto r = run_waxwork("mesh " + kAssets + "/meshes/cube.obj -o " + cube.string() + " --max-tets 3000");
        ASSERT_EQ(r.exit_code, 0) << r.err;
        r = run_waxwork("fracture " + cube.string() + " -o " + pieces().string() + " --pieces 4 --seed 3");
        ASSERT_EQ(r.exit_code, 0) << r.err;
        r = run_waxwork("cut " + pieces().string() + " -o " + cut_pieces().string() + " --plane=1,1,0.3,0.2 --exact");
        ASSERT_EQ(r.exit_code, 0) << r.err;
    }
    static void TearDownTestSuite() { delete dir_; }
    static fs::path pieces() { return *dir_ / "pieces.vtu"; }
    static fs::path cut_pieces() { return *dir_ / "cut_pieces.vtu"; }
    static fs::path* dir_;
};
fs::path* Export::dir_ = nullptr;

// Triangle groups joined by shared vertices (in a separate export, one per piece).
std::vector<std::vector<size_t>> vertex_connected_groups(const ReadSurface& s) {
    std::vector<size_t> parent(s.positions.size());
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](size_t v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
    };
    for (const auto& t : s.triangles) {
        parent[find(t[1])] = find(t[0]);
        parent[find(t[2])] = find(t[0]);
    }
    std::map<size_t, std::vector<size_t>> groups;
    for (size_t t = 0; t < s.triangles.size(); ++t) groups[find(s.triangles[t][0])].push_back(t);
    std::vector<std::vector<size_t>> result;
    for (auto& [root, triangles] : groups) result.push_back(std::move(triangles));
    return result;
}

ReadSurface subset(const ReadSurface& s, const std::vector<size_t>& triangles) {
    ReadSurface part;
    part.positions = s.positions;
    for (size_t t : triangles) part.triangles.push_back(s.triangles[t]);
    return part;
}

TEST_F(Export, WritesEachPieceAsAClosedOutwardShellEnclosingItsVolume) {
    for (const fs::path& input : {pieces(), cut_pieces()}) {
        const TetMesh mesh = read_volume(input);
        const TetConnectivity connectivity = build_connectivity(mesh);
        ASSERT_GE(connectivity.component_count, 2);
        const double volume = total_volume(mesh);
        for (const std::string mode : {"merged", "separate"})
            for (const std::string format : {"ply", "obj", "stl"}) {
                const fs::path out = *dir_ / (mode + "." + format);
                const auto r = run_waxwork("export " + input.string() + " -o " + out.string() + " --pieces " + mode);
                ASSERT_EQ(r.exit_code, 0) << r.err;
                ASSERT_EQ(line_count(r.out), 1u) << r.out;
                const auto summary = nlohmann::json::parse(r.out);
                EXPECT_EQ(summary["triangles"], connectivity.boundary_faces.size());
                EXPECT_EQ(summary["shells"], mode == "merged" ? 1 : connectivity.component_count);
                EXPECT_EQ(summary["radiance"], false);

                const ReadSurface s = read_exported(out);
                const std::string what = input.filename().string() + " " + mode + " " + format;
                EXPECT_EQ(s.triangles.size(), connectivity.boundary_faces.size()) << what;
                EXPECT_NEAR(enclosed_volume(s), volume, (format == "stl" ? 1e-6 : 1e-9) * volume) << what;
                EXPECT_TRUE(closed_and_oriented(s)) << what;
                if (format == "stl") continue;  // STL welds nothing: pieces that touch cannot be told apart
                if (mode == "merged") {
                    EXPECT_EQ(s.positions.size(), connectivity.boundary_vertices.size()) << what;
                    continue;
                }
                // Separate: the pieces share no vertex, and each is one closed shell of positive volume.
                const auto groups = vertex_connected_groups(s);
                EXPECT_EQ(groups.size(), size_t(connectivity.component_count)) << what;
                double sum = 0;
                for (const auto& group : groups) {
                    const ReadSurface part = subset(s, group);
                    EXPECT_TRUE(closed_and_oriented(part)) << what;
                    EXPECT_GT(enclosed_volume(part), 0) << what;
                    sum += enclosed_volume(part);
                }
                EXPECT_NEAR(sum, volume, 1e-9 * volume) << what;
                if (format == "obj") {
                    EXPECT_EQ(s.groups.size(), size_t(connectivity.component_count)) << what;
                }
            }
    }
}

TEST_F(Export, BakedColoursAreRenderFieldsRadianceInSrgb) {
    const std::string light =
        " --material marble --scale 10 --light dir:-1,-0.5,-0.2 --light point:3,2,1:0.5,0.4,0.3 --ambient 0.05";
    const fs::path fields = *dir_ / "fields.csv";
    const auto render = run_waxwork("render " + pieces().string() + " -o " + (*dir_ / "r.png").string() +
                                    " --width 64 --height 48 --fields " + fields.string() + light);
    ASSERT_EQ(render.exit_code, 0) << render.err;
    const Fields table = read_fields(fields);
    std::vector<std::array<uint8_t, 3>> expected;  // per volume vertex
    for (const FieldRow& row : table.rows) expected.push_back(srgb_bytes(row.lo));

    const TetMesh mesh = read_volume(pieces());
    const TetConnectivity connectivity = build_connectivity(mesh);
    for (const std::string mode : {"merged", "separate"})
        for (const std::string format : {"ply", "obj"}) {
            const fs::path out = *dir_ / ("lit_" + mode + "." + format);
            const auto r = run_waxwork("export " + pieces().string() + " -o " + out.string() + " --radiance --pieces " +
                                       mode + light);
            ASSERT_EQ(r.exit_code, 0) << r.err;
            EXPECT_EQ(nlohmann::json::parse(r.out)["radiance"], true);
            const ReadSurface s = read_exported(out);
            const BoundaryShells shells =
                boundary_shells(mesh, connectivity, mode == "merged" ? ShellGrouping::Merged : ShellGrouping::Separate);
            ASSERT_EQ(s.colours.size(), shells.volume_vertices.size()) << mode << " " << format;
            std::set<std::array<uint8_t, 3>> distinct;
            for (size_t v = 0; v < s.colours.size(); ++v) {
                const int32_t volume_vertex = shells.volume_vertices[v];
                const FieldRow& row = table.rows[volume_vertex];
                ASSERT_TRUE(row.boundary);
                EXPECT_NEAR(s.positions[v].x(), row.x, 1e-6);
                EXPECT_EQ(s.colours[v], expected[volume_vertex]) << mode << " " << format << " vertex " << v;
                distinct.insert(s.colours[v]);
            }
            // Lit and shadowed sides: the comparison is over many different colours, not one.
            EXPECT_GT(distinct.size(), 50u) << mode << " " << format;
        }
}

TEST_F(Export, BadInputIsAOneLineErrorNamingTheFileOrOption) {
    struct Case {
        std::string arguments, expected;
    };
    const std::string in = pieces().string();
    const fs::path out = *dir_ / "bad";
    const std::vector<Case> cases = {
        {(*dir_ / "missing.vtu").string() + " -o " + out.string() + ".ply", "missing.vtu"},
        {in + " -o " + out.string() + ".off", "bad.off: unknown surface format '.off'"},
        {in + " -o " + out.string() + ".stl --radiance", "bad.stl: --radiance needs vertex colours"},
        {in + " -o " + out.string() + ".ply --pieces some", "--pieces"},
        {in + " -o " + out.string() + ".ply --radiance --light dir:0,0,0", "dir:0,0,0"},
        {in + " -o " + out.string() + ".ply --scale 0", "--scale"},
    };
    for (const Case& c : cases) {
        const auto r = run_waxwork("export " + c.arguments);
        EXPECT_NE(r.exit_code, 0) << c.arguments;
        EXPECT_EQ(line_count(r.err), 1u) << r.err;
        EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
        EXPECT_TRUE(r.out.empty()) << r.out;
    }
    for (const char* extension : {".ply", ".off", ".stl"}) EXPECT_FALSE(fs::exists(out.string() + extension));
}

}  // namespace
}  // namespace waxwork
