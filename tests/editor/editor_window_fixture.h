// What the window tests share (`waxwork edit` under a virtual X server, xvfb-run): a fixture that skips
// where xvfb-run is missing, the summary line `edit --screenshot` prints, and measures of the PNGs the
// editor and `waxwork render` write.
#pragma once

#include "io/image_io.h"
#include "support/cli_run.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdlib>
#include <string>

namespace waxwork::testing {

// The fixture of every window test: skipped without xvfb-run.
class WindowTest : public ::testing::Test {
protected:
    void SetUp() override {
        if (!have_xvfb()) GTEST_SKIP() << "xvfb-run is not installed (setup.sh installs xvfb and xauth)";
    }
};

// The summary line `edit --screenshot` prints (empty when there is none).
inline nlohmann::json summary_of(const CommandResult& r) {
    const size_t start = r.out.find('{');
    if (start == std::string::npos) return {};
    return nlohmann::json::parse(r.out.substr(start));
}

// Mean of r + g + b over a rectangle.
inline double mean_brightness(const Image& image, int x0, int y0, int x1, int y1) {
    double sum = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) sum += image.pixel(x, y)[0] + image.pixel(x, y)[1] + image.pixel(x, y)[2];
    return sum / ((x1 - x0) * static_cast<double>(y1 - y0));
}

// The largest difference of one channel of one pixel between two images of the same size.
inline int max_channel_difference(const Image& a, const Image& b) {
    int largest = 0;
    for (size_t i = 0; i < a.rgba.size(); ++i) largest = std::max(largest, std::abs(a.rgba[i] - b.rgba[i]));
    return largest;
}

}  // namespace waxwork::testing
