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

TEST_F(ViewerGpu, ValueEditsUploadAndStructuralEditsRecompile) {
    auto scene = std::make_shared<const Scene>(*parseScene(kScene, "scene.json"));
    RenderWorker worker(context());
    RenderJob job;
    job.scene = scene;
    job.sceneVersion = 1;
    job.options.width = 64;
    job.options.height = 48;
    job.options.camera = scene->camera;
    job.id = 1;
    worker.submit(job);
    RenderOutput first = wait(worker);
    ASSERT_FALSE(first.error) << first.error->str();
    EXPECT_EQ(first.id, 1u);
    EXPECT_GT(first.compileSeconds, 0.0);
    EXPECT_EQ(first.image.width, 64u);
    EXPECT_EQ(first.pixels.size(), 64u * 48u);
    EXPECT_TRUE(worker.idle());

    float r = 0.9f;
    job.scene = std::make_shared<const Scene>(*setValue(*scene, 1, "radius", std::span(&r, 1)));
    job.sceneVersion = 2;
    job.id = 2;
    worker.submit(job);
    RenderOutput second = wait(worker);
    EXPECT_EQ(second.compileSeconds, 0.0); // an upload
    EXPECT_NE(second.image.rgba, first.image.rgba);

    job.scene = std::make_shared<const Scene>(*removeNode(*job.scene, 2));
    job.sceneVersion = 3;
    job.id = 3;
    worker.submit(job);
    RenderOutput third = wait(worker);
    EXPECT_GT(third.compileSeconds, 0.0);
    EXPECT_EQ(third.scene->nodes.size(), 2u);
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
