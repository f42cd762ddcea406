#version 450
// The passes of the ray march that do not evaluate the scene (shaders/raymarch.glsl): the
// overlays over shaded hits and the resolve of several samples per pixel; kPass picks one.
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "nodes.glsl"
#include "raymarch.glsl"

layout(constant_id = SDFCSG_SPEC_RAYMARCH_PASS) const uint kPass = SDFCSG_RAYMARCH_PASS_RESOLVE;

void resolvePass() {
    uvec2 pixel = gl_GlobalInvocationID.xy + uvec2(0u, band.firstRow);
    if (any(greaterThanEqual(pixel, frame.size.xy))) return;
    uint aa = max(frame.counts.x, 1u);
    uint row = frame.size.x * aa;
    uint first = gl_GlobalInvocationID.y * aa * row + gl_GlobalInvocationID.x * aa;
    vec3 sum = vec3(0.0);
    for (uint sy = 0u; sy < aa; ++sy)
        for (uint sx = 0u; sx < aa; ++sx)
            sum += unpackColor(colors[first + sy * row + sx]);
    pixels[pixel.y * frame.size.x + pixel.x] = packColor(sum / float(aa * aa));
}

void overlayPass() {
    uint slot = gl_WorkGroupID.x * (SDFCSG_RAYMARCH_GROUP_X * SDFCSG_RAYMARCH_GROUP_Y) +
                gl_LocalInvocationIndex;
    if (slot >= count) return;
    uvec2 hit = hits[slot];
    uvec2 pixel;
    vec3 rd;
    sampleRay(hit.x, pixel, rd);
    uint i = band.colorOffset + hit.x;
    colors[i] = finish(unpackColor(colors[i]), frame.eye.xyz, rd, uintBitsToFloat(hit.y));
}

void main() {
    if (kPass == SDFCSG_RAYMARCH_PASS_RESOLVE) resolvePass();
    else overlayPass();
}
