// The mesh extraction algorithms on the CPU, written plainly, as the reference the GPU mesher is
// held to: the same grid, sign test, edge points, refinement, normals, colours and table
// (engine/src/mesh/mc_tables.h), and for dual contouring the same pieces, vertex placement and
// quads. Only the order of vertices and triangles differs from the GPU's.
#pragma once

#include "mesh/mc_tables.h"
#include "mesh/mesh_dual.h"

#include <sdfcsg/eval.h>
#include <sdfcsg/mesh.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace sdfcsg::test {

// Samples at integer points s in [0, cells] (inclusive), at origin + vec3(s) * voxelSize.
struct ReferenceGrid {
    glm::vec3 origin{0.0f};
    float voxelSize = 1.0f;
    glm::uvec3 cells{1};
};

struct ReferenceMesh {
    Mesh mesh;
    bool surfaceCut = false; // some sample on the grid's boundary is inside
};

// The field sampled on the grid, and the point of each crossed edge (made on first use) with its
// normal and colour, in a mesh whose indices stay empty.
template <class Distance, class Color> struct ReferenceSamples {
    const Distance& distance;
    const Color& color;
    ReferenceGrid grid;
    uint32_t refineSteps;
    // The normal's taps, in cells: their size, and how far off the point two more centres lie
    // along (1, 2, 4) / sqrt(21) (shaders/mesh_common.glsl), or 0.
    float taps = 0.05f, tapOffset = 0.0f;
    glm::uvec3 samples;
    std::vector<float> d;
    std::vector<int64_t> pointOfEdge;
    Mesh points;
    std::vector<glm::vec3> others; // per point, the second normal (dual contouring)
    bool surfaceCut = false;

    ReferenceSamples(const Distance& dist, const Color& col, const ReferenceGrid& g, uint32_t steps)
        : distance(dist), color(col), grid(g), refineSteps(steps), samples(g.cells + 1u) {
        d.resize(size_t(samples.x) * samples.y * samples.z);
        const glm::uvec3 n = grid.cells;
        for (uint32_t z = 0; z <= n.z; ++z)
            for (uint32_t y = 0; y <= n.y; ++y)
                for (uint32_t x = 0; x <= n.x; ++x) {
                    const glm::uvec3 s(x, y, z);
                    const float value = distance(position(s));
                    d[index(s)] = value;
                    const bool boundary =
                        x == 0 || y == 0 || z == 0 || x == n.x || y == n.y || z == n.z;
                    if (boundary && value < 0.0f) surfaceCut = true;
                }
        pointOfEdge.assign(d.size() * 3, -1);
    }
    size_t index(glm::uvec3 s) const { return (size_t(s.z) * samples.y + s.y) * samples.x + s.x; }
    glm::vec3 position(glm::uvec3 s) const { return grid.origin + glm::vec3(s) * grid.voxelSize; }
    bool inside(glm::uvec3 s) const { return d[index(s)] < 0.0f; }

    unsigned cellCase(glm::uvec3 cell) const {
        unsigned c = 0;
        for (int k = 0; k < 8; ++k)
            if (inside(corner(cell, k))) c |= 1u << k;
        return c;
    }
    static glm::uvec3 corner(glm::uvec3 cell, int k) {
        using detail::kCornerOffset;
        return cell + glm::uvec3(kCornerOffset[k][0], kCornerOffset[k][1], kCornerOffset[k][2]);
    }

    // The point on the edge from sample s along `axis`.
    uint32_t point(glm::uvec3 s, int axis) {
        int64_t& slot = pointOfEdge[index(s) * 3 + size_t(axis)];
        if (slot >= 0) return uint32_t(slot);
        glm::uvec3 b = s;
        b[axis] += 1;
        const glm::vec3 pa = position(s), pb = position(b);
        const float da = d[index(s)], db = d[index(b)];
        float t = da / (da - db);
        float lo = 0.0f, hi = 1.0f, dlo = da, dhi = db;
        const float keep = tapOffset > 0.0f ? 0.5f : 1.0f; // Illinois for dual contouring
        for (uint32_t k = 0; k < refineSteps; ++k) {
            const float dt = distance(pa + (pb - pa) * t);
            if ((dt < 0.0f) == (dlo < 0.0f)) {
                lo = t;
                dlo = dt;
                dhi *= keep;
            } else {
                hi = t;
                dhi = dt;
                dlo *= keep;
            }
            t = lo + (hi - lo) * (dlo / (dlo - dhi));
        }
        const glm::vec3 p = pa + (pb - pa) * t;
        const float e = taps * grid.voxelSize;
        const glm::vec3 offset = tapOffset * grid.voxelSize * glm::normalize(glm::vec3(1, 2, 4));
        const glm::vec3 xyy(1, -1, -1), yyx(-1, -1, 1), yxy(-1, 1, -1), xxx(1, 1, 1);
        // The gradient around the point; for dual contouring also around centres `offset` off
        // it either way, which where they disagree are the normals of a sharp edge's two faces
        // (placeVertices() in shaders/mesh_field.comp).
        std::vector<glm::vec3> gradients;
        for (float side : {0.0f, 1.0f, -1.0f}) {
            // Only where the gradient is a blend of two faces (kBlendedGradient in
            // shaders/mesh_common.glsl).
            if (side != 0.0f && (tapOffset == 0.0f || std::abs(glm::length(gradients[0]) -
                                                               4.0f * e) <= 0.001f * 4.0f * e))
                break;
            const glm::vec3 c = p + side * offset;
            gradients.push_back(xyy * distance(c + xyy * e) + yyx * distance(c + yyx * e) +
                                yxy * distance(c + yxy * e) + xxx * distance(c + xxx * e));
        }
        glm::vec3 g = gradients[0], other = g;
        if (gradients.size() == 3) {
            const glm::vec3 ahead = glm::normalize(gradients[1]);
            const glm::vec3 behind = glm::normalize(gradients[2]);
            if (glm::dot(ahead, behind) < 0.98f) {
                g = ahead;
                other = behind;
            }
        }
        glm::vec3 normal(0.0f);
        if (glm::length(g) > 1e-20f) {
            normal = glm::normalize(g);
        } else {
            normal[axis] = db > da ? 1.0f : -1.0f;
        }
        other = glm::length(other) > 1e-20f ? glm::normalize(other) : normal;
        others.push_back(other);
        slot = int64_t(points.positions.size());
        points.positions.push_back(p);
        points.normals.push_back(normal);
        points.colors.push_back(color(p));
        return uint32_t(slot);
    }
    uint32_t point(glm::uvec3 cell, int edge, int) {
        return point(corner(cell, detail::kEdgeCorners[edge][0]), detail::kEdgeAxis[edge]);
    }
};

