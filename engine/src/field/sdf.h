// The SDF function library in C++: shaders/sdf.glsl itself, compiled with GLM standing in for
// GLSL, so that the CPU evaluator runs the formulas the kernels run. tests/unit/test_primitives.cpp
// checks them against true distances and the GPU tests check the kernels against them.
#pragma once

#include "sdfcsg/nodes.h"

#include <glm/common.hpp>
#include <glm/exponential.hpp>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cmath>
#include <cstdint>

namespace sdfcsg::sdf {

using glm::abs, glm::clamp, glm::dot, glm::length, glm::max, glm::min, glm::mix, glm::sign;
using glm::acos, glm::atan, glm::cos, glm::floor, glm::mod, glm::pow, glm::sin, glm::sqrt;
using glm::vec2, glm::vec3, glm::vec4;
using std::sqrt;
using uint = uint32_t;

#define SDF_FN inline
#define SDF_DATA(i) sdfData[i]
#define SDF_DATA_PARAM , const vec4* sdfData
#define SDF_DATA_ARG , sdfData
#include "../../shaders/sdf.glsl"
#undef SDF_FN
#undef SDF_DATA
#undef SDF_DATA_PARAM
#undef SDF_DATA_ARG

// kinds.glsl, which sdf.glsl includes, is written by the build from the same list as NodeKind.
#define SDFCSG_KIND_CHECK(name)                                                                    \
    static_assert(kKind##name == uint(NodeKind::name), "kinds.glsl is out of date");
SDFCSG_NODE_KINDS(SDFCSG_KIND_CHECK)
#undef SDFCSG_KIND_CHECK
static_assert(kKindFirstOperation == uint(kFirstOperation) && kKindCount == uint(kNodeKindCount));
// sdPrimitive's `kinds` holds a bit for each kind of primitive and profile.
static_assert(uint(kFirstOperation) <= 32u,
              "more than 32 primitive and profile kinds: widen the kinds mask of sdPrimitive "
              "(shaders/sdf.glsl) and of SDFCSG_TAPE_KINDS (engine/src/codegen/codegen.cpp)");

using sdfcsg::Params;

// Every kind's bit, for sdPrimitive's `kinds`.
inline constexpr uint kAllKinds = ~0u;

inline Params kernelParams(NodeKind kind, const Params& v) {
    const KindInfo& info = kindInfo(kind);
    return info.kernel ? info.kernel(v) : Params{v[0], v[1]}; // operations: smooth, blend
}

// Local distance of a primitive, given its kernel parameters and, for the kinds with words
// (polygon, text, image), those words (FlatNode::words).
inline float evalPrimitive(NodeKind kind, vec3 p, const Params& k, const vec4* words = nullptr) {
    if (hasWords(kind) && !words) return 1e30f; // built in code without its words
    return sdPrimitive(uint(kind), p, vec4(k[0], k[1], k[2], k[3]), vec4(k[4], k[5], k[6], k[7]),
                       kAllKinds, words);
}

// Exact local bounding box of a primitive: lo/hi corners; false for the (unbounded) plane.
inline bool localBounds(NodeKind kind, const Params& k, vec3& lo, vec3& hi) {
    const KindInfo& info = kindInfo(kind);
    return info.bounds && info.bounds(k, lo, hi);
}

} // namespace sdfcsg::sdf
