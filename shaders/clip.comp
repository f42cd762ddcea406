#version 450
// The clip pass of the ray march (shaders/raymarch.glsl): one invocation per sample of the
// listed workgroups finds the part of its ray that the march pass traces. It does not depend on
// the scene, so out of the march kernel, which every new scene compiles, it is compiled once
// per context.
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "raymarch.glsl"

void main() {
    uvec2 s;
    uint sampleIndex;
    if (!tileSample(s, sampleIndex)) return;
    uvec2 pixel;
    vec3 rd;
    sampleRay(s, pixel, rd);
    vec3 ro = frame.eye.xyz;
    vec3 inv = safeInverse(rd);
    vec2 range = clipRayInverse(frame.clipMin.xyz, frame.clipMax.xyz, ro, inv);
    // Control values that loops use are read before them: on CPU drivers a storage buffer load
    // in a loop stays there, a bounds check and a load in every iteration.
    uint partCount = control.parts.x;
    if (partCount > 0u) {
        // Start at the first entry into a box that holds surfaces, end at the last exit.
        vec2 parts = vec2(1.0e30, -1.0e30);
        for (uint i = 0u; i < partCount; ++i) {
            vec2 b = partInterval(i, ro, rd, inv);
            if (b.x <= b.y) parts = vec2(min(parts.x, b.x), max(parts.y, b.y));
        }
        range = vec2(max(range.x, parts.x), min(range.y, parts.y));
    }
    ranges[2u * sampleIndex] = vec4(rd, range.x);
    ranges[2u * sampleIndex + 1u].x = min(range.y, frame.clipMin.w);
}
