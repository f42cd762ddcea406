// Cheap geometric sanity checks of a valid scene, for generated ones: a model's scene may load
// and still be nonsense. Every check is conservative (it uses bounds that the field never
// undercuts), so a warning is certain, while some nonsense goes unnoticed.
#include "sdfcsg/eval.h"
#include "sdfcsg/generate.h"

#include "parse_util.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
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

std::string number(float v) {
    char text[32];
    std::snprintf(text, sizeof text, v >= 100.0f ? "%.0f" : "%.3g", double(v));
    return text;
}

// The finite part of the scene's bounds: planes reach to infinity.
Aabb finiteBounds(const Evaluator& evaluator) {
    if (evaluator.bounds().finite()) return evaluator.bounds();
    Aabb box;
    for (const FlatNode& n : evaluator.nodes()) {
        if (!n.children.empty() || !n.bounds.finite()) continue;
        box.min = glm::min(box.min, n.bounds.min);
        box.max = glm::max(box.max, n.bounds.max);
    }
    return box;
}

// True when no grid sample over the bounds comes close enough to the surface to hide a solid:
// the field is a lower bound of the distance, so a value above half a cell's diagonal at every
// cell centre leaves no room for one.
bool provablyEmpty(const Evaluator& evaluator) {
    const Aabb& box = evaluator.bounds();
    if (box.empty()) return true;
    if (!box.finite()) return false;
    constexpr int kCells = 16;
    const glm::vec3 cell = (box.max - box.min) / float(kCells);
    const float reach = 0.5f * glm::length(cell);
    for (int z = 0; z < kCells; ++z)
        for (int y = 0; y < kCells; ++y)
            for (int x = 0; x < kCells; ++x) {
                glm::vec3 p = box.min + (glm::vec3(x, y, z) + 0.5f) * cell;
                if (evaluator.distance(p) <= reach) return false;
            }
    return true;
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

    if (provablyEmpty(evaluator)) {
        warn("root", "the solid is empty: no point lies inside it");
        return out; // the other checks would only repeat it
    }

    const Aabb box = finiteBounds(evaluator);
    if (!box.empty()) {
        const float size =
            std::max({box.max.x - box.min.x, box.max.y - box.min.y, box.max.z - box.min.z});
        const float away = glm::length(0.5f * (box.min + box.max));
        if (size > 1000.0f || size < 0.001f)
            warn("root", "absurd bounds: the scene is " + number(size) +
                             " units across (expected 0.001 to 1000)");
        else if (away > 1000.0f)
            warn("root",
                 "absurd bounds: the scene lies " + number(away) + " units from the origin");
    }

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
        const float margin =
            0.01f * std::max({box.max.x - box.min.x, box.max.y - box.min.y, box.max.z - box.min.z});
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
