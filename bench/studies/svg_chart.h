// A small line chart: several named series of (x, y) points, linear or logarithmic axes with ticks and
// grid lines, axis labels, a title, a legend to the right of the plot, and a one-line caption. Used by
// `waxwork bench` for every chart, written as SVG and, from the same display list
// (bench/studies/chart_drawing.h), as PDF (bench/studies/pdf_chart.h) for print.
//
// Hand-written because Debian offers no C++ plotting library that fits: matplot++ and sciplot are not
// packaged, and gnuplot or Python would be run-time dependencies of a C++ tool for one picture. The
// format is plain SVG 1.1 (text, lines, polylines), viewable in any browser and diffable in review.
//
// Conventions: a series naming a method (bench/studies/method_style.h) always has that method's colour,
// marker and dash; other series take the palette in order. A series pinned to the bottom edge (a direct
// solve, exact to rounding) is drawn as a labelled marker there and does not stretch the y range.
#pragma once

#include "bench/studies/chart_drawing.h"

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace waxwork {

struct ChartSeries {
    std::string name;                               // legend label (empty with a method: the method's label)
    std::vector<std::pair<double, double>> points;  // (x, y), drawn in the given order
    bool markers = true;                            // a marker on every point (a lone point always gets one)
    std::string method{};                           // a method_style key, or empty
    // Per point, the (min, max) of x over repeated measurements: drawn as a band where min < max.
    std::vector<std::pair<double, double>> x_spread{};
    // Drawn as markers on the bottom edge of the plot with pin_label beside them, left out of the y range.
    bool pinned_to_bottom = false;
    std::string pin_label{};
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
    // The plot area is width - 270 by height - 105 or so; the legend sits right of it and the picture
    // widens to fit the legend's longest label, and grows by one line for a caption.
    int width = 800, height = 500;
    // A dashed horizontal line at this y (inside the data range), labelled target_label: e.g. 1% error.
    std::optional<double> target_line;
    std::string target_label;
    // Reference slope triangles, one per order (log-log charts only): error ~ size^order.
    std::vector<double> slope_orders;
    // One line under the chart: date, machine, threads, commit, device.
    std::string caption;
};

// The chart as a display list. Throws InvalidArgumentError for a non-positive size or non-finite points.
Drawing chart_drawing(const std::vector<ChartSeries>& series, const ChartOptions& options);

// The chart as SVG text (drawing_to_svg of chart_drawing).
std::string render_svg_chart(const std::vector<ChartSeries>& series, const ChartOptions& options);

// The chart written atomically to `path` (SVG) and beside it as PDF (path with extension .pdf);
// FileError on I/O failure.
void write_svg_chart(const std::filesystem::path& path, const std::vector<ChartSeries>& series,
                     const ChartOptions& options);

}  // namespace waxwork
