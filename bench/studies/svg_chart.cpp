#include "bench/studies/svg_chart.h"

#include "base/error.h"
#include "io/atomic_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace waxwork {
namespace {

// Colour-blind-safe palette (Okabe and Ito), cycled; each further cycle draws dashed (the solver
// comparison has ten series), so no two series of a chart look alike.
constexpr const char* kColours[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#F0E442"};
constexpr const char* kDashes[] = {"", " stroke-dasharray=\"7 4\"", " stroke-dasharray=\"2 3\""};

std::string escape(const std::string& text) {
    std::string out;
    for (char c : text) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            default: out += c;
        }
    }
    return out;
}

std::string number(double v) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.2f", v);
    return buffer;
}

std::string tick_label(double v, AxisScale scale) {
    char buffer[32];
    if (scale == AxisScale::Log) {
        const double e = std::round(std::log10(v));
        if (e >= -2 && e <= 3)
            std::snprintf(buffer, sizeof buffer, "%g", std::pow(10.0, e));
        else
            std::snprintf(buffer, sizeof buffer, "1e%d", static_cast<int>(e));
    } else {
        std::snprintf(buffer, sizeof buffer, "%g", std::abs(v) < 1e-12 ? 0.0 : v);
    }
    return buffer;
}

struct Range {
    double lo, hi;
};

Range data_range(const std::vector<ChartSeries>& series, const ChartAxis& axis, bool is_x) {
    if (axis.min < axis.max) return {axis.min, axis.max};
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& s : series)
        for (const auto& [x, y] : s.points) {
            const double v = is_x ? x : y;
            if (axis.scale == AxisScale::Log && !(v > 0)) continue;
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
    if (!(lo <= hi)) return axis.scale == AxisScale::Log ? Range{1, 10} : Range{0, 1};
    if (axis.scale == AxisScale::Log) {
        lo = std::pow(10.0, std::floor(std::log10(lo)));
        hi = std::pow(10.0, std::ceil(std::log10(hi)));
        if (hi <= lo) hi = lo * 10;
        return {lo, hi};
    }
    if (hi == lo) {
        lo -= 1;
        hi += 1;
    }
    const double pad = 0.04 * (hi - lo);
    return {lo >= 0 && lo - pad < 0 ? 0.0 : lo - pad, hi + pad};
}

std::vector<double> ticks(Range r, AxisScale scale) {
    std::vector<double> out;
    if (scale == AxisScale::Log) {
        const int first = static_cast<int>(std::ceil(std::log10(r.lo) - 1e-9));
        const int last = static_cast<int>(std::floor(std::log10(r.hi) + 1e-9));
        const int step = std::max(1, (last - first) / 10 + 1);
        for (int e = first; e <= last; e += step) out.push_back(std::pow(10.0, e));
        return out;
    }
    const double raw = (r.hi - r.lo) / 6;
    const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
    double step = magnitude;
    for (double m : {1.0, 2.0, 5.0, 10.0})
        if (m * magnitude >= raw) {
            step = m * magnitude;
            break;
        }
    for (double v = std::ceil(r.lo / step) * step; v <= r.hi + 1e-9 * step; v += step) out.push_back(v);
    return out;
}

}  // namespace

