// Properties of a triangle mesh that tests assert on: closed and manifold (every edge shared by two
// triangles in opposite directions), Euler characteristic, signed volume, area, distance of the
// vertices and of points across the triangles from the surface, outward normals, triangles that
// intersect each other or face against the field, and an order-independent comparison of two
// meshes.
#pragma once

#include "mesh/mesh_simplify.h"

#include <sdfcsg/eval.h>
#include <sdfcsg/mesh.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <sstream>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace sdfcsg::test {

struct MeshProperties {
    size_t vertices = 0, triangles = 0;
    size_t referencedVertices = 0; // vertices used by some triangle
    size_t badTriangles = 0;       // an index out of range or repeated within the triangle
    size_t edges = 0;              // distinct undirected edges
    size_t boundaryEdges = 0;      // used by one triangle
    size_t nonManifoldEdges = 0;   // used by more than two triangles
    size_t misorientedEdges = 0;   // used by two triangles in the same direction
    int64_t euler = 0;             // referenced vertices - edges + triangles
    double volume = 0;             // signed: positive when the triangles face outwards
    double area = 0;

    bool closedManifold() const {
        return badTriangles == 0 && boundaryEdges == 0 && nonManifoldEdges == 0 &&
               misorientedEdges == 0;
    }
    std::string str() const {
        std::ostringstream s;
        s << vertices << " vertices (" << referencedVertices << " used), " << triangles
          << " triangles (" << badTriangles << " bad), " << edges << " edges: " << boundaryEdges
          << " boundary, " << nonManifoldEdges << " non-manifold, " << misorientedEdges
          << " misoriented; Euler " << euler << ", volume " << volume << ", area " << area;
        return s.str();
    }
};

inline MeshProperties measureMesh(const Mesh& mesh) {
    MeshProperties m;
    m.vertices = mesh.vertexCount();
    m.triangles = mesh.triangleCount();
    std::vector<bool> used(m.vertices, false);
    // (lower index << 32 | higher index) << 1 | (1 when the triangle runs lower to higher).
    std::vector<uint64_t> halfEdges;
    halfEdges.reserve(mesh.indices.size());
    for (size_t t = 0; t < m.triangles; ++t) {
        const uint32_t* v = &mesh.indices[3 * t];
        if (v[0] >= m.vertices || v[1] >= m.vertices || v[2] >= m.vertices || v[0] == v[1] ||
            v[1] == v[2] || v[2] == v[0]) {
            ++m.badTriangles;
            continue;
        }
        const glm::dvec3 a(mesh.positions[v[0]]), b(mesh.positions[v[1]]), c(mesh.positions[v[2]]);
        m.volume += glm::dot(a, glm::cross(b, c)) / 6.0;
        m.area += glm::length(glm::cross(b - a, c - a)) / 2.0;
        for (int i = 0; i < 3; ++i) {
            used[v[i]] = true;
            const uint32_t from = v[i], to = v[(i + 1) % 3];
            const uint64_t lo = std::min(from, to), hi = std::max(from, to);
            halfEdges.push_back(((lo << 32 | hi) << 1) | (from < to ? 1u : 0u));
        }
    }
    m.referencedVertices = size_t(std::count(used.begin(), used.end(), true));
    std::sort(halfEdges.begin(), halfEdges.end());
    for (size_t i = 0; i < halfEdges.size();) {
        size_t j = i, forward = 0;
        for (; j < halfEdges.size() && halfEdges[j] >> 1 == halfEdges[i] >> 1; ++j)
            forward += halfEdges[j] & 1u;
        const size_t uses = j - i;
        ++m.edges;
        if (uses == 1) ++m.boundaryEdges;
        if (uses > 2) ++m.nonManifoldEdges;
        if (uses == 2 && forward != 1) ++m.misorientedEdges;
        i = j;
    }
    m.euler = int64_t(m.referencedVertices) - int64_t(m.edges) + int64_t(m.triangles);
    return m;
}

