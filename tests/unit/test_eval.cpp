// The CPU reference evaluator: transforms, colours, smooth blending, bounds and bounds skipping.
#include "codegen/gpu_nodes.h"
#include "scene_build_util.h"
#include "shared.h"

#include <sdfcsg/eval.h>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

namespace sdfcsg {
namespace {

using namespace sdfcsg::test;

// Half again the size of the scene's finite part, and at least 5.
float reach(const Evaluator& eval) {
    float r = 5.0f;
    for (const FlatNode& n : eval.nodes())
        if (!kindInfo(n.kind).operation && n.bounds.finite() && n.frame == kWorldFrame)
            r = std::max({r, 1.5f * glm::length(n.bounds.min), 1.5f * glm::length(n.bounds.max)});
    return r;
}

double boxDistance(glm::dvec3 p, glm::dvec3 half) {
    glm::dvec3 q = glm::abs(p) - half;
    return glm::length(glm::max(q, 0.0)) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
}

// translate * Rz * Ry * Rx * scale, built with GLM's matrix helpers (an independent route to
// the same convention as the evaluator).
glm::dmat4 modelMatrix(const Transform& t) {
    glm::dmat4 m = glm::translate(glm::dmat4(1.0), glm::dvec3(t.translate));
    m = glm::rotate(m, glm::radians(double(t.rotate.z)), glm::dvec3(0, 0, 1));
    m = glm::rotate(m, glm::radians(double(t.rotate.y)), glm::dvec3(0, 1, 0));
    m = glm::rotate(m, glm::radians(double(t.rotate.x)), glm::dvec3(1, 0, 0));
    return glm::scale(m, glm::dvec3(t.scale));
}

TEST(Eval, NestedTransformsCompose) {
    Tree inner = box(1.0f, 2.0f, 0.5f).at(0.3f, -0.2f, 0.7f).rotated(25, -40, 70).scaled(0.7f);
    Tree outer = unite({inner}).at(1.0f, 2.0f, -1.0f).rotated(-30, 15, 120).scaled(1.6f);
    Scene scene = makeScene(outer);
    Evaluator eval(scene);

    glm::dmat4 toWorld =
        modelMatrix(scene.nodes[0].transform) * modelMatrix(scene.nodes[1].transform);
    glm::dmat4 toLocal = glm::inverse(toWorld);
    const double scale = 1.6 * 0.7;
    for (glm::vec3 p : randomPoints(1, 2000, 4.0f)) {
        glm::dvec3 local(toLocal * glm::dvec4(glm::dvec3(p), 1.0));
        double expected = scale * boxDistance(local, {0.5, 1.0, 0.25});
        EXPECT_NEAR(eval.distance(p), expected, 1e-5 * (1 + glm::length(p)));
    }
}

TEST(Eval, RotationIsRightHandedXThenYThenZ) {
    // A capsule from the origin to +x, turned +90 degrees about z, reaches +y.
    Scene z = makeScene(capsule({0, 0, 0}, {1, 0, 0}, 0.1f).rotated(0, 0, 90));
    EXPECT_NEAR(Evaluator(z).distance({0, 1, 0}), -0.1f, 1e-6f);
    // About x first (+x stays), then y: +90 about y takes +x to -z.
    Scene xy = makeScene(capsule({0, 0, 0}, {1, 0, 0}, 0.1f).rotated(90, 90, 0));
    EXPECT_NEAR(Evaluator(xy).distance({0, 0, -1}), -0.1f, 1e-6f);
    // x then z: +90 about x takes +y to +z; a capsule along +y ends at +z, then z leaves it.
    Scene xz = makeScene(capsule({0, 0, 0}, {0, 1, 0}, 0.1f).rotated(90, 0, 90));
    EXPECT_NEAR(Evaluator(xz).distance({0, 0, 1}), -0.1f, 1e-6f);
}

TEST(Eval, ScaleScalesDistances) {
    Scene scene = makeScene(unite({sphere(1.0f).at(1, 0, 0)}).scaled(2.0f));
    Evaluator eval(scene);
    EXPECT_FLOAT_EQ(eval.distance({2, 0, 0}), -2.0f); // sphere centre at world x = 2
    EXPECT_FLOAT_EQ(eval.distance({7, 0, 0}), 3.0f);
}

TEST(Eval, ColoursAreInherited) {
    Scene scene = makeScene(unite({
        sphere(0.5f).at(-3, 0, 0),
        unite({sphere(0.5f).at(0, 0, 0), sphere(0.5f).at(3, 0, 0).colored(0, 0, 1)})
            .colored(1, 0, 0),
    }));
    Evaluator eval(scene);
    EXPECT_EQ(eval.sample({-3, 0, 0}).color, glm::vec3(0.8f)); // the default
    EXPECT_EQ(eval.sample({0, 0, 0}).color, glm::vec3(1, 0, 0));
    EXPECT_EQ(eval.sample({3, 0, 0}).color, glm::vec3(0, 0, 1));
    EXPECT_EQ(eval.nodes()[3].color, glm::vec3(1, 0, 0));
}

TEST(Eval, SmoothUnionBlendsDistanceAndColour) {
    // Two unit spheres 2.4 apart, blend radius 0.5 in the union's units, union scaled by 2.
    Scene scene = makeScene(unite({sphere(1).at(-1.2f, 0, 0).colored(1, 0, 0),
                                   sphere(1).at(1.2f, 0, 0).colored(0, 0, 1)},
                                  0.5f)
                                .scaled(2.0f));
    Evaluator eval(scene);
    EXPECT_FLOAT_EQ(eval.nodes()[0].smooth, 1.0f); // world units
    // Half way between: both operands are 0.4 (world), h = 0.5, the blend dips by k/4.
    Sample mid = eval.sample({0, 0, 0});
    EXPECT_NEAR(mid.distance, 0.4f - 1.0f / 4, 1e-6f);
    EXPECT_NEAR(mid.color.r, 0.5f, 1e-6f);
    EXPECT_NEAR(mid.color.b, 0.5f, 1e-6f);
    // Near the red sphere and more than k from the blue one: untouched.
    Sample red = eval.sample({-4, 0, 0});
    EXPECT_FLOAT_EQ(red.distance, 4.0f - 2.4f - 2.0f);
    EXPECT_EQ(red.color, glm::vec3(1, 0, 0));
    // Part way: colour weights follow the distance blend factor h.
    glm::vec3 p(-0.3f, 0.2f, 0);
    float a = glm::length(p - glm::vec3(-2.4f, 0, 0)) - 2,
          b = glm::length(p - glm::vec3(2.4f, 0, 0)) - 2;
    float h = std::clamp(0.5f + 0.5f * (b - a) / 1.0f, 0.0f, 1.0f);
    Sample s = eval.sample(p);
    EXPECT_NEAR(s.distance, b + (a - b) * h - h * (1 - h), 1e-5f);
    EXPECT_NEAR(s.color.r, h, 1e-5f);
    EXPECT_NEAR(s.color.b, 1 - h, 1e-5f);
}

TEST(Eval, DifferenceCutTakesTheSubtrahendsColour) {
    Scene scene = makeScene(
        subtract({box(2, 2, 2).colored(1, 0, 0), sphere(0.8f).at(1, 1, 1).colored(0, 1, 0)}));
    Evaluator eval(scene);
    // On the spherical cut, inside the box: green. On an untouched face: red.
    glm::vec3 cut = glm::vec3(1) - glm::normalize(glm::vec3(1)) * 0.8f;
    Sample s = eval.sample(cut);
    EXPECT_NEAR(s.distance, 0.0f, 1e-5f);
    EXPECT_EQ(s.color, glm::vec3(0, 1, 0));
    EXPECT_EQ(eval.sample({-1.0f, -0.5f, 0}).color, glm::vec3(1, 0, 0));
    // A sharp tie goes to the first operand.
    Scene tie = makeScene(unite({sphere(1).colored(1, 0, 0), sphere(1).colored(0, 1, 0)}));
    EXPECT_EQ(Evaluator(tie).sample({0, 2, 0}).color, glm::vec3(1, 0, 0));
}

TEST(Eval, IntersectionAndDifferenceValues) {
    Scene inter = makeScene(intersect({box(2, 2, 2), sphere(1.2f)}));
    Scene diff = makeScene(subtract({box(2, 2, 2), sphere(1.2f)}));
    for (glm::vec3 p : randomPoints(5, 500, 2.0f)) {
        float b = boxDistance(p, glm::dvec3(1)), s = glm::length(p) - 1.2f;
        EXPECT_NEAR(Evaluator(inter).distance(p), std::max(b, s), 1e-6f);
        EXPECT_NEAR(Evaluator(diff).distance(p), std::max(b, -s), 1e-6f);
    }
}

std::vector<Scene> bundledScenes() {
    std::vector<Scene> scenes;
    for (const auto& path : bundledScenePaths()) {
        auto scene = loadScene(path);
        EXPECT_TRUE(scene) << scene.error().str();
        if (scene) scenes.push_back(std::move(*scene));
    }
    return scenes;
}

std::vector<Scene> boundsScenes() {
    std::vector<Scene> scenes = bundledScenes();
    scenes.push_back(primitiveGallery());
    for (uint32_t seed = 1; seed <= 12; ++seed)
        scenes.push_back(randomScene(seed, 40, 5, seed % 3 == 0));
    return scenes;
}

// The bounds promise: a node's value at p is at least its box's signed distance to p. Checked for
// every node of every scene, at random points around it.
TEST(Eval, BoundsAreLowerBounds) {
    std::vector<Scene> scenes = boundsScenes();
    // A mesh whose grid of bricks reaches past its box by more than its band: beyond the grid
    // its field, the distance to the grid plus the band, fell below the box's distance.
    scenes.push_back(
        parseRoot(R"({"type": "mesh", "file": "gear.stl", "resolution": 128, "band": 0.05})"));
    for (const Scene& scene : scenes) {
        SCOPED_TRACE(scene.file);
        Evaluator eval(scene);
        std::vector<glm::vec3> points = randomPoints(9, 600, reach(eval));
        for (uint32_t i = 0; i < eval.nodes().size(); ++i) {
            const Aabb& box = eval.nodes()[i].bounds;
            ASSERT_FALSE(box.empty());
            if (eval.nodes()[i].frame != kWorldFrame) continue; // a box of a domain's space
            for (glm::vec3 p : points) {
                float value = eval.distance(p, i);
                ASSERT_GE(value, box.signedDistance(p) - 1e-5f)
                    << "node " << i << " (" << kindInfo(eval.nodes()[i].kind).name << ")";
            }
        }
    }
}

// Scenes whose values would fall below their boxes' distance but for the floor of the bounds:
// scales that differ per axis, on a primitive or on an operation (the field is the local one
// times the smallest factor, so far along the largest it grows more slowly than the box's
// distance); a repetition whose copies reach past their neighbours (its value is capped by the
// distance to the copies it leaves out); random trees of every kind scaled per axis.
std::vector<Scene> stretchedScenes() {
    std::vector<Scene> scenes = {
        parseRoot(R"({"type": "union", "scale": [1, 0.5, 2], "rotate": [20, 35, 10], "children": [
            {"type": "box", "size": [1, 0.6, 0.8]},
            {"type": "sphere", "radius": 0.5, "translate": [1, 0.5, 0]},
            {"type": "torus", "major_radius": 0.6, "minor_radius": 0.2, "translate": [-0.8, 0, 0.5]}
            ]})"),
        parseRoot(R"({"type": "union", "children": [{"type": "sphere", "radius": 0.3},
            {"type": "repeat", "count": [6, 1, 1], "spacing": [0.5, 1, 1], "children": [
                {"type": "box", "size": [0.9, 0.3, 0.3]}]}]})"),
    };
    for (uint32_t seed = 1; seed <= 8; ++seed) {
        const std::string name = "<random trees " + std::to_string(seed) + ">";
        auto scene = parseScene(randomTreesJson(seed, {.scalesPerAxis = true}), name);
        EXPECT_TRUE(scene) << scene.error().str();
        if (scene) scenes.push_back(std::move(*scene));
    }
    return scenes;
}