// Meshes any field by marching cubes: `distance(p)` gives the signed value, `color(p)` the
// vertex colour.
template <class Distance, class Color>
ReferenceMesh referenceMeshOf(const Distance& distance, const Color& color,
                              const ReferenceGrid& grid, uint32_t refineSteps) {
    ReferenceSamples<Distance, Color> field(distance, color, grid, refineSteps);
    const glm::uvec3 n = grid.cells;
    std::vector<uint32_t> indices;
    for (uint32_t z = 0; z < n.z; ++z)
        for (uint32_t y = 0; y < n.y; ++y)
            for (uint32_t x = 0; x < n.x; ++x) {
                const glm::uvec3 cell(x, y, z);
                const unsigned cellCase = field.cellCase(cell);
                for (int i = 0; i < 3 * detail::kTriCount[cellCase]; ++i)
                    indices.push_back(field.point(cell, detail::kTriTable[cellCase][i], 0));
            }
    ReferenceMesh out;
    out.mesh = std::move(field.points);
    out.mesh.indices = std::move(indices);
    out.surfaceCut = field.surfaceCut;
    return out;
}

// Dual contouring's vertex for the planes through points[k] with normals normals[k] and
// others[k] (the same, or the other face's at a sharp edge), kept in the
// cell [lo, lo + h]: the mass point plus the least-squares step along the eigenvectors of
// sum n n^T whose eigenvalues reach a hundredth of the largest; outside the cell, moved along
// the weakest of them into it where it can be, else clamped, or for a slab (two normals more
// than 143 degrees apart) the mass point (solveQef() in shaders/mesh_triangles.comp).
inline glm::vec3 referenceQef(const std::vector<glm::vec3>& points,
                              const std::vector<glm::vec3>& normals,
                              const std::vector<glm::vec3>& others, glm::vec3 lo, float h) {
    glm::dvec3 mass(0.0);
    for (const glm::vec3& p : points)
        mass += glm::dvec3(p);
    mass /= double(points.size());
    double a[3][3] = {}, b[3] = {};
    for (size_t k = 0; k < points.size(); ++k)
        for (const glm::vec3& plane : {normals[k], others[k]}) {
            const glm::dvec3 nk(plane);
            const double offset = glm::dot(nk, glm::dvec3(points[k]) - mass);
            for (int i = 0; i < 3; ++i) {
                b[i] += nk[i] * offset;
                for (int j = 0; j < 3; ++j)
                    a[i][j] += nk[i] * nk[j];
            }
        }
    // Flat or gently curved: the mass point moved onto the mean plane (kFlat in
    // shaders/mesh_triangles.comp).
    float leastCos = 1.0f;
    glm::vec3 mean(0.0f);
    for (size_t k = 0; k < points.size(); ++k) {
        leastCos = std::min(
            leastCos, std::min(glm::dot(normals[k], normals[0]), glm::dot(others[k], normals[0])));
        mean += normals[k];
    }
    if (leastCos > 0.995f) {
        const glm::dvec3 m = glm::normalize(glm::dvec3(mean));
        double mam = 0.0;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                mam += m[i] * a[i][j] * m[j];
        const glm::dvec3 x = mass + m * (glm::dot(m, glm::dvec3(b[0], b[1], b[2])) / mam);
        return glm::clamp(glm::vec3(x), lo, lo + glm::vec3(h));
    }
    double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}; // v[i][k]: row i of eigenvector k
    for (int sweep = 0; sweep < 10; ++sweep)
        for (auto [p, q] : {std::pair{0, 1}, {0, 2}, {1, 2}}) {
            if (std::abs(a[p][q]) < 1e-15) continue;
            const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            const double t =
                (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
            const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
            for (int k = 0; k < 3; ++k) { // a = a J, v = v J
                const double akp = a[k][p], akq = a[k][q];
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
                const double vkp = v[k][p], vkq = v[k][q];
                v[k][p] = c * vkp - s * vkq;
                v[k][q] = s * vkp + c * vkq;
            }
            for (int k = 0; k < 3; ++k) { // a = J^T a
                const double apk = a[p][k], aqk = a[q][k];
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
        }
    const glm::dvec3 lambda(a[0][0], a[1][1], a[2][2]);
    const double largest = std::max(lambda.x, std::max(lambda.y, lambda.z));
    const int weakest = lambda.x <= lambda.y && lambda.x <= lambda.z ? 0
                        : lambda.y <= lambda.z                       ? 1
                                                                     : 2;
    auto eigenvector = [&](int k) { return glm::dvec3(v[0][k], v[1][k], v[2][k]); };
    const glm::dvec3 atb(b[0], b[1], b[2]);
    glm::dvec3 base = mass;
    int rank = 0;
    for (int k = 0; k < 3; ++k) {
        if (!(lambda[k] > 0.01 * largest && lambda[k] > 1e-12)) continue;
        ++rank;
        if (k != weakest) base += eigenvector(k) * (glm::dot(eigenvector(k), atb) / lambda[k]);
    }
    const glm::dvec3 dir = eigenvector(weakest);
    const double wanted = rank == 3 ? glm::dot(dir, atb) / lambda[weakest] : 0.0;
    const glm::dvec3 best = base + dir * wanted;
    const glm::dvec3 dlo(lo), dhi(glm::dvec3(lo) + double(h));
    auto inCell = [&](glm::dvec3 x) {
        return glm::all(glm::greaterThanEqual(x, dlo)) && glm::all(glm::lessThanEqual(x, dhi));
    };
    if (inCell(best)) return glm::vec3(best);
    if (rank >= 2) {
        // The part of the line base + s dir inside the cell.
        double s0 = -1e30, s1 = 1e30;
        for (int i = 0; i < 3; ++i) {
            if (std::abs(dir[i]) < 1e-6) {
                if (base[i] < dlo[i] || base[i] > dhi[i]) s0 = 1e30;
                continue;
            }
            const double ta = (dlo[i] - base[i]) / dir[i], tb = (dhi[i] - base[i]) / dir[i];
            s0 = std::max(s0, std::min(ta, tb));
            s1 = std::min(s1, std::max(ta, tb));
        }
        if (s0 <= s1)
            return glm::clamp(glm::vec3(base + dir * std::clamp(wanted, s0, s1)), lo,
                              lo + glm::vec3(h));
    }
    if (leastCos < -0.8f) return glm::vec3(mass); // kSlab
    return glm::clamp(glm::vec3(best), lo, lo + glm::vec3(h));
}

// Meshes any field by dual contouring: one vertex per piece of surface in each cell, one quad
// per crossed edge whose four cells lie in the grid, folded by detail::foldQuads.
template <class Distance, class Color>
ReferenceMesh referenceDualMeshOf(const Distance& distance, const Color& color,
                                  const ReferenceGrid& grid, uint32_t refineSteps) {
    ReferenceSamples<Distance, Color> field(distance, color, grid, refineSteps);
    field.taps = 0.02f;
    field.tapOffset = 0.25f;
    const glm::uvec3 n = grid.cells;
    ReferenceMesh out;
    Mesh& mesh = out.mesh;
    auto cellIndex = [&](glm::uvec3 c) { return (size_t(c.z) * n.y + c.y) * n.x + c.x; };
    std::vector<uint32_t> firstVertex(size_t(n.x) * n.y * n.z, 0);
    std::vector<glm::vec3> smooth;             // per vertex: the mean of its edge points
    std::vector<detail::EdgePoint> edgePoints; // per quad: its edge point, numbered in quadEdges
    std::vector<uint32_t> quadEdges;
    for (uint32_t z = 0; z < n.z; ++z)
        for (uint32_t y = 0; y < n.y; ++y)
            for (uint32_t x = 0; x < n.x; ++x) {
                const glm::uvec3 cell(x, y, z);
                const detail::CellPatches pieces = detail::cellPatches(field.cellCase(cell));
                firstVertex[cellIndex(cell)] = uint32_t(mesh.positions.size());
                for (int piece = 0; piece < pieces.count; ++piece) {
                    std::vector<glm::vec3> points, normals, others, colours;
                    glm::vec3 normal(0.0f);
                    for (int e = 0; e < 12; ++e) {
                        if (pieces.patch[e] != piece) continue;
                        const uint32_t k = field.point(cell, e, 0);
                        points.push_back(field.points.positions[k]);
                        normals.push_back(field.points.normals[k]);
                        others.push_back(field.others[k]);
                        normal += field.points.normals[k] + field.others[k];
                        colours.push_back(field.points.colors[k]);
                    }
                    // kInset in shaders/mesh_triangles.comp: off the cell's faces.
                    const glm::vec3 lo = field.position(cell);
                    const glm::vec3 p = glm::clamp(
                        referenceQef(points, normals, others, lo, grid.voxelSize),
                        lo + 0.005f * grid.voxelSize, lo + (1.0f - 0.005f) * grid.voxelSize);
                    size_t nearest = 0; // its colour is the vertex's
                    for (size_t k = 1; k < points.size(); ++k)
                        if (glm::dot(points[k] - p, points[k] - p) <
                            glm::dot(points[nearest] - p, points[nearest] - p))
                            nearest = k;
                    mesh.positions.push_back(p);
                    glm::vec3 mass(0.0f);
                    for (const glm::vec3& point : points)
                        mass += point;
                    smooth.push_back(glm::clamp(mass / float(points.size()),
                                                lo + 0.005f * grid.voxelSize,
                                                lo + (1.0f - 0.005f) * grid.voxelSize));
                    mesh.normals.push_back(glm::length(normal) > 0.1f ? glm::normalize(normal)
                                                                      : normals[0]);
                    mesh.colors.push_back(colours[nearest]);
                }
            }
    auto vertexOf = [&](glm::uvec3 cell, glm::uvec3 lowerCorner, int axis) {
        int edge = -1;
        for (int e = 0; e < 12; ++e) {
            const int* o = detail::kCornerOffset[detail::kEdgeCorners[e][0]];
            if (detail::kEdgeAxis[e] == axis && glm::uvec3(o[0], o[1], o[2]) == lowerCorner)
                edge = e;
        }
        const detail::CellPatches pieces = detail::cellPatches(field.cellCase(cell));
        return firstVertex[cellIndex(cell)] + uint32_t(pieces.patch[edge]);
    };
    for (uint32_t z = 0; z <= n.z; ++z)
        for (uint32_t y = 0; y <= n.y; ++y)
            for (uint32_t x = 0; x <= n.x; ++x)
                for (int axis = 0; axis < 3; ++axis) {
                    const glm::uvec3 s(x, y, z);
                    glm::uvec3 end = s;
                    end[axis] += 1;
                    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
                    if (s[axis] >= n[axis] || s[u] == 0 || s[u] >= n[u] || s[v] == 0 ||
                        s[v] >= n[v] || field.inside(s) == field.inside(end))
                        continue;
                    glm::uvec3 du(0), dv(0);
                    du[u] = 1;
                    dv[v] = 1;
                    // The four cells around the edge, counter-clockwise seen from its upper end.
                    const glm::uvec3 cells[4] = {s - du - dv, s - dv, s, s - du};
                    uint32_t q[4];
                    for (int k = 0; k < 4; ++k)
                        q[k] = vertexOf(cells[k], s - cells[k], axis);
                    uint32_t quad[2][6] = {{q[0], q[3], q[2], q[0], q[2], q[1]},
                                           {q[0], q[1], q[2], q[0], q[2], q[3]}};
                    uint32_t* t = quad[field.inside(s) ? 1 : 0];
                    std::rotate(t + 3, t + 3 + axis, t + 6); // names the axis (foldQuads)
                    mesh.indices.insert(mesh.indices.end(), t, t + 6);
                    const uint32_t k = field.point(s, axis);
                    const glm::vec3 c = field.points.colors[k];
                    quadEdges.push_back(uint32_t(edgePoints.size()));
                    edgePoints.push_back({field.points.positions[k], c.r, field.points.normals[k],
                                          c.g, field.others[k], c.b});
                }
    // The host steps of Extraction::finish() in engine/src/mesh/mesh.cpp.
    for (std::vector<glm::vec3>* positions : {&mesh.positions, &smooth})
        detail::pullToSurface(*positions, mesh.indices, quadEdges, edgePoints.data(), grid.origin,
                              grid.voxelSize, distance, positions != &smooth);
    detail::foldQuads(mesh, smooth, distance, grid.voxelSize);
    const size_t copiesFrom = mesh.vertexCount();
    detail::splitTouchingSheets(mesh);
    detail::separateCrossings(mesh, copiesFrom, quadEdges, edgePoints.data(), grid.origin,
                              grid.voxelSize, distance);
    out.surfaceCut = field.surfaceCut;
    return out;
}

inline ReferenceMesh referenceMesh(const Evaluator& evaluator, const ReferenceGrid& grid,
                                   uint32_t refineSteps = 3,
                                   MeshMethod method = MeshMethod::MarchingCubes) {
    if (method == MeshMethod::DualContouring)
        return referenceDualMeshOf([&](glm::vec3 p) { return evaluator.distance(p); },
                                   [&](glm::vec3 p) { return evaluator.sample(p).color; }, grid,
                                   refineSteps);
    return referenceMeshOf([&](glm::vec3 p) { return evaluator.distance(p); },
                           [&](glm::vec3 p) { return evaluator.sample(p).color; }, grid,
                           refineSteps);
}

// The grid the GPU mesher reports having used.
inline ReferenceGrid gridOf(const MeshStats& stats) {
    return {stats.bounds.min, stats.voxelSize, stats.cells};
}

} // namespace sdfcsg::test
