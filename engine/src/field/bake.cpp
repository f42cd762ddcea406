// Baked offsets and shells (bake.h).
#include "field/bake.h"

#include "field/mesh_field.h"
#include "field/prune.h"
#include "sdfcsg/eval.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

namespace sdfcsg::detail {

namespace {

// A loss above this is not a distance (eval.cpp's kExactLoss).
constexpr float kExactLoss = 1.001f;
// The finest cell, as a fraction of the distance (bake.h).
constexpr float kCellsPerDistance = 16.0f;

// Whether node c's subtree shows more than c's own colour: a leaf of another colour, or one with
// colours of its own. Then the baked field keeps the colour of the surface nearest each sample.
bool severalColors(const Evaluator& e, uint32_t c) {
    const std::vector<FlatNode>& nodes = e.nodes();
    std::vector<uint32_t> open{c};
    while (!open.empty()) {
        const FlatNode& n = nodes[open.back()];
        open.pop_back();
        if (n.children.empty() && (n.ownColors || n.color != nodes[c].color)) return true;
        open.insert(open.end(), n.children.begin(), n.children.end());
    }
    return false;
}

// The nodes of node c's subtree, up to `limit` + 1.
size_t subtreeSize(const Scene& scene, uint32_t c, size_t limit) {
    size_t count = 0;
    std::vector<uint32_t> open{c};
    while (!open.empty() && count <= limit) {
        const Node& n = scene.nodes[open.back()];
        open.pop_back();
        ++count;
        open.insert(open.end(), n.children.begin(), n.children.end());
    }
    return count;
}

} // namespace

void bakeOffsets(Scene& scene) {
    size_t used = 0; // the scene's other words, in vec4s
    for (Node& n : scene.nodes) {
        if (kindInfo(n.kind).role == Role::Value) n.words.reset();
        if (n.words) used += n.words->size();
    }
    std::optional<Evaluator> e; // made again after each bake, which changes what is above it
    for (size_t i = scene.nodes.size(); i-- > 0;) {
        Node& n = scene.nodes[i];
        if (kindInfo(n.kind).role != Role::Value || n.children.size() != 1 ||
            n.params[kAccuracySlot] != kAccuracyExact)
            continue;
        if (!e) e.emplace(scene);
        const uint32_t c = n.children[0];
        const FlatNode& child = e->nodes()[c];
        const float amount = std::abs(e->nodes()[i].params[0]); // in the frame's units
        const Aabb box = child.bounds;
        if (!(child.loss > kExactLoss) || !box.finite() || box.empty() || !(amount > 0.0f) ||
            !std::isfinite(amount) || subtreeSize(scene, c, kMaxBakedNodes) > kMaxBakedNodes)
            continue;
        if (used + 2 >= kMaxOutlineWords) break;
        const size_t budget = std::min(kMaxBakeBytes, (kMaxOutlineWords - used - 2) * 16);
        const Evaluator& at = *e;
        const auto value = [&](glm::vec3 p) { return subtreeValue(at, c, p); };
        std::function<glm::vec3(glm::vec3)> color;
        if (severalColors(at, c)) color = [&](glm::vec3 p) { return subtreeColor(at, c, p); };
        // The finest cell that fits, with the colours where the child has several; else without
        // them (the child's colour alone), which halves the field.
        std::optional<MeshField> field;
        for (int pass = color ? 0 : 1; pass < 2 && !field; ++pass)
            for (float cell = amount / kCellsPerDistance; !field && cell <= amount / 4.0f * 1.0001f;
                 cell *= 1.25f)
                if (auto made = MeshField::fromField(value, pass == 0 ? color : nullptr, box.min,
                                                     box.max, cell, amount + 2.0f * cell, budget))
                    field = std::move(*made);
        if (!field) continue;
        std::vector<glm::vec4> words = field->words();
        // After sdMesh's words, as a mesh node's (buildMesh): the box the surface lies in, for
        // the bounds, and no defects.
        words.push_back(glm::vec4(box.max - box.min, box.min.x - field->origin().x));
        words.push_back(defectsWord({}));
        used += words.size();
        n.words = std::make_shared<const std::vector<glm::vec4>>(std::move(words));
        e.reset();
    }
}

const Scene& bakedView(const Scene& scene, Scene& storage) {
    if (std::none_of(scene.nodes.begin(), scene.nodes.end(), baked)) return scene;
    storage = scene;
    for (const Node& n : scene.nodes)
        if (baked(n)) {
            Node& child = storage.nodes[n.children[0]];
            child.kind = NodeKind::Mesh;
            child.children.clear();
            child.words = n.words;
        }
    return storage;
}

} // namespace sdfcsg::detail
