// Mesh simplification and GPU ordering, by meshoptimizer (Arseny Kapoulkine).
//
// meshopt_simplify collapses edges in order of their quadric error (Garland and Heckbert,
// "Surface Simplification Using Quadric Error Metrics", SIGGRAPH 1997), keeping each survivor
// where it was; meshopt_optimizeVertexCache orders triangles for the post-transform cache (Tom
// Forsyth, "Linear-Speed Vertex Cache Optimisation", 2006), meshopt_optimizeVertexFetchRemap
// orders vertices by first use. A library that GPU engines ship, rather than collapses and
// quadrics of our own: the ordering alone would be as much code as this file.
//
// The simplifier's error is an area-weighted average of squared distances from the planes that
// a vertex has gathered, so next to a large flat face a small rounded one may move several times
// farther than it says, and it does not keep every edge manifold. Both are checked here after
// each simplification: the scene's field is sampled over every triangle of the result, and its
// edges, vertex fans, parts and Euler characteristic are held to the input's. A faulty result
// is simplified again with the input's vertices around each fault held in place, so one bad
// spot costs its neighbourhood, not the whole mesh. The target error grows over a few passes,
// each from the last one's result, so a pass that cannot be mended leaves the last good one.
// Mending does not always converge (holding vertices changes which collapses come first); where
// it does not, the mesh is simplified further in blocks of space, whose faults stay in their
// block.
#include "sdfcsg/mesh.h"

#include "mesh/mesh_colors.h"
#include "mesh/mesh_simplify.h"

#include "sdfcsg/compile.h"

#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>

#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <unordered_map>
#include <vector>

namespace sdfcsg {
namespace {

// The simplifier's error targets of the passes, as fractions of maxError. Reaching the bound at
// once (1 alone) fails and is mended far more often; starting lower, the later passes start
// from a mesh whose planes already carry the earlier passes' moves.
constexpr float kPasses[] = {0.25f, 0.5f, 1.0f};
// Tries of one pass, each with more of the input held, before the simplification stops.
constexpr uint32_t kTries = 6;
// How far around a fault the input's vertices are held, in spacings (the input's mean edge),
// and how far the search for one that is not held yet may widen.
constexpr float kHoldRadius = 1.0f;
constexpr float kHoldLimit = 32.0f;
// How far around a sample of a result the input's own samples set what it may stray, in spacings.
constexpr float kNear = 2.0f;
// The edge of the blocks simplified on their own where a pass of the whole cannot be mended, in
// spacings: a few thousand triangles each.
constexpr float kBlockSpacings = 32.0f;
// The FIFO cache that optimizeMeshOrder's fast order plans for, as meshoptimizer's own examples
// do: it advises less than the hardware's, since a plan for too large a cache thrashes.
constexpr unsigned kFifoCache = 16;
// The share of the progress that sampling the input takes (csg_part at 256: a tenth of the time).
constexpr float kSamplingShare = 0.1f;

// Points in a grid of cubic cells, for box queries. The points are not copied.
class PointGrid {
  public:
    PointGrid(const std::vector<glm::vec3>& points, float cell) : points_(points), cell_(cell) {
        entries_.reserve(points.size());
        for (uint32_t i = 0; i < points.size(); ++i)
            entries_.push_back({key(cellOf(points[i])), i});
        std::sort(entries_.begin(), entries_.end());
    }
    // Calls f(i) for every point i in the box [lo, hi].
    template <class F> void forEachIn(glm::vec3 lo, glm::vec3 hi, F&& f) const {
        const glm::ivec3 from = cellOf(lo), to = cellOf(hi);
        for (int z = from.z; z <= to.z; ++z)
            for (int y = from.y; y <= to.y; ++y)
                for (int x = from.x; x <= to.x; ++x) {
                    const uint64_t k = key({x, y, z});
                    auto it = std::lower_bound(entries_.begin(), entries_.end(),
                                               std::pair<uint64_t, uint32_t>(k, 0));
                    for (; it != entries_.end() && it->first == k; ++it) {
                        const glm::vec3 p = points_[it->second];
                        if (glm::all(glm::greaterThanEqual(p, lo)) &&
                            glm::all(glm::lessThanEqual(p, hi)))
                            f(it->second);
                    }
                }
    }

  private:
    glm::ivec3 cellOf(glm::vec3 p) const { return glm::ivec3(glm::floor(p / cell_)); }
    static uint64_t key(glm::ivec3 c) {
        return uint64_t(uint32_t(c.x) & 0x1fffff) << 42 | uint64_t(uint32_t(c.y) & 0x1fffff) << 21 |
               uint64_t(uint32_t(c.z) & 0x1fffff);
    }
    const std::vector<glm::vec3>& points_;
    float cell_;
    std::vector<std::pair<uint64_t, uint32_t>> entries_; // (cell, point), sorted
};

// How often each vertex pair is used as an edge, in each direction.
class EdgeTable {
  public:
    explicit EdgeTable(const std::vector<uint32_t>& indices) {
        halfEdges_.reserve(indices.size());
        for (size_t t = 0; t + 3 <= indices.size(); t += 3)
            for (int i = 0; i < 3; ++i) {
                const uint32_t a = indices[t + i], b = indices[t + (i + 1) % 3];
                halfEdges_.push_back(key(a, b) << 1 | (a < b ? 1u : 0u));
            }
        std::sort(halfEdges_.begin(), halfEdges_.end());
    }
    // One triangle uses the edge each way: the surface is closed and consistently wound there.
    bool sound(uint32_t a, uint32_t b) const {
        auto [lo, hi] = range(a, b);
        return hi - lo == 2 && *lo != *(lo + 1);
    }
    // One triangle uses the edge: it lies on the outline of an open surface.
    bool outline(uint32_t a, uint32_t b) const {
        auto [lo, hi] = range(a, b);
        return hi - lo == 1;
    }
    size_t distinct() const {
        size_t n = 0;
        for (size_t i = 0; i < halfEdges_.size(); ++i)
            n += i == 0 || halfEdges_[i] >> 1 != halfEdges_[i - 1] >> 1;
        return n;
    }

