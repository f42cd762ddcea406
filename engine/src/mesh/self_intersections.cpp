#include "mesh/self_intersections.h"

#include "mesh/radix_sort.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <glm/vector_relational.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <thread>

namespace sdfcsg::detail {
namespace {

using glm::dvec3;

double pointSegmentDistance(dvec3 p, dvec3 a, dvec3 b) {
    const dvec3 ab = b - a;
    const double length2 = glm::dot(ab, ab);
    const double t = length2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / length2, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + t * ab));
}

// Ericson, Real-Time Collision Detection (2005), 5.1.9: the closest points of two segments.
double segmentSegmentDistance(dvec3 p1, dvec3 q1, dvec3 p2, dvec3 q2) {
    const dvec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
    const double a = glm::dot(d1, d1), e = glm::dot(d2, d2), f = glm::dot(d2, r);
    if (a <= 0.0 && e <= 0.0) return glm::length(r);
    double s = 0.0, t = 0.0;
    if (a <= 0.0) {
        t = std::clamp(f / e, 0.0, 1.0);
    } else {
        const double c = glm::dot(d1, r);
        if (e <= 0.0) {
            s = std::clamp(-c / a, 0.0, 1.0);
        } else {
            const double b = glm::dot(d1, d2), denominator = a * e - b * b;
            s = denominator > 0.0 ? std::clamp((b * f - c * e) / denominator, 0.0, 1.0) : 0.0;
            t = (b * s + f) / e;
            if (t < 0.0) {
                t = 0.0;
                s = std::clamp(-c / a, 0.0, 1.0);
            } else if (t > 1.0) {
                t = 1.0;
                s = std::clamp((b - c) / a, 0.0, 1.0);
            }
        }
    }
    return glm::length(p1 + d1 * s - (p2 + d2 * t));
}

// A triangle in double precision. One whose height over its longest side is at most the
// tolerance of the test (a needle or a point) gets no plane: within that tolerance it is the
// union of its sides, and a plane through it would only be rounding noise.
struct Triangle {
    std::array<dvec3, 3> v;
    dvec3 normal{0.0}; // unit, or zero without a plane
    dvec3 lo{0.0}, hi{0.0};

    Triangle(glm::vec3 a, glm::vec3 b, glm::vec3 c, double tolerance)
        : v{dvec3(a), dvec3(b), dvec3(c)} {
        const dvec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);
        const double longest = std::max(
            {glm::length(v[1] - v[0]), glm::length(v[2] - v[1]), glm::length(v[0] - v[2])});
        if (glm::length(n) > tolerance * longest) normal = glm::normalize(n);
        lo = glm::min(v[0], glm::min(v[1], v[2]));
        hi = glm::max(v[0], glm::max(v[1], v[2]));
    }
    bool hasPlane() const { return normal != dvec3(0.0); }
    // Whether x, taken as lying in the plane, is within the triangle (the prism over it).
    bool overTriangle(dvec3 x) const {
        for (int i = 0; i < 3; ++i)
            if (glm::dot(glm::cross(v[(i + 1) % 3] - v[i], x - v[i]), normal) < 0.0) return false;
        return true;
    }
    double distance(dvec3 p) const {
        if (hasPlane() && overTriangle(p)) return std::abs(glm::dot(p - v[0], normal));
        double d = pointSegmentDistance(p, v[0], v[1]);
        d = std::min(d, pointSegmentDistance(p, v[1], v[2]));
        return std::min(d, pointSegmentDistance(p, v[2], v[0]));
    }
};

// Whether segment pq comes within `tolerance` of the triangle: it crosses the triangle's plane
// over the triangle, or else the nearest points are an end of the segment and the triangle or
// the segment and a side.
bool segmentMeetsTriangle(dvec3 p, dvec3 q, const Triangle& t, double tolerance) {
    if (glm::any(glm::greaterThan(glm::min(p, q), t.hi + tolerance)) ||
        glm::any(glm::lessThan(glm::max(p, q), t.lo - tolerance)))
        return false; // their boxes are apart
    if (t.hasPlane()) {
        const double sp = glm::dot(p - t.v[0], t.normal), sq = glm::dot(q - t.v[0], t.normal);
        if ((sp > tolerance && sq > tolerance) || (sp < -tolerance && sq < -tolerance))
            return false;
        if ((sp < 0.0) != (sq < 0.0) && t.overTriangle(p + (q - p) * (sp / (sp - sq)))) return true;
    }
    if (t.distance(p) <= tolerance || t.distance(q) <= tolerance) return true;
    for (int i = 0; i < 3; ++i)
        if (segmentSegmentDistance(p, q, t.v[i], t.v[(i + 1) % 3]) <= tolerance) return true;
    return false;
}

