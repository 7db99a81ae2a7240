// Fuzzing the session format: hostile values anywhere in a valid session must be refused with an
// error naming the session file, and sessions whose output names are hostile (links, NUL bytes,
// control characters, '..', absolute and over-long paths) must write nothing outside OUTDIR.
// Deterministic: the seed and the case index reproduce any failure.
#include "base/error.h"
#include "io/volume_file.h"
#include "scene/session.h"
#include "support/cli_run.h"
#include "support/fuzz_mutations.h"
#include "tetops/test_meshes.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <random>

namespace waxwork {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

constexpr uint64_t kSeed = 20261128;

const Json& valid_session() {
    static const Json session = Json::parse(R"({
        "input": {"volume": "cube.vtu"},
        "material": "marble", "scale": 30,
        "lights": [{"direction": [1, -1, -1], "intensity": [1, 1, 1]}, {"position": [0, 2, 0]}],
        "ambient": [0.02, 0.02, 0.02], "shadows": true,
        "camera": {"eye_direction": [0.75, 0.5, -1], "up": [0, 1, 0], "fov_y_deg": 30, "margin": 1.1},
        "image": {"width": 16, "height": 12},
        "tolerance": 0.001, "frame_iterations": 10, "crease_angle": 40,
        "steps": [
            {"op": "plane_cut", "normal": [1, 0, 0], "offset": 0.6, "relax": {"iterations": 5, "step": 0.3}},
            {"render": "a.png", "frames": 2},
            {"op": "paint", "points": [[0.5, 0.5, 0.5]], "sigma": 0.2, "material": "ketchup"},
            {"save": "sub/b.vtu"},
            {"undo": 1}, {"redo": 1},
            {"light": {"ambient": [0.1, 0.1, 0.1]}},
            {"camera": {"eye_direction": [0, 0, 1]}},
            {"render": "c.png"}
        ]})");
    return session;
}

Json hostile_value(testing::ByteMutator& random) {
    static const std::vector<Json> values = {
        Json(nullptr), Json(true), Json(0), Json(-1), Json(1e308), Json(-1e308), Json(1e-320), Json(3.5e38),
        Json(9223372036854775807LL), Json(std::numeric_limits<uint64_t>::max()), Json(""), Json("x"),
        Json(std::string("a\0b.vtu", 7)), Json("../up.vtu"), Json("/tmp/abs.png"), Json("linkdir/x.vtu"),
        Json(std::string(300, 'n') + ".png"), Json::array(), Json::array({1, 2}), Json::array({1e308, 0, 0}),
        Json::array({0, 0, 0}), Json::object(), Json{{"op", "nope"}}};
    return values[random.pick(values.size())];
}

// Every location (a JSON pointer) in `json`.
void collect_pointers(const Json& json, const Json::json_pointer& at, std::vector<Json::json_pointer>& out) {
    out.push_back(at);
    if (json.is_object())
        for (const auto& [key, value] : json.items()) collect_pointers(value, at / key, out);
    if (json.is_array())
        for (size_t i = 0; i < json.size(); ++i) collect_pointers(json[i], at / i, out);
}

