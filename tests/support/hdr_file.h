// Radiance .hdr files written byte by byte for the tests (flat scanlines of RGBE pixels), so the
// reader is tested against the format rather than against its own writer.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

namespace waxwork::testing {

// One RGBE pixel (Ward's shared-exponent format) of a non-negative colour.
inline std::string rgbe_pixel(double r, double g, double b) {
    const double largest = std::max({r, g, b});
    if (largest < 1e-32) return std::string(4, '\0');
    int exponent = 0;
    const double mantissa = std::frexp(largest, &exponent) * 256.0 / largest;
    return {static_cast<char>(r * mantissa), static_cast<char>(g * mantissa), static_cast<char>(b * mantissa),
            static_cast<char>(exponent + 128)};
}

// The bytes of a width x height .hdr image whose pixel (x, y) (row 0 at the top) is colour(x, y).
inline std::string hdr_file_bytes(int width, int height, const std::function<std::array<double, 3>(int, int)>& colour) {
    std::string text = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(height) + " +X " +
                       std::to_string(width) + "\n";
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const auto c = colour(x, y);
            text += rgbe_pixel(c[0], c[1], c[2]);
        }
    return text;
}

inline std::filesystem::path write_bytes(const std::filesystem::path& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
}

}  // namespace waxwork::testing
