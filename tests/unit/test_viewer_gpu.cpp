// The viewer's background renderer and picking on real renders (lavapipe is fine).
#include "gpu_test.h"

#include "edit.h"
#include "picking.h"
#include "workers.h"

#include <chrono>
#include <thread>

using namespace sdfcsg;
using namespace sdfcsg::viewer;

namespace {

constexpr const char* kScene = R"({
  "version": 1,
  "root": {"type": "union", "children": [
    {"type": "sphere", "name": "left", "radius": 0.6, "translate": [-1, 0, 0]},
    {"type": "box", "name": "right", "size": [1, 1, 1], "translate": [1, 0, 0]}
  ]},
  "camera": {"eye": [0, 0, 6], "target": [0, 0, 0], "fov": 40}
})";

RenderOutput wait(RenderWorker& worker) {
    for (;;) {
        if (auto out = worker.take()) return std::move(*out);
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
}

class ViewerGpu : public test::GpuTest {};

} // namespace

// Fraction of pixels whose colour differs by more than `tolerance` in a channel.
double differingFraction(const Image& a, const Image& b, int tolerance) {
    EXPECT_EQ(a.rgba.size(), b.rgba.size());
    size_t differing = 0;
    for (size_t i = 0; i + 3 < std::min(a.rgba.size(), b.rgba.size()); i += 4)
        for (size_t c = 0; c < 3; ++c)
            if (std::abs(int(a.rgba[i + c]) - int(b.rgba[i + c])) > tolerance) {
                ++differing;
                break;
            }
    return double(differing) / double(std::max<size_t>(a.rgba.size() / 4, 1));
}

// Frames are baked (values inlined); a dragged value (previews) starts the live renderer's
// build, after which previews of new values are uploads that match the baked image, while the
// still frame bakes again; a structural edit bakes and drops the live renderer.
TEST_F(ViewerGpu, ValueEditsUploadAndStructuralEditsRecompile) {
    auto scene = std::make_shared<const Scene>(*parseScene(kScene, "scene.json"));
    RenderWorker worker(context());
    RenderJob job;
    job.options.width = 64;
    job.options.height = 48;
    job.options.camera = scene->camera;
    auto render = [&](std::shared_ptr<const Scene> s, uint64_t version, bool preview) {
        job.scene = std::move(s);
        job.sceneVersion = version;
        job.preview = preview;
        ++job.id;
        worker.submit(job);
        RenderOutput out = wait(worker);
        EXPECT_FALSE(out.error) << out.error->str();
        EXPECT_EQ(out.id, job.id);
        return out;
    };
    auto withRadius = [&](float r) {
        return std::make_shared<const Scene>(*setValue(*scene, 1, "radius", std::span(&r, 1)));
    };

    RenderOutput first = render(scene, 1, false);
    EXPECT_GT(first.compileSeconds, 0.0);
    EXPECT_FALSE(first.live);
    EXPECT_EQ(first.image.width, 64u);
    EXPECT_EQ(first.pixels.size(), 64u * 48u);
    EXPECT_TRUE(worker.idle());

    RenderOutput dragged = render(withRadius(0.7f), 2, true); // baked: no live renderer yet
    EXPECT_GT(dragged.compileSeconds, 0.0);
    EXPECT_FALSE(dragged.live);
    EXPECT_NE(dragged.image.rgba, first.image.rgba);
    for (int i = 0; i < 24000 && !worker.liveBuildDone(); ++i) // at most two minutes
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    ASSERT_TRUE(worker.liveBuildDone());

    auto bigger = withRadius(0.9f);
    RenderOutput live = render(bigger, 3, true);
    EXPECT_EQ(live.compileSeconds, 0.0); // an upload
    EXPECT_TRUE(live.live);
    EXPECT_NE(live.image.rgba, dragged.image.rgba);
    RenderOutput still = render(bigger, 3, false); // the same values, baked
    EXPECT_GT(still.compileSeconds, 0.0);
    EXPECT_FALSE(still.live);
    // Kernels with values inlined or read from a buffer may round differently by a step or two.
    EXPECT_LE(differingFraction(live.image, still.image, 6), 0.002);

    RenderOutput removed = render(std::make_shared<const Scene>(*removeNode(*bigger, 2)), 4, false);
    EXPECT_GT(removed.compileSeconds, 0.0);
    EXPECT_EQ(removed.scene->nodes.size(), 2u);
    float r = 0.5f;
    RenderOutput afterRemoval =
        render(std::make_shared<const Scene>(*setValue(*removed.scene, 1, "radius", std::span(&r, 1))),
               5, true);
    EXPECT_FALSE(afterRemoval.live); // the live renderer was for the old structure
    EXPECT_GT(afterRemoval.compileSeconds, 0.0);
}

TEST_F(ViewerGpu, ClickingAPixelSelectsThePrimitiveThere) {
    Scene scene = *parseScene(kScene, "scene.json");
    auto renderer = Renderer::create(context(), scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    RenderOptions options;
    options.width = 160;
    options.height = 120;
    ASSERT_TRUE((*renderer)->render(options));
    const auto& pixels = (*renderer)->lastPixelInfo();
    Evaluator evaluator(scene);
    // The sphere is left of the centre, the box right of it; the corner is sky.
    for (auto [x, name] : {std::pair{45.0f, "left"}, std::pair{115.0f, "right"}}) {
        auto p = pickPoint(*scene.camera, 160, 120, pixels, x, 60.0f);
        ASSERT_TRUE(p) << name;
        // On the surface within the kernel's hit epsilon (half a pixel's footprint, ~0.02 here).
        EXPECT_NEAR(evaluator.distance(*p), 0.0f, 0.03f);
        EXPECT_EQ(nearestPrimitive(evaluator, *p), int(*findNode(scene, name)));
    }
    EXPECT_FALSE(pickPoint(*scene.camera, 160, 120, pixels, 2.0f, 2.0f));
}