TEST(SessionFuzz, HostileValuesAnywhereAreRefusedNamingTheSession) {
    std::vector<Json::json_pointer> pointers;
    collect_pointers(valid_session(), Json::json_pointer(), pointers);
    const fs::path dir = testing::scratch_dir("session_fuzz_values");
    write_volume(testing::make_cube_mesh(2), dir / "cube.vtu");
    testing::ByteMutator random(kSeed);
    int refused = 0, accepted = 0, ran = 0, failed = 0;
    constexpr int kCases = 1500, kMaxRuns = 40;
    for (int i = 0; i < kCases; ++i) {
        Json session = valid_session();
        const int edits = 1 + static_cast<int>(random.pick(2));
        for (int k = 0; k < edits; ++k) {
            const Json::json_pointer& at = pointers[random.pick(pointers.size())];
            if (!session.contains(at)) continue;
            if (random.pick(4) == 0 && !at.empty()) {
                Json& parent = session[at.parent_pointer()];
                if (parent.is_object()) parent.erase(at.back());
                else session[at] = hostile_value(random);
            } else {
                session[at] = hostile_value(random);
            }
        }
        const std::string label = "seed " + std::to_string(kSeed) + " case " + std::to_string(i) + ": " + session.dump();
        std::optional<Session> parsed;
        try {
            parsed = parse_session(session, dir, "fuzz.json");
            ++accepted;
        } catch (const InvalidArgumentError& e) {
            EXPECT_EQ(std::string(e.what()).rfind("fuzz.json", 0), 0u) << label << "\n" << e.what();
            ++refused;
        } catch (const std::exception& e) {
            ADD_FAILURE() << label << ": not an InvalidArgumentError: " << e.what();
        }
        // What is accepted must also run, or fail naming the session and the step (a value that passed
        // the reader must not surface as another module's complaint).
        if (!parsed || ran + failed >= kMaxRuns) continue;
        try {
            run_session(*parsed, dir / "out");
            ++ran;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("fuzz.json"), std::string::npos) << label << "\n" << e.what();
            ++failed;
            if (std::getenv("FUZZ_VERBOSE")) std::cout << e.what() << "\n";
        } catch (const std::exception& e) {
            ADD_FAILURE() << label << ": " << e.what();
        }
    }
    EXPECT_GT(refused, kCases / 2);
    EXPECT_GT(ran, 0);
    std::cout << "[ fuzz     ] session values: " << kCases << " cases, " << refused << " refused naming the session, "
              << accepted << " accepted; of these " << ran + failed << " replayed: " << ran << " ran, " << failed
              << " failed naming the session\n";
}

TEST(SessionFuzz, HostileOutputNamesNeverWriteOutsideTheOutputFolder) {
    const fs::path root = testing::scratch_dir("session_fuzz_outputs");
    write_volume(testing::make_cube_mesh(2), root / "cube.vtu");
    const fs::path out = root / "out", elsewhere = root / "elsewhere";
    fs::create_directories(out / "inside");
    fs::create_directories(elsewhere);
    fs::create_directory_symlink(elsewhere, out / "linkdir");
    fs::create_directory_symlink("inside", out / "insidelink");
    fs::create_directory_symlink(root, out / "rootlink");
    const std::vector<std::string> parts = {"linkdir", "insidelink", "rootlink", "inside", "..", ".", "", "new",
                                            std::string("nul\0", 4), "tab\t", "nl\n", std::string(240, 'p'), "/",
                                            "elsewhere", "rootlink/elsewhere"};
    testing::ByteMutator random(kSeed);
    int refused_on_read = 0, refused_on_run = 0, ran = 0;
    constexpr int kCases = 60;
    for (int i = 0; i < kCases; ++i) {
        std::string name;
        const int depth = 1 + static_cast<int>(random.pick(3));
        for (int d = 0; d < depth; ++d) name += parts[random.pick(parts.size())] + "/";
        name += random.pick(2) ? "x.vtu" : "x.png";
        const std::string key = name.ends_with(".png") ? "render" : "save";
        const Json session{{"input", {{"volume", "cube.vtu"}}}, {"image", {{"width", 8}, {"height", 6}}},
                           {"steps", Json::array({Json{{key, name}}})}};
        const std::string label = "seed " + std::to_string(kSeed) + " case " + std::to_string(i) + ": " + session.dump();
        try {
            run_session(parse_session(session, root, "fuzz.json"), out);
            ++ran;
        } catch (const InvalidArgumentError& e) {
            EXPECT_EQ(std::string(e.what()).rfind("fuzz.json", 0), 0u) << label << "\n" << e.what();
            ++refused_on_read;
        } catch (const FileError& e) {
            EXPECT_NE(e.problem().find("fuzz.json: step 0"), std::string::npos) << label << "\n" << e.what();
            ++refused_on_run;
        } catch (const std::exception& e) {
            ADD_FAILURE() << label << ": " << e.what();
        }
        ASSERT_TRUE(fs::is_empty(elsewhere)) << label;
        for (const auto& entry : fs::directory_iterator(root))  // nothing new beside cube.vtu, out, elsewhere
            ASSERT_TRUE(entry.path() == root / "cube.vtu" || entry.path() == out || entry.path() == elsewhere)
                << label << " wrote " << entry.path();
    }
    EXPECT_GT(ran, 0);
    EXPECT_GT(refused_on_read, 0);
    EXPECT_GT(refused_on_run, 0);
    std::cout << "[ fuzz     ] session outputs: " << kCases << " cases, " << refused_on_read << " refused when read, "
              << refused_on_run << " refused at their step, " << ran << " written inside OUTDIR\n";
}

}  // namespace
}  // namespace waxwork
