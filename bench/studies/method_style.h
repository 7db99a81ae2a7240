// How each solver method looks in every chart: one colour, marker, dash and legend label per method
// name (the solver comparison's JSON keys), so a method is recognised across charts and papers. The
// colours are all distinct (Okabe and Ito's colour-blind-safe eight, less their yellow, then Tol's
// muted scheme); the GPU methods are dashed, as they ran on whatever device the run had.
#pragma once

#include <string>
#include <vector>

namespace waxwork {

enum class Marker { Circle, Square, TriangleUp, TriangleDown, Diamond, Plus, Cross };

struct MethodStyle {
    std::string key;     // the method's name in the JSON, e.g. "jacobi_cg"
    std::string label;   // its legend label, e.g. "Jacobi CG (float)"
    std::string colour;  // "#rrggbb"
    Marker marker = Marker::Circle;
    bool dashed = false;
};

// Every method with a fixed style, in the solver comparison's order.
const std::vector<MethodStyle>& method_styles();

// The style of `key`; null for a name not in the table.
const MethodStyle* find_method_style(const std::string& key);

// Colours for series that are not methods (a chart's i-th series), all distinct from one another; a
// chart with more series than this repeats them dashed.
const std::vector<std::string>& chart_palette();

}  // namespace waxwork
