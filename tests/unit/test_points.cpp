// PointSampler (sdfcsg/points.h): the field at batches of points on the device, against the CPU
// evaluator: random trees of every kind (inlined), a scene large enough for pruned tapes, and
// more points than one batch holds.
#include "gpu_test.h" // tests/gtest_suites.cmake labels the program's fixtures gpu by this line

#include "field/prune.h"

#include <sdfcsg/points.h>

#include <cmath>

namespace sdfcsg::test {
namespace {

class Points : public GpuTest {};

// The sampler's values and colours at `points` are the evaluator's, to single-precision rounding:
// the pruned field's (field/prune.h), which away from the surface is a bound, where the scene
// runs on tapes (above kTapeMinNodes nodes, and wherever value or domain operations are).
void expectCpuField(Context& context, const Scene& scene, const std::vector<glm::vec3>& points) {
    const bool pruned = usesTapes(scene, Evaluation::Auto);
    auto sampler = PointSampler::create(context, scene);
    ASSERT_TRUE(sampler) << sampler.error().str();
    std::vector<float> distances(points.size());
    std::vector<glm::vec3> colors(points.size());
    ASSERT_TRUE((*sampler)->sample(points, distances, colors));
    const Evaluator evaluator(scene);
    const detail::PrunedField field = detail::pruneField(evaluator);
    for (size_t i = 0; i < points.size(); ++i) {
        const Sample s =
            pruned ? field.sample(evaluator.nodes(), points[i]) : evaluator.sample(points[i]);
        ASSERT_NEAR(distances[i], s.distance, 2e-4f * (1.0f + std::abs(s.distance))) << i;
        if (std::abs(s.distance) < 0.5f) {
            EXPECT_NEAR(colors[i].r, s.color.r, 1e-3f) << i;
            EXPECT_NEAR(colors[i].b, s.color.b, 1e-3f) << i;
        }
    }
}

TEST_F(Points, RandomTreesMatchTheCpu) {
    for (uint32_t seed = 0; seed < 3; ++seed) {
        SCOPED_TRACE(seed);
        auto scene = parseScene(randomTreesJson(400 + seed), "<random>");
        ASSERT_TRUE(scene) << scene.error().str();
        expectCpuField(context(), *scene, randomPoints(seed, 4096, 2.5f));
    }
}

TEST_F(Points, LargeScenesRunTheirTapes) {
    auto scene =
        loadScene(std::filesystem::path(SDFCSG_SOURCE_DIR) / "assets/bench/groups_1k.json");
    ASSERT_TRUE(scene) << scene.error().str();
    EXPECT_GE(scene->nodes.size(), kTapeMinNodes);
    const Aabb b = Evaluator(*scene).finiteBounds();
    std::vector<glm::vec3> points = randomPoints(9, 4096, 1.0f);
    for (glm::vec3& p : points)
        p = (b.min + b.max) * 0.5f + p * (b.max - b.min) * 0.5f;
    expectCpuField(context(), *scene, points);
}

TEST_F(Points, MorePointsThanABatch) {
    auto scene = parseScene(R"({"version": 1, "root": {"type": "sphere", "radius": 1}})");
    ASSERT_TRUE(scene);
    auto sampler = PointSampler::create(context(), *scene);
    ASSERT_TRUE(sampler) << sampler.error().str();
    std::vector<glm::vec3> points(PointSampler::kBatch + 1000);
    for (size_t i = 0; i < points.size(); ++i)
        points[i] = glm::vec3(float(i % 1000) * 0.003f, float(i / 1000 % 7) * 0.2f, 0.5f);
    std::vector<float> distances(points.size());
    ASSERT_TRUE((*sampler)->sample(points, distances));
    for (size_t i = 0; i < points.size(); i += 997)
        ASSERT_NEAR(distances[i], glm::length(points[i]) - 1.0f, 1e-5f) << i;
    const size_t last = points.size() - 1;
    EXPECT_NEAR(distances[last], glm::length(points[last]) - 1.0f, 1e-5f);
    // Spans of other lengths are refused.
    std::vector<float> shorter(10);
    auto refused = (*sampler)->sample(points, shorter);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().kind, ErrorKind::Usage);
}

} // namespace
} // namespace sdfcsg::test
