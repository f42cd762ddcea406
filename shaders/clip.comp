#version 450
// The clip and sort passes of the ray march (shaders/raymarch.glsl), one invocation per sample
// of the listed workgroups each: before the march pass, the part of its ray to trace; after it,
// what becomes of the sample. They do not depend on the scene, so out of the march kernel, which
// every new scene compiles, they are compiled once per context.
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "raymarch.glsl"

layout(constant_id = SDFCSG_SPEC_RAYMARCH_PASS) const uint kPass = SDFCSG_RAYMARCH_PASS_CLIP;

void clipPass() {
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

// The march pass left the ray parameter of the hit (negative: a miss) and its steps in the
// sample's range: the pixel's info from its first sample, then a hit to shade goes on the list
// with its ray, any other sample gets its colour.
void sortPass() {
    uvec2 s;
    uint sampleIndex;
    if (!tileSample(s, sampleIndex)) return;
    uint aa = max(control.counts.x, 1u);
    vec3 rd = ranges[2u * sampleIndex].xyz;
    vec2 marched = ranges[2u * sampleIndex + 1u].xy;
    Trace r = Trace(marched.x, uint(marched.y), vec3(0.0), 1.0, vec4(1.0));
    uvec2 pixel = uvec2((vec2(s) + 0.5) / float(aa)); // in the band, as sampleRay() finds it
    if (all(equal(s, pixel * aa))) // the pixel's first sample
        info[(pixel.y + band.firstRow) * control.size.x + pixel.x] = marched;
    if (needsShading(r)) {
        uint slot = atomicAdd(count, 1u);
        if (slot % (SDFCSG_RAYMARCH_GROUP_X * SDFCSG_RAYMARCH_GROUP_Y) == 0u) atomicAdd(groups, 1u);
        hits[slot] = uvec2(sampleIndex, floatBitsToUint(r.t));
        surfaces[4u * slot + 1u] = vec4(rd, r.t);
    } else {
        colors[band.colorOffset + sampleIndex] = packColor(plainColor(r));
    }
}

void main() {
    if (kPass == SDFCSG_RAYMARCH_PASS_CLIP) clipPass();
    else sortPass();
}
