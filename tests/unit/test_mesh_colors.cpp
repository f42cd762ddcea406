// Crisp colour regions (engine/src/mesh/mesh_colors.cpp) by the properties of the meshes, against
// the CPU evaluator: each triangle lies in one colour, the field's at its centre; the vertices
// where colours meet lie on both parts' surfaces; the cut mesh stays closed, manifold, embedded
// and of the same volume; smooth blends keep their blended colours and get no border; ordering
// and simplifying keep the regions.
#include "driver_cache.h"
#include "gpu_test.h"
#include "mesh/mesh_colors.h"
#include "mesh_checks.h"
#include "mesh_reference.h"

#include <cstdio>
#include <filesystem>

namespace sdfcsg::test {
namespace {

Scene sceneFrom(std::string_view json) {
    auto scene = parseScene(json, "<test>");
    if (!scene) {
        ADD_FAILURE() << scene.error().str();
        return Scene{};
    }
    return *scene;
}

// A red box with a blue ball cut out of one face: the cavity's rim is a circle on the face.
// Node 1 is the box, node 2 the ball.
const char* const kBoxMinusBall = R"({"version": 1, "root": {"type": "difference", "children": [
    {"type": "box", "size": [1.6, 1.2, 1.4], "translate": [0.013, 0.021, -0.017],
     "color": [0.9, 0.2, 0.1]},
    {"type": "sphere", "radius": 0.5, "translate": [0.8, 0.03, 0.05], "color": [0.1, 0.3, 0.9]}]}})";

float gap(glm::vec3 a, glm::vec3 b) {
    const glm::vec3 d = glm::abs(a - b);
    return std::max({d.x, d.y, d.z});
}

// The point moved onto the surface by Newton steps with central differences (written apart from
// the library's, which uses tetrahedral ones).
glm::vec3 ontoSurface(const Evaluator& evaluator, glm::vec3 p, float h) {
    const float e = 0.01f * h;
    for (int i = 0; i < 4; ++i) {
        const float d = evaluator.distance(p);
        glm::vec3 g;
        for (int k = 0; k < 3; ++k) {
            glm::vec3 step(0.0f);
            step[k] = e;
            g[k] = (evaluator.distance(p + step) - evaluator.distance(p - step)) / (2.0f * e);
        }
        if (!(glm::dot(g, g) > 1e-12f)) break;
        p -= g * (d / glm::dot(g, g));
    }
    return p;
}

// Triangles whose colour is not the field's at their centre (moved onto the surface).
size_t wrongColours(const Mesh& mesh, const Evaluator& evaluator, float h, std::string* first) {
    size_t wrong = 0;
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
        const uint32_t* v = &mesh.indices[3 * t];
        const glm::vec3 centre =
            (mesh.positions[v[0]] + mesh.positions[v[1]] + mesh.positions[v[2]]) / 3.0f;
        const glm::vec3 field = evaluator.sample(ontoSurface(evaluator, centre, h)).color;
        if (gap(field, mesh.triangleColors[t]) > 1.0f / 255.0f) {
            if (!wrong++ && first) {
                char text[400];
                const glm::vec3 c = mesh.triangleColors[t];
                const glm::vec3 s = ontoSurface(evaluator, centre, h);
                std::snprintf(text, sizeof text,
                              "triangle %zu at (%g, %g, %g), on the surface (%g, %g, %g): colour "
                              "(%g, %g, %g), the field's (%g, %g, %g)",
                              t, centre.x, centre.y, centre.z, s.x, s.y, s.z, c.x, c.y, c.z,
                              field.x, field.y, field.z);
                *first = text;
            }
        }
    }
    return wrong;
}

// Vertices on triangles of more than one colour.
std::vector<uint32_t> borderVertices(const Mesh& mesh) {
    std::vector<int> first(mesh.vertexCount(), -1);
    std::vector<bool> border(mesh.vertexCount(), false);
    for (size_t t = 0; t < mesh.triangleCount(); ++t)
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = mesh.indices[3 * t + k];
            if (first[v] < 0)
                first[v] = int(t);
            else if (gap(mesh.triangleColors[size_t(first[v])], mesh.triangleColors[t]) >
                     1.0f / 512.0f)
                border[v] = true;
        }
    std::vector<uint32_t> out;
    for (uint32_t v = 0; v < border.size(); ++v)
        if (border[v]) out.push_back(v);
    return out;
}

class MeshColors : public GpuTest {
  protected:
    // With the colour regions that every test here is about.
    Mesh extract(const Scene& scene, MeshOptions options, MeshStats* stats) {
        options.colorRegions = true;
        auto mesh = extractMesh(context(), scene, options, stats);
        if (!mesh) {
            ADD_FAILURE() << mesh.error().str();
            return Mesh{};
        }
        return *mesh;
    }
};

