// The scene's data as every kernel binds it, prepared in one direction: the node buffer
// (binding SDFCSG_BINDING_NODES, in packNodes()' layout) and the pruned field (binding
// SDFCSG_BINDING_FIELD, from field/prune.h), each packed on the host and uploaded here. The
// renderer and the mesher each hold one; neither packs, prunes nor uploads these itself.
#pragma once

#include "codegen/gpu_nodes.h"
#include "gpu/vk.h"
#include "sdfcsg/compile.h"
#include "sdfcsg/eval.h"

#include <span>
#include <vector>

namespace sdfcsg::detail {

class SceneBuffers {
  public:
    // `ctx` must outlive the buffers.
    explicit SceneBuffers(Context::Impl& ctx) : ctx_(ctx) {}
    ~SceneBuffers();
    SceneBuffers(const SceneBuffers&) = delete;
    SceneBuffers& operator=(const SceneBuffers&) = delete;

    // What shaders/tape.glsl reads: the scene's pruned field where its kernels run tapes
    // (refused past kMaxMeanCellInstructions), a header alone otherwise (the binding must still
    // hold a buffer). Host work only, on no buffer, so it may run on another thread while the
    // kernels build: they do not depend on it. With `keep`, the evaluator keeps the prune for its
    // own prunedDistance (detail::prunedField: the mesher's host steps); without, it is freed.
    static Result<std::vector<uint32_t>> fieldWords(const Scene& scene, const Evaluator& evaluator,
                                                    Evaluation evaluation, bool keep = false);

    // Makes the node buffer for the evaluator's nodes and uploads them, and a field that no
    // kernel evaluates yet (a header alone: the kernels' warm-ups run no invocation), so that
    // every binding holds a buffer before the field is pruned.
    Status create(const Evaluator& evaluator);
    // New values for the nodes of a scene of the same structure (sameStructure()).
    void uploadNodes(const Evaluator& evaluator);
    // The words of fieldWords(), growing the field's buffer when they no longer fit; true when
    // it made a new one, whose descriptors the caller then writes again.
    Result<bool> uploadField(std::span<const uint32_t> words);

    const Buffer& nodes() const { return nodes_; }
    const Buffer& field() const { return field_; }
    uint64_t heldBytes() const { return nodes_.size + field_.size; }

  private:
    Context::Impl& ctx_;
    Buffer nodes_, field_;
};

} // namespace sdfcsg::detail