  private:
    static uint64_t key(uint32_t a, uint32_t b) {
        return uint64_t(std::min(a, b)) << 32 | std::max(a, b);
    }
    std::pair<std::vector<uint64_t>::const_iterator, std::vector<uint64_t>::const_iterator>
    range(uint32_t a, uint32_t b) const {
        const uint64_t k = key(a, b) << 1;
        auto lo = std::lower_bound(halfEdges_.begin(), halfEdges_.end(), k);
        auto hi = lo;
        while (hi != halfEdges_.end() && *hi >> 1 == k >> 1)
            ++hi;
        return {lo, hi};
    }
    std::vector<uint64_t> halfEdges_; // (pair << 1) | 1 where the edge runs from low to high
};

// Whether each vertex's triangles form one closed fan: a disk around it, as on a closed
// manifold. A pinch (two fans meeting at one vertex) or a fold fails.
std::vector<bool> closedFans(const std::vector<uint32_t>& indices, size_t vertexCount) {
    // The link of vertex v: for each triangle (v, b, c), the step b -> c. One cycle through all
    // of them is one closed fan.
    std::vector<uint32_t> offsets(vertexCount + 1, 0);
    for (uint32_t v : indices)
        ++offsets[v + 1];
    for (size_t v = 0; v < vertexCount; ++v)
        offsets[v + 1] += offsets[v];
    std::vector<std::pair<uint32_t, uint32_t>> links(indices.size());
    std::vector<uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (size_t t = 0; t + 3 <= indices.size(); t += 3)
        for (int i = 0; i < 3; ++i)
            links[fill[indices[t + i]]++] = {indices[t + (i + 1) % 3], indices[t + (i + 2) % 3]};
    std::vector<bool> closed(vertexCount, false);
    for (size_t v = 0; v < vertexCount; ++v) {
        const auto first = links.begin() + offsets[v], last = links.begin() + offsets[v + 1];
        const size_t n = size_t(last - first);
        if (n < 3) continue;
        std::sort(first, last);
        // Each step must start at a distinct vertex, and following them from the first must
        // come back after visiting all.
        bool distinct = true;
        for (auto it = first + 1; it != last; ++it)
            distinct = distinct && it->first != (it - 1)->first;
        if (!distinct) continue;
        uint32_t at = first->second;
        size_t steps = 1;
        while (steps < n && at != first->first) {
            auto next = std::lower_bound(first, last, std::pair<uint32_t, uint32_t>(at, 0));
            if (next == last || next->first != at) break;
            at = next->second;
            ++steps;
        }
        closed[v] = at == first->first && steps == n;
    }
    return closed;
}

// The connected component of each vertex (by shared triangles), named by one of its vertices.
std::vector<uint32_t> components(const std::vector<uint32_t>& indices, size_t vertexCount) {
    std::vector<uint32_t> parent(vertexCount);
    for (uint32_t v = 0; v < vertexCount; ++v)
        parent[v] = v;
    auto find = [&](uint32_t v) {
        while (parent[v] != v)
            v = parent[v] = parent[parent[v]];
        return v;
    };
    for (size_t t = 0; t + 3 <= indices.size(); t += 3)
        for (int i = 1; i < 3; ++i) {
            const uint32_t a = find(indices[t]), b = find(indices[t + i]);
            if (a != b) parent[std::max(a, b)] = std::min(a, b);
        }
    for (uint32_t v = 0; v < vertexCount; ++v)
        parent[v] = find(v);
    return parent;
}

int64_t eulerCharacteristic(const std::vector<uint32_t>& indices, const EdgeTable& edges) {
    std::vector<uint32_t> vertices(indices);
    std::sort(vertices.begin(), vertices.end());
    const int64_t used = int64_t(std::unique(vertices.begin(), vertices.end()) - vertices.begin());
    return used - int64_t(edges.distinct()) + int64_t(indices.size() / 3);
}

// Points spread over triangle (a, b, c), corners excluded: the centre, the middles of the sides
// and the points halfway from the centre to each corner (as `sdfcsg bench --mesh --error`
// samples), and for a triangle longer than twice `spacing` a barycentric lattice about
// `spacing` apart besides.
template <class F> void forEachSample(glm::vec3 a, glm::vec3 b, glm::vec3 c, float spacing, F&& f) {
    for (const glm::vec3& w : detail::kTriangleSamples)
        f(w.x * a + w.y * b + w.z * c);
    const float longest = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
    if (!(longest > 2.0f * spacing)) return;
    const int n = int(std::min(64.0f, std::ceil(longest / spacing)));
    for (int i = 0; i <= n; ++i)
        for (int j = 0; i + j <= n; ++j) {
            const int k = n - i - j;
            if (i == n || j == n || k == n) continue;
            f((float(i) * a + float(j) * b + float(k) * c) / float(n));
        }
}

// A triangle by its corners from the one of least index (the same in every mesh that holds it).
using TriangleKey = std::array<uint32_t, 3>;
TriangleKey keyOf(const uint32_t* v) {
    const int first = v[0] < v[1] ? (v[0] < v[2] ? 0 : 2) : (v[1] < v[2] ? 1 : 2);
    return {v[first], v[(first + 1) % 3], v[(first + 2) % 3]};
}
struct TriangleKeyHash {
    size_t operator()(const TriangleKey& k) const {
        return std::hash<uint64_t>()((uint64_t(k[0]) << 42) ^ (uint64_t(k[1]) << 21) ^ k[2]);
    }
};

// Reports SimplifyOptions::progress from the calling thread: the fraction done within the
// current stage of the whole, never falling. Any thread may ask whether the callback said stop.
class Progress {
  public:
    explicit Progress(const std::function<bool(float)>& callback)
        : callback_(callback), caller_(std::this_thread::get_id()) {}
    // The part of the whole, [from, to), that the next reports' fractions map to.
    void stage(float from, float to) {
        from_ = std::max(from, last_);
        to_ = std::max(to, from_);
    }
    // `done`: the fraction of the stage. Returns whether to go on.
    bool report(float done) {
        if (callback_ && std::this_thread::get_id() == caller_ && !stopped_) {
            last_ = std::max(last_, from_ + (to_ - from_) * std::clamp(done, 0.0f, 1.0f));
            if (!callback_(last_)) stopped_ = true;
        }
        return !stopped_;
    }
    bool stopped() const { return stopped_; }
    float last() const { return last_; }

