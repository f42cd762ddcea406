// Offsets and shells over fields that are not distances (twist, bend, taper, a scale per axis, a
// smooth union), against a dense numerical distance to their child's surface: the child's
// surface found on a fine grid (every crossed edge bisected), and the offset's surface on a
// coarser one, each of its points measured to the nearest of the child's, and where that could
// decide the least or greatest, refined: the least radius of a sphere about the point that
// crosses the child's surface (a cloud's nearest point lies up to s^2 / 2d too far for points s
// apart, and further at sharp edges). Where the child's distance is baked (field/bake.h), the
// surface lies within 2% of the distance asked for; where a node cannot be baked, the division
// by the gradient is first order, and strays where the stretch changes within the offset's
// distance (docs/vocabulary.md#lipschitz-bounds).
// Its cases take minutes (a quarter of an hour under the sanitizers): ctest starts it first.
// ctest cost 100
#include "scene_build_util.h"

#include <sdfcsg/eval.h>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <unordered_map>
#include <vector>

namespace sdfcsg {
namespace {

using test::parseRoot;

// Points on the zero set of `field` inside `box`: every edge of a grid of spacing `step` whose
// ends differ in sign, bisected.
template <class Field>
std::vector<glm::vec3> surfacePoints(const Field& field, const Aabb& box, float step) {
    const glm::ivec3 n = glm::ivec3(glm::ceil((box.max - box.min) / step)) + 1;
    std::vector<float> values(size_t(n.x) * n.y * n.z);
    const auto at = [&](int x, int y, int z) { return box.min + step * glm::vec3(x, y, z); };
    const auto index = [&](int x, int y, int z) { return (size_t(z) * n.y + y) * n.x + x; };
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x)
                values[index(x, y, z)] = field(at(x, y, z));
    std::vector<glm::vec3> points;
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x)
                for (int a = 0; a < 3; ++a) {
                    glm::ivec3 e(x, y, z);
                    e[a] += 1;
                    if (e[a] >= n[a]) continue;
                    const float va = values[index(x, y, z)], vb = values[index(e.x, e.y, e.z)];
                    if ((va < 0) == (vb < 0)) continue;
                    glm::vec3 lo = at(x, y, z), hi = at(e.x, e.y, e.z);
                    for (int i = 0; i < 24; ++i) {
                        const glm::vec3 mid = 0.5f * (lo + hi);
                        ((field(mid) < 0) == (va < 0) ? lo : hi) = mid;
                    }
                    points.push_back(0.5f * (lo + hi));
                }
    return points;
}

// The distance to the nearest of a cloud of points, through a grid of buckets.
class Cloud {
  public:
    Cloud(const std::vector<glm::vec3>& points, float bucket) : size_(bucket) {
        for (const glm::vec3& p : points)
            buckets_[key(cell(p))].push_back(p);
    }
    // The distance to the nearest point, and that point in `nearest`.
    float distance(glm::vec3 q, glm::vec3* nearest = nullptr) const {
        float best = INFINITY;
        const glm::ivec3 c = cell(q);
        for (int r = 0; r < 64; ++r) { // rings of buckets until none nearer can remain
            if (float(r - 1) * size_ > best) break;
            for (int z = -r; z <= r; ++z)
                for (int y = -r; y <= r; ++y)
                    for (int x = -r; x <= r; ++x) {
                        if (std::max({std::abs(x), std::abs(y), std::abs(z)}) != r) continue;
                        const auto it = buckets_.find(key(c + glm::ivec3(x, y, z)));
                        if (it == buckets_.end()) continue;
                        for (const glm::vec3& p : it->second)
                            if (const float d = glm::length(p - q); d < best) {
                                best = d;
                                if (nearest) *nearest = p;
                            }
                    }
        }
        return best;
    }

  private:
    glm::ivec3 cell(glm::vec3 p) const { return glm::ivec3(glm::floor(p / size_)); }
    static int64_t key(glm::ivec3 c) {
        return (int64_t(c.x + 4096) << 26) | (int64_t(c.y + 4096) << 13) | int64_t(c.z + 4096);
    }
    float size_;
    std::unordered_map<int64_t, std::vector<glm::vec3>> buckets_;
};