TEST(Eval, BoundsAreLowerBoundsWhereScalesDifferPerAxis) {
    for (const Scene& scene : stretchedScenes()) {
        SCOPED_TRACE(scene.file);
        Evaluator eval(scene);
        std::vector<glm::vec3> points = randomPoints(9, 600, reach(eval));
        for (uint32_t i = 0; i < eval.nodes().size(); ++i) {
            const Aabb& box = eval.nodes()[i].bounds;
            if (eval.nodes()[i].frame != kWorldFrame) continue;
            for (glm::vec3 p : points)
                ASSERT_GE(eval.distance(p, i), box.signedDistance(p) - 1e-5f)
                    << "node " << i << " (" << kindInfo(eval.nodes()[i].kind).name << ") at " << p.x
                    << " " << p.y << " " << p.z;
        }
    }
}

// Points on each node's own surface (found by Newton steps along the numerical gradient) lie in
// its box.
TEST(Eval, BoundsContainTheSurface) {
    for (const Scene& scene : boundsScenes()) {
        SCOPED_TRACE(scene.file);
        Evaluator eval(scene);
        int projected = 0, nodes = 0;
        for (uint32_t i = 0; i < eval.nodes().size(); ++i) {
            // Inside a domain operation, bounds are in its child space (distance(p, i) is the
            // operation's, in the world): those are tested through the operation's own.
            if (eval.nodes()[i].frame != kWorldFrame) continue;
            ++nodes;
            const Aabb& box = eval.nodes()[i].bounds;
            for (glm::vec3 p : randomPoints(i + 100, 40, 0.6f * reach(eval))) {
                for (int step = 0; step < 30; ++step) {
                    float d = eval.distance(p, i);
                    if (std::abs(d) < 1e-5f) break;
                    glm::vec3 g;
                    const float h = 1e-3f;
                    for (int a = 0; a < 3; ++a) {
                        glm::vec3 e(0);
                        e[a] = h;
                        g[a] = (eval.distance(p + e, i) - eval.distance(p - e, i)) / (2 * h);
                    }
                    if (glm::length(g) < 1e-3f) break;
                    p -= d * g / glm::dot(g, g);
                }
                if (std::abs(eval.distance(p, i)) >= 1e-5f) continue;
                ++projected;
                EXPECT_LE(box.distance(p), 1e-4f)
                    << "node " << i << " surface point outside its box";
            }
        }
        EXPECT_GT(projected, 20 * nodes);
    }
}

