// Volume files: exact round trips in every format, rejection of broken files, atomic saves.
#include "base/error.h"
#include "io/atomic_file.h"
#include "io/gmsh_format.h"
#include "io/medit_format.h"
#include "io/tetgen_format.h"
#include "io/volume_file.h"
#include "io/vtu_format.h"
#include "tetops/model_scale.h"
#include "tetops/tet_mesh.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <linux/fs.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>

namespace waxwork {
namespace {

namespace fs = std::filesystem;

// A 2x2x2 block of cubes, each split into the 6 Kuhn tets around its main diagonal (a conforming
// mesh), with jittered coordinates so every mantissa bit matters, random materials, scrambled
// original ids and two pieces, the second one rotated and translated.
TetMesh make_test_mesh(bool with_materials = true) {
    std::mt19937 random(12345);
    std::uniform_real_distribution<double> jitter(-0.05, 0.05);
    constexpr int n = 2;
    std::vector<Eigen::Vector3d> positions;
    auto vertex = [&](int x, int y, int z) { return static_cast<int32_t>((z * (n + 1) + y) * (n + 1) + x); };
    for (int z = 0; z <= n; ++z)
        for (int y = 0; y <= n; ++y)
            for (int x = 0; x <= n; ++x)
                positions.emplace_back(x + jitter(random), y + jitter(random), z + jitter(random));
    std::vector<Tet> tets;
    std::vector<int32_t> pieces;
    const int axis_orders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x)
                for (const auto& order : axis_orders) {
                    int corner[3] = {x, y, z};
                    Tet tet;
                    tet[0] = vertex(corner[0], corner[1], corner[2]);
                    for (int k = 0; k < 3; ++k) {
                        ++corner[order[k]];
                        tet[k + 1] = vertex(corner[0], corner[1], corner[2]);
                    }
                    tets.push_back(tet);
                    pieces.push_back(x == 0 ? 0 : 1);
                }
    TetMesh mesh = make_tet_mesh(std::move(positions), std::move(tets));
    mesh.piece_ids = pieces;
    mesh.piece_transforms.resize(2);
    mesh.piece_transforms[1].rotation =
        Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, -0.5).normalized()).toRotationMatrix();
    mesh.piece_transforms[1].translation = Eigen::Vector3d(0.1, -2.0 / 3.0, 1e-7);
    for (size_t t = 0; t < mesh.tet_count(); ++t) mesh.original_ids[t] = static_cast<int32_t>(1000 - 7 * t);
    if (with_materials) {
        std::uniform_real_distribution<double> coefficient(0.0, 3.0);
        mesh.materials.resize(mesh.tet_count());
        for (TetMaterial& material : mesh.materials) {
            for (int c = 0; c < 3; ++c) {
                material.mua[c] = coefficient(random) * 1e-3;
                material.musp[c] = coefficient(random);
            }
            material.eta = 1.0 + coefficient(random) / 10;
        }
    }
    validate(mesh);
    return mesh;
}

std::string read_text(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

void write_text(const fs::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
}

class VolumeFileTest : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        directory_ = fs::temp_directory_path() /
                     ("waxwork_volume_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
        fs::remove_all(directory_);
        fs::create_directories(directory_);
    }
    void TearDown() override { fs::remove_all(directory_); }

    fs::path path(const std::string& name) const { return directory_ / name; }
    size_t file_count() const {
        return static_cast<size_t>(std::distance(fs::directory_iterator(directory_), fs::directory_iterator()));
    }

    fs::path directory_;
};

void expect_same_geometry(const TetMesh& expected, const TetMesh& actual) {
    ASSERT_EQ(expected.positions.size(), actual.positions.size());
    ASSERT_EQ(expected.tets, actual.tets);
    // Bit-exact, not merely equal (== treats 0.0 and -0.0 alike).
    EXPECT_EQ(0, std::memcmp(expected.positions.data(), actual.positions.data(),
                             expected.positions.size() * sizeof(Eigen::Vector3d)));
    EXPECT_FALSE(actual.has_materials());
    EXPECT_EQ(actual.piece_transforms.size(), 1u);
    EXPECT_EQ(actual.piece_ids, std::vector<int32_t>(actual.tet_count(), 0));
}

// ---------------------------------------------------------------------------------------------
// Round trips.

// The one list of volume extensions the editor, `bench solvers` and sessions ask before reading or
// saving (they each kept their own, and one forgot .ele).
TEST(VolumePath, NamesExactlyTheFormatsReadVolumeReads) {
    for (const char* name : {"a.vtu", "b.MSH", "c.mesh", "d.node", "e.ele", "dir/f.Vtu"}) EXPECT_TRUE(is_volume_path(name)) << name;
    for (const char* name : {"a.obj", "b.stl", "c.vtk", "d", "e.vtu.bak", ".vtu"}) EXPECT_FALSE(is_volume_path(name)) << name;
}

