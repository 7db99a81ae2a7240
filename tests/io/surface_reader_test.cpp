#include "io/surface_reader.h"

#include "base/error.h"

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <string>

namespace waxwork {
namespace {

namespace fs = std::filesystem;

const fs::path shared_meshes = fs::path(WAXWORK_SHARED_DIR) / "data" / "meshes";
const fs::path asset_meshes = fs::path(WAXWORK_ASSET_DIR) / "meshes";

#define SKIP_WITHOUT_SHARED()                                                     \
    if (!fs::exists(shared_meshes)) GTEST_SKIP() << shared_meshes << " is absent"

// A fresh directory per test, removed afterwards.
class SurfaceReaderFiles : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("waxwork_surface_" + std::string(info->name()) + "_" + std::to_string(std::random_device{}()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    fs::path file(const std::string& name) const { return dir_ / name; }
    fs::path write_text(const std::string& name, const std::string& text) const {
        std::ofstream(file(name), std::ios::binary) << text;
        return file(name);
    }
    fs::path truncated_copy(const fs::path& source, const std::string& name, double fraction) const {
        std::ifstream in(source, std::ios::binary);
        std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        bytes.resize(static_cast<size_t>(bytes.size() * fraction));
        return write_text(name, bytes);
    }

    fs::path dir_;
};

// The unit cube as an OpenMesh mesh, written with OpenMesh's writers so the readers get real files.
OpenMesh::TriMesh_ArrayKernelT<> make_openmesh_cube() {
    OpenMesh::TriMesh_ArrayKernelT<> mesh;
    std::vector<OpenMesh::VertexHandle> v;
    for (int k = 0; k < 8; ++k) v.push_back(mesh.add_vertex({float(k & 1), float((k >> 1) & 1), float((k >> 2) & 1)}));
    const int faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                              {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    for (const auto& f : faces) mesh.add_face(v[f[0]], v[f[1]], v[f[2]]);
    return mesh;
}

// The cube as OBJ text; inward flips every triangle, split gives every triangle its own vertices.
std::string cube_obj(bool inward = false, bool split = false) {
    const int faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                              {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    auto vertex = [](int k) {
        return "v " + std::to_string(k & 1) + " " + std::to_string((k >> 1) & 1) + " " + std::to_string((k >> 2) & 1) + "\n";
    };
    std::string text;
    if (!split)
        for (int k = 0; k < 8; ++k) text += vertex(k);
    int next = 1;
    for (const auto& f : faces) {
        int a = f[0], b = inward ? f[2] : f[1], c = inward ? f[1] : f[2];
        if (split) {
            text += vertex(a) + vertex(b) + vertex(c);
            text += "f " + std::to_string(next) + " " + std::to_string(next + 1) + " " + std::to_string(next + 2) + "\n";
            next += 3;
        } else {
            text += "f " + std::to_string(a + 1) + " " + std::to_string(b + 1) + " " + std::to_string(c + 1) + "\n";
        }
    }
    return text;
}

void expect_file_error(const fs::path& path, const std::string& fragment) {
    try {
        read_surface_file(path);
        ADD_FAILURE() << path << " was read without error";
    } catch (const FileError& e) {
        EXPECT_EQ(e.path(), path.string());
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

std::string load_error(const fs::path& path, const SurfaceRepairOptions& options = {}) {
    try {
        load_closed_surface(path, options);
    } catch (const InvalidMeshError& e) {
        return e.what();
    }
    ADD_FAILURE() << path << " loaded without an InvalidMeshError";
    return {};
}

// ---- the real broken inputs ------------------------------------------------------------------------

TEST(SurfaceReaderShared, BadCowIsPinchedAndSelfIntersecting) {
    SKIP_WITHOUT_SHARED();
    const fs::path path = shared_meshes / "bad_cow.obj";
    const std::string message = load_error(path);
    EXPECT_EQ(message.rfind(path.string() + ": ", 0), 0u) << message;  // starts with the file name
    EXPECT_NE(message.find("non-manifold vertex"), std::string::npos) << message;
    EXPECT_NE(message.find("81 self-intersecting triangle pairs"), std::string::npos) << message;
    // Most important first: topology before intersections.
    EXPECT_LT(message.find("non-manifold"), message.find("self-intersecting")) << message;
    // The way out, last.
    EXPECT_TRUE(message.ends_with("; --repair wrap rebuilds it as a closed surface")) << message;
}

TEST(SurfaceReaderShared, BadBunnyIsOpenWithUnreferencedVertices) {
    SKIP_WITHOUT_SHARED();
    const std::string message = load_error(shared_meshes / "bad_stanford-bunny.obj");
    EXPECT_NE(message.find("223 boundary edges"), std::string::npos) << message;
    EXPECT_NE(message.find("removed 1113 unreferenced vertices"), std::string::npos) << message;
    EXPECT_TRUE(message.ends_with("; --repair wrap rebuilds it as a closed surface")) << message;
}

TEST(SurfaceReaderShared, BadBunnyHolesCanBeFilledOnRequest) {
    SKIP_WITHOUT_SHARED();
    const LoadedSurface loaded =
        load_closed_surface(shared_meshes / "bad_stanford-bunny.obj", {.fill_holes = true, .autorefine = false});
    EXPECT_TRUE(find_surface_defects(loaded.surface).is_clean());
    bool filled = false;
    for (const auto& r : loaded.repairs) filled |= r.find("filled") != std::string::npos;
    EXPECT_TRUE(filled);
}

// With the wrap asked for, the file's triangles go to the wrap before any check (the pinched vertex and
// the intersections never reach the validation) and the wrap passes the validation untouched.
TEST(SurfaceReaderShared, BadCowIsWrappedInsteadOfRefused) {
    SKIP_WITHOUT_SHARED();
    SurfaceRepairOptions options;
    options.wrap = WrapOptions{};
    const LoadedSurface loaded = load_closed_surface(shared_meshes / "bad_cow.obj", options);
    EXPECT_TRUE(find_surface_defects(loaded.surface).is_clean());
    ASSERT_TRUE(loaded.wrap.has_value());
    ASSERT_EQ(loaded.repairs.size(), 1u);  // the wrap alone: no safe repair was needed after it
    EXPECT_EQ(loaded.repairs[0], loaded.wrap->describe());
    EXPECT_EQ(loaded.wrap->triangles, loaded.surface.triangles.size());
}

TEST(SurfaceReaderShared, HorseSelfIntersects) {
    SKIP_WITHOUT_SHARED();
    const std::string message = load_error(shared_meshes / "horse.ply");
    EXPECT_NE(message.find("4 self-intersecting triangle pairs"), std::string::npos) << message;
    EXPECT_TRUE(message.ends_with("; --repair wrap rebuilds it as a closed surface")) << message;
}

TEST(SurfaceReaderShared, HorseRawSoupMatchesTheFile) {
    SKIP_WITHOUT_SHARED();
    const TriangleSurface horse = read_surface_file(shared_meshes / "horse.ply");  // binary PLY
    EXPECT_EQ(horse.points.size(), 48485u);
    EXPECT_EQ(horse.triangles.size(), 96966u);
}

TEST(SurfaceReaderShared, BadCowKeepsItsPinchedVertexInTheSoup) {
    SKIP_WITHOUT_SHARED();
    // OpenMesh would duplicate the pinched vertex; the soup must keep the file's vertices only.
    const TriangleSurface cow = read_surface_file(shared_meshes / "bad_cow.obj");
    EXPECT_EQ(cow.points.size(), 2903u);
    EXPECT_EQ(cow.triangles.size(), 5804u);
    EXPECT_EQ(find_surface_defects(cow).non_manifold_vertices, 1u);
}

TEST(SurfaceReaderShared, CleanMeshesLoad) {
    SKIP_WITHOUT_SHARED();
    for (const char* name : {"cube.obj", "spot.obj", "bunny.off", "torus.obj", "fandisk.obj", "armadillo.obj", "skull.obj"}) {
        SCOPED_TRACE(name);
        const fs::path path = shared_meshes / name;
        const TriangleSurface raw = read_surface_file(path);
        LoadedSurface loaded;
        EXPECT_NO_THROW(loaded = load_closed_surface(path));
        EXPECT_TRUE(loaded.repairs.empty()) << loaded.repairs.front();
        EXPECT_EQ(loaded.surface.triangles.size(), raw.triangles.size());
        EXPECT_GT(find_surface_defects(loaded.surface).signed_volume, 0.0);
    }
}

TEST(SurfaceReader, AssetMeshesLoad) {
    for (const char* name : {"cube.obj", "spot.obj", "torus.obj", "skull.obj"}) {
        SCOPED_TRACE(name);
        EXPECT_NO_THROW(load_closed_surface(asset_meshes / name));
    }
}

// ---- formats -----------------------------------------------------------------------------------------

TEST_F(SurfaceReaderFiles, RoundTripThroughEveryFormat) {
    const auto cube = make_openmesh_cube();
    struct Case {
        std::string name;
        OpenMesh::IO::Options options;
    };
    const Case cases[] = {{"cube.obj", {}},
                          {"cube.off", {}},
                          {"cube_ascii.ply", {}},
                          {"cube_binary.ply", OpenMesh::IO::Options::Binary},
                          {"cube_ascii.stl", {}},
                          {"cube_binary.stl", OpenMesh::IO::Options::Binary}};
    for (const auto& c : cases) {
        SCOPED_TRACE(c.name);
        const fs::path path = file(c.name);
        ASSERT_TRUE(OpenMesh::IO::write_mesh(cube, path.string(), c.options));
        const TriangleSurface raw = read_surface_file(path);
        EXPECT_EQ(raw.triangles.size(), 12u);
        const LoadedSurface loaded = load_closed_surface(path);
        EXPECT_EQ(loaded.surface.points.size(), 8u);
        EXPECT_EQ(loaded.surface.triangles.size(), 12u);
        const SurfaceDefects d = find_surface_defects(loaded.surface);
        EXPECT_TRUE(d.is_clean());
        EXPECT_NEAR(d.signed_volume, 1.0, 1e-6);
        // Every corner of the cube came back.
        for (int k = 0; k < 8; ++k) {
            const Eigen::Vector3d corner(k & 1, (k >> 1) & 1, (k >> 2) & 1);
            EXPECT_TRUE(std::any_of(loaded.surface.points.begin(), loaded.surface.points.end(),
                                    [&](const Eigen::Vector3d& p) { return (p - corner).norm() < 1e-6; }));
        }
    }
    // The binary files really are binary.
    EXPECT_EQ(fs::file_size(file("cube_binary.stl")), 84u + 50u * 12u);
    std::ifstream ply(file("cube_binary.ply"), std::ios::binary);
    std::string header((std::istreambuf_iterator<char>(ply)), std::istreambuf_iterator<char>());
    EXPECT_NE(header.find("format binary"), std::string::npos);
}

TEST_F(SurfaceReaderFiles, UpperCaseExtensionIsAccepted) {
    const fs::path path = write_text("CUBE.OBJ", cube_obj());
    EXPECT_EQ(read_surface_file(path).triangles.size(), 12u);
}

TEST_F(SurfaceReaderFiles, QuadsAreSplitIntoTriangles) {
    const fs::path path = write_text("quads.obj",
                                     "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
                                     "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n");
    const LoadedSurface loaded = load_closed_surface(path);
    EXPECT_EQ(loaded.surface.triangles.size(), 12u);
    EXPECT_NEAR(find_surface_defects(loaded.surface).signed_volume, 1.0, 1e-12);
}

// ---- repairs -----------------------------------------------------------------------------------------

TEST_F(SurfaceReaderFiles, InwardCubeIsReorientedAndReported) {
    const LoadedSurface loaded = load_closed_surface(write_text("inward.obj", cube_obj(true)));
    ASSERT_EQ(loaded.repairs.size(), 1u);
    EXPECT_NE(loaded.repairs[0].find("flipped all 12 triangles to face outward"), std::string::npos) << loaded.repairs[0];
    EXPECT_NEAR(find_surface_defects(loaded.surface).signed_volume, 1.0, 1e-12);
}

TEST_F(SurfaceReaderFiles, DuplicateVerticesAreMergedAndReported) {
    const fs::path path = write_text("split.obj", cube_obj(false, true));
    EXPECT_EQ(read_surface_file(path).points.size(), 36u);  // the raw soup keeps them
    const LoadedSurface loaded = load_closed_surface(path);
    EXPECT_EQ(loaded.surface.points.size(), 8u);
    ASSERT_EQ(loaded.repairs.size(), 1u);
    EXPECT_NE(loaded.repairs[0].find("merged 28 duplicate vertices"), std::string::npos) << loaded.repairs[0];
}

TEST_F(SurfaceReaderFiles, OpenSurfaceNamesFileAndDefect) {
    std::string text = cube_obj();
    text.erase(text.rfind("f "));  // drop the last triangle
    const fs::path path = write_text("open.obj", text);
    const std::string message = load_error(path);
    EXPECT_EQ(message.rfind(path.string() + ": 3 boundary edges", 0), 0u) << message;
    EXPECT_TRUE(message.ends_with("; --repair wrap rebuilds it as a closed surface")) << message;
}

// The refusal is typed, with the defects found, so a front end can offer the repairs that apply.
TEST_F(SurfaceReaderFiles, RefusalCarriesTheDefectsAndWhetherWrappingFixesThem) {
    std::string text = cube_obj();
    text.erase(text.rfind("f "));
    const fs::path path = write_text("open.obj", text);
    try {
        load_closed_surface(path);
        ADD_FAILURE() << "an open cube was accepted";
    } catch (const SurfaceRefusedError& e) {
        EXPECT_EQ(std::string(e.what()), load_error(path));  // the same message as before
        EXPECT_EQ(e.defects().boundary_edges, 3u);
        EXPECT_EQ(e.defects().self_intersecting_pairs, 0u);
        EXPECT_TRUE(e.wrapping_would_fix());
    }
    // A surface too large to check is refused before any defect is measured: not a SurfaceRefusedError.
    SurfaceRepairOptions small;
    small.max_triangles = 5;
    try {
        load_closed_surface(write_text("cube.obj", cube_obj()), small);
        ADD_FAILURE() << "12 triangles passed a limit of 5";
    } catch (const SurfaceRefusedError&) {
        ADD_FAILURE() << "a triangle count refusal carries no defects";
    } catch (const InvalidMeshError&) {
    }
}

TEST_F(SurfaceReaderFiles, PinchedCubesAreRejected) {
    std::string text = cube_obj();
    for (int k = 0; k < 8; ++k)
        text += "v " + std::to_string(1 + (k & 1)) + " " + std::to_string(1 + ((k >> 1) & 1)) + " " +
                std::to_string(1 + ((k >> 2) & 1)) + "\n";
    // The second cube's faces, shifted by 8 vertices.
    std::istringstream in(cube_obj().substr(cube_obj().find("f ")));
    std::string tag;
    int a, b, c;
    while (in >> tag >> a >> b >> c)
        text += "f " + std::to_string(a + 8) + " " + std::to_string(b + 8) + " " + std::to_string(c + 8) + "\n";
    const std::string message = load_error(write_text("pinched.obj", text));
    EXPECT_NE(message.find("1 non-manifold vertex"), std::string::npos) << message;
    EXPECT_EQ(message.find("self-intersecting"), std::string::npos) << message;
    EXPECT_TRUE(message.ends_with("; --repair wrap rebuilds it as a closed surface")) << message;
}

// ---- broken files ------------------------------------------------------------------------------------

TEST_F(SurfaceReaderFiles, MissingEmptyAndUnknownFilesGiveFileErrors) {
    expect_file_error(file("missing.obj"), "no such file");
    expect_file_error(write_text("empty.off", ""), "empty file");
    expect_file_error(write_text("cube.xyz", cube_obj()), "unknown surface format");
    expect_file_error(dir_ / "folder.obj", "no such file");
    fs::create_directories(dir_ / "dir.obj");
    expect_file_error(dir_ / "dir.obj", "not a regular file");
}

TEST_F(SurfaceReaderFiles, GarbageGivesFileErrors) {
    std::string garbage = "this is not a mesh \x01\x02\xff\n";
    std::mt19937 random(7);
    for (int k = 0; k < 2000; ++k) garbage += static_cast<char>(random() % 256);
    for (const char* name : {"garbage.obj", "garbage.off", "garbage.ply", "garbage.stl"}) {
        SCOPED_TRACE(name);
        EXPECT_THROW(read_surface_file(write_text(name, garbage)), FileError);
    }
}

TEST_F(SurfaceReaderFiles, AbsurdHeaderCountsGiveFileErrors) {
    expect_file_error(write_text("huge.off", "OFF\n1000000000 2000000000 0\n0 0 0\n"), "header declares");
    expect_file_error(write_text("huge.ply",
                                 "ply\nformat binary_little_endian 1.0\nelement vertex 999999999\n"
                                 "property float x\nproperty float y\nproperty float z\nelement face 1\n"
                                 "property list uchar int vertex_indices\nend_header\n"),
                      "header declares");
}

// Headers OpenMesh's PLY reader does not survive (it crashed on a property before any element,
// looped for ever on a version that is not a number, printed a line per value for integer
// coordinates) are refused with their line.
TEST_F(SurfaceReaderFiles, MalformedPlyHeadersNameTheirLine) {
    const std::string vertex = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
    const std::string face = "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    const std::string body = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    expect_file_error(write_text("before.ply", "ply\nformat ascii 1.0\nproperty float x\n" + vertex + face + body),
                      "PLY header line 3: a property before any element");
    expect_file_error(write_text("version.ply", "ply\nformat ascii abc\n" + vertex + face + body),
                      "PLY header line 2: unsupported version 'abc'");
    expect_file_error(write_text("version_nan.ply", "ply\nformat binary_little_endian nan\n" + vertex + face),
                      "PLY header line 2: unsupported version 'nan'");
    expect_file_error(write_text("format.ply", "ply\nformat text 1.0\n" + vertex + face + body),
                      "PLY header line 2: unknown format 'text'");
    expect_file_error(write_text("type.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty foo x\n" + face + body),
                      "PLY header line 4: unknown property type");
    expect_file_error(write_text("uchar.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty uchar x\n"
                                              "property float y\nproperty float z\n" + face + body),
                      "PLY header line 4: vertex coordinate x is uchar");
    expect_file_error(write_text("magic.ply", "plx\nformat ascii 1.0\n" + vertex + face + body),
                      "PLY header line 1");
}

TEST_F(SurfaceReaderFiles, FaceWithMissingVertexGivesFileError) {
    expect_file_error(write_text("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"), "");
}

// The cube's vertices and faces as OFF records, with `vertex_line(k)` for vertex k.
std::string cube_off_body(const std::function<std::string(int)>& vertex_line) {
    const int faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                              {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    std::string text;
    for (int k = 0; k < 8; ++k) text += vertex_line(k);
    for (const auto& f : faces)
        text += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) + "\n";
    return text;
}

std::string corner(int k) {
    return std::to_string(k & 1) + " " + std::to_string((k >> 1) & 1) + " " + std::to_string((k >> 2) & 1);
}

TEST_F(SurfaceReaderFiles, LegalOffLayoutsReadAsTheCube) {
    // OpenMesh's OFF reader misread each of these (no faces, or faces naming missing vertices).
    const std::string plain = cube_off_body([](int k) { return corner(k) + "\n"; });
    const std::string layouts[] = {
        "OFF 8 12 0\n" + plain,                                                      // counts on the OFF line
        "# made by hand\nOFF\n# counts\n8 12 0\n\n" + plain,                          // comment and blank lines
        "OFF\n8 12 0\n" + cube_off_body([](int k) { return corner(k) + " # corner\n\n"; }),  // trailing comments
        "COFF\n8 12 0\n" + cube_off_body([](int k) { return corner(k) + " 255 0 0 255\n"; }),  // colours
    };
    for (size_t k = 0; k < std::size(layouts); ++k) {
        SCOPED_TRACE(layouts[k].substr(0, 30));
        const LoadedSurface loaded = load_closed_surface(write_text("cube" + std::to_string(k) + ".off", layouts[k]));
        EXPECT_EQ(loaded.surface.points.size(), 8u);
        EXPECT_EQ(loaded.surface.triangles.size(), 12u);
        EXPECT_NEAR(find_surface_defects(loaded.surface).signed_volume, 1.0, 1e-12);
    }
}

TEST_F(SurfaceReaderFiles, BadCoordinatesAreNamedWithTheirLine) {
    // Vertex 5 (the sixth) gets a bad y; OpenMesh's readers silently skipped such a vertex, so the
    // error used to be about a face instead.
    for (const char* bad : {"nan", "inf", "-inf", "1e400", "x", "1.5.2"}) {
        SCOPED_TRACE(bad);
        const std::string fragment = std::string("vertex coordinate '") + bad + "' is ";
        auto with_bad = [&](const std::string& prefix, const std::string& suffix) {
            return [=](int k) { return prefix + (k == 5 ? "1 " + std::string(bad) + " 1" : corner(k)) + suffix; };
        };
        // OBJ: vertex 5 is on line 6.
        std::string obj;
        for (int k = 0; k < 8; ++k) obj += with_bad("v ", "\n")(k);
        expect_file_error(write_text("bad.obj", obj + "f 1 3 2\n"), "line 6: " + fragment);
        // OFF: two header lines, then the vertices.
        expect_file_error(write_text("bad.off", "OFF\n8 12 0\n" + cube_off_body(with_bad("", "\n"))), "line 8: " + fragment);
        // Ascii PLY: nine header lines.
        const std::string ply_header =
            "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 12\nproperty list uchar int vertex_indices\nend_header\n";
        expect_file_error(write_text("bad.ply", ply_header + cube_off_body(with_bad("", "\n"))), "line 15: " + fragment);
        // Ascii STL: a facet's first vertex on line 4.
        expect_file_error(write_text("bad.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 " + std::string(bad) +
                                                    " 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n"),
                          "line 4: " + fragment);
    }
}

TEST_F(SurfaceReaderFiles, NonFiniteBinaryCoordinatesAreNamed) {
    auto cube = make_openmesh_cube();
    cube.set_point(OpenMesh::VertexHandle(3), {0.0f, std::numeric_limits<float>::quiet_NaN(), 1.0f});
    ASSERT_TRUE(OpenMesh::IO::write_mesh(cube, file("nan.stl").string(), OpenMesh::IO::Options::Binary));
    expect_file_error(file("nan.stl"), "has a non-finite coordinate");
    ASSERT_TRUE(OpenMesh::IO::write_mesh(cube, file("nan.ply").string(), OpenMesh::IO::Options::Binary));
    expect_file_error(file("nan.ply"), "vertex 3 has a non-finite coordinate");
}

// Float's largest value is a valid binary coordinate, but beyond what the renderer can multiply: refused
// by the reader, as the volume readers refuse it, rather than by the renderer after meshing.
TEST_F(SurfaceReaderFiles, CoordinatesBeyondTheRenderersRangeAreNamed) {
    auto cube = make_openmesh_cube();
    cube.set_point(OpenMesh::VertexHandle(5), {std::numeric_limits<float>::max(), 1.0f, 1.0f});
    ASSERT_TRUE(OpenMesh::IO::write_mesh(cube, file("far.stl").string(), OpenMesh::IO::Options::Binary));
    expect_file_error(file("far.stl"), "has a coordinate beyond 1e12");
    ASSERT_TRUE(OpenMesh::IO::write_mesh(cube, file("far.ply").string(), OpenMesh::IO::Options::Binary));
    expect_file_error(file("far.ply"), "vertex 5 has a coordinate beyond 1e12");
    cube.set_point(OpenMesh::VertexHandle(5), {1e11f, 1.0f, 1.0f});
    ASSERT_TRUE(OpenMesh::IO::write_mesh(cube, file("near.ply").string(), OpenMesh::IO::Options::Binary));
    EXPECT_NO_THROW(read_surface_file(file("near.ply")));
}

TEST_F(SurfaceReaderFiles, BadOffFacesAreNamedWithTheirLine) {
    const std::string body = cube_off_body([](int k) { return corner(k) + "\n"; });
    std::string bad_index = body;
    bad_index.replace(bad_index.rfind("3 3 7 5"), 7, "3 3 8 5");
    expect_file_error(write_text("index.off", "OFF\n8 12 0\n" + bad_index), "line 22: face 11 refers to vertex 8");
    std::string short_face = body;
    short_face.replace(short_face.rfind("3 3 7 5"), 7, "4 3 7 5");
    expect_file_error(write_text("short.off", "OFF\n8 12 0\n" + short_face), "line 22: face 11: 3 vertex indices");
    std::string word = body;
    word.replace(word.rfind("3 3 7 5"), 7, "3 3 seven 5");
    expect_file_error(write_text("word.off", "OFF\n8 12 0\n" + word), "line 22: face 11: 'seven' is not a vertex index");
}

TEST_F(SurfaceReaderFiles, TruncatedFilesGiveFileErrors) {
    const auto cube = make_openmesh_cube();
    const struct {
        std::string name;
        OpenMesh::IO::Options options;
    } cases[] = {{"cube.off", {}},
                 {"cube_ascii.ply", {}},
                 {"cube_binary.ply", OpenMesh::IO::Options::Binary},
                 {"cube_binary.stl", OpenMesh::IO::Options::Binary}};
    for (const auto& c : cases) {
        ASSERT_TRUE(OpenMesh::IO::write_mesh(cube, file(c.name).string(), c.options));
        for (double fraction : {0.3, 0.6, 0.9}) {
            SCOPED_TRACE(c.name + " cut at " + std::to_string(fraction));
            const fs::path cut = truncated_copy(file(c.name), "cut_" + c.name, fraction);
            EXPECT_THROW(read_surface_file(cut), FileError);
        }
    }
}

TEST_F(SurfaceReaderFiles, TruncatedTextFilesNeverPassSilently) {
    // OBJ and ascii STL have no element counts: a cut at a line boundary is a smaller, valid file.
    // Whatever the cut, the result is a FileError or a rejected (open) surface, never a surface.
    const auto cube = make_openmesh_cube();
    ASSERT_TRUE(OpenMesh::IO::write_mesh(cube, file("cube_ascii.stl").string()));
    write_text("cube.obj", cube_obj());
    for (const char* name : {"cube.obj", "cube_ascii.stl"}) {
        for (double fraction : {0.2, 0.5, 0.75, 0.95}) {
            SCOPED_TRACE(std::string(name) + " cut at " + std::to_string(fraction));
            const fs::path cut = truncated_copy(file(name), std::string("cut_") + name, fraction);
            try {
                load_closed_surface(cut);
                ADD_FAILURE() << "a truncated file loaded";
            } catch (const FileError&) {
            } catch (const InvalidMeshError&) {
            }
        }
    }
}

}  // namespace
}  // namespace waxwork

namespace waxwork {
namespace {

// Three vertices no face uses (the safe repairs drop them, renumbering the rest) and a face repeating
// a vertex (dropped too), then `body`, whose vertex numbers start at 4.
std::string renumbered_by_repairs(const std::string& body) {
    return "v 9 9 9\nv 8 8 8\nv 7 7 7\nf 1 1 2\n" + body;
}

// The error messages name the file's vertices and faces whether or not a shape-changing repair ran
// first: the repairs renumber the surface, and its numbers pointed at the wrong elements.
TEST_F(SurfaceReaderFiles, DefectsAfterHardRepairsAreNamedByTheFilesNumbers) {
    // Two tets sharing only the corner at file vertex 3 (pinched: the hard repairs cannot run).
    const fs::path pinched = write_text("pinched.obj", renumbered_by_repairs(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv -1 0 0\nv 0 -1 0\nv 0 0 -1\n"
        "f 4 6 5\nf 4 5 7\nf 4 7 6\nf 5 6 7\nf 4 8 9\nf 4 10 8\nf 4 9 10\nf 8 10 9\n"));
    const std::string plain = load_error(pinched);
    EXPECT_NE(plain.find("pinched; vertex 3)"), std::string::npos) << plain;
    for (const SurfaceRepairOptions options : {SurfaceRepairOptions{.fill_holes = true, .autorefine = false},
                                               SurfaceRepairOptions{.fill_holes = false, .autorefine = true}}) {
        const std::string repaired = load_error(pinched, options);
        EXPECT_NE(repaired.find("pinched; vertex 3)"), std::string::npos) << repaired;
    }

    // An open tet (its hole is filled) beside two closed tets crossing each other (they stay crossed):
    // the crossing faces keep the file's numbers, faces 5 on (0-based, after the repeated-index face).
    const fs::path crossed = write_text("crossed.obj", renumbered_by_repairs(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
        "v 5 0 0\nv 6 0 0\nv 5 1 0\nv 5 0 1\n"
        "v 5.2 0.2 0.2\nv 6.2 0.2 0.2\nv 5.2 1.2 0.2\nv 5.2 0.2 1.2\n"
        "f 4 6 5\nf 4 5 7\nf 4 7 6\n"
        "f 8 10 9\nf 8 9 11\nf 8 11 10\nf 9 10 11\n"
        "f 12 14 13\nf 12 13 15\nf 12 15 14\nf 13 14 15\n"));
    const std::string before = load_error(crossed);
    const auto first_pair = [](const std::string& message) {
        const size_t at = message.find("self-intersecting triangle pairs (first: ");
        return at == std::string::npos ? std::string() : message.substr(at, message.find(')', at) - at);
    };
    ASSERT_NE(first_pair(before), "") << before;
    const std::string after = load_error(crossed, {.fill_holes = true, .autorefine = false});
    EXPECT_EQ(after.find("(the surface is open"), std::string::npos) << after;  // the hole was filled
    EXPECT_EQ(first_pair(after), first_pair(before)) << before << "\n" << after;
}

// A wrap finer than the meshers take is refused naming the option that coarsens it; a bad option names
// the file and the option.
TEST_F(SurfaceReaderFiles, WrapLimitsAndOptionErrorsNameTheFile) {
    const fs::path path = write_text("cube.obj", cube_obj());
    SurfaceRepairOptions options{.fill_holes = false, .autorefine = false, .max_triangles = 100};
    options.wrap = WrapOptions{.alpha = 0.02, .offset = {}};
    try {
        load_closed_surface(path, options);
        ADD_FAILURE() << "loaded";
    } catch (const InvalidMeshError& e) {
        const std::string message = e.what();
        EXPECT_EQ(message.rfind(path.string() + ": the wrap has ", 0), 0u) << message;
        EXPECT_NE(message.find("more than the meshers take (100); a larger --wrap-alpha gives fewer"), std::string::npos)
            << message;
    }
    options.wrap = WrapOptions{.alpha = 1e-5, .offset = {}};
    try {
        load_closed_surface(path, options);
        ADD_FAILURE() << "loaded";
    } catch (const InvalidArgumentError& e) {
        EXPECT_EQ(std::string(e.what()).rfind(path.string() + ": --wrap-alpha: 1e-05 is below", 0), 0u) << e.what();
    }
}

// A surface with more triangles than the meshers take is refused right after reading, before the
// checks and repairs (which took a minute on a 2M-triangle surface), naming the file.
TEST_F(SurfaceReaderFiles, MoreTrianglesThanTheLimitAreRefusedBeforeTheChecks) {
    const fs::path path = write_text("cube.obj", cube_obj());
    EXPECT_NO_THROW(load_closed_surface(path, {.fill_holes = false, .autorefine = false, .max_triangles = 12}));
    try {
        load_closed_surface(path, {.fill_holes = false, .autorefine = false, .max_triangles = 11});
        ADD_FAILURE() << "loaded";
    } catch (const InvalidMeshError& e) {
        EXPECT_EQ(std::string(e.what()).rfind(path.string() + ": 12 triangles, more than the meshers take (11", 0), 0u)
            << e.what();
    }
}

// Vertices and faces a repair made have no number in the file: they are marked as new, and the
// message says which numbering the others use.
TEST(SurfaceIndexNames, ElementsARepairMadeAreMarkedAsNew) {
    SurfaceDefects defects;
    defects.triangle_count = 2;
    defects.non_manifold_vertices = 1;
    defects.first_non_manifold_vertex = 1;
    defects.boundary_edges = 1;
    defects.first_boundary_edge = {0, 1};
    SurfaceIndexMap origin;
    origin.points = {17, -1};
    origin.triangles = {0, 1};
    const std::vector<std::string> lines = defects.describe(&origin);
    ASSERT_EQ(lines.size(), 2u);
    EXPECT_NE(lines[0].find("vertices 17 and [new 1]"), std::string::npos) << lines[0];
    EXPECT_NE(lines[1].find("vertex [new 1]"), std::string::npos) << lines[1];
}

}  // namespace
}  // namespace waxwork
