// The value and domain operations on the CPU: each against the explicit construction it stands
// for (a repeat against the union of its copies, an elongated sphere against a capsule, ...),
// the stretching ones as 1-Lipschitz fields with the right sign, and the pruned tapes against
// the tree walk.
#include "field/prune.h"

#include "scene_build_util.h"

#include <sdfcsg/eval.h>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <cmath>
#include <random>
#include <string>

namespace sdfcsg {
namespace {

using test::parseRoot;
using test::randomPoints;

// `field` and `explicit` agree within 1e-5 wherever the explicit one is within `near` of the
// surface, and the field is never above it in magnitude nor of another sign elsewhere.
void expectSameSolid(const std::string& field, const std::string& reference, float reach,
                     float near) {
    SCOPED_TRACE(field);
    Evaluator a(parseRoot(field)), b(parseRoot(reference));
    int close = 0;
    for (glm::vec3 p : randomPoints(7, 6000, reach)) {
        const float fa = a.distance(p), fb = b.distance(p);
        if (std::abs(fb) < near) {
            ++close;
            ASSERT_NEAR(fa, fb, 1e-5f * (1.0f + glm::length(p))) << p.x << " " << p.y << " " << p.z;
        } else {
            ASSERT_EQ(fa < 0, fb < 0) << p.x << " " << p.y << " " << p.z;
            ASSERT_LE(std::abs(fa), std::abs(fb) + 1e-5f) << p.x << " " << p.y << " " << p.z;
        }
    }
    EXPECT_GT(close, 100);
}

const std::string kPart = R"({"type": "round_box", "size": [0.5, 0.3, 0.4], "radius": 0.05,
    "rotate": [10, 20, 30], "translate": [0.05, 0.02, -0.03]})";

std::string copyAt(float x, float y, float z) {
    return R"({"type": "union", "translate": [)" + std::to_string(x) + ", " + std::to_string(y) +
           ", " + std::to_string(z) + R"(], "children": [)" + kPart + "]}";
}

TEST(Operations, RepeatIsTheUnionOfItsCopies) {
    std::string copies;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 2; ++k)
            copies += (copies.empty() ? "" : ", ") + copyAt((i - 1) * 0.7f, 0, (k - 0.5f) * 0.6f);
    expectSameSolid(R"({"type": "repeat", "count": [3, 1, 2], "spacing": [0.7, 1, 0.6],
        "children": [)" +
                        kPart + "]}",
                    R"({"type": "union", "children": [)" + copies + "]}", 2.5f, 0.3f);
}

// Copies that overlap their neighbours: the window of candidates widens.
TEST(Operations, RepeatOfOverlappingCopiesIsTheirUnion) {
    std::string copies;
    for (int i = 0; i < 9; ++i)
        copies += (copies.empty() ? "" : ", ") + copyAt((i - 4) * 0.2f, 0, 0);
    expectSameSolid(R"({"type": "repeat", "count": [9, 1, 1], "spacing": [0.2, 1, 1],
        "children": [)" +
                        kPart + "]}",
                    R"({"type": "union", "children": [)" + copies + "]}", 1.2f, 0.1f);
}

TEST(Operations, PolarRepeatIsTheUnionOfItsTurnedCopies) {
    std::string copies;
    for (int i = 0; i < 9; ++i)
        copies +=
            std::string(copies.empty() ? "" : ", ") + R"({"type": "union", "rotate": [0, )" +
            std::to_string(i * 40.0f) +
            R"(, 0], "children": [{"type": "union", "translate": [1.1, 0, 0], "children": [)" +
            kPart + "]}]}";
    expectSameSolid(R"({"type": "polar_repeat", "count": 9, "radius": 1.1, "children": [)" + kPart +
                        "]}",
                    R"({"type": "union", "children": [)" + copies + "]}", 2.5f, 0.3f);
}

