// A session's outputs stay in the folder given to `run -o`, their names are checked when the session
// is read, and a replay that fails says in metrics.json where it stopped and what it wrote.
#include "base/error.h"
#include "io/output_folder.h"
#include "io/volume_file.h"
#include "scene/session.h"
#include "support/cli_run.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <climits>
#include <filesystem>
#include <fstream>

namespace waxwork {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

// A session on a small cube volume written into `dir`, with `steps` (JSON text of the array's items).
Session cube_session(const fs::path& dir, const std::string& steps) {
    write_volume(testing::make_cube_mesh(3), dir / "cube.vtu");
    return parse_session(Json::parse(R"({"input": {"volume": "cube.vtu"}, "image": {"width": 16, "height": 12},
                                         "steps": [)" + steps + "]}"),
                         dir, "s.json");
}

std::string parse_error(const Json& json) {
    try {
        parse_session(json, "/d", "s.json");
    } catch (const InvalidArgumentError& e) {
        return e.what();
    }
    return "(no error)";
}

Json read_json(const fs::path& path) { return Json::parse(std::ifstream(path)); }

TEST(SessionOutputs, ALinkInTheOutputFolderCannotLeadAWriteOutside) {
    const fs::path root = testing::scratch_dir("session_links");
    const fs::path out = root / "out", elsewhere = root / "elsewhere";
    fs::create_directories(out);
    fs::create_directories(elsewhere);
    fs::create_directory_symlink(elsewhere, out / "linkdir");
    for (const std::string step : {R"({"save": "linkdir/x.vtu"})", R"({"render": "linkdir/x.png"})",
                                   R"({"save": "linkdir/new/x.vtu"})"}) {
        const Session session = cube_session(root, step);
        try {
            run_session(session, out);
            ADD_FAILURE() << step << " ran";
        } catch (const FileError& e) {
            EXPECT_EQ(e.path(), (out / "linkdir").string()) << e.what();
            EXPECT_NE(e.problem().find("s.json: step 0"), std::string::npos) << e.what();
            EXPECT_NE(e.problem().find("leads outside the output folder"), std::string::npos) << e.what();
        }
    }
    EXPECT_TRUE(fs::is_empty(elsewhere));
}

TEST(SessionOutputs, ControlCharactersAndOverlongNamesAreRefusedWhenRead) {
    const Json nul_save = Json::parse(R"({"input": {"volume": "v.vtu"}, "steps": [{"save": "evil.sh\u0000.vtu"}]})");
    EXPECT_NE(parse_error(nul_save).find("s.json: step 0: field 'save': 'evil.sh\\x00.vtu' contains a control character"),
              std::string::npos)
        << parse_error(nul_save);
    const Json nul_render = Json::parse(R"({"input": {"volume": "v.vtu"}, "steps": [{"render": "r0.png\u0000.vtu"}]})");
    EXPECT_NE(parse_error(nul_render).find("contains a control character"), std::string::npos) << parse_error(nul_render);
    Json long_name = Json::parse(R"({"input": {"volume": "v.vtu"}, "steps": [{"render": "a.png"}]})");
    long_name["steps"].push_back(Json{{"save", std::string(300, 'x') + ".vtu"}});
    EXPECT_NE(parse_error(long_name).find("s.json: step 1: field 'save': "), std::string::npos) << parse_error(long_name);
    EXPECT_NE(parse_error(long_name).find("fit a file name"), std::string::npos) << parse_error(long_name);
}

TEST(SessionOutputs, AWholePathTooLongIsRefusedBeforeTheInputLoads) {
    const fs::path dir = testing::scratch_dir("session_long_path");
    std::string deep;
    while (deep.size() + dir.native().size() < PATH_MAX) deep += std::string(200, 'd') + "/";
    // The input does not exist: the length is what must be reported, before anything runs.
    const Session session = parse_session(
        Json::parse(R"({"input": {"volume": "missing.vtu"}, "steps": [{"save": ")" + deep + R"(v.vtu"}]})"), dir,
        "s.json");
    try {
        run_session(session, dir / "out");
        FAIL() << "ran";
    } catch (const InvalidArgumentError& e) {
        EXPECT_NE(std::string(e.what()).find("s.json: step 0 (save): the output path is"), std::string::npos) << e.what();
    }
}

TEST(SessionOutputs, AFailedReplayWritesMetricsSayingWhereItStoppedAndWhatItWrote) {
    const fs::path dir = testing::scratch_dir("session_failed");
    const Session session = cube_session(dir, R"({"save": "a.vtu"}, {"render": "frames/b.png"}, {"undo": 1})");
    EXPECT_THROW(run_session(session, dir / "out"), InvalidArgumentError);
    const Json metrics = read_json(dir / "out" / "metrics.json");
    EXPECT_EQ(metrics["status"], "failed");
    EXPECT_EQ(metrics["failed_step"], 2);
    EXPECT_NE(metrics["error"].get<std::string>().find("s.json: step 2 (undo): nothing left to undo"), std::string::npos)
        << metrics.dump();
    EXPECT_EQ(metrics["written"], Json::parse(R"(["a.vtu", "frames/b.png"])"));
    ASSERT_EQ(metrics["steps"].size(), 2u);  // the steps that finished
    EXPECT_EQ(metrics["steps"][1]["name"], "render");

    // An input that fails to load: no step ran, nothing was written.
    Session bad_input = session;
    bad_input.input.volume = dir / "missing.vtu";
    EXPECT_THROW(run_session(bad_input, dir / "out2"), FileError);
    const Json load_metrics = read_json(dir / "out2" / "metrics.json");
    EXPECT_EQ(load_metrics["status"], "failed");
    EXPECT_TRUE(load_metrics["failed_step"].is_null());
    EXPECT_EQ(load_metrics["written"], Json::array());
}

TEST(SessionOutputs, ASuccessfulReplayListsItsOutputs) {
    const fs::path dir = testing::scratch_dir("session_ok");
    run_session(cube_session(dir, R"({"save": "a.vtu"}, {"save": "sub/b.node"})"), dir / "out");
    const Json metrics = read_json(dir / "out" / "metrics.json");
    EXPECT_EQ(metrics["status"], "ok");
    EXPECT_EQ(metrics["written"], Json::parse(R"(["a.vtu", "sub/b.node"])"));
    EXPECT_EQ(metrics["steps"].size(), 2u);
}

}  // namespace
}  // namespace waxwork
