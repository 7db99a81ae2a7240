// A chart's display list (bench/studies/chart_drawing.h) as a one-page PDF 1.4: vector lines, paths and
// circles, and Helvetica text (one of the 14 standard fonts, so nothing is embedded), a page the size of
// the drawing in points. Written by hand for the same reason as the SVG: a figure for a paper without a
// run-time plotting dependency; pdftoppm or any viewer renders it at any resolution.
#pragma once

#include "bench/studies/chart_drawing.h"

#include <filesystem>
#include <string>

namespace waxwork {

// The PDF file's bytes: header, five objects (catalog, pages, page, content stream, font), a
// cross-reference table with each object's byte offset, trailer and startxref.
std::string drawing_to_pdf(const Drawing& drawing);

// drawing_to_pdf written atomically (io/atomic_file.h); FileError on I/O failure.
void write_pdf_drawing(const std::filesystem::path& path, const Drawing& drawing);

}  // namespace waxwork
