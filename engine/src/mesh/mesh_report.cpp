// The mesh report: edges by sorting half-edges, shells by union-find over the triangles'
// vertices, self-intersections by mesh/self_intersections.cpp.
#include "sdfcsg/mesh_report.h"

#include "mesh/radix_sort.h"
#include "mesh/self_intersections.h"
#include "sdfcsg/compile.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <numeric>
#include <optional>
#include <thread>
#include <vector>

namespace sdfcsg {
namespace {

// Union-find over vertex numbers, with path halving.
struct Pieces {
    std::vector<uint32_t> parent;
    explicit Pieces(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
    uint32_t root(uint32_t v) {
        while (parent[v] != v)
            v = parent[v] = parent[parent[v]];
        return v;
    }
    void join(uint32_t a, uint32_t b) { parent[root(a)] = root(b); }
};

// The wall under point c of the surface, along -n (n the outward unit normal there): the distance
// from c to where the field turns positive again, marching by the field's value (every field is
// 1-Lipschitz, so a step never passes the far side by more than `least`). Nothing where the march
// does not get inside (c on a sharp edge, n off) or leaves no inside within `reach`.
std::optional<float> wallAt(const std::function<float(glm::vec3)>& field, glm::vec3 c, glm::vec3 n,
                            float least, float reach) {
    float t = std::max(field(c), 0.0f) + least;
    if (!(field(c - n * t) < 0.0f)) return std::nullopt;
    for (int step = 0; step < 256 && t < reach; ++step) {
        const float d = field(c - n * t);
        if (d >= 0.0f) return t;
        t += std::max(-d, least);
    }
    return std::nullopt;
}

// The scene's field; large scenes answer from pruned tapes, as their kernels do.
std::function<float(glm::vec3)> fieldOf(const Evaluator& evaluator) {
    const bool pruned = evaluator.nodes().size() >= kTapeMinNodes;
    return [&evaluator, pruned](glm::vec3 x) {
        return pruned ? evaluator.prunedDistance(x) : evaluator.distance(x);
    };
}

Printability printability(const Mesh& mesh, const Evaluator& evaluator, float minWall,
                          size_t samples, const Aabb& bounds) {
    Printability p;
    p.minWall = minWall;
    const size_t n = mesh.triangleCount();
    if (n == 0 || bounds.empty()) return p;
    const float size = glm::length(bounds.max - bounds.min);
    const float least = 1e-4f * size, plate = bounds.min.y + 1e-4f * size;
    const std::function<float(glm::vec3)> field = fieldOf(evaluator);
    const size_t stride = std::max<size_t>(1, (n + samples - 1) / std::max<size_t>(samples, 1));
    double sampledArea = 0, thinSampled = 0, area = 0;
    for (size_t t = 0; t < n; ++t) {
        const uint32_t* v = &mesh.indices[3 * t];
        if (v[0] >= mesh.vertexCount() || v[1] >= mesh.vertexCount() || v[2] >= mesh.vertexCount())
            continue;
        const glm::vec3 a = mesh.positions[v[0]], b = mesh.positions[v[1]],
                        c = mesh.positions[v[2]];
        const glm::vec3 cross = glm::cross(b - a, c - a);
        const float twice = glm::length(cross);
        if (!(twice > 0.0f)) continue;
        const glm::vec3 normal = cross / twice;
        area += 0.5 * twice;
        const bool onPlate = a.y <= plate && b.y <= plate && c.y <= plate;
        if (!onPlate && -normal.y > 0.70710678f) p.overhangArea += 0.5 * twice;
        if (t % stride != 0) continue;
        const glm::vec3 centre = (a + b + c) / 3.0f;
        const auto wall = wallAt(field, centre, normal, least, size);
        if (!wall) continue;
        ++p.samples;
        sampledArea += 0.5 * twice;
        if (*wall < minWall) thinSampled += 0.5 * twice;
        if (*wall < p.thinnestWall) p.thinnestWall = *wall, p.thinnestAt = centre;
    }
    if (sampledArea > 0) p.thinArea = area * thinSampled / sampledArea;
    return p;
}

} // namespace

float defaultMinWall(LengthUnit unit) {
    return float(0.8 / millimetres(unit));
}

std::vector<float> wallThickness(const Mesh& mesh, const Evaluator& evaluator) {
    std::vector<float> walls(mesh.vertexCount(), std::numeric_limits<float>::infinity());
    Aabb box;
    for (const glm::vec3& p : mesh.positions)
        box.min = glm::min(box.min, p), box.max = glm::max(box.max, p);
    if (box.empty()) return walls;
    const float size = glm::length(box.max - box.min);
    const std::function<float(glm::vec3)> field = fieldOf(evaluator);
    for (size_t v = 0; v < walls.size(); ++v)
        if (auto wall = wallAt(field, mesh.positions[v], mesh.normals[v], 1e-4f * size, size))
            walls[v] = *wall;
    return walls;
}

MeshReport reportMesh(const Mesh& mesh, const Evaluator& evaluator, float minWall, size_t samples) {
    // The walls (from the field) on a thread of their own beside the mesh's own checks; they
    // need only the bounds of the vertices that the triangles use.
    Aabb bounds;
    for (const uint32_t v : mesh.indices)
        if (v < mesh.vertexCount()) {
            bounds.min = glm::min(bounds.min, mesh.positions[v]);
            bounds.max = glm::max(bounds.max, mesh.positions[v]);
        }
    Printability walls;
    std::thread measure([&] { walls = printability(mesh, evaluator, minWall, samples, bounds); });
    MeshReport r = reportMesh(mesh);
    measure.join();
    r.printability = walls;
    return r;
}

MeshReport reportMesh(const Mesh& mesh) {
    MeshReport r;
    r.vertices = mesh.vertexCount();
    r.triangles = mesh.triangleCount();
    std::vector<bool> used(r.vertices, false);
    Pieces pieces(r.vertices);
    // Per side of a triangle: lower vertex << bits | higher vertex (`bits` the vertex numbers'
    // width), in `forward` where it runs from the lower to the higher, else in `backward`.
    // Sorted, the uses of each edge lie together in each.
    const int bits = detail::bitsFor(r.vertices);
    std::vector<uint64_t> forward, backward;
    forward.reserve(mesh.indices.size() / 2 + 1);
    backward.reserve(mesh.indices.size() / 2 + 1);
    size_t unusable = 0; // triangles with indices out of range or repeated
    for (size_t t = 0; t < r.triangles; ++t) {
        const uint32_t* v = &mesh.indices[3 * t];
        if (v[0] >= r.vertices || v[1] >= r.vertices || v[2] >= r.vertices || v[0] == v[1] ||
            v[1] == v[2] || v[2] == v[0]) {
            ++r.degenerateTriangles, ++unusable;
            continue;
        }
        const glm::dvec3 a(mesh.positions[v[0]]), b(mesh.positions[v[1]]), c(mesh.positions[v[2]]);
        const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
        if (!(area > 0.0)) ++r.degenerateTriangles;
        r.area += area;
        r.volume += glm::dot(a, glm::cross(b, c)) / 6.0;
        for (int i = 0; i < 3; ++i) {
            const uint32_t from = v[i], to = v[(i + 1) % 3];
            used[from] = true;
            pieces.join(from, to);
            r.bounds.min = glm::min(r.bounds.min, mesh.positions[from]);
            r.bounds.max = glm::max(r.bounds.max, mesh.positions[from]);
            const uint64_t lo = std::min(from, to), hi = std::max(from, to);
            (from < to ? forward : backward).push_back(lo << bits | hi);
        }
    }
    detail::radixSort(forward, 0, 2 * bits);
    detail::radixSort(backward, 0, 2 * bits);
    for (size_t f = 0, b = 0; f < forward.size() || b < backward.size();) {
        const uint64_t edge = b == backward.size()                              ? forward[f]
                              : f == forward.size() || backward[b] < forward[f] ? backward[b]
                                                                                : forward[f];
        size_t along = 0, against = 0;
        for (; f < forward.size() && forward[f] == edge; ++f)
            ++along;
        for (; b < backward.size() && backward[b] == edge; ++b)
            ++against;
        const size_t uses = along + against;
        ++r.edges;
        r.boundaryEdges += uses == 1;
        r.nonManifoldEdges += uses > 2;
        r.misorientedEdges += uses == 2 && along != 1;
    }
    size_t usedVertices = 0;
    for (uint32_t v = 0; v < r.vertices; ++v) {
        if (!used[v]) continue;
        ++usedVertices;
        r.shells += pieces.root(v) == v;
    }
    r.euler = int64_t(usedVertices) - int64_t(r.edges) + int64_t(r.triangles - unusable);
    r.selfIntersections = detail::findSelfIntersections(mesh).total();
    return r;
}

std::string reportText(const MeshReport& r) {
    auto yes = [](bool b) { return b ? "yes" : "no"; };
    char text[1024];
    std::snprintf(
        text, sizeof text,
        "triangles:          %zu (%zu degenerate)\n"
        "vertices:           %zu\n"
        "closed:             %s (%zu boundary edges)\n"
        "manifold:           %s (%zu edges shared by more than two triangles)\n"
        "oriented:           %s (%zu edges used twice in one direction, volume %s)\n"
        "self-intersections: %zu pairs of triangles\n"
        "watertight:         %s\n"
        "shells:             %zu\n"
        "genus:              %s\n"
        "volume:             %.6g\n"
        "area:               %.6g\n"
        "bounds:             [%.6g, %.6g, %.6g] .. [%.6g, %.6g, %.6g]\n",
        r.triangles, r.degenerateTriangles, r.vertices, yes(r.closed()), r.boundaryEdges,
        yes(r.manifold()), r.nonManifoldEdges, yes(r.oriented()), r.misorientedEdges,
        r.volume > 0.0 ? "positive" : "not positive", r.selfIntersections, yes(r.watertight()),
        r.shells, r.genus() >= 0 ? std::to_string(r.genus()).c_str() : "unknown (not watertight)",
        r.volume, r.area, double(r.bounds.min.x), double(r.bounds.min.y), double(r.bounds.min.z),
        double(r.bounds.max.x), double(r.bounds.max.y), double(r.bounds.max.z));
    std::string out = text;
    if (!r.printability) return out;
    const Printability& p = *r.printability;
    const double share = r.area > 0 ? 100.0 / r.area : 0.0;
    if (p.samples == 0)
        std::snprintf(text, sizeof text, "thinnest wall:      not measured\n");
    else
        std::snprintf(text, sizeof text,
                      "thinnest wall:      %.4g at [%.4g, %.4g, %.4g] (%zu points measured)\n",
                      double(p.thinnestWall), double(p.thinnestAt.x), double(p.thinnestAt.y),
                      double(p.thinnestAt.z), p.samples);
    out += text;
    std::snprintf(text, sizeof text,
                  "thin walls:         area %.4g (%.1f%% of the surface) thinner than %.4g\n"
                  "overhangs:          area %.4g (%.1f%% of the surface) facing down past 45 "
                  "degrees, off the plate\n",
                  p.thinArea, p.thinArea * share, double(p.minWall), p.overhangArea,
                  p.overhangArea * share);
    return out + text;
}

std::string reportJson(const MeshReport& r) {
    auto flag = [](bool b) { return b ? "true" : "false"; };
    char text[1024];
    std::snprintf(
        text, sizeof text,
        "{\"triangles\": %zu, \"vertices\": %zu, \"degenerate_triangles\": %zu, "
        "\"edges\": %zu, \"boundary_edges\": %zu, \"non_manifold_edges\": %zu, "
        "\"misoriented_edges\": %zu, \"self_intersections\": %zu, \"closed\": %s, "
        "\"manifold\": %s, \"oriented\": %s, \"watertight\": %s, \"shells\": %zu, "
        "\"euler\": %lld, \"genus\": %lld, \"volume\": %.9g, \"area\": %.9g, \"bounds\": ",
        r.triangles, r.vertices, r.degenerateTriangles, r.edges, r.boundaryEdges,
        r.nonManifoldEdges, r.misorientedEdges, r.selfIntersections, flag(r.closed()),
        flag(r.manifold()), flag(r.oriented()), flag(r.watertight()), r.shells,
        static_cast<long long>(r.euler), static_cast<long long>(r.genus()), r.volume, r.area);
    std::string json = text;
    if (r.bounds.empty()) {
        json += "null";
    } else {
        std::snprintf(text, sizeof text,
                      "{\"min\": [%.9g, %.9g, %.9g], \"max\": [%.9g, %.9g, %.9g]}",
                      double(r.bounds.min.x), double(r.bounds.min.y), double(r.bounds.min.z),
                      double(r.bounds.max.x), double(r.bounds.max.y), double(r.bounds.max.z));
        json += text;
    }
    if (r.printability) {
        const Printability& p = *r.printability;
        char wall[32] = "null";
        if (p.samples > 0) std::snprintf(wall, sizeof wall, "%.9g", double(p.thinnestWall));
        std::snprintf(text, sizeof text,
                      ", \"min_wall\": %.9g, \"thinnest_wall\": %s, \"thin_area\": %.9g, "
                      "\"overhang_area\": %.9g, \"wall_samples\": %zu",
                      double(p.minWall), wall, p.thinArea, p.overhangArea, p.samples);
        json += text;
    }
    return json + "}\n";
}

} // namespace sdfcsg
