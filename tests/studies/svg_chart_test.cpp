#include "base/error.h"
#include "bench/studies/svg_chart.h"

#include <gtest/gtest.h>

#include <cmath>

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
    EXPECT_EQ(count(svg, "<circle"), 3u + 1u);  // markers of "first" and the lone point
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
    for (int k = 0; k < 10; ++k) series.push_back({"s" + std::to_string(k), {{0, double(k)}, {1, k + 0.5}}, false});
    const std::string svg = render_svg_chart(series, options);
    // Each series' line and its legend entry: the first eight solid, the ninth and tenth dashed.
    std::vector<std::string> styles;
    for (size_t at = svg.find("<polyline"); at != std::string::npos; at = svg.find("<polyline", at + 1)) {
        const std::string element = svg.substr(at, svg.find('>', at) - at);
        const size_t colour = element.find("stroke=\"");
        const size_t dash = element.find("stroke-dasharray");
        styles.push_back(element.substr(colour, 16) + (dash == std::string::npos ? "" : element.substr(dash, 24)));
    }
    ASSERT_EQ(styles.size(), 10u);
    for (size_t a = 0; a < styles.size(); ++a)
        for (size_t b = a + 1; b < styles.size(); ++b) EXPECT_NE(styles[a], styles[b]) << a << " and " << b;
    EXPECT_EQ(count(svg, "stroke-dasharray"), 2u * 2u);  // two lines, two legend entries
}

TEST(SvgChart, SkipsNonPositiveValuesOnLogAxesAndRejectsNonFinite) {
    ChartOptions options;
    options.y.scale = AxisScale::Log;
    const std::string svg = render_svg_chart({{"s", {{0, 0.0}, {1, 0.1}, {2, 0.01}}, true}}, options);
    EXPECT_EQ(count(svg, "<circle"), 2u);
    EXPECT_THROW(render_svg_chart({{"s", {{0, std::nan("")}}, true}}, options), InvalidArgumentError);
    options.width = 10;
    EXPECT_THROW(render_svg_chart({}, options), InvalidArgumentError);
}

TEST(SvgChart, EmptyChartIsStillValid) {
    const std::string svg = render_svg_chart({}, ChartOptions{});
    EXPECT_NE(svg.find("</svg>"), std::string::npos);
}

}  // namespace
}  // namespace waxwork
