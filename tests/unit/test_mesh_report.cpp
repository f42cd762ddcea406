// The mesh report (sdfcsg/mesh_report.h) on meshes made by hand, each broken in one known way;
// the GPU meshes of analytic solids are reported on in test_mesh.cpp.
#include <sdfcsg/mesh_report.h>

#include "mesh/mesh_dual.h"

#include <gtest/gtest.h>

#include <glm/vec3.hpp>

namespace {

using namespace sdfcsg;

// The tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1), its triangles facing outwards: volume 1/6.
Mesh tetrahedron(glm::vec3 offset = glm::vec3(0.0f)) {
    Mesh mesh;
    for (glm::vec3 p :
         {glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1)})
        mesh.positions.push_back(p + offset);
    mesh.normals.assign(4, glm::vec3(0.0f));
    mesh.colors.assign(4, glm::vec3(1.0f));
    mesh.indices = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    return mesh;
}

// `b` added to `a`, its vertices renumbered after a's.
Mesh joined(Mesh a, const Mesh& b) {
    const auto base = uint32_t(a.positions.size());
    a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
    a.normals.insert(a.normals.end(), b.normals.begin(), b.normals.end());
    a.colors.insert(a.colors.end(), b.colors.begin(), b.colors.end());
    for (uint32_t i : b.indices)
        a.indices.push_back(base + i);
    return a;
}

TEST(MeshReport, ATetrahedronIsWatertight) {
    const MeshReport r = reportMesh(tetrahedron());
    EXPECT_EQ(r.triangles, 4u);
    EXPECT_EQ(r.vertices, 4u);
    EXPECT_EQ(r.edges, 6u);
    EXPECT_EQ(r.euler, 2);
    EXPECT_EQ(r.shells, 1u);
    EXPECT_TRUE(r.watertight());
    EXPECT_EQ(r.genus(), 0);
    EXPECT_NEAR(r.volume, 1.0 / 6.0, 1e-12);
    EXPECT_NEAR(r.area, 1.5 + 0.5 * std::sqrt(3.0), 1e-6);
    EXPECT_EQ(reportJson(r),
              "{\"triangles\": 4, \"vertices\": 4, \"degenerate_triangles\": 0, \"edges\": 6, "
              "\"boundary_edges\": 0, \"non_manifold_edges\": 0, \"misoriented_edges\": 0, "
              "\"self_intersections\": 0, \"closed\": true, \"manifold\": true, \"oriented\": "
              "true, \"watertight\": true, \"shells\": 1, \"euler\": 2, \"genus\": 0, \"volume\": "
              "0.166666667, \"area\": 2.3660254, \"bounds\": {\"min\": [0, 0, 0], \"max\": [1, 1, "
              "1]}}\n");
}

TEST(MeshReport, EachFlawIsCounted) {
    Mesh open = tetrahedron();
    open.indices.resize(9);
    MeshReport r = reportMesh(open);
    EXPECT_EQ(r.boundaryEdges, 3u);
    EXPECT_FALSE(r.closed());
    EXPECT_FALSE(r.watertight());
    EXPECT_EQ(r.genus(), -1);

    Mesh flipped = tetrahedron();
    std::swap(flipped.indices[10], flipped.indices[11]);
    r = reportMesh(flipped);
    EXPECT_EQ(r.misorientedEdges, 3u);
    EXPECT_FALSE(r.oriented());

    Mesh inward = tetrahedron();
    for (size_t t = 0; t < 4; ++t)
        std::swap(inward.indices[3 * t + 1], inward.indices[3 * t + 2]);
    r = reportMesh(inward);
    EXPECT_EQ(r.misorientedEdges, 0u);
    EXPECT_NEAR(r.volume, -1.0 / 6.0, 1e-12);
    EXPECT_FALSE(r.oriented());

    Mesh doubled = tetrahedron();
    doubled.indices.insert(doubled.indices.end(), {1, 2, 3});
    r = reportMesh(doubled);
    EXPECT_EQ(r.nonManifoldEdges, 3u);
    EXPECT_EQ(r.selfIntersections, 1u); // the two copies of one triangle
    EXPECT_FALSE(r.manifold());

    Mesh bad = tetrahedron();
    bad.indices.insert(bad.indices.end(), {0, 0, 1, 0, 1, 9});
    r = reportMesh(bad);
    EXPECT_EQ(r.degenerateTriangles, 2u);
    EXPECT_EQ(r.euler, 2); // the unusable triangles take no part
    EXPECT_FALSE(r.manifold());

    Mesh flat = tetrahedron();
    flat.positions[3] = glm::vec3(0.5f, 0.5f, 0.0f); // on the edge from 1 to 2: no area there
    r = reportMesh(flat);
    EXPECT_EQ(r.degenerateTriangles, 1u);
}

TEST(MeshReport, ShellsAndSelfIntersections) {
    const MeshReport apart = reportMesh(joined(tetrahedron(), tetrahedron(glm::vec3(3.0f))));
    EXPECT_EQ(apart.shells, 2u);
    EXPECT_EQ(apart.euler, 4);
    EXPECT_TRUE(apart.watertight());
    EXPECT_EQ(apart.genus(), 0);
    EXPECT_NEAR(apart.volume, 2.0 / 6.0, 1e-12);

    const MeshReport crossing =
        reportMesh(joined(tetrahedron(), tetrahedron(glm::vec3(0.2f, 0.2f, 0.2f))));
    EXPECT_EQ(crossing.shells, 2u);
    EXPECT_GT(crossing.selfIntersections, 0u);
    EXPECT_FALSE(crossing.watertight());
    EXPECT_EQ(crossing.genus(), -1);
}

// Two tetrahedra that touch along an edge, sharing its two vertices: the edge joins four
// triangles until splitTouchingSheets gives each solid its own copies of the two.
TEST(MeshReport, SheetsTouchingAlongAnEdgeAreSplit) {
    Mesh mesh = tetrahedron();
    Mesh other = tetrahedron();
    for (glm::vec3& p : other.positions)
        p = glm::vec3(-p.x, -p.y, p.z); // turned half a turn about z: faces still outwards
    Mesh both = joined(mesh, other);
    for (uint32_t& i : both.indices) { // the second's corners 0 and 3 are the first's
        if (i == 4) i = 0;
        if (i == 7) i = 3;
    }
    MeshReport r = reportMesh(both);
    EXPECT_EQ(r.nonManifoldEdges, 1u);
    EXPECT_EQ(r.misorientedEdges, 0u);
    EXPECT_EQ(detail::splitTouchingSheets(both), 1u);
    r = reportMesh(both);
    EXPECT_EQ(r.nonManifoldEdges, 0u);
    EXPECT_EQ(r.misorientedEdges, 0u);
    EXPECT_EQ(r.boundaryEdges, 0u);
    EXPECT_EQ(r.shells, 2u);
    EXPECT_EQ(r.euler, 4);
    EXPECT_EQ(both.vertexCount(), 10u);               // 8 used, 2 unused, 2 copies
    EXPECT_EQ(detail::splitTouchingSheets(both), 0u); // nothing left to split
}

TEST(MeshReport, AnEmptyMeshHasNoBounds) {
    const MeshReport r = reportMesh(Mesh{});
    EXPECT_FALSE(r.watertight());
    EXPECT_EQ(reportJson(r).substr(reportJson(r).size() - 16), "\"bounds\": null}\n");
}

} // namespace
