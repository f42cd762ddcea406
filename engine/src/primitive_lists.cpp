#include "primitive_lists.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <map>

namespace sdfcsg::detail {

std::vector<PrimitiveList> primitiveLists(const Scene& scene, const Evaluator& evaluator) {
    std::vector<PrimitiveList> lists;
    for (uint32_t u = 0; u < scene.nodes.size(); ++u) {
        const Node& n = scene.nodes[u];
        if (n.kind != NodeKind::Union || evaluator.nodes()[u].smooth != 0.0f) continue;
        std::map<NodeKind, std::vector<uint32_t>> byKind;
        for (uint32_t c : n.children)
            if (!kindInfo(scene.nodes[c].kind).operation) byKind[scene.nodes[c].kind].push_back(c);
        for (auto& [kind, members] : byKind)
            if (members.size() >= kMinListLength)
                lists.push_back({u, kind, std::move(members)});
    }
    return lists;
}

namespace {

// Distance between two boxes; 0 when they overlap.
float boxDistance(const Aabb& a, const Aabb& b) {
    glm::vec3 gap = glm::max(glm::max(a.min - b.max, b.min - a.max), glm::vec3(0.0f));
    return glm::length(gap);
}

} // namespace

void pruneLists(const std::vector<PrimitiveList>& lists, const Evaluator& evaluator,
                const Aabb& region, std::vector<uint32_t>& items, std::vector<uint32_t>& ranges) {
    const glm::vec3 centre = 0.5f * (region.min + region.max);
    const float radius = 0.5f * glm::length(region.max - region.min);
    const auto& nodes = evaluator.nodes();
    uint32_t lastUnion = UINT32_MAX;
    float upper = INFINITY; // of the union's value over the region
    for (const PrimitiveList& list : lists) {
        if (list.unionNode != lastUnion) {
            lastUnion = list.unionNode;
            upper = INFINITY;
            for (uint32_t c : nodes[list.unionNode].children)
                upper = std::min(upper, evaluator.distance(centre, c) + radius);
        }
        ranges.push_back(uint32_t(items.size()));
        for (uint32_t m : list.members) {
            // The operand is no nearer than its bounds; inside them it has no useful bound.
            float gap = boxDistance(region, nodes[m].bounds);
            if (gap == 0.0f || gap <= upper) items.push_back(m);
        }
        ranges.push_back(uint32_t(items.size()));
    }
}

} // namespace sdfcsg::detail
