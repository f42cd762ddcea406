// Cheap geometric sanity checks of a valid scene, for generated ones: a model's scene may load
// and still be nonsense. Every check is conservative (it uses bounds that the field never
// undercuts), so a warning is certain, while some nonsense goes unnoticed.
#include "sdfcsg/eval.h"
#include "sdfcsg/generate.h"

#include "field/sdf.h"
#include "scene/parse_util.h"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>

namespace sdfcsg {
namespace {

bool overlap(const Aabb& a, const Aabb& b, float margin) {
    for (int i = 0; i < 3; ++i)
        if (a.min[i] - margin > b.max[i] || b.min[i] - margin > a.max[i]) return false;
    return true;
}

// A name is the model's text: quoted as the validator quotes strings, so it cannot forge a line
// or drive the terminal.
std::string label(const Node& node) {
    return node.name.empty() ? node.path : node.path + " (" + detail::quote(node.name) + ")";
}

std::string number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, v >= 100.0 && v < 1e7 ? "%.0f" : "%.3g", v);
    return text;
}

// Bounds in double precision, so that their size and distance can be told beyond the range of
// single precision.
struct Extent {
    glm::dvec3 min{std::numeric_limits<double>::infinity()};
    glm::dvec3 max{-std::numeric_limits<double>::infinity()};

    bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
    void add(glm::dvec3 lo, glm::dvec3 hi) {
        min = glm::min(min, lo);
        max = glm::max(max, hi);
    }
    double size() const { return std::max({max.x - min.x, max.y - min.y, max.z - min.z}); }
    double away() const { return glm::length(0.5 * (min + max)); }
};

// The world box of a primitive whose float bounds overflowed (a radius of 1e30 scaled by 1e30),
// from its transform, which single precision still holds; infinite where that is lost too.
Extent overflowedBounds(const FlatNode& n) {
    Extent e;
    glm::vec3 lo, hi;
    if (!sdf::localBounds(n.kind, n.params, lo, hi)) return e; // a plane
    const glm::dmat3 toWorld = glm::inverse(glm::dmat3(n.toLocal));
    const glm::dvec3 origin = -(toWorld * glm::dvec3(n.offset));
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 corner(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
        const glm::dvec3 w = toWorld * corner + origin;
        e.add(w, w);
    }
    for (int i = 0; i < 3; ++i)
        if (!std::isfinite(e.min[i]) || !std::isfinite(e.max[i])) {
            e.min[i] = -std::numeric_limits<double>::infinity();
            e.max[i] = std::numeric_limits<double>::infinity();
        }
    return e;
}

// The scene's bounds where they are finite (planes reach to infinity): the root's, else those
// of its bounded primitives.
Extent sceneExtent(const Evaluator& evaluator) {
    Extent e;
    const Aabb& root = evaluator.bounds();
    if (root.finite() && !root.empty()) {
        e.add(root.min, root.max);
        return e;
    }
    for (const FlatNode& n : evaluator.nodes()) {
        // Inside a domain operation bounds are in the operation's child space, not the world's.
        if (!n.children.empty() || n.kind == NodeKind::Plane || n.frame != kWorldFrame) continue;
        if (n.bounds.finite()) {
            e.add(n.bounds.min, n.bounds.max);
        } else {
            const Extent o = overflowedBounds(n);
            e.add(o.min, o.max);
        }
    }
    return e;
}

// What is absurd about the bounds, or "". Far from the origin the bounds are padded by about
// 1e-5 of the distance, so a size below that says nothing: a sphere of radius 1 at x = 3e38
// has bounds 6e33 across, and lies far away.
std::string absurdBounds(const Extent& box) {
    if (box.empty()) return {};
    const double size = box.size(), away = box.away();
    if (!std::isfinite(size) || !std::isfinite(away))
        return "the scene reaches beyond single precision (about 3.4e+38 units)";
    const bool resolved = size > 1e-3 * away;
    if ((size > 1000.0 && resolved) || (size < 0.001 && away <= 1000.0))
        return "the scene is " + number(size) + " units across (expected 0.001 to 1000)";
    if (away > 1000.0) return "the scene lies " + number(away) + " units from the origin";
    return {};
}

} // namespace

std::vector<Diagnostic> sceneSanityWarnings(const Scene& scene) {
    std::vector<Diagnostic> out;
    if (scene.nodes.empty()) return out;
    auto warn = [&](const std::string& path, std::string message) {
        out.push_back(Diagnostic{scene.file, path, std::move(message)});
    };
    Evaluator evaluator(scene);
    const auto& flat = evaluator.nodes();

    // Bounds first: beyond single precision the field that the emptiness check samples means
    // nothing (a radius of 3e38 made every sample NaN, and the solid was called empty).
    const Extent box = sceneExtent(evaluator);
    const double size = box.empty() ? 0.0 : box.size();
    const std::string absurd = absurdBounds(box);
    if (!box.empty() && !(size <= FLT_MAX && box.away() <= FLT_MAX)) {
        warn("root", "absurd bounds: " + absurd);
        return out;
    }
    if (provablyEmpty(evaluator)) {
        warn("root", "the solid is empty: no point lies inside it");
        return out; // the other checks would only repeat it
    }
    if (!absurd.empty()) warn("root", "absurd bounds: " + absurd);

    for (size_t i = 0; i < flat.size(); ++i) {
        if (flat[i].kind != NodeKind::Difference) continue;
        const Aabb& kept = flat[flat[i].children[0]].bounds;
        for (size_t j = 1; j < flat[i].children.size(); ++j) {
            const uint32_t c = flat[i].children[j];
            if (!overlap(kept, flat[c].bounds, flat[i].smooth))
                warn(scene.nodes[c].path, "removes nothing: it does not reach " +
                                              label(scene.nodes[flat[i].children[0]]) +
                                              ", the part it is subtracted from");
        }
    }

    // The parts of the top-level union: groups whose bounds touch no other group float apart.
    uint32_t top = 0;
    while (flat[top].children.size() == 1)
        top = flat[top].children[0];
    const auto& parts = flat[top].children;
    if (flat[top].kind == NodeKind::Union && parts.size() > 1 && !box.empty()) {
        const float margin = float(0.01 * size);
        std::vector<size_t> group(parts.size());
        std::iota(group.begin(), group.end(), 0);
        auto find = [&](size_t a) {
            while (group[a] != a)
                a = group[a] = group[group[a]];
            return a;
        };
        for (size_t a = 0; a < parts.size(); ++a)
            for (size_t b = a + 1; b < parts.size(); ++b)
                if (overlap(flat[parts[a]].bounds, flat[parts[b]].bounds, margin))
                    group[find(a)] = find(b);
        std::vector<size_t> sizes(parts.size(), 0);
        for (size_t a = 0; a < parts.size(); ++a)
            ++sizes[find(a)];
        const size_t largest = size_t(std::max_element(sizes.begin(), sizes.end()) - sizes.begin());
        for (size_t a = 0; a < parts.size(); ++a)
            if (find(a) != largest && !flat[parts[a]].bounds.empty())
                warn(scene.nodes[parts[a]].path,
                     "floats apart: it touches no part of the main group");
    }
    return out;
}

} // namespace sdfcsg
