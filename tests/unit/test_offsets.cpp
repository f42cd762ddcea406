// Offsets and shells over fields that are not distances (twist, bend, taper, a scale per axis, a
// smooth union), against a dense numerical distance to their child's surface: the child's
// surface found on a fine grid (every crossed edge bisected), and the offset's surface on a
// coarser one, each of its points measured to the nearest of the child's. The division by the
// gradient is first order: it is exact where the child's field is a distance times a factor
// that changes slowly, and strays where the stretch changes within the offset's distance (the
// rims of a twisted box's caps), or where a bound with a gradient of length 1 stands in for
// the field (a primitive scaled per axis, floored at its box near the box's corners). The
// bounds below hold what it achieves (docs/vocabulary.md#lipschitz-bounds).
#include "scene_build_util.h"

#include <sdfcsg/eval.h>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
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
    float distance(glm::vec3 q) const {
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
                            best = std::min(best, glm::length(p - q));
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

// Over the offset's (shell's) surface: the least and greatest distance to the child's surface,
// and the same for the raw field (the child's value less the distance, over the child as it is
// now, its bounds grown).
struct Measure {
    float lo = INFINITY, hi = 0.0f, rawLo = INFINITY, rawHi = 0.0f;
    float radius = 0.0f, rawRadius = 0.0f; // the greatest distance from the y axis
};

Measure measure(const Case& c) {
    const std::string key = std::string(c.op) == "offset" ? "distance" : "thickness";
    const Scene scene = parseRoot(std::string(R"({"type": ")") + c.op + R"(", ")" + key + "\": " +
                                  std::to_string(c.amount) + R"(, "children": [)" + c.child + "]}");
    const Evaluator e(scene);
    const auto child = [&](glm::vec3 p) { return e.distance(p, 1); };
    const auto offset = [&](glm::vec3 p) { return e.distance(p); };
    const float shift = std::string(c.op) == "offset" ? c.amount : 0.5f * c.amount;
    const auto raw = [&](glm::vec3 p) {
        const float d = child(p);
        return std::string(c.op) == "offset" ? d - shift : std::abs(d) - shift;
    };
    const Aabb box{e.bounds().min - 0.05f, e.bounds().max + 0.05f};
    const Aabb childBox{e.nodes()[1].bounds.min - 0.05f, e.nodes()[1].bounds.max + 0.05f};
    const Cloud cloud(surfacePoints(child, childBox, 0.015f), 0.05f);
    Measure m;
    // About 1500 of the offset's points, spread over its surface.
    const auto spread = [](std::vector<glm::vec3> points) {
        std::vector<glm::vec3> some;
        const size_t stride = points.size() / 1500 + 1;
        for (size_t i = 0; i < points.size(); i += stride)
            some.push_back(points[i]);
        return some;
    };
    for (const glm::vec3& q : spread(surfacePoints(offset, box, 0.05f))) {
        const float d = cloud.distance(q);
        m.lo = std::min(m.lo, d), m.hi = std::max(m.hi, d);
        m.radius = std::max(m.radius, glm::length(glm::vec2(q.x, q.z)));
    }
    for (const glm::vec3& q : spread(surfacePoints(raw, box, 0.05f))) {
        const float d = cloud.distance(q);
        m.rawLo = std::min(m.rawLo, d), m.rawHi = std::max(m.rawHi, d);
        m.rawRadius = std::max(m.rawRadius, glm::length(glm::vec2(q.x, q.z)));
    }
    return m;
}

const char* const kTwistedBox =
    R"({"type": "twist", "angle": 90, "children": [{"type": "box", "size": [1, 2, 1]}]})";
const char* const kTwistedCylinder =
    R"({"type": "twist", "angle": 90, "children": [{"type": "cylinder", "radius": 0.5, "height": 2}]})";

// Two figures: a twisted box grown by 0.3 reaches 0.707 + 0.3 from the axis (1.30 when offsets
// took the divided field as it was), and a twisted cylinder, which the twist leaves as it is,
// takes a skin of 0.1 (0.206 then).
TEST(Offsets, TwistedBoxAndCylinder) {
    const Measure box = measure({kTwistedBox, "offset", 0.3f});
    std::printf("twisted box offset 0.3: greatest radius %.4f, distance %.4f to %.4f\n", box.radius,
                box.lo, box.hi);
    EXPECT_NEAR(box.radius, std::sqrt(0.5f) + 0.3f, 0.05f);
    const Measure shell = measure({kTwistedCylinder, "shell", 0.1f});
    std::printf("twisted cylinder shell 0.1: thickness %.4f to %.4f\n", 2.0f * shell.lo,
                2.0f * shell.hi);
    EXPECT_NEAR(2.0f * shell.lo, 0.1f, 0.002f);
    EXPECT_LE(2.0f * shell.hi, 0.125f);
}

// Each child that is not a distance, grown and hollowed: the surface lies within the factors
// measured (first-order division; the worst at the rims of the twisted and tapered boxes).
TEST(Offsets, SurfaceLiesNearTheDistanceOverStretchedFields) {
    const std::string children[] = {
        kTwistedBox,
        R"({"type": "bend", "angle": 40, "children": [{"type": "box", "size": [2, 0.4, 0.6]}]})",
        R"({"type": "taper", "height": 1.5, "top_scale": 0.4, "children": [
            {"type": "box", "size": [1, 1.5, 1]}]})",
        R"({"type": "sphere", "radius": 0.5, "scale": [1, 2, 1]})",
        R"({"type": "union", "smooth": 0.3, "children": [
            {"type": "sphere", "radius": 0.5, "translate": [-0.35, 0, 0]},
            {"type": "box", "size": [0.6, 0.6, 0.6], "translate": [0.35, 0, 0]}]})",
    };
    for (const std::string& child : children)
        for (const Case& c : {Case{child, "offset", 0.3f}, Case{child, "shell", 0.1f}}) {
            SCOPED_TRACE(child + " " + c.op + " " + std::to_string(c.amount));
            const Measure m = measure(c);
            const float want = std::string(c.op) == "offset" ? c.amount : 0.5f * c.amount;
            std::printf("%s %g: %.4f to %.4f of %.4f\n", c.op, c.amount, m.lo, m.hi, want);
            EXPECT_GE(m.lo, 0.5f * want);
            EXPECT_LE(m.hi, 1.8f * want);
        }
}

} // namespace
} // namespace sdfcsg
