#version 450
// The passes around the shade pass that do not evaluate the scene (shaders/raymarch.glsl),
// one invocation per listed hit: before it, where each light's shadow ray can end; after it,
// the lighting. kPass picks one. Out of the shade kernel, which every new scene compiles, they
// are compiled once per context.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_ballot : require

#include "shared.h"
#include "raymarch.glsl"

layout(constant_id = SDFCSG_SPEC_RAYMARCH_PASS) const uint kPass = SDFCSG_RAYMARCH_PASS_ENDS;

// A loop index over the lights, the same in every invocation, said so: CPU drivers such as
// lavapipe cannot tell, and read what it indexes lane by lane, eight loads per component;
// from subgroupBroadcastFirst they read once. One loop body instead of one per light cuts
// the kernel's compile.
uint uniformIndex(uint i) { return subgroupBroadcastFirst(i); }

// Where each shadow ray can end: occluders lie inside the clip box and the boxes that hold
// surfaces, so a ray ends where it leaves them. From the hit; the shade pass starts the ray
// from the hit lifted by 2 eps, hence the margin.
void endsPass() {
    uint slot = hitSlot();
    if (slot >= count) return;
    vec4 ray = surfaces[4u * slot + 1u]; // from the march pass
    vec3 p = frame.eye.xyz + ray.xyz * ray.w;
    uint lightCount = control.counts.y;
    float shadowReach = frame.distances.w;
    uint partCount = control.parts.x;
    vec4 ends = vec4(0.0);
    for (uint k = 0u; k < lightCount; ++k) {
        uint i = uniformIndex(k);
        vec3 l = frame.lights[i].direction.xyz, inv = frame.lights[i].inverse.xyz;
        vec3 t0 = (frame.clipMin.xyz - p) * inv, t1 = (frame.clipMax.xyz - p) * inv;
        vec3 far = max(t0, t1);
        float end = min(min(far.x, far.y), min(far.z, shadowReach));
        if (partCount > 0u) {
            float lastExit = 0.0;
            for (uint b = 0u; b < partCount; ++b) {
                vec2 range = partInterval(b, p, l, inv);
                if (range.x <= range.y) lastExit = max(lastExit, range.y);
            }
            end = min(end, lastExit);
        }
        ends = mix(ends, vec4(end), equal(uvec4(0u, 1u, 2u, 3u), uvec4(i)));
    }
    surfaces[4u * slot] = ends;
}

// Scene colours are treated as gamma 2 (sRGB, close enough): squared to shade, square-rooted
// back; pow() is slow on CPU drivers. Lambert and Blinn-Phong per light, an ambient term from the
// background, occlusion and shadows from the shade pass.
vec3 shade(vec3 rd, Trace r, vec3 albedo) {
    uint mode = control.size.z;
    vec3 n = r.n;
    if (mode == SDFCSG_MODE_NORMALS) return n * 0.5 + 0.5;

    albedo *= albedo;
    vec3 col = albedo * (0.10 + 0.15 * frame.sky.rgb * (0.5 + 0.5 * n.y)) * r.ao;
    uint lightCount = control.counts.y;
    for (uint k = 0u; k < lightCount; ++k) {
        uint i = uniformIndex(k);
        vec3 l = frame.lights[i].direction.xyz;
        // r.shadow through selects: a per-lane index would keep it in memory.
        float shadow = i == 0u   ? r.shadow.x
                       : i == 1u ? r.shadow.y
                       : i == 2u ? r.shadow.z
                                 : r.shadow.w;
        float lambert = max(dot(n, l), 0.0);
        float spec = pow48(max(dot(n, normalize(l - rd)), 0.0)) * 0.25;
        col += frame.lights[i].color.rgb * (shadow * lambert) * (albedo + spec);
    }
    col = sqrt(col);
    // Fade into the background towards the far limit so a ground plane has no hard edge.
    float fog = smoothstep(0.6, 1.0, r.t / frame.clipMin.w);
    return mix(col, frame.background.rgb, fog);
}

void lightPass() {
    uint slot = hitSlot();
    if (slot >= count) return;
    uvec2 hit = hits[slot];
    vec3 rd;
    float t;
    hitRay(hit, rd, t);
    vec4 normal = surfaces[4u * slot + 1u];
    Trace r = Trace(t, 0u, normal.xyz, normal.w, surfaces[4u * slot + 2u]);
    colors[band.colorOffset + hit.x] = packColor(shade(rd, r, surfaces[4u * slot + 3u].rgb));
}

void main() {
    if (kPass == SDFCSG_RAYMARCH_PASS_ENDS) endsPass();
    else lightPass();
}