TEST(Eval, PrimitiveBoundsAreTight) {
    Scene scene =
        makeScene(unite({box(2, 4, 6).at(1, 0, 0), sphere(1).at(0, 5, 0), plane({0, 1, 0}, 0)}));
    Evaluator eval(scene);
    const Aabb& b = eval.nodes()[1].bounds;
    EXPECT_NEAR(b.min.x, 0.0f, 1e-4f);
    EXPECT_NEAR(b.max.z, 3.0f, 1e-4f);
    EXPECT_TRUE(eval.nodes()[2].bounds.finite());
    EXPECT_FALSE(eval.nodes()[3].bounds.finite());
    EXPECT_FALSE(eval.bounds().finite());
    // Rotating a cube by 45 degrees about z widens its box to the diagonal.
    Scene turned = makeScene(box(2, 2, 2).rotated(0, 0, 45));
    EXPECT_NEAR(Evaluator(turned).bounds().max.x, std::sqrt(2.0f), 1e-4f);
    EXPECT_NEAR(Evaluator(turned).bounds().max.z, 1.0f, 1e-4f);
}

// The box that framing and the mesh grid take: every point inside the solid lies in it (dense
// samples over the bounds, for every scene of the bounds tests, and over a box three times the
// size of the scene's finite part, for random trees of every kind scaled per axis among planes
// and for the cases a box could most easily miss), and it is within 5% of the sampled solid's
// box where the operations' boxes say as much.

