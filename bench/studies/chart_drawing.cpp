#include "bench/studies/chart_drawing.h"

#include <cstdio>
#include <sstream>

namespace waxwork {
namespace {

// Helvetica's advance widths (1/1000 em) for ASCII 32..126, from its Adobe font metrics.
constexpr int kHelveticaWidths[95] = {
    278, 278, 355, 556, 556, 889, 667, 222, 333, 333, 389, 584, 278, 333, 278, 278,  // ' ' .. '/'
    556, 556, 556, 556, 556, 556, 556, 556, 556, 556,                                // '0' .. '9'
    278, 278, 584, 584, 584, 556, 1015,                                              // ':' .. '@'
    667, 667, 722, 722, 667, 611, 778, 722, 278, 500, 667, 556, 833,                 // 'A' .. 'M'
    722, 778, 667, 778, 722, 667, 611, 722, 667, 944, 667, 667, 611,                 // 'N' .. 'Z'
    278, 278, 278, 469, 556, 222,                                                    // '[' .. '`'
    556, 556, 500, 556, 556, 278, 556, 556, 222, 222, 500, 222, 833,                 // 'a' .. 'm'
    556, 556, 556, 556, 333, 500, 278, 556, 500, 722, 500, 500, 500,                 // 'n' .. 'z'
    334, 260, 334, 584};                                                             // '{' .. '~'

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

std::string stroke_attributes(const Stroke& s) {
    std::string out = " stroke=\"" + s.colour + "\" stroke-width=\"" + number(s.width) + "\"";
    if (!s.dash.empty()) {
        out += " stroke-dasharray=\"";
        for (size_t i = 0; i < s.dash.size(); ++i) out += (i ? " " : "") + number(s.dash[i]);
        out += "\"";
    }
    return out;
}

}  // namespace

std::string to_latin1(const std::string& utf8) {
    std::string out;
    for (size_t i = 0; i < utf8.size();) {
        const auto c = static_cast<unsigned char>(utf8[i]);
        if (c < 0x80) {
            out += static_cast<char>(c);
            ++i;
        } else if ((c & 0xE0) == 0xC0 && i + 1 < utf8.size()) {
            const unsigned code = ((c & 0x1Fu) << 6) | (static_cast<unsigned char>(utf8[i + 1]) & 0x3Fu);
            out += code >= 0xA0 && code <= 0xFF ? static_cast<char>(code) : '?';
            i += 2;
        } else {
            out += '?';
            ++i;
            while (i < utf8.size() && (static_cast<unsigned char>(utf8[i]) & 0xC0) == 0x80) ++i;
        }
    }
    return out;
}

double text_width(const std::string& text, double size) {
    double units = 0;
    for (char ch : to_latin1(text)) {
        const auto c = static_cast<unsigned char>(ch);
        units += c >= 32 && c <= 126 ? kHelveticaWidths[c - 32] : 667;
    }
    return units * size / 1000;
}

std::string drawing_to_svg(const Drawing& d) {
    std::ostringstream svg;
    svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << number(d.width) << "\" height=\"" << number(d.height)
        << "\" viewBox=\"0 0 " << number(d.width) << " " << number(d.height)
        << "\" font-family=\"Helvetica, Arial, sans-serif\" font-size=\"12\">\n"
        << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    int clips = 0;
    for (const Shape& shape : d.shapes) {
        if (const auto* l = std::get_if<LineShape>(&shape)) {
            svg << "<line x1=\"" << number(l->x1) << "\" y1=\"" << number(l->y1) << "\" x2=\"" << number(l->x2)
                << "\" y2=\"" << number(l->y2) << "\"" << stroke_attributes(l->stroke) << "/>\n";
        } else if (const auto* p = std::get_if<PathShape>(&shape)) {
            svg << (p->closed ? "<polygon" : "<polyline") << " fill=\"" << (p->fill.empty() ? "none" : p->fill) << "\"";
            if (p->stroke) svg << stroke_attributes(*p->stroke);
            svg << " points=\"";
            for (const auto& [x, y] : p->points) svg << number(x) << "," << number(y) << " ";
            svg << "\"/>\n";
        } else if (const auto* c = std::get_if<CircleShape>(&shape)) {
            svg << "<circle cx=\"" << number(c->cx) << "\" cy=\"" << number(c->cy) << "\" r=\"" << number(c->r)
                << "\" fill=\"" << c->fill << "\"/>\n";
        } else if (const auto* t = std::get_if<TextShape>(&shape)) {
            const char* anchor = t->anchor == TextAnchor::Start ? "start" : t->anchor == TextAnchor::Middle ? "middle" : "end";
            svg << "<text";
            if (t->vertical)
                svg << " transform=\"translate(" << number(t->x) << "," << number(t->y) << ") rotate(-90)\"";
            else
                svg << " x=\"" << number(t->x) << "\" y=\"" << number(t->y) << "\"";
            if (t->size != 12) svg << " font-size=\"" << number(t->size) << "\"";
            svg << " text-anchor=\"" << anchor << "\">" << escape(t->text) << "</text>\n";
        } else if (const auto* b = std::get_if<ClipBegin>(&shape)) {
            const std::string id = "clip" + std::to_string(clips++);
            svg << "<defs><clipPath id=\"" << id << "\"><rect x=\"" << number(b->x) << "\" y=\"" << number(b->y)
                << "\" width=\"" << number(b->width) << "\" height=\"" << number(b->height) << "\"/></clipPath></defs>\n"
                << "<g clip-path=\"url(#" << id << ")\">\n";
        } else if (const auto* g = std::get_if<GroupBegin>(&shape)) {
            svg << "<g class=\"" << escape(g->name) << "\">\n";
        } else {
            svg << "</g>\n";  // ClipEnd, GroupEnd
        }
    }
    svg << "</svg>\n";
    return svg.str();
}

}  // namespace waxwork
