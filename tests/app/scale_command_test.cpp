// The model's scale through the commands: chosen from the model's size when not given, said so,
// stored in every volume written, kept by edits, and used when the volume is rendered again.
#include "support/cli_run.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace waxwork {
namespace {

using namespace testing;
namespace fs = std::filesystem;
using Json = nlohmann::json;

Json run_json(const std::string& arguments, CommandResult* result = nullptr) {
    const CommandResult r = run_waxwork(arguments);
    if (result) *result = r;
    EXPECT_EQ(r.exit_code, 0) << arguments << "\n" << r.err;
    return r.exit_code == 0 ? Json::parse(r.out) : Json();
}

TEST(ScaleCommands, MeshChoosesAScaleFromTheModelSaysSoAndStoresIt) {
    const fs::path dir = scratch_dir("scale_mesh");
    const std::string cube = kAssets + "/meshes/cube.obj";  // 2 x 2 x 2 units: diagonal 3.46
    CommandResult r;
    const Json mesh = run_json("mesh " + cube + " -o " + (dir / "a.vtu").string() + " --max-tets 3000", &r);
    EXPECT_EQ(mesh["mm_per_unit"], 20.0);
    EXPECT_EQ(mesh["scale_source"], "model size");
    EXPECT_NE(r.err.find("scale: 20 mm per model unit (chosen from the model's size; --scale sets it): the model is "
                         "40 x 40 x 40 mm"),
              std::string::npos)
        << r.err;
    const Json info = run_json("info " + (dir / "a.vtu").string());
    EXPECT_EQ(info["mm_per_unit"], 20.0);
    EXPECT_EQ(info["size_mm"], "40 x 40 x 40 mm");

    // Given: no note, stored in a foreign format too.
    const Json given = run_json("mesh " + cube + " -o " + (dir / "b.msh").string() + " --max-tets 3000 --scale 5", &r);
    EXPECT_EQ(given["scale_source"], "given");
    EXPECT_EQ(r.err.find("scale:"), std::string::npos) << r.err;
    EXPECT_EQ(run_json("info " + (dir / "b.msh").string())["mm_per_unit"], 5.0);
}

TEST(ScaleCommands, EditsKeepTheScaleAndRenderUsesIt) {
    const fs::path dir = scratch_dir("scale_render");
    const std::string volume = (dir / "a.vtu").string();
    run_json("mesh " + kAssets + "/meshes/cube.obj -o " + volume + " --max-tets 3000 --scale 30");
    // A painted, cut volume keeps the scale it was meshed at.
    run_json("paint " + volume + " -o " + (dir / "p.vtu").string() + " --at 0.5,0.5,0.5 --sigma 0.3 --material ketchup");
    run_json("cut " + (dir / "p.vtu").string() + " -o " + (dir / "c.node").string() + " --plane=1,0,0,0.5");
    EXPECT_EQ(run_json("info " + (dir / "p.vtu").string())["mm_per_unit"], 30.0);
    EXPECT_EQ(run_json("info " + (dir / "c.node").string())["mm_per_unit"], 30.0);

    // Rendering the painted volume without --scale renders it at its stored scale: the same image.
    const std::string options = " --width 96 --height 72";
    CommandResult r;
    const Json stored = run_json("render " + (dir / "p.vtu").string() + " -o " + (dir / "s.png").string() + options, &r);
    EXPECT_EQ(stored["mm_per_unit"], 30.0);
    EXPECT_EQ(stored["scale_source"], "stored");
    EXPECT_EQ(r.err.find("scale:"), std::string::npos) << r.err;
    run_json("render " + (dir / "p.vtu").string() + " -o " + (dir / "g.png").string() + options + " --scale 30");
    EXPECT_EQ(read_text(dir / "s.png"), read_text(dir / "g.png"));
    run_json("render " + (dir / "p.vtu").string() + " -o " + (dir / "one.png").string() + options + " --scale 1");
    EXPECT_NE(read_text(dir / "s.png"), read_text(dir / "one.png"));  // at 2 mm the paint is not visible alike
}

TEST(ScaleCommands, AVolumeWithoutAScaleIsRenderedAtTheModelsAndSaysSo) {
    const fs::path dir = scratch_dir("scale_foreign");
    run_json("mesh " + kAssets + "/meshes/cube.obj -o " + (dir / "a.msh").string() + " --max-tets 3000 --scale 5");
    // Another program's .msh: the same file without Waxwork's comment section.
    std::string text = read_text(dir / "a.msh");
    const size_t begin = text.find("$Comments\n"), end = text.find("$EndComments\n");
    ASSERT_NE(begin, std::string::npos);
    text.erase(begin, end + std::string("$EndComments\n").size() - begin);
    std::ofstream(dir / "foreign.msh") << text;
    EXPECT_TRUE(run_json("info " + (dir / "foreign.msh").string())["mm_per_unit"].is_null());
    CommandResult r;
    const Json render =
        run_json("render " + (dir / "foreign.msh").string() + " -o " + (dir / "f.png").string() + " --width 64 --height 48", &r);
    EXPECT_EQ(render["mm_per_unit"], 20.0);
    EXPECT_EQ(render["scale_source"], "model size");
    EXPECT_NE(r.err.find("foreign.msh: scale: 20 mm per model unit (chosen from the model's size"), std::string::npos)
        << r.err;
}

TEST(ScaleCommands, AStoredScaleOutOfRangeIsAOneLineErrorNamingTheFile) {
    const fs::path dir = scratch_dir("scale_corrupt");
    run_json("mesh " + kAssets + "/meshes/cube.obj -o " + (dir / "a.mesh").string() + " --max-tets 3000 --scale 5");
    std::string text = read_text(dir / "a.mesh");
    text.replace(text.find("mm_per_unit 5"), 13, "mm_per_unit -5");
    std::ofstream(dir / "bad.mesh") << text;
    const CommandResult r = run_waxwork("render " + (dir / "bad.mesh").string() + " -o " + (dir / "x.png").string());
    EXPECT_NE(r.exit_code, 0);
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("bad.mesh: stored mm_per_unit must be a length in mm per model unit between 1e-6 and 1e6 (got -5)"),
              std::string::npos)
        << r.err;
}

}  // namespace
}  // namespace waxwork
