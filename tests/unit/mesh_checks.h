// Properties of a triangle mesh that tests assert on: closed and manifold (every edge shared by two
// triangles in opposite directions), Euler characteristic, signed volume, area, distance of the
// vertices and of points across the triangles from the surface, outward normals, triangles that
// intersect each other or face against the field, and an order-independent comparison of two
// meshes.
#pragma once

#include "mesh/mesh_simplify.h"
#include "mesh/self_intersections.h"

#include <sdfcsg/compile.h>
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

// Triangles that intersect each other: engine/src/mesh/self_intersections.h.
using detail::findSelfIntersections;
using detail::SelfIntersections;

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
    // Scenes of pruned tapes by their pruned field, the whole tree near the surface (prune tests).
    const bool pruned = evaluator.nodes().size() >= kTapeMinNodes;
    auto field = [&](glm::vec3 p) {
        return pruned ? evaluator.prunedDistance(p) : evaluator.distance(p);
    };
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
            g += glm::dvec3(tap) * double(field(centre + tap * e));
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