struct Case {
    std::string child; // the child's JSON
    const char* op;    // "offset" or "shell"
    float amount;      // the offset's distance, the shell's thickness
};

// The least radius about q, within `lo` to `hi`, of a sphere that crosses the zero set of `field`
// (takes the sign opposite q's) in a cone of directions about `axis`: the distance from q to the
// surface where its nearest point lies within the cone, bisected to a ten-thousandth.
template <class Field>
float sphereDistance(const Field& field, glm::vec3 q, glm::vec3 axis, float lo, float hi) {
    const bool inside = field(q) < 0.0f;
    const float cone = std::min(1.0f, 0.05f / hi); // the nearest lies within ~0.02 of `axis`'s
    constexpr int kDirections = 400;
    // Whether the sphere crosses the surface: in a spiral of directions over the cap, then, as
    // a sharp tip may poke through between them, over a cap a tenth as wide about the direction
    // where the field came nearest to crossing.
    const auto crossesAbout = [&](float radius, glm::vec3 w, float angle, glm::vec3* nearest) {
        const glm::vec3 a1 = glm::normalize(
            glm::cross(w, std::abs(w.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0)));
        const glm::vec3 a2 = glm::cross(w, a1);
        float least = INFINITY;
        for (int k = 0; k < kDirections; ++k) { // a Fibonacci spiral over the cap
            const float c = 1.0f - (1.0f - std::cos(angle)) * (float(k) + 0.5f) / kDirections;
            const float s = std::sqrt(std::max(0.0f, 1.0f - c * c)), a = 2.3999632f * float(k);
            const glm::vec3 d = c * w + s * (std::cos(a) * a1 + std::sin(a) * a2);
            const float f = field(q + radius * d);
            if ((f < 0.0f) != inside) return true;
            if (inside ? -f < least : f < least) least = inside ? -f : f, *nearest = d;
        }
        return false;
    };
    // Then, for a tip thinner still (a tapered box's corner), descent on the sphere from the
    // nearest direction along the field's gradient, tangent to the sphere.
    const float side = inside ? -1.0f : 1.0f;
    const auto descends = [&](float radius, glm::vec3 d) {
        const float e = 1e-4f;
        float step = 0.05f;
        float f = side * field(q + radius * d);
        for (int i = 0; i < 40 && f >= 0.0f && step > 1e-5f; ++i) {
            const glm::vec3 x = q + radius * d;
            glm::vec3 g(field(x + glm::vec3(e, 0, 0)) - field(x - glm::vec3(e, 0, 0)),
                        field(x + glm::vec3(0, e, 0)) - field(x - glm::vec3(0, e, 0)),
                        field(x + glm::vec3(0, 0, e)) - field(x - glm::vec3(0, 0, e)));
            g *= side / (2.0f * e);
            const glm::vec3 tangent = g - glm::dot(g, d) * d;
            if (!(glm::length(tangent) > 1e-6f)) break;
            const glm::vec3 next = glm::normalize(d - step * glm::normalize(tangent));
            const float fn = side * field(q + radius * next);
            if (fn < f)
                d = next, f = fn, step *= 1.5f;
            else
                step *= 0.3f;
        }
        return f < 0.0f;
    };
    const auto crosses = [&](float radius) {
        glm::vec3 nearest = axis, finer = axis;
        return crossesAbout(radius, axis, cone, &nearest) ||
               crossesAbout(radius, nearest, 0.1f * cone, &finer) || descends(radius, finer);
    };
    if (!crosses(hi)) return hi; // the cloud's point itself is as near as the field resolves
    if (crosses(lo)) return lo;
    for (int i = 0; i < 14; ++i) {
        const float mid = 0.5f * (lo + hi);
        (crosses(mid) ? hi : lo) = mid;
    }
    return hi;
}