// Copies that reach past their sectors leave some out of the candidates; the bound that stands
// for those grows away from them along the axis too, so that a shell of the repetition has no
// sheet along the axis (it had one, endless, where the bound was the distance from the axis).
TEST(Operations, ShellOfAPolarRepeatHasNoSurfaceAlongTheAxis) {
    const Scene scene = parseRoot(R"({"type": "shell", "thickness": 0.1, "children": [
        {"type": "polar_repeat", "count": 7, "radius": 1.2, "children": [
            {"type": "sphere", "radius": 0.8}]}]})");
    const Evaluator e(scene);
    for (float y = -20.0f; y <= 20.0f; y += 0.25f) {
        for (float r : {0.0f, 0.05f, 0.2f}) {
            const glm::vec3 p(r, y, 0.5f * r);
            ASSERT_GT(e.distance(p), 0.0f) << "at " << p.x << ", " << p.y << ", " << p.z;
        }
        // On the axis, every copy's ball is equally near, and the shell's surface half its
        // thickness nearer: the value is no more than that.
        const float onAxis = std::sqrt(1.44f + y * y) - 0.8f - 0.05f;
        EXPECT_LE(e.distance(glm::vec3(0.0f, y, 0.0f)), onAxis + 1e-5f) << "at height " << y;
    }
}

// As the node table describes it: bent by 90 degrees per unit, a bar's point at x = 1 lands on
// (0.59, 0.80), 1 from the axis, and not where an arc of radius 2/pi would take it.
TEST(Operations, BendCurlsABarAsDocumented) {
    const Scene scene = parseRoot(R"({"type": "bend", "angle": 90, "children": [
        {"type": "capsule", "a": [-1, 0, 0], "b": [1, 0, 0], "radius": 0.02}]})");
    const Evaluator e(scene);
    EXPECT_LT(e.distance(glm::vec3(0.5946f, 0.8040f, 0.0f)), 0.0f);
    EXPECT_LT(e.distance(glm::vec3(-0.5946f, 0.8040f, 0.0f)), 0.0f);
    const float r = 2.0f / 3.14159265f;
    EXPECT_GT(e.distance(glm::vec3(r * std::sin(1.0f / r), r * (1.0f - std::cos(1.0f / r)), 0.0f)),
              0.01f);
}

// The eases of bend_linear and the transitions, their formulas and steepest slopes.
const std::string eases[] = {"linear", "smoothstep", "smootherstep"};
float ease(int style, float t) {
    return style == 0 ? t : style == 1 ? t * t * (3 - 2 * t) : t * t * t * (t * (6 * t - 15) + 10);
}
const float slopes[] = {1.0f, 1.5f, 1.875f};

// bend_linear against its formula: the child at p less offset ease(t), t the clamped position of
// p's projection from p0 to p1, divided by 1 + |offset| ease' / |p1 - p0| and floored at the
// distance to its bounds, the child's box swept by the offset. Its surface lies in those bounds.
TEST(Operations, BendLinearIsItsFormula) {
    const glm::vec3 p0(-0.5f, -0.1f, 0.0f), p1(0.7f, 0.2f, 0.1f), offset(0.1f, 0.5f, -0.2f);
    const glm::vec3 half(0.8f, 0.15f, 0.2f); // the box's
    const Aabb swept{glm::min(-half, offset - half), glm::max(half, offset + half)};
    for (int style = 0; style < 3; ++style) {
        SCOPED_TRACE(eases[style]);
        const Evaluator e(parseRoot(R"({"type": "bend_linear", "p0": [-0.5, -0.1, 0],
            "p1": [0.7, 0.2, 0.1], "offset": [0.1, 0.5, -0.2], "ease": ")" +
                                    eases[style] + R"(", "children": [
            {"type": "box", "size": [1.6, 0.3, 0.4]}]})"));
        for (int k = 0; k < 3; ++k) { // rounded outwards
            EXPECT_LE(e.bounds().min[k], swept.min[k]);
            EXPECT_GE(e.bounds().max[k], swept.max[k]);
            EXPECT_NEAR(e.bounds().min[k], swept.min[k], 1e-4f);
            EXPECT_NEAR(e.bounds().max[k], swept.max[k], 1e-4f);
        }
        const glm::vec3 axis = p1 - p0;
        const float lipschitz = 1.0f + glm::length(offset) * slopes[style] / glm::length(axis);
        int inside = 0;
        for (glm::vec3 p : randomPoints(17, 4000, 1.2f)) {
            const float t = glm::clamp(glm::dot(p - p0, axis) / glm::dot(axis, axis), 0.0f, 1.0f);
            const glm::vec3 q = p - offset * ease(style, t);
            const float box = Aabb{-half, half}.signedDistance(q);
            const float want = std::max(box / lipschitz, e.bounds().signedDistance(p));
            ASSERT_NEAR(e.distance(p), want, 1e-5f) << p.x << " " << p.y << " " << p.z;
            if (e.distance(p) <= 0.0f) {
                ++inside;
                ASSERT_LE(e.bounds().signedDistance(p), 0.0f) << p.x << " " << p.y << " " << p.z;
            }
        }
        EXPECT_GT(inside, 50);
    }
}

