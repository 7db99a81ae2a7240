// `waxwork turntable` end to end: one solve, N frames around the model at one exposure, the MP4 when
// ffmpeg is there and a message when it is not.
#include "io/image_io.h"
#include "support/cli_run.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

namespace waxwork {
namespace {

using namespace testing;
namespace fs = std::filesystem;

class Turntable : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        dir_ = scratch_dir("turntable_command");
        volume_ = dir_ / "cube.vtu";
        const auto m = run_waxwork("mesh " + kAssets + "/meshes/cube.obj -o " + volume_.string() + " --max-tets 3000");
        ASSERT_EQ(m.exit_code, 0) << m.err;
    }
    static fs::path dir_, volume_;
};
fs::path Turntable::dir_, Turntable::volume_;

std::string frame(int i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d.png", i);
    return name;
}

// Without ffmpeg on the PATH (an empty one: the binary is called by its full path).
constexpr const char* kNoFfmpeg = "PATH=/nonexistent ";

TEST_F(Turntable, WritesNTurningFramesAtTheFirstFramesExposure) {
    const fs::path out = dir_ / "nested" / "spin";  // created, parents too
    fs::remove_all(dir_ / "nested");
    const auto r = run_waxwork("turntable " + volume_.string() + " -o " + out.string() +
                               " --frames 5 --width 48 --height 36 --elevation 25", kNoFfmpeg);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto summary = nlohmann::json::parse(r.out);
    EXPECT_EQ(summary["frames"], 5);
    EXPECT_TRUE(summary["mp4"].is_null());
    EXPECT_NE(r.err.find("ffmpeg is not on the PATH"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out / "turntable.mp4"));
    std::vector<Image> frames;
    for (int i = 0; i < 5; ++i) {
        ASSERT_TRUE(fs::exists(out / frame(i))) << frame(i);
        frames.push_back(read_png(out / frame(i)));
        EXPECT_EQ(frames.back().width, 48);
        EXPECT_EQ(frames.back().height, 36);
    }
    EXPECT_FALSE(fs::exists(out / frame(5)));
    for (int i = 1; i < 5; ++i) EXPECT_NE(frames[i], frames[0]) << "frame " << i << " shows the same view";
    // One exposure: the same orbit at the reported exposure, fixed, gives the same frames (an exposure
    // taken per view would differ where the lit side turns away).
    const fs::path fixed = dir_ / "fixed";
    const auto f = run_waxwork("turntable " + volume_.string() + " -o " + fixed.string() +
                                   " --frames 5 --width 48 --height 36 --elevation 25 --exposure " +
                                   std::to_string(summary["exposure"].get<double>()),
                               kNoFfmpeg);
    ASSERT_EQ(f.exit_code, 0) << f.err;
    for (int i = 0; i < 5; ++i) EXPECT_EQ(read_png(fixed / frame(i)), frames[i]) << frame(i);
}

TEST_F(Turntable, CallsFfmpegWhenItIsOnThePath) {
    // A stand-in ffmpeg that records its arguments and writes its last one (the output).
    const fs::path bin = dir_ / "bin";
    fs::create_directories(bin);
    {
        std::ofstream script(bin / "ffmpeg");
        script << "#!/bin/sh\necho \"$@\" > \"" << (dir_ / "ffmpeg_args").string() << "\"\n"
               << "for last; do :; done\necho video > \"$last\"\n";
    }
    fs::permissions(bin / "ffmpeg", fs::perms::owner_all);
    const fs::path out = dir_ / "video";
    const auto r = run_waxwork("turntable " + volume_.string() + " -o " + out.string() +
                                   " --frames 3 --width 32 --height 24 --seconds-per-turn 2",
                               "PATH=" + bin.string() + " ");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["mp4"], (out / "turntable.mp4").string());
    EXPECT_TRUE(fs::exists(out / "turntable.mp4"));
    const std::string args = read_text(dir_ / "ffmpeg_args");
    EXPECT_NE(args.find("-framerate 1.5"), std::string::npos) << args;
    EXPECT_NE(args.find((out / "frame_%04d.png").string()), std::string::npos) << args;
}

TEST_F(Turntable, SessionIsReplayedWithItsCamera) {
    const fs::path session = dir_ / "s.json";
    {
        std::ofstream s(session);
        s << R"({"input": {"volume": "cube.vtu"}, "image": {"width": 40, "height": 30},
                 "camera": {"eye_direction": [0, 0.3, 1]},
                 "steps": [{"op": "plane_cut", "normal": [1, 0, 0], "offset": 0.3, "exact": true}, {"render": "x.png"}]})";
    }
    const fs::path out = dir_ / "session_spin";
    const auto r = run_waxwork("turntable " + session.string() + " -o " + out.string() + " --frames 2", kNoFfmpeg);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Image first = read_png(out / frame(0));
    EXPECT_EQ(first.width, 40);  // the session's size
    EXPECT_EQ(first.height, 30);
    EXPECT_FALSE(fs::exists(out / "x.png"));  // its render steps are not replayed
    EXPECT_NE(read_png(out / frame(1)), first);
}

TEST_F(Turntable, BadOptionsAreAOneLineError) {
    const fs::path out = dir_ / "bad";
    for (const std::string args : {" --frames 0", " --frames -3", " --frames abc", " --frames 100001", "",
                                   " --frames 4 --elevation 90", " --frames 4 --seconds-per-turn 0",
                                   " --frames 4 --background nope"}) {
        const auto r = run_waxwork("turntable " + volume_.string() + " -o " + out.string() + args, kNoFfmpeg);
        EXPECT_NE(r.exit_code, 0) << args;
        EXPECT_EQ(line_count(r.err), 1u) << args << ": " << r.err;
        EXPECT_EQ(r.err.rfind("waxwork: ", 0), 0u) << r.err;
    }
    const auto zero = run_waxwork("turntable " + volume_.string() + " -o " + out.string() + " --frames 0");
    EXPECT_NE(zero.err.find("--frames must be between 1 and 100000 (got 0)"), std::string::npos) << zero.err;
    EXPECT_FALSE(fs::exists(out / frame(0)));
}

}  // namespace
}  // namespace waxwork
