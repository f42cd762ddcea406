// Per-region pruning (engine/src/field/prune.h) on the CPU: in every cell that may hold surface the
// pruned tape gives the whole tree's value; elsewhere the bound never exceeds the field in
// magnitude and keeps its sign; the tapes are short; smooth unions' bounds stay tight.
#include "field/prune.h"
#include "scene_build_util.h"

#include <sdfcsg/sdfcsg.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <gtest/gtest.h>

#include <random>

namespace sdfcsg::test {
namespace {

namespace fs = std::filesystem;

// Points uniform in the bounds (the finite leaves' box where planes reach) grown by a quarter,
// and as many pulled onto the surface by a Newton step.
std::vector<glm::vec3> points(const Evaluator& ev, size_t count, uint32_t seed) {
    Aabb box;
    for (const FlatNode& n : ev.nodes())
        if (n.bounds.finite() && n.frame == kWorldFrame) { // others are in a domain's space
            box.min = glm::min(box.min, n.bounds.min);
            box.max = glm::max(box.max, n.bounds.max);
        }
    const glm::vec3 margin = 0.25f * (box.max - box.min) + 0.05f;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<glm::vec3> out;
    for (size_t i = 0; i < count; ++i) {
        glm::vec3 p =
            glm::mix(box.min - margin, box.max + margin, glm::vec3(u(rng), u(rng), u(rng)));
        out.push_back(p);
        const float h = 1e-3f;
        glm::vec3 g(ev.distance(p + glm::vec3(h, 0, 0)) - ev.distance(p - glm::vec3(h, 0, 0)),
                    ev.distance(p + glm::vec3(0, h, 0)) - ev.distance(p - glm::vec3(0, h, 0)),
                    ev.distance(p + glm::vec3(0, 0, h)) - ev.distance(p - glm::vec3(0, 0, h)));
        if (glm::length(g) > 1e-6f) out.push_back(p - ev.distance(p) * glm::normalize(g));
    }
    return out;
}

// Pruned against whole-tree evaluation at every point; returns the mean tape length run at the
// points that ran one.
double expectPrunedMatchesFull(const Scene& scene, size_t count = 3000, uint32_t levels = 5,
                               size_t maxWords = detail::PruneOptions{}.maxWords) {
    Evaluator ev(scene);
    detail::PruneOptions options;
    options.levels = levels;
    options.maxWords = maxWords;
    const detail::PrunedField field = detail::pruneField(ev, options);
    size_t wrong = 0, overBound = 0, ran = 0;
    double length = 0.0;
    std::string first;
    for (glm::vec3 p : points(ev, count, 7)) {
        const float full = ev.distance(p);
        const Sample pruned = field.sample(ev.nodes(), p);
        const float d = field.distance(ev.nodes(), p);
        EXPECT_EQ(d, pruned.distance);
        if (const uint32_t active = field.activeLength(p)) {
            ++ran;
            length += active;
            if (!(std::abs(d - full) <= 1e-5f * (1.0f + std::abs(full)))) {
                if (wrong++ == 0)
                    first = "pruned " + std::to_string(d) + ", full " + std::to_string(full);
            }
            const Sample whole = ev.sample(p);
            // Colours blend by the smooth operators' factor, which a dropped operand 2k above
            // the least one shifts by more than the distance: within the output's 1/255.
            EXPECT_LE(glm::length(pruned.color - whole.color), 1.0f / 255.0f);
        } else {
            // A bound: same sign, magnitude never above the field's.
            const bool ok = full > 0.0f ? (d > 0.0f && d <= full) : (d < 0.0f && d >= full);
            if (!ok && overBound++ == 0)
                first = "bound " + std::to_string(d) + ", full " + std::to_string(full);
        }
    }
    EXPECT_EQ(wrong, 0u) << scene.file << ": first " << first;
    EXPECT_EQ(overBound, 0u) << scene.file << ": first " << first;
    return ran ? length / double(ran) : 0.0;
}

TEST(Prune, FullTapeRunsTheWholeTree) {
    Scene scene = randomScene(3, 60);
    Evaluator ev(scene);
    uint32_t depth = 0;
    const std::vector<uint32_t> tape = detail::fullTape(ev.nodes(), depth);
    // One instruction per primitive and one per fold: 2 * primitives - 1 (every operation has
    // at least one child).
    size_t primitives = 0;
    for (const Node& n : scene.nodes)
        primitives += kindInfo(n.kind).operation ? 0 : 1;
    EXPECT_EQ(tape.size(), 2 * primitives - 1);
    EXPECT_GE(depth, 2u);
    detail::PruneOptions none;
    none.levels = 0;
    const detail::PrunedField field = detail::pruneField(ev, none);
    for (glm::vec3 p : points(ev, 500, 3))
        EXPECT_EQ(field.distance(ev.nodes(), p), ev.distance(p));
}

// The C++ tape machine (shaders/tape_run.glsl, compiled in prune.cpp) sizes its arrays for the
// tape: a stack of 41 values, where a right-leaning chain of unions and differences keeps every
// left operand until its end, inside five domain operations nested in one another and value
// operations between them, which normalise their child's field (eval.cpp, FlatNode::loss; too
// thin against it to bake, field/bake.h) and so open as domain operations do. The whole tape gives
// the tree's bits. (The pruner's runs of domain operations are the bundled scenes' part.)
TEST(Prune, TheMachineRunsDeepStacksInNestedDomains) {
    std::string chain = R"({"type": "sphere", "radius": 0.3})";
    for (int i = 0; i < 40; ++i) {
        const float x = 0.05f * float(i % 7) - 0.15f, y = 0.04f * float(i % 5) - 0.1f;
        chain = std::string(R"({"type": ")") + (i % 3 == 2 ? "difference" : "union") +
                R"(", "smooth": )" + (i % 2 ? "0.05" : "0") + R"(, "children": [{"type": "box", )" +
                R"("size": [0.2, 0.3, 0.25], "translate": [)" + std::to_string(x) + ", " +
                std::to_string(y) + R"(, 0.1], "color": [0.9, 0.2, 0.1]}, )" + chain + "]}";
    }
    const Scene scene = parseRoot(
        R"({"type": "repeat", "count": [3, 1, 2], "spacing": [2.5, 1, 2.5], "children": [
            {"type": "polar_repeat", "count": 5, "radius": 0.6, "children": [
            {"type": "offset", "distance": 0.002, "children": [
            {"type": "mirror", "axes": "x", "children": [
            {"type": "twist", "angle": 40, "children": [
            {"type": "shell", "thickness": 0.002, "children": [
            {"type": "elongate", "length": [0.2, 0, 0.1], "children": [)" +
        chain + "]}]}]}]}]}]}]}");
    ASSERT_FALSE(scene.nodes.empty());
    const Evaluator ev(scene);
    detail::PruneOptions whole;
    whole.levels = 0;
    const detail::PrunedField field = detail::pruneField(ev, whole);
    EXPECT_EQ(field.domainDepth, 7u);
    EXPECT_GE(field.stackDepth, 41u);
    for (glm::vec3 p : points(ev, 400, 13)) {
        const Sample s = field.sample(ev.nodes(), p), full = ev.sample(p);
        ASSERT_EQ(field.distance(ev.nodes(), p), ev.distance(p));
        ASSERT_EQ(s.distance, full.distance);
        ASSERT_EQ(s.color, full.color);
    }
}

TEST(Prune, BundledScenesMatchTheWholeTree) {
    for (const fs::path& path : bundledScenePaths()) {
        auto scene = loadScene(path);
        ASSERT_TRUE(scene) << scene.error().str();
        expectPrunedMatchesFull(*scene);
    }
}

TEST(Prune, RandomScenesMatchTheWholeTree) {
    for (uint32_t seed = 1; seed <= 12; ++seed)
        expectPrunedMatchesFull(randomScene(seed, 150, 6, seed % 3 == 0), 1500, 4);
}

// Many small spheres in one smooth union, as in the molecule benchmark scene: cells near the
// surface run a few of them, and the bounds are the spheres' box widened by the blend radius.
Scene molecule(int count, float radius, float k) {
    std::mt19937 rng(11);
    std::normal_distribution<float> step(0.0f, 0.02f);
    std::vector<Tree> spheres;
    glm::vec3 p(0.0f);
    for (int i = 0; i < count; ++i) {
        p += glm::vec3(step(rng), step(rng), step(rng));
        if (glm::length(p) > 0.9f) p *= 0.9f / glm::length(p);
        spheres.push_back(sphere(radius).at(p.x, p.y, p.z));
    }
    return makeScene(unite(std::move(spheres), k), "<molecule>");
}

TEST(Prune, SmoothUnionOfManySpheresPrunesToAFew) {
    Scene scene = molecule(1000, 0.03f, 0.026f);
    const double mean = expectPrunedMatchesFull(scene, 2000);
    EXPECT_GT(mean, 0.0);
    EXPECT_LT(mean, 100.0) << "of a tape of 1999 instructions";
}

TEST(Prune, SmoothUnionBoundsDoNotGrowWithItsOperands) {
    const float k = 0.026f;
    Scene scene = molecule(1000, 0.03f, k);
    Evaluator ev(scene);
    Aabb spheres;
    for (const FlatNode& n : ev.nodes())
        if (n.kind == NodeKind::Sphere) {
            spheres.min = glm::min(spheres.min, n.bounds.min);
            spheres.max = glm::max(spheres.max, n.bounds.max);
        }
    const Aabb& b = ev.bounds();
    for (int a = 0; a < 3; ++a) {
        EXPECT_GE(b.min[a], spheres.min[a] - k * 1.001f);
        EXPECT_LE(b.max[a], spheres.max[a] + k * 1.001f);
    }
    // And they still bound the field: its value is never below their signed distance.
    for (glm::vec3 p : points(ev, 3000, 5))
        EXPECT_GE(ev.distance(p), b.signedDistance(p) - 1e-6f);
}

// The evaluator's pruned path is that field: the same values, near the surface the whole tree's.
TEST(Prune, TheEvaluatorsPrunedDistanceIsThePrunedField) {
    const Scene scene = molecule(1000, 0.03f, 0.026f);
    const Evaluator ev(scene);
    const detail::PrunedField field = detail::pruneField(ev);
    const Evaluator copy = ev;
    size_t near = 0;
    for (glm::vec3 p : points(ev, 1000, 9)) {
        const float d = ev.prunedDistance(p), full = ev.distance(p);
        EXPECT_EQ(d, field.distance(ev.nodes(), p));
        EXPECT_EQ(copy.prunedDistance(p), d);
        if (field.activeLength(p) > 0) { // a cell near the surface: the whole tree's value
            ++near;
            EXPECT_NEAR(d, full, 1e-5f * (1.0f + std::abs(full)));
        } else { // a bound
            EXPECT_TRUE(full > 0.0f ? d > 0.0f && d <= full : d < 0.0f && d >= full);
        }
    }
    EXPECT_GT(near, 100u);
}

// 2,000 spheres nearly on top of each other prune to little: past the budget, refinement stops,
// so the tapes stay within it (about 4,000 words a cell; the sphere's shell crosses some 20,000
// leaf cells), and the coarser cells still give the whole tree's values.
TEST(Prune, TreesThatPruneLittleStayWithinTheBudget) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> jitter(-0.01f, 0.01f);
    std::vector<Tree> spheres;
    for (int i = 0; i < 2000; ++i)
        spheres.push_back(sphere(0.5f).at(jitter(rng), jitter(rng), jitter(rng)));
    const Scene scene = makeScene(unite(std::move(spheres), 0.05f), "<overlapping>");
    const size_t budget = size_t(1) << 18;
    detail::PruneOptions options;
    options.maxWords = budget;
    const detail::PrunedField field = detail::pruneField(Evaluator(scene), options);
    EXPECT_LE(field.tape.size(), field.fullLength + budget + 2 * field.fullLength);
    expectPrunedMatchesFull(scene, 1000, 5, budget);
}

TEST(Prune, BenchmarkScenesMatchTheWholeTree) {
    const fs::path dir = fs::path(SDFCSG_SOURCE_DIR) / "assets/bench";
    ASSERT_TRUE(fs::is_directory(dir));
    for (const auto& entry : fs::directory_iterator(dir)) {
        if (entry.path().extension() != ".json") continue;
        auto scene = loadScene(entry.path());
        ASSERT_TRUE(scene) << scene.error().str();
        const double mean = expectPrunedMatchesFull(*scene, 400);
        EXPECT_LT(mean, 0.05 * double(2 * scene->nodes.size())) << entry.path();
    }
}

} // namespace
} // namespace sdfcsg::test