TEST_F(VolumeFileTest, VtuRoundTripIsBitExact) {
    const TetMesh mesh = make_test_mesh();
    write_volume(mesh, path("volume.vtu"));
    const TetMesh loaded = read_volume(path("volume.vtu"));
    EXPECT_EQ(mesh, loaded);
    EXPECT_EQ(0, std::memcmp(mesh.positions.data(), loaded.positions.data(),
                             mesh.positions.size() * sizeof(Eigen::Vector3d)));
    EXPECT_EQ(0, std::memcmp(mesh.materials.data(), loaded.materials.data(),
                             mesh.materials.size() * sizeof(TetMaterial)));
    ASSERT_EQ(loaded.piece_transforms.size(), 2u);
    EXPECT_TRUE(loaded.piece_transforms[1] == mesh.piece_transforms[1]);
}

TEST_F(VolumeFileTest, VtuWithoutMaterialsStaysWithoutMaterials) {
    const TetMesh mesh = make_test_mesh(/*with_materials=*/false);
    write_volume(mesh, path("plain.VTU"));
    const TetMesh loaded = read_volume(path("plain.VTU"));
    EXPECT_FALSE(loaded.has_materials());
    EXPECT_EQ(mesh, loaded);
    EXPECT_EQ(read_text(path("plain.VTU")).find("Name=\"mua\""), std::string::npos);
}

TEST_F(VolumeFileTest, VtuIsAnUnstructuredGridOfTetra) {
    const TetMesh mesh = make_test_mesh();
    std::ostringstream out;
    format_vtu(mesh, out);
    const std::string text = out.str();
    EXPECT_NE(text.find("<VTKFile type=\"UnstructuredGrid\""), std::string::npos);
    EXPECT_NE(text.find("NumberOfCells=\"" + std::to_string(mesh.tet_count()) + "\""), std::string::npos);
    EXPECT_NE(text.find("NumberOfPoints=\"" + std::to_string(mesh.vertex_count()) + "\""), std::string::npos);
    for (const char* name : {"Points", "connectivity", "offsets", "types", "mua", "musp", "eta", "original_id",
                             "piece", "piece_transforms", "waxwork_format_version"})
        EXPECT_NE(text.find("Name=\"" + std::string(name) + "\""), std::string::npos) << name;
}

TEST_F(VolumeFileTest, VtuAsciiArraysAreRead) {
    // A minimal ascii .vtu as a third-party tool might write it: no waxwork version, one triangle
    // that is ignored, one inverted tet that is reoriented, one unused point that is dropped.
    const std::string text = R"(<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
  <UnstructuredGrid>
    <Piece NumberOfPoints="5" NumberOfCells="2">
      <Points><DataArray type="Float32" NumberOfComponents="3" format="ascii">
        0 0 0  1 0 0  0 1 0  0 0 1  7 7 7
      </DataArray></Points>
      <Cells>
        <DataArray type="Int32" Name="connectivity" format="ascii">0 1 2  0 2 1 3</DataArray>
        <DataArray type="Int32" Name="offsets" format="ascii">3 7</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">5 10</DataArray>
      </Cells>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
)";
    const TetMesh mesh = parse_vtu(text, "third_party.vtu");
    ASSERT_EQ(mesh.tet_count(), 1u);
    EXPECT_EQ(mesh.vertex_count(), 4u);
    EXPECT_GT(signed_volume(mesh, 0), 0.0);
}

TEST_F(VolumeFileTest, GmshRoundTripKeepsGeometryExactly) {
    const TetMesh mesh = make_test_mesh();
    write_volume(mesh, path("volume.msh"));
    expect_same_geometry(mesh, read_volume(path("volume.msh")));
}

TEST_F(VolumeFileTest, MeditRoundTripKeepsGeometryExactly) {
    const TetMesh mesh = make_test_mesh();
    write_volume(mesh, path("volume.mesh"));
    expect_same_geometry(mesh, read_volume(path("volume.mesh")));
}

TEST_F(VolumeFileTest, TetGenRoundTripKeepsGeometryExactly) {
    const TetMesh mesh = make_test_mesh();
    write_volume(mesh, path("volume.node"));
    EXPECT_TRUE(fs::exists(path("volume.ele")));
    expect_same_geometry(mesh, read_volume(path("volume.node")));
    expect_same_geometry(mesh, read_volume(path("volume.ele")));
}

// ---------------------------------------------------------------------------------------------
// Foreign files with features our writers do not produce.

