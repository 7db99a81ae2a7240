// 8-bit RGBA images and PNG files (what the headless renderer produces and the tests compare), and
// the high-dynamic-range Radiance .hdr files environment lights are read from.
#pragma once

#include <array>
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

// Writes an 8-bit image by the file's extension (case-insensitive): .png (RGBA, straight alpha) or
// .jpg/.jpeg (write_jpeg). Throws InvalidArgumentError naming the file for any other extension.
void write_image(const Image& image, const std::filesystem::path& path);

// Whether write_image takes this file's extension: .png, .jpg or .jpeg.
bool is_image_extension(const std::filesystem::path& path);

// Writes a baseline JPEG (stb_image_write) at `quality` (1-100) atomically. JPEG has no alpha: a
// pixel that is not opaque is composited over `matte` (8-bit sRGB) by its alpha. Throws as write_png.
inline constexpr int kJpegQuality = 92;
void write_jpeg(const Image& image, const std::filesystem::path& path, int quality = kJpegQuality,
                std::array<uint8_t, 3> matte = {255, 255, 255});

// Reads a PNG or JPEG (any file stb_image decodes except .hdr) as 8-bit RGBA. Throws as read_png.
Image read_image(const std::filesystem::path& path);

// Linear (not sRGB-encoded) RGBA in floats, row-major, top row first, straight alpha: the renderer's
// exposed radiance before tone mapping, with the coverage as alpha.
struct LinearImage {
    int width = 0;
    int height = 0;
    std::vector<float> rgba;

    const float* pixel(int x, int y) const { return rgba.data() + 4 * (static_cast<size_t>(y) * width + x); }
};

// Writes a 16-bit RGBA PNG (libpng) of linear values atomically: each channel clamped to [0, 1] and
// scaled to 0..65535, no gamma. The PNG carries a gAMA chunk of 1.0 (linear) and, when `exposure` is
// positive, a tEXt chunk "Exposure" with it, so the absolute radiance is the value over the exposure.
// Throws as write_png.
void write_linear_png(const LinearImage& image, const std::filesystem::path& path, float exposure = 0);

// Reads a 16-bit (or 8-bit) PNG as linear values in [0, 1], without any gamma conversion: the inverse
// of write_linear_png up to its 16-bit quantisation. Throws as read_png.
LinearImage read_linear_png(const std::filesystem::path& path);

// Reads any PNG (grey, grey-alpha, rgb, rgba, palette; 8 or 16 bits) as 8-bit RGBA. Throws
// FileError("PATH: PROBLEM") for a missing, unreadable, truncated or corrupt file, and for one of
// another format (no PNG signature).
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
