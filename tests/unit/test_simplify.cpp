// Mesh simplification (engine/src/mesh/mesh_simplify.cpp) by the properties of its results on GPU
// meshes of bundled scenes: closed and manifold with the input's Euler characteristic, vertices
// and colours taken from the input, every colour outline kept, points sampled on the triangles
// within the bound by the CPU evaluator, triangle counts; and the GPU ordering.
#include "gpu_test.h"
#include "mesh/mesh_simplify.h"
#include "mesh_checks.h"

#include <glm/geometric.hpp>

#include <cmath>
#include <cstring>
#include <deque>
#include <map>
#include <set>
#include <tuple>

namespace sdfcsg::test {
namespace {

const std::filesystem::path kScenes = std::filesystem::path(SDFCSG_SOURCE_DIR) / "assets/scenes";

// Exact positions as keys: a simplification moves no vertex, so its vertices are the input's.
using Key = std::tuple<uint32_t, uint32_t, uint32_t>;
Key bits(glm::vec3 p) {
    uint32_t b[3];
    std::memcpy(b, &p, sizeof b);
    return {b[0], b[1], b[2]};
}

float meanEdge(const Mesh& mesh) {
    double sum = 0;
    for (size_t t = 0; t < mesh.triangleCount(); ++t)
        for (int i = 0; i < 3; ++i)
            sum += glm::length(mesh.positions[mesh.indices[3 * t + i]] -
                               mesh.positions[mesh.indices[3 * t + (i + 1) % 3]]);
    return float(sum / double(mesh.indices.size()));
}

struct SurfacePoint {
    glm::vec3 point;
    float distance; // |field| there
};

// Points on every triangle: the seven that `sdfcsg bench --mesh --error` samples (the centre,
// the middles of the sides, halfway from the centre to each corner), and with `lattice` the
// points of a barycentric grid of quarters besides.
std::vector<SurfacePoint> samplePoints(const Mesh& mesh, const Evaluator& evaluator, bool lattice,
                                       bool pruned = false) {
    std::vector<glm::vec3> weights(std::begin(detail::kTriangleSamples),
                                   std::end(detail::kTriangleSamples));
    if (lattice)
        for (int i = 0; i <= 4; ++i)
            for (int j = 0; i + j <= 4; ++j)
                weights.push_back(glm::vec3(float(i), float(j), float(4 - i - j)) / 4.0f);
    std::vector<SurfacePoint> out;
    out.reserve(mesh.triangleCount() * weights.size());
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
        const glm::vec3 a = mesh.positions[mesh.indices[3 * t]],
                        b = mesh.positions[mesh.indices[3 * t + 1]],
                        c = mesh.positions[mesh.indices[3 * t + 2]];
        for (const glm::vec3& w : weights) {
            const glm::vec3 p = w.x * a + w.y * b + w.z * c;
            out.push_back(
                {p, std::abs(pruned ? evaluator.prunedDistance(p) : evaluator.distance(p))});
        }
    }
    return out;
}

float largest(const std::vector<SurfacePoint>& points) {
    float worst = 0.0f;
    for (const SurfacePoint& s : points)
        worst = std::max(worst, s.distance);
    return worst;
}

// Samples of `out` farther from the surface than `bound` and than every sample of the input
// within `near` (per axis): where the input lay farther than the bound, the result may too.
size_t straying(const std::vector<SurfacePoint>& out, const std::vector<SurfacePoint>& in,
                float bound, float near) {
    std::map<std::tuple<int, int, int>, std::vector<const SurfacePoint*>> grid; // far ones only
    auto cell = [&](glm::vec3 p) {
        const glm::ivec3 c(glm::floor(p / near));
        return std::tuple<int, int, int>(c.x, c.y, c.z);
    };
    for (const SurfacePoint& s : in)
        if (s.distance > bound) grid[cell(s.point)].push_back(&s);
    size_t count = 0;
    for (const SurfacePoint& s : out) {
        if (s.distance <= bound) continue;
        float allowed = bound;
        const auto [x, y, z] = cell(s.point);
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    auto it = grid.find({x + dx, y + dy, z + dz});
                    if (it == grid.end()) continue;
                    for (const SurfacePoint* q : it->second)
                        if (glm::all(
                                glm::lessThanEqual(glm::abs(q->point - s.point), glm::vec3(near))))
                            allowed = std::max(allowed, q->distance);
                }
        if (s.distance > allowed) ++count;
    }
    return count;
}