TEST_F(VolumeFileTest, GmshSparseTagsOtherElementsAndSectionsAreHandled) {
    // Nodes 10, 20, 30, 40, 50 (+ 99, a geometry point used by no tet) in two blocks, one parametric;
    // a point element, triangles, and two tets of which the second is inverted.
    const std::string text = R"($MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
1
3 1 "wax"
$EndPhysicalNames
$Entities
1 0 0 1
1 0 0 0 0
1 0 0 0 1 1 1 0 0
$EndEntities
$Nodes
2 6 10 99
0 1 0 1
99
5 5 5
3 1 1 5
10
20
30
40
50
0 0 0 0.1 0.2 0.3
1 0 0 0.1 0.2 0.3
0 1 0 0.1 0.2 0.3
0 0 1 0.1 0.2 0.3
1 1 1 0.1 0.2 0.3
$EndNodes
$Elements
3 4 1 40
0 1 15 1
1 99
2 1 2 1
5 10 20 30
3 1 4 2
7 10 20 30 40
40 20 30 40 50
$EndElements
)";
    const TetMesh mesh = parse_gmsh(text, "sparse.msh");
    ASSERT_EQ(mesh.tet_count(), 2u);
    EXPECT_EQ(mesh.vertex_count(), 5u);
    for (size_t t = 0; t < mesh.tet_count(); ++t) EXPECT_GT(signed_volume(mesh, t), 0.0);
    EXPECT_EQ(mesh.positions[4], Eigen::Vector3d(1, 1, 1));
}

TEST_F(VolumeFileTest, MeditSkipsUnknownSectionsAndReorients) {
    const std::string text = R"(MeshVersionFormatted 1
# a comment
Dimension
3
Vertices
5
0 0 0 1
1 0 0 1
0 1 0 1
0 0 1 1
1e0 1.0E+0 +1 1
Triangles
1
1 2 3 7
Corners 2 1 2
Tetrahedra
2
1 3 2 4 0
2 3 4 5 0
End
)";
    const TetMesh mesh = parse_medit(text, "skip.mesh");
    ASSERT_EQ(mesh.tet_count(), 2u);
    for (size_t t = 0; t < mesh.tet_count(); ++t) EXPECT_GT(signed_volume(mesh, t), 0.0);
}

TEST_F(VolumeFileTest, TetGenOneBasedWithAttributesAndMarkers) {
    const std::string node = "# points\n4 3 2 1\n1 0 0 0 5 6 1\n2 1 0 0 5 6 1\n3 0 1 0 5 6 1\n4 0 0 1 5 6 1\n";
    const std::string ele = "1 4 1\n1 1 3 2 4 -2.5  # inverted, with a region\n";
    const TetMesh mesh = parse_tetgen(node, "a.node", ele, "a.ele");
    ASSERT_EQ(mesh.tet_count(), 1u);
    EXPECT_GT(signed_volume(mesh, 0), 0.0);
}

// ---------------------------------------------------------------------------------------------
// Broken files: a FileError that names the file and the problem.

template <class Function>
std::string error_of(Function&& function) {
    try {
        function();
    } catch (const FileError& error) {
        return error.what();
    }
    ADD_FAILURE() << "no FileError";
    return {};
}

// A volume every reader accepts is one the renderer can draw: coordinates beyond float's range (or
// beyond what float can multiply) are refused naming the file, and nothing of the kind is written.
TEST_F(VolumeFileTest, CoordinatesBeyondTheRenderersRangeAreRefused) {
    const TetMesh far = make_tet_mesh({{0, 0, 0}, {3.5e38, 0, 0}, {0, 3.5e38, 0}, {0, 0, 3.5e38}}, {{0, 1, 2, 3}});
    for (const std::string name : {"far.vtu", "far.msh", "far.mesh", "far.node"})
        EXPECT_THROW(write_volume(far, path(name)), InvalidMeshError) << name;
    EXPECT_EQ(file_count(), 0u);
    std::ostringstream node, ele, medit;
    node.precision(17);
    medit.precision(17);
    node << far.vertex_count() << " 3 0 0\n";
    medit << "MeshVersionFormatted 2\nDimension 3\nVertices\n" << far.vertex_count() << "\n";
    for (size_t v = 0; v < far.vertex_count(); ++v) {
        const Eigen::Vector3d& p = far.positions[v];
        node << v << " " << p.x() << " " << p.y() << " " << p.z() << "\n";
        medit << p.x() << " " << p.y() << " " << p.z() << " 0\n";
    }
    ele << far.tet_count() << " 4 0\n";
    medit << "Tetrahedra\n" << far.tet_count() << "\n";
    for (size_t t = 0; t < far.tet_count(); ++t) {
        const auto& tet = far.tets[t];
        ele << t << " " << tet[0] << " " << tet[1] << " " << tet[2] << " " << tet[3] << "\n";
        medit << tet[0] + 1 << " " << tet[1] + 1 << " " << tet[2] + 1 << " " << tet[3] + 1 << " 0\n";
    }
    medit << "End\n";
    write_text(path("far.node"), node.str());
    write_text(path("far.ele"), ele.str());
    write_text(path("far.mesh"), medit.str());
    for (const std::string name : {"far.node", "far.mesh"}) {
        const std::string e = error_of([&] { read_volume(path(name)); });
        EXPECT_NE(e.find("lies beyond 1e12"), std::string::npos) << name << ": " << e;
    }
}

