// The node buffer's layout: one GpuNode per scene node, index-aligned, read by the generated scene
// code (the inlined scene code holds the same values as literals). SceneBuffers uploads it.
#pragma once

#include "sdfcsg/eval.h"

#include <glm/vec4.hpp>

#include <vector>

namespace sdfcsg::detail {

// std430 layout of `struct Node` in shaders/nodes.glsl; keep the two in step. A primitive has no
// blend radius: its bmin.w is 1 where its value is floored at its bounds (FlatNode::boundsFloor).
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

} // namespace sdfcsg::detail
