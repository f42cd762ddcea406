// The marching-cubes tables (engine/src/mesh/mc_tables.h) and the CPU reference mesher
// (mesh_reference.h) on their own, without a GPU: every table case is checked against the rule
// that makes meshes closed and manifold, and meshes of known solids have the right volume, area,
// topology and orientation.
#include "mesh/mc_tables.h"
#include "mesh_checks.h"
#include "mesh_reference.h"
#include "scene_build_util.h"

#include <gtest/gtest.h>

#include <glm/common.hpp>
#include <glm/vector_relational.hpp>

#include <array>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <utility>

namespace sdfcsg::test {
namespace {

using detail::kCornerOffset;
using detail::kEdgeAxis;
using detail::kEdgeCorners;
using detail::kTriCount;
using detail::kTriTable;

constexpr double kPi = std::numbers::pi;

// ---------------------------------------------------------------------------------------------
// The tables, case by case.

glm::ivec3 cornerOffset(int c) {
    return {kCornerOffset[c][0], kCornerOffset[c][1], kCornerOffset[c][2]};
}

// The edge between two corners, or -1.
int edgeBetween(int a, int b) {
    for (int e = 0; e < 12; ++e)
        if ((kEdgeCorners[e][0] == a && kEdgeCorners[e][1] == b) ||
            (kEdgeCorners[e][0] == b && kEdgeCorners[e][1] == a))
            return e;
    return -1;
}

// Face (axis, side) of the cube: its corners in cyclic order.
std::array<int, 4> faceCorners(int axis, int side) {
    const int u = (axis + 1) % 3, w = (axis + 2) % 3;
    std::array<int, 4> corners{};
    const int uw[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int i = 0; i < 4; ++i)
        for (int c = 0; c < 8; ++c) {
            const glm::ivec3 o = cornerOffset(c);
            if (o[axis] == side && o[u] == uw[i][0] && o[w] == uw[i][1]) corners[size_t(i)] = c;
        }
    return corners;
}

bool edgeOnFace(int e, int axis, int side) {
    return kEdgeAxis[e] != axis && kCornerOffset[kEdgeCorners[e][0]][axis] == side;
}

bool shareFace(int e1, int e2) {
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side)
            if (edgeOnFace(e1, axis, side) && edgeOnFace(e2, axis, side)) return true;
    return false;
}

bool inside(int cellCase, int corner) {
    return (cellCase >> corner) & 1;
}

// Directed edges (vertex on edge a -> vertex on edge b) of case c's triangles, with their uses.
std::map<std::pair<int, int>, int> directedEdges(int c) {
    std::map<std::pair<int, int>, int> uses;
    for (int t = 0; t < kTriCount[c]; ++t)
        for (int i = 0; i < 3; ++i)
            ++uses[{kTriTable[c][3 * t + i], kTriTable[c][3 * t + (i + 1) % 3]}];
    return uses;
}

// Directed edges used by one triangle of the cell and not in reverse: where the cell's surface
// meets its faces.
std::set<std::pair<int, int>> boundarySegments(int c) {
    auto uses = directedEdges(c);
    std::set<std::pair<int, int>> out;
    for (const auto& [edge, count] : uses)
        if (count == 1 && !uses.count({edge.second, edge.first})) out.insert(edge);
    return out;
}

TEST(MarchingCubesTable, EdgesRunFromTheirLowerCornerAlongTheirAxis) {
    for (int e = 0; e < 12; ++e) {
        const glm::ivec3 step = cornerOffset(kEdgeCorners[e][1]) - cornerOffset(kEdgeCorners[e][0]);
        glm::ivec3 unit(0);
        unit[kEdgeAxis[e]] = 1;
        EXPECT_EQ(step, unit) << "edge " << e;
    }
    std::set<std::array<int, 3>> offsets;
    for (int c = 0; c < 8; ++c) {
        for (int i = 0; i < 3; ++i)
            EXPECT_TRUE(kCornerOffset[c][i] == 0 || kCornerOffset[c][i] == 1);
        offsets.insert({kCornerOffset[c][0], kCornerOffset[c][1], kCornerOffset[c][2]});
    }
    EXPECT_EQ(offsets.size(), 8u) << "the corners are the cube's eight corners";
}

TEST(MarchingCubesTable, CountsMatchTheTerminators) {
    for (int c = 0; c < 256; ++c) {
        ASSERT_LE(kTriCount[c], 5) << "case " << c;
        for (int i = 0; i < 16; ++i) {
            if (i < 3 * kTriCount[c]) {
                EXPECT_TRUE(kTriTable[c][i] >= 0 && kTriTable[c][i] < 12)
                    << "case " << c << " entry " << i;
            } else {
                EXPECT_EQ(kTriTable[c][i], -1) << "case " << c << " entry " << i;
            }
        }
    }
    EXPECT_EQ(kTriCount[0], 0);
    EXPECT_EQ(kTriCount[255], 0);
}

TEST(MarchingCubesTable, EveryCaseUsesExactlyItsCrossedEdges) {
    for (int c = 0; c < 256; ++c) {
        std::set<int> used(kTriTable[c], kTriTable[c] + 3 * kTriCount[c]);
        for (int e = 0; e < 12; ++e) {
            const bool crossed = inside(c, kEdgeCorners[e][0]) != inside(c, kEdgeCorners[e][1]);
            EXPECT_EQ(used.count(e) == 1, crossed) << "case " << c << " edge " << e;
        }
        for (int t = 0; t < kTriCount[c]; ++t) {
            const int8_t* v = &kTriTable[c][3 * t];
            EXPECT_TRUE(v[0] != v[1] && v[1] != v[2] && v[2] != v[0])
                << "case " << c << " triangle " << t;
        }
    }
}

// Within a cell, the triangles form disks: each interior diagonal is used twice in opposite
// directions and joins two vertices that share no cube face (so no other cell holds it), and the
// boundary is exactly the face segments: on each face the crossed edges paired up, and on an
// ambiguous face each inside corner cut off by its own segment.
TEST(MarchingCubesTable, CellSurfacesMeetTheFacesByTheFixedRule) {
    for (int c = 0; c < 256; ++c) {
        auto uses = directedEdges(c);
        std::set<std::set<int>> segments;
        for (const auto& [edge, count] : uses) {
            EXPECT_EQ(count, 1) << "case " << c << ": edge " << edge.first << "->" << edge.second
                                << " used twice in the same direction";
            if (uses.count({edge.second, edge.first})) {
                EXPECT_FALSE(shareFace(edge.first, edge.second))
                    << "case " << c << ": diagonal " << edge.first << "-" << edge.second
                    << " lies on a cube face, where the neighbour cell could use it too";
            } else {
                EXPECT_TRUE(shareFace(edge.first, edge.second))
                    << "case " << c << ": open edge " << edge.first << "-" << edge.second
                    << " is not on a cube face";
                segments.insert({edge.first, edge.second});
            }
        }
        std::set<std::set<int>> expected;
        for (int axis = 0; axis < 3; ++axis)
            for (int side = 0; side < 2; ++side) {
                const auto f = faceCorners(axis, side);
                auto at = [&](int i) { return f[size_t((i + 4) % 4)]; };
                int count = 0;
                for (int i = 0; i < 4; ++i)
                    count += inside(c, at(i));
                const bool ambiguous = count == 2 && inside(c, at(0)) == inside(c, at(2));
                if (ambiguous) {
                    for (int i = 0; i < 4; ++i)
                        if (inside(c, at(i)))
                            expected.insert(
                                {edgeBetween(at(i - 1), at(i)), edgeBetween(at(i), at(i + 1))});
                } else if (count > 0 && count < 4) {
                    std::set<int> crossed;
                    for (int i = 0; i < 4; ++i)
                        if (inside(c, at(i)) != inside(c, at(i + 1)))
                            crossed.insert(edgeBetween(at(i), at(i + 1)));
                    expected.insert(crossed);
                }
            }
        EXPECT_EQ(segments, expected) << "case " << c;
    }
}

// Two cells that share a face agree on its segments and run them in opposite directions, for
// every pair of cases that agree on the shared samples.
TEST(MarchingCubesTable, NeighbouringCellsJoinWithOppositeDirections) {
    for (int axis = 0; axis < 3; ++axis) {
        const auto upper = faceCorners(axis, 1), lower = faceCorners(axis, 0);
        auto edgeKey = [&](int e, int shift) {
            glm::ivec3 o = cornerOffset(kEdgeCorners[e][0]);
            o[axis] -= shift;
            return std::array<int, 4>{o.x, o.y, o.z, kEdgeAxis[e]};
        };
        for (int c = 0; c < 256; ++c)
            for (int far = 0; far < 16; ++far) {
                // The neighbour above: its lower face holds this cell's upper-face samples.
                int n = 0;
                for (size_t i = 0; i < 4; ++i) {
                    if (inside(c, upper[i])) n |= 1 << lower[i];
                    if ((far >> i) & 1) n |= 1 << upper[i];
                }
                std::set<std::pair<std::array<int, 4>, std::array<int, 4>>> mine, theirs;
                for (const auto& [a, b] : boundarySegments(c))
                    if (edgeOnFace(a, axis, 1) && edgeOnFace(b, axis, 1))
                        mine.insert({edgeKey(b, 1), edgeKey(a, 1)}); // reversed
                for (const auto& [a, b] : boundarySegments(n))
                    if (edgeOnFace(a, axis, 0) && edgeOnFace(b, axis, 0))
                        theirs.insert({edgeKey(a, 0), edgeKey(b, 0)});
                ASSERT_EQ(mine, theirs) << "axis " << axis << ", case " << c << " below case " << n;
            }
    }
}

// ---------------------------------------------------------------------------------------------
// The reference mesher on fields and scenes.

// A grid of cubic cells, `cells` along the longest axis, covering `box` grown by `margin` cells
// and shifted by `shift` cells, so that no sample falls exactly on a surface of simple shapes.
ReferenceGrid gridAround(const Aabb& box, uint32_t cells, float margin = 1.5f,
                         glm::vec3 shift = glm::vec3(0.137f, 0.291f, 0.223f)) {
    const glm::vec3 size = box.max - box.min;
    const float longest = std::max(size.x, std::max(size.y, size.z));
    const float h = longest / float(cells - 2.0f * margin);
    ReferenceGrid grid;
    grid.voxelSize = h;
    grid.origin = box.min - margin * h + (shift - 0.5f) * h;
    grid.cells = glm::uvec3(glm::ceil((size + 2.0f * margin * h) / h)) + 1u;
    return grid;
}

TEST(MeshReference, SphereHasTheAnalyticVolumeAndArea) {
    const Evaluator evaluator(makeScene(sphere(1.0f)));
    const ReferenceGrid grid = gridAround(evaluator.bounds(), 128);
    const ReferenceMesh result = referenceMesh(evaluator, grid);
    const MeshProperties m = measureMesh(result.mesh);
    SCOPED_TRACE(m.str());
    EXPECT_FALSE(result.surfaceCut);
    EXPECT_TRUE(m.closedManifold());
    EXPECT_EQ(m.euler, 2);
    EXPECT_EQ(m.referencedVertices, m.vertices);
    EXPECT_NEAR(m.volume, 4.0 / 3.0 * kPi, 0.01 * 4.0 / 3.0 * kPi);
    EXPECT_NEAR(m.area, 4.0 * kPi, 0.01 * 4.0 * kPi);
    EXPECT_LE(maxSurfaceDistance(result.mesh, evaluator), 0.1f * grid.voxelSize);
    const NormalProperties normals = checkNormals(result.mesh);
    EXPECT_EQ(normals.notUnit, 0u) << normals.str();
    EXPECT_EQ(normals.inward, 0u) << normals.str();
    EXPECT_GT(normals.worstDot, 0.9) << normals.str();
    for (size_t i = 0; i < result.mesh.vertexCount(); i += 97)
        ASSERT_NEAR(glm::dot(result.mesh.normals[i], result.mesh.positions[i]), 1.0f, 1e-3f)
            << "the normal of a unit sphere at p is p";
}

TEST(MeshReference, TorusHasEulerCharacteristicZero) {
    const Evaluator evaluator(makeScene(torus(0.7f, 0.25f).rotated(30, 0, 20)));
    const ReferenceMesh result = referenceMesh(evaluator, gridAround(evaluator.bounds(), 64));
    const MeshProperties m = measureMesh(result.mesh);
    SCOPED_TRACE(m.str());
    EXPECT_FALSE(result.surfaceCut);
    EXPECT_TRUE(m.closedManifold());
    EXPECT_EQ(m.euler, 0);
    const double volume = 2 * kPi * kPi * 0.7 * 0.25 * 0.25;
    EXPECT_NEAR(m.volume, volume, 0.02 * volume);
}

TEST(MeshReference, RefinementMovesVerticesOntoTheSurface) {
    // A smooth union's field bends between the two spheres, so the linear estimate misses the
    // surface; refinement closes in.
    const Evaluator evaluator(
        makeScene(unite({sphere(0.6f), sphere(0.5f).at(0.7f, 0.1f, 0)}, 0.3f)));
    const ReferenceGrid grid = gridAround(evaluator.bounds(), 24);
    const float linear = maxSurfaceDistance(referenceMesh(evaluator, grid, 0).mesh, evaluator);
    const float refined = maxSurfaceDistance(referenceMesh(evaluator, grid, 2).mesh, evaluator);
    EXPECT_LT(refined, linear);
    EXPECT_LT(refined, 0.01f * grid.voxelSize);
}

// Every case inside a closed neighbourhood: the cell's eight samples set by the case, all other
// samples outside.
TEST(MeshReference, EveryCaseAloneGivesAClosedMesh) {
    ReferenceGrid grid;
    grid.cells = glm::uvec3(3);
    for (int c = 1; c < 256; ++c) {
        auto field = [&](glm::vec3 p) {
            const glm::ivec3 s(glm::round(p));
            const glm::ivec3 o = s - 1;
            if (glm::any(glm::lessThan(o, glm::ivec3(0))) ||
                glm::any(glm::greaterThan(o, glm::ivec3(1))))
                return 1.0f;
            for (int k = 0; k < 8; ++k)
                if (cornerOffset(k) == o) return inside(c, k) ? -1.0f : 1.0f;
            return 1.0f;
        };
        // Only samples are ever at integer points; refinement and normals are off the grid and
        // see the rounded sample's value, which keeps every sign test on the grid.
        const ReferenceMesh result = referenceMeshOf(
            field, [](glm::vec3) { return glm::vec3(0.0f); }, grid, 0);
        const MeshProperties m = measureMesh(result.mesh);
        EXPECT_TRUE(m.closedManifold()) << "case " << c << ": " << m.str();
        EXPECT_GT(m.volume, 0.0) << "case " << c << ": " << m.str();
        EXPECT_FALSE(result.surfaceCut);
    }
}

// Trilinear interpolation of random values on the grid's samples: every cell gets an arbitrary
// case, and its neighbours whatever they happen to share with it.
struct RandomField {
    glm::uvec3 size;
    std::vector<float> values;

