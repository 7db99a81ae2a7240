// drawing_to_pdf (bench/studies/pdf_chart.h): a structurally valid PDF (every cross-reference offset
// points at its object, startxref at the table), Helvetica text escaped, and, where poppler's pdftoppm
// is installed, a file it renders.
#include "bench/studies/pdf_chart.h"
#include "bench/studies/svg_chart.h"

#include "support/scratch_dir.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace waxwork {
namespace {

Drawing sample_drawing() {
    ChartOptions options;
    options.title = "Errors (a) \\ times (quick run)";
    options.x = {"time (ms)", AxisScale::Log, 0, 0};
    options.y = {"error", AxisScale::Log, 0, 0};
    options.target_line = 1e-2;
    options.target_label = "1% error";
    options.caption = "2026-11-28 | 5 runs";
    ChartSeries direct{"", {{100, 1e-16}}, true, "direct", {}, true, "direct: 100 ms, error 1e-16"};
    return chart_drawing({{"", {{1, 1}, {2, 0.1}, {4, 1e-3}}, true, "jacobi_cg", {{0.9, 1.1}, {1.8, 2.5}, {3.5, 5}}},
                          {"", {{1, 1}, {3, 1e-3}}, true, "eigen_ic_cg"},
                          direct},
                         options);
}

TEST(PdfChart, CrossReferenceOffsetsPointAtTheirObjects) {
    const std::string pdf = drawing_to_pdf(sample_drawing());
    ASSERT_EQ(pdf.rfind("%PDF-1.4\n", 0), 0u);
    EXPECT_EQ(pdf.substr(pdf.size() - 6), "%%EOF\n");
    const size_t startxref = pdf.rfind("startxref\n");
    ASSERT_NE(startxref, std::string::npos);
    const size_t xref = std::stoul(pdf.substr(startxref + 10));
    ASSERT_EQ(pdf.compare(xref, 5, "xref\n"), 0);
    std::istringstream table(pdf.substr(xref + 5));
    int first = -1, count = 0;
    table >> first >> count;
    ASSERT_EQ(first, 0);
    ASSERT_EQ(count, 6);  // the free entry and five objects
    std::string offset, generation, kind;
    table >> offset >> generation >> kind;
    EXPECT_EQ(kind, "f");
    for (int object = 1; object < count; ++object) {
        table >> offset >> generation >> kind;
        ASSERT_EQ(offset.size(), 10u);
        EXPECT_EQ(kind, "n");
        const std::string header = std::to_string(object) + " 0 obj";
        EXPECT_EQ(pdf.compare(std::stoul(offset), header.size(), header), 0) << "object " << object;
    }
    // The content stream's /Length is its byte count.
    const size_t length_at = pdf.find("/Length ");
    const size_t length = std::stoul(pdf.substr(length_at + 8));
    const size_t data = pdf.find("stream\n", length_at) + 7;
    EXPECT_EQ(pdf.compare(data + length, 9, "endstream"), 0);
    // Text: Helvetica, parentheses and backslash escaped.
    EXPECT_NE(pdf.find("/BaseFont /Helvetica"), std::string::npos);
    EXPECT_NE(pdf.find("(Errors \\(a\\) \\\\ times \\(quick run\\)) Tj"), std::string::npos);
    EXPECT_NE(pdf.find("(1% error) Tj"), std::string::npos);
    EXPECT_NE(pdf.find("(2026-11-28 | 5 runs) Tj"), std::string::npos);
}

TEST(PdfChart, PdftoppmRendersTheWrittenChart) {
    const auto dir = testing::scratch_dir("pdf_chart");
    ChartOptions options;
    options.x = {"x", AxisScale::Linear, 0, 0};
    options.y = {"y", AxisScale::Log, 0, 0};
    options.caption = "caption";
    write_svg_chart(dir / "chart.svg", {{"line", {{0, 1}, {1, 0.1}}, true}}, options);
    ASSERT_TRUE(std::filesystem::exists(dir / "chart.svg"));
    ASSERT_TRUE(std::filesystem::exists(dir / "chart.pdf"));  // written beside the SVG
    std::ofstream(dir / "sample.pdf", std::ios::binary) << drawing_to_pdf(sample_drawing());
    if (std::system("command -v pdftoppm > /dev/null 2>&1") != 0) GTEST_SKIP() << "pdftoppm not installed";
    for (const char* name : {"chart", "sample"}) {
        const std::string pdf = (dir / (std::string(name) + ".pdf")).string();
        const std::string command = "pdftoppm -r 300 -png " + pdf + " " + (dir / name).string() + " 2> " +
                                    (dir / (std::string(name) + ".err")).string();
        EXPECT_EQ(std::system(command.c_str()), 0) << name;
        std::ifstream err(dir / (std::string(name) + ".err"));
        const std::string errors((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
        EXPECT_TRUE(errors.empty()) << name << ": " << errors;  // poppler reports repairs on stderr
        EXPECT_TRUE(std::filesystem::exists(dir / (std::string(name) + "-1.png"))) << name;
    }
}

}  // namespace
}  // namespace waxwork
