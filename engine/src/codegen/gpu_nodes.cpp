#include "codegen/gpu_nodes.h"

#include "shared.h"

#include <algorithm>
#include <cstring>

namespace sdfcsg::detail {

namespace {

// Infinite bounds become +-SDFCSG_HUGE: boundsDistance() then still gives 0 inside them
// without inf - inf arithmetic on the GPU.
glm::vec3 clampHuge(glm::vec3 v) {
    constexpr float huge = float(SDFCSG_HUGE);
    return glm::clamp(v, glm::vec3(-huge), glm::vec3(huge));
}

} // namespace

std::vector<GpuNode> packNodes(const Evaluator& evaluator) {
    std::vector<GpuNode> out;
    out.reserve(evaluator.nodes().size());
    for (const FlatNode& n : evaluator.nodes()) {
        GpuNode g;
        const glm::mat3& m = n.toLocal; // column-major: m[column][row]
        g.row0 = glm::vec4(m[0][0], m[1][0], m[2][0], n.offset.x);
        g.row1 = glm::vec4(m[0][1], m[1][1], m[2][1], n.offset.y);
        g.row2 = glm::vec4(m[0][2], m[1][2], m[2][2], n.offset.z);
        g.p0 = glm::vec4(n.params[0], n.params[1], n.params[2], n.params[3]);
        g.p1 = glm::vec4(n.params[4], n.params[5], n.params[6], n.params[7]);
        g.color = glm::vec4(n.color, n.scale);
        // Primitives: w is 1 where the value is floored at the bounds (FlatNode::boundsFloor).
        const bool primitive = kindInfo(n.kind).role == Role::Primitive;
        g.bmin = glm::vec4(clampHuge(n.bounds.min),
                           primitive ? (n.boundsFloor ? 1.0f : 0.0f) : n.smooth);
        // Domain operations: w holds their child's index, whose bounds the tape machine reads.
        const bool domain = kindInfo(n.kind).role == Role::Domain;
        g.bmax = glm::vec4(clampHuge(n.bounds.max), domain ? float(n.children[0]) : float(n.blend));
        out.push_back(g);
    }
    // Node words (outlines, images) after the nodes, 8 vec4 to a node's room; their first record
    // (slot 0) becomes its index in the buffer seen as vec4s (sdf.glsl, nodeWords).
    std::vector<glm::vec4> words;
    for (size_t i = 0; i < evaluator.nodes().size(); ++i) {
        const FlatNode& n = evaluator.nodes()[i];
        if (!n.words) continue;
        out[i].p0.x = float(out.size() * 8 + words.size());
        words.insert(words.end(), n.words->begin(), n.words->end());
    }
    words.resize((words.size() + 7) / 8 * 8, glm::vec4(0.0f));
    for (size_t k = 0; k < words.size(); k += 8) {
        GpuNode g;
        std::memcpy(&g, &words[k], sizeof g);
        out.push_back(g);
    }
    return out;
}

} // namespace sdfcsg::detail
