#include "io/image_io.h"

#include "base/error.h"
#include "io/atomic_file.h"

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
#include <stb/stb_image.h>
#define STBIW_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

namespace waxwork {

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
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path.string(), "cannot open for reading");
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw FileError(path.string(), "read error");
    if (bytes.empty()) throw FileError(path.string(), "empty file, not a PNG");
    if (bytes.size() > static_cast<size_t>(std::numeric_limits<int>::max())) {
        throw FileError(path.string(), "file too large for a PNG image");
    }
    const auto* data = reinterpret_cast<const stbi_uc*>(bytes.data());
    const int length = static_cast<int>(bytes.size());
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

}  // namespace waxwork
