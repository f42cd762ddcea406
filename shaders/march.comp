#version 450
// The march pass of the ray march (shaders/raymarch.glsl): one invocation per sample of the
// listed workgroups traces its ray to the first hit.
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "sdf.glsl"
#include "nodes.glsl"
#include "raymarch.glsl"
#include "scene.glsl"

// The march pass: the first hit along the ray, clipped to the boxes that hold surfaces.
Trace march(vec3 ro, vec3 rd) {
    Trace r = Trace(-1.0, 0u, vec3(0.0), 1.0, vec4(1.0));
    vec2 range = clipRay(frame.clipMin.xyz, frame.clipMax.xyz, ro, rd);
    // Control values that loops use are read before them: on CPU drivers a storage buffer
    // load in a loop stays there, a bounds check and a load in every iteration.
    uint partCount = control.parts.x;
    if (partCount > 0u) {
        // Start at the first entry into a box that holds surfaces, end at the last exit.
        vec2 parts = vec2(1.0e30, -1.0e30);
        for (uint i = 0u; i < partCount; ++i) {
            vec2 b = partInterval(i, ro, rd);
            if (b.x <= b.y) parts = vec2(min(parts.x, b.x), max(parts.y, b.y));
        }
        range = vec2(max(range.x, parts.x), min(range.y, parts.y));
    }
    float tFar = min(range.y, frame.clipMin.w);
    float t = range.x;
    bool marching = t <= tFar;
    while (marching) {
        float d = sceneDistance(ro + rd * t);
        r.steps += 1u;
        if (d < hitEpsilon(t)) {
            r.t = t;
            marching = false;
        } else {
            t += d;
            marching = t <= tFar && r.steps < SDFCSG_MAX_STEPS;
        }
    }
    return r;
}

void marchPass() {
    uint aa = max(control.counts.x, 1u);
    uint tile = tiles[gl_WorkGroupID.x];
    uvec2 s = uvec2(tile & 0xffffu, tile >> 16) * gl_WorkGroupSize.xy + gl_LocalInvocationID.xy;
    if (s.x >= control.size.x * aa || s.y >= (control.size.y - band.firstRow) * aa) return;
    uint sampleIndex = s.y * control.size.x * aa + s.x;
    uvec2 pixel;
    vec3 rd;
    sampleRay(s, pixel, rd);
    vec3 ro = frame.eye.xyz;
    Trace r = march(ro, rd);
    if (all(equal(s, (pixel - uvec2(0u, band.firstRow)) * aa))) // the pixel's first sample
        info[pixel.y * control.size.x + pixel.x] = vec2(r.t, float(r.steps));
    if (needsShading(r)) {
        uint slot = atomicAdd(count, 1u);
        if (slot % (SDFCSG_RAYMARCH_GROUP_X * SDFCSG_RAYMARCH_GROUP_Y) == 0u) atomicAdd(groups, 1u);
        hits[slot] = uvec2(sampleIndex, floatBitsToUint(r.t));
    } else {
        colors[band.colorOffset + sampleIndex] = packColor(plainColor(r));
    }
}

void main() { marchPass(); }