// Two triangles come within `tolerance` of each other exactly when a side of one comes within it
// of the other: where they cross, the ends of the crossing lie on sides; where they are apart,
// the nearest points can be chosen with one of them on a side.
bool trianglesMeet(const Triangle& a, const Triangle& b, double tolerance) {
    for (int i = 0; i < 3; ++i)
        if (segmentMeetsTriangle(a.v[i], a.v[(i + 1) % 3], b, tolerance) ||
            segmentMeetsTriangle(b.v[i], b.v[(i + 1) % 3], a, tolerance))
            return true;
    return false;
}

// Quick proofs that two triangles do not meet, tried before the exact tests above (each proof
// only skips pairs those tests would pass). A plane with one triangle on its closed inner side and
// the other's vertices more than `tolerance` beyond it keeps them apart: the triangle's own plane
// (either side), or the plane through one of its sides and its normal (outward: away from the
// third vertex). Two triangles with a common vertex v touch there: the far one's other vertices
// must be beyond the plane, and the points of it within `tolerance` of the plane, a tip at v no
// longer than tolerance / (their least depth) * (its longest side from v), must stay farther than
// `tolerance` from the near one's side opposite v, which lies `height` from v.
bool beyond(dvec3 origin, dvec3 outward, const Triangle& far, int shared, double tolerance,
            double height) {
    double least = 1e300, reach = 0.0;
    for (int i = 0; i < 3; ++i) {
        if (i == shared) continue;
        least = std::min(least, glm::dot(far.v[i] - origin, outward));
        if (shared >= 0) reach = std::max(reach, glm::length(far.v[i] - far.v[shared]));
    }
    if (!(least > tolerance)) return false;
    return shared < 0 || height * least > tolerance * (least + reach);
}

// Whether a plane of `a` (see beyond()) keeps `b` apart; `sharedA`, `sharedB`: the places of a
// common vertex in each, or -1.
bool planeOfASeparates(const Triangle& a, const Triangle& b, int sharedA, int sharedB,
                       double tolerance) {
    if (!a.hasPlane()) return false;
    // a's height over its side opposite the shared vertex.
    double height = 0.0;
    if (sharedA >= 0) {
        const dvec3 side = a.v[(sharedA + 2) % 3] - a.v[(sharedA + 1) % 3];
        const double length = glm::length(side);
        if (!(length > 0.0)) return false;
        height = glm::length(glm::cross(side, a.v[sharedA] - a.v[(sharedA + 1) % 3])) / length;
    }
    const dvec3 origin = a.v[sharedA >= 0 ? sharedA : 0];
    if (beyond(origin, a.normal, b, sharedB, tolerance, height) ||
        beyond(origin, -a.normal, b, sharedB, tolerance, height))
        return true;
    for (int i = 0; i < 3; ++i) {
        const dvec3 p = a.v[i], q = a.v[(i + 1) % 3];
        // With a common vertex, only the two sides through it.
        if (sharedA >= 0 && i != sharedA && (i + 1) % 3 != sharedA) continue;
        const dvec3 outward = glm::cross(q - p, a.normal); // away from the third vertex
        const double length = glm::length(outward);
        if (!(length > 0.0)) continue;
        if (beyond(p, outward / length, b, sharedB, tolerance, height)) return true;
    }
    return false;
}

bool separated(const Triangle& a, const Triangle& b, int sharedA, int sharedB, double tolerance) {
    return planeOfASeparates(a, b, sharedA, sharedB, tolerance) ||
           planeOfASeparates(b, a, sharedB, sharedA, tolerance);
}

} // namespace

