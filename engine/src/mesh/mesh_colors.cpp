// Crisp colour regions. Where a hard union or difference joins parts of different colours, the
// field's colour jumps along the curve where their surfaces meet; the extraction's vertices lie
// on either side of it, and triangles across it would blend the two colours. As the sharp
// features of dual contouring are found from the field rather than from the grid, the border is
// found on each edge that crosses it by bisection on the surface (each middle point moved onto
// the surface by Newton steps along the gradient), and the triangles are cut there. A smooth
// blend is told from a jump by its colours meeting as the bisection closes in.
#include "mesh/mesh_colors.h"

#include "mesh/self_intersections.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <thread>
#include <tuple>
#include <unordered_map>
#include <vector>

namespace sdfcsg::detail {
namespace {

constexpr float kConverged = 1e-3f; // cells: the bisection stops with its ends this close
constexpr float kSnap = 0.02f;      // cells: a border point this close to an end is that end
constexpr int kMaxHalvings = 40;
constexpr uint32_t kNone = UINT32_MAX;

float colourGap(glm::vec3 a, glm::vec3 b) {
    const glm::vec3 d = glm::abs(a - b);
    return std::max(d.x, std::max(d.y, d.z));
}

// f(begin, end) over [0, n), halved between two threads where that pays; every index writes only
// its own results, so they do not depend on the threads.
template <class F> void onTwoThreads(size_t n, F&& f) {
    if (n < 64 || std::thread::hardware_concurrency() < 2) {
        f(size_t(0), n);
        return;
    }
    std::thread helper([&] { f(n / 2, n); });
    f(size_t(0), n / 2);
    helper.join();
}

// The field near the surface, with differences a hundredth of a cell wide (as the dual
// contouring's host step takes them); on scenes of pruned tapes, the tapes' (the same near the
// surface, where the whole tree would be far too slow).
struct Field {
    const Evaluator& evaluator;
    float h;
    bool pruned = evaluator.nodes().size() >= kTapeMinNodes;

    float distance(glm::vec3 p) const {
        return pruned ? evaluator.prunedDistance(p) : evaluator.distance(p);
    }
    glm::vec3 colour(glm::vec3 p) const {
        return (pruned ? evaluator.prunedSample(p) : evaluator.sample(p)).color;
    }