// Every point of a grid of n + 1 points a side over `within` where the field is below 0 lies in
// the solid bounds.
void expectSolidWithin(const Evaluator& eval, const Aabb& within, int n) {
    const Aabb& tight = eval.solidBounds();
    const glm::vec3 step = (within.max - within.min) / float(n);
    int outside = 0;
    for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j)
            for (int k = 0; k <= n; ++k) {
                const glm::vec3 p = within.min + glm::vec3(i, j, k) * step;
                if (eval.distance(p) >= 0.0f) continue;
                const float slack = 1e-5f * (1.0f + glm::length(p));
                if (glm::all(glm::greaterThanEqual(p, tight.min - slack)) &&
                    glm::all(glm::lessThanEqual(p, tight.max + slack)))
                    continue;
                if (outside++ == 0)
                    ADD_FAILURE() << "inside the solid at " << p.x << " " << p.y << " " << p.z
                                  << ", outside its bounds [" << tight.min.x << " " << tight.min.y
                                  << " " << tight.min.z << "] .. [" << tight.max.x << " "
                                  << tight.max.y << " " << tight.max.z << "]";
            }
    EXPECT_EQ(outside, 0);
}

// The scene's finite part (its bounds where finite, else its finite primitives' box), grown by
// its size on every side.
Aabb searchBox(const Evaluator& eval) {
    Aabb finite;
    for (const FlatNode& n : eval.nodes())
        if (n.frame == kWorldFrame && n.bounds.finite() && !n.bounds.empty()) {
            finite.min = glm::min(finite.min, n.bounds.min);
            finite.max = glm::max(finite.max, n.bounds.max);
        }
    for (int a = 0; a < 3; ++a) {
        if (std::isfinite(eval.bounds().min[a])) finite.min[a] = eval.bounds().min[a];
        if (std::isfinite(eval.bounds().max[a])) finite.max[a] = eval.bounds().max[a];
    }
    if (finite.empty()) finite = Aabb{glm::vec3(-1.0f), glm::vec3(1.0f)};
    const glm::vec3 size = finite.max - finite.min;
    const float grow = std::max({size.x, size.y, size.z, 0.1f});
    return Aabb{finite.min - grow, finite.max + grow};
}

TEST(Eval, SolidBoundsHoldTheSolid) {
    for (const Scene& scene : boundsScenes()) {
        SCOPED_TRACE(scene.file);
        const Evaluator eval(scene);
        const Aabb& tight = eval.solidBounds();
        const Aabb& loose = eval.bounds();
        for (int a = 0; a < 3; ++a) {
            EXPECT_GE(tight.min[a], loose.min[a]);
            EXPECT_LE(tight.max[a], loose.max[a]);
        }
        if (loose.finite()) expectSolidWithin(eval, loose, 48);
    }
}

