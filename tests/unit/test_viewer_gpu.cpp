// The viewer's background renderer and picking on real renders (lavapipe is fine).
#include "gpu_test.h"
#include "mesh_checks.h"

#include "edit.h"
#include "picking.h"
#include "workers.h"

#include <algorithm>
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

// Frames are baked (values inlined); a structure on screen starts the live renderer's build, on
// a Context of its own. Once built, value edits are uploads drawn at once (previews and still
// frames), and a still frame's values are baked again in the background as a refinement that
// matches the live image; a structural edit bakes and drops the live renderer.
TEST_F(ViewerGpu, ValueEditsUploadAndStructuralEditsRecompile) {
    auto scene = std::make_shared<const Scene>(*parseScene(kScene, "scene.json"));
    auto liveContext = Context::create();
    ASSERT_TRUE(liveContext) << liveContext.error().str();
    RenderWorker worker(context(), liveContext->get());
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
    auto withRadius = [&](std::shared_ptr<const Scene> from, float r) {
        return std::make_shared<const Scene>(*setValue(*from, 1, "radius", std::span(&r, 1)));
    };
    auto waitFor = [](auto done) {
        for (int i = 0; i < 24000 && !done(); ++i) // at most two minutes
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        return done();
    };

    RenderOutput first = render(scene, 1, false);
    EXPECT_GT(first.compileSeconds, 0.0);
    EXPECT_FALSE(first.live);
    EXPECT_EQ(first.image.width, 64u);
    EXPECT_EQ(first.pixels.size(), 64u * 48u);
    EXPECT_TRUE(worker.idle());
    ASSERT_TRUE(waitFor([&] { return worker.liveBuildDone(); }));

    auto bigger = withRadius(scene, 0.9f);
    RenderOutput dragged = render(withRadius(scene, 0.7f), 2, true);
    EXPECT_EQ(dragged.compileSeconds, 0.0); // an upload
    EXPECT_TRUE(dragged.live);
    EXPECT_FALSE(worker.refinementPending(2)); // previews are not baked
    RenderOutput live = render(bigger, 3, false);
    EXPECT_EQ(live.compileSeconds, 0.0);
    EXPECT_TRUE(live.live);
    EXPECT_NE(live.image.rgba, dragged.image.rgba);
    EXPECT_TRUE(worker.refinementPending(3));
    ASSERT_TRUE(waitFor([&] { return worker.refinementReady(3); }));
    RenderOutput still = render(bigger, 3, false); // the same values, baked meanwhile
    EXPECT_EQ(still.compileSeconds, 0.0);
    EXPECT_FALSE(still.live);
    EXPECT_FALSE(worker.refinementPending(3));
    // Kernels with values inlined or read from a buffer may round differently by a step or two.
    EXPECT_LE(differingFraction(live.image, still.image, 6), 0.002);

    // A blend profile is a value too.
    const float chamfer = 2.0f;
    auto profiled =
        std::make_shared<const Scene>(*setValue(*bigger, 0, "blend", std::span(&chamfer, 1)));
    RenderOutput reprofiled = render(profiled, 4, true);
    EXPECT_EQ(reprofiled.compileSeconds, 0.0);
    EXPECT_TRUE(reprofiled.live);

    RenderOutput removed = render(std::make_shared<const Scene>(*removeNode(*bigger, 2)), 5, false);
    EXPECT_GT(removed.compileSeconds, 0.0);
    EXPECT_FALSE(removed.live);
    EXPECT_EQ(removed.scene->nodes.size(), 2u);
    RenderOutput afterRemoval = render(withRadius(removed.scene, 0.5f), 6, true);
    // The old structure's live renderer is gone; the new structure's may be built already.
    if (!afterRemoval.live) {
        EXPECT_GT(afterRemoval.compileSeconds, 0.0);
    }
    EXPECT_EQ(afterRemoval.scene->nodes.size(), 2u);
}