TEST_F(VolumeFileTest, ErrorsNameTheFileAndTheProblem) {
    const std::string gmsh = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n"
                             "0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n$Elements\n1 1 17 17\n3 1 4 1\n"
                             "17 1 2 3 99999\n$EndElements\n";
    const std::string message = error_of([&] { parse_gmsh(gmsh, "x.msh"); });
    EXPECT_NE(message.find("x.msh: "), std::string::npos) << message;
    EXPECT_NE(message.find("tet 17 references node 99999 which does not exist"), std::string::npos) << message;

    EXPECT_NE(error_of([] { parse_gmsh("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n", "old.msh"); })
                  .find("unsupported Gmsh format version 2.2"),
              std::string::npos);
    EXPECT_NE(error_of([] {
                  parse_medit("MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\nnan 1 0 0\n"
                              "0 0 1 0\nTetrahedra\n1\n1 2 3 4 0\nEnd\n",
                              "nan.mesh");
              }).find("not finite"),
              std::string::npos);

    std::ostringstream vtu;
    format_vtu(make_test_mesh(), vtu);
    std::string future = vtu.str();
    // Version 1 is base64 "AQAAAA==" after the 8-byte header; version 2 is "AgAAAA==".
    const size_t at = future.find("BAAAAAAAAAABAAAA");
    ASSERT_NE(at, std::string::npos);
    future.replace(at, 16, "BAAAAAAAAAACAAAA");
    EXPECT_NE(error_of([&] { parse_vtu(future, "future.vtu"); }).find("unsupported waxwork_format_version 2"),
              std::string::npos);

    EXPECT_NE(error_of([&] { read_volume(path("missing.vtu")); }).find("missing.vtu"), std::string::npos);
}

// The same third-party file with other cells: volume cells that are not linear tetrahedra, and a
// tetrahedron whose offsets give it the wrong number of points, are refused by name instead of
// dropping part of the volume.
TEST_F(VolumeFileTest, VtuVolumeCellsThatAreNotTetrahedraAreRefused) {
    const auto with_cells = [](const std::string& connectivity, const std::string& offsets, const std::string& types) {
        return std::string(R"(<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
  <UnstructuredGrid>
    <Piece NumberOfPoints="8" NumberOfCells="2">
      <Points><DataArray type="Float32" NumberOfComponents="3" format="ascii">
        0 0 0  1 0 0  1 1 0  0 1 0  0 0 1  1 0 1  1 1 1  0 1 1
      </DataArray></Points>
      <Cells>
        <DataArray type="Int32" Name="connectivity" format="ascii">)") + connectivity + R"(</DataArray>
        <DataArray type="Int32" Name="offsets" format="ascii">)" + offsets + R"(</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">)" + types + R"(</DataArray>
      </Cells>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
)";
    };
    EXPECT_EQ(parse_vtu(with_cells("0 1 3 4  0 1 2", "4 7", "10 5"), "tet.vtu").tet_count(), 1u);
    const std::string hexahedron =
        error_of([&] { parse_vtu(with_cells("0 1 3 4  0 1 2 3 4 5 6 7", "4 12", "10 12"), "hex.vtu"); });
    EXPECT_NE(hexahedron.find("hex.vtu: cell 1 is not a tetrahedron (VTK type 12)"), std::string::npos) << hexahedron;
    EXPECT_NE(hexahedron.find("tetrahedra only"), std::string::npos) << hexahedron;
    const std::string five_points =
        error_of([&] { parse_vtu(with_cells("0 1 3 4 5  0 1 2", "5 8", "10 5"), "offsets.vtu"); });
    EXPECT_NE(five_points.find("cell 0 is a tetrahedron (VTK type 10) with 5 points"), std::string::npos)
        << five_points;
}

