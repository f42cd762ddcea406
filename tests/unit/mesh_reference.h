// The mesh extraction algorithm on the CPU, written plainly, as the reference the GPU mesher is
// held to: the same grid, sign test, vertex placement, refinement, normals, colours and table
// (engine/src/mc_tables.h). Only the order of vertices and triangles differs from the GPU's.
#pragma once

#include "mc_tables.h"

#include <sdfcsg/eval.h>
#include <sdfcsg/mesh.h>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

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

// Meshes any field: `distance(p)` gives the signed value, `color(p)` the vertex colour.
template <class Distance, class Color>
ReferenceMesh referenceMeshOf(const Distance& distance, const Color& color,
                              const ReferenceGrid& grid, uint32_t refineSteps) {
    const glm::uvec3 n = grid.cells;
    const glm::uvec3 samples = n + 1u;
    auto sampleIndex = [&](glm::uvec3 s) {
        return (size_t(s.z) * samples.y + s.y) * samples.x + s.x;
    };
    auto position = [&](glm::uvec3 s) { return grid.origin + glm::vec3(s) * grid.voxelSize; };

    ReferenceMesh out;
    std::vector<float> d(size_t(samples.x) * samples.y * samples.z);
    for (uint32_t z = 0; z <= n.z; ++z)
        for (uint32_t y = 0; y <= n.y; ++y)
            for (uint32_t x = 0; x <= n.x; ++x) {
                const glm::uvec3 s(x, y, z);
                const float value = distance(position(s));
                d[sampleIndex(s)] = value;
                const bool boundary =
                    x == 0 || y == 0 || z == 0 || x == n.x || y == n.y || z == n.z;
                if (boundary && value < 0.0f) out.surfaceCut = true;
            }

    const float e = 0.05f * grid.voxelSize;
    auto gradient = [&](glm::vec3 p) {
        const glm::vec3 xyy(1, -1, -1), yyx(-1, -1, 1), yxy(-1, 1, -1), xxx(1, 1, 1);
        return xyy * distance(p + xyy * e) + yyx * distance(p + yyx * e) +
               yxy * distance(p + yxy * e) + xxx * distance(p + xxx * e);
    };

    // The vertex on the edge from sample s along `axis`, made on first use.
    std::vector<int64_t> vertexOfEdge(d.size() * 3, -1);
    Mesh& mesh = out.mesh;
    auto vertex = [&](glm::uvec3 s, int axis) {
        int64_t& slot = vertexOfEdge[sampleIndex(s) * 3 + size_t(axis)];
        if (slot >= 0) return uint32_t(slot);
        glm::uvec3 b = s;
        b[axis] += 1;
        const glm::vec3 pa = position(s), pb = position(b);
        const float da = d[sampleIndex(s)], db = d[sampleIndex(b)];
        float t = da / (da - db);
        float lo = 0.0f, hi = 1.0f, dlo = da, dhi = db;
        for (uint32_t k = 0; k < refineSteps; ++k) {
            const float dt = distance(pa + (pb - pa) * t);
            if ((dt < 0.0f) == (dlo < 0.0f)) {
                lo = t;
                dlo = dt;
            } else {
                hi = t;
                dhi = dt;
            }
            t = lo + (hi - lo) * (dlo / (dlo - dhi));
        }
        const glm::vec3 p = pa + (pb - pa) * t;
        const glm::vec3 g = gradient(p);
        glm::vec3 normal(0.0f);
        if (glm::length(g) > 1e-20f) {
            normal = glm::normalize(g);
        } else {
            normal[axis] = db > da ? 1.0f : -1.0f;
        }
        slot = int64_t(mesh.positions.size());
        mesh.positions.push_back(p);
        mesh.normals.push_back(normal);
        mesh.colors.push_back(color(p));
        return uint32_t(slot);
    };

    for (uint32_t z = 0; z < n.z; ++z)
        for (uint32_t y = 0; y < n.y; ++y)
            for (uint32_t x = 0; x < n.x; ++x) {
                const glm::uvec3 cell(x, y, z);
                auto corner = [&](int c) {
                    using detail::kCornerOffset;
                    return cell + glm::uvec3(kCornerOffset[c][0], kCornerOffset[c][1],
                                             kCornerOffset[c][2]);
                };
                unsigned cellCase = 0;
                for (int c = 0; c < 8; ++c)
                    if (d[sampleIndex(corner(c))] < 0.0f) cellCase |= 1u << c;
                for (int i = 0; i < 3 * detail::kTriCount[cellCase]; ++i) {
                    const int edge = detail::kTriTable[cellCase][i];
                    mesh.indices.push_back(
                        vertex(corner(detail::kEdgeCorners[edge][0]), detail::kEdgeAxis[edge]));
                }
            }
    return out;
}

inline ReferenceMesh referenceMesh(const Evaluator& evaluator, const ReferenceGrid& grid,
                                   uint32_t refineSteps = 2) {
    return referenceMeshOf([&](glm::vec3 p) { return evaluator.distance(p); },
                           [&](glm::vec3 p) { return evaluator.sample(p).color; }, grid,
                           refineSteps);
}

// The grid the GPU mesher reports having used.
inline ReferenceGrid gridOf(const MeshStats& stats) {
    return {stats.bounds.min, stats.voxelSize, stats.cells};
}

} // namespace sdfcsg::test