// The vertices of a mesh with a neighbour of another colour.
std::set<Key> colourOutline(const Mesh& mesh) {
    std::set<Key> out;
    for (size_t t = 0; t < mesh.triangleCount(); ++t)
        for (int i = 0; i < 3; ++i) {
            const uint32_t a = mesh.indices[3 * t + i], b = mesh.indices[3 * t + (i + 1) % 3];
            if (mesh.colors[a] != mesh.colors[b]) {
                out.insert(bits(mesh.positions[a]));
                out.insert(bits(mesh.positions[b]));
            }
        }
    return out;
}

std::set<std::tuple<float, float, float>> colourSet(const Mesh& mesh) {
    std::set<std::tuple<float, float, float>> out;
    for (const glm::vec3& c : mesh.colors)
        out.insert({c.r, c.g, c.b});
    return out;
}

// The properties every simplification keeps, whatever its limits.
void expectFaithful(const Mesh& in, const Mesh& out) {
    const MeshProperties before = measureMesh(in), after = measureMesh(out);
    SCOPED_TRACE("before: " + before.str() + "\nafter: " + after.str());
    ASSERT_EQ(out.normals.size(), out.vertexCount());
    ASSERT_EQ(out.colors.size(), out.vertexCount());
    EXPECT_EQ(after.closedManifold(), before.closedManifold());
    EXPECT_EQ(after.boundaryEdges, before.boundaryEdges == 0 ? 0u : after.boundaryEdges);
    EXPECT_EQ(after.euler, before.euler);
    EXPECT_EQ(after.referencedVertices, after.vertices) << "unused vertices are dropped";
    EXPECT_GT(after.volume, 0.0);

    // Every vertex is one of the input's, with its normal and colour.
    std::map<Key, size_t> inputVertex;
    for (size_t v = 0; v < in.vertexCount(); ++v)
        inputVertex[bits(in.positions[v])] = v;
    size_t foreign = 0, changed = 0;
    for (size_t v = 0; v < out.vertexCount(); ++v) {
        auto it = inputVertex.find(bits(out.positions[v]));
        if (it == inputVertex.end()) {
            ++foreign;
            continue;
        }
        if (out.normals[v] != in.normals[it->second] || out.colors[v] != in.colors[it->second])
            ++changed;
    }
    EXPECT_EQ(foreign, 0u) << "vertices that are not the input's";
    EXPECT_EQ(changed, 0u) << "vertices whose normal or colour changed";

    // The same colours, and every vertex where two colours meet still there: each patch of one
    // colour keeps its outline.
    EXPECT_EQ(colourSet(out), colourSet(in));
    std::set<Key> kept;
    for (const glm::vec3& p : out.positions)
        kept.insert(bits(p));
    size_t lost = 0;
    for (const auto& p : colourOutline(in))
        lost += !kept.count(p);
    EXPECT_EQ(lost, 0u) << "vertices on the outline of a colour that the simplification removed";
}

class SimplifyTest : public GpuTest {
  protected:
    Mesh extract(const Scene& scene, uint32_t resolution, MeshStats* stats = nullptr,
                 std::optional<Aabb> bounds = std::nullopt) {
        MeshOptions options;
        options.resolution = resolution;
        options.bounds = bounds;
        auto mesh = extractMesh(context(), scene, options, stats);
        if (!mesh) {
            ADD_FAILURE() << mesh.error().str();
            return Mesh{};
        }
        return *mesh;
    }
};

// Simplified at a tenth of a cell, and at half a cell (more than the unsimplified meshes stray),
// where no point may stray farther at all; to at most `kept` of the triangles.
void expectWithinTheBound(const Mesh& in, const Evaluator& evaluator, float cell, bool wholeFirst,
                          double kept = 1.0 / 3, bool pruned = false) {
    const std::vector<SurfacePoint> inputSamples = samplePoints(in, evaluator, true, pruned);
    const float inputError = largest(inputSamples);
    for (float cells : {0.1f, 0.5f}) {
        SCOPED_TRACE(std::to_string(cells) + " cells");
        SimplifyOptions options;
        options.maxError = cells * cell;
        MeshStats stats;
        auto out = detail::simplifyMesh(in, evaluator, options, &stats, wholeFirst);
        ASSERT_TRUE(out) << out.error().str();
        expectFaithful(in, *out);
        EXPECT_EQ(stats.unsimplifiedTriangles, in.triangleCount());
        EXPECT_EQ(stats.triangles, out->triangleCount());
        EXPECT_LT(double(out->triangleCount()), kept * double(in.triangleCount()));

        const std::vector<SurfacePoint> samples = samplePoints(*out, evaluator, false, pruned);
        const float error = largest(samples);
        EXPECT_LE(error, std::max(*options.maxError, inputError));
        EXPECT_LE(straying(samples, inputSamples, *options.maxError, 2.0f * meanEdge(in)), 0u)
            << "points farther than the bound and than the unsimplified mesh nearby";
        if (inputError < *options.maxError) {
            EXPECT_LE(error, *options.maxError);
        }
        // Sampled at other points (the simplifier samples from each triangle's corner of least
        // index, and more often on large triangles): the two agree within half the bound, and
        // a fifth of the error where the input strays beyond it (thin parts: flat_4k at 64 cells,
        // whose largest errors lie on parts thinner than a cell, gives 0.048 against 0.040).
        EXPECT_NEAR(stats.simplifiedError, error, 1e-6f + 0.5f * *options.maxError + 0.2f * error)
            << "the reported error samples the same surface";
    }
}

