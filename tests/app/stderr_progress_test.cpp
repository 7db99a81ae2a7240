#include "app/stderr_progress.h"

#include <gtest/gtest.h>

#include <chrono>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>

namespace waxwork {
namespace {

// Captures std::cerr while alive.
class CerrCapture {
public:
    CerrCapture() : old_(std::cerr.rdbuf(text_.rdbuf())) {}
    ~CerrCapture() { std::cerr.rdbuf(old_); }
    std::string text() const { return text_.str(); }

private:
    std::ostringstream text_;
    std::streambuf* old_;
};

// Waits (at most 20 s, never asserting a time) until `capture` holds `fragment`.
bool wait_for(const CerrCapture& capture, const std::string& fragment) {
    for (int i = 0; i < 2000; ++i) {
        if (capture.text().find(fragment) != std::string::npos) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
}

// A stage that runs past the first delay (here 0 s) is shown as one status line rewritten in place,
// and the line is blanked when the work ends: stderr gains no line, so an error after it is still
// the one line the command line promises.
TEST(StderrProgress, ShowsTheRunningStageOnOneLineAndBlanksItAtTheEnd) {
    CerrCapture capture;
    {
        StderrProgress progress("waxwork: horse.ply: ", 0.0, 0.01);
        progress.set_stage("repairing (removing self-intersections)");
        EXPECT_TRUE(wait_for(capture, "\rwaxwork: horse.ply: repairing (removing self-intersections)... 0 s"))
            << capture.text();
        progress.set_stage("meshing (TetGen)");
        EXPECT_TRUE(wait_for(capture, "\rwaxwork: horse.ply: meshing (TetGen)... 0 s")) << capture.text();
        progress.finish();
    }
    const std::string text = capture.text();
    EXPECT_EQ(text.find('\n'), std::string::npos) << text;
    EXPECT_EQ(text.back(), '\r');  // the blanked line leaves the cursor at its start
}

// Stages shorter than the first delay print nothing.
TEST(StderrProgress, QuickStagesPrintNothing) {
    CerrCapture capture;
    {
        StderrProgress progress("waxwork: cube.obj: ", 3600.0);
        progress.set_stage("reading");
        progress.set_stage("meshing (TetGen)");
    }
    EXPECT_EQ(capture.text(), "");
}

}  // namespace
}  // namespace waxwork