  private:
    const std::function<bool(float)>& callback_;
    const std::thread::id caller_;
    float from_ = 0.0f, to_ = 1.0f, last_ = 0.0f;
    std::atomic<bool> stopped_{false};
};

struct Probe {
    glm::vec3 point;
    float error;       // |distance|
    uint32_t triangle; // the triangle it was sampled on
};

// The largest |distance| sampled on each triangle, on two threads if `parallel`; the samples for
// which keep(sample) holds are collected in `kept`. A triangle is sampled from its corner of
// least index, so that it is sampled alike in every mesh that holds it. Reports the fraction
// sampled to `progress`, and stops early (the errors unfinished) where it says stop.
template <class Distance, class Keep>
std::vector<float>
triangleErrors(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
               float spacing, const Distance& distance, const Keep& keep, std::vector<Probe>& kept,
               bool parallel, Progress* progress = nullptr) {
    const size_t triangles = indices.size() / 3;
    std::vector<float> errors(triangles, 0.0f);
    auto run = [&](size_t begin, size_t end, std::vector<Probe>& out) {
        for (size_t t = begin; t < end; ++t) {
            if (progress && (t - begin) % 4096 == 0 &&
                !progress->report(float(t - begin) / float(std::max<size_t>(end - begin, 1))))
                return;
            float worst = 0.0f;
            const TriangleKey v = keyOf(&indices[3 * t]);
            forEachSample(positions[v[0]], positions[v[1]], positions[v[2]], spacing,
                          [&](glm::vec3 p) {
                              const Probe s{p, std::abs(distance(p)), uint32_t(t)};
                              worst = std::max(worst, s.error);
                              if (keep(s)) out.push_back(s);
                          });
            errors[t] = worst;
        }
    };
    std::vector<Probe> theirs;
    // Two threads: the CPU evaluator's share of a small machine (the GPU meshes on the rest).
    if (!parallel || std::thread::hardware_concurrency() < 2 || triangles < 4096) {
        run(0, triangles, kept);
    } else {
        std::thread helper(run, triangles / 2, triangles, std::ref(theirs));
        run(0, triangles / 2, kept);
        helper.join();
    }
    kept.insert(kept.end(), theirs.begin(), theirs.end());
    return errors;
}

// Removes pairs of triangles on the same three vertices facing opposite ways. The simplifier
// leaves such fins, two-sided flaps hinged on an edge of the surface, where a collapse closes
// around a valence-three vertex; without them the surface is whole again.
size_t removeFins(std::vector<uint32_t>& indices) {
    struct Triangle {
        std::array<uint32_t, 3> sorted;
        bool odd; // the corners in sorted order wind the other way
        uint32_t at;
        bool operator<(const Triangle& o) const {
            return std::tie(sorted, odd, at) < std::tie(o.sorted, o.odd, o.at);
        }
    };
    std::vector<Triangle> triangles(indices.size() / 3);
    for (uint32_t t = 0; t < triangles.size(); ++t) {
        const uint32_t a = indices[3 * t], b = indices[3 * t + 1], c = indices[3 * t + 2];
        // (a, b, c) is an even permutation of its sorted order when it cycles upwards.
        const bool odd = (a < b) + (b < c) + (c < a) == 1;
        std::array<uint32_t, 3> sorted{a, b, c};
        std::sort(sorted.begin(), sorted.end());
        triangles[t] = {sorted, odd, t};
    }
    std::sort(triangles.begin(), triangles.end());
    std::vector<bool> removed(triangles.size(), false);
    size_t count = 0;
    for (size_t i = 0; i < triangles.size();) {
        size_t j = i;
        while (j < triangles.size() && triangles[j].sorted == triangles[i].sorted)
            ++j;
        size_t odd = i;
        while (odd < j && !triangles[odd].odd)
            ++odd;
        // Pairs each facing one way with one facing the other.
        for (size_t even = i, k = odd; even < odd && k < j; ++even, ++k) {
            removed[triangles[even].at] = removed[triangles[k].at] = true;
            count += 2;
        }
        i = j;
    }
    if (count == 0) return 0;
    size_t out = 0;
    for (size_t t = 0; t < removed.size(); ++t)
        if (!removed[t])
            for (int i = 0; i < 3; ++i)
                indices[out++] = indices[3 * t + i];
    indices.resize(out);
    return count;
}

// The mesh's positions with a copy of each held vertex appended. meshoptimizer classifies a
// position that two vertices share as an attribute seam, and a seam vertex that no open edge
// passes through (the copy is in no triangle) as locked: it may receive collapses but never
// moves. This is how meshoptimizer 0.18 (Debian 12's) can be told to hold a vertex; from 0.21
// on, meshopt_simplifyWithAttributes takes a lock array instead.
std::vector<glm::vec3> withHeldCopies(const std::vector<glm::vec3>& positions,
                                      const std::vector<bool>& held) {
    std::vector<glm::vec3> out(positions);
    for (size_t v = 0; v < positions.size(); ++v)
        if (held[v]) out.push_back(positions[v]);
    return out;
}

// Vertices with a neighbour of another colour, or on triangles of different colours: holding
// them keeps every one-coloured patch's outline where it is, and a collapse inside a patch joins
// vertices of the same colour, so the colour of every point of the surface stays what it was.
std::vector<bool> colourOutlines(const Mesh& mesh) {
    std::vector<bool> held(mesh.vertexCount(), false);
    if (mesh.colors.size() == mesh.vertexCount())
        for (size_t t = 0; t + 3 <= mesh.indices.size(); t += 3)
            for (int i = 0; i < 3; ++i) {
                const uint32_t a = mesh.indices[t + i], b = mesh.indices[t + (i + 1) % 3];
                if (mesh.colors[a] != mesh.colors[b]) held[a] = held[b] = true;
            }
    if (mesh.triangleColors.size() == mesh.triangleCount()) {
        std::vector<uint32_t> first(mesh.vertexCount(), UINT32_MAX);
        for (size_t t = 0; t < mesh.triangleCount(); ++t)
            for (int i = 0; i < 3; ++i) {
                uint32_t& f = first[mesh.indices[3 * t + i]];
                if (f == UINT32_MAX)
                    f = uint32_t(t);
                else if (mesh.triangleColors[f] != mesh.triangleColors[t])
                    held[mesh.indices[3 * t + i]] = true;
            }
    }
    return held;
}

// The colour of each triangle of `indices`, a simplification of `mesh`'s triangles: a corner that
// no outline holds lay inside one patch of one colour, and every triangle around it still does;
// a triangle of held corners alone takes the field's colour at its centre.
std::vector<glm::vec3> simplifiedColours(const Mesh& mesh, const std::vector<uint32_t>& indices,
                                         const Evaluator& evaluator, float spacing) {
    const std::vector<bool> outline = colourOutlines(mesh);
    std::vector<glm::vec3> patch(mesh.vertexCount());
    for (size_t t = 0; t < mesh.triangleCount(); ++t)
        for (int i = 0; i < 3; ++i)
            patch[mesh.indices[3 * t + i]] = mesh.triangleColors[t];
    std::vector<glm::vec3> colours(indices.size() / 3);
    for (size_t t = 0; t < colours.size(); ++t) {
        const uint32_t* v = &indices[3 * t];
        const int free = !outline[v[0]] ? 0 : !outline[v[1]] ? 1 : !outline[v[2]] ? 2 : -1;
        colours[t] =
            free >= 0
                ? patch[v[free]]
                : detail::surfaceColour(
                      evaluator,
                      (mesh.positions[v[0]] + mesh.positions[v[1]] + mesh.positions[v[2]]) / 3.0f,
                      spacing);
    }
    return colours;
}

// Holds the vertices around each fault: those within kHoldRadius spacings or, if all of those
// were held already (vertices that collapsed onto held ones made the fault), within twice, four
// times ... that, until one was not.
void holdAround(const std::vector<glm::vec3>& faults, std::vector<bool>& held,
                const PointGrid& grid, float spacing) {
    const std::vector<bool> wasHeld = held;
    for (const glm::vec3& p : faults)
        for (float r = kHoldRadius * spacing; r <= kHoldLimit * spacing; r *= 2.0f) {
            bool added = false;
            grid.forEachIn(p - r, p + r, [&](uint32_t v) {
                added = added || !wasHeld[v];
                held[v] = true;
            });
            if (added) break;
        }
}

Error usage(std::string text) {
    return Error::message(ErrorKind::Usage, "<simplify>", text);
}

// A simplification in rounds. A round simplifies the mesh whole or split into blocks of space
// (by the centres of its triangles), each block on its own with its outline locked
// (meshopt_SimplifyLockBorder) so that the blocks still fit together; a block whose result
// fails its checks is mended or left as it was without touching the others. Blocks are
// independent, so two threads share them and the result does not depend on their timing.
class Simplifier {
  public:
    // Samples the input, reporting to `progress`, which the simplification then reports to.
    Simplifier(const Mesh& mesh, const Evaluator& evaluator, const SimplifyOptions& options,
               Progress& progress)
        : mesh_(mesh), evaluator_(evaluator), options_(options), progress_(progress),
          pruned_(evaluator.nodes().size() >= kTapeMinNodes), spacing_(meanEdge(mesh)),
          held_(colourOutlines(mesh)), inputEdges_(mesh.indices),
          inputClosed_(closedFans(mesh.indices, mesh.vertexCount())),
          inputEuler_(eulerCharacteristic(mesh.indices, inputEdges_)) {
        // Where the input itself lies farther from the surface than maxError, a result may lie
        // as far as the input's samples within kNear spacings.
        if (options.maxError)
            for (float e : triangleErrors(
                     mesh.positions, mesh.indices, spacing_,
                     [&](glm::vec3 p) { return distance(p); },
                     [&](const Probe& s) { return s.error > *options.maxError; }, inputFar_, true,
                     &progress))
                error_ = std::max(error_, e);
        for (const Probe& s : inputFar_)
            inputFarPoints_.push_back(s.point);
        inputFarGrid_ = std::make_unique<PointGrid>(inputFarPoints_, 4.0f * spacing_);
        vertexGrid_ = std::make_unique<PointGrid>(mesh.positions, 4.0f * spacing_);
    }

