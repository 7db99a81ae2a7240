#include "base/error.h"
#include "bench/studies/method_style.h"
#include "bench/studies/svg_chart.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

namespace waxwork {
namespace {

size_t count(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

TEST(SvgChart, DrawsSeriesLegendAxesAndDecadeTicks) {
    ChartOptions options;
    options.title = "Errors <&> times";
    options.x = {"time (ms)", AxisScale::Linear, 0, 0};
    options.y = {"error", AxisScale::Log, 0, 0};
    const std::vector<ChartSeries> series = {
        {"first", {{1, 1}, {2, 0.1}, {3, 0.001}}, true},
        {"second", {{1.5, 0.5}, {4, 1e-5}}, false},
        {"lone", {{2.5, 1e-3}}, false},
    };
    const std::string svg = render_svg_chart(series, options);
    EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
    EXPECT_EQ(count(svg, "<polyline"), 2u);  // the lone point has no line
    EXPECT_EQ(count(svg, "<circle"), 3u + 1u + 1u);  // markers of "first", the lone point, "first"'s legend
    EXPECT_NE(svg.find("Errors &lt;&amp;&gt; times"), std::string::npos);
    for (const char* label : {"first", "second", "lone", "time (ms)", "error"})
        EXPECT_NE(svg.find(std::string(">") + label + "<"), std::string::npos) << label;
    // Decades from 1e-5 to 1 on the log axis.
    for (const char* tick : {">1e-5<", ">1e-4<", ">1e-3<", ">0.01<", ">0.1<", ">1<"})
        EXPECT_NE(svg.find(tick), std::string::npos) << tick;
    EXPECT_EQ(svg.find("nan"), std::string::npos);
}

TEST(SvgChart, SeriesBeyondThePaletteAreDashedNotRepeated) {
    ChartOptions options;
    options.x = {"x", AxisScale::Linear, 0, 0};
    options.y = {"y", AxisScale::Linear, 0, 0};
    std::vector<ChartSeries> series;
    const size_t palette = chart_palette().size();
    ASSERT_GT(palette, 8u);
    for (size_t k = 0; k < palette + 2; ++k)
        series.push_back({"s" + std::to_string(k), {{0, double(k)}, {1, double(k) + 0.5}}, false});
    const std::string svg = render_svg_chart(series, options);
    // Each series' line and its legend entry: the palette's colours solid, the two beyond it dashed.
    std::vector<std::string> styles;
    for (size_t at = svg.find("<polyline"); at != std::string::npos; at = svg.find("<polyline", at + 1)) {
        const std::string element = svg.substr(at, svg.find('>', at) - at);
        const size_t colour = element.find("stroke=\"");
        const size_t dash = element.find("stroke-dasharray");
        styles.push_back(element.substr(colour, 16) + (dash == std::string::npos ? "" : element.substr(dash, 24)));
    }
    ASSERT_EQ(styles.size(), palette + 2);
    for (size_t a = 0; a < styles.size(); ++a)
        for (size_t b = a + 1; b < styles.size(); ++b) EXPECT_NE(styles[a], styles[b]) << a << " and " << b;
    EXPECT_EQ(count(svg, "stroke-dasharray"), 2u * 2u);  // two lines, two legend entries
}

TEST(SvgChart, SkipsNonPositiveValuesOnLogAxesAndRejectsNonFinite) {
    ChartOptions options;
    options.y.scale = AxisScale::Log;
    const std::string svg = render_svg_chart({{"s", {{0, 0.0}, {1, 0.1}, {2, 0.01}}, true}}, options);
    EXPECT_EQ(count(svg, "<circle"), 2u + 1u);  // two points and the legend's marker
    EXPECT_THROW(render_svg_chart({{"s", {{0, std::nan("")}}, true}}, options), InvalidArgumentError);
    options.width = 10;
    EXPECT_THROW(render_svg_chart({}, options), InvalidArgumentError);
}

TEST(SvgChart, EmptyChartIsStillValid) {
    const std::string svg = render_svg_chart({}, ChartOptions{});
    EXPECT_NE(svg.find("</svg>"), std::string::npos);
}

// The value of attribute `name` in the first element of `svg` that starts with `element`.
double attribute(const std::string& svg, const std::string& element, const std::string& name) {
    const size_t at = svg.find(element);
    if (at == std::string::npos) return std::nan("");
    const size_t value = svg.find(name + "=\"", at);
    return std::strtod(svg.c_str() + value + name.size() + 2, nullptr);
}

// Every horizontal <text> element: its x, content, font size and whether it extends right of x.
struct Text {
    double x = 0;
    std::string content;
    double size = 12;
    bool from_start = true;
};
std::vector<Text> texts(const std::string& svg) {
    std::vector<Text> out;
    for (size_t at = svg.find("<text x=\""); at != std::string::npos; at = svg.find("<text x=\"", at + 1)) {
        Text t;
        t.x = std::strtod(svg.c_str() + at + 9, nullptr);
        const size_t open = svg.find('>', at) + 1;
        const std::string element = svg.substr(at, open - at);
        if (const size_t size = element.find("font-size=\""); size != std::string::npos)
            t.size = std::strtod(element.c_str() + size + 11, nullptr);
        t.from_start = element.find("text-anchor=\"start\"") != std::string::npos;
        t.content = svg.substr(open, svg.find("</text>", open) - open);
        out.push_back(t);
    }
    return out;
}

// A solver comparison's chart: iterative curves from 1 down to 1e-4 and a direct solve exact to 1e-16.
std::vector<ChartSeries> comparison_series() {
    std::vector<ChartSeries> series;
    for (const char* method : {"jacobi_cg", "multigrid_cg_rgb", "eigen_ic_cg"}) {
        ChartSeries s;
        s.method = method;
        s.points = {{1, 1}, {3, 0.05}, {9, 1e-3}, {20, 1e-4}};
        s.x_spread = {{0.9, 1.2}, {2.5, 3.5}, {8, 11}, {18, 25}};
        series.push_back(s);
    }
    ChartSeries direct;
    direct.method = "direct";
    direct.points = {{300, 2e-16}};
    direct.pinned_to_bottom = true;
    direct.pin_label = "CHOLMOD direct: 300 ms, error 2.0e-16";
    series.push_back(direct);
    return series;
}

ChartOptions comparison_options() {
    ChartOptions options;
    options.title = "Solvers (quick run)";
    options.x = {"solve time (ms)", AxisScale::Log, 0, 0};
    options.y = {"relative error", AxisScale::Log, 0, 0};
    options.target_line = 1e-2;
    options.target_label = "1% error";
    options.caption = "2026-11-28 | times: median of 5 runs after one warm-up | GPU curves: software GPU (llvmpipe)";
    return options;
}

TEST(SvgChart, MethodsKeepTheirColourAndLabelAcrossCharts) {
    const std::string svg = render_svg_chart(comparison_series(), comparison_options());
    for (const char* label : {">Jacobi CG (float)<", ">Multigrid CG (RGB frame solver)<", ">Eigen IC-CG<", ">CHOLMOD direct<"})
        EXPECT_NE(svg.find(label), std::string::npos) << label;
    // The same method alone, or after others, has its own colour, not the palette's first.
    std::vector<ChartSeries> alone = {comparison_series()[1]};
    const std::string colour = find_method_style("multigrid_cg_rgb")->colour;
    ASSERT_NE(colour, chart_palette()[0]);
    EXPECT_NE(render_svg_chart(alone, comparison_options()).find("stroke=\"" + colour + "\""), std::string::npos);
    EXPECT_NE(svg.find("stroke=\"" + colour + "\""), std::string::npos);
}

TEST(SvgChart, LegendAndCaptionFitInsideTheWidenedPicture) {
    const std::vector<ChartSeries> series = comparison_series();
    ChartOptions options = comparison_options();
    const std::string svg = render_svg_chart(series, options);
    const double width = attribute(svg, "<svg", "width");
    ASSERT_GT(width, options.width);  // widened for the legend's longest label
    ASSERT_FALSE(texts(svg).empty());
    for (const Text& t : texts(svg)) {
        // Start-anchored text ends its width right of x; the others end at or left of x.
        EXPECT_LE(t.x + (t.from_start ? text_width(t.content, t.size) : 0), width) << t.content;
        EXPECT_GE(t.x, 0.0) << t.content;
    }
    // The legend is right of the plot frame (its second corner is the top right).
    const size_t frame = svg.find("points=\"", svg.find("<polygon fill=\"none\""));
    ASSERT_NE(frame, std::string::npos);
    const double plot_right = std::strtod(svg.c_str() + svg.find(' ', frame) + 1, nullptr);
    bool legend_found = false;
    for (const Text& t : texts(svg))
        if (t.content == "Multigrid CG (RGB frame solver)") {
            legend_found = true;
            EXPECT_GT(t.x, plot_right);
        }
    EXPECT_TRUE(legend_found);
    EXPECT_NE(svg.find(options.caption), std::string::npos);
    EXPECT_GT(attribute(svg, "<svg", "height"), options.height);  // a line added for the caption
}

TEST(SvgChart, DirectSolveIsPinnedToTheBottomEdgeNotStretchingTheAxis) {
    const std::string svg = render_svg_chart(comparison_series(), comparison_options());
    EXPECT_NE(svg.find(">CHOLMOD direct: 300 ms, error 2.0e-16<"), std::string::npos);
    // The y axis ends at the iterative curves' decade, 1e-4, not at 1e-16.
    EXPECT_NE(svg.find(">1e-4<"), std::string::npos);
    EXPECT_EQ(svg.find(">1e-5<"), std::string::npos);
    EXPECT_EQ(svg.find(">1e-16<"), std::string::npos);
    // Without pinning the same point stretches it.
    std::vector<ChartSeries> unpinned = comparison_series();
    unpinned.back().pinned_to_bottom = false;
    EXPECT_NE(render_svg_chart(unpinned, comparison_options()).find(">1e-16<"), std::string::npos);
}

TEST(SvgChart, TargetLineBandsAndSlopeTriangles) {
    const std::string svg = render_svg_chart(comparison_series(), comparison_options());
    const size_t target = svg.find("<g class=\"target\">");
    ASSERT_NE(target, std::string::npos);
    EXPECT_NE(svg.find("stroke-dasharray", target), std::string::npos);
    EXPECT_NE(svg.find(">1% error<"), std::string::npos);
    EXPECT_EQ(count(svg, "<g class=\"band\">"), 3u);  // one per iterative method with spread
    // No spread (single runs): no band.
    std::vector<ChartSeries> single = comparison_series();
    for (ChartSeries& s : single)
        for (auto& [lo, hi] : s.x_spread) lo = hi;
    EXPECT_EQ(count(render_svg_chart(single, comparison_options()), "class=\"band\""), 0u);

    ChartOptions convergence;
    convergence.x = {"tet size (mm)", AxisScale::Log, 0, 0};
    convergence.y = {"error", AxisScale::Log, 0, 0};
    convergence.slope_orders = {1, 2};
    const std::string triangles = render_svg_chart({{"ball", {{0.5, 1e-3}, {1, 4e-3}, {2, 1.6e-2}}, true}}, convergence);
    EXPECT_EQ(count(triangles, "<g class=\"slope\">"), 2u);
    EXPECT_NE(triangles.find(">order 1<"), std::string::npos);
    EXPECT_NE(triangles.find(">order 2<"), std::string::npos);
}

}  // namespace
}  // namespace waxwork