SelfIntersections findSelfIntersections(const Mesh& mesh, double tolerance, double foldAngle,
                                        std::vector<std::pair<uint32_t, uint32_t>>* pairs,
                                        bool quick) {
    using glm::dvec3;
    SelfIntersections r;
    const size_t n = mesh.triangleCount();
    if (n == 0) return r;
    dvec3 lo(1e300), hi(-1e300);
    for (const glm::vec3& p : mesh.positions) {
        lo = glm::min(lo, dvec3(p));
        hi = glm::max(hi, dvec3(p));
    }
    if (tolerance < 0.0) tolerance = 1e-6 * glm::length(hi - lo);
    std::vector<Triangle> triangles;
    std::vector<uint32_t> valid; // triangles with three distinct vertices in range
    triangles.reserve(n);
    double extent = 0.0;
    for (size_t t = 0; t < n; ++t) {
        const uint32_t* v = &mesh.indices[3 * t];
        const bool ok = v[0] < mesh.vertexCount() && v[1] < mesh.vertexCount() &&
                        v[2] < mesh.vertexCount() && v[0] != v[1] && v[1] != v[2] && v[2] != v[0];
        triangles.emplace_back(mesh.positions[ok ? v[0] : 0], mesh.positions[ok ? v[1] : 0],
                               mesh.positions[ok ? v[2] : 0], tolerance);
        if (!ok) continue;
        valid.push_back(uint32_t(t));
        const dvec3 size = triangles.back().hi - triangles.back().lo;
        extent += std::max(size.x, std::max(size.y, size.z));
    }
    if (valid.empty()) return r;

    // A uniform grid of cells about twice the mean triangle's size; each triangle is listed in
    // every cell its bounds (grown by the tolerance) reach, and each pair is tested only in the
    // cell that holds the low corner of the overlap of their grown bounds.
    // Cells are numbered from a corner one cell below the grown bounds, each axis in as many bits
    // as its cells need (21 at most: past that, far cells share numbers, which only joins their
    // lists).
    const double cell = std::max(2.0 * extent / double(valid.size()), 1e-30);
    const dvec3 corner = lo - tolerance - cell;
    auto cellOf = [&](dvec3 p) { return glm::ivec3(glm::floor((p - corner) / cell)); };
    const glm::ivec3 last = cellOf(hi + tolerance);
    const int bx = std::min(detail::bitsFor(uint64_t(last.x) + 1), 21);
    const int by = std::min(detail::bitsFor(uint64_t(last.y) + 1), 21);
    const int bz = std::min(detail::bitsFor(uint64_t(last.z) + 1), 21);
    auto key = [&](glm::ivec3 c) {
        return uint64_t(uint32_t(c.x) & ((1u << bx) - 1)) |
               uint64_t(uint32_t(c.y) & ((1u << by) - 1)) << bx |
               uint64_t(uint32_t(c.z) & ((1u << bz) - 1)) << (bx + by);
    };
    std::vector<std::pair<uint64_t, uint32_t>> listed;
    for (uint32_t t : valid) {
        const glm::ivec3 c0 = cellOf(triangles[t].lo - tolerance);
        const glm::ivec3 c1 = cellOf(triangles[t].hi + tolerance);
        for (int z = c0.z; z <= c1.z; ++z)
            for (int y = c0.y; y <= c1.y; ++y)
                for (int x = c0.x; x <= c1.x; ++x)
                    listed.push_back({key({x, y, z}), t});
    }
    // Listed in the order of the triangles, so that the stable sort keeps each cell's in it.
    const bool twoThreads = listed.size() >= 30000 && std::thread::hardware_concurrency() >= 2;
    radixSort(listed, 0, bx + by + bz,
              [](const std::pair<uint64_t, uint32_t>& entry) { return entry.first; });
    // The grown bounds of listed[i] in single precision, rounded outwards, side by side in the
    // order of `listed`: most pairs of a cell are told apart by these alone, without reading the
    // triangles (which the test below then does in double precision).
    struct Box {
        glm::vec3 lo, hi;
    };
    std::vector<Box> boxes(listed.size());
    for (size_t i = 0; i < listed.size(); ++i) {
        const Triangle& t = triangles[listed[i].second];
        for (int k = 0; k < 3; ++k) {
            boxes[i].lo[k] = std::nextafter(float(t.lo[k] - tolerance), -HUGE_VALF);
            boxes[i].hi[k] = std::nextafter(float(t.hi[k] + tolerance), HUGE_VALF);
        }
    }

    auto describe = [&](uint32_t t) {
        std::ostringstream s;
        s.precision(7);
        s << "triangle " << t;
        for (int i = 0; i < 3; ++i) {
            const glm::vec3 p = mesh.positions[mesh.indices[3 * t + i]];
            s << (i ? ", " : " (") << mesh.indices[3 * t + i] << " at " << p.x << " " << p.y << " "
              << p.z;
        }
        return s.str() + ")";
    };
    // The cells of listed[begin, end) into `out` (and `outPairs`): two threads take a half each.
    auto scan = [&](size_t begin, size_t end, SelfIntersections& out,
                    std::vector<std::pair<uint32_t, uint32_t>>* outPairs) {
        auto found = [&](size_t& count, uint32_t a, uint32_t b, const char* what) {
            ++count;
            if (outPairs) outPairs->push_back({a, b});
            if (out.first.empty()) out.first = describe(a) + " and " + describe(b) + " " + what;
        };
        for (size_t i = begin; i < end;) {
            size_t cellEnd = i;
            while (cellEnd < end && listed[cellEnd].first == listed[i].first)
                ++cellEnd;
            for (size_t j = i; j < cellEnd; ++j)
                for (size_t k = j + 1; k < cellEnd; ++k) {
                    if (glm::any(glm::greaterThan(boxes[j].lo, boxes[k].hi)) ||
                        glm::any(glm::greaterThan(boxes[k].lo, boxes[j].hi)))
                        continue;
                    const uint32_t ta = listed[j].second, tb = listed[k].second;
                    const Triangle &a = triangles[ta], &b = triangles[tb];
                    const dvec3 overlapLo = glm::max(a.lo, b.lo) - tolerance;
                    const dvec3 overlapHi = glm::min(a.hi, b.hi) + tolerance;
                    if (glm::any(glm::greaterThan(overlapLo, overlapHi)) ||
                        key(cellOf(overlapLo)) != listed[i].first)
                        continue;
                    const uint32_t* va = &mesh.indices[3 * size_t(ta)];
                    const uint32_t* vb = &mesh.indices[3 * size_t(tb)];
                    int shared = 0, inA = -1, inB = -1; // a shared vertex's place in a and in b
                    int onlyA = 3, onlyB = 3;           // the sum of the unshared places
                    for (int x = 0; x < 3; ++x)
                        for (int y = 0; y < 3; ++y)
                            if (va[x] == vb[y]) {
                                ++shared;
                                inA = x, inB = y;
                                onlyA -= x, onlyB -= y;
                            }
                    if (shared == 0) {
                        if (!(quick && separated(a, b, -1, -1, tolerance)) &&
                            trianglesMeet(a, b, tolerance))
                            found(r.crossing, ta, tb, "cross");
                    } else if (shared == 1) {
                        if (quick && separated(a, b, inA, inB, tolerance)) continue;
                        const dvec3 &a1 = a.v[(inA + 1) % 3], &a2 = a.v[(inA + 2) % 3];
                        const dvec3 &b1 = b.v[(inB + 1) % 3], &b2 = b.v[(inB + 2) % 3];
                        if (segmentMeetsTriangle(a1, a2, b, tolerance) ||
                            segmentMeetsTriangle(b1, b2, a, tolerance))
                            found(r.overlapping, ta, tb, "overlap beyond their common vertex");
                    } else if (shared == 2) {
                        if (!a.hasPlane() || !b.hasPlane()) continue;
                        // onlyA and onlyB now name each triangle's vertex off the common side.
                        const dvec3 u = a.v[(onlyA + 1) % 3], side = a.v[(onlyA + 2) % 3] - u;
                        auto across = [&](dvec3 p) { // from the side's line to p, at right angles
                            const dvec3 d = p - u;
                            return glm::normalize(
                                d - side * (glm::dot(d, side) / glm::dot(side, side)));
                        };
                        if (glm::dot(across(a.v[onlyA]), across(b.v[onlyB])) > std::cos(foldAngle))
                            found(r.folded, ta, tb, "fold onto their common side");
                    } else {
                        found(r.duplicates, ta, tb, "have the same vertices");
                    }
                }
            i = cellEnd;
        }
    };
    // The halves meet at a change of cell, so that each cell is one thread's.
    size_t middle = listed.size() / 2;
    while (middle > 0 && middle < listed.size() && listed[middle].first == listed[middle - 1].first)
        ++middle;
    if (!twoThreads) {
        scan(0, listed.size(), r, pairs);
        return r;
    }
    SelfIntersections second;
    std::vector<std::pair<uint32_t, uint32_t>> secondPairs;
    std::thread helper(scan, middle, listed.size(), std::ref(second),
                       pairs ? &secondPairs : nullptr);
    scan(0, middle, r, pairs);
    helper.join();
    r.crossing += second.crossing;
    r.overlapping += second.overlapping;
    r.folded += second.folded;
    r.duplicates += second.duplicates;
    if (r.first.empty()) r.first = second.first;
    if (pairs) pairs->insert(pairs->end(), secondPairs.begin(), secondPairs.end());
    return r;
}

} // namespace sdfcsg::detail
