// RunProvenance and its parts: the file hash sha256sum prints, the command line, the build, the
// machine block, and the warnings for a busy machine and an under-resolved mesh.
#include "bench/studies/provenance.h"

#include "base/error.h"
#include "solver/material.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <thread>

namespace waxwork {
namespace {

std::filesystem::path scratch(const std::string& name) {
    const auto dir = std::filesystem::temp_directory_path() / ("waxwork_provenance_" + name);
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

TEST(Provenance, HashesFilesAsSha256sumDoes) {
    const auto dir = scratch("hash");
    std::ofstream(dir / "abc.txt", std::ios::binary) << "abc";
    // FIPS 180-2's first example.
    EXPECT_EQ(file_sha256(dir / "abc.txt"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    std::ofstream(dir / "empty.txt", std::ios::binary);
    EXPECT_EQ(file_sha256(dir / "empty.txt"), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
    try {
        file_sha256(dir / "missing.obj");
        FAIL() << "no error";
    } catch (const FileError& e) {
        EXPECT_NE(std::string(e.what()).find("missing.obj"), std::string::npos) << e.what();
    }
}

TEST(Provenance, RecordsTheCommandTheBuildAndTheMachine) {
    EXPECT_NE(command_line().find("waxwork_studies_tests"), std::string::npos) << command_line();
    const auto build = build_provenance();
    EXPECT_FALSE(build["commit"].get<std::string>().empty());
    EXPECT_EQ(build["build_type"], "Release");
    EXPECT_EQ(utc_timestamp().size(), 20u);

    const ThreadLimit limit(1);
    RunProvenance provenance(limit);
    provenance.set_gl_renderer("llvmpipe (LLVM 15.0.6, 256 bits)");
    const TetMesh mesh = testing::make_cube_mesh(3);
    const auto block = provenance.to_json(mesh_inputs("", mesh, 10.0), {{"error", "none"}});
    EXPECT_EQ(block["machine"]["threads_used"], 1);
    EXPECT_EQ(block["machine"]["opengl_renderer"], "llvmpipe (LLVM 15.0.6, 256 bits)");
    EXPECT_EQ(block["inputs"]["tets"], mesh.tet_count());
    EXPECT_EQ(block["inputs"]["mesh_sha256"], "");
    EXPECT_NEAR(block["inputs"]["mm_per_unit"].get<double>(), 10.0, 0);
    EXPECT_EQ(block["definitions"]["error"], "none");
    const std::string caption = provenance_caption(block);
    EXPECT_NE(caption.find("| 1 thread | commit "), std::string::npos) << caption;
    EXPECT_EQ(caption.substr(0, 10), block["started"].get<std::string>().substr(0, 10));
    EXPECT_EQ(provenance.caption(), caption);
}

// Another process spinning on a core during the run: the block says so and warns.
TEST(Provenance, WarnsWhenOtherProcessesKeepTheMachineBusy) {
    const ThreadLimit limit(1);
    RunProvenance provenance(limit);
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        volatile double x = 0;
        for (;;) x = x + 1;  // killed by the parent
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(600));
    const auto block = provenance.to_json({}, {});
    kill(child, SIGKILL);
    waitpid(child, nullptr, 0);
    EXPECT_GT(block["machine"]["other_load_cores"].get<double>(), kBusyMachineCores);
    ASSERT_GE(block["warnings"].size(), 1u);
    EXPECT_NE(block["warnings"].back().get<std::string>().find("the machine was busy"), std::string::npos);
}

TEST(Provenance, WarnsWhenTheMeshUnderResolvesTheLight) {
    const ThreadLimit limit(1);
    RunProvenance provenance(limit);
    const TetMesh cube = testing::make_cube_mesh(4);  // edges of a quarter unit
    const std::vector<TetMaterial> skin(cube.tet_count(), material_preset("skin1"));
    provenance.warn_if_under_resolved(cube, skin, 100.0);  // 25 mm edges against under 1 mm
    const std::vector<TetMaterial> marble(cube.tet_count(), material_preset("marble"));
    provenance.warn_if_under_resolved(cube, marble, 0.1);  // 0.025 mm edges: fine
    const auto block = provenance.to_json({}, {});
    size_t resolution_warnings = 0;  // (a busy-machine warning can come too, when tests run side by side)
    for (const auto& warning : block["warnings"])
        resolution_warnings += warning.get<std::string>().find("under-resolves") != std::string::npos;
    EXPECT_EQ(resolution_warnings, 1u);
}

}  // namespace
}  // namespace waxwork
