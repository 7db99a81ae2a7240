// A small SVG line chart: several named series of (x, y) points, linear or logarithmic axes with
// ticks and grid lines, axis labels, a title and a legend. Used by `waxwork bench` for every chart.
//
// Hand-written because Debian offers no C++ plotting library that fits: matplot++ and sciplot are not
// packaged, and gnuplot or Python would be run-time dependencies of a C++ tool for one picture. The
// format is plain SVG 1.1 (text, lines, polylines), viewable in any browser and diffable in review.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace waxwork {

struct ChartSeries {
    std::string name;
    std::vector<std::pair<double, double>> points;  // (x, y), drawn in the given order
    bool markers = true;                            // a dot on every point (a lone point always gets one)
};

enum class AxisScale { Linear, Log };

struct ChartAxis {
    std::string label;
    AxisScale scale = AxisScale::Linear;
    // Range; when min >= max it is taken from the data (padded, and on a log axis widened to whole
    // decades). Points outside the range, and points <= 0 on a log axis, are not drawn.
    double min = 0, max = 0;
};

struct ChartOptions {
    std::string title;
    ChartAxis x, y;
    int width = 800, height = 500;
};

// The chart as SVG text. Throws InvalidArgumentError for a non-positive size or non-finite points.
std::string render_svg_chart(const std::vector<ChartSeries>& series, const ChartOptions& options);

// render_svg_chart written atomically (io/atomic_file.h); FileError on I/O failure.
void write_svg_chart(const std::filesystem::path& path, const std::vector<ChartSeries>& series,
                     const ChartOptions& options);

}  // namespace waxwork