// A Waxwork file with a DataArray given twice is ambiguous; one whose version array was lost is a
// damaged Waxwork file, not another program's geometry (which would silently drop its materials).
TEST_F(VolumeFileTest, VtuDuplicateArraysAndALostVersionAreRefused) {
    TetMesh mesh = make_test_mesh();
    mesh.materials.assign(mesh.tet_count(), TetMaterial{{0.1, 0.1, 0.1}, {1, 1, 1}, 1.3});
    std::ostringstream out;
    format_vtu(mesh, out);
    const std::string text = out.str();
    ASSERT_EQ(parse_vtu(text, "ok.vtu").materials, mesh.materials);

    std::string twice = text;
    const size_t begin = twice.find("<DataArray type=\"Float64\" Name=\"eta\"");
    ASSERT_NE(begin, std::string::npos);
    const size_t end = twice.find("</DataArray>", begin) + std::string("</DataArray>").size();
    twice.insert(end, twice.substr(begin, end - begin));
    const std::string duplicate = error_of([&] { parse_vtu(twice, "twice.vtu"); });
    EXPECT_NE(duplicate.find("twice.vtu: CellData has two DataArrays named 'eta'"), std::string::npos) << duplicate;

    std::string unversioned = text;
    const size_t name = unversioned.find("Name=\"waxwork_format_version\"");
    ASSERT_NE(name, std::string::npos);
    unversioned.replace(name, std::string("Name=\"waxwork_format_version\"").size(), "Name=\"something_else\"");
    const std::string lost = error_of([&] { parse_vtu(unversioned, "lost.vtu"); });
    EXPECT_NE(lost.find("lost.vtu: has Waxwork's CellData"), std::string::npos) << lost;
    EXPECT_NE(lost.find("waxwork_format_version"), std::string::npos) << lost;
}

// MEDIT files with hexahedra, prisms or pyramids are refused (their part of the volume would be lost);
// an empty section of them is harmless.
TEST_F(VolumeFileTest, MeditVolumeElementsOtherThanTetrahedraAreRefused) {
    const std::string head = "MeshVersionFormatted 1\nDimension 3\nVertices\n5\n0 0 0 1\n1 0 0 1\n0 1 0 1\n"
                             "0 0 1 1\n1 1 1 1\nTetrahedra\n1\n1 2 3 4 0\n";
    EXPECT_EQ(parse_medit(head + "Hexahedra\n0\nEnd\n", "empty.mesh").tet_count(), 1u);
    for (const std::string section : {"Hexahedra\n1\n1 2 3 4 5 1 2 3 0\n", "Prisms\n1\n1 2 3 4 5 1 0\n",
                                      "Pyramids\n1\n1 2 3 4 5 0\n"}) {
        const std::string message = error_of([&] { parse_medit(head + section + "End\n", "mixed.mesh"); });
        EXPECT_NE(message.find("mixed.mesh"), std::string::npos) << message;
        EXPECT_NE(message.find("contains 1 " + section.substr(0, section.find('\n'))), std::string::npos) << message;
        EXPECT_NE(message.find("tetrahedra only"), std::string::npos) << message;
    }
}

TEST_F(VolumeFileTest, VtuTruncatedBase64IsReported) {
    std::ostringstream out;
    format_vtu(make_test_mesh(), out);
    std::string text = out.str();
    // Drop 40 characters (a multiple of 4) from the middle of the connectivity data.
    const size_t name = text.find("Name=\"connectivity\"");
    const size_t data = text.find('>', name) + 20;
    text.erase(data, 40);
    const std::string message = error_of([&] { parse_vtu(text, "spot.vtu"); });
    EXPECT_NE(message.find("spot.vtu: truncated base64 data in DataArray 'connectivity'"), std::string::npos)
        << message;
}

TEST_F(VolumeFileTest, VtuInconsistentFilesAreRejected) {
    const TetMesh mesh = make_test_mesh();
    TetMesh inverted = mesh;
    std::swap(inverted.tets[3][0], inverted.tets[3][1]);
    std::ostringstream out;
    format_vtu(inverted, out);
    EXPECT_NE(error_of([&] { parse_vtu(out.str(), "inverted.vtu"); }).find("not positively oriented"),
              std::string::npos);

    TetMesh bad_piece = mesh;
    bad_piece.piece_ids[0] = 5;
    std::ostringstream out2;
    format_vtu(bad_piece, out2);
    EXPECT_THROW(parse_vtu(out2.str(), "piece.vtu"), FileError);

    std::ostringstream out3;
    format_vtu(mesh, out3);
    std::string wrong_count = out3.str();
    const std::string cells = "NumberOfCells=\"" + std::to_string(mesh.tet_count()) + "\"";
    wrong_count.replace(wrong_count.find(cells), cells.size(), "NumberOfCells=\"47\"");
    EXPECT_THROW(parse_vtu(wrong_count, "count.vtu"), FileError);
}