// What a box misses first: an offset of a difference wraps round the edges of the box it
// subtracts (a cut box grown by the offset would not hold it), smooth blends of cut solids,
// offsets and shells of solids cut by planes that are not along an axis, planes subtracted,
// planes scaled per axis, every domain operation turned and scaled per axis. `tight` where
// boxes and half-spaces say all there is to say of the solid's box (not of a ball cut by a
// plane, nor of a solid shrunk by an inward offset or a blend).
struct EdgeCase {
    Scene scene;
    bool tight;
};
std::vector<EdgeCase> edgeScenes() {
    const bool tight[] = {true, false, true, false, true};
    const char* const roots[] = {
        R"({"type": "offset", "distance": 0.3, "children": [{"type": "difference", "children": [
            {"type": "box", "size": [2, 2, 2]},
            {"type": "box", "size": [2, 1, 2], "translate": [0, 1, 0]}]}]})",
        R"({"type": "union", "smooth": 0.4, "children": [
            {"type": "intersection", "children": [{"type": "sphere", "radius": 1},
                {"type": "plane", "normal": [1, 1, 0], "offset": -0.3}]},
            {"type": "difference", "children": [{"type": "box", "size": [1, 1, 1]},
                {"type": "plane", "normal": [0, -1, 0.2], "offset": 0.1}]}]})",
        R"({"type": "shell", "thickness": 0.2, "children": [{"type": "intersection", "children": [
            {"type": "box", "size": [2, 1, 1.5], "rotate": [10, 20, 30]},
            {"type": "plane", "normal": [1, 2, 0.5], "offset": 0.2},
            {"type": "plane", "normal": [-1, 0.3, -0.4], "offset": 0.1}]}]})",
        R"({"type": "offset", "distance": -0.1, "children": [{"type": "intersection",
            "smooth": 0.3, "blend": "chamfer", "children": [
            {"type": "round_box", "size": [1.5, 1.5, 1.5], "radius": 0.2},
            {"type": "plane", "normal": [1, 1, 1], "offset": 0.1, "scale": [1, 3, 0.5]}]}]})",
        R"({"type": "union", "children": [
            {"type": "twist", "angle": 50, "rotate": [20, 0, 10], "scale": [1, 1.5, 0.7],
             "children": [{"type": "box", "size": [0.8, 2, 0.3], "translate": [0.2, 0, 0]}]},
            {"type": "bend", "angle": 40, "translate": [2, 0, 0], "children": [
                {"type": "box", "size": [2, 0.2, 0.3], "translate": [0.3, 0, 0]}]},
            {"type": "taper", "height": 1, "top_scale": 0.3, "translate": [-2, 0, 0],
             "children": [{"type": "box", "size": [1, 0.6, 1], "translate": [0, 0.3, 0]}]},
            {"type": "polar_repeat", "count": 3, "radius": 0.5, "translate": [0, 0, 2],
             "rotate": [0, 0, 30], "children": [{"type": "box", "size": [0.6, 0.3, 0.2]}]},
            {"type": "mirror", "axes": "xz", "smooth": 0.2, "translate": [0, 0, -2],
             "children": [{"type": "sphere", "radius": 0.4, "translate": [0.3, 0, 0.1]}]},
            {"type": "elongate", "length": [0.5, 0, 0.2], "translate": [0, 2, 0],
             "children": [{"type": "torus", "major_radius": 0.3, "minor_radius": 0.1}]}]})",
    };
    std::vector<EdgeCase> cases;
    for (const char* root : roots) {
        cases.push_back({parseRoot(root), tight[cases.size()]});
        cases.back().scene.file = "<edge case " + std::to_string(cases.size()) + ">";
    }
    return cases;
}

TEST(Eval, SolidBoundsHoldRandomTreesAndEdgeCases) {
    std::vector<Scene> scenes;
    for (EdgeCase& edge : edgeScenes())
        scenes.push_back(std::move(edge.scene));
    for (uint32_t seed = 1; seed <= 24; ++seed) {
        std::mt19937 rng(seed);
        const std::string root = randomTreeJson(rng, 3, {.scalesPerAxis = true, .planes = true});
        auto scene = parseScene(R"({"version": 1, "root": )" + root + "}", root);
        ASSERT_TRUE(scene) << scene.error().str();
        scenes.push_back(std::move(*scene));
    }
    for (const Scene& scene : scenes) {
        SCOPED_TRACE(scene.file);
        const Evaluator eval(scene);
        expectSolidWithin(eval, searchBox(eval), 40);
        if (eval.bounds().finite()) expectSolidWithin(eval, eval.bounds(), 40);
    }
}