// Transition_linear and transition_radial against their formula: the mix of a sphere's value a and
// a box's b by the eased weight w, b - a clamped to +-D (D twice the diagonal of the children's
// bounds U), divided by 1 + D W (W the weight's steepest slope) and floored at U's distance; of
// the mix's sign wherever the mix is not near 0, so that the surface is the mix's.
TEST(Operations, TransitionsAreTheirFormula) {
    const std::string children = R"("children": [
        {"type": "sphere", "radius": 0.5, "translate": [-0.3, 0, 0]},
        {"type": "box", "size": [0.8, 0.6, 0.7], "translate": [0.3, 0.1, 0]}]})";
    const Aabb u{glm::vec3(-0.8f, -0.5f, -0.5f), glm::vec3(0.7f, 0.5f, 0.5f)};
    const float reach = 2.0f * glm::length(u.max - u.min);
    const glm::vec3 p0(-0.4f, -0.1f, 0.0f), p1(0.5f, 0.2f, 0.1f), centre(0.1f, 0.0f, 0.05f);
    const float r0 = 0.15f, r1 = 0.6f;
    for (bool radial : {false, true})
        for (int style = 0; style < 3; ++style) {
            const std::string json =
                radial ? R"({"type": "transition_radial", "center": [0.1, 0, 0.05], "r0": 0.15,
                    "r1": 0.6, "ease": ")" +
                             eases[style] + "\", " + children
                       : R"({"type": "transition_linear", "p0": [-0.4, -0.1, 0],
                    "p1": [0.5, 0.2, 0.1], "ease": ")" +
                             eases[style] + "\", " + children;
            SCOPED_TRACE(json);
            const Evaluator e(parseRoot(json));
            for (int k = 0; k < 3; ++k) { // the children's boxes, rounded outwards
                EXPECT_NEAR(e.bounds().min[k], u.min[k], 1e-4f);
                EXPECT_NEAR(e.bounds().max[k], u.max[k], 1e-4f);
            }
            const glm::vec3 axis = p1 - p0;
            const float slope = slopes[style] / (radial ? r1 - r0 : glm::length(axis)); // W
            int inside = 0, between = 0;
            for (glm::vec3 p : randomPoints(23, 4000, 1.0f)) {
                const float t = radial ? (glm::length(p - centre) - r0) / (r1 - r0)
                                       : glm::dot(p - p0, axis) / glm::dot(axis, axis);
                const float w = ease(style, glm::clamp(t, 0.0f, 1.0f));
                const float a = glm::length(p - glm::vec3(-0.3f, 0, 0)) - 0.5f;
                const float b = Aabb{glm::vec3(-0.1f, -0.2f, -0.35f), glm::vec3(0.7f, 0.4f, 0.35f)}
                                    .signedDistance(p);
                const float mix = (1 - w) * a + w * b;
                const float want =
                    std::max((a + w * glm::clamp(b - a, -reach, reach)) / (1.0f + reach * slope),
                             e.nodes()[0].bounds.signedDistance(p)); // U rounded outwards
                const float got = e.distance(p);
                ASSERT_NEAR(got, want, 2e-5f) << p.x << " " << p.y << " " << p.z;
                if (std::abs(mix) > 1e-4f) {
                    ASSERT_EQ(got < 0, mix < 0) << p.x << " " << p.y << " " << p.z;
                }
                inside += got < 0;
                between += got < 0 && w > 0.05f && w < 0.95f;
            }
            EXPECT_GT(inside, 60);
            EXPECT_GT(between, 20);
        }
}