// The issue's test: every triangle one colour, the border's vertices on the intersection curve
// (on the box's surface and the ball's) within 0.05 cells.
TEST_F(MeshColors, BoxMinusBallHasOneColourPerTriangleAndItsBorderOnTheCurve) {
    const Scene scene = sceneFrom(kBoxMinusBall);
    const Evaluator evaluator(scene);
    ASSERT_TRUE(detail::hasSeveralColours(evaluator));
    struct Case {
        MeshMethod method;
        uint32_t resolution;
    };
    for (const Case& c :
         {Case{MeshMethod::DualContouring, 64}, Case{MeshMethod::DualContouring, 97},
          Case{MeshMethod::DualContouring, 128}, Case{MeshMethod::MarchingCubes, 61}}) {
        SCOPED_TRACE(std::string(c.method == MeshMethod::MarchingCubes ? "mc" : "dc") + " at " +
                     std::to_string(c.resolution));
        MeshOptions options;
        options.method = c.method;
        options.resolution = c.resolution;
        MeshStats stats;
        const Mesh mesh = extract(scene, options, &stats);
        const float h = stats.voxelSize;
        ASSERT_EQ(mesh.triangleColors.size(), mesh.triangleCount());
        const MeshProperties m = measureMesh(mesh);
        SCOPED_TRACE(m.str());
        EXPECT_TRUE(m.closedManifold());
        EXPECT_EQ(m.euler, 2);
        EXPECT_GT(m.volume, 0.0);
        const SelfIntersections crossings = findSelfIntersections(mesh);
        EXPECT_EQ(crossings.total(), 0u) << crossings.str();
        const bool dual = c.method == MeshMethod::DualContouring;
        const TriangleFacing facing = checkTriangleFacing(mesh, evaluator, h);
        EXPECT_EQ(facing.degenerate, 0u) << facing.str();
        // Marching cubes bevels the rim, which the border's points on the rim itself stand out
        // of: pieces there may face across the field.
        if (dual) {
            EXPECT_EQ(facing.flipped, 0u) << facing.str();
        }

        std::string first;
        EXPECT_EQ(wrongColours(mesh, evaluator, h, &first), 0u) << first;
        size_t colours[2] = {0, 0};
        for (const glm::vec3& c3 : mesh.triangleColors) {
            const bool red = gap(c3, glm::vec3(0.9f, 0.2f, 0.1f)) <= 1.0f / 512.0f;
            const bool blue = gap(c3, glm::vec3(0.1f, 0.3f, 0.9f)) <= 1.0f / 512.0f;
            EXPECT_TRUE(red || blue) << c3.x << ", " << c3.y << ", " << c3.z;
            ++colours[blue];
        }
        EXPECT_GT(colours[0], 0u);
        EXPECT_GT(colours[1], 0u);

        if (!dual) continue; // the bevel's vertices lie off the rim by up to a cell
        const std::vector<uint32_t> border = borderVertices(mesh);
        // The rim is some 3 units long: a vertex or more per cell along it.
        EXPECT_GT(border.size(), size_t(2.0f / h));
        float worst = 0.0f;
        for (uint32_t v : border) {
            const glm::vec3 p = mesh.positions[v];
            worst = std::max({worst, std::abs(evaluator.distance(p, 1)) / h,
                              std::abs(evaluator.distance(p, 2)) / h});
        }
        EXPECT_LT(worst, 0.05f) << "cells from the intersection curve";
    }
}

// The cut leaves the surface where it was: on the CPU reference's mesh, the same volume, still
// closed and manifold, and each new vertex shared by the two triangles of its edge.
TEST(MeshColorsHost, CuttingKeepsTheVolumeAndTheTopology) {
    const Scene scene = sceneFrom(kBoxMinusBall);
    const Evaluator evaluator(scene);
    for (uint32_t cells : {40u, 57u}) {
        SCOPED_TRACE(std::to_string(cells) + " cells");
        Aabb box = evaluator.finiteBounds();
        const float h = glm::length(box.max - box.min) / float(cells);
        const ReferenceGrid grid{box.min - 2.0f * h, h, glm::uvec3(cells + 4)};
        Mesh mesh =
            referenceDualMeshOf([&](glm::vec3 p) { return evaluator.distance(p); },
                                [&](glm::vec3 p) { return evaluator.sample(p).color; }, grid, 3)
                .mesh;
        const MeshProperties before = measureMesh(mesh);
        ASSERT_TRUE(before.closedManifold()) << before.str();
        const size_t splits = detail::splitColourBorders(mesh, evaluator, h);
        const MeshProperties after = measureMesh(mesh);
        EXPECT_GT(splits, 0u);
        EXPECT_TRUE(after.closedManifold()) << after.str();
        EXPECT_EQ(after.euler, before.euler);
        EXPECT_GE(after.vertices, before.vertices + splits);
        EXPECT_GE(after.triangles, before.triangles + splits);
        EXPECT_NEAR(after.volume, before.volume, 2e-3 * before.volume);
        // A few pieces at the rim whose points went back onto their sides (mesh_colors.cpp)
        // lie off the rim by their chord's sag.
        std::string first;
        EXPECT_LE(wrongColours(mesh, evaluator, h, &first), mesh.triangleCount() / 2000) << first;
    }
}

