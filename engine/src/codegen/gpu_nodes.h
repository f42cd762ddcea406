// The node buffer: one GpuNode per scene node, index-aligned, read by the generated scene code.
#pragma once

#include "gpu/vk.h"
#include "sdfcsg/compile.h"
#include "sdfcsg/eval.h"

#include <glm/vec4.hpp>

#include <span>
#include <vector>

namespace sdfcsg::detail {

// std430 layout of `struct Node` in shaders/nodes.glsl; keep the two in step.
struct GpuNode {
    glm::vec4 row0, row1, row2; // world -> local affine rows: local.x = dot(row0, vec4(p, 1))
    glm::vec4 p0, p1;           // kernel parameters, slots 0..3 and 4..7 (sdf::kernelParams)
    glm::vec4 color;            // rgb resolved colour; w accumulated scale
    glm::vec4 bmin;             // xyz world bounds minimum (-SDFCSG_HUGE if unbounded); w smooth
    glm::vec4 bmax;             // xyz world bounds maximum (+SDFCSG_HUGE if unbounded); w blend
};
static_assert(sizeof(GpuNode) == 128, "GpuNode must match the std430 Node in nodes.glsl");

// Everything numeric the shaders need, so that changing values needs only a re-upload.
std::vector<GpuNode> packNodes(const Evaluator& evaluator);

// What shaders/tape.glsl reads (binding SDFCSG_BINDING_FIELD): the scene's pruned field where
// its kernels run tapes (refused past kMaxMeanCellInstructions), a header alone otherwise (the
// binding must still hold a buffer). Host work only, so it may run while the kernels build:
// they do not depend on it.
Result<std::vector<uint32_t>> fieldWords(const Scene& scene, const Evaluator& evaluator,
                                         Evaluation evaluation);
// A header alone: a field that no kernel evaluates yet (their warm-ups run no invocation).
std::vector<uint32_t> emptyField();

// Grows `buffer` when the words no longer fit and uploads them; returns true when it made a new
// one, whose descriptors the caller then writes again.
Result<bool> uploadField(Context::Impl& ctx, Buffer& buffer, std::span<const uint32_t> words);

} // namespace sdfcsg::detail
