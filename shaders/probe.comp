#version 450
// Evaluates the scene at given points: output i = sceneSample(points[i].xyz) (rgb colour,
// distance in w). The GPU tests compare it with the CPU evaluator (engine/src/field/eval.cpp).
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "sdf.glsl"
#include "nodes.glsl"
#include "scene.glsl"

layout(local_size_x = SDFCSG_PROBE_GROUP_X) in;

layout(std430, set = 0, binding = SDFCSG_BINDING_PROBE_IN) readonly buffer ProbeIn {
    vec4 points[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_PROBE_OUT) writeonly buffer ProbeOut {
    vec4 samples[];
};

layout(push_constant) uniform Push {
    uint count;
} push;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count) return;
    samples[i] = sceneSample(points[i].xyz);
}