// The scale is stored in every format, read back bit for bit, and other tools' files (no scale) and
// files saved without one read as having none.
TEST_F(VolumeFileTest, EveryFormatStoresTheScale) {
    const TetMesh mesh = make_test_mesh();
    for (const double scale : {30.0, 0.1 + 0.2, kMinMmPerUnit, kMaxMmPerUnit}) {
        for (const char* name : {"s.vtu", "s.msh", "s.mesh", "s.node"}) {
            write_volume(mesh, path(name), VolumeMetadata{scale});
            const VolumeFile file = read_volume_file(path(name));
            ASSERT_TRUE(file.metadata.mm_per_unit) << name;
            EXPECT_EQ(std::memcmp(&*file.metadata.mm_per_unit, &scale, sizeof scale), 0) << name << " " << scale;
            EXPECT_EQ(file.mesh.positions, mesh.positions) << name;
            write_volume(mesh, path(name));
            EXPECT_FALSE(read_volume_file(path(name)).metadata.mm_per_unit) << name;
        }
    }
    // The foreign readers still read the files: the scale is a comment or a section they skip.
    write_volume(mesh, path("t.msh"), VolumeMetadata{30});
    EXPECT_NE(read_text(path("t.msh")).find("$Comments\nwaxwork mm_per_unit 30\n$EndComments"), std::string::npos);
    write_volume(mesh, path("t.mesh"), VolumeMetadata{30});
    EXPECT_EQ(read_text(path("t.mesh")).rfind("MeshVersionFormatted 2\n# waxwork mm_per_unit 30\n", 0), 0u);
}

TEST_F(VolumeFileTest, AStoredScaleOutOfRangeIsRefusedNamingTheFile) {
    const TetMesh mesh = make_test_mesh();
    EXPECT_THROW(write_volume(mesh, path("bad.vtu"), VolumeMetadata{0.0}), FileError);
    EXPECT_FALSE(fs::exists(path("bad.vtu")));
    std::ostringstream vtu;
    format_vtu(mesh, vtu, VolumeMetadata{-1.0});
    write_text(path("neg.vtu"), vtu.str());
    std::ostringstream medit;
    format_medit(mesh, medit, VolumeMetadata{1e300});
    write_text(path("huge.mesh"), medit.str());
    std::string nan_text = medit.str();
    nan_text.replace(nan_text.find("1e+300"), 6, "nan");
    write_text(path("nan.mesh"), nan_text);
    std::string word = medit.str();
    word.replace(word.find("1e+300"), 6, "thirty");
    write_text(path("word.mesh"), word);
    for (const auto& [name, problem] : std::vector<std::pair<std::string, std::string>>{
             {"neg.vtu", "stored mm_per_unit must be a length in mm per model unit between 1e-6 and 1e6 (got -1)"},
             {"huge.mesh", "stored mm_per_unit must be a length in mm per model unit"},
             {"nan.mesh", "stored mm_per_unit must be a length"},
             {"word.mesh", "stored mm_per_unit 'thirty' is not a number"}}) {
        const std::string e = error_of([&] { read_volume(path(name)); });
        EXPECT_NE(e.find(path(name).string() + ": " + problem), std::string::npos) << e;
    }
}

TEST_F(VolumeFileTest, UnknownExtensionIsAFileError) {
    const std::string message = error_of([&] { read_volume(path("volume.obj")); });
    EXPECT_NE(message.find("volume.obj"), std::string::npos);
    EXPECT_NE(message.find("unknown volume file extension"), std::string::npos);
    EXPECT_THROW(write_volume(make_test_mesh(), path("volume.stl")), FileError);
    EXPECT_THROW(write_volume(make_test_mesh(), path("no_extension")), FileError);
}

// ---------------------------------------------------------------------------------------------
// Fuzzing: truncation and garbage never crash and never slip through.

struct Format {
    std::string name;
    std::function<std::string(const TetMesh&)> format;
    std::function<TetMesh(const std::string&)> parse;
};

std::vector<Format> all_formats() {
    auto text_of = [](void (*writer)(const TetMesh&, std::ostream&)) {
        return [writer](const TetMesh& mesh) {
            std::ostringstream out;
            writer(mesh, out);
            return out.str();
        };
    };
    std::ostringstream node;
    format_tetgen_node(make_test_mesh(), node);
    std::ostringstream ele;
    format_tetgen_ele(make_test_mesh(), ele);
    const std::string valid_node = node.str();
    const std::string valid_ele = ele.str();
    return {
        {"vtu", text_of([](const TetMesh& m, std::ostream& out) { format_vtu(m, out); }), [](const std::string& s) { return parse_vtu(s, "fuzz.vtu"); }},
        {"gmsh", text_of([](const TetMesh& m, std::ostream& out) { format_gmsh(m, out); }), [](const std::string& s) { return parse_gmsh(s, "fuzz.msh"); }},
        {"medit", text_of([](const TetMesh& m, std::ostream& out) { format_medit(m, out); }), [](const std::string& s) { return parse_medit(s, "fuzz.mesh"); }},
        {"tetgen_node", text_of([](const TetMesh& m, std::ostream& out) { format_tetgen_node(m, out); }),
         [valid_ele](const std::string& s) { return parse_tetgen(s, "fuzz.node", valid_ele, "fuzz.ele"); }},
        {"tetgen_ele", text_of(format_tetgen_ele),
         [valid_node](const std::string& s) { return parse_tetgen(valid_node, "fuzz.node", s, "fuzz.ele"); }},
    };
}

