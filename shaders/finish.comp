#version 450
// The passes of the ray march that do not evaluate the scene (shaders/raymarch.glsl): the
// resolve of several samples per pixel and the overlays; kPass picks one.
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "nodes.glsl"
#include "raymarch.glsl"

layout(constant_id = SDFCSG_SPEC_RAYMARCH_PASS) const uint kPass = SDFCSG_RAYMARCH_PASS_RESOLVE;

// Thin edges of node boxes in front of the hit: where the ray enters or leaves a box close to
// one of its edges (the second-smallest distance to a face plane is within a pixel or so).
vec4 boxOverlay(vec3 ro, vec3 rd, float tHit) {
    uint flags = control.size.w;
    uint first = 0u, last = control.counts.z;
    if ((flags & SDFCSG_FLAG_BOXES_SELECTED) != 0u) {
        first = control.counts.w;
        last = min(first + 1u, control.counts.z);
    }
    float tLimit = tHit < 0.0 ? frame.clipMin.w : tHit;
    vec4 result = vec4(0.0);
    for (uint i = first; i < last; ++i) {
        vec3 bmin = nodes[i].bmin.xyz, bmax = nodes[i].bmax.xyz;
        if (any(greaterThan(bmax - bmin, vec3(1.0e29))) || any(greaterThan(bmin, bmax))) continue;
        vec2 range = clipRay(bmin, bmax, ro, rd);
        if (range.x > range.y) continue;
        for (int e = 0; e < 2; ++e) {
            float t = e == 0 ? range.x : range.y;
            if (t <= 0.0 || t > tLimit) continue;
            vec3 p = ro + rd * t;
            vec3 d = min(abs(p - bmin), abs(p - bmax));
            // Second smallest component: distance to the nearest edge on this face.
            float edge = max(min(d.x, d.y), min(max(d.x, d.y), d.z));
            float width = 1.2 * t * frame.up.w;
            if (edge < width) {
                float a = 1.0 - edge / width;
                result = max(result, vec4(1.0, 0.85, 0.2, 0.9 * a));
            }
        }
    }
    return result;
}

// How much of the pixel the ground grid covers where the ray meets the grid's plane in front
// of the hit (tHit < 0: a miss): lines frame.grid.w apart, 2 SDFCSG_GRID_HALF_LINES + 1 each
// way, about a pixel wide, fading out where a pixel spans so much of the spacing that they
// would alias.
float gridCoverage(vec3 ro, vec3 rd, float tHit) {
    float spacing = frame.grid.w;
    float tPlane = (frame.grid.z - ro.y) / (abs(rd.y) < 1.0e-20 ? 1.0e-20 : rd.y);
    if (tPlane <= 0.0 || (tHit >= 0.0 && tPlane > tHit) || tPlane > frame.clipMin.w) return 0.0;
    vec2 q = (ro.xz + rd.xz * tPlane - frame.grid.xy) / spacing; // in spacings from the centre
    if (any(greaterThan(abs(q), vec2(float(SDFCSG_GRID_HALF_LINES) + 0.5)))) return 0.0;
    vec2 toLine = abs(q - round(q));
    float width = tPlane * frame.up.w / spacing; // a pixel, in spacings, across the ray
    float along = width / max(abs(rd.y), 0.05);  // ... and along it, where the plane tilts away
    float line = 1.0 - smoothstep(0.5 * width, 1.5 * width, min(toLine.x, toLine.y));
    bool axis = (abs(round(q.x)) < 0.5 && toLine.x <= toLine.y) ||
                (abs(round(q.y)) < 0.5 && toLine.y <= toLine.x);
    return line * (axis ? 0.7 : 0.4) * (1.0 - smoothstep(0.1, 0.3, along));
}

// The pixel's final colour: the ground grid and the box edges drawn over it.
uint finish(vec3 c, vec3 ro, vec3 rd, float t) {
    if ((control.size.w & SDFCSG_FLAG_GRID) != 0u) c = mix(c, vec3(0.12), gridCoverage(ro, rd, t));
    if ((control.size.w & (SDFCSG_FLAG_BOXES_ALL | SDFCSG_FLAG_BOXES_SELECTED)) != 0u) {
        vec4 o = boxOverlay(ro, rd, t);
        c = mix(c, o.rgb, o.a);
    }
    return packColor(c);
}

void resolvePass() {
    uvec2 pixel = gl_GlobalInvocationID.xy + uvec2(0u, band.firstRow);
    if (any(greaterThanEqual(pixel, control.size.xy))) return;
    uint aa = max(control.counts.x, 1u);
    uint row = control.size.x * aa;
    uint first = gl_GlobalInvocationID.y * aa * row + gl_GlobalInvocationID.x * aa;
    vec3 sum = vec3(0.0);
    for (uint sy = 0u; sy < aa; ++sy)
        for (uint sx = 0u; sx < aa; ++sx)
            sum += unpackColor(colors[first + sy * row + sx]);
    pixels[pixel.y * control.size.x + pixel.x] = packColor(sum / float(aa * aa));
}

// The overlays over a pixel's colour, along the ray through its centre and in front of its
// first sample's hit (Info). Their lines carry coverage of their own, so once per pixel is
// enough.
void overlayPass() {
    uvec2 pixel = gl_GlobalInvocationID.xy + uvec2(0u, band.firstRow);
    if (any(greaterThanEqual(pixel, control.size.xy))) return;
    vec3 rd = rayDirection(vec2(pixel) + 0.5);
    uint i = pixel.y * control.size.x + pixel.x;
    pixels[i] = finish(unpackColor(pixels[i]), frame.eye.xyz, rd, info[i].x);
}

void main() {
    if (kPass == SDFCSG_RAYMARCH_PASS_RESOLVE) resolvePass();
    else overlayPass();
}
