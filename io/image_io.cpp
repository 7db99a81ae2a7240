#include "io/image_io.h"

#include "base/error.h"
#include "io/atomic_file.h"
#include "io/file_extension.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <string_view>

// stb (Debian libstb-dev) rather than libpng: two self-contained headers cover encoding and robust,
// bounds-checked decoding. Static linkage keeps the implementation private to this file, so another
// translation unit that also uses stb cannot collide with it.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
#define STBI_ONLY_HDR
#include <stb/stb_image.h>
#define STBIW_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

// 16-bit PNGs through libpng: stb_image_write writes 8 bits per channel only.
#include <png.h>

#include <cmath>
#include <csetjmp>

namespace waxwork {

namespace {

// The whole file, or FileError.
std::string read_bytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path.string(), "cannot open for reading");
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw FileError(path.string(), "read error");
    return bytes;
}

}  // namespace

void write_png(const Image& image, const std::filesystem::path& path) {
    if (image.width <= 0 || image.height <= 0 ||
        image.rgba.size() != 4 * static_cast<size_t>(image.width) * static_cast<size_t>(image.height)) {
        throw InvalidArgumentError(path.string() + ": cannot write a " + std::to_string(image.width) + "x" +
                                   std::to_string(image.height) + " image from " +
                                   std::to_string(image.rgba.size()) + " bytes of RGBA");
    }
    // Encode to memory first: an encoder failure then never touches the file system.
    std::string png;
    auto append = [](void* context, void* data, int size) {
        static_cast<std::string*>(context)->append(static_cast<const char*>(data), static_cast<size_t>(size));
    };
    if (!stbi_write_png_to_func(append, &png, image.width, image.height, 4, image.rgba.data(), 4 * image.width)) {
        throw FileError(path.string(), "PNG encoding failed");
    }
    write_file_atomically(path, [&](std::ostream& out) { out.write(png.data(), static_cast<std::streamsize>(png.size())); });
}

namespace {

void check_image_size(int width, int height, size_t values, const std::filesystem::path& path) {
    if (width <= 0 || height <= 0 || values != 4 * static_cast<size_t>(width) * static_cast<size_t>(height)) {
        throw InvalidArgumentError(path.string() + ": cannot write a " + std::to_string(width) + "x" +
                                   std::to_string(height) + " image from " + std::to_string(values) +
                                   " values of RGBA");
    }
}

void write_bytes_atomically(const std::string& bytes, const std::filesystem::path& path) {
    write_file_atomically(path, [&](std::ostream& out) { out.write(bytes.data(), static_cast<std::streamsize>(bytes.size())); });
}

void append_to_string(void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), static_cast<size_t>(size));
}

// The decoded pixels of a PNG or JPEG file in memory, as stb returns them, after the checks read_png
// states; `sixteen`: 16 bits per channel.
struct DecodedPixels {
    int width = 0, height = 0;
    void* pixels = nullptr;
    ~DecodedPixels() { stbi_image_free(pixels); }
};

// `bytes` is the file's content (read_bytes(path)); `path` names it in errors.
void decode(const std::filesystem::path& path, const std::string& bytes, bool sixteen, DecodedPixels& out) {
    if (bytes.empty()) throw FileError(path.string(), "empty file, not an image");
    if (bytes.size() > static_cast<size_t>(std::numeric_limits<int>::max()))
        throw FileError(path.string(), "file too large for an image");
    const auto* data = reinterpret_cast<const stbi_uc*>(bytes.data());
    const int length = static_cast<int>(bytes.size());
    if (stbi_is_hdr_from_memory(data, length)) throw FileError(path.string(), "a Radiance .hdr image, not a PNG");
    if (!stbi_info_from_memory(data, length, nullptr, nullptr, nullptr))
        throw FileError(path.string(), std::string("not a PNG or JPEG image (") + stbi_failure_reason() + ")");
    int channels = 0;
    out.pixels = sixteen ? static_cast<void*>(stbi_load_16_from_memory(data, length, &out.width, &out.height, &channels, 4))
                         : static_cast<void*>(stbi_load_from_memory(data, length, &out.width, &out.height, &channels, 4));
    if (!out.pixels) throw FileError(path.string(), std::string("corrupt image: ") + stbi_failure_reason());
}

}  // namespace

bool is_image_extension(const std::filesystem::path& path) {
    const std::string extension = lower_extension(path);
    return extension == ".png" || extension == ".jpg" || extension == ".jpeg";
}