    RandomField(uint32_t seed, uint32_t cells, float insideFraction) : size(cells + 1) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<float> uni(0.0f, 1.0f);
        values.resize(size_t(size.x) * size.y * size.z);
        for (uint32_t z = 0; z < size.z; ++z)
            for (uint32_t y = 0; y < size.y; ++y)
                for (uint32_t x = 0; x < size.x; ++x) {
                    const bool edge =
                        x == 0 || y == 0 || z == 0 || x == cells || y == cells || z == cells;
                    const float magnitude = 0.05f + uni(rng);
                    const bool in = !edge && uni(rng) < insideFraction;
                    values[(size_t(z) * size.y + y) * size.x + x] = in ? -magnitude : magnitude;
                }
    }
    float at(glm::ivec3 s) const {
        s = glm::clamp(s, glm::ivec3(0), glm::ivec3(size) - 1);
        return values[(size_t(s.z) * size.y + size_t(s.y)) * size.x + size_t(s.x)];
    }
    float operator()(glm::vec3 p) const {
        const glm::vec3 f = glm::floor(p);
        const glm::vec3 t = p - f;
        const glm::ivec3 s(f);
        float sum = 0;
        for (int k = 0; k < 8; ++k) {
            const glm::ivec3 o = cornerOffset(k);
            const float w = (o.x ? t.x : 1 - t.x) * (o.y ? t.y : 1 - t.y) * (o.z ? t.z : 1 - t.z);
            sum += w * at(s + o);
        }
        return sum;
    }
};