// Without MeshOptions::colorRegions the mesh has no colour per triangle, and its vertices are
// those of the regions' mesh before the vertices that its cuts add (at 64 cells the rim's
// vertices lie on the border itself, and it adds none).
TEST_F(MeshColors, RegionsOnlyWhenAskedFor) {
    const Scene scene = sceneFrom(kBoxMinusBall);
    MeshOptions options;
    options.resolution = 64;
    auto plain = extractMesh(context(), scene, options);
    ASSERT_TRUE(plain) << plain.error().str();
    EXPECT_TRUE(plain->triangleColors.empty());
    MeshStats stats;
    const Mesh regions = extract(scene, options, &stats);
    EXPECT_EQ(regions.triangleColors.size(), regions.triangleCount());
    ASSERT_GE(regions.vertexCount(), plain->vertexCount());
    for (size_t v = 0; v < plain->vertexCount(); ++v)
        ASSERT_EQ(plain->positions[v], regions.positions[v]) << "vertex " << v;
}

// A smooth union of two colours blends them: no border, no new vertex, blended colours kept.
TEST_F(MeshColors, SmoothUnionKeepsBlendedColoursAndGetsNoBorder) {
    const Scene scene = sceneFrom(R"({"version": 1, "root": {"type": "union", "smooth": 0.3,
        "children": [{"type": "sphere", "radius": 0.6, "translate": [-0.4, 0, 0],
                      "color": [0.9, 0.2, 0.1]},
                     {"type": "box", "size": [0.9, 0.9, 0.9], "translate": [0.45, 0.1, 0],
                      "color": [0.1, 0.3, 0.9]}]}})");
    const Evaluator evaluator(scene);
    ASSERT_TRUE(detail::hasSeveralColours(evaluator));
    MeshOptions options;
    options.resolution = 64;
    MeshStats stats;
    const Mesh mesh = extract(scene, options, &stats);
    const float h = stats.voxelSize;
    ASSERT_EQ(mesh.triangleColors.size(), mesh.triangleCount());
    // The CPU reference of the same grid, cut or not, has the same triangles: nothing was cut.
    Mesh reference = referenceDualMeshOf([&](glm::vec3 p) { return evaluator.distance(p); },
                                         [&](glm::vec3 p) { return evaluator.sample(p).color; },
                                         gridOf(stats), options.refineSteps)
                         .mesh;
    EXPECT_EQ(detail::splitColourBorders(reference, evaluator, h), 0u);
    EXPECT_EQ(mesh.vertexCount(), reference.vertexCount());
    EXPECT_EQ(mesh.triangleCount(), reference.triangleCount());
    size_t blended = 0;
    for (const glm::vec3& c : mesh.colors)
        blended += gap(c, glm::vec3(0.9f, 0.2f, 0.1f)) > 0.05f &&
                   gap(c, glm::vec3(0.1f, 0.3f, 0.9f)) > 0.05f;
    EXPECT_GT(blended, 50u);
    std::string first;
    EXPECT_EQ(wrongColours(mesh, evaluator, h, &first), 0u) << first;
    EXPECT_TRUE(measureMesh(mesh).closedManifold());
}

// The snowman's eyes, nose, buttons and hat band: every triangle the colour of its centre, after
// the vertex-cache order as the command line writes it.
TEST_F(MeshColors, SnowmanTrianglesHaveTheColourOfTheirCentres) {
    const Scene scene =
        loadOrDie(std::filesystem::path(SDFCSG_SOURCE_DIR) / "assets/scenes/snowman.json");
    const Evaluator evaluator(scene);
    MeshOptions options;
    options.resolution = 128;
    MeshStats stats;
    Mesh mesh = extract(scene, options, &stats);
    optimizeMeshOrder(mesh, true);
    ASSERT_EQ(mesh.triangleColors.size(), mesh.triangleCount());
    // The arms are thinner than a cell: where one meets the body, a border may pass through a
    // triangle between its vertices (5 of 83,000 triangles).
    std::string first;
    EXPECT_LE(wrongColours(mesh, evaluator, stats.voxelSize, &first), mesh.triangleCount() / 10000)
        << first;
    const MeshProperties m = measureMesh(mesh);
    EXPECT_TRUE(m.closedManifold()) << m.str();
    const SelfIntersections crossings = findSelfIntersections(mesh);
    EXPECT_EQ(crossings.total(), 0u) << crossings.str();
}

