// One Context shared by threads that render and mesh at the same time (context.h, "Threads"):
// every result equals the one computed alone, and the validation layer, whose thread-safety
// checks see every command buffer, queue and fence call, reports nothing.
#include "gpu_test.h"

#include <latch>
#include <thread>

namespace sdfcsg::test {
namespace {

using ThreadsTest = GpuTest;

TEST_F(ThreadsTest, RenderAndMeshFromTwoThreadsAtOnce) {
    const Scene scene =
        loadOrDie(std::filesystem::path(SDFCSG_SOURCE_DIR) / "assets/scenes/csg_part.json");
    RenderOptions view;
    view.width = 96;
    view.height = 72;
    MeshOptions grid;
    grid.resolution = 40;

    // Alone first.
    auto renderer = Renderer::create(context(), scene);
    ASSERT_TRUE(renderer) << renderer.error().str();
    auto image = (*renderer)->render(view);
    ASSERT_TRUE(image) << image.error().str();
    auto mesher = Mesher::create(context(), scene);
    ASSERT_TRUE(mesher) << mesher.error().str();
    auto mesh = (*mesher)->extract(grid);
    ASSERT_TRUE(mesh) << mesh.error().str();
    ASSERT_GT(mesh->triangleCount(), 0u);

    // Then together, each thread building its own renderer or mesher on the shared context.
    // Both start their loops together.
    constexpr int kRuns = 8;
    std::vector<std::string> renderFailures, meshFailures;
    std::latch ready(2);
    std::thread renderThread([&] {
        auto r = Renderer::create(context(), scene);
        ready.arrive_and_wait();
        if (!r) return renderFailures.push_back(r.error().str());
        for (int run = 0; run < kRuns; ++run) {
            auto got = (*r)->render(view);
            if (!got)
                renderFailures.push_back(got.error().str());
            else if (got->rgba != image->rgba)
                renderFailures.push_back("image " + std::to_string(run) + " differs");
        }
    });
    std::thread meshThread([&] {
        auto m = Mesher::create(context(), scene);
        ready.arrive_and_wait();
        if (!m) return meshFailures.push_back(m.error().str());
        for (int run = 0; run < kRuns; ++run) {
            auto got = (*m)->extract(grid);
            if (!got)
                meshFailures.push_back(got.error().str());
            else if (got->positions != mesh->positions || got->indices != mesh->indices ||
                     got->colors != mesh->colors || got->normals != mesh->normals)
                meshFailures.push_back("mesh " + std::to_string(run) + " differs");
        }
    });
    renderThread.join();
    meshThread.join();
    EXPECT_TRUE(renderFailures.empty()) << renderFailures.front();
    EXPECT_TRUE(meshFailures.empty()) << meshFailures.front();
}

} // namespace
} // namespace sdfcsg::test