// Over the offset's (shell's) surface: the least and greatest distance to the child's surface,
// and whether the node was baked.
struct Measure {
    float lo = INFINITY, hi = 0.0f;
    float radius = 0.0f; // the greatest distance from the y axis
    bool baked = false;
};

// The case's offset or shell, asking for the baked distance, over its child.
Scene exactScene(const Case& c) {
    const std::string key = std::string(c.op) == "offset" ? "distance" : "thickness";
    return parseRoot(std::string(R"({"type": ")") + c.op + R"(", "accuracy": "exact", ")" + key +
                     "\": " + std::to_string(c.amount) + R"(, "children": [)" + c.child + "]}");
}

Measure measure(const Case& c) {
    const Scene scene = exactScene(c);
    const Scene alone = parseRoot(c.child);
    const Evaluator e(scene), childEvaluator(alone);
    const auto child = [&](glm::vec3 p) { return childEvaluator.distance(p); };
    const auto offset = [&](glm::vec3 p) { return e.distance(p); };
    const Aabb box{e.bounds().min - 0.05f, e.bounds().max + 0.05f};
    const Aabb childBox{childEvaluator.bounds().min - 0.05f, childEvaluator.bounds().max + 0.05f};
    const Cloud cloud(surfacePoints(child, childBox, 0.015f), 0.05f);
    Measure m;
    m.baked = e.nodes()[1].kind == NodeKind::Mesh;
    // About 1500 of the offset's points, spread over its surface, each with its cloud distance.
    std::vector<glm::vec3> points = surfacePoints(offset, box, 0.05f);
    const size_t stride = points.size() / 1500 + 1;
    struct Point {
        glm::vec3 q, nearest;
        float d;
    };
    std::vector<Point> some;
    for (size_t i = 0; i < points.size(); i += stride) {
        Point p{points[i], {}, 0.0f};
        p.d = cloud.distance(p.q, &p.nearest);
        some.push_back(p);
        m.radius = std::max(m.radius, glm::length(glm::vec2(p.q.x, p.q.z)));
    }
    // The cloud's distance exceeds the surface's by about s^2 / 2d (s ~ 0.02 here), and by up
    // to a cell where it misses a sharp corner: only the points whose cloud distance lies that
    // near the extremes are refined.
    const auto refine = [&](const Point& p) {
        return sphereDistance(child, p.q, glm::normalize(p.nearest - p.q), 0.5f * p.d,
                              1.0001f * p.d);
    };
    std::sort(some.begin(), some.end(), [](const Point& a, const Point& b) { return a.d < b.d; });
    for (const Point& p : some) {
        if (p.d - 0.015f > m.lo) break;
        m.lo = std::min(m.lo, refine(p));
    }
    for (size_t i = some.size(); i-- > 0;) {
        if (some[i].d < m.hi) break;
        m.hi = std::max(m.hi, refine(some[i]));
    }
    return m;
}

const char* const kTwistedBox =
    R"({"type": "twist", "angle": 90, "children": [{"type": "box", "size": [1, 2, 1]}]})";
const char* const kTwistedCylinder =
    R"({"type": "twist", "angle": 90, "children": [{"type": "cylinder", "radius": 0.5, "height": 2}]})";

// Two figures: a twisted box grown by 0.3 reaches 0.707 + 0.3 from the axis (1.30 when offsets
// took the divided field as it was), and a twisted cylinder, which the twist leaves as it is,
// takes a skin of 0.1 (0.206 then), each within 2%.
TEST(Offsets, TwistedBoxAndCylinder) {
    const Measure box = measure({kTwistedBox, "offset", 0.3f});
    std::printf("twisted box offset 0.3: greatest radius %.4f, distance %.4f to %.4f\n", box.radius,
                box.lo, box.hi);
    EXPECT_NEAR(box.radius, std::sqrt(0.5f) + 0.3f, 0.02f);
    EXPECT_GE(box.lo, 0.98f * 0.3f);
    EXPECT_LE(box.hi, 1.02f * 0.3f);
    const Measure shell = measure({kTwistedCylinder, "shell", 0.1f});
    std::printf("twisted cylinder shell 0.1: thickness %.4f to %.4f\n", 2.0f * shell.lo,
                2.0f * shell.hi);
    EXPECT_GE(2.0f * shell.lo, 0.098f);
    EXPECT_LE(2.0f * shell.hi, 0.102f);
}