void write_image(const Image& image, const std::filesystem::path& path) {
    const std::string extension = lower_extension(path);
    if (extension == ".png") return write_png(image, path);
    if (extension == ".jpg" || extension == ".jpeg") return write_jpeg(image, path);
    throw InvalidArgumentError(path.string() + ": an image must be .png, .jpg or .jpeg");
}

void write_jpeg(const Image& image, const std::filesystem::path& path, int quality, std::array<uint8_t, 3> matte) {
    check_image_size(image.width, image.height, image.rgba.size(), path);
    if (quality < 1 || quality > 100) throw InvalidArgumentError(path.string() + ": JPEG quality must be in 1-100");
    // Over the matte by alpha, in the encoded values as the renderer's resolve blends them.
    std::vector<uint8_t> rgb(3 * static_cast<size_t>(image.width) * static_cast<size_t>(image.height));
    for (size_t p = 0; p < rgb.size() / 3; ++p) {
        const uint8_t* in = image.rgba.data() + 4 * p;
        for (int c = 0; c < 3; ++c)
            rgb[3 * p + c] = static_cast<uint8_t>((in[c] * in[3] + matte[c] * (255 - in[3]) + 127) / 255);
    }
    std::string jpeg;
    if (!stbi_write_jpg_to_func(append_to_string, &jpeg, image.width, image.height, 3, rgb.data(), quality))
        throw FileError(path.string(), "JPEG encoding failed");
    write_bytes_atomically(jpeg, path);
}

namespace {

// The decoded 8-bit RGBA of a file's content.
Image decoded_image(const std::filesystem::path& path, const std::string& bytes) {
    DecodedPixels decoded;
    decode(path, bytes, false, decoded);
    Image image;
    image.width = decoded.width;
    image.height = decoded.height;
    const auto* pixels = static_cast<const stbi_uc*>(decoded.pixels);
    image.rgba.assign(pixels, pixels + 4 * static_cast<size_t>(image.width) * static_cast<size_t>(image.height));
    return image;
}

}  // namespace

Image read_image(const std::filesystem::path& path) { return decoded_image(path, read_bytes(path)); }

namespace {

// libpng reports errors by longjmp; the message is kept for the exception thrown after it.
struct PngWriteState {
    std::string bytes;
    std::string error;
};

void png_error_handler(png_structp png, png_const_charp message) {
    static_cast<PngWriteState*>(png_get_error_ptr(png))->error = message;
    png_longjmp(png, 1);
}
void png_warning_handler(png_structp, png_const_charp) {}
void png_append(png_structp png, png_bytep data, png_size_t size) {
    static_cast<PngWriteState*>(png_get_io_ptr(png))->bytes.append(reinterpret_cast<const char*>(data), size);
}
void png_flush(png_structp) {}

}  // namespace

void write_linear_png(const LinearImage& image, const std::filesystem::path& path, float exposure) {
    check_image_size(image.width, image.height, image.rgba.size(), path);
    // Big-endian 16-bit samples, as PNG stores them.
    const size_t row_bytes = 8 * static_cast<size_t>(image.width);
    std::vector<uint8_t> samples(row_bytes * static_cast<size_t>(image.height));
    for (size_t i = 0; i < image.rgba.size(); ++i) {
        const float v = image.rgba[i];
        const auto code = static_cast<uint16_t>(std::isnan(v) ? 0.0f : std::lround(std::clamp(v, 0.0f, 1.0f) * 65535.0f));
        samples[2 * i] = static_cast<uint8_t>(code >> 8);
        samples[2 * i + 1] = static_cast<uint8_t>(code & 0xff);
    }
    std::vector<png_bytep> rows(static_cast<size_t>(image.height));
    for (size_t y = 0; y < rows.size(); ++y) rows[y] = samples.data() + y * row_bytes;
    const std::string exposure_text = std::to_string(exposure);

    PngWriteState state;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &state, png_error_handler, png_warning_handler);
    if (!png) throw FileError(path.string(), "PNG encoding failed (out of memory)");
    png_infop info = png_create_info_struct(png);
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        throw FileError(path.string(), "PNG encoding failed: " + state.error);
    }
    png_set_write_fn(png, &state, png_append, png_flush);
    png_set_IHDR(png, info, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height), 16,
                 PNG_COLOR_TYPE_RGB_ALPHA, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_gAMA(png, info, 1.0);
    png_text text{};
    char key[] = "Exposure";
    text.compression = PNG_TEXT_COMPRESSION_NONE;
    text.key = key;
    text.text = const_cast<char*>(exposure_text.c_str());
    if (exposure > 0) png_set_text(png, info, &text, 1);
    png_set_rows(png, info, rows.data());
    png_write_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
    png_destroy_write_struct(&png, &info);
    write_bytes_atomically(state.bytes, path);
}