    // The mesh after a round of blocks `blockSize` wide (all of it in one block when 0), their
    // grid shifted by `shift` blocks; each block stops at its share of `targetIndices` (0: none).
    std::vector<uint32_t> round(const std::vector<uint32_t>& indices, float blockSize, float shift,
                                size_t targetIndices) {
        // Blocks by the centre of each triangle, in the order of their keys.
        std::vector<std::pair<uint64_t, uint32_t>> keyed; // (block, triangle)
        keyed.reserve(indices.size() / 3);
        for (uint32_t t = 0; t < indices.size() / 3; ++t) {
            uint64_t key = 0;
            if (blockSize > 0) {
                const glm::vec3 centre =
                    (mesh_.positions[indices[3 * t]] + mesh_.positions[indices[3 * t + 1]] +
                     mesh_.positions[indices[3 * t + 2]]) /
                    3.0f;
                const glm::ivec3 c = glm::ivec3(glm::floor(centre / blockSize + shift));
                key = uint64_t(uint32_t(c.x) & 0x1fffff) << 42 |
                      uint64_t(uint32_t(c.y) & 0x1fffff) << 21 | uint64_t(uint32_t(c.z) & 0x1fffff);
            }
            keyed.push_back({key, t});
        }
        std::sort(keyed.begin(), keyed.end());
        std::vector<std::pair<size_t, size_t>> blocks; // ranges of `keyed`
        for (size_t i = 0; i < keyed.size();) {
            size_t j = i;
            while (j < keyed.size() && keyed[j].first == keyed[i].first)
                ++j;
            blocks.push_back({i, j});
            i = j;
        }

        std::vector<Piece> pieces(blocks.size());
        // Simplifies the listed blocks, two at a time.
        auto simplifyBlocks = [&](const std::vector<size_t>& list) {
            std::atomic<size_t> next{0}, done{0};
            auto work = [&] {
                for (size_t i; !progress_.stopped() && (i = next++) < list.size();) {
                    const size_t b = list[i];
                    std::vector<uint32_t> block;
                    block.reserve(3 * (blocks[b].second - blocks[b].first));
                    for (size_t k = blocks[b].first; k < blocks[b].second; ++k)
                        for (int c = 0; c < 3; ++c)
                            block.push_back(indices[3 * keyed[k].second + c]);
                    const size_t share = targetIndices
                                             ? std::max<size_t>(3, targetIndices * block.size() /
                                                                       indices.size() / 3 * 3)
                                             : 0;
                    pieces[b] = Piece{};
                    simplify(block, share, blocks.size() == 1, pieces[b]);
                    if (blocks.size() > 1) progress_.report(float(++done) / float(list.size()));
                }
            };
            if (list.size() > 1 && std::thread::hardware_concurrency() >= 2) {
                std::thread helper(work);
                work();
                helper.join();
            } else {
                work();
            }
            for (size_t b : list) {
                for (uint32_t v : pieces[b].held)
                    held_[v] = true;
                attempts_ += pieces[b].attempts;
            }
        };
        std::vector<size_t> all(blocks.size());
        for (size_t b = 0; b < blocks.size(); ++b)
            all[b] = b;
        simplifyBlocks(all);
        if (progress_.stopped()) return indices;

        // Each block keeps its own topology, but two may meet badly along their common outline:
        // both joining the same two outline vertices makes an edge of four triangles. Such
        // blocks are simplified again with the vertices there held, and after kTries left as
        // they were (as the round's input, they fit). A single block has been checked whole.
        std::vector<bool> restored(blocks.size(), false);
        auto restore = [&](size_t b) {
            Piece& piece = pieces[b];
            piece.indices.clear();
            for (size_t k = blocks[b].first; k < blocks[b].second; ++k)
                for (int c = 0; c < 3; ++c)
                    piece.indices.push_back(indices[3 * keyed[k].second + c]);
            piece.error = errorOf(piece.indices, blocks.size() == 1);
            restored[b] = true;
        };
        std::vector<uint32_t> out;
        for (uint32_t tries = 1;; ++tries) {
            out.clear();
            std::vector<uint32_t> owner; // block of each triangle of `out`
            for (size_t b = 0; b < pieces.size(); ++b) {
                out.insert(out.end(), pieces[b].indices.begin(), pieces[b].indices.end());
                owner.insert(owner.end(), pieces[b].indices.size() / 3, uint32_t(b));
            }
            if (blocks.size() == 1) break;
            std::vector<glm::vec3> faults;
            std::vector<size_t> redo;
            for (size_t t : topologyFaults(out)) {
                redo.push_back(owner[t]);
                for (int i = 0; i < 3; ++i)
                    faults.push_back(mesh_.positions[out[3 * t + i]]);
            }
            if (redo.empty()) {
                if (eulerOf(out) == inputEuler_) break;
                stalled_ = true; // changed where no check points: the round is undone
                return indices;
            }
            std::sort(redo.begin(), redo.end());
            redo.erase(std::unique(redo.begin(), redo.end()), redo.end());
            if (tries >= kTries) {
                if (std::all_of(redo.begin(), redo.end(), [&](size_t b) { return restored[b]; })) {
                    stalled_ = true; // cannot happen when the round's input was sound
                    return indices;
                }
                for (size_t b : redo)
                    restore(b);
                continue;
            }
            holdAround(faults, held_, *vertexGrid_, spacing_);
            simplifyBlocks(redo);
        }
        error_ = 0.0f;
        stalled_ = false;
        for (const Piece& piece : pieces) {
            error_ = std::max(error_, piece.error);
            stalled_ = stalled_ || piece.stalled;
        }
        return out;
    }