// The largest |distance| of a vertex from the surface, by the CPU evaluator.
inline float maxSurfaceDistance(const Mesh& mesh, const Evaluator& evaluator) {
    float worst = 0.0f;
    for (const glm::vec3& p : mesh.positions)
        worst = std::max(worst, std::abs(evaluator.distance(p)));
    return worst;
}

// The largest |distance| from the surface, by the CPU evaluator, of the points
// detail::kTriangleSamples of every triangle. Unlike maxSurfaceDistance(), this sees a triangle
// that cuts across a sharp edge or corner of the solid.
inline float maxSampledSurfaceDistance(const Mesh& mesh, const Evaluator& evaluator) {
    float worst = 0.0f;
    for (size_t t = 0; t + 3 <= mesh.indices.size(); t += 3) {
        const glm::vec3 a = mesh.positions[mesh.indices[t]];
        const glm::vec3 b = mesh.positions[mesh.indices[t + 1]];
        const glm::vec3 c = mesh.positions[mesh.indices[t + 2]];
        for (const glm::vec3& w : detail::kTriangleSamples)
            worst = std::max(worst, std::abs(evaluator.distance(w.x * a + w.y * b + w.z * c)));
    }
    return worst;
}

// ---------------------------------------------------------------------------------------------
// Triangles that intersect each other.

namespace geometry {

using glm::dvec3;

inline double pointSegmentDistance(dvec3 p, dvec3 a, dvec3 b) {
    const dvec3 ab = b - a;
    const double length2 = glm::dot(ab, ab);
    const double t = length2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / length2, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + t * ab));
}