TEST(MeshReference, RandomFieldsGiveClosedManifoldMeshes) {
    ReferenceGrid grid;
    grid.cells = glm::uvec3(12);
    size_t triangles = 0;
    for (uint32_t seed = 1; seed <= 60; ++seed) {
        const float fraction = 0.2f + 0.6f * float(seed % 5) / 4.0f;
        const RandomField field(seed, 12, fraction);
        const ReferenceMesh result = referenceMeshOf(
            field, [](glm::vec3) { return glm::vec3(0.0f); }, grid, 2);
        const MeshProperties m = measureMesh(result.mesh);
        triangles += m.triangles;
        EXPECT_TRUE(m.closedManifold()) << "seed " << seed << ": " << m.str();
        EXPECT_GT(m.volume, 0.0) << "seed " << seed << ": " << m.str();
        EXPECT_EQ(m.euler % 2, 0) << "seed " << seed << ": " << m.str();
        EXPECT_EQ(m.referencedVertices, m.vertices) << "seed " << seed;
        EXPECT_FALSE(result.surfaceCut);
    }
    EXPECT_GT(triangles, 60u * 1000u) << "the fields should be busy";
}

TEST(MeshReference, RandomSphereUnionsGiveClosedManifoldMeshes) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    for (int trial = 0; trial < 8; ++trial) {
        std::vector<Tree> spheres;
        for (int i = 0; i < 12; ++i)
            spheres.push_back(sphere(0.1f + 0.3f * uni(rng))
                                  .at(uni(rng) * 2 - 1, uni(rng) * 2 - 1, uni(rng) * 2 - 1));
        const Evaluator evaluator(makeScene(unite(std::move(spheres), trial % 2 ? 0.2f : 0.0f)));
        const ReferenceGrid grid = gridAround(evaluator.bounds(), 20 + 3 * uint32_t(trial));
        const ReferenceMesh result = referenceMesh(evaluator, grid);
        const MeshProperties m = measureMesh(result.mesh);
        EXPECT_FALSE(result.surfaceCut) << "trial " << trial;
        EXPECT_TRUE(m.closedManifold()) << "trial " << trial << ": " << m.str();
        EXPECT_GT(m.volume, 0.0) << "trial " << trial << ": " << m.str();
        // Where an edge crosses the crease between two spheres, the field bends along it and
        // the refined point may stay an eighth of a cell off.
        EXPECT_LE(maxSurfaceDistance(result.mesh, evaluator), 0.15f * grid.voxelSize)
            << "trial " << trial;
    }
}