// A scene of pruned tapes (8 x 8 red boxes, each less a blue ball: 193 nodes, over the 160 of
// kTapeMinNodes) gets its regions from the tapes' field: every triangle
// one colour, the field's at its centre, the mesh closed, manifold and without crossings.
TEST_F(MeshColors, ScenesOfPrunedTapesGetRegions) {
    std::string json = R"({"version": 1, "root": {"type": "union", "children": [)";
    for (int i = 0; i < 64; ++i) {
        const float x = float(i % 8) * 1.1f, z = float(i / 8) * 1.1f;
        json += (i ? "," : "") + std::string(R"({"type": "difference", "translate": [)") +
                std::to_string(x) + ", 0, " + std::to_string(z) + R"(], "children": [
            {"type": "box", "size": [0.8, 0.6, 0.7], "translate": [0.013, 0.021, -0.017],
             "color": [0.9, 0.2, 0.1]},
            {"type": "sphere", "radius": 0.3, "translate": [0.4, 0.03, 0.05],
             "color": [0.1, 0.3, 0.9]}]})";
    }
    const Scene scene = sceneFrom(json + "]}}");
    ASSERT_GE(scene.nodes.size(), kTapeMinNodes);
    const Evaluator evaluator(scene);
    MeshOptions options;
    options.resolution = 128;
    MeshStats stats;
    const Mesh mesh = extract(scene, options, &stats);
    ASSERT_EQ(mesh.triangleColors.size(), mesh.triangleCount());
    // Balls of 6 cells: a few triangles along the rim, their centres within a hundredth of a
    // cell of it, take the other side's colour: 31, 58 and 88 triangles at 96, 128 and 256 cells
    // (under 1 in 1,000) on the same scene of 7 x 7 parts, below kTapeMinNodes, from the whole
    // tree.
    std::string first;
    EXPECT_LE(wrongColours(mesh, evaluator, stats.voxelSize, &first), mesh.triangleCount() / 1000)
        << first;
    EXPECT_GT(borderVertices(mesh).size(), 64u * 20u);
    const MeshProperties m = measureMesh(mesh);
    EXPECT_TRUE(m.closedManifold()) << m.str();
    const SelfIntersections crossings = findSelfIntersections(mesh);
    EXPECT_EQ(crossings.total(), 0u) << crossings.str();
}

// A scene of one colour gets no triangle colours (and no colour pass).
TEST_F(MeshColors, OneColourGetsNoTriangleColours) {
    const Scene scene = sceneFrom(R"({"version": 1, "root": {"type": "difference", "children": [
        {"type": "box", "size": [1, 1, 1]}, {"type": "sphere", "radius": 0.6}]}})");
    EXPECT_FALSE(detail::hasSeveralColours(Evaluator(scene)));
    MeshOptions options;
    options.resolution = 24;
    MeshStats stats;
    const Mesh mesh = extract(scene, options, &stats);
    EXPECT_GT(mesh.triangleCount(), 0u);
    EXPECT_TRUE(mesh.triangleColors.empty());
    for (const MeshStats::Stage& stage : stats.stages)
        EXPECT_NE(stage.name, "colours");
}

// Simplification moves no border: its result's triangles still lie in one colour each, and the
// vertices where colours meet are still on the curve.
TEST_F(MeshColors, SimplificationKeepsTheRegions) {
    const Scene scene = sceneFrom(kBoxMinusBall);
    const Evaluator evaluator(scene);
    MeshOptions options;
    options.resolution = 64;
    MeshStats stats;
    const Mesh mesh = extract(scene, options, &stats);
    const float h = stats.voxelSize;
    SimplifyOptions simplify;
    simplify.maxError = 0.2f * h;
    auto simplified = simplifyMesh(mesh, evaluator, simplify);
    ASSERT_TRUE(simplified) << simplified.error().str();
    EXPECT_LT(simplified->triangleCount(), mesh.triangleCount() / 2);
    ASSERT_EQ(simplified->triangleColors.size(), simplified->triangleCount());
    std::string first;
    EXPECT_EQ(wrongColours(*simplified, evaluator, h, &first), 0u) << first;
    float worst = 0.0f;
    for (uint32_t v : borderVertices(*simplified)) {
        const glm::vec3 p = simplified->positions[v];
        worst = std::max({worst, std::abs(evaluator.distance(p, 1)) / h,
                          std::abs(evaluator.distance(p, 2)) / h});
    }
    EXPECT_LT(worst, 0.05f) << "cells from the intersection curve";
    EXPECT_TRUE(measureMesh(*simplified).closedManifold());
}

} // namespace
} // namespace sdfcsg::test