class SimplifyScene : public SimplifyTest, public ::testing::WithParamInterface<const char*> {};

TEST_P(SimplifyScene, KeepsTopologyVerticesColoursAndTheBound) {
    const Scene scene = loadOrDie(kScenes / (std::string(GetParam()) + ".json"));
    MeshStats stats;
    const Mesh in = extract(scene, 96, &stats);
    ASSERT_TRUE(measureMesh(in).closedManifold());
    expectWithinTheBound(in, Evaluator(scene), stats.voxelSize, true);
}

INSTANTIATE_TEST_SUITE_P(Scenes, SimplifyScene,
                         ::testing::Values("mesh_a", "csg_part", "house", "gear", "chess_pawn"),
                         [](const auto& param) { return std::string(param.param); });

// The way taken where simplifying the whole mesh cannot be mended: blocks of space, each with its
// outline locked, then blocks shifted by half, then the whole.
TEST_F(SimplifyTest, InBlocksKeepsTheSameProperties) {
    for (const char* name : {"csg_part", "house"}) {
        SCOPED_TRACE(name);
        const Scene scene = loadOrDie(kScenes / (std::string(name) + ".json"));
        MeshStats stats;
        const Mesh in = extract(scene, 96, &stats);
        expectWithinTheBound(in, Evaluator(scene), stats.voxelSize, false);
    }
}

// A scene of 4,000 nodes, sampled by the pruned field as the GPU evaluates it. Its boxes of many
// colours hold most vertices in place at this resolution.
TEST_F(SimplifyTest, LargeScenesAreSampledByPrunedTapes) {
    const Scene scene =
        loadOrDie(std::filesystem::path(SDFCSG_SOURCE_DIR) / "assets/bench/flat_4k.json");
    MeshStats stats;
    const Mesh in = extract(scene, 64, &stats);
    expectWithinTheBound(in, Evaluator(scene), stats.voxelSize, true, 0.9, true);
}

// Down to the vertices that must stay (the outline of each colour); no further.
TEST_F(SimplifyTest, TargetTrianglesAloneAreReached) {
    const Scene scene = loadOrDie(kScenes / "mesh_a.json");
    const Mesh in = extract(scene, 96);
    for (size_t target : {in.triangleCount() / 4, in.triangleCount() / 8}) {
        SCOPED_TRACE(target);
        SimplifyOptions options;
        options.targetTriangles = target;
        MeshStats stats;
        auto out = simplifyMesh(in, Evaluator(scene), options, &stats);
        ASSERT_TRUE(out) << out.error().str();
        expectFaithful(in, *out);
        EXPECT_LE(out->triangleCount(), target);
        EXPECT_GT(out->triangleCount(), target * 9 / 10) << "no more than needed is removed";
        EXPECT_TRUE(std::isnan(stats.simplifiedError)) << "nothing was sampled";
    }
    SimplifyOptions options;
    options.targetTriangles = 10;
    auto out = simplifyMesh(in, Evaluator(scene), options);
    ASSERT_TRUE(out) << out.error().str();
    expectFaithful(in, *out);
    EXPECT_GT(out->triangleCount(), colourOutline(in).size() / 2);
}

