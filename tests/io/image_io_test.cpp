// Image files beyond the 8-bit PNG: JPEG by extension, and the 16-bit linear PNG.
#include "io/image_io.h"

#include "base/error.h"
#include "support/scratch_dir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace waxwork {
namespace {

namespace fs = std::filesystem;

TEST(LinearPng, RoundTripsSixteenBitValuesWithoutGamma) {
    const fs::path dir = testing::scratch_dir("linear_png");
    LinearImage image;
    image.width = 300;
    image.height = 2;
    image.rgba.resize(4 * 300 * 2);
    // Steps of 1/600: finer than 8 bits could hold, and none near sRGB's encoding of itself.
    for (int i = 0; i < 600; ++i) {
        for (int c = 0; c < 3; ++c) image.rgba[4 * i + c] = static_cast<float>((i + c) % 600) / 600.0f;
        image.rgba[4 * i + 3] = i % 2 ? 1.0f : 0.25f;
    }
    image.rgba[0] = 7.0f;  // clamped to 1
    image.rgba[1] = -1.0f;  // clamped to 0
    const fs::path path = dir / "linear.png";
    write_linear_png(image, path, 2.5f);
    const LinearImage back = read_linear_png(path);
    ASSERT_EQ(back.width, 300);
    ASSERT_EQ(back.height, 2);
    EXPECT_EQ(back.rgba[0], 1.0f);
    EXPECT_EQ(back.rgba[1], 0.0f);
    for (size_t i = 2; i < image.rgba.size(); ++i) EXPECT_NEAR(back.rgba[i], image.rgba[i], 0.5 / 65535) << i;
    // The file says its values are linear and names the exposure.
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(bytes.find("gAMA"), std::string::npos);
    EXPECT_NE(bytes.find(std::string("Exposure\0", 9) + "2.5"), std::string::npos);
    // An 8-bit reading sees the top byte.
    const Image eight = read_png(path);
    EXPECT_EQ(eight.pixel(1, 0)[3], 255);
    EXPECT_EQ(eight.pixel(0, 0)[3], 64);
}

TEST(Jpeg, WritesOverTheMatteAndReadsBack) {
    const fs::path dir = testing::scratch_dir("jpeg");
    Image image;
    image.width = 16;
    image.height = 8;
    image.rgba.assign(4 * 16 * 8, 0);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 16; ++x) {
            uint8_t* p = image.pixel(x, y);
            p[0] = 200;
            p[3] = x < 8 ? 255 : 0;  // the right half transparent
        }
    const fs::path path = dir / "half.jpeg";
    write_image(image, path);
    const Image back = read_image(path);
    ASSERT_EQ(back.width, 16);
    ASSERT_EQ(back.height, 8);
    EXPECT_NEAR(back.pixel(2, 4)[0], 200, 6);
    EXPECT_NEAR(back.pixel(2, 4)[1], 0, 6);
    EXPECT_NEAR(back.pixel(13, 4)[1], 255, 6);  // white matte behind the transparent half
    EXPECT_EQ(back.pixel(13, 4)[3], 255);
    EXPECT_THROW(write_image(image, dir / "x.tga"), InvalidArgumentError);
    EXPECT_FALSE(fs::exists(dir / "x.tga"));
}

}  // namespace
}  // namespace waxwork

namespace waxwork {
namespace {

// read_png reads PNGs only: a JPEG (which read_image takes) is refused naming the file.
TEST(ImageIo, ReadPngRefusesOtherFormats) {
    const std::filesystem::path dir = testing::scratch_dir("read_png_formats");
    Image image;
    image.width = 4;
    image.height = 3;
    image.rgba.assign(4 * 12, 200);
    write_jpeg(image, dir / "a.jpg");
    EXPECT_EQ(read_image(dir / "a.jpg").width, 4);
    try {
        read_png(dir / "a.jpg");
        ADD_FAILURE() << "read_png accepted a JPEG";
    } catch (const FileError& e) {
        EXPECT_NE(std::string(e.what()).find("a.jpg: not a PNG image"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace waxwork