// Ericson, Real-Time Collision Detection (2005), 5.1.9: the closest points of two segments.
inline double segmentSegmentDistance(dvec3 p1, dvec3 q1, dvec3 p2, dvec3 q2) {
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
inline bool segmentMeetsTriangle(dvec3 p, dvec3 q, const Triangle& t, double tolerance) {
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
inline bool trianglesMeet(const Triangle& a, const Triangle& b, double tolerance) {
    for (int i = 0; i < 3; ++i)
        if (segmentMeetsTriangle(a.v[i], a.v[(i + 1) % 3], b, tolerance) ||
            segmentMeetsTriangle(b.v[i], b.v[(i + 1) % 3], a, tolerance))
            return true;
    return false;
}

} // namespace geometry

struct SelfIntersections {
    size_t crossing = 0;    // pairs with no vertex in common that meet
    size_t overlapping = 0; // pairs with one vertex in common that also meet away from it
    size_t folded = 0;      // pairs with a side in common that lie folded onto each other
    size_t duplicates = 0;  // pairs with all three vertices in common
    std::string first;      // the first pair found

    size_t total() const { return crossing + overlapping + folded + duplicates; }
    std::string str() const {
        std::ostringstream s;
        s << crossing << " pairs of triangles crossing, " << overlapping
          << " overlapping beyond a common vertex, " << folded << " folded onto a common side, "
          << duplicates << " duplicated";
        if (!first.empty()) s << "; first: " << first;
        return s.str();
    }
};

// Pairs of triangles that meet where a surface embedded without self-intersections would not let
// them: by vertex numbers, triangles with no vertex in common must not come within `tolerance` of
// each other (distinct vertices at one position count: the surface is pinched there). Two with
// one vertex v in common meet at v; they meet elsewhere as well exactly when the side opposite v
// in one comes within the tolerance of the other (their intersection is convex and holds v, so
// it is v alone or reaches from v to a point on such a side). Two with a side in common meet
// beyond it only when they lie in one plane on the same side of it, folded onto each other: when
// the angle between them at the side is under `foldAngle` radians. Triangles without a plane
// (see geometry::Triangle) are judged by their sides alone, and pairs with a side in common of
// which one has no plane not at all: checkTriangleFacing() reports them as degenerate.
// `tolerance` defaults to 1e-6 of the diagonal of the mesh's bounds, above the rounding of float
// positions and far below any feature a mesher should make. `pairs`, if given, receives every
// pair found (triangle numbers).
inline SelfIntersections
findSelfIntersections(const Mesh& mesh, double tolerance = -1.0, double foldAngle = 1e-3,
                      std::vector<std::pair<uint32_t, uint32_t>>* pairs = nullptr) {
    using geometry::Triangle;
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
    const double cell = std::max(2.0 * extent / double(valid.size()), 1e-30);
    auto cellOf = [&](dvec3 p) { return glm::ivec3(glm::floor((p - lo) / cell)); };
    auto key = [](glm::ivec3 c) {
        return (uint64_t(uint32_t(c.x) & 0x1fffff) << 42) |
               (uint64_t(uint32_t(c.y) & 0x1fffff) << 21) | uint64_t(uint32_t(c.z) & 0x1fffff);
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
    std::sort(listed.begin(), listed.end());

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
    auto found = [&](size_t& count, uint32_t a, uint32_t b, const char* what) {
        ++count;
        if (pairs) pairs->push_back({a, b});
        if (r.first.empty()) r.first = describe(a) + " and " + describe(b) + " " + what;
    };
    for (size_t i = 0; i < listed.size();) {
        size_t end = i;
        while (end < listed.size() && listed[end].first == listed[i].first)
            ++end;
        for (size_t j = i; j < end; ++j)
            for (size_t k = j + 1; k < end; ++k) {
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
                    if (geometry::trianglesMeet(a, b, tolerance))
                        found(r.crossing, ta, tb, "cross");
                } else if (shared == 1) {
                    const dvec3 &a1 = a.v[(inA + 1) % 3], &a2 = a.v[(inA + 2) % 3];
                    const dvec3 &b1 = b.v[(inB + 1) % 3], &b2 = b.v[(inB + 2) % 3];
                    if (geometry::segmentMeetsTriangle(a1, a2, b, tolerance) ||
                        geometry::segmentMeetsTriangle(b1, b2, a, tolerance))
                        found(r.overlapping, ta, tb, "overlap beyond their common vertex");
                } else if (shared == 2) {
                    if (!a.hasPlane() || !b.hasPlane()) continue;
                    // onlyA and onlyB now name each triangle's vertex off the common side.
                    const dvec3 u = a.v[(onlyA + 1) % 3], side = a.v[(onlyA + 2) % 3] - u;
                    auto across = [&](dvec3 p) { // from the side's line to p, at right angles
                        const dvec3 d = p - u;
                        return glm::normalize(d -
                                              side * (glm::dot(d, side) / glm::dot(side, side)));
                    };
                    if (glm::dot(across(a.v[onlyA]), across(b.v[onlyB])) > std::cos(foldAngle))
                        found(r.folded, ta, tb, "fold onto their common side");
                } else {
                    found(r.duplicates, ta, tb, "have the same vertices");
                }
            }
        i = end;
    }
    return r;
}

// ---------------------------------------------------------------------------------------------
// Triangles that face against the field.

struct TriangleFacing {
    size_t degenerate = 0; // no usable normal: height over the longest side under 1e-4 cell
    size_t flipped = 0;    // facing against the field's gradient at the centre
    double worstCos = 1;   // the least cosine between a judged triangle and the gradient
    std::string first;     // the first flipped or degenerate triangle

    std::string str() const {
        std::ostringstream s;
        s << flipped << " triangles flipped, " << degenerate
          << " degenerate, least cosine to the gradient " << worstCos;
        if (!first.empty()) s << "; first: " << first;
        return s.str();
    }
};

// Each triangle against the gradient of the CPU evaluator's field at its centre (tetrahedral
// differences a hundredth of a cell wide), for a mesh from a grid of cells of edge h. On the
// surface the field's gradient is the outward normal, and a little off it the normal of the
// nearest part of the surface, which a triangle lying along that part faces like; one that spans
// a sharp edge faces between its two sides. So a triangle facing more than a right angle away
// from the gradient is flipped. (Where two sheets of surface pass within a cell of each other,
// the grid does not tell them apart and this holds only roughly.) Bad triangles (see
// measureMesh) are skipped.
inline TriangleFacing checkTriangleFacing(const Mesh& mesh, const Evaluator& evaluator, float h) {
    TriangleFacing r;
    const float e = 0.01f * h;
    const glm::vec3 taps[4] = {{1, -1, -1}, {-1, -1, 1}, {-1, 1, -1}, {1, 1, 1}};
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
        const uint32_t* v = &mesh.indices[3 * t];
        if (v[0] >= mesh.vertexCount() || v[1] >= mesh.vertexCount() ||
            v[2] >= mesh.vertexCount() || v[0] == v[1] || v[1] == v[2] || v[2] == v[0])
            continue;
        const glm::dvec3 a(mesh.positions[v[0]]), b(mesh.positions[v[1]]), c(mesh.positions[v[2]]);
        const glm::dvec3 n = glm::cross(b - a, c - a);
        const double longest =
            std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
        auto note = [&](const char* what) {
            if (!r.first.empty()) return;
            std::ostringstream s;
            s.precision(7);
            s << "triangle " << t << " " << what << " at";
            for (const glm::dvec3& p : {a, b, c})
                s << " (" << p.x << " " << p.y << " " << p.z << ")";
            r.first = s.str();
        };
        if (!(glm::length(n) > 1e-4 * h * longest)) {
            ++r.degenerate;
            note("degenerate");
            continue;
        }
        const glm::vec3 centre((a + b + c) / 3.0);
        glm::dvec3 g(0.0);
        for (const glm::vec3& tap : taps)
            g += glm::dvec3(tap) * double(evaluator.distance(centre + tap * e));
        if (glm::length(g) <= 0.0) continue; // no direction to judge by
        const double cosine = glm::dot(glm::normalize(n), glm::normalize(g));
        r.worstCos = std::min(r.worstCos, cosine);
        if (cosine < 0.0) {
            ++r.flipped;
            note("flipped");
        }
    }
    return r;
}