TEST_F(VolumeFileTest, TruncatedFilesAreRejectedByEveryReader) {
    const TetMesh mesh = make_test_mesh();
    for (const Format& format : all_formats()) {
        const std::string valid = format.format(mesh);
        ASSERT_NO_THROW(format.parse(valid)) << format.name;
        // Every cut that removes more than the final newline; at most ~1500 cuts per format.
        const size_t step = std::max<size_t>(1, valid.size() / 1500);
        for (size_t length = 0; length + 1 < valid.size(); length += step) {
            EXPECT_THROW(format.parse(valid.substr(0, length)), FileError)
                << format.name << " cut at " << length << " of " << valid.size();
        }
    }
}

TEST_F(VolumeFileTest, GarbageIsRejectedByEveryReader) {
    std::mt19937 random(2024);
    for (const Format& format : all_formats()) {
        for (int trial = 0; trial < 200; ++trial) {
            std::string garbage(random() % 2000, '\0');
            for (char& c : garbage) c = static_cast<char>(random());
            EXPECT_THROW(format.parse(garbage), FileError) << format.name << " trial " << trial;
        }
    }
}

// Mutated files of every format: volume_fuzz_test.cpp.

// ---------------------------------------------------------------------------------------------
// Atomic saves.

TEST_F(VolumeFileTest, AtomicWriteReplacesTheFile) {
    write_text(path("data.txt"), "old content");
    ::chmod(path("data.txt").c_str(), 0640);
    write_file_atomically(path("data.txt"), [](std::ostream& out) { out << "new content"; });
    EXPECT_EQ(read_text(path("data.txt")), "new content");
    struct stat status {};
    ASSERT_EQ(::stat(path("data.txt").c_str(), &status), 0);
    EXPECT_EQ(status.st_mode & 0777, 0640u);
    EXPECT_EQ(file_count(), 1u);
}

TEST_F(VolumeFileTest, AtomicWriteThatThrowsLeavesTheOldFile) {
    write_text(path("data.txt"), "old content");
    auto failing = [](std::ostream& out) {
        out << std::string(3 << 20, 'x');  // larger than the buffer: some of it reaches the disk
        throw std::runtime_error("writer failed midway");
    };
    EXPECT_THROW(write_file_atomically(path("data.txt"), failing), std::runtime_error);
    EXPECT_EQ(read_text(path("data.txt")), "old content");
    EXPECT_EQ(file_count(), 1u) << "the temporary file was not removed";
}

TEST_F(VolumeFileTest, AtomicWriteOfSeveralFilesIsAllOrNothingOnWriterFailure) {
    write_text(path("v.node"), "old node");
    write_text(path("v.ele"), "old ele");
    EXPECT_THROW(write_files_atomically({
                     FileWriter{path("v.node"), [](std::ostream& out) { out << "new node"; }},
                     FileWriter{path("v.ele"), [](std::ostream&) { throw std::runtime_error("no"); }},
                 }),
                 std::runtime_error);
    EXPECT_EQ(read_text(path("v.node")), "old node");
    EXPECT_EQ(read_text(path("v.ele")), "old ele");
    EXPECT_EQ(file_count(), 2u);
}

// A .node/.ele pair whose .ele is a directory: refused before the .node is replaced.
TEST_F(VolumeFileTest, AtomicWriteOfSeveralFilesChecksEveryTargetBeforeReplacingAny) {
    write_volume(make_test_mesh(), path("v.node"));
    const std::string node_before = read_text(path("v.node"));
    fs::remove(path("v.ele"));
    fs::create_directory(path("v.ele"));
    const std::string message = error_of([&] { write_volume(make_test_mesh(), path("v.node")); });
    EXPECT_NE(message.find("v.ele"), std::string::npos) << message;
    EXPECT_NE(message.find("directory"), std::string::npos) << message;
    EXPECT_EQ(read_text(path("v.node")), node_before);
    EXPECT_EQ(file_count(), 2u) << "a temporary file was left";
}

// Sets or clears the immutable flag (chattr +i): a file even root cannot replace. False where the
// file system or the process's privileges do not allow it.
bool set_immutable(const fs::path& file, bool immutable) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return false;
    int flags = 0;
    bool ok = ::ioctl(fd, FS_IOC_GETFLAGS, &flags) == 0;
    if (ok) {
        flags = immutable ? (flags | FS_IMMUTABLE_FL) : (flags & ~FS_IMMUTABLE_FL);
        ok = ::ioctl(fd, FS_IOC_SETFLAGS, &flags) == 0;
    }
    ::close(fd);
    return ok;
}