TEST(MeshReference, RandomScenesGiveClosedManifoldMeshes) {
    for (uint32_t seed = 1; seed <= 8; ++seed) {
        const Evaluator evaluator(randomScene(seed, 12));
        ASSERT_TRUE(evaluator.bounds().finite()) << "seed " << seed;
        if (evaluator.bounds().empty()) continue;
        const ReferenceMesh result = referenceMesh(evaluator, gridAround(evaluator.bounds(), 32));
        const MeshProperties m = measureMesh(result.mesh);
        EXPECT_FALSE(result.surfaceCut) << "seed " << seed;
        EXPECT_TRUE(m.closedManifold()) << "seed " << seed << ": " << m.str();
        EXPECT_GE(m.volume, 0.0) << "seed " << seed << ": " << m.str();
        const NormalProperties normals = checkNormals(result.mesh);
        EXPECT_EQ(normals.notUnit, 0u) << "seed " << seed << ": " << normals.str();
    }
}

TEST(MeshReference, BoundsThatCutTheSurfaceLeaveItOpenAndSaySo) {
    const Evaluator evaluator(makeScene(box(2, 2, 2)));
    Aabb cut;
    cut.min = glm::vec3(0.3f, -1.5f, -1.5f);
    cut.max = glm::vec3(1.5f, 1.5f, 1.5f);
    const ReferenceMesh result = referenceMesh(evaluator, gridAround(cut, 24, 0.0f));
    const MeshProperties m = measureMesh(result.mesh);
    EXPECT_TRUE(result.surfaceCut);
    EXPECT_GT(m.boundaryEdges, 0u) << m.str();
    EXPECT_EQ(m.nonManifoldEdges, 0u) << m.str();
    EXPECT_EQ(m.misorientedEdges, 0u) << m.str();
}

