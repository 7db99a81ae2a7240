#include "io/image_io.h"

#include "base/error.h"
#include "support/hdr_file.h"
#include "support/scratch_dir.h"

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <string>

namespace waxwork {
namespace {

namespace fs = std::filesystem;

// A .hdr image whose pixel (x, y) is (x, y, 1).
std::string hdr_file(int width, int height) {
    return testing::hdr_file_bytes(width, height, [](int x, int y) { return std::array<double, 3>{double(x), double(y), 1.0}; });
}

fs::path write(const fs::path& path, const std::string& bytes) { return testing::write_bytes(path, bytes); }

std::string error_of(const fs::path& path) {
    try {
        read_hdr(path);
    } catch (const FileError& e) {
        return e.what();
    }
    return "no error";
}

TEST(HdrImage, ReadsRadiancePixelsTopRowFirst) {
    const fs::path dir = testing::scratch_dir("hdr_image_read");
    const HdrImage image = read_hdr(write(dir / "ramp.hdr", hdr_file(16, 3)));
    ASSERT_EQ(image.width, 16);
    ASSERT_EQ(image.height, 3);
    ASSERT_EQ(image.rgb.size(), 16u * 3 * 3);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 16; ++x) {
            const float* p = image.rgb.data() + 3 * (y * 16 + x);
            EXPECT_NEAR(p[0], x, 0.01 * std::max(x, 1)) << x << "," << y;
            EXPECT_NEAR(p[1], y, 0.01 * std::max(x, std::max(y, 1))) << x << "," << y;
            EXPECT_GT(p[2], 0.0f);
        }
}

TEST(HdrImage, BadFilesGetOneLineErrorsNamingThem) {
    const fs::path dir = testing::scratch_dir("hdr_image_bad");
    const std::string good = hdr_file(16, 4);
    const std::vector<std::pair<fs::path, std::string>> cases = {
        {dir / "missing.hdr", "no such file"},
        {write(dir / "empty.hdr", ""), "empty file"},
        {write(dir / "text.hdr", "hello, not an image\n"), "not a Radiance .hdr image"},
        {write(dir / "truncated.hdr", good.substr(0, good.size() - 9)), "truncated"},
        {write(dir / "zero.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 0 +X 4\n"), ".hdr"},
        {dir, "not a regular file"},
    };
    for (const auto& [path, expected] : cases) {
        const std::string message = error_of(path);
        EXPECT_NE(message.find(path.string()), std::string::npos) << message;
        EXPECT_NE(message.find(expected), std::string::npos) << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
    // A PNG reader handed an .hdr says so.
    try {
        read_png(write(dir / "image.png", good));
        ADD_FAILURE() << "read_png accepted an .hdr file";
    } catch (const FileError& e) {
        EXPECT_NE(std::string(e.what()).find("not a PNG"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace waxwork