// The .ele of a pair cannot be replaced after the .node was: the .node is put back, so the pair on
// disk is still the old, consistent one, and the error names the .ele.
TEST_F(VolumeFileTest, APairWhoseSecondFileCannotBeReplacedKeepsTheOldPair) {
    const TetMesh old_mesh = make_test_mesh();
    write_volume(old_mesh, path("v.node"));
    const std::string node_before = read_text(path("v.node"));
    if (!set_immutable(path("v.ele"), true)) GTEST_SKIP() << "cannot make a file immutable here (needs root on ext4)";
    TetMesh new_mesh = old_mesh;
    for (Eigen::Vector3d& p : new_mesh.positions) p *= 2;
    const std::string message = error_of([&] { write_volume(new_mesh, path("v.node")); });
    ASSERT_TRUE(set_immutable(path("v.ele"), false));
    EXPECT_NE(message.find("v.ele"), std::string::npos) << message;
    EXPECT_EQ(read_text(path("v.node")), node_before);
    EXPECT_EQ(read_volume(path("v.node")).positions, old_mesh.positions);
    EXPECT_EQ(file_count(), 2u) << "a temporary or a backup was left";
    write_volume(new_mesh, path("v.node"));  // and once the .ele can be replaced, both are
    EXPECT_EQ(read_volume(path("v.node")).positions, new_mesh.positions);
    EXPECT_EQ(file_count(), 2u);
}

// Hidden temporaries and backups of a target left by a process that was killed during a save are
// removed by the next save to that target; a live process's are not, nor other files' ones.
TEST_F(VolumeFileTest, ASaveRemovesTheTemporariesOfKilledSaves) {
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) ::_exit(0);
    ASSERT_EQ(::waitpid(child, nullptr, 0), child);
    const std::string dead = std::to_string(child), live = std::to_string(::getppid());
    write_text(path(".v.vtu.tmp-" + dead + "-0-1"), "half a volume");
    write_text(path(".v.vtu.bak-" + dead + "-2-3"), "an old volume");
    write_text(path(".v.vtu.tmp-" + live + "-0-1"), "another process's save in progress");
    write_text(path(".w.vtu.tmp-" + dead + "-0-1"), "another file's leftover");
    write_volume(make_test_mesh(), path("v.vtu"));
    EXPECT_FALSE(fs::exists(path(".v.vtu.tmp-" + dead + "-0-1")));
    EXPECT_FALSE(fs::exists(path(".v.vtu.bak-" + dead + "-2-3")));
    EXPECT_TRUE(fs::exists(path(".v.vtu.tmp-" + live + "-0-1")));
    EXPECT_TRUE(fs::exists(path(".w.vtu.tmp-" + dead + "-0-1")));
    EXPECT_EQ(file_count(), 3u);
}

// A pipe (or a device) is refused by name instead of blocking the reader.
TEST_F(VolumeFileTest, APipeIsNotReadAsAVolume) {
    ASSERT_EQ(::mkfifo(path("pipe.vtu").c_str(), 0600), 0);
    const std::string message = error_of([&] { read_volume(path("pipe.vtu")); });
    EXPECT_NE(message.find("pipe.vtu"), std::string::npos) << message;
    EXPECT_NE(message.find("not a regular file"), std::string::npos) << message;
}

TEST_F(VolumeFileTest, AtomicWriteIntoMissingDirectoryIsAFileError) {
    const fs::path target = path("no/such/dir/volume.vtu");
    const std::string message = error_of([&] { write_volume(make_test_mesh(), target); });
    EXPECT_NE(message.find(target.string()), std::string::npos) << message;
}

TEST_F(VolumeFileTest, AtomicWriteOverADirectoryFailsCleanly) {
    fs::create_directory(path("volume.vtu"));
    EXPECT_THROW(write_volume(make_test_mesh(), path("volume.vtu")), FileError);
    EXPECT_TRUE(fs::is_directory(path("volume.vtu")));
    EXPECT_EQ(file_count(), 1u);
}

TEST_F(VolumeFileTest, SavingAnInvalidMeshKeepsTheOldFile) {
    const TetMesh mesh = make_test_mesh();
    write_volume(mesh, path("volume.vtu"));
    const std::string before = read_text(path("volume.vtu"));
    TetMesh broken = mesh;
    broken.tets[0][0] = 12345;
    EXPECT_THROW(write_volume(broken, path("volume.vtu")), InvalidMeshError);
    EXPECT_EQ(read_text(path("volume.vtu")), before);
    EXPECT_EQ(file_count(), 1u);
}

}  // namespace
}  // namespace waxwork