// The checks themselves: a tetrahedron, and comparisons that must and must not match.
Mesh tetrahedron() {
    Mesh mesh;
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    mesh.normals = {glm::normalize(glm::vec3(-1)), {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    mesh.colors.assign(4, glm::vec3(0.5f));
    mesh.indices = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    return mesh;
}

TEST(MeshChecks, MeasureATetrahedron) {
    const MeshProperties m = measureMesh(tetrahedron());
    EXPECT_TRUE(m.closedManifold()) << m.str();
    EXPECT_EQ(m.edges, 6u);
    EXPECT_EQ(m.euler, 2);
    EXPECT_NEAR(m.volume, 1.0 / 6.0, 1e-9);
    EXPECT_NEAR(m.area, 1.5 + std::sqrt(3.0) / 2.0, 1e-6);

    Mesh flipped = tetrahedron();
    std::swap(flipped.indices[1], flipped.indices[2]);
    const MeshProperties f = measureMesh(flipped);
    EXPECT_EQ(f.misorientedEdges, 3u) << f.str();
    EXPECT_FALSE(f.closedManifold());

    Mesh open = tetrahedron();
    open.indices.resize(9);
    const MeshProperties o = measureMesh(open);
    EXPECT_EQ(o.boundaryEdges, 3u) << o.str();
    EXPECT_EQ(o.referencedVertices, 4u);

    Mesh fin = tetrahedron();
    fin.positions.push_back({1, 1, 1});
    fin.normals.push_back({0, 0, 1});
    fin.colors.push_back({0, 0, 0});
    fin.indices.insert(fin.indices.end(), {1, 2, 4});
    EXPECT_EQ(measureMesh(fin).nonManifoldEdges, 1u);
}

TEST(MeshChecks, CompareIgnoresOrderButNotOrientation) {
    const Mesh a = tetrahedron();
    Mesh b;
    const uint32_t order[4] = {2, 3, 0, 1}; // b's vertex i is a's vertex order[i]
    uint32_t inverse[4];
    for (uint32_t i = 0; i < 4; ++i) {
        b.positions.push_back(a.positions[order[i]] + glm::vec3(1e-6f));
        b.normals.push_back(a.normals[order[i]]);
        b.colors.push_back(a.colors[order[i]]);
        inverse[order[i]] = i;
    }
    for (int t = 3; t >= 0; --t) // reversed triangle order, each rotated
        for (int i = 0; i < 3; ++i)
            b.indices.push_back(inverse[a.indices[size_t(3 * t + (i + 1) % 3)]]);
    EXPECT_TRUE(compareMeshes(a, b, 1e-4f).same()) << compareMeshes(a, b, 1e-4f).str();

    Mesh flipped = b;
    std::swap(flipped.indices[0], flipped.indices[1]);
    EXPECT_EQ(compareMeshes(a, flipped, 1e-4f).unmatchedTriangles, 2u);

    Mesh moved = b;
    moved.positions[0].x += 0.01f;
    EXPECT_EQ(compareMeshes(a, moved, 1e-4f).unmatchedVertices, 1u);

    Mesh recoloured = b;
    recoloured.colors[3] = glm::vec3(1.0f);
    EXPECT_EQ(compareMeshes(a, recoloured, 1e-4f).colorMismatches, 1u);

    const NormalProperties normals = checkNormals(a);
    EXPECT_EQ(normals.inward, 0u) << normals.str();
    Mesh inward = a;
    inward.normals[3] = -inward.normals[3];
    EXPECT_EQ(checkNormals(inward).inward, 1u);
}

// Two triangles, each with vertices of its own unless `shared` names vertices of the first
// (by place) that the second uses instead of its own.
Mesh twoTriangles(std::array<glm::vec3, 3> a, std::array<glm::vec3, 3> b,
                  std::array<int, 3> shared = {-1, -1, -1}) {
    Mesh mesh;
    mesh.positions.assign(a.begin(), a.end());
    mesh.indices = {0, 1, 2};
    for (size_t i = 0; i < 3; ++i) {
        if (shared[i] >= 0) {
            mesh.indices.push_back(uint32_t(shared[i]));
            continue;
        }
        mesh.indices.push_back(uint32_t(mesh.positions.size()));
        mesh.positions.push_back(b[i]);
    }
    mesh.normals.assign(mesh.positions.size(), glm::vec3(0, 0, 1));
    mesh.colors.assign(mesh.positions.size(), glm::vec3(0.5f));
    return mesh;
}

// Each kind of meeting on its own, and configurations as close to them as can be that do not
// meet.
TEST(MeshChecks, SelfIntersectionsOfTrianglePairs) {
    const std::array<glm::vec3, 3> base = {glm::vec3(0, 0, 0), {1, 0, 0}, {0, 1, 0}};
    auto count = [](const Mesh& mesh) { return findSelfIntersections(mesh, 1e-6); };

    // No vertex in common: one pierces the other; they touch at a point (a vertex on the other's
    // face, or two vertices at one position); they overlap in one plane; or they lie apart.
    SelfIntersections r =
        count(twoTriangles(base, {{{0.2f, 0.2f, -0.5f}, {0.3f, 0.2f, 0.5f}, {0.2f, 0.3f, 0.5f}}}));
    EXPECT_EQ(r.crossing, 1u) << r.str();
    EXPECT_EQ(r.total(), 1u) << r.str();
    EXPECT_NE(r.first.find("triangle 0"), std::string::npos) << r.first;
    r = count(twoTriangles(base, {{{0.2f, 0.2f, 0}, {0.3f, 0.2f, 1}, {0.2f, 0.3f, 1}}}));
    EXPECT_EQ(r.crossing, 1u) << "a vertex on the face: " << r.str();
    r = count(twoTriangles(base, {{{1, 0, 0}, {2, 0, 1}, {2, 1, 0}}}));
    EXPECT_EQ(r.crossing, 1u) << "two vertices at one position: " << r.str();
    r = count(twoTriangles(base, {{{0.5f, 0.5f, 0}, {-0.5f, 0.2f, 0}, {0.2f, -0.5f, 0}}}));
    EXPECT_EQ(r.crossing, 1u) << "overlapping in one plane: " << r.str();
    r = count(twoTriangles(base, {{{0.1f, 0.1f, 0}, {0.3f, 0.1f, 0}, {0.1f, 0.3f, 0}}}));
    EXPECT_EQ(r.crossing, 1u) << "one inside the other in one plane: " << r.str();
    r = count(twoTriangles(base, {{{0.2f, 0.2f, 1e-3f}, {0.3f, 0.2f, 1}, {0.2f, 0.3f, 1}}}));
    EXPECT_EQ(r.total(), 0u) << "a vertex just above the face: " << r.str();
    r = count(twoTriangles(base, {{{0.6f, 0.6f, 0}, {1, 1, 0}, {0.6f, 1, 0}}}));
    EXPECT_EQ(r.total(), 0u) << "apart in one plane: " << r.str();

    // One vertex in common (the first's corner 0): the second passes through the first, or folds
    // back into its plane over it; or it only meets it at the corner, in one plane or not.
    r = count(twoTriangles(base, {{{0, 0, 0}, {0.3f, 0.3f, -1}, {0.4f, 0.3f, 1}}}, {0, -1, -1}));
    EXPECT_EQ(r.overlapping, 1u) << r.str();
    EXPECT_EQ(r.total(), 1u) << r.str();
    r = count(twoTriangles(base, {{{0, 0, 0}, {0.5f, 0.1f, 0}, {0.1f, 0.5f, 0}}}, {0, -1, -1}));
    EXPECT_EQ(r.overlapping, 1u) << "within it in one plane: " << r.str();
    r = count(twoTriangles(base, {{{0, 0, 0}, {-1, 0.1f, 0}, {-1, -0.1f, 0}}}, {0, -1, -1}));
    EXPECT_EQ(r.total(), 0u) << "beside it in one plane: " << r.str();
    r = count(twoTriangles(base, {{{0, 0, 0}, {0.3f, 0.3f, 1}, {0.4f, 0.3f, 1}}}, {0, -1, -1}));
    EXPECT_EQ(r.total(), 0u) << "above it: " << r.str();

    // A side in common (the first's corners 1 and 2, in the opposite direction): the second
    // folds onto the first in its plane; it folds nearly onto it, or continues it in its plane.
    r = count(twoTriangles(base, {{{0, 1, 0}, {1, 0, 0}, {0.2f, 0.2f, 0}}}, {2, 1, -1}));
    EXPECT_EQ(r.folded, 1u) << r.str();
    EXPECT_EQ(r.total(), 1u) << r.str();
    r = count(twoTriangles(base, {{{0, 1, 0}, {1, 0, 0}, {0.2f, 0.2f, 0.05f}}}, {2, 1, -1}));
    EXPECT_EQ(r.total(), 0u) << "a sharp fold: " << r.str();
    r = count(twoTriangles(base, {{{0, 1, 0}, {1, 0, 0}, {1, 1, 0}}}, {2, 1, -1}));
    EXPECT_EQ(r.total(), 0u) << "a flat quad: " << r.str();

    r = count(twoTriangles(base, base, {0, 1, 2}));
    EXPECT_EQ(r.duplicates, 1u) << r.str();
    EXPECT_EQ(r.total(), 1u) << r.str();
}

// The quick proofs that a pair does not meet (a plane between them) agree with the exact tests
// on seeded random pairs placed to meet, nearly meet or touch within the tolerance: apart, with
// a vertex in common, in one plane or leaning out of it by about the tolerance.
TEST(MeshChecks, QuickSelfIntersectionProofsAgreeWithTheExactTests) {
    std::mt19937 rng(7);
    auto uni = [&](float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng); };
    const double tolerance = 1e-6;
    const float lean[] = {0.0f, 3e-7f, -3e-7f, 3e-6f, -3e-6f, 1e-3f, -1e-3f, 0.2f};
    size_t meeting = 0;
    for (int pair = 0; pair < 20000; ++pair) {
        const glm::vec3 o(uni(-1, 1), uni(-1, 1), uni(-1, 1));
        const glm::vec3 u(uni(-1, 1), uni(-1, 1), uni(-1, 1)),
            w(uni(-1, 1), uni(-1, 1), uni(-1, 1));
        const std::array<glm::vec3, 3> a = {o, o + u, o + w};
        const glm::vec3 n = glm::normalize(glm::cross(u, w));
        std::array<glm::vec3, 3> b;
        for (glm::vec3& p : b) // in a's plane around it, leaning out of it
            p = o + uni(-0.5f, 1.5f) * u + uni(-0.5f, 1.5f) * w + lean[rng() % 8] * n;
        std::array<int, 3> shared = {-1, -1, -1};
        if (pair % 2) { // a's corner k as b's first vertex
            const int k = int(rng() % 3);
            shared[0] = k;
            b[0] = a[size_t(k)];
            if (pair % 4 == 3) { // b rises from the corner just past the tolerance, reaching far
                const float rise = lean[1 + rng() % 4];
                for (size_t i = 1; i < 3; ++i)
                    b[i] = o + uni(-1, 3) * u + uni(-1, 3) * w + rise * n;
            }
        }
        const Mesh mesh = twoTriangles(a, b, shared);
        const SelfIntersections quick = findSelfIntersections(mesh, tolerance, 1e-3, nullptr);
        const SelfIntersections exact =
            findSelfIntersections(mesh, tolerance, 1e-3, nullptr, false);
        ASSERT_EQ(quick.total(), exact.total()) << "pair " << pair << ": " << exact.str();
        meeting += exact.total();
    }
    // Both outcomes are common, so the comparison means something.
    EXPECT_GT(meeting, 2000u);
    EXPECT_LT(meeting, 18000u);
}

// Meshes of many triangles: closed surfaces that do not meet themselves, two that cross, and one
// with a vertex pushed through the far side.
TEST(MeshChecks, SelfIntersectionsOfClosedMeshes) {
    const Evaluator evaluator(makeScene(torus(0.7f, 0.25f).rotated(30, 0, 20)));
    const ReferenceGrid grid = gridAround(evaluator.bounds(), 32);
    Mesh torusMesh = referenceMesh(evaluator, grid, 3, MeshMethod::DualContouring).mesh;
    SelfIntersections r = findSelfIntersections(torusMesh);
    EXPECT_EQ(r.total(), 0u) << r.str();

    Mesh two = torusMesh; // a copy moved along the hole's axis by half the tube's radius
    const uint32_t offset = uint32_t(two.vertexCount());
    for (uint32_t i = 0; i < offset; ++i) {
        two.positions.push_back(torusMesh.positions[i] + glm::vec3(0.05f, 0.1f, 0.05f));
        two.normals.push_back(torusMesh.normals[i]);
        two.colors.push_back(torusMesh.colors[i]);
    }
    for (uint32_t index : torusMesh.indices)
        two.indices.push_back(index + offset);
    EXPECT_TRUE(measureMesh(two).closedManifold());
    r = findSelfIntersections(two);
    EXPECT_GT(r.crossing, 100u) << r.str();
    EXPECT_EQ(r.overlapping + r.folded + r.duplicates, 0u) << r.str();

    // The vertex farthest out along x, pushed to the inner rim's far side.
    Mesh dented = torusMesh;
    size_t outermost = 0;
    for (size_t i = 0; i < dented.vertexCount(); ++i)
        if (dented.positions[i].x > dented.positions[outermost].x) outermost = i;
    dented.positions[outermost] *= -0.5f;
    r = findSelfIntersections(dented);
    EXPECT_GT(r.total(), 0u) << r.str();
}

// A flipped triangle and a degenerate one in a closed mesh of a sphere, which has neither.
TEST(MeshChecks, FlippedAndDegenerateTriangles) {
    const Evaluator evaluator(makeScene(sphere(1.0f)));
    const ReferenceGrid grid = gridAround(evaluator.bounds(), 24);
    for (MeshMethod method : {MeshMethod::DualContouring, MeshMethod::MarchingCubes}) {
        const Mesh mesh = referenceMesh(evaluator, grid, 3, method).mesh;
        TriangleFacing f = checkTriangleFacing(mesh, evaluator, grid.voxelSize);
        EXPECT_EQ(f.flipped + f.degenerate, 0u) << f.str();
        EXPECT_GT(f.worstCos, 0.5) << f.str();

        Mesh flipped = mesh;
        std::swap(flipped.indices[30], flipped.indices[31]);
        f = checkTriangleFacing(flipped, evaluator, grid.voxelSize);
        EXPECT_EQ(f.flipped, 1u) << f.str();
        EXPECT_EQ(f.degenerate, 0u) << f.str();
        EXPECT_LT(f.worstCos, -0.9) << f.str();
        EXPECT_NE(f.first.find("triangle 10 flipped"), std::string::npos) << f.first;

        // Triangle 10's first vertex moved onto the middle of its opposite side.
        Mesh flat = mesh;
        const uint32_t* v = &flat.indices[30];
        flat.positions[v[0]] = 0.5f * (flat.positions[v[1]] + flat.positions[v[2]]);
        f = checkTriangleFacing(flat, evaluator, grid.voxelSize);
        EXPECT_GE(f.degenerate, 1u) << f.str();
    }
}

// Points across the triangles see what the vertices miss: a coarse cube's faces cut into a
// sphere.
TEST(MeshChecks, SampledSurfaceDistanceSeesAcrossTriangles) {
    const Evaluator evaluator(makeScene(sphere(1.0f)));
    Mesh cube;
    for (int k = 0; k < 8; ++k)
        cube.positions.push_back(
            glm::normalize(glm::vec3(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1)));
    cube.indices = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                    2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
    EXPECT_TRUE(measureMesh(cube).closedManifold()) << measureMesh(cube).str();
    EXPECT_LT(maxSurfaceDistance(cube, evaluator), 1e-6f);
    // The face centres lie 1/sqrt(3) from the centre.
    EXPECT_NEAR(maxSampledSurfaceDistance(cube, evaluator), 1.0f - 1.0f / std::sqrt(3.0f), 1e-5f);
}

} // namespace
} // namespace sdfcsg::test
