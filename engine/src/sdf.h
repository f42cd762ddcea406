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
using glm::atan, glm::cos, glm::floor, glm::mod, glm::sin, glm::sqrt;
using glm::vec2, glm::vec3, glm::vec4;
using std::sqrt;
using uint = uint32_t;

#define SDF_FN inline
#include "../../shaders/sdf.glsl"
#undef SDF_FN

using sdfcsg::Params;

// Every kind's bit, for sdPrimitive's `kinds`.
inline constexpr uint kAllKinds = ~0u;

inline Params kernelParams(NodeKind kind, const Params& v) {
    const KindInfo& info = kindInfo(kind);
    return info.kernel ? info.kernel(v) : Params{v[0], v[1]}; // operations: smooth, blend
}

// Local distance of a primitive, given its kernel parameters.
inline float evalPrimitive(NodeKind kind, vec3 p, const Params& k) {
    return sdPrimitive(uint(kind), p, vec4(k[0], k[1], k[2], k[3]), vec4(k[4], k[5], k[6], k[7]),
                       kAllKinds);
}

// Exact local bounding box of a primitive: lo/hi corners; false for the (unbounded) plane.
inline bool localBounds(NodeKind kind, const Params& k, vec3& lo, vec3& hi) {
    const KindInfo& info = kindInfo(kind);
    return info.bounds && info.bounds(k, lo, hi);
}

} // namespace sdfcsg::sdf