// With both limits the simplification stops at the first it reaches.
TEST_F(SimplifyTest, TargetAndErrorStopAtTheFirstLimit) {
    const Scene scene = loadOrDie(kScenes / "csg_part.json");
    const Evaluator evaluator(scene);
    MeshStats stats;
    const Mesh in = extract(scene, 96, &stats);
    SimplifyOptions byError;
    byError.maxError = 0.1f * stats.voxelSize;
    auto errorOnly = simplifyMesh(in, evaluator, byError);
    ASSERT_TRUE(errorOnly) << errorOnly.error().str();

    SimplifyOptions both = byError;
    both.targetTriangles = errorOnly->triangleCount() * 3; // reached before the error limit
    auto countFirst = simplifyMesh(in, evaluator, both);
    ASSERT_TRUE(countFirst) << countFirst.error().str();
    expectFaithful(in, *countFirst);
    EXPECT_LE(countFirst->triangleCount(), *both.targetTriangles);
    EXPECT_GT(countFirst->triangleCount(), errorOnly->triangleCount());

    both.targetTriangles = 10; // the error limit comes first
    auto errorFirst = simplifyMesh(in, evaluator, both);
    ASSERT_TRUE(errorFirst) << errorFirst.error().str();
    expectFaithful(in, *errorFirst);
    EXPECT_GT(errorFirst->triangleCount(), 10u);
    EXPECT_LE(largest(samplePoints(*errorFirst, evaluator, false)),
              std::max(*byError.maxError, largest(samplePoints(in, evaluator, true))));
}

// The edges used by one triangle, as pairs of positions.
std::set<std::pair<Key, Key>> openEdges(const Mesh& mesh) {
    // +1 for each use from the lower position to the higher, -1 the other way.
    std::map<std::pair<Key, Key>, int> uses;
    for (size_t t = 0; t < mesh.triangleCount(); ++t)
        for (int i = 0; i < 3; ++i) {
            auto a = bits(mesh.positions[mesh.indices[3 * t + i]]);
            auto b = bits(mesh.positions[mesh.indices[3 * t + (i + 1) % 3]]);
            if (a < b)
                ++uses[{a, b}];
            else
                --uses[{b, a}];
        }
    std::set<std::pair<Key, Key>> open;
    for (const auto& [edge, n] : uses)
        if (n != 0) open.insert(edge);
    return open;
}

// Bounds that cut the surface leave an open mesh, whose outline must stay exactly where it is,
// straight stretches (of the box) included.
TEST_F(SimplifyTest, OpenMeshesKeepTheirOutline) {
    const Scene box = parseRoot(R"({"type": "box", "size": [1.5, 1, 1], "rotate": [0, 20, 0]})");
    for (const auto& [scene, bounds] :
         {std::pair(loadOrDie(kScenes / "mesh_a.json"),
                    Aabb{glm::vec3(-1.1f), glm::vec3(1.1f, 1.1f, 0.2f)}),
          std::pair(box, Aabb{glm::vec3(-1.0f), glm::vec3(1.0f, 0.2f, 1.0f)})}) {
        MeshStats stats;
        const Mesh in = extract(scene, 96, &stats, bounds);
        ASSERT_TRUE(stats.surfaceCut);
        const auto before = openEdges(in);
        ASSERT_GT(before.size(), 100u);
        SimplifyOptions byError, byCount; // the count far past what any error would allow
        byError.maxError = 0.1f * stats.voxelSize;
        byCount.targetTriangles = in.triangleCount() / 50;
        for (const SimplifyOptions& options : {byError, byCount}) {
            auto out = simplifyMesh(in, Evaluator(scene), options);
            ASSERT_TRUE(out) << out.error().str();
            EXPECT_LT(out->triangleCount() * 3, in.triangleCount());
            EXPECT_EQ(openEdges(*out), before);
            const MeshProperties after = measureMesh(*out);
            EXPECT_EQ(after.nonManifoldEdges, 0u) << after.str();
            EXPECT_EQ(after.misorientedEdges, 0u) << after.str();
            EXPECT_EQ(after.euler, measureMesh(in).euler);
        }
    }
}

TEST_F(SimplifyTest, IsRepeatable) {
    const Scene scene = loadOrDie(kScenes / "house.json");
    const Evaluator evaluator(scene);
    MeshStats stats;
    const Mesh in = extract(scene, 96, &stats);
    SimplifyOptions options;
    options.maxError = 0.1f * stats.voxelSize;
    auto a = simplifyMesh(in, evaluator, options), b = simplifyMesh(in, evaluator, options);
    ASSERT_TRUE(a && b);
    EXPECT_EQ(a->indices, b->indices);
    EXPECT_EQ(a->positions, b->positions);
    auto c = detail::simplifyMesh(in, evaluator, options, nullptr, false),
         d = detail::simplifyMesh(in, evaluator, options, nullptr, false);
    ASSERT_TRUE(c && d);
    EXPECT_EQ(c->indices, d->indices) << "blocks on two threads, in any order";
}