const char* const kSmoothUnion = R"({"type": "union", "smooth": 0.3, "children": [
    {"type": "sphere", "radius": 0.5, "translate": [-0.35, 0, 0]},
    {"type": "box", "size": [0.6, 0.6, 0.6], "translate": [0.35, 0, 0], "color": [0.9, 0.2, 0.1]}]})";

// Each child that is not a distance, grown and hollowed, by up to the child's size: baked, the
// surface lies within 2% of the distance asked for (half the thickness, each side of a shell),
// but where the offset's own surface has a crease that the field's trilinear interpolation rounds
// by up to half a cell: the inner skin of a shell, and an inward offset, at the convex edges of
// a box (there the measured limits, with the cell the memory allows: a shell 0.1 over the twisted
// box 1 x 2 x 1 takes a cell of about a fifth of its half thickness).
TEST(Offsets, SurfaceLiesWithinTwoPercentOverStretchedFields) {
    const std::string bend =
        R"({"type": "bend", "angle": 40, "children": [{"type": "box", "size": [2, 0.4, 0.6]}]})";
    const std::string taper = R"({"type": "taper", "height": 1.5, "top_scale": 0.4, "children": [
            {"type": "box", "size": [1, 1.5, 1]}]})";
    std::vector<std::string> children = {
        kTwistedBox,
        kSmoothUnion,
        bend,
        taper,
        R"({"type": "sphere", "radius": 0.5, "scale": [1, 2, 1]})",
    };
    // The sanitized suite bakes the first two only (a child without colours, one with): the
    // others take the same code paths, at ten times the cost there.
    if (std::getenv("SDFCSG_SANITIZED")) children.resize(2);
    // The exceptions: a child, an operation and amount, and the fraction the surface lies within.
    const auto tolerance = [&](const std::string& child, const Case& c) {
        if (child == kTwistedBox && std::string(c.op) == "shell") return 0.06f;
        if (child == kTwistedBox && c.amount < 0.0f) return 0.045f;
        if (child == bend && c.amount < 0.0f) return 0.03f;
        if (child == taper && std::string(c.op) == "shell") return 0.03f;
        return 0.02f;
    };
    for (const std::string& child : children)
        for (const Case& c : {Case{child, "offset", 0.3f}, Case{child, "shell", 0.1f},
                              Case{child, "offset", 1.0f}, Case{child, "offset", -0.1f}}) {
            SCOPED_TRACE(child + " " + c.op + " " + std::to_string(c.amount));
            const Measure m = measure(c);
            const float want = std::string(c.op) == "offset" ? std::abs(c.amount) : 0.5f * c.amount;
            std::printf("%s %g: %.5f to %.5f of %.4f (%s)\n", c.op, c.amount, m.lo, m.hi, want,
                        m.baked ? "baked" : "first order");
            EXPECT_TRUE(m.baked);
            EXPECT_GE(m.lo, (1.0f - tolerance(child, c)) * want);
            EXPECT_LE(m.hi, (1.0f + tolerance(child, c)) * want);
        }
}

// A skin of 0.05 over a smooth union: thin against the child, so the cell is set by the memory
// the field may take (without the colours, which do not fit beside it), and the skin lies
// within 3% of its thickness. (Over the twisted box, whose surface is larger, even a cell of a
// quarter of 0.025 would not fit: that shell keeps the first-order division.)
TEST(Offsets, ThinShellWithinThreePercent) {
    const Measure m = measure({kSmoothUnion, "shell", 0.05f});
    std::printf("shell 0.05: %.5f to %.5f of 0.025 (%s)\n", m.lo, m.hi,
                m.baked ? "baked" : "first order");
    EXPECT_TRUE(m.baked);
    EXPECT_GE(m.lo, 0.97f * 0.025f);
    EXPECT_LE(m.hi, 1.03f * 0.025f);
    const Scene twisted =
        parseRoot(R"({"type": "shell", "thickness": 0.05, "accuracy": "exact", "children": [)" +
                  std::string(kTwistedBox) + "]}");
    EXPECT_EQ(twisted.nodes[0].words, nullptr);
}