// A scene evaluated from pruned tapes (molecule_1k: 1,000 spheres) has a baked renderer that
// takes value edits itself: the edited still frame comes without a compile and shows what a
// renderer made for the edited scene shows. Its kernel reads the spheres as balls, so a live
// renderer is built beside it, and draws at once, without a compile, the edit that scales a
// sphere differently per axis; the bake of that follows as a refinement.
TEST_F(ViewerGpu, ValueEditsOfALargeSceneRedrawWithoutACompile) {
    auto scene = std::make_shared<const Scene>(test::loadOrDie(
        std::filesystem::path(SDFCSG_SOURCE_DIR) / "assets/bench/molecule_1k.json"));
    RenderWorker worker(context());
    RenderJob job;
    job.options.width = 160;
    job.options.height = 120;
    job.options.camera = frameCamera(Evaluator(*scene), 160.0f / 120.0f);
    auto render = [&](std::shared_ptr<const Scene> s, uint64_t version) {
        job.scene = std::move(s);
        job.sceneVersion = version;
        ++job.id;
        worker.submit(job);
        RenderOutput out = wait(worker);
        EXPECT_FALSE(out.error) << out.error->str();
        return out;
    };
    auto expectFreshImage = [&](const RenderOutput& out) {
        auto fresh = Renderer::create(context(), *out.scene);
        ASSERT_TRUE(fresh) << fresh.error().str();
        auto expected = (*fresh)->render(job.options);
        ASSERT_TRUE(expected) << expected.error().str();
        EXPECT_EQ(differingFraction(out.image, *expected, 1), 0.0);
    };
    auto waitFor = [](auto done) {
        for (int i = 0; i < 24000 && !done(); ++i) // at most two minutes
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        return done();
    };
    RenderOutput first = render(scene, 1);
    EXPECT_GT(first.compileSeconds, 0.0);
    const float r = 0.06f; // twice the radius of the first sphere (node 1)
    auto edited = std::make_shared<const Scene>(*setValue(*scene, 1, "radius", std::span(&r, 1)));
    RenderOutput after = render(edited, 2);
    EXPECT_EQ(after.compileSeconds, 0.0);
    EXPECT_GT(after.renderSeconds, 0.0);
    EXPECT_FALSE(after.live);
    EXPECT_EQ(after.scene, edited);
    EXPECT_FALSE(worker.refinementPending(2));
    EXPECT_NE(after.image.rgba, first.image.rgba);
    expectFreshImage(after);

    ASSERT_TRUE(waitFor([&] { return worker.liveBuildDone(); }));
    const float scale[] = {1.5f, 1.0f, 0.6f};
    auto skewed = std::make_shared<const Scene>(*setValue(*edited, 1, "scale", scale));
    RenderOutput drawnLive = render(skewed, 3);
    EXPECT_EQ(drawnLive.compileSeconds, 0.0);
    EXPECT_TRUE(drawnLive.live);
    EXPECT_EQ(drawnLive.scene, skewed);
    EXPECT_NE(drawnLive.image.rgba, after.image.rgba);
    expectFreshImage(drawnLive);
    ASSERT_TRUE(waitFor([&] { return worker.refinementReady(3); }));
    RenderOutput baked = render(skewed, 3);
    EXPECT_EQ(baked.compileSeconds, 0.0);
    EXPECT_FALSE(baked.live);
    EXPECT_EQ(baked.image.rgba, drawnLive.image.rgba);
}

