#include "bench/studies/pdf_chart.h"

#include "io/atomic_file.h"

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <vector>

namespace waxwork {
namespace {

std::string number(double v) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.2f", v);
    return buffer;
}

// "#rrggbb" as PDF's "r g b" in 0..1 (black for anything else).
std::string rgb(const std::string& colour) {
    if (colour.size() != 7 || colour[0] != '#') return "0 0 0";
    std::string out;
    for (int i = 0; i < 3; ++i) {
        const long v = std::strtol(colour.substr(1 + 2 * static_cast<size_t>(i), 2).c_str(), nullptr, 16);
        out += (i ? " " : "") + number(static_cast<double>(v) / 255.0);
    }
    return out;
}

// A PDF literal string: backslash, parentheses escaped; bytes outside printable ASCII as octal.
std::string literal(const std::string& latin1) {
    std::string out = "(";
    for (char ch : latin1) {
        const auto c = static_cast<unsigned char>(ch);
        if (c == '(' || c == ')' || c == '\\') {
            out += '\\';
            out += ch;
        } else if (c < 32 || c > 126) {
            char octal[8];
            std::snprintf(octal, sizeof octal, "\\%03o", c);
            out += octal;
        } else {
            out += ch;
        }
    }
    return out + ")";
}

void set_stroke(std::ostringstream& s, const Stroke& stroke) {
    s << rgb(stroke.colour) << " RG " << number(stroke.width) << " w [";
    for (double d : stroke.dash) s << number(d) << " ";
    s << "] 0 d\n";
}

// The page content. PDF's y axis points up: the drawing's y becomes height - y.
std::string content_stream(const Drawing& d) {
    std::ostringstream s;
    auto y = [&](double v) { return number(d.height - v); };
    s << "1 1 1 rg 0 0 " << number(d.width) << " " << number(d.height) << " re f\n1 J 1 j\n";
    for (const Shape& shape : d.shapes) {
        if (const auto* l = std::get_if<LineShape>(&shape)) {
            set_stroke(s, l->stroke);
            s << number(l->x1) << " " << y(l->y1) << " m " << number(l->x2) << " " << y(l->y2) << " l S\n";
        } else if (const auto* p = std::get_if<PathShape>(&shape)) {
            if (p->points.empty() || (p->fill.empty() && !p->stroke)) continue;
            if (p->stroke) set_stroke(s, *p->stroke);
            if (!p->fill.empty()) s << rgb(p->fill) << " rg\n";
            for (size_t i = 0; i < p->points.size(); ++i)
                s << number(p->points[i].first) << " " << y(p->points[i].second) << (i ? " l\n" : " m\n");
            if (p->closed) s << "h ";
            s << (p->fill.empty() ? "S" : p->stroke ? "B" : "f") << "\n";
        } else if (const auto* c = std::get_if<CircleShape>(&shape)) {
            // Four cubic Bezier quarter arcs; k = 4/3 (sqrt 2 - 1) puts their midpoints on the circle.
            const double k = 0.5523 * c->r, x = c->cx, yc = d.height - c->cy, r = c->r;
            s << rgb(c->fill) << " rg\n"
              << number(x + r) << " " << number(yc) << " m\n"
              << number(x + r) << " " << number(yc + k) << " " << number(x + k) << " " << number(yc + r) << " "
              << number(x) << " " << number(yc + r) << " c\n"
              << number(x - k) << " " << number(yc + r) << " " << number(x - r) << " " << number(yc + k) << " "
              << number(x - r) << " " << number(yc) << " c\n"
              << number(x - r) << " " << number(yc - k) << " " << number(x - k) << " " << number(yc - r) << " "
              << number(x) << " " << number(yc - r) << " c\n"
              << number(x + k) << " " << number(yc - r) << " " << number(x + r) << " " << number(yc - k) << " "
              << number(x + r) << " " << number(yc) << " c f\n";
        } else if (const auto* t = std::get_if<TextShape>(&shape)) {
            const std::string text = to_latin1(t->text);
            const double w = text_width(t->text, t->size);
            const double shift = t->anchor == TextAnchor::Start ? 0 : t->anchor == TextAnchor::Middle ? w / 2 : w;
            s << "0 0 0 rg BT /F1 " << number(t->size) << " Tf ";
            if (t->vertical)  // rotated 90 degrees counter-clockwise: the text runs up the page
                s << "0 1 -1 0 " << number(t->x) << " " << number(d.height - t->y - shift) << " Tm ";
            else
                s << "1 0 0 1 " << number(t->x - shift) << " " << y(t->y) << " Tm ";
            s << literal(text) << " Tj ET\n";
        } else if (const auto* b = std::get_if<ClipBegin>(&shape)) {
            s << "q " << number(b->x) << " " << number(d.height - b->y - b->height) << " " << number(b->width) << " "
              << number(b->height) << " re W n\n";
        } else if (std::holds_alternative<ClipEnd>(shape)) {
            s << "Q\n";
        }
    }
    return s.str();
}

}  // namespace

std::string drawing_to_pdf(const Drawing& d) {
    const std::string content = content_stream(d);
    const std::vector<std::string> objects = {
        "<< /Type /Catalog /Pages 2 0 R >>",
        "<< /Type /Pages /Kids [3 0 R] /Count 1 >>",
        "<< /Type /Page /Parent 2 0 R /MediaBox [0 0 " + number(d.width) + " " + number(d.height) +
            "] /Resources << /Font << /F1 5 0 R >> >> /Contents 4 0 R >>",
        "<< /Length " + std::to_string(content.size()) + " >>\nstream\n" + content + "endstream",
        "<< /Type /Font /Subtype /Type1 /BaseFont /Helvetica /Encoding /WinAnsiEncoding >>",
    };
    std::string pdf = "%PDF-1.4\n%\xE2\xE3\xCF\xD3\n";
    std::vector<size_t> offsets;
    for (size_t i = 0; i < objects.size(); ++i) {
        offsets.push_back(pdf.size());
        pdf += std::to_string(i + 1) + " 0 obj\n" + objects[i] + "\nendobj\n";
    }
    const size_t xref = pdf.size();
    pdf += "xref\n0 " + std::to_string(objects.size() + 1) + "\n0000000000 65535 f \n";
    for (size_t offset : offsets) {
        char entry[24];
        std::snprintf(entry, sizeof entry, "%010zu 00000 n \n", offset);
        pdf += entry;
    }
    pdf += "trailer\n<< /Size " + std::to_string(objects.size() + 1) + " /Root 1 0 R >>\nstartxref\n" +
           std::to_string(xref) + "\n%%EOF\n";
    return pdf;
}

void write_pdf_drawing(const std::filesystem::path& path, const Drawing& drawing) {
    const std::string bytes = drawing_to_pdf(drawing);
    write_file_atomically(path, [&](std::ostream& out) { out << bytes; });
}

}  // namespace waxwork