    glm::vec3 gradient(glm::vec3 p) const {
        const float s = 0.01f * h;
        const glm::vec3 taps[4] = {{1, -1, -1}, {-1, -1, 1}, {-1, 1, -1}, {1, 1, 1}};
        glm::vec3 g(0.0f);
        for (const glm::vec3& t : taps)
            g += t * distance(p + t * s);
        return g / (4.0f * s);
    }
    // Newton steps towards the surface, each at most a cell long; with `across` (unit length),
    // within the plane through p normal to it.
    glm::vec3 project(glm::vec3 p, int steps, glm::vec3 across = glm::vec3(0.0f)) const {
        for (int i = 0; i < steps; ++i) {
            const float d = distance(p);
            if (!(std::abs(d) > 1e-5f * h)) break;
            glm::vec3 g = gradient(p);
            g -= glm::dot(g, across) * across;
            const float g2 = glm::dot(g, g);
            if (!(g2 > 1e-12f)) break;
            glm::vec3 step = g * (d / g2);
            const float length = glm::length(step);
            if (length > h) step *= h / length;
            p -= step;
        }
        return p;
    }
};

// A point where the colour jumps on the edge between vertices a < b.
struct Border {
    uint32_t a = 0, b = 0;
    bool found = false;
    glm::vec3 position{0.0f}, normal{0.0f};
    glm::vec3 colour{0.0f}; // the new vertex's: one of the colours on either side
};

// The bisection stays in the plane of the edge and the surface's normal along it: free, the
// middles would slide along a concave crease towards where it passes nearest, and the edges
// from one vertex across the crease would all be cut at about one point.
void searchEdge(const Field& field, const Mesh& mesh, const std::vector<glm::vec3>& colourAt,
                Border& border) {
    const glm::vec3 pa = mesh.positions[border.a], pb = mesh.positions[border.b];
    glm::vec3 across = glm::cross(pb - pa, field.gradient(0.5f * (pa + pb)));
    const float acrossLength = glm::length(across);
    across = acrossLength > 0.0f ? across / acrossLength : glm::vec3(0.0f);
    glm::vec3 lo = pa, hi = pb, cLo = colourAt[border.a], cHi = colourAt[border.b];
    for (int i = 0;; ++i) {
        if (colourGap(cLo, cHi) <= kColourTolerance) return; // a blend: the colours met
        if (glm::distance(lo, hi) < kConverged * field.h) break;
        if (i == kMaxHalvings) return;
        const glm::vec3 m = field.project(0.5f * (lo + hi), 2, across);
        const glm::vec3 cm = field.colour(m);
        if (colourGap(cm, cLo) <= colourGap(cm, cHi)) {
            lo = m;
            cLo = cm;
        } else {
            hi = m;
            cHi = cm;
        }
    }
    const glm::vec3 p = 0.5f * (lo + hi);
    const float snap = kSnap * field.h;
    if (glm::distance(p, pa) < snap || glm::distance(p, pb) < snap) return;
    // A bisection that wandered off along the surface (to another sheet) found nothing here.
    const glm::vec3 d = pb - pa;
    const float t = std::clamp(glm::dot(p - pa, d) / glm::dot(d, d), 0.0f, 1.0f);
    if (glm::distance(pa + t * d, p) > 0.5f * glm::length(d)) return;
    glm::vec3 n = field.gradient(p);
    if (!(glm::dot(n, n) > 1e-12f)) n = mesh.normals.empty() ? d : mesh.normals[border.a];
    border.position = p;
    border.normal = glm::normalize(n);
    // The new vertex's colour, one of the two, by a rule that does not depend on the vertices'
    // numbers (the CPU reference numbers them otherwise): the smaller as (r, g, b).
    border.colour = std::tie(cLo.r, cLo.g, cLo.b) <= std::tie(cHi.r, cHi.g, cHi.b) ? cLo : cHi;
    border.found = true;
}

uint64_t edgeKey(uint32_t a, uint32_t b) {
    return a < b ? uint64_t(a) << 32 | b : uint64_t(b) << 32 | a;
}

// The pieces of triangle `tri` cut at the points `mid` (mid[k] on the side tri[k] -> tri[k + 1],
// or kNone), wound as the triangle; `centre` is the vertex at its centre, used where all three
// sides are cut. Returns how many pieces.
int cutTriangle(const uint32_t tri[3], const uint32_t mid[3], uint32_t centre,
                const std::function<glm::vec3(uint32_t)>& position, uint32_t out[6][3]) {
    const int cuts = (mid[0] != kNone) + (mid[1] != kNone) + (mid[2] != kNone);
    auto put = [&](int i, uint32_t a, uint32_t b, uint32_t c) {
        out[i][0] = a;
        out[i][1] = b;
        out[i][2] = c;
    };
    if (cuts == 0) {
        put(0, tri[0], tri[1], tri[2]);
        return 1;
    }
    if (cuts == 1) {
        const int k = mid[0] != kNone ? 0 : mid[1] != kNone ? 1 : 2;
        const uint32_t a = tri[k], b = tri[(k + 1) % 3], c = tri[(k + 2) % 3], m = mid[k];
        put(0, a, m, c);
        put(1, m, b, c);
        return 2;
    }
    if (cuts == 2) {
        // Side j is whole; the corner b between the two cut sides is cut off, and the quad
        // x, m1, m2, y that is left is split along its shorter diagonal.
        const int j = mid[0] == kNone ? 0 : mid[1] == kNone ? 1 : 2;
        const uint32_t y = tri[j], x = tri[(j + 1) % 3], b = tri[(j + 2) % 3];
        const uint32_t m1 = mid[(j + 1) % 3], m2 = mid[(j + 2) % 3];
        put(0, m1, b, m2);
        if (glm::distance(position(x), position(m2)) <= glm::distance(position(m1), position(y))) {
            put(1, x, m1, m2);
            put(2, x, m2, y);
        } else {
            put(1, x, m1, y);
            put(2, m1, m2, y);
        }
        return 3;
    }
    for (int k = 0; k < 3; ++k) {
        put(2 * k, tri[k], mid[k], centre);
        put(2 * k + 1, mid[k], tri[(k + 1) % 3], centre);
    }
    return 6;
}

} // namespace

bool hasSeveralColours(const Evaluator& evaluator) {
    const glm::vec3* first = nullptr;
    for (const FlatNode& n : evaluator.nodes()) {
        if (!n.children.empty()) continue;
        if (!first)
            first = &n.color;
        else if (colourGap(*first, n.color) > kColourTolerance)
            return true;
    }
    return false;
}

glm::vec3 surfaceColour(const Evaluator& evaluator, glm::vec3 p, float h) {
    const Field field{evaluator, h};
    return field.colour(field.project(p, 3));
}

size_t splitColourBorders(Mesh& mesh, const Evaluator& evaluator, float h) {
    const size_t triangles = mesh.triangleCount(), vertices = mesh.vertexCount();
    const Field field{evaluator, h};
    const bool coloured = mesh.colors.size() == vertices;
    const uint32_t* idx = mesh.indices.data();

    // Triangles whose corners came out of the extraction in more than one colour or in a blend
    // (a vertex takes its nearest edge point's colour, so a blend's neighbours may share one),
    // and the triangles around them, where a border may pass between vertices of one colour;
    // then the evaluator's colour at their corners.
    std::vector<glm::vec3> palette; // the primitives' colours
    for (const FlatNode& n : evaluator.nodes())
        if (n.children.empty() && std::none_of(palette.begin(), palette.end(), [&](glm::vec3 c) {
                return colourGap(c, n.color) <= kColourTolerance;
            }))
            palette.push_back(n.color);
    std::vector<uint8_t> mixed(triangles, 1);
    if (coloured) {
        size_t last = 0; // the palette's entry that matched last
        auto pure = [&](glm::vec3 c) {
            if (colourGap(c, palette[last]) <= kColourTolerance) return true;
            for (size_t i = 0; i < palette.size(); ++i)
                if (colourGap(c, palette[i]) <= kColourTolerance) {
                    last = i;
                    return true;
                }
            return false;
        };
        std::vector<uint8_t> touched(vertices, 0);
        for (size_t t = 0; t < triangles; ++t) {
            const glm::vec3 &c0 = mesh.colors[idx[3 * t]], &c1 = mesh.colors[idx[3 * t + 1]],
                            &c2 = mesh.colors[idx[3 * t + 2]];
            mixed[t] = colourGap(c0, c1) > kColourTolerance ||
                       colourGap(c1, c2) > kColourTolerance ||
                       colourGap(c0, c2) > kColourTolerance || palette.empty() || !pure(c0);
            if (mixed[t])
                for (int k = 0; k < 3; ++k)
                    touched[idx[3 * t + k]] = 1;
        }
        for (size_t t = 0; t < triangles; ++t)
            mixed[t] = mixed[t] || touched[idx[3 * t]] || touched[idx[3 * t + 1]] ||
                       touched[idx[3 * t + 2]];
    }
    std::vector<uint8_t> listed(vertices, 0);
    std::vector<uint32_t> corners;
    for (size_t t = 0; t < triangles; ++t)
        if (mixed[t])
            for (int k = 0; k < 3; ++k)
                if (!listed[idx[3 * t + k]]) {
                    listed[idx[3 * t + k]] = 1;
                    corners.push_back(idx[3 * t + k]);
                }
    std::vector<glm::vec3> colourAt(vertices, glm::vec3(0.0f));
    onTwoThreads(corners.size(), [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i)
            colourAt[corners[i]] = field.colour(mesh.positions[corners[i]]);
    });