    float error() const { return error_; } // largest sampled distance of the last round's result
    uint32_t attempts() const { return attempts_; }
    bool stalled() const { return stalled_; } // a block of the last round did not simplify
    float spacing() const { return spacing_; }

  private:
    // A block's result: global indices, the vertices it held besides those held before, the
    // largest distance sampled on it and the simplifications it took.
    struct Piece {
        std::vector<uint32_t> indices;
        std::vector<uint32_t> held;
        float error = 0;
        uint32_t attempts = 0;
        bool stalled = false; // a pass could not be mended
    };

    static float meanEdge(const Mesh& mesh) {
        double sum = 0;
        for (size_t t = 0; t + 3 <= mesh.indices.size(); t += 3)
            for (int i = 0; i < 3; ++i)
                sum += glm::length(mesh.positions[mesh.indices[t + i]] -
                                   mesh.positions[mesh.indices[t + (i + 1) % 3]]);
        return mesh.indices.empty() ? 1.0f : float(sum / double(mesh.indices.size()));
    }

    // The triangles of a simplification of the whole input on an edge that is not used once
    // each way (unless it was the input's outline) or at a vertex whose closed fan is not.
    std::vector<size_t> topologyFaults(const std::vector<uint32_t>& indices) const {
        const EdgeTable edges(indices);
        const std::vector<bool> closed = closedFans(indices, mesh_.vertexCount());
        std::vector<size_t> faulty;
        for (size_t t = 0; t + 3 <= indices.size(); t += 3)
            for (int i = 0; i < 3; ++i) {
                const uint32_t a = indices[t + i], b = indices[t + (i + 1) % 3];
                if ((!edges.sound(a, b) && !(edges.outline(a, b) && inputEdges_.outline(a, b))) ||
                    (inputClosed_[a] && !closed[a])) {
                    faulty.push_back(t / 3);
                    break;
                }
            }
        return faulty;
    }
    static int64_t eulerOf(const std::vector<uint32_t>& indices) {
        return eulerCharacteristic(indices, EdgeTable(indices));
    }

