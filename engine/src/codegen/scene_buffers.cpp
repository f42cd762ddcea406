#include "codegen/scene_buffers.h"

#include "field/prune.h"
#include "shared.h"

#include <string>

namespace sdfcsg::detail {

namespace {

// A header alone: a field that no kernel evaluates.
std::vector<uint32_t> emptyField() {
    return std::vector<uint32_t>(kFieldHeaderWords, 0u);
}

Error prunesTooLittle(const Scene& scene, double mean) {
    return Error(ErrorKind::Limit,
                 Diagnostic{scene.file, "root",
                            "the tree prunes too little to render or mesh in bounded time: near "
                            "its surface, a region evaluates " +
                                std::to_string(uint32_t(mean)) +
                                " instructions on average, above the limit of " +
                                std::to_string(kMaxMeanCellInstructions) +
                                " (many primitives that all overlap in one smooth operation do "
                                "this)"});
}

} // namespace

SceneBuffers::~SceneBuffers() {
    destroyBuffer(ctx_, nodes_);
    destroyBuffer(ctx_, field_);
}

Result<std::vector<uint32_t>> SceneBuffers::fieldWords(const Scene& scene,
                                                       const Evaluator& evaluator,
                                                       Evaluation evaluation, bool keep) {
    if (!usesTapes(scene, evaluation)) return emptyField();
    PrunedField made;
    const PrunedField& field = keep ? prunedField(evaluator) : (made = pruneField(evaluator));
    if (const double mean = field.meanActiveLength(); mean > kMaxMeanCellInstructions)
        return prunesTooLittle(scene, mean);
    return packField(field, evaluator.nodes());
}

Status SceneBuffers::create(const Evaluator& evaluator) {
    const std::vector<GpuNode> packed = packNodes(evaluator);
    auto nodes = createBuffer(ctx_, packed.size() * sizeof(GpuNode),
                              VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::Upload);
    if (!nodes) return nodes.error();
    destroyBuffer(ctx_, nodes_);
    nodes_ = *nodes;
    uploadBuffer(ctx_, nodes_, packed.data(), packed.size() * sizeof(GpuNode));
    if (auto made = uploadField(emptyField()); !made) return made.error();
    return Ok{};
}

void SceneBuffers::uploadNodes(const Evaluator& evaluator) {
    const std::vector<GpuNode> packed = packNodes(evaluator);
    uploadBuffer(ctx_, nodes_, packed.data(), packed.size() * sizeof(GpuNode));
}

Result<bool> SceneBuffers::uploadField(std::span<const uint32_t> words) {
    const VkDeviceSize bytes = words.size() * sizeof(uint32_t);
    bool made = false;
    if (!field_.buffer || field_.size < bytes) {
        auto grown =
            createBuffer(ctx_, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::Upload);
        if (!grown) return grown.error();
        destroyBuffer(ctx_, field_);
        field_ = *grown;
        made = true;
    }
    uploadBuffer(ctx_, field_, words.data(), size_t(bytes));
    return made;
}

} // namespace sdfcsg::detail
