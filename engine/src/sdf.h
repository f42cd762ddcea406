// The SDF function library in C++: shaders/sdf.glsl line by line, with GLM standing in for GLSL
// (distance functions after Inigo Quilez, https://iquilezles.org/articles/distfunctions/). Keep
// the two files in step; tests/unit/test_primitives.cpp checks these against true distances and
// the GPU tests check the shader against these.
#pragma once

#include "sdfcsg/nodes.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <cmath>

namespace sdfcsg::sdf {

using glm::abs, glm::clamp, glm::dot, glm::length, glm::max, glm::min, glm::mix, glm::sign;
using glm::vec2, glm::vec3, glm::vec4;
using std::sqrt;

inline float dot2(vec2 v) {
    return dot(v, v);
}
inline float dot2(vec3 v) {
    return dot(v, v);
}

inline float sdSphere(vec3 p, float r) {
    return length(p) - r;
}

inline float sdBox(vec3 p, vec3 b) {
    vec3 q = abs(p) - b;
    return length(max(q, 0.0f)) + min(max(q.x, max(q.y, q.z)), 0.0f);
}

inline float sdRoundBox(vec3 p, vec3 b, float r) {
    vec3 q = abs(p) - b + r;
    return length(max(q, 0.0f)) + min(max(q.x, max(q.y, q.z)), 0.0f) - r;
}

inline float sdPlane(vec3 p, vec3 n, float offset) {
    return dot(p, n) - offset;
}

inline float sdTriangularPrism(vec3 p, float hw, float h, float hl) {
    vec2 q = vec2(hw, h);
    vec2 t = vec2(abs(p.x), 0.5f * h - p.y);
    vec2 a = t - q * clamp(dot(t, q) / dot(q, q), 0.0f, 1.0f);
    vec2 b = t - q * vec2(clamp(t.x / q.x, 0.0f, 1.0f), 1.0f);
    vec2 d = min(vec2(dot(a, a), -(t.x * q.y - t.y * q.x)), vec2(dot(b, b), -(t.y - q.y)));
    float d2 = -sqrt(d.x) * sign(d.y);
    vec2 w = vec2(d2, abs(p.z) - hl);
    return min(max(w.x, w.y), 0.0f) + length(max(w, 0.0f));
}

inline float sdTorus(vec3 p, float major, float minor) {
    vec2 q = vec2(length(vec2(p.x, p.z)) - major, p.y);
    return length(q) - minor;
}

inline float sdCylinder(vec3 p, float r, float hh) {
    vec2 d = abs(vec2(length(vec2(p.x, p.z)), p.y)) - vec2(r, hh);
    return min(max(d.x, d.y), 0.0f) + length(max(d, 0.0f));
}

inline float sdCone(vec3 p, float r1, float hh, float r2) {
    vec2 q = vec2(length(vec2(p.x, p.z)), p.y);
    vec2 k1 = vec2(r2, hh);
    vec2 k2 = vec2(r2 - r1, 2.0f * hh);
    vec2 ca = vec2(q.x - min(q.x, (q.y < 0.0f) ? r1 : r2), abs(q.y) - hh);
    vec2 cb = q - k1 + k2 * clamp(dot(k1 - q, k2) / dot2(k2), 0.0f, 1.0f);
    float s = (cb.x < 0.0f && ca.y < 0.0f) ? -1.0f : 1.0f;
    return s * sqrt(min(dot2(ca), dot2(cb)));
}

inline float sdCapsule(vec3 p, vec3 a, vec3 b, float r) {
    vec3 pa = p - a, ba = b - a;
    float h = clamp(dot(pa, ba) / max(dot(ba, ba), 1e-30f), 0.0f, 1.0f);
    return length(pa - ba * h) - r;
}

inline float opUnion(float a, float b, float k) {
    float h = clamp(0.5f + 0.5f * (b - a) / max(k, 1e-30f), 0.0f, 1.0f);
    float blend = mix(b, a, h) - k * h * (1.0f - h);
    float r = (a - b >= k) ? b : blend;
    return (b - a >= k) ? a : r;
}

inline float opIntersection(float a, float b, float k) {
    float h = clamp(0.5f - 0.5f * (b - a) / max(k, 1e-30f), 0.0f, 1.0f);
    float blend = mix(b, a, h) + k * h * (1.0f - h);
    float r = (b - a >= k) ? b : blend;
    return (a - b >= k) ? a : r;
}

inline float opDifference(float a, float b, float k) {
    return opIntersection(a, -b, k);
}

inline vec4 opUnion(vec4 a, vec4 b, float k) {
    float h = clamp(0.5f + 0.5f * (b.w - a.w) / max(k, 1e-30f), 0.0f, 1.0f);
    vec4 blend = vec4(mix(vec3(b), vec3(a), h), mix(b.w, a.w, h) - k * h * (1.0f - h));
    vec4 r = (a.w - b.w >= k) ? b : blend;
    return (b.w - a.w >= k) ? a : r;
}

inline vec4 opIntersection(vec4 a, vec4 b, float k) {
    float h = clamp(0.5f - 0.5f * (b.w - a.w) / max(k, 1e-30f), 0.0f, 1.0f);
    vec4 blend = vec4(mix(vec3(b), vec3(a), h), mix(b.w, a.w, h) + k * h * (1.0f - h));
    vec4 r = (b.w - a.w >= k) ? b : blend;
    return (a.w - b.w >= k) ? a : r;
}

inline vec4 opDifference(vec4 a, vec4 b, float k) {
    return opIntersection(a, vec4(vec3(b), -b.w), k);
}

// The operators at k = 0 (sdf.glsl's sharp*, which generated code with literal values uses):
// bit for bit opUnion(a, b, 0) and the others, in one comparison.
inline float sharpUnion(float a, float b) { return a <= b ? a : b; }
inline float sharpIntersection(float a, float b) { return a >= b ? a : b; }
inline float sharpDifference(float a, float b) { return a >= -b ? a : -b; }
inline vec4 sharpUnion(vec4 a, vec4 b) { return a.w <= b.w ? a : b; }
inline vec4 sharpIntersection(vec4 a, vec4 b) { return a.w >= b.w ? a : b; }
inline vec4 sharpDifference(vec4 a, vec4 b) { return a.w >= -b.w ? a : vec4(vec3(b), -b.w); }

// ---- Kernel parameters ----
// What a primitive's kernel takes, derived once from the table's values (Node::params) so that
// the shader does no arithmetic on them. packNodes() copies these into the node buffer
// (slots 0..3 -> p0, 4..7 -> p1) and the code generator reads them from the same slots.
//   sphere            r
//   box               half extents xyz
//   round_box         half extents xyz, radius (clamped to the smallest half extent)
//   plane             unit normal xyz, offset
//   triangular_prism  half width, height, half length
//   torus             major, minor
//   cylinder          radius, half height
//   cone              bottom radius, half height, top radius
//   capsule           a xyz, radius, b xyz
using Params = std::array<float, kMaxParams>;

inline Params kernelParams(NodeKind kind, const Params& v) {
    switch (kind) {
    case NodeKind::Sphere:
        return {v[0]};
    case NodeKind::Box:
        return {0.5f * v[0], 0.5f * v[1], 0.5f * v[2]};
    case NodeKind::RoundBox: {
        vec3 b = 0.5f * vec3(v[0], v[1], v[2]);
        return {b.x, b.y, b.z, min(v[3], min(b.x, min(b.y, b.z)))};
    }
    case NodeKind::Plane: {
        vec3 n = vec3(v[0], v[1], v[2]);
        float len = length(n);
        n = len > 0.0f ? n / len : vec3(0.0f, 1.0f, 0.0f);
        return {n.x, n.y, n.z, v[3]};
    }
    case NodeKind::TriangularPrism:
        return {0.5f * v[0], v[1], 0.5f * v[2]};
    case NodeKind::Torus:
        return {v[0], v[1]};
    case NodeKind::Cylinder:
        return {v[0], 0.5f * v[1]};
    case NodeKind::Cone:
        return {v[0], 0.5f * v[1], v[2]};
    case NodeKind::Capsule:
        return {v[0], v[1], v[2], v[6], v[3], v[4], v[5]};
    default:
        return {v[0]}; // operations: the smooth radius, in their local units
    }
}

// Local distance of a primitive, given its kernel parameters.
inline float evalPrimitive(NodeKind kind, vec3 p, const Params& k) {
    switch (kind) {
    case NodeKind::Sphere:
        return sdSphere(p, k[0]);
    case NodeKind::Box:
        return sdBox(p, vec3(k[0], k[1], k[2]));
    case NodeKind::RoundBox:
        return sdRoundBox(p, vec3(k[0], k[1], k[2]), k[3]);
    case NodeKind::Plane:
        return sdPlane(p, vec3(k[0], k[1], k[2]), k[3]);
    case NodeKind::TriangularPrism:
        return sdTriangularPrism(p, k[0], k[1], k[2]);
    case NodeKind::Torus:
        return sdTorus(p, k[0], k[1]);
    case NodeKind::Cylinder:
        return sdCylinder(p, k[0], k[1]);
    case NodeKind::Cone:
        return sdCone(p, k[0], k[1], k[2]);
    case NodeKind::Capsule:
        return sdCapsule(p, vec3(k[0], k[1], k[2]), vec3(k[4], k[5], k[6]), k[3]);
    default:
        return 0.0f;
    }
}

// Exact local bounding box of a primitive: lo/hi corners; false for the (unbounded) plane.
inline bool localBounds(NodeKind kind, const Params& k, vec3& lo, vec3& hi) {
    switch (kind) {
    case NodeKind::Sphere:
        hi = vec3(k[0]);
        break;
    case NodeKind::Box:
    case NodeKind::RoundBox:
        hi = vec3(k[0], k[1], k[2]);
        break;
    case NodeKind::Plane:
        return false;
    case NodeKind::TriangularPrism:
        hi = vec3(k[0], 0.5f * k[1], k[2]);
        break;
    case NodeKind::Torus:
        hi = vec3(k[0] + k[1], k[1], k[0] + k[1]);
        break;
    case NodeKind::Cylinder:
        hi = vec3(k[0], k[1], k[0]);
        break;
    case NodeKind::Cone:
        hi = vec3(max(k[0], k[2]), k[1], max(k[0], k[2]));
        break;
    case NodeKind::Capsule: {
        vec3 a(k[0], k[1], k[2]), b(k[4], k[5], k[6]);
        lo = min(a, b) - k[3];
        hi = max(a, b) + k[3];
        return true;
    }
    default:
        return false;
    }
    lo = -hi;
    return true;
}

} // namespace sdfcsg::sdf