    float distance(glm::vec3 p) const {
        return pruned_ ? evaluator_.prunedDistance(p) : evaluator_.distance(p);
    }
    // The largest distance sampled on the triangles (0 without maxError, which is not sampled).
    float errorOf(const std::vector<uint32_t>& indices, bool parallel) const {
        float worst = 0.0f;
        std::vector<Probe> none;
        if (options_.maxError)
            for (float e : triangleErrors(
                     mesh_.positions, indices, spacing_, [&](glm::vec3 p) { return distance(p); },
                     [](const Probe&) { return false; }, none, parallel))
                worst = std::max(worst, e);
        return worst;
    }

    bool tooFar(const Probe& s) const {
        const float limit = *options_.maxError;
        if (s.error <= limit) return false;
        float allowed = limit;
        inputFarGrid_->forEachIn(
            s.point - kNear * spacing_, s.point + kNear * spacing_,
            [&](uint32_t i) { allowed = std::max(allowed, inputFar_[i].error); });
        return s.error > allowed;
    }

    // Simplifies one block (global indices) in passes of growing error, each retried with more
    // of it held until it passes; ends with the last result that passed. `parallel`: sample on
    // two threads (when the block is the whole mesh).
    void simplify(const std::vector<uint32_t>& block, size_t targetIndices, bool parallel,
                  Piece& piece) const {
        // The block with vertices of its own, 0 ..
        std::vector<uint32_t> ids(block); // local -> global
        std::sort(ids.begin(), ids.end());
        ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
        const size_t n = ids.size();
        std::vector<uint32_t> reference(block.size());
        for (size_t i = 0; i < block.size(); ++i)
            reference[i] =
                uint32_t(std::lower_bound(ids.begin(), ids.end(), block[i]) - ids.begin());
        std::vector<glm::vec3> positions(n);
        std::vector<bool> held(n);
        for (size_t v = 0; v < n; ++v) {
            positions[v] = mesh_.positions[ids[v]];
            held[v] = held_[ids[v]];
        }
        const std::vector<bool> heldBefore = held;
        const PointGrid grid(positions, 4.0f * spacing_);
        const float scale = meshopt_simplifyScale(&positions[0].x, n, sizeof(glm::vec3));

        // What the block is held to: its edges (its outline is used once), the vertices whose
        // fan is closed, its parts and its Euler characteristic.
        const EdgeTable referenceEdges(reference);
        const std::vector<bool> referenceClosed = closedFans(reference, n);
        const std::vector<uint32_t> parts = components(reference, n);
        const int64_t referenceEuler = eulerCharacteristic(reference, referenceEdges);
        // The largest distance sampled on each triangle checked so far that strays nowhere.
        std::unordered_map<TriangleKey, float, TriangleKeyHash> sampled;
        // False, with the places to hold in `faults` (empty when the topology changed where no
        // check can point), where a result strays too far or its topology changed.
        const auto check = [&](const std::vector<uint32_t>& indices, std::vector<glm::vec3>& faults,
                               float& worst) {
            faults.clear();
            const EdgeTable edges(indices);
            const std::vector<bool> closed = closedFans(indices, n);
            std::vector<bool> present(n, false); // by part
            // A triangle on an edge or at a vertex whose neighbourhood changed: the vertices that
            // collapsed into it came from around its corners.
            for (size_t t = 0; t + 3 <= indices.size(); t += 3) {
                bool bad = false;
                for (int i = 0; i < 3; ++i) {
                    const uint32_t a = indices[t + i], b = indices[t + (i + 1) % 3];
                    present[parts[a]] = true;
                    bad = bad ||
                          (!edges.sound(a, b) &&
                           !(edges.outline(a, b) && referenceEdges.outline(a, b))) ||
                          (referenceClosed[a] && !closed[a]);
                }
                if (bad)
                    for (int i = 0; i < 3; ++i)
                        faults.push_back(positions[indices[t + i]]);
            }
            // A small part simplified down to a fin, and gone with it.
            for (size_t t = 0; t + 3 <= reference.size(); t += 3)
                if (!present[parts[reference[t]]]) faults.push_back(positions[reference[t]]);
            worst = 0.0f;
            if (options_.maxError) {
                // Only triangles not sampled before: a retry or the next pass keeps most.
                std::vector<uint32_t> fresh;
                std::vector<TriangleKey> freshKeys;
                for (size_t t = 0; t + 3 <= indices.size(); t += 3) {
                    const TriangleKey key = keyOf(&indices[t]);
                    if (auto it = sampled.find(key); it != sampled.end()) {
                        worst = std::max(worst, it->second);
                    } else {
                        fresh.insert(fresh.end(), &indices[t], &indices[t] + 3);
                        freshKeys.push_back(key);
                    }
                }
                std::vector<Probe> far;
                const std::vector<float> errors = triangleErrors(
                    positions, fresh, spacing_, [&](glm::vec3 p) { return distance(p); },
                    [&](const Probe& s) { return tooFar(s); }, far, parallel);
                std::vector<bool> strays(errors.size(), false);
                for (const Probe& s : far) {
                    faults.push_back(s.point);
                    strays[s.triangle] = true;
                }
                for (size_t t = 0; t < errors.size(); ++t) {
                    worst = std::max(worst, errors[t]);
                    if (!strays[t]) sampled.emplace(freshKeys[t], errors[t]);
                }
            }
            return faults.empty() && eulerCharacteristic(indices, edges) == referenceEuler;
        };
        std::vector<float> passes; // the simplifier's target errors, relative to the block
        if (options_.maxError)
            for (float fraction : kPasses)
                passes.push_back(fraction * *options_.maxError / std::max(scale, 1e-30f));
        else
            passes.push_back(std::numeric_limits<float>::max());
        std::vector<uint32_t> current = reference, indices;
        std::vector<glm::vec3> faults;
        std::optional<float> currentError; // unknown until a pass passes
        bool stuck = false;
        for (size_t pass = 0; pass < passes.size() && !stuck; ++pass) {
            for (uint32_t tries = 1;; ++tries) {
                if (progress_.stopped()) {
                    stuck = piece.stalled = true;
                    break;
                }
                ++piece.attempts;
                const std::vector<glm::vec3> withCopies = withHeldCopies(positions, held);
                indices.resize(current.size());
                indices.resize(meshopt_simplify(indices.data(), current.data(), current.size(),
                                                &withCopies[0].x, withCopies.size(),
                                                sizeof(glm::vec3), targetIndices, passes[pass],
                                                meshopt_SimplifyLockBorder, nullptr));
                removeFins(indices);
                float worst = 0.0f;
                const bool passed = check(indices, faults, worst);
                if (parallel) // the whole mesh in one block
                    progress_.report((float(pass) + float(passed ? kTries : tries) / kTries) /
                                     float(passes.size()));
                if (passed) {
                    current.swap(indices);
                    currentError = worst;
                    break;
                }
                // A changed topology that no check points at cannot be mended.
                if (tries == kTries || faults.empty()) {
                    stuck = true;
                    piece.stalled = true;
                    break;
                }
                holdAround(faults, held, grid, spacing_);
            }
            if (targetIndices && current.size() <= targetIndices) break;
        }
        piece.indices.resize(current.size());
        for (size_t i = 0; i < current.size(); ++i)
            piece.indices[i] = ids[current[i]];
        for (size_t v = 0; v < n; ++v)
            if (held[v] && !heldBefore[v]) piece.held.push_back(ids[v]);
        piece.error = currentError ? *currentError : errorOf(piece.indices, parallel);
    }

