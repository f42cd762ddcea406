// Golden images: small renders of a few scenes and modes compared with tests/golden/*.png under
// explicit tolerances. On failure the actual image and a diff are written to
// SDFCSG_TEST_OUTPUT_DIR/golden; SDFCSG_UPDATE_GOLDEN=1 rewrites the goldens instead.
#include "gpu_test.h"

#include <cstdio>
#include <cstdlib>
#include <optional>
#include <ostream>

namespace sdfcsg::test {
namespace {

namespace fs = std::filesystem;

// A pixel differs when any channel is off by more than this (of 255): drivers may round
// transcendental functions differently.
constexpr int kChannelTolerance = 4;
// At most this fraction of pixels may differ: edges that a ray grazes can flip either way.
constexpr double kDifferingFraction = 0.005;
// Mean absolute channel difference over the whole image, of 255.
constexpr double kMeanTolerance = 0.5;

struct GoldenCase {
    const char* scene; // file in assets/scenes, without .json
    RenderMode mode;
    bool boxes = false;
};

const char* modeName(RenderMode mode) {
    switch (mode) {
    case RenderMode::Shaded:
        return "shaded";
    case RenderMode::Normals:
        return "normals";
    case RenderMode::Depth:
        return "depth";
    case RenderMode::Steps:
        return "steps";
    }
    return "?";
}

std::string caseName(const GoldenCase& c) {
    return std::string(c.scene) + "_" + modeName(c.mode) + (c.boxes ? "_boxes" : "");
}

// Readable test names and failure messages instead of a byte dump.
void PrintTo(const GoldenCase& c, std::ostream* os) {
    *os << caseName(c);
}

class Golden : public GpuTest, public ::testing::WithParamInterface<GoldenCase> {};

TEST_P(Golden, MatchesWithinTolerance) {
    const GoldenCase& c = GetParam();
    const std::string name = caseName(c);
    Scene scene =
        loadOrDie(fs::path(SDFCSG_SOURCE_DIR) / "assets/scenes" / (std::string(c.scene) + ".json"));
    auto renderer = Renderer::create(context(), scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    RenderOptions options;
    options.width = 160;
    options.height = 120;
    options.mode = c.mode;
    options.boxes = c.boxes ? BoxOverlay::All : BoxOverlay::None;
    auto actual = (*renderer)->render(options);
    ASSERT_TRUE(actual) << actual.error().str();

    const fs::path golden = fs::path(SDFCSG_SOURCE_DIR) / "tests/golden" / (name + ".png");
    if (const char* update = std::getenv("SDFCSG_UPDATE_GOLDEN");
        update && std::string(update) == "1") {
        auto written = writePng(*actual, golden);
        ASSERT_TRUE(written) << written.error().str();
        std::printf("updated %s\n", golden.string().c_str());
        return;
    }

    const fs::path outDir = fs::path(SDFCSG_TEST_OUTPUT_DIR) / "golden";
    fs::create_directories(outDir);
    const fs::path actualPath = outDir / (name + "_actual.png");
    const fs::path diffPath = outDir / (name + "_diff.png");
    fs::remove(actualPath);
    fs::remove(diffPath);

    std::optional<Image> expected = readPng(golden);
    if (!expected) {
        ASSERT_TRUE(writePng(*actual, actualPath));
        FAIL() << "missing golden " << golden << "; the actual image is " << actualPath
               << "; run with SDFCSG_UPDATE_GOLDEN=1 to create it";
    }
    ASSERT_EQ(expected->width, actual->width);
    ASSERT_EQ(expected->height, actual->height);

    // Diff image: grey where equal, red where a pixel is beyond tolerance, otherwise the
    // amplified difference.
    Image diff{actual->width, actual->height, std::vector<uint8_t>(actual->rgba.size(), 255)};
    size_t differing = 0;
    double sum = 0.0;
    const size_t pixels = size_t(actual->width) * actual->height;
    for (size_t i = 0; i < pixels; ++i) {
        int worst = 0;
        for (int ch = 0; ch < 3; ++ch) {
            int d = std::abs(int(actual->rgba[4 * i + ch]) - int(expected->rgba[4 * i + ch]));
            worst = std::max(worst, d);
            sum += d;
            diff.rgba[4 * i + ch] = uint8_t(std::min(255, 40 + 8 * d));
        }
        if (worst > kChannelTolerance) {
            ++differing;
            diff.rgba[4 * i] = 255, diff.rgba[4 * i + 1] = 0, diff.rgba[4 * i + 2] = 0;
        }
    }
    const double fraction = double(differing) / pixels;
    const double mean = sum / (3.0 * pixels);
    const bool ok = fraction <= kDifferingFraction && mean <= kMeanTolerance;
    if (!ok) {
        EXPECT_TRUE(writePng(*actual, actualPath));
        EXPECT_TRUE(writePng(diff, diffPath));
    }
    EXPECT_TRUE(ok) << name << ": " << differing << " pixels (" << fraction * 100.0
                    << "%) differ by more than " << kChannelTolerance << "/255 (allowed "
                    << kDifferingFraction * 100.0 << "%), mean difference " << mean
                    << "/255 (allowed " << kMeanTolerance << ").\n  golden: " << golden
                    << "\n  actual: " << actualPath << "\n  diff:   " << diffPath
                    << "\n  If the change is intended, run with SDFCSG_UPDATE_GOLDEN=1.";
}

const GoldenCase kCases[] = {
    {"house", RenderMode::Shaded},          {"snowman", RenderMode::Shaded},
    {"smooth_blend", RenderMode::Shaded},   {"csg_part", RenderMode::Normals},
    {"robot", RenderMode::Depth},           {"gallery", RenderMode::Steps},
    {"csg_part", RenderMode::Shaded, true},
};

INSTANTIATE_TEST_SUITE_P(Scenes, Golden, ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<GoldenCase>& param) {
                             return caseName(param.param);
                         });

// Soft shadows on concave walls, where shadow rays run along the surface: a ball with three
// crossed holes, from two views. What shadows take from each pixel (the luminance without them
// less the luminance with them) must be smooth across the surface: it may depart from the mean
// of its four neighbours by more than kRough only at a few pixels (where a penumbra is narrower
// than a pixel). Streaks and speckle fail this; creases and highlights, in both images, cancel.
TEST_F(GpuTest, ShadowsOnConcaveWallsAreFreeOfStreaks) {
    constexpr const char* kPart = R"({"version": 1, "root": {"type": "difference", "children": [
        {"type": "sphere", "radius": 1.0, "color": [0.8, 0.8, 0.8]},
        {"type": "cylinder", "radius": 0.45, "height": 3, "rotate": [0, 0, 90]},
        {"type": "cylinder", "radius": 0.45, "height": 3},
        {"type": "cylinder", "radius": 0.45, "height": 3, "rotate": [90, 0, 0]}]}})";
    auto scene = parseScene(kPart, "concave.json");
    ASSERT_TRUE(scene) << scene.error().str();
    auto renderer = Renderer::create(context(), *scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    constexpr double kRough = 4.0; // of 255
    constexpr uint32_t kWidth = 320, kHeight = 240;
    const Camera views[] = {{{0.9f, 0.8f, 2.4f}, {0.0f, -0.05f, 0.0f}, {0, 1, 0}, 40.0f},
                            {{-1.6f, 1.4f, 1.9f}, {0.0f, 0.0f, 0.0f}, {0, 1, 0}, 45.0f}};
    for (const Camera& view : views) {
        RenderOptions options;
        options.width = kWidth, options.height = kHeight;
        options.camera = view;
        options.mode = RenderMode::Normals;
        auto normals = (*renderer)->render(options);
        ASSERT_TRUE(normals) << normals.error().str();
        options.mode = RenderMode::Shaded;
        std::vector<double> taken(size_t(kWidth) * kHeight, 0.0);
        for (bool shadows : {false, true}) {
            options.shadows = shadows;
            auto image = (*renderer)->render(options);
            ASSERT_TRUE(image) << image.error().str();
            for (size_t i = 0; i < taken.size(); ++i) {
                const uint8_t* c = &image->rgba[4 * i];
                taken[i] += (shadows ? -1.0 : 1.0) * (0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2]);
            }
        }
        // On a smooth part of the surface: the pixels two around hit, with normals (as colours)
        // alike, which leaves out silhouettes and creases.
        const std::vector<PixelInfo>& pixels = (*renderer)->lastPixelInfo();
        auto alike = [&](size_t i, size_t j) {
            for (int ch = 0; ch < 3; ++ch)
                if (std::abs(int(normals->rgba[4 * i + ch]) - int(normals->rgba[4 * j + ch])) > 12)
                    return false;
            return pixels[j].depth > 0.0f;
        };
        size_t inside = 0, rough = 0;
        for (uint32_t y = 2; y + 2 < kHeight; ++y)
            for (uint32_t x = 2; x + 2 < kWidth; ++x) {
                const size_t i = size_t(y) * kWidth + x;
                bool smooth = pixels[i].depth > 0.0f;
                for (int dy = -2; dy <= 2; ++dy)
                    for (int dx = -2; dx <= 2; ++dx)
                        smooth = smooth && alike(i, i + dy * ptrdiff_t(kWidth) + dx);
                const double mean =
                    (taken[i - 1] + taken[i + 1] + taken[i - kWidth] + taken[i + kWidth]) / 4.0;
                inside += smooth;
                rough += smooth && std::abs(taken[i] - mean) > kRough;
            }
        EXPECT_LE(rough, inside / 200)
            << rough << " of " << inside << " surface pixels have shadows unlike their "
            << "neighbours', seen from (" << view.eye.x << ", " << view.eye.y << ", " << view.eye.z
            << ")";
    }
}

} // namespace
} // namespace sdfcsg::test