struct NormalProperties {
    size_t notUnit = 0;  // | |n| - 1 | > 1e-3
    size_t inward = 0;   // pointing against the area-weighted normal of the triangles around it
    double worstDot = 1; // smallest cosine between a normal and its triangles' normal
    std::string str() const {
        std::ostringstream s;
        s << notUnit << " normals not of unit length, " << inward
          << " pointing inwards, smallest cosine to the faces " << worstDot;
        return s.str();
    }
};

// Vertices whose triangles have no usable normal (all degenerate) are not judged.
inline NormalProperties checkNormals(const Mesh& mesh) {
    NormalProperties r;
    std::vector<glm::dvec3> faceSum(mesh.vertexCount(), glm::dvec3(0.0));
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
        const uint32_t* v = &mesh.indices[3 * t];
        if (v[0] >= faceSum.size() || v[1] >= faceSum.size() || v[2] >= faceSum.size()) continue;
        const glm::dvec3 a(mesh.positions[v[0]]), b(mesh.positions[v[1]]), c(mesh.positions[v[2]]);
        const glm::dvec3 n = glm::cross(b - a, c - a); // length: twice the area
        for (int i = 0; i < 3; ++i)
            faceSum[v[i]] += n;
    }
    for (size_t i = 0; i < mesh.vertexCount(); ++i) {
        const glm::dvec3 n(mesh.normals[i]);
        if (std::abs(glm::length(n) - 1.0) > 1e-3) ++r.notUnit;
        const double len = glm::length(faceSum[i]);
        if (len < 1e-20) continue;
        const double cosine = glm::dot(n, faceSum[i]) / (len * std::max(glm::length(n), 1e-20));
        if (cosine < 0) ++r.inward;
        r.worstDot = std::min(r.worstDot, cosine);
    }
    return r;
}

struct MeshComparison {
    size_t verticesA = 0, verticesB = 0, trianglesA = 0, trianglesB = 0;
    size_t unmatchedVertices = 0; // vertices of A with no vertex of B within the tolerance
    size_t normalMismatches = 0;  // matched vertices whose normals differ by more than allowed
    size_t colorMismatches = 0;
    size_t unmatchedTriangles = 0; // triangles of A or B (orientation kept) missing in the other
    std::string firstProblem;