    const Mesh& mesh_;
    const Evaluator& evaluator_;
    const SimplifyOptions& options_;
    Progress& progress_;
    const bool pruned_;      // evaluate by pruned tapes, as the GPU does for large scenes
    const float spacing_;    // the input's mean edge length, about a cell of its grid
    std::vector<bool> held_; // vertices no simplification may move (read by the blocks)
    const EdgeTable inputEdges_;
    const std::vector<bool> inputClosed_; // vertices whose fan is closed
    const int64_t inputEuler_;
    std::unique_ptr<PointGrid> vertexGrid_;
    std::vector<Probe> inputFar_;
    std::vector<glm::vec3> inputFarPoints_;
    std::unique_ptr<PointGrid> inputFarGrid_;
    float error_ = 0.0f;
    uint32_t attempts_ = 0;
    bool stalled_ = false;
};

} // namespace

void optimizeMeshOrder(Mesh& mesh, bool fast) {
    const size_t n = mesh.vertexCount();
    if (mesh.indices.empty()) {
        mesh = Mesh{};
        return;
    }
    // meshoptimizer reorders whole triangles, each with its corners in their order; a triangle's
    // colour follows it, found among the triangles of the same first corner.
    const bool triangleColours = mesh.triangleColors.size() == mesh.triangleCount();
    std::vector<uint32_t> before, byFirst, firstStart;
    if (triangleColours) {
        before = mesh.indices;
        firstStart.assign(n + 1, 0);
        for (size_t t = 0; t < mesh.triangleCount(); ++t)
            ++firstStart[before[3 * t] + 1];
        for (size_t v = 0; v < n; ++v)
            firstStart[v + 1] += firstStart[v];
        byFirst.resize(mesh.triangleCount());
        std::vector<uint32_t> fill(firstStart.begin(), firstStart.end() - 1);
        for (size_t t = 0; t < mesh.triangleCount(); ++t)
            byFirst[fill[before[3 * t]]++] = uint32_t(t);
    }
    if (fast)
        meshopt_optimizeVertexCacheFifo(mesh.indices.data(), mesh.indices.data(),
                                        mesh.indices.size(), n, kFifoCache);
    else
        meshopt_optimizeVertexCache(mesh.indices.data(), mesh.indices.data(), mesh.indices.size(),
                                    n);
    if (triangleColours) {
        std::vector<glm::vec3> colours(mesh.triangleCount());
        std::vector<bool> taken(mesh.triangleCount(), false);
        for (size_t o = 0; o < colours.size(); ++o) {
            const uint32_t* v = &mesh.indices[3 * o];
            for (uint32_t j = firstStart[v[0]]; j < firstStart[v[0] + 1]; ++j) {
                const uint32_t t = byFirst[j];
                if (!taken[t] && before[3 * t + 1] == v[1] && before[3 * t + 2] == v[2]) {
                    taken[t] = true;
                    colours[o] = mesh.triangleColors[t];
                    break;
                }
            }
        }
        mesh.triangleColors = std::move(colours);
    }
    std::vector<uint32_t> remap(n);
    const size_t kept =
        meshopt_optimizeVertexFetchRemap(remap.data(), mesh.indices.data(), mesh.indices.size(), n);
    meshopt_remapIndexBuffer(mesh.indices.data(), mesh.indices.data(), mesh.indices.size(),
                             remap.data());
    auto reorder = [&](std::vector<glm::vec3>& values) {
        if (values.size() != n) return;
        std::vector<glm::vec3> out(kept);
        for (size_t v = 0; v < n; ++v)
            if (remap[v] != ~0u) out[remap[v]] = values[v];
        values = std::move(out);
    };
    reorder(mesh.positions);
    reorder(mesh.normals);
    reorder(mesh.colors);
}

namespace detail {

Result<Mesh> simplifyMesh(const Mesh& mesh, const Evaluator& evaluator,
                          const SimplifyOptions& options, MeshStats* stats, bool wholeFirst) {
    if (!options.maxError && !options.targetTriangles)
        return usage("simplification needs a largest error, a triangle count or both");
    if (options.maxError && !(std::isfinite(*options.maxError) && *options.maxError > 0.0f))
        return usage("the largest error of a simplification must be a finite number > 0, got " +
                     std::to_string(*options.maxError));
    if (options.targetTriangles && *options.targetTriangles == 0)
        return usage("the triangle count of a simplification must be at least 1");

    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    const Error cancelled = Error::message(ErrorKind::Cancelled, "<simplify>", "cancelled");
    Progress progress(options.progress);
    progress.stage(0.0f, kSamplingShare);
    Simplifier simplifier(mesh, evaluator, options, progress);
    std::vector<uint32_t> indices = mesh.indices;
    const size_t targetIndices = options.targetTriangles ? *options.targetTriangles * 3 : 0;
    if (!indices.empty()) {
        // The whole mesh at once leaves the fewest triangles. Where a pass cannot be mended,
        // blocks can, a fault costing only its own block: then the mesh in blocks, again in
        // blocks shifted by half a block, and once more whole for the strips along their
        // outlines (which stay as they are if that fails too). Each round reports as a stage.
        struct Round {
            float block, shift;
        };
        std::vector<Round> rounds;
        if (wholeFirst) rounds.push_back({0.0f, 0.0f});
        const auto blockRounds = [&] {
            const float block = kBlockSpacings * simplifier.spacing();
            rounds.insert(rounds.end(), {{block, 0.0f}, {block, 0.5f}, {0.0f, 0.0f}});
        };
        if (!wholeFirst) blockRounds();
        for (size_t r = 0; r < rounds.size(); ++r) {
            const float from = progress.last(), left = float(rounds.size() - r);
            progress.stage(from, from + (1.0f - from) / left);
            indices = simplifier.round(indices, rounds[r].block, rounds[r].shift, targetIndices);
            if (progress.stopped()) return cancelled;
            if (wholeFirst && r == 0 && simplifier.stalled()) blockRounds();
        }
    }
    if (progress.stopped()) return cancelled;
    progress.stage(1.0f, 1.0f);
    if (!progress.report(1.0f)) return cancelled;

    Mesh result;
    result.positions = mesh.positions;
    result.normals = mesh.normals;
    result.colors = mesh.colors;
    if (mesh.triangleColors.size() == mesh.triangleCount())
        result.triangleColors = simplifiedColours(mesh, indices, evaluator, simplifier.spacing());
    result.indices = std::move(indices);
    const auto simplified = Clock::now();
    optimizeMeshOrder(result);

    if (stats) {
        const auto seconds = [](auto from, auto to) {
            return std::chrono::duration<double>(to - from).count();
        };
        const double simplifySeconds = seconds(start, simplified);
        const double orderSeconds = seconds(simplified, Clock::now());
        stats->unsimplifiedTriangles = mesh.triangleCount();
        stats->simplifyAttempts = simplifier.attempts();
        stats->simplifiedError = options.maxError ? simplifier.error() : NAN;
        stats->vertices = result.vertexCount();
        stats->triangles = result.triangleCount();
        stats->stages.push_back({"simplify", simplifySeconds});
        stats->stages.push_back({"order", orderSeconds});
        stats->totalSeconds += simplifySeconds + orderSeconds;
    }
    return result;
}

} // namespace detail

Result<Mesh> simplifyMesh(const Mesh& mesh, const Evaluator& evaluator,
                          const SimplifyOptions& options, MeshStats* stats) {
    return detail::simplifyMesh(mesh, evaluator, options, stats, true);
}

} // namespace sdfcsg
