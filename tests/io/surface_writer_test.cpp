// write_surface: the boundary of a volume saved as PLY, OBJ and STL and read back, exactly (the test's
// own readers) and by OpenMesh (what other programs see): every boundary face once, outward, closed
// shells enclosing the volume's own volume, colours as given, pieces apart when asked.
#include "io/surface_writer.h"

#include "base/error.h"
#include "support/exported_surface.h"
#include "support/scratch_dir.h"
#include "tetops/boundary_shells.h"
#include "tetops/connectivity.h"
#include "tetops/test_meshes.h"

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <gtest/gtest.h>

#include <set>

namespace waxwork {
namespace {

using namespace testing;
namespace fs = std::filesystem;

// OpenMesh reads coordinates as float whatever the file holds: it checks counts and colours here.
using OpenMeshSurface = OpenMesh::TriMesh_ArrayKernelT<>;

// Colours that differ per vertex, so a permutation would show.
std::vector<std::array<uint8_t, 3>> test_colours(size_t n) {
    std::vector<std::array<uint8_t, 3>> colours(n);
    for (size_t v = 0; v < n; ++v) colours[v] = {uint8_t(v * 7), uint8_t(255 - v), uint8_t(v * 13 + 1)};
    return colours;
}

// Two unit cubes that touch along one edge: two face-connected parts sharing two vertices.
TetMesh touching_cubes() {
    return make_cell_mesh(2, 2, 1, [](int i, int j, int) { return i == j; });
}

TEST(SurfaceWriter, EveryFormatRoundTripsTheBoundaryOutwardAndClosed) {
    const auto dir = scratch_dir("surface_writer_roundtrip");
    TetMesh mesh = make_cube_mesh(3, Eigen::Vector3d(0.3, -1.7, 2.1), 1.9);
    // A moved piece: the surface is written where the volume is seen (world space).
    mesh.piece_transforms[0].rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    mesh.piece_transforms[0].translation = Eigen::Vector3d(5, 0, -2);
    const TetConnectivity connectivity = build_connectivity(mesh);
    const BoundaryShells shells = boundary_shells(mesh, connectivity, ShellGrouping::Merged);
    ASSERT_EQ(shells.triangles.size(), connectivity.boundary_faces.size());
    ASSERT_EQ(shells.positions.size(), connectivity.boundary_vertices.size());
    const double volume = total_volume(mesh);
    for (const char* name : {"cube.ply", "cube.obj", "cube.stl"}) {
        const fs::path path = dir / name;
        write_surface(path, shells);
        const ReadSurface s = read_exported(path);
        EXPECT_EQ(s.triangles.size(), connectivity.boundary_faces.size()) << name;
        EXPECT_EQ(s.positions.size(), connectivity.boundary_vertices.size()) << name;
        EXPECT_TRUE(closed_and_oriented(s)) << name;
        // PLY and OBJ keep doubles; binary STL is float32 by its format.
        const double tolerance = path.extension() == ".stl" ? 1e-6 : 1e-9;
        EXPECT_NEAR(enclosed_volume(s), volume, tolerance * volume) << name;
        EXPECT_TRUE(s.colours.empty()) << name;
        // Where the world transform put it, not the rest frame.
        EXPECT_NEAR(s.positions[0].x(), shells.positions[0].x(), 1e-5) << name;

        OpenMeshSurface other;
        ASSERT_TRUE(OpenMesh::IO::read_mesh(other, path.string())) << name;
        EXPECT_EQ(other.n_faces(), connectivity.boundary_faces.size()) << name;
    }
}

TEST(SurfaceWriter, ColoursRoundTripInPlyAndObj) {
    const auto dir = scratch_dir("surface_writer_colours");
    const TetMesh mesh = make_cube_mesh(2);
    const BoundaryShells shells = boundary_shells(mesh, build_connectivity(mesh), ShellGrouping::Merged);
    const auto colours = test_colours(shells.positions.size());
    for (const char* name : {"c.ply", "c.obj"}) {
        const fs::path path = dir / name;
        write_surface(path, shells, colours);
        EXPECT_EQ(read_exported(path).colours, colours) << name;

        OpenMeshSurface other;
        other.request_vertex_colors();
        OpenMesh::IO::Options options = OpenMesh::IO::Options::VertexColor;
        ASSERT_TRUE(OpenMesh::IO::read_mesh(other, path.string(), options)) << name;
        ASSERT_TRUE(options.vertex_has_color()) << name;
        ASSERT_EQ(other.n_vertices(), colours.size()) << name;
        for (size_t v = 0; v < colours.size(); ++v) {
            const auto c = other.color(OpenMeshSurface::VertexHandle(int(v)));
            EXPECT_EQ((std::array<uint8_t, 3>{c[0], c[1], c[2]}), colours[v]) << name << " vertex " << v;
        }
    }
}

TEST(SurfaceWriter, SeparatePartsShareNoVertexAndEachIsAClosedOutwardShell) {
    const auto dir = scratch_dir("surface_writer_parts");
    const TetMesh mesh = touching_cubes();
    const TetConnectivity connectivity = build_connectivity(mesh);
    ASSERT_EQ(connectivity.component_count, 2);

    // Merged: the two vertices of the shared edge appear once.
    const BoundaryShells merged = boundary_shells(mesh, connectivity, ShellGrouping::Merged);
    EXPECT_EQ(merged.shell_count(), 1u);
    EXPECT_EQ(merged.positions.size(), 14u);  // 2 x 8 corners, 2 shared

    const BoundaryShells separate = boundary_shells(mesh, connectivity, ShellGrouping::Separate);
    ASSERT_EQ(separate.shell_count(), 2u);
    EXPECT_EQ(separate.positions.size(), 16u);
    for (const char* name : {"parts.obj", "parts.ply", "parts.stl"}) {
        const fs::path path = dir / name;
        write_surface(path, separate);
        const ReadSurface s = read_exported(path);
        ASSERT_EQ(s.triangles.size(), separate.triangles.size()) << name;
        EXPECT_NEAR(enclosed_volume(s), 2.0, 1e-9) << name;
        for (size_t p = 0; p < 2; ++p) {
            const size_t first = separate.shell_offsets[p], last = separate.shell_offsets[p + 1];
            EXPECT_TRUE(closed_and_oriented(s, first, last)) << name << " piece " << p;
            EXPECT_NEAR(enclosed_volume(s, first, last), 1.0, 1e-9) << name << " piece " << p;
        }
        if (path.extension() == ".stl") continue;  // STL has no shared vertices to check
        std::set<int32_t> first_part, second_part;
        for (size_t t = 0; t < s.triangles.size(); ++t)
            for (int32_t v : s.triangles[t]) (t < size_t(separate.shell_offsets[1]) ? first_part : second_part).insert(v);
        for (int32_t v : first_part) EXPECT_FALSE(second_part.count(v)) << name << " vertex " << v;
        if (path.extension() == ".obj") {
            EXPECT_EQ(s.groups, (std::vector<std::string>{"piece_1", "piece_2"}));
            EXPECT_EQ(s.group_triangle_offsets, (std::vector<size_t>{0, size_t(separate.shell_offsets[1]),
                                                                     separate.triangles.size()}));
        }
    }
}

TEST(SurfaceWriter, RefusesWhatTheFormatCannotHoldNamingTheFile) {
    const auto dir = scratch_dir("surface_writer_errors");
    const TetMesh mesh = make_cube_mesh(1);
    const BoundaryShells shells = boundary_shells(mesh, build_connectivity(mesh), ShellGrouping::Merged);
    const auto colours = test_colours(shells.positions.size());
    auto message = [&](const fs::path& path, std::span<const std::array<uint8_t, 3>> c) {
        try {
            write_surface(path, shells, c);
        } catch (const InvalidArgumentError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(message(dir / "c.stl", colours).find("c.stl: STL has no standard vertex colours"), std::string::npos);
    EXPECT_NE(message(dir / "c.off", {}).find("c.off: unknown surface format '.off'"), std::string::npos);
    EXPECT_NE(message(dir / "c.ply", std::span(colours).first(3)).find("c.ply: 3 colours for"), std::string::npos);
    EXPECT_FALSE(fs::exists(dir / "c.stl"));
    EXPECT_FALSE(fs::exists(dir / "c.ply"));
    EXPECT_EQ(surface_format("A.PLY"), SurfaceFormat::Ply);
}

}  // namespace
}  // namespace waxwork