// A selected node's visible surface is tinted and outlined in still frames, inside its
// projected bounds only; choosing another node redraws the highlight, not the image.
TEST_F(ViewerGpu, SelectionIsHighlighted) {
    auto scene = std::make_shared<const Scene>(*parseScene(kScene, "scene.json"));
    RenderWorker worker(context());
    RenderJob job;
    job.scene = scene;
    job.sceneVersion = 1;
    job.options.width = 96;
    job.options.height = 64;
    job.options.camera = scene->camera;
    job.id = 1;
    worker.submit(job);
    RenderOutput plain = wait(worker);
    ASSERT_FALSE(plain.image.rgba.empty());
    const uint32_t left = *findNode(*scene, "left");
    job.highlight = int(left);
    job.id = 2;
    worker.submit(job);
    RenderOutput selected = wait(worker);
    EXPECT_EQ(selected.renderSeconds, 0.0); // the same frame, highlighted
    Evaluator evaluator(*scene);
    PixelRect r = projectedRect(*scene->camera, 96, 64, evaluator.nodes()[left].bounds);
    size_t changed = 0;
    for (uint32_t y = 0; y < 64; ++y)
        for (uint32_t x = 0; x < 96; ++x) {
            size_t k = (size_t(y) * 96 + x) * 4;
            if (std::equal(&plain.image.rgba[k], &plain.image.rgba[k + 3], &selected.image.rgba[k]))
                continue;
            ++changed;
            // Hits lie within half a pixel of a surface, and the outline one pixel outside.
            EXPECT_TRUE(int(x) >= r.x0 - 3 && int(x) < r.x1 + 3 && int(y) >= r.y0 - 3 &&
                        int(y) < r.y1 + 3)
                << x << "," << y;
        }
    EXPECT_GT(double(changed), 0.3 * double((r.x1 - r.x0) * (r.y1 - r.y0)));
    EXPECT_EQ(plain.pixels.size(), selected.pixels.size());
    // Previews are not highlighted.
    job.preview = true;
    job.id = 3;
    worker.submit(job);
    EXPECT_EQ(wait(worker).image.rgba, plain.image.rgba);
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

// A scene whose kernel does not build (as a shader compile can fail) reports the error and
// leaves the last scene that did on screen; the next scene that builds replaces it.
TEST_F(ViewerGpu, AFailedCompileKeepsTheLastSceneOnScreen) {
    auto scene = std::make_shared<const Scene>(*parseScene(kScene, "scene.json"));
    RendererFactory create = [](Context& c, const Scene& s,
                                const RendererOptions& o) -> Result<std::unique_ptr<Renderer>> {
        if (s.nodes.size() > 3)
            return Error::message(ErrorKind::Shader, "<kernel>", "compile failed (test)");
        return Renderer::create(c, s, o);
    };
    RenderWorker worker(context(), nullptr, create);
    RenderJob job;
    job.options.width = 64;
    job.options.height = 48;
    job.options.camera = scene->camera;
    auto render = [&](std::shared_ptr<const Scene> s, uint64_t version) {
        job.scene = std::move(s);
        job.sceneVersion = version;
        ++job.id;
        worker.submit(job);
        return wait(worker);
    };
    RenderOutput good = render(scene, 1);
    ASSERT_FALSE(good.error) << good.error->str();
    ASSERT_FALSE(good.image.rgba.empty());

    std::string bigger = kScene;
    bigger.replace(bigger.find("  ]},"), 5,
                   R"(  , {"type": "sphere", "radius": 0.3, "translate": [0, 1.5, 0]}]},)");
    auto broken = std::make_shared<const Scene>(*parseScene(bigger, "scene.json"));
    RenderOutput failed = render(broken, 2);
    ASSERT_TRUE(failed.error);
    EXPECT_EQ(failed.error->str(), "<kernel>: compile failed (test)");
    EXPECT_EQ(failed.scene, scene);
    EXPECT_EQ(failed.image.rgba, good.image.rgba);

    float radius = 0.9f;
    auto fixed =
        std::make_shared<const Scene>(*setValue(*scene, 1, "radius", std::span(&radius, 1)));
    RenderOutput again = render(fixed, 3);
    EXPECT_FALSE(again.error) << again.error->str();
    EXPECT_EQ(again.scene, fixed);
    EXPECT_NE(again.image.rgba, good.image.rgba);
}

// A large mesh comes with a simplified copy for moving views, of at most the threshold's
// triangles, closed, with the same topology, volume and area; a small one comes alone. The
// threshold is lowered so that a coarse grid stands for a fine one.
TEST_F(ViewerGpu, MeshWorkerSimplifiesAPreviewOfALargeMesh) {
    auto scene = std::make_shared<const Scene>(*parseScene(kScene, "scene.json"));
    auto extract = [&](size_t threshold, uint32_t resolution, float simplify = 0.0f) {
        MeshWorker worker(context(), threshold);
        MeshOptions options;
        options.resolution = resolution;
        EXPECT_TRUE(worker.start(scene, options, simplify));
        while (worker.running())
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        auto done = worker.take();
        EXPECT_TRUE(done && *done) << (done && !*done ? done->error().str() : "no result");
        return done && *done ? std::move(**done) : ExtractedMesh{};
    };

    ExtractedMesh large = extract(3000, 96);
    ASSERT_GT(large.mesh.triangleCount(), 3000u);
    ASSERT_TRUE(large.preview);
    EXPECT_LE(large.preview->triangleCount(), 3000u);
    EXPECT_GT(large.preview->triangleCount(), 1000u);
    const test::MeshProperties full = test::measureMesh(large.mesh),
                               coarse = test::measureMesh(*large.preview);
    EXPECT_TRUE(coarse.closedManifold()) << coarse.str();
    EXPECT_EQ(coarse.euler, full.euler);
    EXPECT_NEAR(coarse.volume, full.volume, 0.03 * full.volume);
    EXPECT_NEAR(coarse.area, full.area, 0.03 * full.area);

    // Simplified as asked: fewer triangles, still closed.
    ExtractedMesh simplified = extract(kPreviewMeshTriangles, 96, 0.25f);
    EXPECT_LT(simplified.mesh.triangleCount(), large.mesh.triangleCount() / 2);
    EXPECT_TRUE(test::measureMesh(simplified.mesh).closedManifold());

    ExtractedMesh small = extract(kPreviewMeshTriangles, 96);
    EXPECT_GT(small.mesh.triangleCount(), 1000u);
    EXPECT_FALSE(small.preview);
    // The report the mesh panel shows is the mesh's.
    EXPECT_EQ(small.report.triangles, small.mesh.triangleCount());
    EXPECT_EQ(small.report.euler, test::measureMesh(small.mesh).euler);
    ASSERT_TRUE(small.report.printability);
    EXPECT_GT(small.report.printability->samples, 0u);
    EXPECT_EQ(small.walls.size(), small.mesh.vertexCount());
    EXPECT_EQ(large.previewWalls.size(), large.preview->vertexCount());
}