std::string render_svg_chart(const std::vector<ChartSeries>& series, const ChartOptions& o) {
    if (o.width < 200 || o.height < 150 || o.width > 10000 || o.height > 10000)
        throw InvalidArgumentError("svg chart: size " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                                   " outside 200x150 .. 10000x10000");
    for (const auto& s : series)
        for (const auto& [x, y] : s.points)
            if (!std::isfinite(x) || !std::isfinite(y))
                throw InvalidArgumentError("svg chart: series '" + s.name + "' has a non-finite point");
    const Range xr = data_range(series, o.x, true), yr = data_range(series, o.y, false);
    const double left = 80, right = 190, top = o.title.empty() ? 20 : 45, bottom = 60;
    const double plot_w = o.width - left - right, plot_h = o.height - top - bottom;
    auto map = [](double v, Range r, AxisScale scale) {
        return scale == AxisScale::Log ? (std::log10(v) - std::log10(r.lo)) / (std::log10(r.hi) - std::log10(r.lo))
                                       : (v - r.lo) / (r.hi - r.lo);
    };
    auto px = [&](double x) { return left + plot_w * map(x, xr, o.x.scale); };
    auto py = [&](double y) { return top + plot_h * (1 - map(y, yr, o.y.scale)); };
    auto visible = [&](double x, double y) {
        if (o.x.scale == AxisScale::Log && !(x > 0)) return false;
        if (o.y.scale == AxisScale::Log && !(y > 0)) return false;
        const double u = map(x, xr, o.x.scale), v = map(y, yr, o.y.scale);
        return u >= -1e-9 && u <= 1 + 1e-9 && v >= -1e-9 && v <= 1 + 1e-9;
    };

    std::ostringstream svg;
    svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << o.width << "\" height=\"" << o.height
        << "\" viewBox=\"0 0 " << o.width << " " << o.height << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
        << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    if (!o.title.empty())
        svg << "<text x=\"" << number(left + plot_w / 2) << "\" y=\"25\" text-anchor=\"middle\" font-size=\"15\">"
            << escape(o.title) << "</text>\n";
    // Grid, ticks and tick labels.
    for (double t : ticks(xr, o.x.scale)) {
        const std::string x = number(px(t));
        svg << "<line x1=\"" << x << "\" y1=\"" << number(top) << "\" x2=\"" << x << "\" y2=\"" << number(top + plot_h)
            << "\" stroke=\"#dddddd\"/>\n"
            << "<text x=\"" << x << "\" y=\"" << number(top + plot_h + 16) << "\" text-anchor=\"middle\">"
            << tick_label(t, o.x.scale) << "</text>\n";
    }
    for (double t : ticks(yr, o.y.scale)) {
        const std::string y = number(py(t));
        svg << "<line x1=\"" << number(left) << "\" y1=\"" << y << "\" x2=\"" << number(left + plot_w) << "\" y2=\"" << y
            << "\" stroke=\"#dddddd\"/>\n"
            << "<text x=\"" << number(left - 6) << "\" y=\"" << y << "\" dy=\"4\" text-anchor=\"end\">"
            << tick_label(t, o.y.scale) << "</text>\n";
    }
    svg << "<rect x=\"" << number(left) << "\" y=\"" << number(top) << "\" width=\"" << number(plot_w) << "\" height=\""
        << number(plot_h) << "\" fill=\"none\" stroke=\"black\"/>\n";
    svg << "<text x=\"" << number(left + plot_w / 2) << "\" y=\"" << number(o.height - 15)
        << "\" text-anchor=\"middle\">" << escape(o.x.label) << "</text>\n";
    svg << "<text transform=\"translate(18," << number(top + plot_h / 2) << ") rotate(-90)\" text-anchor=\"middle\">"
        << escape(o.y.label) << "</text>\n";
    // Series, clipped to the plot area, then the legend.
    svg << "<defs><clipPath id=\"plot\"><rect x=\"" << number(left) << "\" y=\"" << number(top) << "\" width=\""
        << number(plot_w) << "\" height=\"" << number(plot_h) << "\"/></clipPath></defs>\n";
    for (size_t i = 0; i < series.size(); ++i) {
        const ChartSeries& s = series[i];
        const char* colour = kColours[i % std::size(kColours)];
        const char* dash = kDashes[(i / std::size(kColours)) % std::size(kDashes)];
        std::vector<std::pair<double, double>> shown;
        for (const auto& [x, y] : s.points)
            if (visible(x, y)) shown.emplace_back(px(x), py(y));
        svg << "<g clip-path=\"url(#plot)\">";
        if (shown.size() > 1) {
            svg << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"2\"" << dash << " points=\"";
            for (const auto& [x, y] : shown) svg << number(x) << "," << number(y) << " ";
            svg << "\"/>";
        }
        if (s.markers || shown.size() == 1)
            for (const auto& [x, y] : shown)
                svg << "<circle cx=\"" << number(x) << "\" cy=\"" << number(y) << "\" r=\"3\" fill=\"" << colour << "\"/>";
        svg << "</g>\n";
        const double ly = top + 10 + 20.0 * static_cast<double>(i);
        const double lx = left + plot_w + 15;
        svg << "<line x1=\"" << number(lx) << "\" y1=\"" << number(ly) << "\" x2=\"" << number(lx + 25) << "\" y2=\""
            << number(ly) << "\" stroke=\"" << colour << "\" stroke-width=\"2\"" << dash << "/>"
            << "<text x=\"" << number(lx + 32) << "\" y=\"" << number(ly) << "\" dy=\"4\">" << escape(s.name)
            << "</text>\n";
    }
    svg << "</svg>\n";
    return svg.str();
}

void write_svg_chart(const std::filesystem::path& path, const std::vector<ChartSeries>& series,
                     const ChartOptions& options) {
    const std::string text = render_svg_chart(series, options);
    write_file_atomically(path, [&](std::ostream& out) { out << text; });
}

}  // namespace waxwork