// Transitions, turned, scaled per axis and holding other operations: 1-Lipschitz (sampled), their
// colour the children's mixed by the weight.
TEST(Operations, TransitionsStayOneLipschitz) {
    for (const char* op :
         {R"("type": "transition_linear", "p0": [0, -0.4, 0], "p1": [0, 0.4, 0], "ease": "linear")",
          R"("type": "transition_linear", "p0": [-0.1, -0.2, 0], "p1": [0.1, 0.1, 0.05])",
          R"("type": "transition_radial", "r0": 0.1, "r1": 0.5, "ease": "smootherstep")",
          R"("type": "transition_radial", "center": [0.2, 0, 0], "r0": 0.6, "r1": 0.2)"}) {
        SCOPED_TRACE(op);
        Evaluator e(parseRoot(std::string("{") + op +
                              R"(, "rotate": [5, 10, 0], "scale": [1, 1.4, 0.8], "children": [
            {"type": "torus", "major_radius": 0.4, "minor_radius": 0.1, "color": [1, 0, 0]},
            {"type": "union", "smooth": 0.1, "children": [
                {"type": "box", "size": [0.4, 1.2, 0.3], "translate": [0.1, 0, 0]},
                {"type": "sphere", "radius": 0.3, "translate": [0, 0.5, 0]}],
             "color": [0, 0, 1]}]})"));
        std::mt19937 rng(3);
        std::uniform_real_distribution<float> u(-1.0f, 1.0f);
        int inside = 0, mixed = 0;
        for (glm::vec3 p : randomPoints(11, 4000, 1.2f)) {
            const glm::vec3 step = 1e-3f * glm::normalize(glm::vec3(u(rng), u(rng), u(rng)));
            const float slope = std::abs(e.distance(p + step) - e.distance(p)) / 1e-3f;
            ASSERT_LE(slope, 1.0f + 2e-2f) << p.x << " " << p.y << " " << p.z;
            inside += e.distance(p) < 0;
            const Sample s = e.sample(p);
            ASSERT_NEAR(s.color.r + s.color.b, 1.0f, 1e-5f);
            ASSERT_EQ(s.color.g, 0.0f);
            mixed += s.color.r > 0.01f && s.color.b > 0.01f;
        }
        EXPECT_GT(inside, 20);
        EXPECT_GT(mixed, 100);
    }
}

// Spacing means nothing along an axis of one copy, so 0 is accepted there: the same field.
TEST(Operations, RepeatTakesSpacingZeroAlongAnAxisOfOneCopy) {
    const Evaluator zero(parseRoot(R"({"type": "repeat", "count": [4, 1, 1],
        "spacing": [0.6, 0, 0], "children": [)" +
                                   kPart + "]}"));
    const Evaluator one(parseRoot(R"({"type": "repeat", "count": [4, 1, 1],
        "spacing": [0.6, 1, 1], "children": [)" +
                                  kPart + "]}"));
    for (glm::vec3 p : randomPoints(3, 2000, 2.5f))
        ASSERT_EQ(zero.distance(p), one.distance(p)) << p.x << " " << p.y << " " << p.z;
}

TEST(Operations, MirrorOfAHalfIsItAndItsImage) {
    const std::string ball = R"({"type": "sphere", "radius": 0.3, "translate": [0.5, 0.2, 0]})";
    const std::string image = R"({"type": "sphere", "radius": 0.3, "translate": [-0.5, 0.2, 0]})";
    expectSameSolid(R"({"type": "mirror", "axes": "x", "children": [)" + ball + "]}",
                    R"({"type": "union", "children": [)" + ball + ", " + image + "]}", 1.2f, 0.2f);
}

