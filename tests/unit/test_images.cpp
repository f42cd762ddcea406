// The image profile and the heightmap on the CPU: masks and heights drawn into PNGs here against
// the analytic distances of what was drawn, their fields' slopes, their parameters' and hostile
// files' messages.
#include "scene/image.h"

#include "scene_build_util.h"

#include <sdfcsg/eval.h>
#include <sdfcsg/render.h>

#include <gtest/gtest.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>

namespace sdfcsg {
namespace {

namespace fs = std::filesystem;

fs::path outputDir() {
    const fs::path dir = fs::path(SDFCSG_TEST_OUTPUT_DIR) / "images";
    fs::create_directories(dir);
    return dir;
}

// A w by h PNG in the output folder, black where `ink` holds at a pixel's centre (x right, y up,
// in pixels from the image's centre), white elsewhere.
fs::path drawPng(const std::string& name, uint32_t w, uint32_t h,
                 const std::function<bool(glm::vec2)>& ink) {
    Image image{w, h, std::vector<uint8_t>(size_t(w) * h * 4, 255)};
    for (uint32_t r = 0; r < h; ++r)
        for (uint32_t c = 0; c < w; ++c)
            if (ink({float(c) + 0.5f - 0.5f * float(w), 0.5f * float(h) - float(r) - 0.5f}))
                for (int k = 0; k < 3; ++k)
                    image.rgba[4 * (c + size_t(w) * r) + size_t(k)] = 0;
    const fs::path file = outputDir() / name;
    EXPECT_TRUE(writePng(image, file));
    return file;
}

void writeBytes(const fs::path& file, const std::string& bytes) {
    std::ofstream(file, std::ios::binary) << bytes;
}

// The image profile's field in its plane: extruded far along z, evaluated at z = 0.
Evaluator imageField(const fs::path& file, const std::string& members) {
    return Evaluator(test::parseRoot(R"({"type": "extrude", "height": 100, "children": [
        {"type": "image", "file": ")" +
                                     file.string() + "\", " + members + "}]}"));
}

std::string errorOf(const std::string& image, const ParseOptions& options = {}) {
    auto scene = parseScene(R"({"version": 1, "root": {"type": "extrude", "height": 1,
        "children": [{"type": "image", )" +
                                image + "}]}}",
                            "test.json", options);
    return scene ? "accepted" : scene.error().str();
}

// A disk of 40 pixels' radius in a 128-pixel image 1.28 across (a pixel is 0.01): within 0.6 of a
// pixel of the disk's distance over the image (the mask's staircase is up to half a pixel from
// the circle, and the interpolation adds a little); beyond it, a lower bound of that distance and
// at least the distance to the image's rectangle.
TEST(ImageProfile, DiskIsWithinAFractionOfAPixelOfItsDistance) {
    const float radius = 40.0f, pixel = 0.01f;
    const fs::path file =
        drawPng("disk.png", 128, 128, [&](glm::vec2 p) { return glm::length(p) <= radius; });
    const Evaluator field = imageField(file, R"("size": 1.28)");
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(-1.5f, 1.5f);
    float worst = 0.0f;
    for (int i = 0; i < 20000; ++i) {
        const glm::vec2 p(u(rng), u(rng));
        const float truth = glm::length(p) - radius * pixel, d = field.distance({p, 0.0f});
        if (glm::max(std::abs(p.x), std::abs(p.y)) <= 0.64f) {
            worst = std::max(worst, std::abs(d - truth));
        } else {
            ASSERT_LE(d, truth + 0.5f * pixel) << p.x << " " << p.y;
            const glm::vec2 e = glm::abs(p) - 0.64f;
            ASSERT_GE(d, glm::length(glm::max(e, 0.0f)) - 1e-6f) << p.x << " " << p.y;
        }
    }
    EXPECT_LT(worst, 0.6f * pixel);
    std::printf("disk: within %.3f of a pixel\n", double(worst / pixel));
}

// A square of 60 by 60 pixels, off centre, in a 100 by 80 image given its width: its edges lie
// on pixel edges, so the distance is exact at the pixels' centres and within a small part of a
// pixel between them (a bit more around the corners, where bilinear interpolation rounds them).
TEST(ImageProfile, SquareMatchesTheBoxDistance) {
    const float pixel = 0.02f;
    const glm::vec2 centre(-10.0f, 5.0f), half(30.0f);
    const fs::path file = drawPng("square.png", 100, 80, [&](glm::vec2 p) {
        const glm::vec2 e = glm::abs(p - centre);
        return e.x < half.x && e.y < half.y;
    });
    const Evaluator field = imageField(file, R"("width": 2)");
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    float worst = 0.0f;
    for (int i = 0; i < 20000; ++i) {
        const glm::vec2 p(u(rng), 0.8f * u(rng));
        const glm::vec2 e = glm::abs(p - centre * pixel) - half * pixel;
        const float truth = glm::length(glm::max(e, 0.0f)) + std::min(std::max(e.x, e.y), 0.0f);
        worst = std::max(worst, std::abs(field.distance({p, 0.0f}) - truth));
    }
    EXPECT_LT(worst, 0.35f * pixel);
    std::printf("square: within %.3f of a pixel\n", double(worst / pixel));
}

// The slope between points a pixel or more apart stays within 1 and a small part of a pixel
// over their distance, over the emblem and beyond its image (sdImage's bound there).
TEST(ImageProfile, SlopeStaysNearOne) {
    const Evaluator field = imageField(fs::path(SDFCSG_SOURCE_DIR) / "assets/scenes/emblem.png",
                                       R"("size": 2.56)"); // a pixel is 0.01
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-1.6f, 1.6f), step(-0.05f, 0.05f);
    for (int i = 0; i < 40000; ++i) {
        const glm::vec3 a(u(rng), u(rng), 0.0f), b = a + glm::vec3(step(rng), step(rng), 0.0f);
        const float apart = glm::length(b - a);
        if (apart < 0.01f) continue;
        ASSERT_LE(std::abs(field.distance(a) - field.distance(b)), apart + 0.003f)
            << a.x << " " << a.y << " to " << b.x << " " << b.y;
    }
}

TEST(ImageProfile, DistancesAreHalfAPixelAtTheEdge) {
    // One pixel inside, in the middle of three by three.
    std::vector<bool> inside(9, false);
    inside[4] = true;
    const std::vector<float> d = detail::signedDistances(inside, 3, 3);
    EXPECT_FLOAT_EQ(d[4], -0.5f);
    EXPECT_FLOAT_EQ(d[1], 0.5f);
    EXPECT_FLOAT_EQ(d[0], std::sqrt(2.0f) - 0.5f);
}

TEST(ImageProfile, InsideLightInvertsTheMask) {
    const fs::path file =
        drawPng("dot.png", 32, 32, [](glm::vec2 p) { return glm::length(p) <= 8.0f; });
    const Evaluator dark = imageField(file, R"("size": 1)");
    const Evaluator light = imageField(file, R"("size": 1, "inside": "light")");
    EXPECT_LT(dark.distance({0.0f, 0.0f, 0.0f}), 0.0f);
    EXPECT_GT(light.distance({0.0f, 0.0f, 0.0f}), 0.0f);
    EXPECT_GT(dark.distance({0.4f, 0.4f, 0.0f}), 0.0f);
    EXPECT_LT(light.distance({0.4f, 0.4f, 0.0f}), 0.0f);
}

TEST(ImageProfile, ItsFileProblemsAreNamed) {
    const fs::path dir = outputDir();
    ParseOptions options;
    options.files.folder = fs::relative(dir); // the messages' paths, short enough to show whole
    const std::string at = "test.json: root.children[0].file: cannot load image \"";
    EXPECT_EQ(errorOf(R"("file": "missing.png")", options),
              at + (options.files.folder / "missing.png").string() + "\": no such file");
    writeBytes(options.files.folder / "text.png", "this is not a picture");
    EXPECT_EQ(errorOf(R"("file": "text.png")", options),
              at + (options.files.folder / "text.png").string() + "\": not a PNG file");
    // A real PNG cut short.
    const fs::path whole = drawPng("whole.png", 64, 64, [](glm::vec2 p) { return p.x < 0.0f; });
    std::ifstream in(whole, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    writeBytes(options.files.folder / "cut.png", bytes.substr(0, bytes.size() / 2));
    EXPECT_EQ(errorOf(R"("file": "cut.png")", options),
              at + (options.files.folder / "cut.png").string() +
                  "\": a PNG that cannot be decoded (Corrupt PNG)");
    // Headers that claim no pixels, and far too many: refused before anything is decoded.
    auto header = [&](uint32_t w, uint32_t h) {
        std::string ihdr = std::string("\x89PNG\r\n\x1a\n", 8) + std::string("\0\0\0\x0dIHDR", 8);
        for (uint32_t v : {w, h})
            for (int s = 24; s >= 0; s -= 8)
                ihdr += char((v >> s) & 0xff);
        return ihdr + std::string("\x08\x00\x00\x00\x00", 5) + std::string(4, '\0');
    };
    writeBytes(options.files.folder / "empty.png", header(0, 0));
    EXPECT_EQ(errorOf(R"("file": "empty.png")", options),
              at + (options.files.folder / "empty.png").string() +
                  "\": a PNG of 0 x 0 pixels, expected at least 1 x 1");
    writeBytes(options.files.folder / "huge.png", header(2147483647u, 2147483647u));
    EXPECT_EQ(errorOf(R"("file": "huge.png")", options),
              at + (options.files.folder / "huge.png").string() +
                  "\": a PNG of 2147483647 x 2147483647 pixels, more than the limit of 4194304 "
                  "pixels and 8192 on a side");
    // Blank: nothing inside the mask.
    drawPng("blank.png", 8, 8, [](glm::vec2) { return false; });
    EXPECT_EQ(errorOf(R"("file": "blank.png", "threshold": 0.25)", options),
              "test.json: root.children[0].file: expected an image with pixels inside its mask "
              "(dark and opaque, at least the threshold 0.25), got none in \"blank.png\"");
    // An untrusted scene's problems say nothing of the file system.
    options.files.trusted = false;
    for (const char* name : {"missing.png", "text.png", "/etc/passwd", "../images/cut.png"})
        EXPECT_EQ(errorOf(R"("file": ")" + std::string(name) + "\"", options),
                  "test.json: root.children[0].file: unknown image \"" + std::string(name) +
                      "\": name a PNG file in the scene's folder");
}

TEST(ImageProfile, ItsParametersAreChecked) {
    const std::string emblem = R"("file": "emblem.png")";
    EXPECT_EQ(errorOf(emblem + R"(, "size": 1, "width": 2)"),
              "test.json: root.children[0].width: expected one of \"size\", \"width\" and "
              "\"height\" (each sets the image's size), got both \"size\" and \"width\"");
    EXPECT_EQ(errorOf(emblem + R"(, "threshold": 1.5)"),
              "test.json: root.children[0].threshold: expected at most 1, got 1.5");
    EXPECT_EQ(errorOf(emblem + R"(, "inside": "white")"),
              "test.json: root.children[0].inside: expected one of \"dark\" or \"light\", got "
              "\"white\"");
    EXPECT_EQ(errorOf(R"("size": 1)"),
              "test.json: root.children[0]: missing required key \"file\" (a string)");
}

// A w by h PNG of grey levels grey(column, row) in 0..255.
fs::path greyPng(const std::string& name, uint32_t w, uint32_t h,
                 const std::function<uint8_t(uint32_t, uint32_t)>& grey) {
    Image image{w, h, std::vector<uint8_t>(size_t(w) * h * 4, 255)};
    for (uint32_t r = 0; r < h; ++r)
        for (uint32_t c = 0; c < w; ++c)
            for (size_t k = 0; k < 3; ++k)
                image.rgba[4 * (c + size_t(w) * r) + k] = grey(c, r);
    const fs::path file = outputDir() / name;
    EXPECT_TRUE(writePng(image, file));
    return file;
}

Evaluator heightmapField(const fs::path& file, const std::string& size) {
    return Evaluator(test::parseRoot(R"({"type": "heightmap", "file": ")" + file.string() +
                                     R"(", "size": )" + size + "}"));
}

// Grey levels rising by 5 a column (exactly linear in 8 bits) make a ramp: above it, away from
// its edges, the field is the distance to its plane (its slope is the bound it divides by).
TEST(Heightmap, RampIsTheDistanceToItsPlane) {
    const fs::path file = greyPng("ramp.png", 52, 8, [](uint32_t c, uint32_t) { return c * 5; });
    const Evaluator field = heightmapField(file, "[2.6, 0.5, 1]"); // a pixel is 0.05 along x
    const double slope = 0.5 / 2.55;                               // 0.5 over 51 pixels
    auto height = [&](double x) { return (x + 1.3 - 0.025) * slope; };
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), up(0.0f, 0.15f);
    for (int i = 0; i < 5000; ++i) {
        const float x = u(rng), z = 0.3f * u(rng);
        const float y = float(height(x)) + up(rng);
        const double truth = (y - height(x)) / std::sqrt(1.0 + slope * slope);
        ASSERT_NEAR(field.distance({x, y, z}), truth, 2e-5) << x << " " << y << " " << z;
    }
    // Below the ramp, inside its box: inside.
    EXPECT_LT(field.distance({0.5f, float(height(0.5)) - 0.01f, 0.0f}), 0.0f);
    EXPECT_GT(field.distance({0.5f, float(height(0.5)) + 0.01f, 0.0f}), 0.0f);
}

// Over the bundled terrain the field changes by at most the distance between two points, is
// negative exactly below the interpolated heights within the box, and bounds the distance.
TEST(Heightmap, TerrainFieldIsABound) {
    const Evaluator field =
        heightmapField(fs::path(SDFCSG_SOURCE_DIR) / "assets/scenes/terrain.png", "[2, 0.6, 2]");
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1.3f, 1.3f), step(-0.2f, 0.2f);
    for (int i = 0; i < 20000; ++i) {
        const glm::vec3 a(u(rng), 0.5f * u(rng) + 0.3f, u(rng));
        const glm::vec3 b = a + glm::vec3(step(rng), step(rng), step(rng));
        ASSERT_LE(std::abs(field.distance(a) - field.distance(b)),
                  glm::length(b - a) * (1.0f + 1e-5f) + 1e-6f)
            << a.x << " " << a.y << " " << a.z;
    }
    // A column through the terrain changes sign once, where the heights are; the value above is
    // at most the height above the surface.
    for (int i = 0; i < 200; ++i) {
        const float x = 0.95f * u(rng) / 1.3f, z = 0.95f * u(rng) / 1.3f;
        float surface = -1.0f;
        for (float y = 0.0005f; y < 0.6f; y += 0.001f)
            if (field.distance({x, y, z}) >= 0.0f) {
                surface = y;
                break;
            }
        ASSERT_GE(surface, 0.0f) << x << " " << z;
        for (float y : {surface + 0.05f, surface + 0.3f})
            EXPECT_LE(field.distance({x, y, z}), y - surface + 1e-3f);
        for (float y = surface + 0.002f; y < 0.7f; y += 0.01f)
            ASSERT_GT(field.distance({x, y, z}), 0.0f) << x << " " << y << " " << z;
    }
}

TEST(Heightmap, ItsProblemsAreNamed) {
    auto error = [](const std::string& members) {
        auto scene = parseScene(R"({"version": 1, "root": {"type": "heightmap", )" + members + "}}",
                                "test.json");
        return scene ? "accepted" : scene.error().str();
    };
    EXPECT_EQ(error(R"("file": "emblem.png")"),
              "test.json: root: missing required key \"size\" (an array of 3 positive numbers)");
    EXPECT_EQ(error(R"("file": "nothing.png", "size": [1, 1, 1])"),
              "test.json: root.file: cannot load image \"nothing.png\": no such file");
}

} // namespace
} // namespace sdfcsg