LinearImage read_linear_png(const std::filesystem::path& path) {
    DecodedPixels decoded;
    decode(path, read_bytes(path), true, decoded);
    LinearImage image;
    image.width = decoded.width;
    image.height = decoded.height;
    const auto* pixels = static_cast<const uint16_t*>(decoded.pixels);
    image.rgba.resize(4 * static_cast<size_t>(image.width) * static_cast<size_t>(image.height));
    for (size_t i = 0; i < image.rgba.size(); ++i) image.rgba[i] = pixels[i] / 65535.0f;
    return image;
}

Image read_png(const std::filesystem::path& path) {
    const std::string bytes = read_bytes(path);
    if (bytes.empty()) throw FileError(path.string(), "empty file, not a PNG");
    // stb decodes a dozen formats; a file read as a PNG must be one: its 8-byte signature.
    static constexpr std::string_view kSignature("\x89PNG\r\n\x1a\n", 8);
    if (bytes.compare(0, kSignature.size(), kSignature) != 0) throw FileError(path.string(), "not a PNG image (no PNG signature)");
    return decoded_image(path, bytes);
}

namespace {

// stb's decoders read past the end of a short file as zeros and carry on for flat (not run-length
// encoded) scanlines, so a truncated .hdr would load with black rows. Reading through callbacks
// over the bytes tells the decoder asking for bytes that are not there, which a complete file never
// does.
struct MemoryReader {
    const std::string* bytes;
    size_t position = 0;
    bool read_past_end = false;

    static int read(void* user, char* out, int size) {
        auto* r = static_cast<MemoryReader*>(user);
        const size_t n = std::min(static_cast<size_t>(std::max(size, 0)), r->bytes->size() - r->position);
        if (n == 0 && size > 0) r->read_past_end = true;
        std::memcpy(out, r->bytes->data() + r->position, n);
        r->position += n;
        return static_cast<int>(n);
    }
    static void skip(void* user, int n) {
        auto* r = static_cast<MemoryReader*>(user);
        if (n < 0) {
            r->position -= std::min(r->position, static_cast<size_t>(-n));
            return;
        }
        if (r->position + static_cast<size_t>(n) > r->bytes->size()) r->read_past_end = true;
        r->position = std::min(r->bytes->size(), r->position + static_cast<size_t>(n));
    }
    static int eof(void* user) {
        const auto* r = static_cast<MemoryReader*>(user);
        return r->position >= r->bytes->size();
    }
};

}  // namespace

HdrImage read_hdr(const std::filesystem::path& path) {
    // Refuse devices and pipes (/dev/zero never ends) and files no environment map needs, before reading.
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
        if (!std::filesystem::exists(path, ec)) throw FileError(path.string(), "no such file");
        throw FileError(path.string(), "not a regular file");
    }
    if (std::filesystem::file_size(path, ec) > (size_t{1} << 30))
        throw FileError(path.string(), "larger than 1 GiB; an environment map needs far less");
    const std::string bytes = read_bytes(path);
    if (bytes.empty()) throw FileError(path.string(), "empty file, not a Radiance .hdr image");
    if (bytes.size() > static_cast<size_t>(std::numeric_limits<int>::max()))
        throw FileError(path.string(), "file too large for an .hdr image");
    if (!stbi_is_hdr_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()), static_cast<int>(bytes.size())))
        throw FileError(path.string(), "not a Radiance .hdr image (no #?RADIANCE or #?RGBE header)");
    MemoryReader reader{&bytes};
    const stbi_io_callbacks callbacks{&MemoryReader::read, &MemoryReader::skip, &MemoryReader::eof};
    int width = 0, height = 0, channels = 0;
    float* pixels = stbi_loadf_from_callbacks(&callbacks, &reader, &width, &height, &channels, 3);
    if (!pixels) throw FileError(path.string(), std::string("corrupt .hdr image: ") + stbi_failure_reason());
    HdrImage image;
    image.width = width;
    image.height = height;
    image.rgb.assign(pixels, pixels + 3 * static_cast<size_t>(width) * static_cast<size_t>(height));
    stbi_image_free(pixels);
    if (reader.read_past_end) throw FileError(path.string(), "truncated .hdr image (the pixel data ends early)");
    if (width <= 0 || height <= 0) throw FileError(path.string(), "the .hdr image has no pixels");
    return image;
}

}  // namespace waxwork