TEST(Eval, SolidBoundsAreTight) {
    std::vector<Scene> scenes = {
        // Two boxes overlapping in a corner: the overlap, not the smaller box.
        makeScene(intersect({box(2, 2, 2), box(2, 2, 2).at(1, 1, 1)})),
        // The same, smooth, inside a union with a ball.
        makeScene(unite({intersect({box(2, 2, 2), box(2, 4, 2).at(1, 1, 1)}, 0.1f),
                         sphere(0.3f).at(0.5f, 0.5f, 0.5f)})),
        // A box that spans a rounded box across two axes cuts it along the third.
        makeScene(subtract({roundBox(1.6f, 0.6f, 1.0f, 0.08f), box(2, 0.4f, 2).at(0, 0.4f, 0)})),
        // A box cut by a plane across its diagonal, and a ball less a half-space.
        makeScene(intersect({box(2, 2, 2), plane(glm::normalize(glm::vec3(1, 1, 0)), -0.5f)})),
        makeScene(subtract({sphere(1), plane({0, -1, 0}, -0.3f).rotated(0, 0, 20)})),
    };
    for (Scene& scene : clippedScenes())
        scenes.push_back(std::move(scene));
    for (EdgeCase& edge : edgeScenes())
        if (edge.tight) scenes.push_back(std::move(edge.scene));
    for (const Scene& scene : scenes) {
        SCOPED_TRACE(scene.file);
        const Evaluator eval(scene);
        const Aabb& tight = eval.solidBounds();
        float spacing = 0.0f;
        const Aabb solid = sampledSolid(eval, tight, 96, spacing);
        for (int a = 0; a < 3; ++a) {
            const float size = solid.max[a] - solid.min[a];
            EXPECT_LE(tight.max[a] - tight.min[a], 1.05f * size + 2.0f * spacing) << "axis " << a;
        }
    }
}

// Offsets, shells and smooth blends over fields that are not distances are noted, with how far
// off they land: the offsets and shells too thin against their child to bake (field/bake.h);
// over distances, baked, and in the bundled scenes, nothing is.
TEST(Eval, FieldNotesNameWhatDependsOnDistancesThatAreNot) {
    const Scene scene = parseRoot(R"({"type": "union", "children": [
        {"type": "offset", "distance": 0.002, "accuracy": "exact", "children": [
            {"type": "twist", "angle": 90, "children": [{"type": "box", "size": [1, 2, 1]}]}]},
        {"type": "shell", "thickness": 0.002, "children": [
            {"type": "sphere", "radius": 0.5, "scale": [1, 2, 1]}]},
        {"type": "union", "smooth": 0.2, "children": [
            {"type": "ellipsoid", "radii": [0.5, 0.3, 0.4]}, {"type": "sphere", "radius": 0.3}]},
        {"type": "offset", "distance": -0.001, "children": [
            {"type": "intersection", "smooth": 0.1, "children": [
                {"type": "sphere", "radius": 0.3}, {"type": "box", "size": [0.5, 0.5, 0.5]}]}]},
        {"type": "offset", "distance": 0.2, "children": [
            {"type": "difference", "children": [
                {"type": "box", "size": [1, 1, 1]}, {"type": "sphere", "radius": 0.6}]}]}]})");
    const std::vector<FieldNote> notes = fieldNotes(scene, Evaluator(scene));
    ASSERT_EQ(notes.size(), 5u);
    EXPECT_EQ(notes[0].path, "root.children[0]");
    EXPECT_EQ(notes[0].message,
              "offset over a field that is not a distance (twist at root.children[0].children[0] "
              "divides its field by up to 2.08): the surface lies about 0.002 from the child's "
              "(divided by the field's gradient, to first order, not baked: at a quarter of the "
              "distance its field would exceed 32 MiB, or its child is unbounded or of more than "
              "256 nodes; 0.002 to 0.00416 without)");
    EXPECT_EQ(notes[1].message,
              "shell over a field that is not a distance (sphere at root.children[1].children[0], "
              "scaled unevenly: its field below the distance by up to 2): the skin is about 0.002 "
              "thick (divided by the field's gradient, to first order; \"accuracy\": \"exact\" "
              "bakes the child's distance; 0.002 to 0.004 without)");
    EXPECT_EQ(notes[2].message,
              "smooth union over a field that is not a distance (ellipsoid at "
              "root.children[2].children[0]: a bound, below the distance by up to 1.67): the "
              "blend reaches up to 0.333 instead of 0.2");
    EXPECT_EQ(notes[3].path, "root.children[3]");
    EXPECT_EQ(notes[3].message,
              "offset over a field that is not a distance (smooth blend at "
              "root.children[3].children[0]: no distance within 0.1 of its seam): the surface "
              "lies about 0.001 from the child's (divided by the field's gradient, to first "
              "order; \"accuracy\": \"exact\" bakes the child's distance; not 0.001 within the "
              "blend)");
    EXPECT_EQ(notes[4].path, "root");
    EXPECT_EQ(notes[4].message,
              "ambient occlusion and soft shadows over a field that is not a distance (twist at "
              "root.children[0].children[0] divides its field by up to 2.08): the shading can be "
              "darker where its values lie below the distance (down to 1/2.08 of it); --no-ao "
              "and --no-shadows leave them out");
    // Below a loss of 2 the shading shows nothing worth a note.
    const Scene gentle = parseRoot(
        R"({"type": "twist", "angle": 40, "children": [{"type": "box", "size": [1, 2, 1]}]})");
    EXPECT_TRUE(fieldNotes(gentle, Evaluator(gentle)).empty());
    const Scene baked =
        parseRoot(R"({"type": "offset", "distance": 0.3, "accuracy": "exact", "children": [
        {"type": "twist", "angle": 90, "children": [{"type": "box", "size": [1, 2, 1]}]}]})");
    EXPECT_NE(baked.nodes[0].words, nullptr);
    EXPECT_TRUE(fieldNotes(baked, Evaluator(baked)).empty());
    for (const Scene& bundled : bundledScenes())
        EXPECT_TRUE(fieldNotes(bundled, Evaluator(bundled)).empty()) << bundled.file;
}