    bool same() const {
        return verticesA == verticesB && trianglesA == trianglesB && unmatchedVertices == 0 &&
               normalMismatches == 0 && colorMismatches == 0 && unmatchedTriangles == 0;
    }
    std::string str() const {
        std::ostringstream s;
        s << verticesA << " vs " << verticesB << " vertices, " << trianglesA << " vs " << trianglesB
          << " triangles; " << unmatchedVertices << " vertices unmatched, " << normalMismatches
          << " normals and " << colorMismatches << " colours differ, " << unmatchedTriangles
          << " triangles unmatched";
        if (!firstProblem.empty()) s << "; first: " << firstProblem;
        return s.str();
    }
};

// Compares two meshes regardless of the order of their vertices and triangles. Vertices match by
// position within `tolerance` (per coordinate); triangles match as cyclic triples, so a flipped
// triangle does not match. Vertices of B closer than the tolerance to each other (coincident
// vertices) are treated as one, so the triangle comparison does not depend on which one of them
// a vertex of A was paired with.
inline MeshComparison compareMeshes(const Mesh& a, const Mesh& b, float tolerance,
                                    float normalTolerance = 1e-3f, float colorTolerance = 1e-3f) {
    MeshComparison r;
    r.verticesA = a.vertexCount();
    r.verticesB = b.vertexCount();
    r.trianglesA = a.triangleCount();
    r.trianglesB = b.triangleCount();
    auto note = [&](const std::string& problem) {
        if (r.firstProblem.empty()) r.firstProblem = problem;
    };
    auto fmt = [](glm::vec3 v) {
        std::ostringstream s;
        s.precision(9);
        s << "(" << v.x << ", " << v.y << ", " << v.z << ")";
        return s.str();
    };

    // B's vertices in a hash grid of cells `tolerance` wide: a match lies in the 27 cells around.
    auto cellOf = [&](glm::vec3 p) { return glm::ivec3(glm::floor(p / tolerance)); };
    auto key = [](glm::ivec3 c) {
        return (uint64_t(uint32_t(c.x) & 0x1fffff) << 42) |
               (uint64_t(uint32_t(c.y) & 0x1fffff) << 21) | uint64_t(uint32_t(c.z) & 0x1fffff);
    };
    std::unordered_map<uint64_t, std::vector<uint32_t>> grid;
    for (uint32_t i = 0; i < b.vertexCount(); ++i)
        grid[key(cellOf(b.positions[i]))].push_back(i);
    auto near = [&](glm::vec3 p, glm::vec3 q) {
        const glm::vec3 diff = glm::abs(p - q);
        return diff.x <= tolerance && diff.y <= tolerance && diff.z <= tolerance;
    };
    auto forNeighbours = [&](glm::vec3 p, auto&& visit) {
        const glm::ivec3 c = cellOf(p);
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    auto it = grid.find(key(c + glm::ivec3(dx, dy, dz)));
                    if (it == grid.end()) continue;
                    for (uint32_t j : it->second)
                        if (near(p, b.positions[j])) visit(j);
                }
    };

    // Classes of coincident vertices of B (union-find), named by their smallest member.
    std::vector<uint32_t> parent(b.vertexCount());
    for (uint32_t i = 0; i < parent.size(); ++i)
        parent[i] = i;
    auto find = [&](uint32_t i) {
        while (parent[i] != i)
            i = parent[i] = parent[parent[i]];
        return i;
    };
    for (uint32_t i = 0; i < b.vertexCount(); ++i)
        forNeighbours(b.positions[i], [&](uint32_t j) {
            const uint32_t x = find(i), y = find(j);
            if (x != y) parent[std::max(x, y)] = std::min(x, y);
        });

    // Each vertex of A goes to the class of its nearest vertex of B; unmatched ones get a class of
    // their own beyond B's indices, so triangles that use them match nothing.
    std::vector<uint32_t> classOfA(a.vertexCount());
    for (uint32_t i = 0; i < a.vertexCount(); ++i) {
        const glm::vec3 p = a.positions[i];
        int64_t best = -1;
        float bestDistance = 0;
        forNeighbours(p, [&](uint32_t j) {
            const float dist = glm::length(p - b.positions[j]);
            if (best < 0 || dist < bestDistance) {
                best = j;
                bestDistance = dist;
            }
        });
        if (best < 0) {
            ++r.unmatchedVertices;
            note("vertex " + std::to_string(i) + " of A at " + fmt(p) + " has no match in B");
            classOfA[i] = uint32_t(b.vertexCount() + i);
            continue;
        }
        const uint32_t j = uint32_t(best);
        classOfA[i] = find(j);
        if (i < a.normals.size() && j < b.normals.size() &&
            glm::length(a.normals[i] - b.normals[j]) > normalTolerance) {
            ++r.normalMismatches;
            note("normal at " + fmt(p) + ": " + fmt(a.normals[i]) + " vs " + fmt(b.normals[j]));
        }
        if (i < a.colors.size() && j < b.colors.size() &&
            glm::length(a.colors[i] - b.colors[j]) > colorTolerance) {
            ++r.colorMismatches;
            note("colour at " + fmt(p) + ": " + fmt(a.colors[i]) + " vs " + fmt(b.colors[j]));
        }
    }

    // Triangles as class triples rotated to start at their smallest class, then as multisets.
    struct Tri {
        uint32_t v[3];
        bool operator<(const Tri& o) const {
            return std::lexicographical_compare(v, v + 3, o.v, o.v + 3);
        }
        bool operator==(const Tri& o) const {
            return v[0] == o.v[0] && v[1] == o.v[1] && v[2] == o.v[2];
        }
    };
    auto canonical = [](uint32_t x, uint32_t y, uint32_t z) {
        if (y < x && y <= z) return Tri{{y, z, x}};
        if (z < x && z < y) return Tri{{z, x, y}};
        return Tri{{x, y, z}};
    };
    std::vector<Tri> ta, tb;
    for (size_t t = 0; t < a.triangleCount(); ++t) {
        const uint32_t* v = &a.indices[3 * t];
        if (v[0] >= a.vertexCount() || v[1] >= a.vertexCount() || v[2] >= a.vertexCount()) {
            ta.push_back({{UINT32_MAX, UINT32_MAX, UINT32_MAX}});
            continue;
        }
        ta.push_back(canonical(classOfA[v[0]], classOfA[v[1]], classOfA[v[2]]));
    }
    for (size_t t = 0; t < b.triangleCount(); ++t) {
        const uint32_t* v = &b.indices[3 * t];
        if (v[0] >= b.vertexCount() || v[1] >= b.vertexCount() || v[2] >= b.vertexCount()) {
            tb.push_back({{UINT32_MAX - 1, UINT32_MAX - 1, UINT32_MAX - 1}});
            continue;
        }
        tb.push_back(canonical(find(v[0]), find(v[1]), find(v[2])));
    }
    std::sort(ta.begin(), ta.end());
    std::sort(tb.begin(), tb.end());
    std::vector<Tri> onlyA, onlyB;
    std::set_difference(ta.begin(), ta.end(), tb.begin(), tb.end(), std::back_inserter(onlyA));
    std::set_difference(tb.begin(), tb.end(), ta.begin(), ta.end(), std::back_inserter(onlyB));
    r.unmatchedTriangles = onlyA.size() + onlyB.size();
    auto describe = [&](const Tri& t) {
        std::string s;
        for (uint32_t c : t.v)
            s += c < b.vertexCount() ? fmt(b.positions[c]) : std::string("(unmatched)");
        return s;
    };
    if (!onlyA.empty()) note("triangle of A missing in B: " + describe(onlyA[0]));
    if (!onlyB.empty()) note("triangle of B missing in A: " + describe(onlyB[0]));
    return r;
}

} // namespace sdfcsg::test