TEST(Operations, ElongatedSphereIsACapsule) {
    expectSameSolid(
        R"({"type": "elongate", "length": [0, 0.8, 0], "children": [{"type": "sphere", "radius": 0.3}]})",
        R"({"type": "capsule", "a": [0, -0.4, 0], "b": [0, 0.4, 0], "radius": 0.3})", 2.0f, 0.25f);
}

TEST(Operations, ShellAndOffsetOfASphere) {
    expectSameSolid(
        R"({"type": "offset", "distance": 0.1, "children": [{"type": "sphere", "radius": 0.3}]})",
        R"({"type": "sphere", "radius": 0.4})", 2.0f, 10.0f);
    Evaluator shell(parseRoot(
        R"({"type": "shell", "thickness": 0.1, "scale": 2, "children": [{"type": "sphere", "radius": 0.5}]})"));
    EXPECT_NEAR(shell.distance({0, 0, 0}), 0.9f, 1e-6f);    // |-1| - 0.1
    EXPECT_NEAR(shell.distance({1.5f, 0, 0}), 0.4f, 1e-6f); // |0.5| - 0.1
    EXPECT_NEAR(shell.distance({0, 1.05f, 0}), -0.05f, 1e-6f);
}

// Twist, bend, taper and bend_linear: 1-Lipschitz (sampled), and negative exactly where the child
// is at the warped point.
TEST(Operations, StretchingOperationsStayOneLipschitz) {
    for (
        const char* op :
        {R"("type": "twist", "angle": 120)", R"("type": "bend", "angle": 60)",
         R"("type": "taper", "height": 1, "top_scale": 0.3)",
         R"("type": "bend_linear", "p0": [0, -0.3, 0], "p1": [0, 0.3, 0], "offset": [0.6, 0, 0.2],
             "ease": "linear")",
         R"("type": "bend_linear", "p0": [0, -0.3, 0], "p1": [0.1, 0.3, 0], "offset": [0.6, 0, 0.2])",
         R"("type": "bend_linear", "p0": [0, -0.3, 0], "p1": [0, 0.3, 0.1],
             "offset": [0.6, 0.1, 0.2], "ease": "smootherstep")"}) {
        SCOPED_TRACE(op);
        Evaluator e(parseRoot(std::string("{") + op + R"(, "rotate": [5, 10, 0], "children": [
            {"type": "box", "size": [0.4, 1.2, 0.3], "translate": [0.1, 0, 0]}]})"));
        std::mt19937 rng(3);
        std::uniform_real_distribution<float> u(-1.0f, 1.0f);
        int inside = 0;
        for (glm::vec3 p : randomPoints(11, 4000, 0.9f)) {
            const glm::vec3 step = 1e-3f * glm::normalize(glm::vec3(u(rng), u(rng), u(rng)));
            const float slope = std::abs(e.distance(p + step) - e.distance(p)) / 1e-3f;
            ASSERT_LE(slope, 1.0f + 2e-2f) << p.x << " " << p.y << " " << p.z;
            inside += e.distance(p) < 0;
        }
        EXPECT_GT(inside, 20);
    }
}

// A scale per axis: the box it makes, with the field scaled by the smallest factor, so never
// above the exact distance and at least smallest/largest of it; the bounds hug the box.
TEST(Operations, NonUniformScaleIsAConservativeField) {
    const Scene scaled = parseRoot(R"({"type": "union", "rotate": [0, 30, 0], "children": [
        {"type": "box", "size": [1, 1, 1], "scale": [2, 1, 0.5]}]})");
    Evaluator a(scaled);
    Evaluator b(parseRoot(R"({"type": "union", "rotate": [0, 30, 0], "children": [
        {"type": "box", "size": [2, 1, 0.5]}]})"));
    for (glm::vec3 p : randomPoints(5, 4000, 2.0f)) {
        const float fa = a.distance(p), fb = b.distance(p);
        ASSERT_EQ(fa < 0, fb < 0) << p.x << " " << p.y << " " << p.z;
        ASSERT_LE(std::abs(fa), std::abs(fb) + 1e-5f);
        ASSERT_GE(std::abs(fa), 0.25f * std::abs(fb) - 1e-5f);
    }
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(a.bounds().min[k], b.bounds().min[k], 1e-4f);
        EXPECT_NEAR(a.bounds().max[k], b.bounds().max[k], 1e-4f);
    }
    // Written back as the vector it was read as.
    EXPECT_NE(toJson(scaled).find(R"("scale": [2, 1, 0.5])"), std::string::npos) << toJson(scaled);
}

