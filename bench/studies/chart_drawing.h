// A chart as a display list: lines, paths, circles and text in points (1/72 inch, y down), so that one
// layout (bench/studies/svg_chart.h) renders to SVG here and to PDF (bench/studies/pdf_chart.h) with the
// same geometry. Colours are "#rrggbb". Text is measured with Helvetica's metrics (text_width), the font
// both renderers name, so a label placed from its width fits in either.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace waxwork {

struct Stroke {
    std::string colour = "#000000";
    double width = 1;
    std::vector<double> dash;  // on, off, ... lengths; empty: solid
};

struct LineShape {
    double x1 = 0, y1 = 0, x2 = 0, y2 = 0;
    Stroke stroke;
};

// An open polyline or, when closed, a polygon; drawn filled (fill non-empty) and/or stroked.
struct PathShape {
    std::vector<std::pair<double, double>> points;
    bool closed = false;
    std::optional<Stroke> stroke;
    std::string fill;  // empty: not filled
};

struct CircleShape {
    double cx = 0, cy = 0, r = 1;
    std::string fill = "#000000";
};

enum class TextAnchor { Start, Middle, End };

struct TextShape {
    double x = 0, y = 0;  // baseline point of the anchor
    std::string text;     // UTF-8; the PDF keeps Latin-1 and writes '?' for the rest
    double size = 12;
    TextAnchor anchor = TextAnchor::Start;
    bool vertical = false;  // rotated 90 degrees counter-clockwise about (x, y)
};

// Shapes between ClipBegin and ClipEnd are clipped to the rectangle; begin and end pair up, not nested.
struct ClipBegin {
    double x = 0, y = 0, width = 0, height = 0;
};
struct ClipEnd {};

// A named group: in SVG a <g class="NAME">, so a series can be found by its method key; ignored in PDF.
struct GroupBegin {
    std::string name;
};
struct GroupEnd {};

using Shape = std::variant<LineShape, PathShape, CircleShape, TextShape, ClipBegin, ClipEnd, GroupBegin, GroupEnd>;

struct Drawing {
    double width = 0, height = 0;
    std::vector<Shape> shapes;  // painted in order
};

// UTF-8 text as Latin-1 bytes (PDF's WinAnsi encoding agrees on the printable ones); any other
// character becomes '?'.
std::string to_latin1(const std::string& utf8);

// The width of `text` in Helvetica at `size` points (Latin-1 glyphs; others counted as wide ones).
double text_width(const std::string& text, double size);

// The drawing as an SVG 1.1 document, one pixel per point.
std::string drawing_to_svg(const Drawing& drawing);

}  // namespace waxwork