// Skipping never changes a single bit of the result.
TEST(Eval, SkippingGivesIdenticalValues) {
    std::vector<Scene> scenes = bundledScenes();
    for (uint32_t seed = 20; seed < 40; ++seed)
        scenes.push_back(randomScene(seed, 60, 6, seed % 2 == 0));
    for (Scene& scene : stretchedScenes())
        scenes.push_back(std::move(scene));
    for (const Scene& scene : scenes) {
        Evaluator on(scene), off(scene);
        off.setBoundsSkipping(false);
        for (glm::vec3 p : randomPoints(7, 1000, reach(on))) {
            Sample a = on.sample(p), b = off.sample(p);
            ASSERT_EQ(a.distance, b.distance) << scene.file;
            ASSERT_EQ(a.color, b.color) << scene.file;
            ASSERT_EQ(on.distance(p), off.distance(p)) << scene.file;
            ASSERT_EQ(on.distance(p), a.distance) << "distance() and sample() disagree";
        }
    }
}

TEST(Eval, SkippingHappens) {
    // Poison the far operand after its bounds were computed: evaluated, it would make the result
    // NaN; skipped, it cannot.
    Scene scene = makeScene(unite({sphere(1), sphere(1).at(100, 0, 0)}));
    Evaluator eval(scene);
    const_cast<FlatNode&>(eval.nodes()[2]).params[0] = NAN;
    EXPECT_FLOAT_EQ(eval.distance({0, 2, 0}), 1.0f);
    EXPECT_FLOAT_EQ(eval.sample({0, 2, 0}).distance, 1.0f);
    EXPECT_TRUE(std::isnan(eval.distance({100, 2, 0})));
    eval.setBoundsSkipping(false);
    EXPECT_TRUE(std::isnan(eval.distance({0, 2, 0})));
}

TEST(Eval, DeepTreesNeedNoRecursion) {
    // 20,000 nested unions (far beyond the parser's depth limit): flattening and evaluation use
    // explicit stacks.
    const int depth = 20000;
    // Pre-order: each union, then its sphere, then the next union.
    Scene ordered;
    for (int i = 0; i < depth; ++i) {
        Node u;
        u.kind = NodeKind::Union;
        u.children = {uint32_t(2 * i + 1), uint32_t(2 * i + 2)};
        ordered.nodes.push_back(u);
        Node s;
        s.kind = NodeKind::Sphere;
        s.params[0] = 0.5f;
        s.transform.translate = {float(i), 0, 0};
        ordered.nodes.push_back(s);
    }
    Node last;
    last.kind = NodeKind::Sphere;
    last.params[0] = 0.5f;
    last.transform.translate = {float(depth), 0, 0};
    ordered.nodes.push_back(last);
    Evaluator eval(ordered);
    EXPECT_FLOAT_EQ(eval.distance({0, 0, 0}), -0.5f);
    EXPECT_FLOAT_EQ(eval.distance({float(depth), 2, 0}), 1.5f);
    eval.setBoundsSkipping(false);
    EXPECT_FLOAT_EQ(eval.distance({float(depth), 2, 0}), 1.5f);
}

