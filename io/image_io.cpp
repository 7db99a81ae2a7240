#include "io/image_io.h"

#include "base/error.h"
#include "io/atomic_file.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

// stb (Debian libstb-dev) rather than libpng: two self-contained headers cover encoding and robust,
// bounds-checked decoding. Static linkage keeps the implementation private to this file, so another
// translation unit that also uses stb cannot collide with it.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_ONLY_HDR
#include <stb/stb_image.h>
#define STBIW_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

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

Image read_png(const std::filesystem::path& path) {
    const std::string bytes = read_bytes(path);
    if (bytes.empty()) throw FileError(path.string(), "empty file, not a PNG");
    if (bytes.size() > static_cast<size_t>(std::numeric_limits<int>::max())) {
        throw FileError(path.string(), "file too large for a PNG image");
    }
    const auto* data = reinterpret_cast<const stbi_uc*>(bytes.data());
    const int length = static_cast<int>(bytes.size());
    if (stbi_is_hdr_from_memory(data, length)) throw FileError(path.string(), "a Radiance .hdr image, not a PNG");
    if (!stbi_info_from_memory(data, length, nullptr, nullptr, nullptr)) {
        throw FileError(path.string(), std::string("not a PNG image (") + stbi_failure_reason() + ")");
    }
    int width = 0, height = 0, channels = 0;
    stbi_uc* pixels = stbi_load_from_memory(data, length, &width, &height, &channels, 4);
    if (!pixels) throw FileError(path.string(), std::string("corrupt PNG: ") + stbi_failure_reason());
    Image image;
    image.width = width;
    image.height = height;
    image.rgba.assign(pixels, pixels + 4 * static_cast<size_t>(width) * static_cast<size_t>(height));
    stbi_image_free(pixels);
    return image;
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