    // The edges of those triangles whose ends the evaluator colours differently, each once.
    std::vector<uint64_t> keys;
    for (size_t t = 0; t < triangles; ++t)
        if (mixed[t])
            for (int k = 0; k < 3; ++k) {
                const uint32_t a = idx[3 * t + k], b = idx[3 * t + (k + 1) % 3];
                if (colourGap(colourAt[a], colourAt[b]) > kColourTolerance)
                    keys.push_back(edgeKey(a, b));
            }
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    std::vector<Border> borders(keys.size());
    onTwoThreads(keys.size(), [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) {
            borders[i].a = uint32_t(keys[i] >> 32);
            borders[i].b = uint32_t(keys[i]);
            searchEdge(field, mesh, colourAt, borders[i]);
        }
    });
    std::unordered_map<uint64_t, uint32_t> borderOf; // edge -> its entry in borders
    std::vector<uint8_t> atBorder(vertices, 0);
    for (size_t i = 0; i < borders.size(); ++i)
        if (borders[i].found) {
            borderOf.emplace(keys[i], uint32_t(i));
            atBorder[borders[i].a] = atBorder[borders[i].b] = 1;
        }

    // The triangles with a cut side, and the point at the centre of those with three.
    std::vector<uint32_t> cut;
    for (size_t t = 0; t < triangles; ++t)
        if (atBorder[idx[3 * t]] + atBorder[idx[3 * t + 1]] + atBorder[idx[3 * t + 2]] >= 2)
            for (int k = 0; k < 3; ++k)
                if (borderOf.count(edgeKey(idx[3 * t + k], idx[3 * t + (k + 1) % 3]))) {
                    cut.push_back(uint32_t(t));
                    break;
                }
    std::vector<glm::vec3> centres(cut.size());
    onTwoThreads(cut.size(), [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) {
            const uint32_t* v = idx + 3 * size_t(cut[i]);
            centres[i] = field.project(
                (mesh.positions[v[0]] + mesh.positions[v[1]] + mesh.positions[v[2]]) / 3.0f, 3);
        }
    });

    // Vertex numbers while checking: borders[i] is kBorderBase + i, the centre kCentre.
    constexpr uint32_t kCentre = kNone - 1;
    const uint32_t kBorderBase = uint32_t(vertices);
    const glm::vec3* centre = nullptr;
    const std::function<glm::vec3(uint32_t)> position = [&](uint32_t v) {
        return v == kCentre       ? *centre
               : v >= kBorderBase ? borders[v - kBorderBase].position
                                  : mesh.positions[v];
    };
    auto midsOf = [&](const uint32_t* v, uint32_t mid[3]) {
        for (int k = 0; k < 3; ++k) {
            const auto it = borderOf.find(edgeKey(v[k], v[(k + 1) % 3]));
            mid[k] = it == borderOf.end() ? kNone : kBorderBase + it->second;
        }
    };
    // Drops the points that would turn a piece over, face it against the field's gradient at its
    // centre (across a crease) or leave it without area, until none does.
    // Only the triangles beside a dropped point need another look.
    const float leastArea = 1e-6f * h * h;
    std::vector<uint8_t> recheck(vertices, 1);
    for (bool dropped = true; dropped;) {
        dropped = false;
        std::vector<uint32_t> ends;
        for (size_t i = 0; i < cut.size(); ++i) {
            const uint32_t* v = idx + 3 * size_t(cut[i]);
            if (!recheck[v[0]] && !recheck[v[1]] && !recheck[v[2]]) continue;
            uint32_t mid[3], pieces[6][3];
            midsOf(v, mid);
            centre = &centres[i];
            const int count = cutTriangle(v, mid, kCentre, position, pieces);
            if (count == 1) continue;
            const glm::vec3 whole = glm::cross(mesh.positions[v[1]] - mesh.positions[v[0]],
                                               mesh.positions[v[2]] - mesh.positions[v[0]]);
            bool fine = glm::length(whole) > 2.0f * leastArea;
            for (int p = 0; p < count && fine; ++p) {
                const glm::vec3 a = position(pieces[p][0]);
                const glm::vec3 n =
                    glm::cross(position(pieces[p][1]) - a, position(pieces[p][2]) - a);
                const glm::vec3 centroid =
                    (a + position(pieces[p][1]) + position(pieces[p][2])) / 3.0f;
                fine = glm::dot(n, whole) > 0.0f && glm::length(n) > 2.0f * leastArea &&
                       glm::dot(n, field.gradient(centroid)) > 0.0f;
            }
            if (fine) continue;
            for (int k = 0; k < 3; ++k)
                if (mid[k] != kNone) {
                    borderOf.erase(edgeKey(v[k], v[(k + 1) % 3]));
                    ends.push_back(v[k]);
                    ends.push_back(v[(k + 1) % 3]);
                }
            dropped = true;
        }
        std::fill(recheck.begin(), recheck.end(), 0);
        for (uint32_t e : ends)
            recheck[e] = 1;
    }

    // The new vertices: the border points that stayed, then the centres that are used.
    std::vector<uint32_t> vertexOf(borders.size(), kNone);
    size_t splits = 0;
    for (size_t i = 0; i < borders.size(); ++i)
        if (borders[i].found && borderOf.count(keys[i])) {
            vertexOf[i] = uint32_t(mesh.positions.size());
            mesh.positions.push_back(borders[i].position);
            if (!mesh.normals.empty()) mesh.normals.push_back(borders[i].normal);
            if (coloured) mesh.colors.push_back(borders[i].colour);
            ++splits;
        }

    // The triangles in their order, each cut one in its pieces' place (`source`: the cut
    // triangle each piece comes from, or kNone); the triangles whose colour needs the field.
    std::vector<uint32_t> indices, source, sampled;
    indices.reserve(mesh.indices.size() + 12 * cut.size());
    source.reserve(triangles + 4 * cut.size());
    std::vector<glm::vec3>& colours = mesh.triangleColors;
    colours.clear();
    colours.reserve(triangles + 4 * cut.size());
    std::vector<std::array<uint32_t, 4>> made(cut.size()); // each cut's points, its centre last
    const std::function<glm::vec3(uint32_t)> at = [&](uint32_t i) { return mesh.positions[i]; };
    size_t nextCut = 0;
    for (size_t t = 0; t < triangles; ++t) {
        const uint32_t* v = idx + 3 * t;
        const bool isCut = nextCut < cut.size() && cut[nextCut] == t;
        uint32_t mid[3] = {kNone, kNone, kNone}, pieces[6][3];
        if (isCut) midsOf(v, mid);
        const bool cuts = mid[0] != kNone || mid[1] != kNone || mid[2] != kNone;
        if (!cuts) {
            if (isCut) ++nextCut;
            indices.insert(indices.end(), v, v + 3);
            source.push_back(kNone);
            if (mixed[t]) sampled.push_back(uint32_t(colours.size()));
            colours.push_back(coloured ? mesh.colors[v[0]] : glm::vec3(0.0f));
            continue;
        }
        const size_t c = nextCut++;
        made[c] = {kNone, kNone, kNone, kNone};
        if (mid[0] != kNone && mid[1] != kNone && mid[2] != kNone) {
            // The centre touches all three colours; it takes the field's there.
            const glm::vec3 p = centres[c];
            made[c][3] = uint32_t(mesh.positions.size());
            mesh.positions.push_back(p);
            if (!mesh.normals.empty()) {
                const glm::vec3 g = field.gradient(p);
                mesh.normals.push_back(glm::dot(g, g) > 1e-12f ? glm::normalize(g)
                                                               : mesh.normals[v[0]]);
            }
            if (coloured) mesh.colors.push_back(field.colour(p));
        }
        for (int k = 0; k < 3; ++k)
            if (mid[k] != kNone) made[c][k] = mid[k] = vertexOf[mid[k] - kBorderBase];
        const int count = cutTriangle(v, mid, made[c][3], at, pieces);
        for (int p = 0; p < count; ++p) {
            indices.insert(indices.end(), pieces[p], pieces[p] + 3);
            source.push_back(uint32_t(c));
            sampled.push_back(uint32_t(colours.size()));
            colours.push_back(glm::vec3(0.0f));
        }
    }
    std::vector<uint32_t> original; // keeps idx's triangles
    original.swap(mesh.indices);
    mesh.indices = std::move(indices);

    // On the surface, the new points may fold the pieces into their neighbours where the surface
    // turns sharply within a cell (a concave crease). Where a piece meets another triangle that
    // way, or faces against the field, its triangle's new points go back onto its sides and its
    // centre into its plane: the pieces then tile the triangle exactly and meet nothing it did
    // not meet.
    std::vector<uint8_t> flat(cut.size(), 0);
    for (int round = 0; round < 4 && !cut.empty(); ++round) {
        std::vector<uint8_t> near(mesh.positions.size(), 0);
        for (size_t t = 0; t < source.size(); ++t)
            if (source[t] != kNone && !flat[source[t]])
                for (int k = 0; k < 3; ++k)
                    near[mesh.indices[3 * t + k]] = 1;
        Mesh local;
        local.positions = mesh.positions;
        std::vector<uint32_t> localSource;
        for (size_t t = 0; t < source.size(); ++t) {
            const uint32_t* v = &mesh.indices[3 * t];
            if (near[v[0]] || near[v[1]] || near[v[2]]) {
                local.indices.insert(local.indices.end(), v, v + 3);
                localSource.push_back(source[t]);
            }
        }
        if (local.indices.empty()) break;
        std::vector<std::pair<uint32_t, uint32_t>> pairs;
        findSelfIntersections(local, -1.0, 1e-3, &pairs);
        // Pieces that face against the field's gradient at their centre fold as well.
        for (size_t t = 0; t < localSource.size(); ++t) {
            if (localSource[t] == kNone || flat[localSource[t]]) continue;
            const uint32_t* v = &local.indices[3 * t];
            const glm::vec3 a = mesh.positions[v[0]], b = mesh.positions[v[1]],
                            c = mesh.positions[v[2]];
            if (glm::dot(glm::cross(b - a, c - a), field.gradient((a + b + c) / 3.0f)) < 0.0f)
                pairs.emplace_back(uint32_t(t), uint32_t(t));
        }
        bool flattened = false;
        for (auto [p, q] : pairs)
            for (uint32_t c : {localSource[p], localSource[q]}) {
                if (c == kNone || flat[c]) continue;
                flat[c] = 1;
                flattened = true;
                const uint32_t* v = idx + 3 * size_t(cut[c]);
                for (int k = 0; k < 3; ++k) {
                    const uint32_t m = made[c][k];
                    if (m == kNone) continue;
                    const glm::vec3 a = mesh.positions[v[k]],
                                    d = mesh.positions[v[(k + 1) % 3]] - a;
                    const float t = std::clamp(glm::dot(mesh.positions[m] - a, d) / glm::dot(d, d),
                                               0.01f, 0.99f); // never onto a corner
                    mesh.positions[m] = a + t * d;
                }
                if (made[c][3] != kNone)
                    mesh.positions[made[c][3]] =
                        (mesh.positions[v[0]] + mesh.positions[v[1]] + mesh.positions[v[2]]) / 3.0f;
            }
        if (!flattened) break;
    }

    onTwoThreads(sampled.size(), [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) {
            const uint32_t* v = &mesh.indices[3 * size_t(sampled[i])];
            colours[sampled[i]] = surfaceColour(
                evaluator,
                (mesh.positions[v[0]] + mesh.positions[v[1]] + mesh.positions[v[2]]) / 3.0f, h);
        }
    });
    return splits;
}

} // namespace sdfcsg::detail