TEST(Eval, FrameCameraSeesTheWholeScene) {
    std::vector<Scene> scenes = {primitiveGallery(), randomScene(3, 30)};
    for (Scene& scene : clippedScenes())
        scenes.push_back(std::move(scene));
    for (const Scene& scene : scenes) {
        SCOPED_TRACE(scene.file);
        Evaluator eval(scene);
        for (float aspect : {0.5f, 1.0f, 16.0f / 9.0f}) {
            Camera cam = frameCamera(eval, aspect, 40.0f);
            glm::vec3 forward = glm::normalize(cam.target - cam.eye);
            glm::vec3 right = glm::normalize(glm::cross(forward, cam.up));
            glm::vec3 up = glm::cross(right, forward);
            EXPECT_GT(cam.eye.z - cam.target.z, 0.0f) << "looks from the front";
            EXPECT_GT(cam.eye.y - cam.target.y, 0.0f) << "looks from above";
            EXPECT_GT(cam.eye.x - cam.target.x, 0.0f) << "looks from the right";
            float tanV = std::tan(glm::radians(20.0f)), tanH = tanV * aspect;
            // Every corner of the box the solid lies in is in view, and some corner is near
            // the view's edge (the solid fills the picture).
            const Aabb b = eval.finiteBounds();
            float fill = 0.0f;
            for (int c = 0; c < 8; ++c) {
                glm::vec3 corner(c & 1 ? b.max.x : b.min.x, c & 2 ? b.max.y : b.min.y,
                                 c & 4 ? b.max.z : b.min.z);
                glm::vec3 v = corner - cam.eye;
                float z = glm::dot(v, forward);
                ASSERT_GT(z, 0.0f);
                EXPECT_LE(std::abs(glm::dot(v, right)) / z, tanH);
                EXPECT_LE(std::abs(glm::dot(v, up)) / z, tanV);
                fill = std::max({fill, std::abs(glm::dot(v, right)) / z / tanH,
                                 std::abs(glm::dot(v, up)) / z / tanV});
            }
            EXPECT_GT(fill, 0.85f);
        }
    }
    // Nothing finite: a sensible default.
    Camera cam = frameCamera(Evaluator(makeScene(plane({0, 1, 0}, 0))), 1.0f);
    EXPECT_TRUE(std::isfinite(cam.eye.x + cam.eye.y + cam.eye.z));
    EXPECT_GT(glm::length(cam.eye - cam.target), 0.0f);
}

// A flat part is seen at a slant, from its broad side: a plate lying down, standing across the
// view or standing along it, and a woven mat, are seen at least 30 degrees off their plane and
// at least 25 degrees off their normal (a three-quarter view).
TEST(Eval, FrameCameraSeesFlatPartsAtASlant) {
    struct Flat {
        Scene scene;
        glm::vec3 normal;
    };
    std::vector<Flat> flats = {
        {makeScene(box(4, 0.1f, 3)), {0, 1, 0}},
        {makeScene(box(4, 3, 0.1f)), {0, 0, 1}},
        {makeScene(box(0.1f, 3, 4)), {1, 0, 0}},
        {clippedScenes()[1], {0, 1, 0}},
    };
    for (const Flat& flat : flats) {
        SCOPED_TRACE(flat.scene.file);
        const Camera cam = frameCamera(Evaluator(flat.scene), 4.0f / 3.0f);
        const float along = std::abs(glm::dot(glm::normalize(cam.target - cam.eye), flat.normal));
        EXPECT_GE(along, std::sin(glm::radians(30.0f)));
        EXPECT_LE(along, std::cos(glm::radians(25.0f)));
    }
}

TEST(Eval, PackedNodesMirrorTheEvaluator) {
    Scene scene = primitiveGallery();
    Evaluator eval(scene);
    std::vector<detail::GpuNode> packed = detail::packNodes(eval);
    ASSERT_EQ(packed.size(), eval.nodes().size());
    for (glm::vec3 p : randomPoints(4, 200, 3.0f)) {
        for (size_t i = 0; i < packed.size(); ++i) {
            const FlatNode& n = eval.nodes()[i];
            const detail::GpuNode& g = packed[i];
            glm::vec4 q(p, 1);
            glm::vec3 local(glm::dot(g.row0, q), glm::dot(g.row1, q), glm::dot(g.row2, q));
            EXPECT_NEAR(glm::length(local - (n.toLocal * p + n.offset)), 0, 1e-5f);
        }
    }
    for (size_t i = 0; i < packed.size(); ++i) {
        const FlatNode& n = eval.nodes()[i];
        EXPECT_EQ(packed[i].color, glm::vec4(n.color, n.scale));
        EXPECT_EQ(packed[i].bmin.w, n.smooth);
        EXPECT_EQ(packed[i].p0.x, n.params[0]);
        if (!n.bounds.finite()) {
            EXPECT_EQ(packed[i].bmin.x, -float(SDFCSG_HUGE));
            EXPECT_EQ(packed[i].bmax.y, float(SDFCSG_HUGE));
        }
    }
}

} // namespace
} // namespace sdfcsg
