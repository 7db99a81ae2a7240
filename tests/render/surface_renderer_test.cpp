#include "base/error.h"
#include "gl/gl_context.h"
#include "io/image_io.h"
#include "render/camera.h"
#include "render/ground_plane.h"
#include "render/srgb.h"
#include "render/surface_renderer.h"
#include "solver/environment_light.h"
#include "solver/lighting.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>

namespace waxwork {
namespace {

// A UV sphere of radius 1 at the origin with E = `factor` everywhere.
SurfaceRenderInput make_sphere(const std::array<float, 3>& factor, int width = 96, int height = 72) {
    SurfaceRenderInput input;
    const int rings = 24, segments = 48;
    for (int i = 0; i <= rings; ++i) {
        const double theta = std::numbers::pi * i / rings;
        for (int j = 0; j < segments; ++j) {
            const double phi = 2 * std::numbers::pi * j / segments;
            const Eigen::Vector3f p(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
            input.positions.push_back(p);
            input.normals.push_back(p);
            input.radiance_factor.push_back(factor);
        }
    }
    for (int i = 0; i < rings; ++i) {
        for (int j = 0; j < segments; ++j) {
            const int a = i * segments + j, b = i * segments + (j + 1) % segments;
            const int c = a + segments, d = b + segments;
            input.triangles.push_back({a, b, c});
            input.triangles.push_back({b, d, c});
        }
    }
    input.width = width;
    input.height = height;
    input.lighting.lights.push_back({LightType::Directional, {-1, -1, -1}, {2, 2, 2}});
    return input;
}

double luminance(const Image& image, int x, int y) {
    const uint8_t* p = image.pixel(x, y);
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

double mean_luminance(const Image& image) {
    double sum = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) sum += luminance(image, x, y);
    return sum / (image.width * image.height);
}

std::filesystem::path temp_path(const std::string& name) {
    return std::filesystem::temp_directory_path() /
           ("waxwork_render_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" + name);
}

// The ground's irradiance at the texel nearest to world (x, z).
float ground_irradiance_at(const GroundPlane& plane, float x, float z) {
    const float texel = 2 * plane.texture_extent / plane.resolution;
    const int column = static_cast<int>((x - plane.centre.x() + plane.texture_extent) / texel);
    const int row = static_cast<int>((z - plane.centre.y() + plane.texture_extent) / texel);
    return plane.irradiance[3 * (static_cast<size_t>(row) * plane.resolution + column)];
}

TEST(GroundPlane, HoldsTheLightsShadowAndAContactShadow) {
    SurfaceRenderInput input = make_sphere({0.3f, 0.3f, 0.3f});
    input.lighting.lights = {{LightType::Directional, {-1, -1, -1}, {2, 2, 2}}};
    input.lighting.ambient = {0.2, 0.2, 0.2};
    const GroundPlane plane = ground_plane(input);
    EXPECT_FLOAT_EQ(plane.height, -1.0f);  // the sphere's lowest point
    ASSERT_GT(plane.resolution, 0);
    // Far from the sphere: the light at 54.7 degrees from the normal, the whole sky open.
    const float open = 2 * std::sqrt(1.0f / 3) + 0.2f;
    EXPECT_NEAR(ground_irradiance_at(plane, 3, 3), open, 0.01);
    // The sphere's shadow is centred where the ray from its centre along the light meets the plane,
    // (-1, -1): only the occluded fill reaches it.
    EXPECT_LT(ground_irradiance_at(plane, -1, -1), 0.2f);
    EXPECT_GT(ground_irradiance_at(plane, -1, -1), 0.0f);
    // Beside the contact on the lit side, the sphere above hides part of the sky: darker than far away,
    // lighter than the shadow.
    const float contact = ground_irradiance_at(plane, 0.35f, 0.35f);
    EXPECT_LT(contact, open - 0.03f);
    EXPECT_GT(contact, 2 * std::sqrt(1.0f / 3));
    // Without shadows the light reaches the shadow's place too.
    input.lighting.shadows = false;
    EXPECT_GT(ground_irradiance_at(ground_plane(input), -1, -1), 1.0f);
}

TEST(SurfaceRenderer, GroundPlaneIsDrawnUnderTheModelAndFadesIntoTransparency) {
    SurfaceRenderInput input = make_sphere({0.3f, 0.3f, 0.3f}, 120, 90);
    input.lighting.ambient = {0.2, 0.2, 0.2};
    HeadlessGlContext context;
    SurfaceRenderer renderer(context.gl());
    const Image bare = renderer.render(input);
    input.ground = true;
    const Image grounded = renderer.render(input);
    // Seen from above the front, the ground fills the bottom corners; the top ones keep the background.
    EXPECT_NE(luminance(grounded, 2, 87), luminance(bare, 2, 87));
    EXPECT_EQ(luminance(grounded, 2, 2), luminance(bare, 2, 2));
    EXPECT_EQ(luminance(grounded, 60, 45), luminance(bare, 60, 45));  // the sphere in front of it
    input.transparent_background = true;
    const Image transparent = renderer.render(input);
    EXPECT_EQ(transparent.pixel(2, 2)[3], 0);
    EXPECT_GT(transparent.pixel(60, 88)[3], 0);  // the ground below the sphere
}

TEST(HeadlessGl, CreatesACoreContextOfAtLeast43) {
    HeadlessGlContext context;
    const std::string version = context.version();
    ASSERT_FALSE(version.empty());
    int major = 0, minor = 0;
    ASSERT_EQ(std::sscanf(version.c_str(), "%d.%d", &major, &minor), 2) << version;
    EXPECT_GE(major * 10 + minor, 43) << version;
    EXPECT_NE(version.find("Core"), std::string::npos) << version;
    std::cout << "OpenGL " << version << " on " << context.renderer() << "\n";
}

TEST(SurfaceRenderer, LitSphereCoversTheCentreOnTheBackground) {
    SurfaceRenderInput input = make_sphere({0.3f, 0.2f, 0.1f});
    input.background = {10, 20, 30};
    const Image image = render_surface(input);
    ASSERT_EQ(image.width, 96);
    ASSERT_EQ(image.height, 72);
    ASSERT_EQ(image.rgba.size(), 96u * 72u * 4u);

    // The centre shows the sphere, warm as its E (red > green > blue), and is not background.
    const uint8_t* centre = image.pixel(48, 36);
    EXPECT_GT(luminance(image, 48, 36), 20);
    EXPECT_GT(centre[0], centre[1]);
    EXPECT_GT(centre[1], centre[2]);
    // Corners are exactly the background colour (the sphere is framed with a margin).
    for (auto [x, y] : {std::pair{0, 0}, std::pair{95, 0}, std::pair{0, 71}, std::pair{95, 71}}) {
        const uint8_t* p = image.pixel(x, y);
        EXPECT_EQ(p[0], 10);
        EXPECT_EQ(p[1], 20);
        EXPECT_EQ(p[2], 30);
        EXPECT_EQ(p[3], 255);
    }
}

TEST(SurfaceRenderer, BrighterRadianceGivesABrighterImage) {
    SurfaceRenderInput dim = make_sphere({0.05f, 0.05f, 0.05f});
    SurfaceRenderInput bright = make_sphere({0.5f, 0.5f, 0.5f});
    dim.specular_scale = bright.specular_scale = 0;
    const Image a = render_surface(dim);
    const Image b = render_surface(bright);
    EXPECT_GT(mean_luminance(b), mean_luminance(a) + 10);
    EXPECT_GT(luminance(b, 48, 36), luminance(a, 48, 36) + 30);
}

TEST(SurfaceRenderer, TopRowOfTheImageIsTheTopOfTheScene) {
    // Only the upper hemisphere (y > 0, y is up) glows: the upper half of the image must be brighter.
    SurfaceRenderInput input = make_sphere({0, 0, 0});
    input.specular_scale = 0;
    for (size_t i = 0; i < input.positions.size(); ++i) {
        if (input.positions[i].y() > 0) input.radiance_factor[i] = {1, 1, 1};
    }
    input.camera.eye_direction = {0, 0, 1};
    const Image image = render_surface(input);
    EXPECT_GT(luminance(image, 48, 26), luminance(image, 48, 46) + 50);
}

// The highlight of every light validate() accepts: directions with components far below or above
// float's range, and point lights too far for float's d.d, draw what the same light at a unit scale
// draws (they used to come out black: a direction of 1e-30 normalised in float is 0/0).
TEST(SurfaceRenderer, LightsOfAnyValidScaleDrawTheSameHighlight) {
    SurfaceRenderInput input = make_sphere({0, 0, 0});  // highlight only
    const Eigen::Vector3d travel(-1, -1, -1);
    input.lighting.lights = {{LightType::Directional, travel, {2, 2, 2}}};
    const Image reference = render_surface(input);
    int lit = 0;
    for (int y = 0; y < reference.height; ++y)
        for (int x = 0; x < reference.width; ++x) lit += luminance(reference, x, y) > 60;
    ASSERT_GT(lit, 5) << "the reference shows no highlight";
    const auto max_difference = [&](const Image& image) {
        int worst = 0;
        for (size_t k = 0; k < image.rgba.size(); ++k) worst = std::max(worst, std::abs(image.rgba[k] - reference.rgba[k]));
        return worst;
    };
    for (const double scale : {1e-30, 1e-60, 1e50, 1e100 / std::sqrt(3.0)}) {
        input.lighting.lights = {{LightType::Directional, scale * travel, {2, 2, 2}}};
        EXPECT_LE(max_difference(render_surface(input)), 1) << "direction scaled by " << scale;
    }
    // A point light at distance d gives the irradiance I / d^2 of a parallel light; exposed by 2 d^2 / I
    // it draws the reference's highlight.
    const double intensity = kMaxLightIntensity;
    for (const double distance : {1e16, 1e18, 1e20}) {
        input.lighting.lights = {{LightType::Point, -distance * travel.normalized(), {intensity, intensity, intensity}}};
        input.exposure = static_cast<float>(2 * distance * distance / intensity);
        EXPECT_LE(max_difference(render_surface(input)), 1) << "point light at " << distance;
    }
}

TEST(SurfaceRenderer, RendererIsReusableAndInputIsValidated) {
    HeadlessGlContext context;
    SurfaceRenderer renderer(context.gl());
    SurfaceRenderInput input = make_sphere({0.2f, 0.2f, 0.2f}, 32, 32);
    const Image first = renderer.render(input);
    const Image second = renderer.render(input);
    EXPECT_EQ(first, second);

    SurfaceRenderInput bad = input;
    bad.triangles[3][1] = static_cast<int32_t>(bad.positions.size());
    EXPECT_THROW(renderer.render(bad), InvalidArgumentError);
    bad = input;
    bad.normals.pop_back();
    EXPECT_THROW(renderer.render(bad), InvalidArgumentError);
    bad = input;
    bad.width = 0;
    EXPECT_THROW(renderer.render(bad), InvalidArgumentError);
    bad = input;
    bad.lighting.lights[0].vector = Eigen::Vector3d::Zero();
    EXPECT_THROW(renderer.render(bad), InvalidArgumentError);
}

TEST(Camera, FramesTheBoxInsideTheFrustum) {
    const Eigen::AlignedBox3d box(Eigen::Vector3d(-1, -2, 0), Eigen::Vector3d(3, 1, 2));
    const CameraFrame frame = frame_camera(box, CameraSettings{}, 4.0 / 3.0);
    for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d p = box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
        const Eigen::Vector4d clip = frame.projection * frame.view * p.homogeneous();
        ASSERT_GT(clip.w(), 0);
        for (int k = 0; k < 3; ++k) EXPECT_LE(std::abs(clip[k] / clip.w()), 1.0) << corner;
    }
    CameraSettings bad;
    bad.eye_direction = {0, 1, 0};  // parallel to up
    EXPECT_THROW(frame_camera(box, bad, 1.0), InvalidArgumentError);
}

// Only the directions of the eye and up vectors count, at any magnitude a double holds.
TEST(Camera, EyeAndUpVectorsOfAnyMagnitudeAreDirections) {
    const Eigen::AlignedBox3d box(Eigen::Vector3d(-1, -2, 0), Eigen::Vector3d(3, 1, 2));
    const CameraFrame unit = frame_camera(box, CameraSettings{}, 4.0 / 3.0);
    for (const double magnitude : {1e308, 1e-300}) {
        CameraSettings scaled;
        scaled.eye_direction *= magnitude;
        scaled.up *= magnitude;
        const CameraFrame frame = frame_camera(box, scaled, 4.0 / 3.0);
        EXPECT_LT((frame.view - unit.view).norm(), 1e-12 * unit.view.norm()) << magnitude;
        EXPECT_LT((frame.projection - unit.projection).norm(), 1e-12 * unit.projection.norm()) << magnitude;
    }
}

TEST(ImageIo, PngRoundTripIsExact) {
    Image image;
    image.width = 37;
    image.height = 11;
    image.rgba.resize(37 * 11 * 4);
    std::mt19937 rng(7);
    for (uint8_t& b : image.rgba) b = static_cast<uint8_t>(rng());
    const auto path = temp_path("round_trip.png");
    write_png(image, path);
    EXPECT_EQ(read_png(path), image);
    std::filesystem::remove(path);
}

TEST(ImageIo, RenderedImageSurvivesAPngRoundTrip) {
    const Image image = render_surface(make_sphere({0.3f, 0.3f, 0.3f}, 40, 30));
    const auto path = temp_path("render.png");
    write_png(image, path);
    EXPECT_EQ(read_png(path), image);
    std::filesystem::remove(path);
}

TEST(ImageIo, CorruptOrMissingPngThrowsFileError) {
    Image image;
    image.width = 8;
    image.height = 8;
    image.rgba.assign(8 * 8 * 4, 200);
    const auto path = temp_path("corrupt.png");
    write_png(image, path);
    const auto size = std::filesystem::file_size(path);

    std::filesystem::resize_file(path, size / 2);  // truncated
    EXPECT_THROW(read_png(path), FileError);
    {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out << "definitely not a png, just text";
    }
    try {
        read_png(path);
        ADD_FAILURE() << "no exception for a text file";
    } catch (const FileError& e) {
        EXPECT_EQ(e.path(), path.string());
    }
    { std::ofstream out(path, std::ios::binary | std::ios::trunc); }  // empty
    EXPECT_THROW(read_png(path), FileError);
    std::filesystem::remove(path);
    EXPECT_THROW(read_png(path), FileError);  // missing

    Image inconsistent = image;
    inconsistent.rgba.pop_back();
    EXPECT_THROW(write_png(inconsistent, path), InvalidArgumentError);
    EXPECT_FALSE(std::filesystem::exists(path));
}


// An environment of `width` x width / 2 pixels with radiance `radiance(direction)`.
template <typename F>
EnvironmentLight test_environment(int width, F radiance) {
    std::vector<Rgb> pixels;
    for (int y = 0; y < width / 2; ++y)
        for (int x = 0; x < width; ++x)
            pixels.push_back(radiance(EnvironmentMap::direction((x + 0.5) / width, (y + 0.5) / (width / 2))));
    return environment_light(std::make_shared<const EnvironmentMap>(width, width / 2, std::move(pixels), "test map"), 2);
}

// Each background pixel is the environment's radiance along its view ray, rotated and scaled as the
// lighting computes it (environment_radiance), so what is drawn is what lights the model.
TEST(SurfaceRenderer, TheBackgroundIsTheRotatedEnvironmentAlongEachViewRay) {
    SurfaceRenderInput input = make_sphere({0.2f, 0.2f, 0.2f}, 64, 48);
    input.lighting.environment = test_environment(512, [](const Eigen::Vector3d& w) {
        return Rgb{0.5 + 0.4 * w.x(), 0.5 + 0.4 * w.y(), 0.5 - 0.4 * w.z()};
    });
    input.lighting.environment->rotation_degrees = 70;
    input.lighting.environment->intensity = 0.9;
    input.tone_map = ToneMap::Clamp;
    input.exposure = 1.0f;
    input.camera.eye_direction = {0.3, 0.4, 1.0};
    const Image image = render_surface(input);
    Eigen::AlignedBox3d box;
    for (const Eigen::Vector3f& p : input.positions) box.extend(p.cast<double>());
    const CameraFrame frame = frame_camera(box, input.camera, static_cast<double>(input.width) / input.height);
    const Eigen::Matrix4d inverse = (frame.projection * frame.view).inverse();
    int checked = 0;
    for (const auto& [x, y] : std::vector<std::pair<int, int>>{{0, 0}, {63, 0}, {0, 47}, {63, 47}, {32, 1}, {1, 24}, {62, 30}}) {
        // Pixel centres in normalised device coordinates (OpenGL's rows run bottom up).
        const double nx = (x + 0.5) / input.width * 2 - 1, ny = (input.height - 1 - y + 0.5) / input.height * 2 - 1;
        const Eigen::Vector4d near = inverse * Eigen::Vector4d(nx, ny, -1, 1), far = inverse * Eigen::Vector4d(nx, ny, 1, 1);
        const Eigen::Vector3d w = (far.head<3>() / far.w() - near.head<3>() / near.w()).normalized();
        const std::array<uint8_t, 3> expected = srgb_bytes(environment_radiance(*input.lighting.environment, w));
        const uint8_t* p = image.pixel(x, y);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(p[c], expected[c], 3) << "pixel " << x << "," << y << " channel " << c;
        ++checked;
    }
    EXPECT_EQ(checked, 7);
    // Without `background` the clear colour shows, and with another rotation the corner changes.
    input.lighting.environment->background = false;
    const Image plain = render_surface(input);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(plain.pixel(0, 0)[c], input.background[c]);
    input.lighting.environment->background = true;
    input.lighting.environment->rotation_degrees = 250;
    const Image turned = render_surface(input);
    int difference = 0;
    for (int c = 0; c < 3; ++c) difference += std::abs(turned.pixel(0, 0)[c] - image.pixel(0, 0)[c]);
    EXPECT_GT(difference, 20);
}

// A black body under a uniform white environment shows only the environment's reflection: about F0 L
// where it faces the camera (F0 = ((eta - 1) / (eta + 1))^2), brighter towards the rim as the Fresnel
// reflectance grows, and nothing with the highlights turned off or in the inspection views.
TEST(SurfaceRenderer, TheEnvironmentsReflectionFollowsFresnel) {
    SurfaceRenderInput input = make_sphere({0, 0, 0}, 96, 96);
    input.lighting.lights.clear();
    const double radiance = 10;
    input.lighting.environment = test_environment(64, [&](const Eigen::Vector3d&) { return Rgb{radiance, radiance, radiance}; });
    input.lighting.environment->background = false;
    input.uniform_eta = 1.5f;
    input.tone_map = ToneMap::Clamp;
    input.exposure = 1.0f;
    const Image image = render_surface(input);
    const double f0 = 0.04;  // ((1.5 - 1) / (1.5 + 1))^2
    const double centre = image.pixel(48, 48)[0];
    EXPECT_GT(centre, srgb_byte(0.7 * f0 * radiance));
    EXPECT_LT(centre, srgb_byte(1.5 * f0 * radiance));
    // Along the row through the centre, the last pixel on the sphere before the background.
    int rim = 48;
    while (rim + 1 < input.width && image.pixel(rim + 1, 48)[0] != input.background[0]) ++rim;
    ASSERT_GT(rim, 60);
    EXPECT_GT(image.pixel(rim - 1, 48)[0], centre + 20);
    input.specular_scale = 0;
    EXPECT_EQ(render_surface(input).pixel(48, 48)[0], 0);
    input.specular_scale = 1;
    input.shading = SurfaceShading::VertexColour;
    input.colours.assign(input.positions.size(), {0.0f, 0.0f, 0.0f});
    EXPECT_EQ(render_surface(input).pixel(48, 48)[0], 0);
}

}  // namespace
}  // namespace waxwork