// A baked offset is still a bound for sphere tracing: outside, nowhere above the distance to its
// surface (the child's distance less the offset's, against the dense cloud of the child's
// surface, which is never below that distance), and the field grows no faster than the distance
// between points.
TEST(Offsets, BakedOffsetStaysABound) {
    for (const Case& c : {Case{kTwistedBox, "offset", 0.3f}, Case{kSmoothUnion, "shell", 0.1f}}) {
        SCOPED_TRACE(std::string(c.op) + " " + c.child);
        const Scene scene = exactScene(c);
        const Scene alone = parseRoot(c.child);
        const Evaluator e(scene), childEvaluator(alone);
        ASSERT_EQ(e.nodes()[1].kind, NodeKind::Mesh);
        const auto child = [&](glm::vec3 p) { return childEvaluator.distance(p); };
        const Aabb box{childEvaluator.bounds().min - 0.05f, childEvaluator.bounds().max + 0.05f};
        const Cloud cloud(surfacePoints(child, box, 0.015f), 0.05f);
        const float shift = std::string(c.op) == "offset" ? c.amount : 0.5f * c.amount;
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> u(-1.5f, 1.5f);
        int above = 0, steep = 0;
        for (int i = 0; i < 1500; ++i) {
            const glm::vec3 p(u(rng), u(rng), u(rng));
            const float d = cloud.distance(p);
            const float value = e.distance(p);
            const bool inside = child(p) < 0.0f;
            // The offset's (shell's) exact field: the child's distance, signed, less the shift.
            const float exact =
                std::string(c.op) == "offset" ? (inside ? -d : d) - shift : d - shift;
            // Outside, where rays march, a bound: no farther from 0 than the exact value. (Inside
            // the offset's surface the cloud misses sharp tips of the child by more than the
            // baked field does, so it does not tell.)
            above += value > 0.0f && value > exact + 0.01f * shift;
            const glm::vec3 q = p + 0.05f * glm::normalize(glm::vec3(u(rng), u(rng), u(rng)));
            steep += std::abs(e.distance(q) - value) > 1.05f * glm::length(q - p);
        }
        EXPECT_EQ(above, 0);
        EXPECT_EQ(steep, 0);
    }
}

// The bake is asked for: by default ("accuracy": "fast") an offset over a twist divides.
TEST(Offsets, OnlyExactAccuracyBakes) {
    for (const char* accuracy : {"", R"("accuracy": "fast", )", R"("accuracy": "exact", )"}) {
        const Scene scene =
            parseRoot(R"({"type": "offset", "distance": 0.3, )" + std::string(accuracy) +
                      R"("children": [)" + std::string(kTwistedBox) + "]}");
        const bool exact = std::string(accuracy).find("exact") != std::string::npos;
        EXPECT_EQ(scene.nodes[0].words != nullptr, exact) << accuracy;
        EXPECT_EQ(Evaluator(scene).nodes()[1].kind, exact ? NodeKind::Mesh : NodeKind::Twist);
    }
}

// An offset too thin to bake against its child's size (a field at a quarter of it would exceed
// the limit) keeps the first-order division, near its distance.
TEST(Offsets, TooThinToBakeKeepsTheFirstOrderDivision) {
    const Scene scene = parseRoot(R"({"type": "offset", "distance": 0.002, "accuracy": "exact",
                                  "children": [)" +
                                  std::string(kTwistedBox) + "]}");
    const Evaluator e(scene);
    EXPECT_EQ(e.nodes()[1].kind, NodeKind::Twist);
    EXPECT_EQ(scene.nodes[0].words, nullptr);
    EXPECT_GT(e.nodes()[0].params[1], 0.0f); // the tap step: normalising
}

} // namespace
} // namespace sdfcsg
