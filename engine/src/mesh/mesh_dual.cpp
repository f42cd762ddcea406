#include "mesh/mesh_dual.h"

#include "mesh/self_intersections.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vector_relational.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <thread>
#include <tuple>
#include <type_traits>
#include <unordered_map>

namespace sdfcsg::detail {

namespace {

// A quad around a grid edge along `axis`: corners a, b, c, d in order around it.
struct Quad {
    uint32_t a, b, c, d;
    int axis;
};

// The diagonal that quad q splits along by its shape and its vertices' normals: b-d rather than
// a-c (`bd`), and whether the other one would also do (`either`: both split it into triangles
// that wind around the edge alike); and which splits wind so.
struct Diagonal {
    bool bd, either;
    bool winds[2]; // along a-c, along b-d
};
Diagonal diagonalOf(const Mesh& mesh, const Quad& q) {
    const std::vector<glm::vec3>& p = mesh.positions;
    const std::vector<glm::vec3>& n = mesh.normals;
    // How well triangle (u, v, w) faces like vertex `off`'s normal: the cosine, or -2 when it
    // has no area.
    auto facing = [&](uint32_t u, uint32_t v, uint32_t w, uint32_t off) {
        const glm::vec3 c = glm::cross(p[v] - p[u], p[w] - p[u]);
        const float length = glm::length(c);
        return length > 0.0f ? glm::dot(c, n[off]) / length : -2.0f;
    };
    // Twice the area of triangle (u, v, w) seen along the edge: the axis'th component of its
    // cross product.
    auto along = [](glm::vec2 u, glm::vec2 v, glm::vec2 w) {
        const glm::vec2 e = v - u, f = w - u;
        return e.x * f.y - e.y * f.x;
    };
    // The quad seen along its edge. Each vertex lies strictly inside its cell (kInset in the
    // shader), so it is a simple polygon around the edge, and at least one diagonal lies
    // inside it.
    auto seen = [&](uint32_t k) {
        const glm::vec3& x = p[k];
        return q.axis == 0   ? glm::vec2(x.y, x.z)
               : q.axis == 1 ? glm::vec2(x.z, x.x)
                             : glm::vec2(x.x, x.y);
    };
    const glm::vec2 sa = seen(q.a), sb = seen(q.b), sc = seen(q.c), sd = seen(q.d);
    const float abc = along(sa, sb, sc), acd = along(sa, sc, sd);
    const float abd = along(sa, sb, sd), bcd = along(sb, sc, sd);
    const float winding = abc + acd;
    const bool acWinds = abc * winding > 0.0f && acd * winding > 0.0f;
    const bool bdWinds = abd * winding > 0.0f && bcd * winding > 0.0f;
    if (acWinds != bdWinds) return {bdWinds, false, {acWinds, bdWinds}};
    const float facingAc = std::min(facing(q.a, q.b, q.c, q.b), facing(q.a, q.c, q.d, q.d));
    const float facingBd = std::min(facing(q.a, q.b, q.d, q.a), facing(q.b, q.c, q.d, q.c));
    // The margin keeps the first diagonal where both fold alike (a flat quad), so that float
    // rounding does not pick between them.
    return {facingBd > facingAc + 1e-3f, acWinds, {acWinds, bdWinds}};
}

// A triangle faces the field only where the cosine between it and the gradient is above this
// (it faces within 84 degrees of it), so that one nearly side-on to the gradient, as where a
// sheet thinner than a cell passes through it, does not pass or fail by rounding.
constexpr float kLeastCosine = 0.1f;

// How triangle (u, v, w) faces the field: the cosine between it and the field's gradient at its
// centre (tetrahedral differences a hundredth of a cell `h` wide, as in the tests' check), less
// kLeastCosine; 1 where the gradient gives no direction.
float fieldFacing(const Mesh& mesh, const Distance& distance, float h, uint32_t u, uint32_t v,
                  uint32_t w) {
    const std::vector<glm::vec3>& p = mesh.positions;
    const glm::vec3 c = glm::cross(p[v] - p[u], p[w] - p[u]);
    const glm::vec3 centre = (p[u] + p[v] + p[w]) / 3.0f;
    const glm::vec3 taps[4] = {{1, -1, -1}, {-1, -1, 1}, {-1, 1, -1}, {1, 1, 1}};
    glm::vec3 g(0.0f);
    for (const glm::vec3& tap : taps)
        g += tap * distance(centre + tap * (0.01f * h));
    const float gg = glm::dot(g, g);
    if (!(gg > 0.0f)) return 1.0f; // no direction to judge by
    return glm::dot(c, g) / std::sqrt(glm::dot(c, c) * gg) - kLeastCosine;
}

// How triangle (u, v, w) faces, positive where it does not fold. By its vertices' normals alone
// it folds (-2, below any cosine) where it faces nearly a right angle or more away from their
// mean (a triangle of a wedge of the solid as sharp as 30 degrees faces within 75 degrees of it,
// cosine 0.26), and it is fine (1) where it faces within 30 degrees of each of them. Between, as
// across a sharp edge or where the normals miss a sheet thinner than a cell, the field decides
// where `distance` is set: the cosine between the triangle and the field's gradient at its
// centre (tetrahedral differences a hundredth of a cell `h` wide, as in the tests' check), less
// kLeastCosine. The field is slow, so only these ask it, unless `always`.
float facing(const Mesh& mesh, const Distance& distance, float h, uint32_t u, uint32_t v,
             uint32_t w, bool always = false) {
    const std::vector<glm::vec3>& p = mesh.positions;
    const std::vector<glm::vec3>& n = mesh.normals;
    const glm::vec3 c = glm::cross(p[v] - p[u], p[w] - p[u]), m = n[u] + n[v] + n[w];
    const float cm = glm::dot(c, m), cc = glm::dot(c, c), mm = glm::dot(m, m);
    if (cm < 0.0f || cm * cm < 0.04f * cc * mm) return -2.0f;
    const float least = 0.866f * std::sqrt(cc); // cos 30 degrees
    if (!distance || (!always && glm::dot(c, n[u]) >= least && glm::dot(c, n[v]) >= least &&
                      glm::dot(c, n[w]) >= least))
        return 1.0f;
    return fieldFacing(mesh, distance, h, u, v, w);
}

// Writes quad q into t split along a-c, as (a, b, c), (a, c, d), or along b-d, as (a, b, d),
// (b, c, d); returns whether one of the two triangles folds. Where the diagonal of diagonalOf()
// folds and the other would also do, the one whose worse triangle faces better is taken.
bool fold(const Mesh& mesh, const Distance& distance, float h, const Quad& q, uint32_t* t) {
    const uint32_t split[2][6] = {{q.a, q.b, q.c, q.a, q.c, q.d}, {q.a, q.b, q.d, q.b, q.c, q.d}};
    auto worse = [&](const uint32_t* s) {
        return std::min(facing(mesh, distance, h, s[0], s[1], s[2]),
                        facing(mesh, distance, h, s[3], s[4], s[5]));
    };
    const Diagonal diagonal = diagonalOf(mesh, q);
    int k = diagonal.bd ? 1 : 0;
    float f = worse(split[k]);
    if (f < 0.0f && diagonal.either && distance) {
        if (const float other = worse(split[1 - k]); other > f) {
            k = 1 - k;
            f = other;
        }
    }
    std::copy(split[k], split[k] + 6, t);
    return f < 0.0f;
}

// A folding quad moves all four of its vertices, most of them only for being its corners. Each
// moved vertex goes back where the QEF placed it (on the sharp features) wherever every quad
// around it then still splits into triangles that wind around its edge alike and none of them
// folds, by its vertices' normals nor by the field (asked of each: a vertex going back may turn a
// triangle over that still faces like its vertices' normals, as on a sheet thinner than a cell).
// One vertex at a time, in the order they moved, so that the result does not depend on threads.
void placeBack(Mesh& mesh, const std::vector<uint8_t>& axes,
               const std::vector<std::pair<uint32_t, glm::vec3>>& moves, const Distance& distance,
               float h) {
    if (moves.empty()) return;
    // The quads around each moved vertex, by its place in `moves`.
    std::vector<uint32_t> slot(mesh.positions.size(), UINT32_MAX), first(moves.size() + 1, 0);
    for (uint32_t i = 0; i < moves.size(); ++i)
        slot[moves[i].first] = i;
    auto forEachMoved = [&](size_t q, auto&& f) {
        const uint32_t* t = &mesh.indices[6 * q];
        for (int k = 0; k < 6; ++k) // each corner once: t[3] and t[5] repeat t[0], t[2] or t[1]
            if (slot[t[k]] != UINT32_MAX && std::find(t, t + k, t[k]) == t + k) f(slot[t[k]]);
    };
    const size_t quads = mesh.indices.size() / 6;
    for (size_t q = 0; q < quads; ++q)
        forEachMoved(q, [&](uint32_t i) { ++first[i + 1]; });
    for (size_t i = 0; i < moves.size(); ++i)
        first[i + 1] += first[i];
    std::vector<uint32_t> around(first.back()), filled(first.begin(), first.end() - 1);
    for (size_t q = 0; q < quads; ++q)
        forEachMoved(q, [&](uint32_t i) { around[filled[i]++] = uint32_t(q); });

    for (uint32_t i = 0; i < moves.size(); ++i) {
        const auto [v, placed] = moves[i];
        const glm::vec3 smooth = mesh.positions[v];
        mesh.positions[v] = placed;
        for (uint32_t j = first[i]; j < first[i + 1]; ++j) {
            const uint32_t* t = &mesh.indices[6 * size_t(around[j])];
            // As fold() wrote it: a-c is (a, b, c), (a, c, d); b-d is (a, b, d), (b, c, d).
            const bool bd = t[3] != t[0];
            const Quad quad = bd ? Quad{t[0], t[1], t[4], t[2], axes[around[j]]}
                                 : Quad{t[0], t[1], t[2], t[5], axes[around[j]]};
            if (!diagonalOf(mesh, quad).winds[bd] ||
                facing(mesh, distance, h, t[0], t[1], t[2], true) < 0 ||
                facing(mesh, distance, h, t[3], t[4], t[5], true) < 0) {
                mesh.positions[v] = smooth;
                break;
            }
        }
    }
}

} // namespace

void foldQuads(Mesh& mesh, const std::vector<glm::vec3>& smooth, const Distance& distance,
               float h) {
    const size_t quads = mesh.indices.size() / 6;
    std::vector<uint8_t> axes(quads);
    // movedIn[k]: the round in which vertex k moved to its smooth place; 0: never.
    std::vector<uint8_t> movedIn(mesh.positions.size(), 0);
    // Each round folds quads (in round 1 all of them, as the quads pass wrote them: (a, b, c),
    // then (a, c, d) rotated to start at its axis'th corner; then those around the vertices that
    // moved in the round before, as fold() wrote them) and lists those that still fold (see
    // facing()); then their vertices move to their smooth places. The last round only folds.
    // Quads change only their own indices while positions stay, so two threads share a round's
    // quads and the result does not depend on them.
    auto foldRange = [&](uint8_t round, size_t begin, size_t end, std::vector<size_t>& folding) {
        for (size_t q = begin; q < end; ++q) {
            uint32_t* t = &mesh.indices[6 * q];
            Quad quad;
            if (round == 1) {
                const int axis = t[3] == t[0] ? 0 : t[3] == t[2] ? 1 : 2;
                quad = {t[0], t[1], t[2], axis == 0 ? t[5] : axis == 1 ? t[4] : t[3], axis};
                axes[q] = uint8_t(axis);
            } else if (std::any_of(t, t + 6, [&](uint32_t k) { return movedIn[k] == round - 1; })) {
                // a-c is (a, b, c), (a, c, d); b-d is (a, b, d), (b, c, d).
                quad = t[3] == t[0] ? Quad{t[0], t[1], t[2], t[5], axes[q]}
                                    : Quad{t[0], t[1], t[4], t[2], axes[q]};
            } else {
                continue;
            }
            if (fold(mesh, distance, h, quad, t)) folding.push_back(q);
        }
    };
    std::vector<std::pair<uint32_t, glm::vec3>> moves; // vertex, where the QEF placed it
    constexpr uint8_t kRounds = 5;
    for (uint8_t round = 1; round <= kRounds; ++round) {
        std::vector<size_t> folding, theirs;
        if (quads < 65536 || std::thread::hardware_concurrency() < 2) {
            foldRange(round, 0, quads, folding);
        } else {
            std::thread helper(foldRange, round, quads / 2, quads, std::ref(theirs));
            foldRange(round, 0, quads / 2, folding);
            helper.join();
            folding.insert(folding.end(), theirs.begin(), theirs.end());
        }
        if (round == kRounds) break;
        bool moved = false;
        for (size_t q : folding)
            for (int k = 0; k < 6; ++k)
                if (const uint32_t v = mesh.indices[6 * q + k]; movedIn[v] == 0) {
                    movedIn[v] = round;
                    moves.push_back({v, mesh.positions[v]});
                    mesh.positions[v] = smooth[v];
                    moved = true;
                }
        if (!moved) break;
    }
    placeBack(mesh, axes, moves, distance, h);
}

namespace {

// Whether some side runs from one vertex to another in more than one triangle: never in a
// manifold, consistently oriented mesh. Each vertex's outgoing sides, listed by a counting sort,
// are compared among themselves: a tenth of the time of sorting all sides.
bool repeatsASide(const Mesh& mesh) {
    const size_t n = mesh.vertexCount();
    std::vector<uint32_t> first(n + 1, 0);
    for (uint32_t v : mesh.indices)
        ++first[v + 1];
    for (size_t v = 0; v < n; ++v)
        first[v + 1] += first[v];
    std::vector<uint32_t> next(first.begin(), first.end() - 1), to(mesh.indices.size());
    for (size_t t = 0; t < mesh.triangleCount(); ++t)
        for (int k = 0; k < 3; ++k)
            to[next[mesh.indices[3 * t + k]]++] = mesh.indices[3 * t + (k + 1) % 3];
    for (size_t v = 0; v < n; ++v)
        for (uint32_t i = first[v]; i < first[v + 1]; ++i)
            for (uint32_t j = i + 1; j < first[v + 1]; ++j)
                if (to[i] == to[j]) return true;
    return false;
}

} // namespace

size_t splitTouchingSheets(Mesh& mesh) {
    if (!repeatsASide(mesh)) return 0;
    const size_t triangles = mesh.triangleCount();
    // Each triangle's sides as (lower vertex << 32 | higher vertex, triangle << 1 | forward),
    // sorted so that the uses of an edge lie together.
    std::vector<std::pair<uint64_t, uint64_t>> sides;
    sides.reserve(3 * triangles);
    for (size_t t = 0; t < triangles; ++t)
        for (int i = 0; i < 3; ++i) {
            const uint32_t from = mesh.indices[3 * t + i], to = mesh.indices[3 * t + (i + 1) % 3];
            sides.push_back({uint64_t(std::min(from, to)) << 32 | std::max(from, to),
                             uint64_t(t) << 1 | (from < to ? 1u : 0u)});
        }
    std::sort(sides.begin(), sides.end());
    // partner[3 t + i]: the triangle across side i of t (its sheet's at a cut edge); none where
    // the side's edge is used by other than two triangles that could not be paired.
    constexpr uint32_t kNone = UINT32_MAX;
    std::vector<uint32_t> partner(3 * triangles, kNone);
    auto sideOf = [&](uint32_t t, uint32_t a, uint32_t b) {
        for (int i = 0; i < 3; ++i) {
            const uint32_t from = mesh.indices[3 * t + i], to = mesh.indices[3 * t + (i + 1) % 3];
            if ((from == a && to == b) || (from == b && to == a)) return 3 * t + i;
        }
        return 3 * t; // not reached: t has the side
    };
    auto pair = [&](uint32_t a, uint32_t b, uint32_t lo, uint32_t hi) {
        partner[sideOf(a, lo, hi)] = b;
        partner[sideOf(b, lo, hi)] = a;
    };
    // The triangles on edge (a, b), a < b: a range of `sides`.
    auto uses = [&](uint32_t a, uint32_t b) {
        const uint64_t key = uint64_t(std::min(a, b)) << 32 | std::max(a, b);
        return std::equal_range(sides.begin(), sides.end(), std::pair<uint64_t, uint64_t>{key, 0},
                                [](const auto& x, const auto& y) { return x.first < y.first; });
    };
    // From triangle `t` on edge (v, w), around v across sides shared by two triangles only, to
    // the triangle that comes back to (v, w) running the other way; none where the walk meets
    // another edge or does not come back within a few dozen triangles.
    auto walkAround = [&](uint32_t t, uint32_t v, uint32_t w) -> uint32_t {
        const uint32_t* start = &mesh.indices[3 * t];
        int startForward = 0; // t runs v -> w
        for (int k = 0; k < 3; ++k)
            startForward |= start[k] == v && start[(k + 1) % 3] == w;
        uint32_t at = t, from = w;
        for (int step = 0; step < 64; ++step) {
            uint32_t next = 0; // at's other vertex beside v
            for (int k = 0; k < 3; ++k)
                if (mesh.indices[3 * at + k] != v && mesh.indices[3 * at + k] != from)
                    next = mesh.indices[3 * at + k];
            if (next == w) {
                int forward = 0;
                for (int k = 0; k < 3; ++k)
                    forward |=
                        mesh.indices[3 * at + k] == v && mesh.indices[3 * at + (k + 1) % 3] == w;
                return at != t && forward != startForward ? at : kNone;
            }
            const auto [b, e] = uses(v, next);
            if (e - b != 2) return kNone;
            const auto other0 = uint32_t(b->second >> 1), other1 = uint32_t((b + 1)->second >> 1);
            at = other0 == at ? other1 : other0;
            from = next;
        }
        return kNone;
    };
    std::vector<uint32_t> ends; // vertices at the ends of cut edges
    size_t cut = 0;
    for (size_t i = 0; i < sides.size();) {
        size_t end = i;
        while (end < sides.size() && sides[end].first == sides[i].first)
            ++end;
        const auto lo = uint32_t(sides[i].first >> 32), hi = uint32_t(sides[i].first);
        if (end - i == 2) {
            pair(uint32_t(sides[i].second >> 1), uint32_t(sides[i + 1].second >> 1), lo, hi);
        } else if (end - i > 2) {
            // Each triangle's fan around `lo`, walked across the sides that join two triangles,
            // comes back to the edge in the triangle of its sheet.
            bool paired = false;
            for (size_t j = i; j < end; ++j) {
                const auto first = uint32_t(sides[j].second >> 1);
                if (partner[sideOf(first, lo, hi)] != kNone) continue;
                if (const uint32_t last = walkAround(first, lo, hi); last != kNone) {
                    pair(first, last, lo, hi);
                    paired = true;
                }
            }
            if (paired) {
                ends.push_back(lo);
                ends.push_back(hi);
                ++cut;
            }
        }
        i = end;
    }
    if (cut == 0) return 0;
    std::sort(ends.begin(), ends.end());
    ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
    // The triangles around each end, then their fans: triangles joined through partners across
    // the sides that hold the end.
    std::vector<std::vector<uint32_t>> around(ends.size());
    for (size_t t = 0; t < triangles; ++t)
        for (int k = 0; k < 3; ++k) {
            auto it = std::lower_bound(ends.begin(), ends.end(), mesh.indices[3 * t + k]);
            if (it != ends.end() && *it == mesh.indices[3 * t + k])
                around[size_t(it - ends.begin())].push_back(uint32_t(t));
        }
    for (size_t e = 0; e < ends.size(); ++e) {
        const uint32_t vertex = ends[e];
        std::vector<uint32_t>& fan = around[e];
        std::vector<int> component(fan.size(), -1);
        int components = 0;
        for (size_t start = 0; start < fan.size(); ++start) {
            if (component[start] >= 0) continue;
            std::vector<size_t> stack{start};
            component[start] = components;
            while (!stack.empty()) {
                const uint32_t t = fan[stack.back()];
                stack.pop_back();
                for (int k = 0; k < 3; ++k) {
                    const uint32_t a = mesh.indices[3 * t + k],
                                   b = mesh.indices[3 * t + (k + 1) % 3];
                    const uint32_t other = partner[3 * t + k];
                    if ((a != vertex && b != vertex) || other == kNone) continue;
                    const auto at = size_t(std::find(fan.begin(), fan.end(), other) - fan.begin());
                    if (at < fan.size() && component[at] < 0) {
                        component[at] = components;
                        stack.push_back(at);
                    }
                }
            }
            if (components > 0) { // a further fan: its own copy of the vertex
                const auto copy = uint32_t(mesh.positions.size());
                mesh.positions.push_back(mesh.positions[vertex]);
                mesh.normals.push_back(mesh.normals[vertex]);
                mesh.colors.push_back(mesh.colors[vertex]);
                for (size_t j = 0; j < fan.size(); ++j)
                    if (component[j] == components)
                        for (int k = 0; k < 3; ++k)
                            if (mesh.indices[3 * fan[j] + k] == vertex)
                                mesh.indices[3 * fan[j] + k] = copy;
            }
            ++components;
        }
    }
    return cut;
}

namespace {

bool finite(glm::vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// kInset in shaders/mesh_triangles.comp: how far vertices keep from their cells' faces, in cells.
constexpr float kInset = 0.005f;

// A quad's corners in order around its edge, from its two triangles as foldQuads() wrote them:
// (a, b, c), (a, c, d) or (a, b, d), (b, c, d).
std::array<uint32_t, 4> cornersOf(const uint32_t* t) {
    return t[3] == t[0] ? std::array<uint32_t, 4>{t[0], t[1], t[2], t[5]}
                        : std::array<uint32_t, 4>{t[0], t[1], t[4], t[2]};
}

// starWedges() state per vertex: how many of its quads' wedges hold the first direction of the
// plane it is seen in, and whether one of its quads folds there.
constexpr uint8_t kWraps = 0x7f, kFolds = 0x80;

// Quad t (its two triangles as foldQuads() wrote them) seen from each of its corners v along v's
// normal (`view` holds the plane across it, two vectors per vertex): the quad must lie in the wedge
// at v between its sides from v, turning less than half a turn counter-clockwise, with its far
// corner strictly inside and both triangles facing the viewer; else v's state gets kFolds. Where
// every quad of v does so and the wedges wrap once around v (exactly one holds the plane's first
// direction, counted in v's state), the quads around v are a disk that the view maps one-to-one:
// none of them crosses another.
void starWedges(const Mesh& mesh, const uint32_t* t, const std::vector<glm::vec3>& view,
                float margin, std::vector<uint8_t>& state) {
    const std::array<uint32_t, 4> c = cornersOf(t);
    const bool ac = t[3] == t[0]; // split along a-c, else b-d
    for (int i = 0; i < 4; ++i) {
        const uint32_t v = c[size_t(i)];
        const glm::vec3 p = mesh.positions[v], u = view[2 * size_t(v)], w = view[2 * size_t(v) + 1];
        auto seen = [&](uint32_t k) {
            const glm::vec3 d = mesh.positions[k] - p;
            return glm::vec2(glm::dot(d, u), glm::dot(d, w));
        };
        const glm::vec2 next = seen(c[size_t(i + 1) % 4]), far = seen(c[size_t(i + 2) % 4]),
                        prev = seen(c[size_t(i + 3) % 4]);
        auto cross = [](glm::vec2 x, glm::vec2 y) { return x.x * y.y - x.y * y.x; };
        // Each point must lie farther than `margin` from the lines it must not cross, and so
        // farther from the other quads than the check's tolerance: nearer, it would count as
        // meeting them.
        auto apart = [&](glm::vec2 x, glm::vec2 y) {
            return cross(x, y) >
                   margin * (std::abs(x.x) + std::abs(x.y) + std::abs(y.x) + std::abs(y.y));
        };
        const bool throughV = ac == (i % 2 == 0);
        const bool opens = apart(next, prev) && apart(next, far) && apart(far, prev) &&
                           (throughV || apart(far - next, prev - next));
        if (!opens)
            state[v] |= kFolds;
        else if (next.y <= 0.0f && prev.y > 0.0f)
            ++state[v];
    }
}

// The field's gradient at p, by tetrahedral differences a hundredth of a cell `h` wide.
glm::vec3 gradientAt(const Distance& distance, glm::vec3 p, float h) {
    const glm::vec3 taps[4] = {{1, -1, -1}, {-1, -1, 1}, {-1, 1, -1}, {1, 1, 1}};
    glm::vec3 g(0.0f);
    for (const glm::vec3& tap : taps)
        g += tap * distance(p + tap * (0.01f * h));
    return g / (0.04f * h);
}

// Point p moved toward the surface along the field's gradient, kept in the box [lo, hi] (a cell,
// or a face of one: lo and hi agree on its axis): two Newton steps, each kept only where it
// brings p nearer to the surface.
glm::vec3 towardSurface(const Distance& distance, glm::vec3 p, glm::vec3 lo, glm::vec3 hi,
                        float h) {
    float d = distance(p);
    for (int step = 0; step < 2; ++step) {
        glm::vec3 g = gradientAt(distance, p, h);
        for (int k = 0; k < 3; ++k)
            if (lo[k] == hi[k]) g[k] = 0.0f;
        const float gg = glm::dot(g, g);
        if (!(gg > 1e-6f)) break;
        const glm::vec3 next = glm::clamp(p - d * g / gg, lo, hi);
        const float e = distance(next);
        if (!(std::abs(e) < std::abs(d))) break;
        p = next;
        d = e;
    }
    return p;
}

// Runs f(begin, end, half) over [0, n), in two halves on two threads where n is large enough to
// pay for the second (`least`: where each item costs a few values of the field, fewer).
template <class F> void inHalves(size_t n, F&& f, size_t least = 65536) {
    if (n < least || std::thread::hardware_concurrency() < 2) {
        f(size_t(0), n, 0);
        return;
    }
    std::thread helper([&] { f(n / 2, n, 1); });
    f(size_t(0), n / 2, 0);
    helper.join();
}

} // namespace

size_t pullToSurface(std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                     const std::vector<uint32_t>& quadEdges, const EdgePoint* points,
                     glm::vec3 origin, float h, const Distance& distance, bool clampedOnly) {
    const size_t quads = indices.size() / 6;
    if (!distance || quadEdges.size() != quads) return 0;
    // Per vertex: the squared distance to its nearest edge point, and the largest distance from
    // the tangent planes of its edge points.
    std::vector<float> nearest(positions.size(), INFINITY), off(positions.size(), 0.0f);
    for (size_t q = 0; q < quads; ++q) {
        const EdgePoint& e = points[quadEdges[q]];
        if (!finite(e.position) || !finite(e.normal) || !finite(e.other)) continue;
        const uint32_t* t = &indices[6 * q];
        for (int k = 0; k < 6; ++k) {
            const glm::vec3 d = positions[t[k]] - e.position;
            nearest[t[k]] = std::min(nearest[t[k]], glm::dot(d, d));
            off[t[k]] = std::max(
                {off[t[k]], std::abs(glm::dot(d, e.normal)), std::abs(glm::dot(d, e.other))});
        }
    }
    size_t moved[2] = {0, 0};
    inHalves(positions.size(), [&](size_t begin, size_t end, int half) {
        for (size_t v = begin; v < end; ++v) {
            if (nearest[v] <= 0.25f * h * h) continue; // then the field is within half a cell
            glm::vec3& p = positions[v];
            const glm::vec3 lo = origin + glm::floor((p - origin) / h) * h, in = (p - lo) / h;
            const bool clamped = glm::any(glm::lessThan(in, glm::vec3(2 * kInset))) ||
                                 glm::any(glm::greaterThan(in, glm::vec3(1 - 2 * kInset)));
            if ((!clamped && (clampedOnly || off[v] <= 0.2f * h)) ||
                std::abs(distance(p)) <= 0.45f * h)
                continue;
            const glm::vec3 to =
                towardSurface(distance, p, lo + kInset * h, lo + (1 - kInset) * h, h);
            moved[half] += to != p;
            p = to;
        }
    });
    return moved[0] + moved[1];
}

Separation separateCrossings(Mesh& mesh, size_t copiesFrom, const std::vector<uint32_t>& quadEdges,
                             const EdgePoint* points, glm::vec3 origin, float h,
                             const Distance& distance) {
    Separation result;
    const size_t quads = mesh.indices.size() / 6;
    if (quads == 0 || quadEdges.size() != quads) return result;
    auto edge = [&](uint32_t q) -> const EdgePoint& { return points[quadEdges[q]]; };
    const size_t dualVertices = mesh.positions.size();
    copiesFrom = std::min(copiesFrom, dualVertices);
    // Each dual vertex's cell (a vertex lies strictly inside its cell, kInset in
    // shaders/mesh_triangles.comp, so its floor names the cell), and the plane that starWedges()
    // sees it in: across its normal, a basis right-handed with it (Duff et al. 2017).
    std::vector<uint64_t> key(dualVertices);
    std::vector<glm::vec3> view(2 * dualVertices);
    inHalves(dualVertices, [&](size_t begin, size_t end, int) {
        for (size_t v = begin; v < end; ++v) {
            const glm::vec3 c = glm::max(glm::floor((mesh.positions[v] - origin) / h), 0.0f);
            key[v] = uint64_t(c.x) | uint64_t(c.y) << 21 | uint64_t(c.z) << 42;
            const glm::vec3 n = mesh.normals[v];
            const float sign = std::copysign(1.0f, n.z), a = -1.0f / (sign + n.z);
            const float b = n.x * n.y * a;
            view[2 * v] = glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
            view[2 * v + 1] = glm::vec3(b, sign + n.y * n.y * a, -n.y);
        }
    });
    auto cellLo = [&](uint32_t v) {
        return origin + glm::vec3(uint32_t(key[v] & 0x1fffff), uint32_t((key[v] >> 21) & 0x1fffff),
                                  uint32_t(key[v] >> 42)) *
                            h;
    };
    // cellOf[v]: v, or for a vertex that shares its cell (`shared`: several pieces of surface,
    // or copies for sheets that touch), the first vertex of the cell, which names it. The pieces
    // of a cell come one after another (the dual pass writes them so), the copies after all.
    std::vector<uint32_t> cellOf(dualVertices);
    std::vector<uint8_t> shared(dualVertices, 0);
    std::vector<std::pair<uint64_t, uint32_t>> group; // the shared vertices by cell
    {
        std::vector<uint64_t> copied(key.begin() + std::ptrdiff_t(copiesFrom), key.end());
        std::sort(copied.begin(), copied.end());
        for (size_t v = 0; v < dualVertices; ++v) {
            cellOf[v] = uint32_t(v);
            shared[v] =
                v >= copiesFrom || (v > 0 && key[v - 1] == key[v]) ||
                (v + 1 < copiesFrom && key[v + 1] == key[v]) ||
                (!copied.empty() && std::binary_search(copied.begin(), copied.end(), key[v]));
            if (shared[v]) group.push_back({key[v], uint32_t(v)});
        }
        std::sort(group.begin(), group.end());
        for (size_t i = 1; i < group.size(); ++i)
            if (group[i - 1].first == group[i].first)
                cellOf[group[i].second] = cellOf[group[i - 1].second];
    }
    // Quad q's edge point on its grid edge (the edge that its four cells lie around: along the
    // axis on which their places agree, at the greater of their places across it), kept off the
    // edge's ends by kInset of a cell, as the vertices are kept off their cells' faces: where a
    // sample lies on the surface, the points of all its crossed edges lie there, and the pieces
    // of the cells around it would meet at one point. Where the vertices pass found no point on
    // the edge (a few come back far off it, or not numbers), the edge's middle.
    auto edgePosition = [&](uint32_t q) {
        const std::array<uint32_t, 4> c = cornersOf(&mesh.indices[6 * size_t(q)]);
        auto at = [&](uint32_t v, int k) { return (key[v] >> (21 * k)) & 0x1fffff; };
        int axis = 0;
        for (int k = 0; k < 3; ++k)
            if (at(c[0], k) == at(c[1], k) && at(c[0], k) == at(c[2], k) &&
                at(c[0], k) == at(c[3], k))
                axis = k;
        const glm::vec3 point = edge(q).position;
        glm::vec3 p;
        for (int k = 0; k < 3; ++k) {
            const uint64_t line = std::max({at(c[0], k), at(c[1], k), at(c[2], k), at(c[3], k)});
            const float lo = origin[k] + float(line) * h;
            if (k != axis) // the shader's own rounding of the grid line, where it is one
                p[k] = std::abs(point[k] - lo) <= 1e-3f * h ? point[k] : lo;
            else
                p[k] = std::isfinite(point[k])
                           ? std::clamp(point[k], lo + kInset * h, lo + (1.0f - kInset) * h)
                           : lo + 0.5f * h;
        }
        return p;
    };
    // Its normal and colour, or where they are not numbers, its vertices' mean normal and the
    // first one's colour.
    auto edgeNormal = [&](uint32_t q) {
        const glm::vec3 n = edge(q).normal;
        if (finite(n) && glm::dot(n, n) > 0.5f) return n;
        glm::vec3 sum(0.0f);
        for (uint32_t v : cornersOf(&mesh.indices[6 * size_t(q)]))
            sum += mesh.normals[v];
        return glm::length(sum) > 0.0f ? glm::normalize(sum) : glm::vec3(0.0f, 0.0f, 1.0f);
    };
    auto edgeColor = [&](uint32_t q) {
        const EdgePoint& e = edge(q);
        const glm::vec3 rgb(e.red, e.green, e.blue);
        return finite(rgb) ? rgb : mesh.colors[mesh.indices[6 * size_t(q)]];
    };
    std::vector<uint8_t> marked(dualVertices, 0); // by cell, at the vertex that names it
    auto isMarked = [&](uint32_t v) { return marked[cellOf[v]] != 0; };
    auto anyMarked = [&](const std::array<uint32_t, 4>& c) {
        return isMarked(c[0]) || isMarked(c[1]) || isMarked(c[2]) || isMarked(c[3]);
    };
    auto quad = [&](size_t q) { return &mesh.indices[6 * q]; };

    // The quads the check looks at: those with a corner whose quads may cross (`near`). Two
    // triangles that cross lie in quads that share a cell (a quad's triangles lie inside the four
    // cells around its edge, its vertices being inside them). Where that cell holds one vertex,
    // both quads hold it, and they cannot cross where that vertex's quads are seen along its
    // normal without overlap (starWedges()); where it holds several, each is near.
    std::vector<uint8_t> near(shared);
    float margin = 0.0f; // four times the check's tolerance (see findSelfIntersections)
    {
        glm::vec3 lo(INFINITY), hi(-INFINITY);
        for (const glm::vec3& p : mesh.positions) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        margin = 4e-6f * glm::length(hi - lo);
    }
    {
        std::vector<uint8_t> state[2];
        state[1].assign(dualVertices, 0);
        inHalves(quads, [&](size_t begin, size_t end, int part) {
            if (part == 0) state[0].assign(dualVertices, 0);
            for (size_t q = begin; q < end; ++q)
                starWedges(mesh, quad(q), view, margin, state[part]);
        });
        for (size_t v = 0; v < dualVertices; ++v) {
            const unsigned a = state[0][v], b = state[1][v];
            if (((a | b) & kFolds) || (a & kWraps) + (b & kWraps) != 1) near[v] = 1;
        }
    }

    // The quads around each vertex of a marked cell, (vertex, quad) sorted, remade each round.
    std::vector<std::pair<uint32_t, uint32_t>> around;
    auto addVertex = [&](glm::vec3 p, glm::vec3 n, glm::vec3 c) {
        mesh.positions.push_back(p);
        mesh.normals.push_back(n);
        mesh.colors.push_back(c);
        return uint32_t(mesh.positions.size() - 1);
    };
    // The point F on side (a, b) of quad q, halfway between the edge points of q and of the
    // quad across the side (around the other crossed edge of the face between the cells of a
    // and b; a point of the face on the chord where the surface crosses it), shared by the two;
    // none where no single quad lies across. One of a and b lies in a marked cell.
    std::unordered_map<uint64_t, uint32_t> facePoints; // side (lower << 32 | higher) -> F
    auto faceOf = [&](uint32_t q, uint32_t a, uint32_t b) -> uint32_t {
        const uint64_t side = uint64_t(std::min(a, b)) << 32 | std::max(a, b);
        if (auto it = facePoints.find(side); it != facePoints.end()) return it->second;
        const uint32_t v = isMarked(a) ? a : b, w = v == a ? b : a;
        uint32_t other = UINT32_MAX, found = 0;
        for (auto it = std::lower_bound(around.begin(), around.end(), std::pair{v, 0u});
             it != around.end() && it->first == v; ++it) {
            if (it->second == q) continue;
            const std::array<uint32_t, 4> c = cornersOf(quad(it->second));
            if (std::find(c.begin(), c.end(), w) != c.end()) {
                other = it->second;
                ++found;
            }
        }
        if (found != 1) return UINT32_MAX;
        const glm::vec3 between = 0.5f * (edgePosition(q) + edgePosition(other));
        const glm::vec3 n = edgeNormal(q) + edgeNormal(other);
        const uint32_t f = addVertex(
            between, glm::length(n) > 0.0f ? glm::normalize(n) : edgeNormal(q), edgeColor(q));
        facePoints.emplace(side, f);
        return f;
    };
    std::unordered_map<uint32_t, uint32_t> edgePoints; // quad -> E
    auto edgeOf = [&](uint32_t q) {
        if (auto it = edgePoints.find(q); it != edgePoints.end()) return it->second;
        const uint32_t e = addVertex(edgePosition(q), edgeNormal(q), edgeColor(q));
        edgePoints.emplace(q, e);
        return e;
    };
    // The triangles of quad q under the marks, into `out`: its own two, or its fan from E.
    auto trianglesOf = [&](uint32_t q, std::vector<uint32_t>& out) {
        const uint32_t* t = quad(q);
        const std::array<uint32_t, 4> c = cornersOf(t);
        if (!anyMarked(c)) {
            out.insert(out.end(), t, t + 6);
            return;
        }
        const uint32_t e = edgeOf(q);
        uint32_t polygon[8];
        int count = 0;
        for (int k = 0; k < 4; ++k) {
            const uint32_t a = c[size_t(k)], b = c[size_t(k + 1) % 4];
            polygon[count++] = a;
            if (isMarked(a) || isMarked(b))
                if (const uint32_t f = faceOf(q, a, b); f != UINT32_MAX) polygon[count++] = f;
        }
        for (int k = 0; k < count; ++k)
            out.insert(out.end(), {e, polygon[k], polygon[(k + 1) % count]});
    };

    // Rounds over the triangles of the quads near others, in a mesh of their own that shares
    // the positions (`probe`); the whole mesh takes the split quads at the end. After the
    // first, a round checks only the quads that share a cell with a split one (`split`, their
    // corners `reach`): the others are as the first round found them, apart.
    std::vector<uint8_t> toMean(dualVertices, 0); // lone vertices moved for their fans
    std::vector<uint32_t> probe, split;
    std::vector<uint8_t> reach;
    std::vector<std::pair<uint32_t, uint32_t>> pairs;
    constexpr size_t kRounds = 6;
    for (size_t round = 0;; ++round) {
        const std::vector<uint8_t>& checked = round == 0 ? near : reach;
        probe.clear();
        for (uint32_t q = 0; q < quads; ++q) {
            const std::array<uint32_t, 4> c = cornersOf(quad(q));
            if (checked[c[0]] || checked[c[1]] || checked[c[2]] || checked[c[3]])
                trianglesOf(q, probe);
        }
        pairs.clear();
        if (!probe.empty()) {
            std::swap(mesh.indices, probe);
            findSelfIntersections(mesh, -1.0, 1e-3, &pairs);
            std::swap(mesh.indices, probe);
        }
        result.remaining = pairs.size();
        // Fan triangles (those with an edge or face point) that fold (see facing()): a marked
        // cell's lone vertex there lies across a sharp edge from a chord of its loop, or on the
        // face that holds the chord, clamped into its cell, or deep inside a feature thinner than
        // a cell. It moves, once, to whichever of a few points of its cell its fan faces best
        // from (fewest folding triangles, by the field where it is known): where it is, the mean
        // of its quads' edge points (inside the hull of its loop, where its fan faces like the
        // loop), each of these two moved onto the surface, and the cell's centre; any point
        // inside the cell keeps the fan embedded. The next round checks it. Cells are not marked
        // for folding: a decision by a threshold would change the mesh's counts where rounding
        // moves a triangle across it (marking them was tried: fans there fold more often than
        // the quads did).
        size_t newly = 0, moved = 0;
        std::vector<uint32_t> toPlace;
        for (size_t t = 0; t < probe.size(); t += 3) {
            const uint32_t* f = &probe[t];
            if (std::max({f[0], f[1], f[2]}) < dualVertices ||
                facing(mesh, distance, h, f[0], f[1], f[2]) >= 0.0f)
                continue;
            for (size_t k = 0; k < 3; ++k) {
                const uint32_t v = f[k];
                if (v >= dualVertices || !isMarked(v) || shared[v] || toMean[v]) continue;
                toMean[v] = 1;
                toPlace.push_back(v);
            }
        }
        if (!toPlace.empty()) {
            // Each such vertex's triangles in the probe, (vertex, first index) sorted.
            std::vector<std::pair<uint32_t, uint32_t>> fan;
            for (size_t t = 0; t < probe.size(); t += 3)
                for (size_t k = 0; k < 3; ++k)
                    if (const uint32_t v = probe[t + k]; v < dualVertices && toMean[v] == 1)
                        fan.push_back({v, uint32_t(t)});
            std::sort(fan.begin(), fan.end());
            for (uint32_t v : toPlace) {
                toMean[v] = 2;
                const auto mine = std::equal_range(
                    fan.begin(), fan.end(), std::pair{v, 0u},
                    [](const auto& x, const auto& y) { return x.first < y.first; });
                // How the fan faces with v at p: its folding triangles, then their sum.
                auto score = [&](glm::vec3 p) {
                    mesh.positions[v] = p;
                    float folds = 0.0f, sum = 0.0f;
                    for (auto it = mine.first; it != mine.second; ++it) {
                        const uint32_t* f = &probe[it->second];
                        const float c = facing(mesh, distance, h, f[0], f[1], f[2], true);
                        if (c < 0.0f) {
                            folds += 1.0f;
                            sum += c;
                        }
                    }
                    return std::pair{folds, -sum};
                };
                const glm::vec3 lo = cellLo(v) + kInset * h, hi = cellLo(v) + (1 - kInset) * h;
                auto onSurface = [&](glm::vec3 p) {
                    return distance ? towardSurface(distance, p, lo, hi, h) : p;
                };
                glm::vec3 sum(0.0f);
                int count = 0;
                for (auto it = std::lower_bound(around.begin(), around.end(), std::pair{v, 0u});
                     it != around.end() && it->first == v; ++it, ++count)
                    sum += edgePosition(it->second);
                const glm::vec3 placed = mesh.positions[v];
                glm::vec3 best = placed;
                auto bestScore = score(placed);
                if (count > 0) {
                    const glm::vec3 mean = sum / float(count);
                    for (const glm::vec3& p :
                         {mean, onSurface(mean), onSurface(placed), cellLo(v) + 0.5f * h}) {
                        if (const auto c = score(p); c < bestScore) {
                            bestScore = c;
                            best = p;
                        }
                    }
                }
                mesh.positions[v] = best;
                moved += best != placed;
            }
        }
        if ((pairs.empty() && moved == 0) || round == kRounds) break;
        for (const auto& [a, b] : pairs)
            for (uint32_t t : {a, b})
                for (int k = 0; k < 3; ++k)
                    if (const uint32_t v = probe[3 * size_t(t) + size_t(k)];
                        v < dualVertices && !isMarked(v)) {
                        marked[cellOf[v]] = 1;
                        ++newly;
                    }
        if (newly + moved == 0) break; // what crosses lies in cells already split
        result.cells += newly;
        result.rounds = round + 1;
        // A marked cell with several vertices (pieces of surface, or copies of one vertex for
        // two sheets that touch): each goes to the mean of its quads' edge points, inside the
        // convex hull of its loop of chords, where its fan then stays; loops whose hulls are
        // apart give fans that are apart.
        around.clear();
        split.clear();
        if (reach.empty()) reach.assign(dualVertices, 0);
        std::vector<std::pair<uint32_t, glm::vec3>> sums; // vertex, its quads' edge points
        for (uint32_t q = 0; q < quads; ++q) {
            const std::array<uint32_t, 4> c = cornersOf(quad(q));
            if (!anyMarked(c)) continue;
            split.push_back(q);
            for (uint32_t v : c) {
                reach[v] = 1;
                if (!isMarked(v)) continue;
                around.push_back({v, q});
                if (shared[v]) sums.push_back({v, edgePosition(q)});
            }
        }
        // A reached cell of several vertices is reached at all of them.
        for (const auto& [k, v] : group)
            if (reach[v]) reach[cellOf[v]] = 1;
        for (const auto& [k, v] : group)
            if (reach[cellOf[v]]) reach[v] = 1;
        std::sort(around.begin(), around.end());
        std::stable_sort(sums.begin(), sums.end(),
                         [](const auto& x, const auto& y) { return x.first < y.first; });
        for (size_t k = 0; k < sums.size();) {
            size_t end = k;
            glm::vec3 sum(0.0f);
            for (; end < sums.size() && sums[end].first == sums[k].first; ++end)
                sum += sums[end].second;
            mesh.positions[sums[k].first] = sum / float(end - k);
            k = end;
        }
    }
    // The split quads into the mesh: each its first two triangles in its own place, the rest at
    // the end. All fans are made before any quad is written over: making one reads others.
    std::vector<uint32_t> fans, ends;
    for (uint32_t q : split) {
        trianglesOf(q, fans);
        ends.push_back(uint32_t(fans.size()));
    }
    for (size_t i = 0, begin = 0; i < split.size(); begin = ends[i++]) {
        std::copy(fans.begin() + std::ptrdiff_t(begin), fans.begin() + std::ptrdiff_t(begin + 6),
                  quad(split[i]));
        mesh.indices.insert(mesh.indices.end(), fans.begin() + std::ptrdiff_t(begin + 6),
                            fans.begin() + ends[i]);
    }
    return result;
}

size_t unfoldVertices(Mesh& mesh, glm::vec3 origin, float h, const Distance& distance) {
    if (!distance) return 0;
    const size_t triangles = mesh.triangleCount();
    const std::vector<glm::vec3>& p = mesh.positions;
    // How triangle t faces the field (fieldFacing()); a triangle without a plane (as the tests'
    // check sees it: its height under 1e-4 of a cell) counts as folding.
    auto faces = [&](size_t t, const glm::vec3* gradient = nullptr) {
        const uint32_t* v = &mesh.indices[3 * t];
        const glm::vec3 a = p[v[0]], b = p[v[1]], c = p[v[2]];
        const float longest =
            std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
        if (!(glm::length(glm::cross(b - a, c - a)) > 1e-4f * h * longest)) return -2.0f;
        if (!gradient) return fieldFacing(mesh, distance, h, v[0], v[1], v[2]);
        const glm::vec3 n = glm::cross(b - a, c - a);
        const float gg = glm::dot(*gradient, *gradient);
        if (!(gg > 0.0f)) return 1.0f; // no direction to judge by, as fieldFacing()
        return glm::dot(n, *gradient) / std::sqrt(glm::dot(n, n) * gg) - kLeastCosine;
    };
    // The vertices of the triangles that fold, in order. The field is asked only where a
    // triangle faces more than 10 degrees away from one of its vertices' normals (as at a sharp
    // feature, or on a surface curved within a few cells): one that faces like its vertices'
    // normals, across a groove thinner than a cell, may still face away from the field where
    // its centre lies near the groove's wall.
    std::vector<uint32_t> moving, theirs;
    inHalves(
        triangles,
        [&](size_t begin, size_t end, int half) {
            std::vector<uint32_t>& found = half == 0 ? moving : theirs;
            const std::vector<glm::vec3>& n = mesh.normals;
            for (size_t t = begin; t < end; ++t) {
                const uint32_t* v = &mesh.indices[3 * t];
                const glm::vec3 c = glm::cross(p[v[1]] - p[v[0]], p[v[2]] - p[v[0]]);
                const float least = 0.985f * glm::length(c); // cos 10 degrees
                if (glm::dot(c, n[v[0]]) >= least && glm::dot(c, n[v[1]]) >= least &&
                    glm::dot(c, n[v[2]]) >= least)
                    continue;
                // First the field's slope along the triangle's normal, two values: where it rises
                // at half the rate of a distance or more, the gradient (the field is 1-Lipschitz)
                // lies within 60 degrees of the normal.
                const float cc = glm::length(c);
                if (cc > 0.0f) {
                    const glm::vec3 centre = (p[v[0]] + p[v[1]] + p[v[2]]) / 3.0f;
                    const glm::vec3 step = c / cc * (0.01f * h);
                    if (distance(centre + step) - distance(centre - step) >= 0.5f * 0.02f * h)
                        continue;
                }
                if (faces(t) >= 0.0f) continue;
                found.insert(found.end(), v, v + 3);
            }
        },
        4096);
    moving.insert(moving.end(), theirs.begin(), theirs.end());
    std::sort(moving.begin(), moving.end());
    moving.erase(std::unique(moving.begin(), moving.end()), moving.end());
    // The vertices farther than 0.45 of a cell from the surface (moved after below), one value
    // of the field each.
    std::vector<uint32_t> far, farTheirs;
    inHalves(
        p.size(),
        [&](size_t begin, size_t end, int half) {
            for (size_t v = begin; v < end; ++v)
                if (std::abs(distance(p[v])) > 0.45f * h)
                    (half == 0 ? far : farTheirs).push_back(uint32_t(v));
        },
        4096);
    far.insert(far.end(), farTheirs.begin(), farTheirs.end());
    if (moving.empty() && far.empty()) return 0;
    // The triangles by the cell of their centre, (cell, triangle) sorted, to find those near a
    // vertex: a triangle spans at most two cells along each axis, so those that may meet a
    // vertex's triangles have their centres within three cells of it.
    auto cellKey = [&](glm::ivec3 c) {
        c += 8; // cells just outside the grid's corner
        return uint64_t(uint32_t(c.x)) | uint64_t(uint32_t(c.y)) << 21 |
               uint64_t(uint32_t(c.z)) << 42;
    };
    auto cellOf = [&](glm::vec3 x) { return glm::ivec3(glm::floor((x - origin) / h)); };
    std::vector<std::pair<uint64_t, uint32_t>> byCell(triangles);
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (size_t t = 0; t < triangles; ++t) {
        const uint32_t* v = &mesh.indices[3 * t];
        byCell[t] = {cellKey(cellOf((p[v[0]] + p[v[1]] + p[v[2]]) / 3.0f)), uint32_t(t)};
    }
    for (const glm::vec3& x : p) {
        lo = glm::min(lo, x);
        hi = glm::max(hi, x);
    }
    std::sort(byCell.begin(), byCell.end());
    const double tolerance = 1e-6 * double(glm::length(hi - lo)); // findSelfIntersections'

    // Whether a vertex's triangles meet others, with it where it is: findSelfIntersections on a
    // small mesh of its triangles and those of `local` whose bounds reach theirs (the whole
    // mesh's positions would make each call as slow as the mesh is large).
    std::vector<uint32_t> local, star, order;
    std::vector<std::pair<uint32_t, uint32_t>> pairs;
    Mesh near;
    std::unordered_map<uint32_t, uint32_t> numbers;
    auto meets = [&] {
        glm::vec3 starLo(INFINITY), starHi(-INFINITY);
        for (uint32_t t : star)
            for (int k = 0; k < 3; ++k) {
                starLo = glm::min(starLo, p[mesh.indices[3 * size_t(t) + k]]);
                starHi = glm::max(starHi, p[mesh.indices[3 * size_t(t) + k]]);
            }
        const float grow = 2.0f * float(tolerance);
        near.positions.clear();
        near.indices.clear();
        numbers.clear();
        order.clear(); // the triangles of `near`, by their numbers in `mesh`
        for (uint32_t t : local) {
            const uint32_t* k = &mesh.indices[3 * size_t(t)];
            const glm::vec3 tLo = glm::min(p[k[0]], glm::min(p[k[1]], p[k[2]]));
            const glm::vec3 tHi = glm::max(p[k[0]], glm::max(p[k[1]], p[k[2]]));
            if (glm::any(glm::greaterThan(tLo, starHi + grow)) ||
                glm::any(glm::lessThan(tHi, starLo - grow)))
                continue;
            order.push_back(t);
            for (int i = 0; i < 3; ++i) {
                const auto [it, added] = numbers.try_emplace(k[i], uint32_t(near.positions.size()));
                if (added) near.positions.push_back(p[k[i]]);
                near.indices.push_back(it->second);
            }
        }
        pairs.clear();
        findSelfIntersections(near, tolerance, 1e-3, &pairs);
        size_t count = 0;
        for (const auto& [a, b] : pairs)
            count += std::binary_search(star.begin(), star.end(), order[a]) ||
                     std::binary_search(star.begin(), star.end(), order[b]);
        return count;
    };

    // Each vertex in turn, at candidate points of its cell: it moves to the first from which
    // none of its triangles faces against the field and they meet no more others than they did
    // (else to the one that unfolds most of them, on the same terms). A candidate costs the field
    // about a dozen values to move onto the surface and four per triangle (fewer where one folds
    // early: those that fold where the vertex is are asked first), so a prediction orders them:
    // each triangle's gradient where the vertex is, against the triangle's plane with the vertex
    // at the candidate. A vertex's search asks the field at most kBudget times (about a lattice
    // of 5^3; most that unfold do so within ten candidates), and a mesh's searches together at
    // most 100,000 times and four per triangle more: the random trees of one seed, whose thin
    // parts fold 2,500 triangles at 131 cells, took 4.8 s without that cap.
    constexpr size_t kBudget = 1500;
    std::vector<float> facingNow;
    std::vector<glm::vec3> gradients;
    std::vector<std::pair<int, glm::vec3>> candidates;
    // The triangles near vertex v (`local`) and its own (`star`).
    auto gather = [&](uint32_t v) {
        const glm::ivec3 c = cellOf(p[v]);
        local.clear();
        for (int x = -3; x <= 3; ++x)
            for (int y = -3; y <= 3; ++y)
                for (int z = -3; z <= 3; ++z) {
                    const uint64_t key = cellKey(c + glm::ivec3(x, y, z));
                    for (auto it =
                             std::lower_bound(byCell.begin(), byCell.end(), std::pair{key, 0u});
                         it != byCell.end() && it->first == key; ++it)
                        local.push_back(it->second);
                }
        std::sort(local.begin(), local.end());
        star.clear();
        for (uint32_t t : local) {
            const uint32_t* k = &mesh.indices[3 * size_t(t)];
            if (k[0] == v || k[1] == v || k[2] == v) star.push_back(t);
        }
    };
    // Where a vertex at `placed` may go: within its cell, and on the faces of its cell that it
    // lies on (a fan's edge and face points): there the fans stay inside their cells.
    auto bounds = [&](glm::vec3 placed, glm::vec3& inLo, glm::vec3& inHi) {
        const glm::vec3 cell = origin + glm::vec3(cellOf(placed)) * h;
        inLo = cell + kInset * h;
        inHi = cell + (1.0f - kInset) * h;
        for (int k = 0; k < 3; ++k) {
            const float at = (placed[k] - origin[k]) / h;
            if (std::abs(at - std::round(at)) <= 1e-3f) inLo[k] = inHi[k] = placed[k];
        }
    };
    size_t moved = 0;
    size_t meshLeft = 100000 + 4 * triangles;
    for (uint32_t v : moving) {
        const glm::vec3 placed = p[v];
        const glm::ivec3 c = cellOf(placed);
        gather(v);
        // The star's triangles as the field sees them now; those that fold are asked first.
        facingNow.resize(star.size());
        gradients.resize(star.size());
        int folds = 0;
        for (size_t i = 0; i < star.size(); ++i) {
            const uint32_t* k = &mesh.indices[3 * size_t(star[i])];
            gradients[i] = gradientAt(distance, (p[k[0]] + p[k[1]] + p[k[2]]) / 3.0f, h);
            facingNow[i] = faces(star[i], &gradients[i]);
            folds += facingNow[i] < 0.0f;
        }
        if (folds == 0) continue;
        std::vector<uint32_t> asked(star.size());
        for (size_t i = 0; i < star.size(); ++i)
            asked[i] = uint32_t(i);
        std::stable_sort(asked.begin(), asked.end(),
                         [&](uint32_t a, uint32_t b) { return facingNow[a] < facingNow[b]; });
        // How many of the vertex's triangles fold with it at `at`, counted up to `most`.
        size_t spent = 0;
        auto folding = [&](glm::vec3 at, int most) {
            mesh.positions[v] = at;
            int n = 0;
            for (uint32_t i : asked) {
                spent += 4;
                if (faces(star[i]) < 0.0f && ++n >= most) break;
            }
            return n;
        };
        // How many of the triangles the gradients where the vertex is say fold, with it at `at`.
        auto predicted = [&](glm::vec3 at) {
            int n = 0;
            for (size_t i = 0; i < star.size(); ++i) {
                const uint32_t* k = &mesh.indices[3 * size_t(star[i])];
                glm::vec3 q[3] = {p[k[0]], p[k[1]], p[k[2]]};
                for (int j = 0; j < 3; ++j)
                    if (k[j] == v) q[j] = at;
                const glm::vec3 n3 = glm::cross(q[1] - q[0], q[2] - q[0]);
                n += glm::dot(n3, gradients[i]) <
                     kLeastCosine * glm::length(n3) * glm::length(gradients[i]);
            }
            return n;
        };
        // No candidate lies farther from the surface than 0.45 of a cell, or than the vertex.
        const float reach = std::max(0.45f * h, std::abs(distance(placed)));
        const glm::vec3 cell = origin + glm::vec3(c) * h;
        glm::vec3 inLo, inHi;
        bounds(placed, inLo, inHi);
        // Candidates: the vertex pulled onto the surface, the mean of its neighbours, and the
        // points of a lattice of 3^3 in the cell, then of 5^3, each moved onto the surface and
        // as it is; those the gradients predict to unfold most first, then nearest to where the
        // vertex is (where the QEF or the steps before put it, on the sharp features).
        glm::vec3 ring(0.0f);
        for (uint32_t t : star)
            for (int k = 0; k < 3; ++k)
                ring += p[mesh.indices[3 * size_t(t) + k]];
        ring = (ring - float(star.size()) * placed) / float(2 * star.size());
        candidates.clear();
        candidates.push_back({-1, placed});
        candidates.push_back({-1, glm::clamp(ring, inLo, inHi)});
        for (const int steps : {3, 5})
            for (int x = 0; x < steps; ++x)
                for (int y = 0; y < steps; ++y)
                    for (int z = 0; z < steps; ++z) {
                        const glm::vec3 q = glm::clamp(
                            cell + (glm::vec3(x, y, z) + 0.5f) / float(steps) * h, inLo, inHi);
                        candidates.push_back({predicted(q), q});
                    }
        std::stable_sort(
            candidates.begin() + 2, candidates.end(), [&](const auto& x, const auto& y) {
                return x.first < y.first ||
                       (x.first == y.first && glm::dot(x.second - placed, x.second - placed) <
                                                  glm::dot(y.second - placed, y.second - placed));
            });
        // Where none unfolds all, the candidates that unfold most (fewest folding first).
        std::vector<std::pair<int, glm::vec3>> partial;
        size_t before = SIZE_MAX;
        auto keeps = [&](glm::vec3 at) {
            if (before == SIZE_MAX) {
                mesh.positions[v] = placed;
                before = meets();
            }
            mesh.positions[v] = at;
            return meets() <= before;
        };
        bool done = false;
        int fewest = folds;
        for (const auto& candidate : candidates) {
            const glm::vec3 q = candidate.second;
            if (spent >= kBudget || spent >= meshLeft) break;
            // Onto the surface by one Newton step, kept where it brings the point nearer.
            const float d = distance(q);
            const glm::vec3 g = gradientAt(distance, q, h);
            glm::vec3 onSurface = q;
            if (const float gg = glm::dot(g, g); gg > 1e-6f) {
                const glm::vec3 next = glm::clamp(q - d * g / gg, inLo, inHi);
                if (std::abs(distance(next)) < std::abs(d)) onSurface = next;
            }
            spent += 6;
            for (const glm::vec3& at : {onSurface, q}) {
                if (at == placed || (at == q && !(std::abs(d) <= reach)) ||
                    (at != q && !(std::abs(d) <= reach) && !(std::abs(distance(at)) <= reach)))
                    continue;
                const int n = folding(at, fewest + 1);
                if (n == 0 && keeps(at)) {
                    done = true;
                    break;
                }
                if (n > 0 && n <= fewest && n < folds) {
                    fewest = n;
                    partial.push_back({n, at});
                }
            }
            if (done) break;
        }
        std::stable_sort(partial.begin(), partial.end(),
                         [](const auto& x, const auto& y) { return x.first < y.first; });
        for (size_t k = 0; !done && k < partial.size() && k < 3; ++k)
            done = keeps(partial[k].second);
        meshLeft -= std::min(meshLeft, spent);
        if (done)
            ++moved;
        else
            mesh.positions[v] = placed;
    }
    // Then each vertex still farther than 0.45 of a cell from the surface moves toward it, within
    // its cell or the face it lies on, where none of its triangles then faces against the field
    // that did not and they meet no more others: over 12 seeds of the tests' random trees and
    // Booleans and table_and_chairs, 67 vertices lay beyond half a cell, up to 0.58 (58 where
    // the QEF placed them inside their cells, on the corner of tangent planes of a rounded
    // piece; 3 means of curved pieces and 6 fans' face points of separateCrossings()).
    for (uint32_t v : far) {
        const glm::vec3 placed = p[v];
        const float d = std::abs(distance(placed));
        if (!(d > 0.45f * h)) continue; // brought nearer by the unfolding
        glm::vec3 inLo, inHi;
        bounds(placed, inLo, inHi);
        const glm::vec3 to = towardSurface(distance, placed, inLo, inHi, h);
        gather(v);
        facingNow.resize(star.size());
        for (size_t i = 0; i < star.size(); ++i)
            facingNow[i] = faces(star[i]);
        mesh.positions[v] = placed;
        const size_t before = meets();
        bool done = false;
        // Along the gradient, a share of the way, the largest first: then the shares that bring
        // it to about 0.45 and 0.49 of a cell (the field being about linear there), below a
        // quarter, where a quarter turns a triangle over; then a fifth, nearer at least. Then
        // toward each neighbour, a quarter and half of the way, kept to the cell or face: a fan's
        // face point, halfway along a chord of a curved piece, nears it toward the chord's ends
        // where the gradient's way turns a triangle over.
        const float gain = std::max(d - std::abs(distance(to)), 1e-6f * h);
        const float to45 = 1.1f * (d - 0.45f * h) / gain, to49 = 1.05f * (d - 0.49f * h) / gain;
        candidates.clear();
        for (const float share : {1.0f, 0.75f, 0.5f, 0.25f})
            candidates.push_back({0, placed + share * (to - placed)});
        for (const float share : {to45, to49, 0.2f})
            if (share > 0.0f && share < 0.25f)
                candidates.push_back({0, placed + share * (to - placed)});
        for (uint32_t t : star)
            for (int k = 0; k < 3; ++k)
                if (const uint32_t u = mesh.indices[3 * size_t(t) + size_t(k)]; u != v)
                    for (const float share : {0.25f, 0.5f})
                        candidates.push_back(
                            {1, glm::clamp(placed + share * (p[u] - placed), inLo, inHi)});
        for (const auto& [kind, at] : candidates) {
            const float e = std::abs(distance(at));
            if (at == placed || !(e < d) || (kind == 1 && !(e <= 0.45f * h))) continue;
            mesh.positions[v] = at;
            bool folds = false;
            for (size_t i = 0; i < star.size() && !folds; ++i)
                folds = facingNow[i] >= 0.0f && faces(star[i]) < 0.0f;
            if (!folds && meets() <= before) {
                done = true;
                break;
            }
        }
        if (done)
            ++moved;
        else
            mesh.positions[v] = placed;
    }
    return moved;
}

} // namespace sdfcsg::detail