// The pruned tapes give the tree walk's values near the surface and a bound of the same sign,
// never larger, elsewhere, with every operation nested in others.
TEST(Operations, PrunedTapesAgreeWithTheTree) {
    Scene scene = parseRoot(R"({"type": "union", "smooth": 0.05, "children": [
        {"type": "repeat", "count": [4, 1, 3], "spacing": [0.8, 1, 0.8], "children": [
            {"type": "twist", "angle": 90, "children": [
                {"type": "shell", "thickness": 0.05, "children": [
                    {"type": "box", "size": [0.3, 0.8, 0.3]}]}]}]},
        {"type": "polar_repeat", "count": 10, "radius": 2.2, "children": [
            {"type": "mirror", "axes": "z", "children": [
                {"type": "offset", "distance": 0.02, "children": [
                    {"type": "capsule", "a": [0, 0, 0.05], "b": [0.2, 0.3, 0.1], "radius": 0.05}]}]}]},
        {"type": "bend_linear", "p0": [0, 0, -0.8], "p1": [0, 0, 0.8], "offset": [0.4, 0.3, 0],
         "translate": [0, 1.6, 0], "children": [
            {"type": "cylinder", "radius": 0.1, "height": 2.4, "rotate": [90, 0, 0]}]},
        {"type": "transition_linear", "p0": [-0.3, 0, 0], "p1": [0.3, 0, 0],
         "translate": [-1.8, 1.4, 0], "children": [
            {"type": "union", "smooth": 0.05, "children": [
                {"type": "sphere", "radius": 0.2, "translate": [-0.4, 0, 0]},
                {"type": "sphere", "radius": 0.2, "translate": [0.4, 0, 0]},
                {"type": "box", "size": [0.1, 0.6, 0.1]}]},
            {"type": "torus", "major_radius": 0.4, "minor_radius": 0.1, "rotate": [90, 0, 0]}]},
        {"type": "transition_radial", "r0": 0.1, "r1": 0.4, "ease": "linear",
         "translate": [1.8, 1.4, 0], "children": [
            {"type": "box", "size": [0.6, 0.6, 0.6]},
            {"type": "difference", "children": [
                {"type": "sphere", "radius": 0.45},
                {"type": "cylinder", "radius": 0.15, "height": 1}]}]},
        {"type": "bend", "angle": 20, "translate": [0, -1, 0], "children": [
            {"type": "taper", "height": 0.4, "top_scale": 0.5, "children": [
                {"type": "elongate", "length": [3, 0, 0], "children": [
                    {"type": "sphere", "radius": 0.15}]}]}]}]})");
    Evaluator e(scene);
    const detail::PrunedField field = detail::pruneField(e);
    int near = 0;
    for (glm::vec3 p : randomPoints(5, 20000, 3.0f)) {
        const float full = e.distance(p), pruned = field.distance(e.nodes(), p);
        if (std::abs(full) < field.cell) {
            ++near;
            ASSERT_NEAR(pruned, full, 1e-5f) << p.x << " " << p.y << " " << p.z;
        } else {
            ASSERT_EQ(pruned < 0, full < 0) << p.x << " " << p.y << " " << p.z;
            ASSERT_LE(std::abs(pruned), std::abs(full) + 1e-5f) << p.x << " " << p.y << " " << p.z;
        }
    }
    EXPECT_GT(near, 50);
}

} // namespace
} // namespace sdfcsg
