#include "bench/studies/svg_chart.h"

#include "base/error.h"
#include "bench/studies/method_style.h"
#include "bench/studies/pdf_chart.h"
#include "io/atomic_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

namespace waxwork {
namespace {

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

// The axis range: given, or from the data (pinned series count for x only) and `extra` values.
Range data_range(const std::vector<ChartSeries>& series, const ChartAxis& axis, bool is_x,
                 const std::vector<double>& extra) {
    if (axis.min < axis.max) return {axis.min, axis.max};
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    auto add = [&](double v) {
        if (axis.scale == AxisScale::Log && !(v > 0)) return;
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    };
    for (const auto& s : series) {
        if (s.pinned_to_bottom && !is_x) continue;
        for (const auto& [x, y] : s.points) add(is_x ? x : y);
        if (is_x)
            for (const auto& [a, b] : s.x_spread) {
                add(a);
                add(b);
            }
    }
    if (lo <= hi)  // extra values widen a range the data gave, never make one
        for (double v : extra) add(v);
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

// A series' look: its method's, else the palette's i-th colour, dashed (then dotted) past the palette.
struct Look {
    std::string colour;
    Marker marker = Marker::Circle;
    std::vector<double> dash;
};

Look look_of(const ChartSeries& s, size_t index) {
    if (const MethodStyle* style = find_method_style(s.method))
        return {style->colour, style->marker, style->dashed ? std::vector<double>{6, 3} : std::vector<double>{}};
    const std::vector<std::string>& palette = chart_palette();
    static const std::vector<double> dashes[] = {{}, {7, 4}, {2, 3}};
    return {palette[index % palette.size()], Marker::Circle, dashes[(index / palette.size()) % std::size(dashes)]};
}

std::string label_of(const ChartSeries& s) {
    if (!s.name.empty()) return s.name;
    const MethodStyle* style = find_method_style(s.method);
    return style ? style->label : s.method;
}

// The colour a quarter of the way from white to `colour`: the fill of an error band under its line.
std::string tint(const std::string& colour) {
    if (colour.size() != 7) return "#dddddd";
    std::string out = "#";
    for (size_t i = 0; i < 3; ++i) {
        const long v = std::strtol(colour.substr(1 + 2 * i, 2).c_str(), nullptr, 16);
        char hex[4];
        std::snprintf(hex, sizeof hex, "%02x", static_cast<int>(std::lround(255 - 0.25 * (255 - static_cast<double>(v)))));
        out += hex;
    }
    return out;
}

void add_marker(Drawing& d, Marker marker, double x, double y, const std::string& colour) {
    const double r = 3.5;
    auto polygon = [&](std::vector<std::pair<double, double>> points) {
        d.shapes.push_back(PathShape{std::move(points), true, std::nullopt, colour});
    };
    switch (marker) {
        case Marker::Circle: d.shapes.push_back(CircleShape{x, y, r, colour}); break;
        case Marker::Square: polygon({{x - r, y - r}, {x + r, y - r}, {x + r, y + r}, {x - r, y + r}}); break;
        case Marker::TriangleUp: polygon({{x, y - 1.2 * r}, {x + 1.1 * r, y + 0.8 * r}, {x - 1.1 * r, y + 0.8 * r}}); break;
        case Marker::TriangleDown: polygon({{x, y + 1.2 * r}, {x + 1.1 * r, y - 0.8 * r}, {x - 1.1 * r, y - 0.8 * r}}); break;
        case Marker::Diamond: polygon({{x, y - 1.3 * r}, {x + r, y}, {x, y + 1.3 * r}, {x - r, y}}); break;
        case Marker::Plus:
        case Marker::Cross: {
            const Stroke stroke{colour, 2, {}};
            const double a = marker == Marker::Plus ? 1.3 * r : r;
            if (marker == Marker::Plus) {
                d.shapes.push_back(LineShape{x - a, y, x + a, y, stroke});
                d.shapes.push_back(LineShape{x, y - a, x, y + a, stroke});
            } else {
                d.shapes.push_back(LineShape{x - a, y - a, x + a, y + a, stroke});
                d.shapes.push_back(LineShape{x - a, y + a, x + a, y - a, stroke});
            }
            break;
        }
    }
}

}  // namespace

Drawing chart_drawing(const std::vector<ChartSeries>& series, const ChartOptions& o) {
    if (o.width < 200 || o.height < 150 || o.width > 10000 || o.height > 10000)
        throw InvalidArgumentError("svg chart: size " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                                   " outside 200x150 .. 10000x10000");
    for (const auto& s : series) {
        for (const auto& [x, y] : s.points)
            if (!std::isfinite(x) || !std::isfinite(y))
                throw InvalidArgumentError("svg chart: series '" + label_of(s) + "' has a non-finite point");
        for (const auto& [a, b] : s.x_spread)
            if (!std::isfinite(a) || !std::isfinite(b))
                throw InvalidArgumentError("svg chart: series '" + label_of(s) + "' has a non-finite spread");
    }
    std::vector<double> extra_y;
    if (o.target_line) extra_y.push_back(*o.target_line);
    const Range xr = data_range(series, o.x, true, {}), yr = data_range(series, o.y, false, extra_y);
    const double left = 80, top = o.title.empty() ? 20 : 45, bottom = 60;
    const double plot_w = o.width - left - 190, plot_h = o.height - top - bottom;
    const double legend_x = left + plot_w + 15;
    double legend_w = 0;
    for (const auto& s : series) legend_w = std::max(legend_w, 32 + text_width(label_of(s), 12));
    Drawing d;
    d.width = std::max<double>(o.width, legend_x + legend_w + 10);
    d.height = o.height + (o.caption.empty() ? 0 : 18);
    if (!o.caption.empty()) d.width = std::max(d.width, 20 + text_width(o.caption, 10));
    const double title_w = text_width(o.title, 15);
    const double title_x = std::max(left + plot_w / 2, 5 + title_w / 2);
    d.width = std::max(d.width, title_x + title_w / 2 + 5);

    auto map = [](double v, Range r, AxisScale scale) {
        return scale == AxisScale::Log ? (std::log10(v) - std::log10(r.lo)) / (std::log10(r.hi) - std::log10(r.lo))
                                       : (v - r.lo) / (r.hi - r.lo);
    };
    auto px = [&](double x) { return left + plot_w * map(x, xr, o.x.scale); };
    auto py = [&](double y) { return top + plot_h * (1 - map(y, yr, o.y.scale)); };
    auto in_x = [&](double x) {
        if (o.x.scale == AxisScale::Log && !(x > 0)) return false;
        const double u = map(x, xr, o.x.scale);
        return u >= -1e-9 && u <= 1 + 1e-9;
    };
    auto visible = [&](double x, double y) {
        if (!in_x(x) || (o.y.scale == AxisScale::Log && !(y > 0))) return false;
        const double v = map(y, yr, o.y.scale);
        return v >= -1e-9 && v <= 1 + 1e-9;
    };
    auto text = [&](double x, double y, std::string s, double size, TextAnchor anchor, bool vertical = false) {
        d.shapes.push_back(TextShape{x, y, std::move(s), size, anchor, vertical});
    };

    if (!o.title.empty()) text(title_x, 25, o.title, 15, TextAnchor::Middle);
    // Grid, ticks and tick labels.
    const Stroke grid{"#dddddd", 1, {}};
    for (double t : ticks(xr, o.x.scale)) {
        d.shapes.push_back(LineShape{px(t), top, px(t), top + plot_h, grid});
        text(px(t), top + plot_h + 16, tick_label(t, o.x.scale), 12, TextAnchor::Middle);
    }
    for (double t : ticks(yr, o.y.scale)) {
        d.shapes.push_back(LineShape{left, py(t), left + plot_w, py(t), grid});
        text(left - 6, py(t) + 4, tick_label(t, o.y.scale), 12, TextAnchor::End);
    }
    d.shapes.push_back(PathShape{{{left, top}, {left + plot_w, top}, {left + plot_w, top + plot_h}, {left, top + plot_h}},
                                 true, Stroke{}, ""});
    text(left + plot_w / 2, o.height - 15, o.x.label, 12, TextAnchor::Middle);
    text(18, top + plot_h / 2, o.y.label, 12, TextAnchor::Middle, true);

    // Inside the plot: the target line, error bands, then the series.
    d.shapes.push_back(ClipBegin{left, top, plot_w, plot_h});
    if (o.target_line && visible(xr.lo, *o.target_line)) {
        d.shapes.push_back(GroupBegin{"target"});
        d.shapes.push_back(LineShape{left, py(*o.target_line), left + plot_w, py(*o.target_line), Stroke{"#555555", 1, {5, 4}}});
        text(left + 6, py(*o.target_line) - 4, o.target_label, 11, TextAnchor::Start);
        d.shapes.push_back(GroupEnd{});
    }
    for (size_t i = 0; i < series.size(); ++i) {
        const ChartSeries& s = series[i];
        if (s.pinned_to_bottom || s.x_spread.size() != s.points.size()) continue;
        std::vector<std::pair<double, double>> lower, upper;
        bool spread = false;
        for (size_t k = 0; k < s.points.size(); ++k) {
            const auto [a, b] = s.x_spread[k];
            const double y = s.points[k].second;
            if (!visible(s.points[k].first, y) || !in_x(a) || !in_x(b)) continue;
            spread = spread || a < b;
            lower.emplace_back(px(a), py(y));
            upper.emplace_back(px(b), py(y));
        }
        if (!spread || lower.size() < 2) continue;
        lower.insert(lower.end(), upper.rbegin(), upper.rend());
        d.shapes.push_back(GroupBegin{"band"});
        d.shapes.push_back(PathShape{std::move(lower), true, std::nullopt, tint(look_of(s, i).colour)});
        d.shapes.push_back(GroupEnd{});
    }
    std::vector<std::pair<size_t, std::pair<double, double>>> pins;  // (series, pixel point) on the bottom edge
    for (size_t i = 0; i < series.size(); ++i) {
        const ChartSeries& s = series[i];
        const Look look = look_of(s, i);
        if (s.pinned_to_bottom) {
            for (const auto& [x, y] : s.points)
                if (in_x(x)) pins.emplace_back(i, std::pair{px(x), top + plot_h});
            continue;
        }
        std::vector<std::pair<double, double>> shown;
        for (const auto& [x, y] : s.points)
            if (visible(x, y)) shown.emplace_back(px(x), py(y));
        d.shapes.push_back(GroupBegin{s.method.empty() ? "series" : s.method});
        if (shown.size() > 1) d.shapes.push_back(PathShape{shown, false, Stroke{look.colour, 2, look.dash}, ""});
        if (s.markers || shown.size() == 1)
            for (const auto& [x, y] : shown) add_marker(d, look.marker, x, y, look.colour);
        d.shapes.push_back(GroupEnd{});
    }
    d.shapes.push_back(ClipEnd{});

    // Pinned points: the marker on the bottom edge (unclipped, so whole), the label above it, kept inside.
    for (const auto& [i, point] : pins) {
        const ChartSeries& s = series[i];
        d.shapes.push_back(GroupBegin{s.method.empty() ? "pinned" : s.method});
        add_marker(d, look_of(s, i).marker, point.first, point.second, look_of(s, i).colour);
        const std::string label = s.pin_label.empty() ? label_of(s) : s.pin_label;
        const bool right_half = point.first > left + plot_w / 2;
        text(right_half ? point.first - 4 : point.first + 4, point.second - 8, label, 11,
             right_half ? TextAnchor::End : TextAnchor::Start);
        d.shapes.push_back(GroupEnd{});
    }

    // Reference slopes on a log-log chart: triangles along the bottom right, legs in decades.
    if (o.x.scale == AxisScale::Log && o.y.scale == AxisScale::Log && !o.slope_orders.empty()) {
        const double x_decades = std::log10(xr.hi / xr.lo), y_decades = std::log10(yr.hi / yr.lo);
        const double base = 0.12 * plot_w;
        double right_end = left + plot_w - 20;
        for (double order : o.slope_orders) {
            const double rise = order * (base / plot_w * x_decades) / y_decades * plot_h;
            if (!(rise > 0) || rise > 0.8 * plot_h) continue;
            const double y0 = top + plot_h - 12;
            d.shapes.push_back(GroupBegin{"slope"});
            d.shapes.push_back(PathShape{{{right_end - base, y0}, {right_end, y0}, {right_end, y0 - rise}}, true,
                                         Stroke{"#555555", 1, {}}, ""});
            char label[32];
            std::snprintf(label, sizeof label, "order %g", order);
            text(right_end - base / 2, y0 - rise / 2 - 4, label, 11, TextAnchor::End);
            d.shapes.push_back(GroupEnd{});
            right_end -= base + 40;
        }
    }

    // Legend, right of the plot.
    for (size_t i = 0; i < series.size(); ++i) {
        const ChartSeries& s = series[i];
        const Look look = look_of(s, i);
        const double ly = top + 10 + 20.0 * static_cast<double>(i);
        d.shapes.push_back(GroupBegin{"legend"});
        if (!s.pinned_to_bottom) d.shapes.push_back(LineShape{legend_x, ly, legend_x + 25, ly, Stroke{look.colour, 2, look.dash}});
        if (s.markers || s.pinned_to_bottom) add_marker(d, look.marker, legend_x + 12.5, ly, look.colour);
        text(legend_x + 32, ly + 4, label_of(s), 12, TextAnchor::Start);
        d.shapes.push_back(GroupEnd{});
    }
    if (!o.caption.empty()) text(10, d.height - 8, o.caption, 10, TextAnchor::Start);
    return d;
}

std::string render_svg_chart(const std::vector<ChartSeries>& series, const ChartOptions& options) {
    return drawing_to_svg(chart_drawing(series, options));
}

void write_svg_chart(const std::filesystem::path& path, const std::vector<ChartSeries>& series,
                     const ChartOptions& options) {
    const Drawing drawing = chart_drawing(series, options);
    const std::string text = drawing_to_svg(drawing);
    write_file_atomically(path, [&](std::ostream& out) { out << text; });
    std::filesystem::path pdf = path;
    write_pdf_drawing(pdf.replace_extension(".pdf"), drawing);
}

}  // namespace waxwork
