// The GPU ray march against CPU sphere tracing with the reference evaluator: same rays (camera.h),
// same clipping, same epsilon rule. Plus modes, bounds skipping, value updates and PNG output.
#include "codegen/shader_compile.h"
#include "driver_cache.h"
#include "gpu/vk.h"
#include "gpu_test.h"
#include "render/camera.h"
#include "scoped_env.h"
#include "shared.h"

#include <glm/common.hpp>
#include <glm/exponential.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <fstream>
#include <random>

#include <sys/resource.h>

namespace sdfcsg::test {
namespace {

namespace fs = std::filesystem;

constexpr uint32_t kSize = 128;

struct CpuHit {
    float t = -1.0f;
    uint32_t steps = 0;
};

// The loop of march() in shaders/march.comp.
CpuHit traceCpu(const Evaluator& ev, const detail::RayCamera& rc, const detail::ClipVolume& clip,
                glm::vec3 dir) {
    CpuHit hit;
    float tNear, tFar;
    if (!detail::rayInterval(clip, rc.eye, dir, tNear, tFar)) return hit;
    float t = tNear;
    for (uint32_t i = 0; i < SDFCSG_MAX_STEPS; ++i) {
        hit.steps = i + 1;
        float d = ev.distance(rc.eye + dir * t);
        if (d < detail::hitEpsilon(rc, t)) {
            hit.t = t;
            break;
        }
        t += d;
        if (t > tFar) break;
    }
    return hit;
}

glm::vec3 tetraNormal(const Evaluator& ev, glm::vec3 p, float h) {
    const glm::vec3 a(1, -1, -1), b(-1, -1, 1), c(-1, 1, -1), d(1, 1, 1);
    return glm::normalize(a * ev.distance(p + a * h) + b * ev.distance(p + b * h) +
                          c * ev.distance(p + c * h) + d * ev.distance(p + d * h));
}

Camera cameraFor(const Scene& scene, const Evaluator& ev, float aspect = 1.0f) {
    return scene.camera ? *scene.camera : frameCamera(ev, aspect);
}

glm::vec3 pixel(const Image& image, size_t i) {
    return glm::vec3(image.rgba[4 * i], image.rgba[4 * i + 1], image.rgba[4 * i + 2]);
}

// Shading of shaders/shade.comp without shadows and occlusion, in 0..255.
glm::vec3 shadeCpu(const Scene& scene, const Evaluator& ev, const detail::RayCamera& rc,
                   const detail::ClipVolume& clip, glm::vec3 dir, float t) {
    glm::vec3 p = rc.eye + dir * t;
    glm::vec3 n = tetraNormal(ev, p, detail::hitEpsilon(rc, t));
    glm::vec3 albedo = ev.sample(p).color;
    albedo *= albedo;
    glm::vec3 sky = scene.background * scene.background;
    glm::vec3 col = albedo * (0.10f + 0.15f * sky * (0.5f + 0.5f * n.y));
    std::vector<Light> lights = scene.lights.empty() ? defaultLights() : scene.lights;
    for (size_t i = 0; i < lights.size() && i < SDFCSG_MAX_LIGHTS; ++i) {
        glm::vec3 l = -glm::normalize(lights[i].direction);
        float lambert = std::max(glm::dot(n, l), 0.0f);
        float spec = std::pow(std::max(glm::dot(n, glm::normalize(l - dir)), 0.0f), 48.0f) * 0.25f;
        col += lights[i].color * lights[i].intensity * lambert * (albedo + spec);
    }
    col = glm::sqrt(col);
    float x = glm::clamp((t / clip.far - 0.6f) / 0.4f, 0.0f, 1.0f);
    float fog = x * x * (3.0f - 2.0f * x);
    col = glm::mix(col, scene.background, fog);
    return glm::clamp(col, 0.0f, 1.0f) * 255.0f;
}

class SceneRender : public GpuTest, public ::testing::WithParamInterface<fs::path> {};

TEST_P(SceneRender, HitMaskDepthAndColoursAgreeWithCpuTracing) {
    Scene scene = loadOrDie(GetParam());
    ASSERT_FALSE(scene.nodes.empty());
    Evaluator ev(scene);
    Camera camera = cameraFor(scene, ev);
    auto renderer = Renderer::create(context(), scene);
    ASSERT_TRUE(renderer) << renderer.error().str();

    RenderOptions options;
    options.width = options.height = kSize;
    options.camera = camera;
    options.shadows = false;
    options.ambientOcclusion = false;
    auto shaded = (*renderer)->render(options);
    ASSERT_TRUE(shaded) << shaded.error().str();
    std::vector<PixelInfo> info = (*renderer)->lastPixelInfo();
    options.mode = RenderMode::Normals;
    auto normals = (*renderer)->render(options);
    ASSERT_TRUE(normals) << normals.error().str();
    ASSERT_EQ(info.size(), size_t(kSize) * kSize);

    detail::RayCamera rc = detail::makeRayCamera(camera, kSize, kSize);
    detail::ClipVolume clip = detail::makeClipVolume(ev, rc.eye);
    size_t agree = 0, hits = 0, colourChecked = 0, colourOk = 0, normalOk = 0;
    for (uint32_t y = 0; y < kSize; ++y) {
        for (uint32_t x = 0; x < kSize; ++x) {
            size_t i = size_t(y) * kSize + x;
            glm::vec3 dir = detail::rayDirection(rc, x + 0.5f, y + 0.5f, kSize, kSize);
            CpuHit cpu = traceCpu(ev, rc, clip, dir);
            bool gpuHit = info[i].depth >= 0.0f, cpuHit = cpu.t >= 0.0f;
            hits += cpuHit;
            if (gpuHit != cpuHit) continue;
            if (!cpuHit) {
                ++agree;
                continue;
            }
            float tolerance = 4.0f * detail::hitEpsilon(rc, cpu.t) + 1e-4f * cpu.t;
            if (std::abs(info[i].depth - cpu.t) > tolerance) continue;
            ++agree;
            ++colourChecked;
            glm::vec3 expected = shadeCpu(scene, ev, rc, clip, dir, info[i].depth);
            glm::vec3 diff = glm::abs(pixel(*shaded, i) - expected);
            colourOk += std::max(diff.x, std::max(diff.y, diff.z)) <= 6.0f;
            glm::vec3 n = tetraNormal(ev, rc.eye + dir * info[i].depth,
                                      detail::hitEpsilon(rc, info[i].depth));
            glm::vec3 nDiff =
                glm::abs(pixel(*normals, i) - glm::clamp(n * 0.5f + 0.5f, 0.0f, 1.0f) * 255.0f);
            normalOk += std::max(nDiff.x, std::max(nDiff.y, nDiff.z)) <= 6.0f;
        }
    }
    const double total = double(kSize) * kSize;
    EXPECT_GE(hits, total * 0.05) << "the camera should see the scene";
    EXPECT_GE(agree / total, 0.995) << agree << " of " << total << " pixels agree";
    ASSERT_GT(colourChecked, 0u);
    EXPECT_GE(double(colourOk) / colourChecked, 0.99)
        << colourOk << " of " << colourChecked << " hit colours within 6/255";
    EXPECT_GE(double(normalOk) / colourChecked, 0.99)
        << normalOk << " of " << colourChecked << " normals within 6/255";
}

// The march pass skips workgroups outside the projections of the surface boxes; a ray there
// must miss everything, and the renderer must report it as a miss without steps.
TEST_P(SceneRender, RaysOutsideTheSurfaceRectanglesMiss) {
    Scene scene = loadOrDie(GetParam());
    Evaluator ev(scene);
    Camera camera = cameraFor(scene, ev);
    detail::RayCamera rc = detail::makeRayCamera(camera, kSize, kSize);
    detail::ClipVolume clip = detail::makeClipVolume(ev, rc.eye);
    std::vector<detail::ScreenRect> rects;
    if (!detail::surfaceRects(rc, clip, kSize, kSize, rects))
        GTEST_SKIP() << "a half-space holds surfaces: every ray is traced";
    auto renderer = Renderer::create(context(), scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    RenderOptions options;
    options.width = options.height = kSize;
    options.camera = camera;
    ASSERT_TRUE((*renderer)->render(options));
    const std::vector<PixelInfo>& info = (*renderer)->lastPixelInfo();
    size_t outside = 0;
    for (uint32_t y = 0; y < kSize; ++y)
        for (uint32_t x = 0; x < kSize; ++x) {
            const float px = x + 0.5f, py = y + 0.5f;
            bool inside = false;
            for (const detail::ScreenRect& r : rects)
                inside = inside || (px >= r.x0 && px < r.x1 && py >= r.y0 && py < r.y1);
            if (inside) continue;
            ++outside;
            glm::vec3 dir = detail::rayDirection(rc, px, py, kSize, kSize);
            EXPECT_LT(traceCpu(ev, rc, clip, dir).t, 0.0f) << "pixel " << x << ", " << y;
            const PixelInfo& p = info[size_t(y) * kSize + x];
            EXPECT_LT(p.depth, 0.0f) << "pixel " << x << ", " << y;
            EXPECT_EQ(p.steps, 0u) << "pixel " << x << ", " << y;
        }
    if (fs::path(GetParam()).stem() == "house") {
        EXPECT_GT(outside, size_t(kSize) * kSize / 5) << "the sky above the house";
    }
}

TEST_P(SceneRender, BoundsSkippingDoesNotChangeTheImage) {
    Scene scene = loadOrDie(GetParam());
    auto renderer = Renderer::create(context(), scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    RenderOptions options;
    options.width = 96, options.height = 72;
    options.boundsSkipping = true;
    auto on = (*renderer)->render(options);
    ASSERT_TRUE(on);
    std::vector<PixelInfo> infoOn = (*renderer)->lastPixelInfo();
    options.boundsSkipping = false;
    auto off = (*renderer)->render(options);
    ASSERT_TRUE(off);
    std::vector<PixelInfo> infoOff = (*renderer)->lastPixelInfo();
    // Skipping never changes a value, but the compiler may contract the two variants'
    // arithmetic differently, so allow last-bit differences.
    size_t same = 0, maxDiff = 0;
    for (size_t i = 0; i < on->rgba.size(); ++i) {
        size_t d = size_t(std::abs(int(on->rgba[i]) - int(off->rgba[i])));
        maxDiff = std::max(maxDiff, d);
        same += d == 0;
    }
    EXPECT_GE(double(same) / on->rgba.size(), 0.999);
    EXPECT_LE(maxDiff, 64u);
    size_t maskSame = 0;
    for (size_t i = 0; i < infoOn.size(); ++i)
        maskSame += (infoOn[i].depth >= 0) == (infoOff[i].depth >= 0);
    EXPECT_GE(double(maskSame) / infoOn.size(), 0.999);
}

// Pruned tapes against the inlined tree: the same hits and depths, and the same colours but
// where a far cell's bound steers a shadow ray or an occlusion tap differently.
void expectTapesMatchInlined(Context& context, const Scene& scene, uint32_t width, uint32_t height,
                             double colourShare = 0.02) {
    RenderOptions options;
    options.width = width, options.height = height;
    std::optional<Image> images[2];
    std::vector<PixelInfo> infos[2];
    for (int tapes = 0; tapes < 2; ++tapes) {
        RendererOptions made;
        made.evaluation = tapes ? Evaluation::Tapes : Evaluation::Inlined;
        auto renderer = Renderer::create(context, scene, made);
        ASSERT_TRUE(renderer) << renderer.error().str();
        auto image = (*renderer)->render(options);
        ASSERT_TRUE(image) << image.error().str();
        images[tapes] = std::move(*image);
        infos[tapes] = (*renderer)->lastPixelInfo();
    }
    // The two march with other steps (a far cell's bound is shorter than the field), so their
    // hits may lie apart by the hit tolerance: up to half a pixel's footprint.
    const float footprint =
        2.0f *
        std::tan(
            glm::radians(cameraFor(scene, Evaluator(scene), float(width) / float(height)).fov) *
            0.5f) /
        float(height);
    size_t agree = 0, hits = 0, colourOff = 0;
    for (size_t i = 0; i < infos[0].size(); ++i) {
        const PixelInfo &a = infos[0][i], &b = infos[1][i];
        const bool hit = a.depth >= 0.0f;
        agree += hit == (b.depth >= 0.0f) &&
                 (!hit || std::abs(a.depth - b.depth) <= footprint * a.depth + 1e-3f);
        if (!hit) continue;
        ++hits;
        int worst = 0;
        for (int c = 0; c < 3; ++c)
            worst = std::max(
                worst, std::abs(int(images[0]->rgba[4 * i + c]) - int(images[1]->rgba[4 * i + c])));
        colourOff += worst > 24;
    }
    EXPECT_GE(double(agree) / double(infos[0].size()), 0.995) << scene.file;
    EXPECT_LE(double(colourOff), colourShare * double(hits)) << scene.file;
}

// At 320 x 240 the rims of thin raised parts (the name plate's letters), where the two hits'
// shift within the hit tolerance turns the normal, are few enough beside the hits.
TEST_P(SceneRender, PrunedTapesMatchTheInlinedTree) {
    expectTapesMatchInlined(context(), loadOrDie(GetParam()), 320, 240);
}

TEST_P(SceneRender, DefaultCameraIsTheScenesOrTheFramedOne) {
    Scene scene = loadOrDie(GetParam());
    Evaluator ev(scene);
    auto renderer = Renderer::create(context(), scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    RenderOptions options;
    options.width = 64, options.height = 48;
    auto implicit = (*renderer)->render(options);
    ASSERT_TRUE(implicit);
    options.camera = cameraFor(scene, ev, 64.0f / 48.0f);
    auto explicitCamera = (*renderer)->render(options);
    ASSERT_TRUE(explicitCamera);
    EXPECT_EQ(implicit->rgba, explicitCamera->rgba);
}

INSTANTIATE_TEST_SUITE_P(Bundled, SceneRender, ::testing::ValuesIn(bundledScenes()), sceneTestName);

fs::path scenePath(const char* name) {
    return fs::path(SDFCSG_SOURCE_DIR) / "assets/scenes" / name;
}

class Render : public GpuTest {};

// Random scenes of a few hundred nodes, every kind and operation, sharp and smooth: as many
// as the inlined path compiles in a few seconds on lavapipe (test_prune holds the benchmark
// scenes' pruned field to the whole tree on the CPU).
TEST_F(Render, RandomScenesRenderTheSameWithTapes) {
    for (uint32_t seed : {4u, 9u})
        // Random scenes pack many surfaces into shadow rays' way: more colours differ.
        expectTapesMatchInlined(context(), randomScene(seed, 220), 96, 72, 0.06);
}

// A cell far from every surface holds none, however small beside the hit epsilon: seen from
// far away at a low resolution, where a pixel's footprint spans several leaf cells, the tapes'
// silhouette is the inlined tree's, not grown by the far cells around it.
TEST_F(Render, FarCellsAreNeverHits) {
    std::vector<Tree> balls;
    for (int i = 0; i < 200; ++i)
        balls.push_back(sphere(0.05f).at(0.9f * std::sin(0.37f * float(i)),
                                         0.9f * std::cos(0.23f * float(i)),
                                         0.9f * std::sin(0.11f * float(i) + 1.0f)));
    const Scene scene = makeScene(unite(std::move(balls)), "<far>");
    RenderOptions options;
    options.width = 64, options.height = 48;
    options.camera =
        Camera{glm::vec3(0.0f, 0.0f, 12.0f), glm::vec3(0.0f), glm::vec3(0, 1, 0), 20.0f};
    std::vector<PixelInfo> infos[2];
    for (int tapes = 0; tapes < 2; ++tapes) {
        RendererOptions made;
        made.evaluation = tapes ? Evaluation::Tapes : Evaluation::Inlined;
        auto renderer = Renderer::create(context(), scene, made);
        ASSERT_TRUE(renderer) << renderer.error().str();
        ASSERT_TRUE((*renderer)->render(options));
        infos[tapes] = (*renderer)->lastPixelInfo();
    }
    size_t hits[2] = {}, grown = 0;
    for (size_t i = 0; i < infos[0].size(); ++i) {
        const bool a = infos[0][i].depth >= 0.0f, b = infos[1][i].depth >= 0.0f;
        hits[0] += a, hits[1] += b, grown += b && !a;
    }
    EXPECT_GT(hits[0], 100u);
    // When far bounds counted as hits: 414 hits against 347. Rays that pass
    // the surface within the epsilon but only through far cells (beyond a leaf cell's radius
    // from it) hit the inlined tree and miss the tapes: a silhouette thinner by a fraction of a
    // pixel, where the leaf cells are smaller than a pixel's footprint.
    EXPECT_LE(double(grown), 0.005 * double(infos[0].size()))
        << hits[0] << " inlined hits, " << hits[1] << " with tapes";
}

// A scene at the node and nesting limits (Limits: 16,384 nodes, 64 nested operations) renders at
// 1280 x 720 and meshes at resolution 256, the process staying under 2 GiB resident: a chain of
// 63 smooth unions inside the root, and a field of 16,256 primitives of four kinds.
TEST_F(Render, SceneAtTheLimitsRendersAndMeshesUnderTwoGiB) {
    Tree chain = sphere(0.6f).at(0.0f, 1.0f, 0.0f);
    for (int d = 1; d < 64; ++d)
        chain =
            unite({std::move(chain), box(0.3f, 0.3f, 0.3f).at(0.1f * float(d), 1.0f, 0.0f)}, 0.05f);
    std::vector<Tree> parts{std::move(chain)};
    const Tree kinds[] = {sphere(0.3f), box(0.3f, 0.2f, 0.3f), cylinder(0.25f, 0.4f),
                          torus(0.25f, 0.08f)};
    for (int i = 0; i < 16256; ++i) {
        Tree t = kinds[i % 4];
        parts.push_back(t.at(float(i % 128) - 64.0f, 0.0f, float(i / 128) - 64.0f));
    }
    const Scene built = makeScene(unite(std::move(parts)), "<limits>");
    ASSERT_EQ(built.nodes.size(), size_t(Limits{}.maxNodes));
    auto scene = parseScene(toJson(built), "<limits>"); // within the limits, exactly
    ASSERT_TRUE(scene) << scene.error().str();
    auto deeper = parseScene(toJson(built), "<limits>", Limits{.maxDepth = 63});
    ASSERT_FALSE(deeper);

    auto renderer = Renderer::create(context(), *scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    RenderOptions options;
    options.width = 1280;
    options.height = 720;
    auto image = (*renderer)->render(options);
    ASSERT_TRUE(image) << image.error().str();
    MeshOptions meshOptions;
    meshOptions.resolution = 256;
    auto mesh = extractMesh(context(), *scene, meshOptions);
    ASSERT_TRUE(mesh) << mesh.error().str();
    EXPECT_GT(mesh->triangleCount(), 100000u);
    rusage usage{};
    ::getrusage(RUSAGE_SELF, &usage);
    EXPECT_LT(double(usage.ru_maxrss) * 1024.0, 2.0 * double(1u << 30)) << "peak resident";
}

// 2,000 spheres that all overlap in one smooth union prune to nearly nothing: every region near
// the surface would evaluate all of them, so the renderer and the mesher refuse the scene before
// any render, naming the limit.
TEST_F(Render, TreesThatPruneTooLittleAreRefused) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> jitter(-0.01f, 0.01f);
    std::vector<Tree> spheres;
    for (int i = 0; i < 2000; ++i)
        spheres.push_back(sphere(0.5f).at(jitter(rng), jitter(rng), jitter(rng)));
    const Scene scene = makeScene(unite(std::move(spheres), 0.05f), "blob.json");
    const std::string expected =
        "blob.json: root: the tree prunes too little to render or mesh in bounded time: near its "
        "surface, a region evaluates 3999 instructions on average, above the limit of 1024 (many "
        "primitives that all overlap in one smooth operation do this)";
    auto renderer = Renderer::create(context(), scene);
    ASSERT_FALSE(renderer);
    EXPECT_EQ(renderer.error().kind, ErrorKind::Limit);
    EXPECT_EQ(renderer.error().str(), expected);
    auto mesher = Mesher::create(context(), scene);
    ASSERT_FALSE(mesher);
    EXPECT_EQ(mesher.error().str(), expected);
}

TEST_F(Render, AllModesRenderWhatTheyPromise) {
    Scene scene = loadOrDie(scenePath("snowman.json"));
    auto renderer = Renderer::create(context(), scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    RenderOptions options;
    options.width = 80, options.height = 60;

    options.mode = RenderMode::Steps;
    auto steps = (*renderer)->render(options);
    ASSERT_TRUE(steps);
    std::vector<PixelInfo> info = (*renderer)->lastPixelInfo();
    size_t hits = 0;
    for (size_t i = 0; i < info.size(); ++i) {
        ASSERT_GE(info[i].steps, info[i].depth >= 0 ? 1u : 0u);
        ASSERT_LE(info[i].steps, uint32_t(SDFCSG_MAX_STEPS));
        hits += info[i].depth >= 0;
    }
    ASSERT_GT(hits, info.size() / 20);
    // The heat map of shaders/raymarch.glsl: blue for few steps through green to red, on a log
    // scale.
    auto heat = [](uint32_t n) {
        float x = std::log2(1.0f + float(n)) / std::log2(1.0f + float(SDFCSG_MAX_STEPS));
        glm::vec3 c(1.5f - std::abs(4 * x - 3), 1.5f - std::abs(4 * x - 2),
                    1.5f - std::abs(4 * x - 1));
        return glm::round(glm::clamp(c, 0.0f, 1.0f) * 255.0f);
    };
    for (size_t i = 0; i < info.size(); ++i) {
        glm::vec3 d = glm::abs(pixel(*steps, i) - heat(info[i].steps));
        ASSERT_LE(std::max(d.x, std::max(d.y, d.z)), 1.0f) << "pixel " << i;
    }
    std::mt19937 rng(7);
    std::uniform_int_distribution<size_t> pick(0, info.size() - 1);
    int ordered = 0, compared = 0;

    options.mode = RenderMode::Depth;
    auto depth = (*renderer)->render(options);
    ASSERT_TRUE(depth);
    compared = ordered = 0;
    for (int k = 0; k < 4000; ++k) {
        size_t a = pick(rng), b = pick(rng);
        if (info[a].depth < 0) {
            EXPECT_EQ(pixel(*depth, a), glm::vec3(0.0f)) << "misses are black";
            continue;
        }
        if (info[b].depth < 0 || info[a].depth + 0.05f > info[b].depth) continue;
        ++compared;
        ordered += pixel(*depth, a).r >= pixel(*depth, b).r; // nearer is brighter
    }
    ASSERT_GT(compared, 20);
    EXPECT_EQ(ordered, compared);

    options.mode = RenderMode::Normals;
    auto normals = (*renderer)->render(options);
    ASSERT_TRUE(normals);
    for (size_t i = 0; i < info.size(); ++i) {
        if (info[i].depth < 0) continue;
        glm::vec3 n = pixel(*normals, i) / 127.5f - 1.0f;
        EXPECT_NEAR(glm::length(n), 1.0f, 0.03f);
    }

    options.mode = RenderMode::Shaded;
    auto shaded = (*renderer)->render(options);
    ASSERT_TRUE(shaded);
    EXPECT_NE(shaded->rgba, normals->rgba);
    for (size_t i = 0; i < info.size(); ++i) { // the background shows where nothing is hit
        if (info[i].depth >= 0) continue;
        glm::vec3 expected = glm::round(glm::clamp(scene.background, 0.0f, 1.0f) * 255.0f);
        ASSERT_EQ(pixel(*shaded, i), expected);
    }
}

TEST_F(Render, ShadowsOcclusionAndSupersamplingChangeTheImage) {
    Scene scene = loadOrDie(scenePath("house.json"));
    auto renderer = Renderer::create(context(), scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    RenderOptions options;
    options.width = 80, options.height = 60;
    options.shadows = options.ambientOcclusion = false;
    auto plain = (*renderer)->render(options);
    options.shadows = true;
    auto shadows = (*renderer)->render(options);
    options.ambientOcclusion = true;
    auto both = (*renderer)->render(options);
    options.aa = 3;
    auto aa = (*renderer)->render(options);
    ASSERT_TRUE(plain && shadows && both && aa);
    auto darker = [](const Image& a, const Image& b) { // pixels of b darker than in a
        size_t n = 0;
        for (size_t i = 0; i + 3 < a.rgba.size(); i += 4)
            n += int(b.rgba[i]) + b.rgba[i + 1] + b.rgba[i + 2] + 6 <
                 int(a.rgba[i]) + a.rgba[i + 1] + a.rgba[i + 2];
        return n;
    };
    EXPECT_GT(darker(*plain, *shadows), 50u) << "shadows darken some pixels";
    EXPECT_GT(darker(*shadows, *both), 50u) << "occlusion darkens some pixels";
    EXPECT_EQ(darker(*shadows, *plain), 0u) << "shadows never brighten";
    EXPECT_NE(both->rgba, aa->rgba);
    EXPECT_EQ(aa->rgba.size(), both->rgba.size());
}

TEST_F(Render, SupersamplingAveragesTheSamplesOfALargerImage) {
    // aa 2 traces the rays of the image twice as large, with its hit epsilon, and averages each
    // 2 x 2 block; the two sets of rays round differently in the last bit, and the average of
    // 8-bit samples rounds once more.
    auto parsed = parseScene(R"({"version": 1, "root": {"type": "union", "smooth": 0.3,
        "children": [{"type": "sphere", "radius": 1, "color": [0.9, 0.3, 0.2]},
                     {"type": "box", "size": [1.2, 1.2, 1.2], "translate": [1.2, 0, 0],
                      "rotate": [20, 30, 0], "color": [0.2, 0.5, 0.9]}]}})",
                             "aa.json");
    ASSERT_TRUE(parsed) << parsed.error().str();
    Scene scene = *parsed;
    auto renderer = Renderer::create(context(), scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    RenderOptions options;
    options.width = 128, options.height = 96;
    auto large = (*renderer)->render(options);
    options.width = 64, options.height = 48, options.aa = 2;
    auto aa = (*renderer)->render(options);
    ASSERT_TRUE(large && aa);
    size_t close = 0;
    double total = 0.0;
    for (uint32_t y = 0; y < 48; ++y)
        for (uint32_t x = 0; x < 64; ++x) {
            bool near = true;
            for (int c = 0; c < 3; ++c) {
                int sum = 0;
                for (uint32_t k = 0; k < 4; ++k)
                    sum += large->rgba[4 * ((2 * y + k / 2) * 128 + 2 * x + k % 2) + c];
                const double diff = std::abs(sum / 4.0 - aa->rgba[4 * (y * 64 + x) + c]);
                total += diff;
                near = near && diff <= 1.0;
            }
            close += near;
        }
    EXPECT_GE(close, size_t(0.995 * 64 * 48));
    EXPECT_LT(total / (64 * 48 * 3), 0.3) << "mean difference per channel";
}

TEST_F(Render, BoxOverlayDrawsEdges) {
    Scene scene = loadOrDie(scenePath("csg_part.json"));
    auto renderer = Renderer::create(context(), scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    RenderOptions options;
    options.width = 96, options.height = 96;
    auto none = (*renderer)->render(options);
    options.boxes = BoxOverlay::All;
    auto all = (*renderer)->render(options);
    options.boxes = BoxOverlay::Selected;
    options.selectedNode = 1;
    auto selected = (*renderer)->render(options);
    ASSERT_TRUE(none && all && selected);
    auto changed = [&](const Image& a) {
        size_t n = 0;
        for (size_t i = 0; i < a.rgba.size(); ++i)
            n += a.rgba[i] != none->rgba[i];
        return n;
    };
    EXPECT_GT(changed(*all), 50u);
    EXPECT_GT(changed(*selected), 10u);
    EXPECT_LT(changed(*selected), changed(*all));
    options.selectedNode = int(scene.nodes.size());
    auto bad = (*renderer)->render(options);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().kind, ErrorKind::Usage);
}

// The grid lies on its plane under the solid, only where that plane is nearer than the surface,
// within its lines' extent and near a line; it darkens what it covers.
TEST_F(Render, GroundGridLiesOnItsPlaneInFrontOfSurfaces) {
    auto scene = parseScene(R"({"version": 1, "background": [0.9, 0.9, 0.9],
        "root": {"type": "union", "children": [
            {"type": "sphere", "radius": 1},
            {"type": "box", "size": [0.5, 0.5, 0.5], "translate": [1.0, -0.5, 0]}]}})");
    ASSERT_TRUE(scene) << scene.error().str();
    auto renderer = Renderer::create(context(), *scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    RenderOptions options;
    options.width = 160, options.height = 120;
    options.camera = Camera{glm::vec3(1.0f, 2.0f, 5.0f), glm::vec3(0.5f, -0.5f, 0.0f)};
    auto plain = (*renderer)->render(options);
    ASSERT_TRUE(plain);
    const std::vector<PixelInfo> info = (*renderer)->lastPixelInfo();
    options.grid = true;
    auto grid = (*renderer)->render(options);
    ASSERT_TRUE(grid);

    const GroundGrid g = groundGrid(Evaluator(*scene));
    EXPECT_NEAR(g.height, -1.0f, 1e-3f); // the sphere's bottom and the box's
    EXPECT_FLOAT_EQ(g.spacing, 1.0f);    // the solid is about 2.5 wide
    EXPECT_FLOAT_EQ(g.centreX, 0.0f);    // its middle, rounded to the spacing
    const detail::RayCamera rc = detail::makeRayCamera(*options.camera, 160, 120);
    size_t changed = 0, onLines = 0;
    for (uint32_t y = 0; y < 120; ++y)
        for (uint32_t x = 0; x < 160; ++x) {
            const size_t i = y * 160 + x;
            glm::vec3 dir = detail::rayDirection(rc, x + 0.5f, y + 0.5f, 160, 120);
            float tPlane = (g.height - rc.eye.y) / dir.y;
            glm::vec3 p = rc.eye + dir * tPlane;
            glm::vec2 q = (glm::vec2(p.x, p.z) - glm::vec2(g.centreX, g.centreZ)) / g.spacing;
            glm::vec2 toLine = glm::abs(q - glm::round(q)) * g.spacing;
            float pixelWidth = tPlane * rc.footprint;
            bool inFront = tPlane > 0 && (info[i].depth < 0 || tPlane <= info[i].depth * 1.001f);
            bool inside = std::max(std::abs(q.x), std::abs(q.y)) <= g.halfLines + 0.5f;
            bool nearLine = std::min(toLine.x, toLine.y) < 2.0f * pixelWidth / std::abs(dir.y);
            bool differs = pixel(*grid, i) != pixel(*plain, i);
            changed += differs;
            if (differs) {
                ASSERT_TRUE(inFront && inside && nearLine) << "pixel " << x << ", " << y;
                glm::vec3 a = pixel(*plain, i), b = pixel(*grid, i);
                ASSERT_LE(b.r + b.g + b.b, a.r + a.g + a.b) << "pixel " << x << ", " << y;
            }
            onLines += inFront && inside && std::min(toLine.x, toLine.y) < 0.25f * pixelWidth &&
                       std::abs(dir.y) > 0.3f;
        }
    EXPECT_GT(onLines, 100u);
    EXPECT_GT(changed, onLines / 2);
}

// Grows the first sphere found; returns false if the scene has none.
bool growFirstSphere(Scene& scene) {
    for (Node& node : scene.nodes)
        if (node.kind == NodeKind::Sphere) {
            node.params[0] *= 1.3f;
            return true;
        }
    return false;
}

class UpdateValues : public GpuTest, public ::testing::WithParamInterface<bool> {};

TEST_P(UpdateValues, ChangesTheImageToTheNewScene) {
    const bool inlineValues = GetParam();
    Scene scene = loadOrDie(scenePath("csg_part.json"));
    RendererOptions rendererOptions;
    rendererOptions.inlineValues = inlineValues;
    auto renderer = Renderer::create(context(), scene, rendererOptions);
    ASSERT_TRUE(renderer) << renderer.error().str();
    Evaluator before(scene);
    RenderOptions options;
    options.width = options.height = kSize;
    options.camera = cameraFor(scene, before); // fixed, so only the geometry changes
    auto first = (*renderer)->render(options);
    ASSERT_TRUE(first);

    ASSERT_TRUE(growFirstSphere(scene));
    scene.nodes[0].color = glm::vec3(0.9f, 0.1f, 0.1f);
    const detail::ShaderCacheStats statsBefore = detail::shaderCacheStats();
    auto updated = (*renderer)->updateValues(scene);
    ASSERT_TRUE(updated) << updated.error().str();
    auto second = (*renderer)->render(options);
    ASSERT_TRUE(second);
    const detail::ShaderCacheStats statsAfter = detail::shaderCacheStats();
    EXPECT_NE(first->rgba, second->rgba);
    // Values in a buffer: an upload only, no compile and not even a cache lookup. Inlined: one
    // compile for each of the scene's two kernels (march.comp, shade.comp).
    const uint64_t lookups = [](const detail::ShaderCacheStats& s) {
        return s.compiles + s.memoryHits + s.diskHits;
    }(statsAfter) - [](const detail::ShaderCacheStats& s) {
        return s.compiles + s.memoryHits + s.diskHits;
    }(statsBefore);
    EXPECT_EQ(lookups, inlineValues ? 2u : 0u);

    // The new image is the new scene's: its hit mask agrees with CPU tracing of the new values.
    Evaluator after(scene);
    const auto& info = (*renderer)->lastPixelInfo();
    detail::RayCamera rc = detail::makeRayCamera(*options.camera, kSize, kSize);
    detail::ClipVolume clipBefore = detail::makeClipVolume(before, rc.eye);
    detail::ClipVolume clipAfter = detail::makeClipVolume(after, rc.eye);
    size_t agree = 0, changed = 0;
    for (uint32_t y = 0; y < kSize; ++y)
        for (uint32_t x = 0; x < kSize; ++x) {
            glm::vec3 dir = detail::rayDirection(rc, x + 0.5f, y + 0.5f, kSize, kSize);
            bool hitAfter = traceCpu(after, rc, clipAfter, dir).t >= 0;
            bool hitBefore = traceCpu(before, rc, clipBefore, dir).t >= 0;
            agree += hitAfter == (info[size_t(y) * kSize + x].depth >= 0);
            changed += hitAfter != hitBefore;
        }
    EXPECT_GT(changed, 20u) << "the edit should change the silhouette";
    EXPECT_GE(agree / double(kSize * kSize), 0.995);
}

INSTANTIATE_TEST_SUITE_P(Render, UpdateValues, ::testing::Values(true, false),
                         [](const ::testing::TestParamInfo<bool>& param) {
                             return param.param ? std::string("InlineValues")
                                                : std::string("BufferValues");
                         });

// On tapes a value edit is an upload (a larger sphere, another blend profile), but where it
// changes what the tape machine holds code for: a sphere scaled differently per axis is no longer
// a ball (detail::isBall), so the kernel is compiled again, and the image is the new scene's. A
// renderer that does not inline values reads spheres through their transforms and compiles
// nothing, with the same image.
TEST_F(Render, UpdateValuesOnTapesRecompilesOnlyWhereTheCodeChanges) {
    Scene scene = loadOrDie(scenePath("csg_part.json"));
    RendererOptions made;
    made.evaluation = Evaluation::Tapes;
    auto renderer = Renderer::create(context(), scene, made);
    ASSERT_TRUE(renderer) << renderer.error().str();
    RendererOptions buffered = made;
    buffered.inlineValues = false;
    auto live = Renderer::create(context(), scene, buffered);
    ASSERT_TRUE(live) << live.error().str();
    EXPECT_TRUE((*renderer)->followsValues());
    EXPECT_FALSE((*live)->followsValues());
    RenderOptions options;
    options.width = options.height = kSize;
    options.camera = cameraFor(scene, Evaluator(scene));
    auto lookups = [] {
        const detail::ShaderCacheStats s = detail::shaderCacheStats();
        return s.compiles + s.memoryHits + s.diskHits;
    };
    for (int edit = 0; edit < 3; ++edit) {
        const bool perAxis = edit == 2;
        SCOPED_TRACE(edit == 0   ? "a larger sphere"
                     : edit == 1 ? "another blend"
                                 : "a scale per axis");
        if (edit == 0) {
            ASSERT_TRUE(growFirstSphere(scene));
        } else if (edit == 1) {
            bool changed = false;
            for (Node& node : scene.nodes)
                if (kindInfo(node.kind).role == Role::Boolean && !changed) {
                    node.params[0] = 0.05f; // smooth
                    node.params[1] = 2.0f;  // chamfer
                    changed = true;
                }
            ASSERT_TRUE(changed);
        } else {
            for (Node& node : scene.nodes)
                if (node.kind == NodeKind::Sphere)
                    node.transform.scale = glm::vec3(1.3f, 1.0f, 0.8f);
        }
        EXPECT_EQ((*renderer)->uploads(scene), !perAxis);
        EXPECT_TRUE((*live)->uploads(scene));
        const uint64_t before = lookups();
        auto updated = (*renderer)->updateValues(scene);
        ASSERT_TRUE(updated) << updated.error().str();
        EXPECT_EQ(lookups() - before, perAxis ? 2u : 0u);
        EXPECT_EQ((*renderer)->followsValues(), !perAxis);
        auto image = (*renderer)->render(options);
        ASSERT_TRUE(image);
        const uint64_t beforeLive = lookups();
        updated = (*live)->updateValues(scene);
        ASSERT_TRUE(updated) << updated.error().str();
        EXPECT_EQ(lookups() - beforeLive, 0u);
        auto liveImage = (*live)->render(options);
        ASSERT_TRUE(liveImage);
        auto fresh = Renderer::create(context(), scene, made);
        ASSERT_TRUE(fresh) << fresh.error().str();
        auto expected = (*fresh)->render(options);
        ASSERT_TRUE(expected);
        EXPECT_EQ(image->rgba, expected->rgba);
        if (perAxis) {
            EXPECT_EQ(liveImage->rgba, expected->rgba); // the same kernel
            continue;
        }
        // Balls round as their transforms do not: a pixel on a silhouette may turn.
        size_t differing = 0;
        for (size_t i = 0; i < expected->rgba.size(); i += 4)
            for (size_t c = 0; c < 3; ++c)
                if (std::abs(int(liveImage->rgba[i + c]) - int(expected->rgba[i + c])) > 2) {
                    ++differing;
                    break;
                }
        EXPECT_LE(differing, expected->rgba.size() / 4 / 200);
    }
}

// lavapipe may specialise a kernel on values that it reads from a uniform block or from push
// constants to decide branches, and then compiles it again whenever they change, which would
// be at every band of every frame. Whether it does depends on the kernel's code, the scene's
// included. Its disk cache shows such compiles: with the cache in a folder of the test's own,
// renders with other values (camera, size and so bands, mode, samples, overlays, lights) after
// renders that used the same pipelines must add nothing to it.
TEST_F(Render, OtherValuesCompileNothing) {
    if (!onLavapipe(context()))
        GTEST_SKIP() << "a property of lavapipe's compiler; " << context().deviceName();
    const DriverCacheFolder cache(testFolder("sdfcsg-mesa-cache"));
    // Each list uses the same pipelines: march, shade, resolve and overlay.
    auto renderAll = [&](const Scene& scene, const std::vector<RenderOptions>& renders) {
        onNewContext(true, [&](Context& ctx) {
            auto renderer = Renderer::create(ctx, scene);
            ASSERT_TRUE(renderer) << renderer.error().str();
            for (const RenderOptions& options : renders)
                ASSERT_TRUE((*renderer)->render(options));
        });
    };
    RenderOptions first;
    first.width = 64, first.height = 48, first.aa = 2, first.grid = true;
    RenderOptions depth = first;
    depth.mode = RenderMode::Depth, depth.aa = 1;

    RenderOptions other = first;
    other.width = 320, other.height = 240; // two bands
    other.aa = 3, other.grid = false, other.boxes = BoxOverlay::All;
    other.camera = Camera{glm::vec3(3.0f, 2.0f, 4.0f), glm::vec3(0.0f)};
    other.ambientOcclusion = false;
    RenderOptions normals = other;
    normals.mode = RenderMode::Normals, normals.shadows = false;
    RenderOptions otherDepth = other;
    otherDepth.mode = RenderMode::Depth, otherDepth.aa = 1, otherDepth.width = 200;

    for (const fs::path& path : bundledScenes()) {
        SCOPED_TRACE(path.filename().string());
        const Scene scene = loadOrDie(path);
        cache.clear();
        renderAll(scene, {first, depth});
        const size_t before = cache.kernels();
        ASSERT_GT(before, 0u) << "the driver cached nothing in " << cache.dir();
        renderAll(scene, {normals, other, otherDepth});
        EXPECT_EQ(cache.kernels(), before) << "kernels were compiled again for other values";
    }
}

// On lavapipe a second device compiles the march kernel while the context's own compiles the
// shade kernel, and hands the machine code over through Mesa's disk cache (expectHelperHandsOver()
// in driver_cache.h); in a context's first build, also the clip and ends passes. The image is the
// same either way.
TEST_F(Render, CompileHelperHandsMachineCodeOver) {
    if (!onLavapipe(context())) GTEST_SKIP() << "lavapipe only; " << context().deviceName();
    const DriverCacheFolder cache(testFolder("sdfcsg-helper-cache"));
    const Scene scene = loadOrDie(scenePath("robot.json"));
    RenderOptions options;
    options.width = 64, options.height = 48;
    std::optional<Image> images[2];
    // The first build of a context: the march kernel, the clip and ends passes.
    expectHelperHandsOver(cache, 3, [&](Context& ctx, int helper) {
        auto renderer = Renderer::create(ctx, scene);
        ASSERT_TRUE(renderer) << renderer.error().str();
        auto image = (*renderer)->render(options);
        ASSERT_TRUE(image) << image.error().str();
        images[helper] = *image;
    });
    ASSERT_TRUE(images[0] && images[1]);
    EXPECT_EQ(images[1]->rgba, images[0]->rgba);

    // Without Mesa's disk cache there is nothing to hand the machine code over with.
    ScopedEnv cacheOff("MESA_SHADER_CACHE_DISABLE", "true");
    ContextOptions contextOptions;
    contextOptions.validation = 1;
    auto ctx = Context::create(contextOptions);
    ASSERT_TRUE(ctx) << ctx.error().str();
    EXPECT_FALSE(detail::contextImpl(**ctx).helperWanted);
}

// Mesa turns its disk cache off where it cannot make its folder, which the environment does not
// tell. The context then sees this device compile what the helper compiled, and stops using it.
// It sees that by time (this device's compile against the helper's), so on a loaded machine it
// may take a second build: the first build's helper compiles the march kernel, clip and ends
// passes, a later one the march kernel alone, and none compiles after the miss.
TEST_F(Render, CompileHelperStopsWhereTheCacheHandsNothingOver) {
    if (!onLavapipe(context())) GTEST_SKIP() << "lavapipe only; " << context().deviceName();
    const DriverCacheFolder cache(testFolder("sdfcsg-no-folder") / "mesa");
    ContextOptions contextOptions;
    contextOptions.validation = 1;
    contextOptions.shaderCacheDir = fs::path(); // glslang runs, so the helper is asked to compile
    auto ctx = Context::create(contextOptions);
    ASSERT_TRUE(ctx) << ctx.error().str();
    Context::Impl& impl = detail::contextImpl(**ctx);
    ASSERT_TRUE(impl.helperWanted);
    uint32_t missedAt = 0; // the build after which the context knew
    const char* const scenes[] = {"robot.json", "snowman.json", "gear.json"};
    for (uint32_t build = 1; build <= 3; ++build) {
        SCOPED_TRACE(scenes[build - 1]);
        clearShaderMemoryCache();
        auto renderer = Renderer::create(**ctx, loadOrDie(scenePath(scenes[build - 1])));
        ASSERT_TRUE(renderer) << renderer.error().str();
        std::lock_guard lock(impl.helperMutex);
        if (!missedAt && impl.helperFailed) missedAt = build;
        if (missedAt) {
            EXPECT_EQ(impl.helperCompiles.load(), 3u + (missedAt - 1))
                << "the helper compiled after it missed";
            EXPECT_EQ(impl.helper, nullptr);
        }
    }
    EXPECT_TRUE(missedAt == 1 || missedAt == 2) << "missed after build " << missedAt;
    EXPECT_EQ((*ctx)->validationMessageCount(), 0u);
    EXPECT_FALSE(fs::exists(cache.dir()));
}

// A renderer that reads its values from the node buffer takes a blend profile as a value, as it
// takes the radius: no compile, and the image a new renderer makes of the edited scene.
TEST_F(Render, BufferValuesTakeABlendProfileEdit) {
    Scene scene = makeScene(
        unite({sphere(0.6f).at(-0.3f, 0, 0), box(0.5f, 0.5f, 0.5f).at(0.4f, 0, 0)}, 0.3f));
    ASSERT_EQ(scene.nodes[0].kind, NodeKind::Union);
    RendererOptions buffered;
    buffered.inlineValues = false;
    auto renderer = Renderer::create(context(), scene, buffered);
    ASSERT_TRUE(renderer) << renderer.error().str();
    RenderOptions options;
    options.width = options.height = kSize;
    options.camera = cameraFor(scene, Evaluator(scene));
    auto first = (*renderer)->render(options);
    ASSERT_TRUE(first);
    scene.nodes[0].params[1] = 2.0f; // chamfer
    const detail::ShaderCacheStats before = detail::shaderCacheStats();
    auto updated = (*renderer)->updateValues(scene);
    ASSERT_TRUE(updated) << updated.error().str();
    const detail::ShaderCacheStats after = detail::shaderCacheStats();
    EXPECT_EQ(after.compiles + after.memoryHits + after.diskHits,
              before.compiles + before.memoryHits + before.diskHits);
    auto second = (*renderer)->render(options);
    ASSERT_TRUE(second);
    EXPECT_NE(second->rgba, first->rgba);
    auto fresh = Renderer::create(context(), scene, buffered);
    ASSERT_TRUE(fresh) << fresh.error().str();
    auto expected = (*fresh)->render(options);
    ASSERT_TRUE(expected);
    EXPECT_EQ(second->rgba, expected->rgba);
}

TEST_F(Render, UpdateValuesRefusesStructuralChanges) {
    Scene scene = loadOrDie(scenePath("csg_part.json"));
    auto renderer = Renderer::create(context(), scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    Scene other = scene;
    other.nodes.back().kind =
        other.nodes.back().kind == NodeKind::Sphere ? NodeKind::Box : NodeKind::Sphere;
    auto result = (*renderer)->updateValues(other);
    ASSERT_FALSE(result);
    EXPECT_EQ(result.error().kind, ErrorKind::Usage);
    Scene fewer = scene;
    fewer.nodes.pop_back();
    ASSERT_FALSE((*renderer)->updateValues(fewer));
    // The renderer still works with its old values.
    RenderOptions options;
    options.width = options.height = 16;
    EXPECT_TRUE((*renderer)->render(options));
}

TEST_F(Render, RejectsBadOptions) {
    Scene scene = loadOrDie(scenePath("csg_part.json"));
    auto renderer = Renderer::create(context(), scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    auto refused = [&](const RenderOptions& options) {
        auto image = (*renderer)->render(options);
        return image ? std::string("rendered") : image.error().str();
    };
    RenderOptions options;
    options.width = 0;
    EXPECT_EQ(refused(options), "<render>: the image must be at least 1 x 1 pixels");
    options.width = 8;
    options.aa = 0;
    EXPECT_EQ(refused(options), "<render>: aa must be in 1..8");
    options.aa = 9;
    EXPECT_EQ(refused(options), "<render>: aa must be in 1..8");
    options.aa = 1;
    options.width = options.height = 1u << 16; // 4 G pixels
    auto huge = (*renderer)->render(options);
    ASSERT_FALSE(huge);
    EXPECT_EQ(huge.error().kind, ErrorKind::Limit);
    EXPECT_EQ(huge.error().str(), "<render>: an image of 65536 x 65536 pixels is too large for " +
                                      context().deviceName());
}

// A render is computed in bands of rows; the caller follows them and may stop between two.
TEST_F(Render, ReportsProgressPerBandAndStopsWhenAsked) {
    Scene scene = loadOrDie(scenePath("csg_part.json"));
    auto renderer = Renderer::create(context(), scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    RenderOptions options;
    options.width = 256;
    options.height = 600; // three bands of 65536 pixels or fewer
    auto whole = (*renderer)->render(options);
    ASSERT_TRUE(whole) << whole.error().str();

    std::vector<float> reported;
    options.progress = [&](float done) {
        reported.push_back(done);
        return true;
    };
    auto banded = (*renderer)->render(options);
    ASSERT_TRUE(banded) << banded.error().str();
    EXPECT_EQ(banded->rgba, whole->rgba);
    ASSERT_EQ(reported.size(), 3u);
    EXPECT_TRUE(std::is_sorted(reported.begin(), reported.end()));
    EXPECT_LT(reported.front(), 1.0f);
    EXPECT_EQ(reported.back(), 1.0f);

    reported.clear();
    options.progress = [&](float done) {
        reported.push_back(done);
        return false;
    };
    auto stopped = (*renderer)->render(options);
    ASSERT_FALSE(stopped);
    EXPECT_EQ(stopped.error().kind, ErrorKind::Cancelled);
    EXPECT_EQ(stopped.error().str(), "<render>: cancelled");
    EXPECT_EQ(reported.size(), 1u);
}

TEST(RenderMode, ParsesTheFourNames) {
    EXPECT_EQ(parseRenderMode("shaded"), RenderMode::Shaded);
    EXPECT_EQ(parseRenderMode("normals"), RenderMode::Normals);
    EXPECT_EQ(parseRenderMode("depth"), RenderMode::Depth);
    EXPECT_EQ(parseRenderMode("steps"), RenderMode::Steps);
    EXPECT_FALSE(parseRenderMode("Shaded"));
    EXPECT_FALSE(parseRenderMode(""));
}

class Png : public GpuTest {};

Image gradient(uint32_t w, uint32_t h) {
    Image image{w, h, std::vector<uint8_t>(size_t(w) * h * 4)};
    for (size_t i = 0; i < image.rgba.size(); ++i)
        image.rgba[i] = uint8_t(i * 7 + i / 13);
    return image;
}

fs::path freshDir(const char* name) {
    fs::path dir = fs::path(SDFCSG_TEST_OUTPUT_DIR) / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

TEST_F(Png, WritesARenderAtomicallyAndReplacesWholeFiles) {
    fs::path dir = freshDir("png_atomic");
    fs::path out = dir / "image.png";
    Image big = gradient(300, 200);
    ASSERT_TRUE(writePng(big, out));
    Image small = gradient(7, 5);
    auto written = writePng(small, out);
    ASSERT_TRUE(written) << written.error().str();
    Image back = readPng(out).value_or(Image{});
    EXPECT_EQ(back.width, 7u);
    EXPECT_EQ(back.height, 5u);
    EXPECT_EQ(back.rgba, small.rgba);
    size_t files = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir))
        ++files;
    EXPECT_EQ(files, 1u) << "no temporary file may be left behind";

    // A real render round-trips exactly.
    Scene scene = loadOrDie(scenePath("robot.json"));
    auto renderer = Renderer::create(context(), scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    RenderOptions options;
    options.width = 64, options.height = 40;
    auto image = (*renderer)->render(options);
    ASSERT_TRUE(image);
    ASSERT_TRUE(writePng(*image, out));
    back = readPng(out).value_or(Image{});
    EXPECT_EQ(back.width, 64u);
    EXPECT_EQ(back.rgba, image->rgba);
}

TEST(PngErrors, NameThePath) {
    fs::path dir = freshDir("png_errors");
    fs::path out = dir / "missing-dir" / "x.png";
    auto result = writePng(gradient(4, 4), out);
    ASSERT_FALSE(result);
    EXPECT_EQ(result.error().kind, ErrorKind::Io);
    EXPECT_NE(result.error().str().find(out.string()), std::string::npos) << result.error().str();
    EXPECT_FALSE(writePng(Image{}, dir / "empty.png"));
    EXPECT_FALSE(fs::exists(dir / "empty.png"));
}

class ContextTest : public GpuTest {};

TEST_F(ContextTest, DeviceOverrideByNameOrIndex) {
    ContextOptions options;
    options.validation = 0;
    options.device = "no such device 42";
    auto missing = Context::create(options);
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().kind, ErrorKind::Vulkan);
    EXPECT_NE(missing.error().str().find("no such device 42"), std::string::npos);

    std::string name = context().deviceName();
    ASSERT_FALSE(name.empty());
    std::string upper = name.substr(0, std::min<size_t>(name.size(), 6));
    for (char& c : upper)
        c = char(std::toupper(static_cast<unsigned char>(c)));
    options.device = upper; // a case-insensitive part of the name
    auto byName = Context::create(options);
    ASSERT_TRUE(byName) << byName.error().str();
    EXPECT_EQ((*byName)->deviceName(), name);
    EXPECT_FALSE((*byName)->validationEnabled());

    options.device = "0";
    auto byIndex = Context::create(options);
    ASSERT_TRUE(byIndex) << byIndex.error().str();
    options.device = "999";
    EXPECT_FALSE(Context::create(options));
}

TEST_F(ContextTest, ValidationIsOnInTests) {
    EXPECT_TRUE(context().validationEnabled());
}

// Depth spans the solid: a revolved or extruded profile's depth range is its solid's, not its
// 2D outline's (which left chess_pawn two grey levels).
TEST_F(Render, DepthOfProfileSolidsHasManyLevels) {
    for (const char* name : {"chess_pawn.json", "name_plate.json"}) {
        Scene scene = loadOrDie(scenePath(name));
        auto renderer = Renderer::create(context(), scene);
        ASSERT_TRUE(renderer) << renderer.error().str();
        RenderOptions options;
        options.width = 160, options.height = 120;
        options.mode = RenderMode::Depth;
        auto image = (*renderer)->render(options);
        ASSERT_TRUE(image) << image.error().str();
        std::set<uint8_t> levels;
        for (size_t i = 0; i < image->rgba.size(); i += 4)
            levels.insert(image->rgba[i]);
        EXPECT_GT(levels.size(), 20u) << name;
    }
}

} // namespace
} // namespace sdfcsg::test