// Progress climbs to 1 without changing the result; a callback that returns false stops the
// simplification, whole or in blocks, at whichever report it does so.
TEST_F(SimplifyTest, ProgressEndsAtOneAndFalseCancels) {
    const Scene scene = loadOrDie(kScenes / "csg_part.json");
    const Evaluator evaluator(scene);
    MeshStats stats;
    const Mesh in = extract(scene, 96, &stats);
    for (bool wholeFirst : {true, false}) {
        SCOPED_TRACE(wholeFirst ? "whole first" : "in blocks");
        SimplifyOptions options;
        options.maxError = 0.1f * stats.voxelSize;
        auto quiet = detail::simplifyMesh(in, evaluator, options, nullptr, wholeFirst);
        ASSERT_TRUE(quiet) << quiet.error().str();
        std::vector<float> reported;
        options.progress = [&](float done) {
            reported.push_back(done);
            return true;
        };
        auto mesh = detail::simplifyMesh(in, evaluator, options, nullptr, wholeFirst);
        ASSERT_TRUE(mesh) << mesh.error().str();
        EXPECT_EQ(mesh->indices, quiet->indices);
        ASSERT_GT(reported.size(), 3u);
        EXPECT_TRUE(std::is_sorted(reported.begin(), reported.end()));
        EXPECT_GE(reported.front(), 0.0f);
        EXPECT_FLOAT_EQ(reported.back(), 1.0f);

        // The first report, the first at half or more, and the last.
        for (float stop : {0.0f, 0.5f, 1.0f}) {
            bool said = false, after = false;
            options.progress = [&](float done) {
                after = after || said;
                said = said || done >= stop;
                return !said;
            };
            auto stopped = detail::simplifyMesh(in, evaluator, options, nullptr, wholeFirst);
            ASSERT_FALSE(stopped) << "stopped at " << stop;
            EXPECT_EQ(stopped.error().kind, ErrorKind::Cancelled);
            EXPECT_EQ(stopped.error().str(), "<simplify>: cancelled");
            EXPECT_FALSE(after) << "no report after the one that said stop";
        }
    }
}

// Post-transform cache misses per triangle, by a FIFO cache of 16 vertices.
double missesPerTriangle(const Mesh& mesh) {
    std::deque<uint32_t> cache;
    size_t misses = 0;
    for (uint32_t v : mesh.indices) {
        if (std::find(cache.begin(), cache.end(), v) != cache.end()) continue;
        ++misses;
        cache.push_back(v);
        if (cache.size() > 16) cache.pop_front();
    }
    return double(misses) / double(mesh.triangleCount());
}

TEST_F(SimplifyTest, GpuOrderKeepsTheMeshAndSavesCacheMisses) {
    const Scene scene = loadOrDie(kScenes / "csg_part.json");
    const Mesh in = extract(scene, 96);
    for (bool fast : {false, true}) {
        SCOPED_TRACE(fast ? "fast" : "best");
        Mesh ordered = in;
        optimizeMeshOrder(ordered, fast);
        const MeshComparison diff = compareMeshes(ordered, in, 1e-6f, 0.0f, 0.0f);
        EXPECT_TRUE(diff.same()) << diff.str();
        EXPECT_LT(missesPerTriangle(ordered), 0.9 * missesPerTriangle(in));
        // Vertices in the order the triangles first use them.
        uint32_t next = 0;
        for (uint32_t v : ordered.indices) {
            ASSERT_LE(v, next);
            if (v == next) ++next;
        }
        EXPECT_EQ(next, ordered.vertexCount());
    }

    Mesh empty;
    optimizeMeshOrder(empty);
    EXPECT_EQ(empty.vertexCount(), 0u);
}

TEST(Simplify, BadOptionsAreUsageErrors) {
    const Scene scene = parseRoot(R"({"type": "sphere", "radius": 1})");
    const Evaluator evaluator(scene);
    const Mesh mesh;
    auto expectUsage = [&](const SimplifyOptions& options, const char* what) {
        SCOPED_TRACE(what);
        auto out = simplifyMesh(mesh, evaluator, options);
        ASSERT_FALSE(out);
        EXPECT_EQ(out.error().kind, ErrorKind::Usage);
    };
    expectUsage({}, "no limit");
    for (float bad : {0.0f, -1.0f, NAN, INFINITY}) {
        SimplifyOptions options;
        options.maxError = bad;
        expectUsage(options, "a bad error");
    }
    SimplifyOptions none;
    none.targetTriangles = 0;
    expectUsage(none, "no triangles");

    SimplifyOptions fine;
    fine.maxError = 0.1f;
    auto empty = simplifyMesh(mesh, evaluator, fine);
    ASSERT_TRUE(empty) << empty.error().str();
    EXPECT_EQ(empty->triangleCount(), 0u);
}

} // namespace
} // namespace sdfcsg::test
