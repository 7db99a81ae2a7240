// 8-bit RGBA images and PNG files (what the headless renderer produces and the tests compare), and
// the high-dynamic-range Radiance .hdr files environment lights are read from.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace waxwork {

// Row-major, top row first, 4 bytes (r, g, b, a) per pixel, non-premultiplied alpha, sRGB-encoded.
struct Image {
    int width = 0;
    int height = 0;
    std::vector<uint8_t> rgba;

    const uint8_t* pixel(int x, int y) const { return rgba.data() + 4 * (static_cast<size_t>(y) * width + x); }
    uint8_t* pixel(int x, int y) { return rgba.data() + 4 * (static_cast<size_t>(y) * width + x); }
    friend bool operator==(const Image&, const Image&) = default;
};

// Writes an RGBA PNG atomically (temporary file + rename, io/atomic_file.h). Throws
// InvalidArgumentError for an image whose size and pixel count disagree, FileError on I/O failure.
void write_png(const Image& image, const std::filesystem::path& path);

// Reads any PNG (grey, grey-alpha, rgb, rgba, palette; 8 or 16 bits) as 8-bit RGBA. Throws
// FileError("PATH: PROBLEM") for a missing, unreadable, truncated or corrupt file.
Image read_png(const std::filesystem::path& path);

// Linear RGB radiance from a Radiance RGBE (.hdr) file, row-major, top row first, 3 floats per pixel.
struct HdrImage {
    int width = 0;
    int height = 0;
    std::vector<float> rgb;
};

// Reads a Radiance .hdr file (flat or run-length encoded). Throws FileError("PATH: PROBLEM") for a
// missing or empty file, another format, a corrupt or truncated one, or one of no pixels.
HdrImage read_hdr(const std::filesystem::path& path);

}  // namespace waxwork
