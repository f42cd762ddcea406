#version 450
// The shade pass of the ray march (shaders/raymarch.glsl): one invocation per listed hit.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_ballot : require

#include "shared.h"
#include "sdf.glsl"
#include "nodes.glsl"
#include "raymarch.glsl"
#include "scene.glsl"

// A loop index over the lights, the same in every invocation, said so: CPU drivers such as
// lavapipe cannot tell, and read what it indexes lane by lane, eight loads per component;
// from subgroupBroadcastFirst they read once. One loop body instead of one per light cuts
// the kernel's compile.
uint uniformIndex(uint i) { return subgroupBroadcastFirst(i); }

// Steps per shadow ray, each a full scene evaluation. A ray that grazes a surface crawls along
// it in short steps; one that runs out of them before passing it ends too lit, and with 16 a
// patch of the snowman's drift showed the edge where that began. 24 cost about 1% of a frame.
const int kShadowSteps = 24;
const float kShadowSharpness = 10.0;

// The shade pass: colour, normal, occlusion and shadows at the hit r.t. All scene evaluations
// go through one call of sceneSample in one loop, driven by a small state machine: the colour
// at the hit (shaded mode), four normal taps, five occlusion taps and one shadow ray per light,
// each evaluating the scene at origin + dir * t. Two reasons, both about lavapipe: its compiler
// inlines every call site, so one site keeps the JIT compile short (the colour's own call cost
// the house about 50 ms of compile); and a lane that has finished its occlusion taps evaluates
// its shadow steps in the same instructions as its neighbours' taps instead of idling through
// them.
const uint kColor = 0u, kNormal = 1u, kOcclusion = 2u, kShadow = 3u, kDone = 4u;

// The tetrahedron k = (1, -1): k.xyy, k.yyx, k.yxy, k.xxx.
vec3 tetraTap(int i) {
    return i == 0 ? vec3(1.0, -1.0, -1.0)
         : i == 1 ? vec3(-1.0, -1.0, 1.0)
         : i == 2 ? vec3(-1.0, 1.0, -1.0)
                  : vec3(1.0);
}

void surface(vec3 ro, vec3 rd, inout Trace r, out vec3 albedo) {
    uint mode = control.size.z;
    uint flags = control.size.w;
    uint lightCount = (flags & SDFCSG_FLAG_SHADOWS) != 0u ? control.counts.y : 0u;
    float aoScale = frame.distances.z;
    float shadowReach = frame.distances.w;
    uint partCount = control.parts.x; // read before the loops (see march.comp)

    // For the loop below, whose lanes may be on different lights (see nextLight).
    vec3 light0 = frame.lights[0].direction.xyz, light1 = frame.lights[1].direction.xyz;
    vec3 light2 = frame.lights[2].direction.xyz, light3 = frame.lights[3].direction.xyz;

    float eps = hitEpsilon(r.t);
    vec3 p = ro + rd * r.t; // the hit, then the hit lifted off the surface

    // Where each shadow ray can end, worked out here rather than in the loop (whose every
    // iteration would run it): occluders lie inside the clip box and the boxes that hold
    // surfaces, so a ray ends where it leaves them. From the hit; the ray starts from the
    // hit lifted by 2 eps, hence the margin.
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
                vec2 range = partInterval(b, p, l);
                if (range.x <= range.y) lastExit = max(lastExit, range.y);
            }
            end = min(end, lastExit);
        }
        ends = mix(ends, vec4(end), equal(uvec4(0u, 1u, 2u, 3u), uvec4(i)));
    }
    uint phase = mode == SDFCSG_MODE_SHADED ? kColor : kNormal;
    vec3 origin = p, dir = tetraTap(0);
    float t = phase == kColor ? 0.0 : eps; // the colour is taken at the hit itself
    albedo = vec3(0.0);
    int tap = 0;
    float weight = 1.0;
    uint light = 0u;
    float res = 1.0, ph = 1.0e20, shadowEnd = 0.0; // shadow ray (IQ's improved soft shadow)

    while (phase != kDone) {
        vec4 s = sceneSample(origin + dir * t);
        float d = s.w;
        bool nextLight = false;

        if (phase == kColor) {
            albedo = s.rgb;
            phase = kNormal;
            t = eps;
        } else if (phase == kNormal) {
            r.n += dir * d;
            tap += 1;
            dir = tetraTap(tap);
            if (tap == 4) {
                r.n = normalize(r.n);
                // Lift off the surface so occlusion and shadow rays do not re-hit it at once.
                p += r.n * (2.0 * eps);
                origin = p;
                if (mode != SDFCSG_MODE_SHADED) {
                    phase = kDone;
                } else if ((flags & SDFCSG_FLAG_AO) != 0u) {
                    phase = kOcclusion;
                    tap = 0;
                    r.ao = 0.0; // accumulates occlusion until the last tap
                    dir = r.n;
                    t = aoScale * 0.01;
                } else {
                    nextLight = true;
                }
            }
        } else if (phase == kOcclusion) {
            r.ao += (t - d) * weight;
            weight *= 0.95;
            tap += 1;
            t += aoScale * 0.03;
            if (tap == 5) {
                r.ao = clamp(1.0 - 3.0 * r.ao / aoScale, 0.0, 1.0);
                nextLight = true;
            }
        } else { // kShadow
            if (d < eps * 0.5) {
                res = 0.0;
            } else {
                float y = d * d / (2.0 * ph);
                float w = sqrt(max(d * d - y * y, 0.0));
                res = min(res, kShadowSharpness * w / max(0.0, t - y));
                ph = d;
                t += max(d, eps);
            }
            tap += 1;
            if (res < 0.02 || t >= shadowEnd || tap >= kShadowSteps) {
                r.shadow = mix(r.shadow, vec4(res < 0.02 ? 0.0 : res),
                               equal(uvec4(0u, 1u, 2u, 3u), uvec4(light)));
                light += 1u;
                nextLight = true;
            }
        }

        if (nextLight) {
            // Light directions come from locals with selects: indexing the uniform array by a
            // per-lane index would gather in every iteration of this loop on CPU drivers.
            dir = light == 0u ? light0 : light == 1u ? light1 : light == 2u ? light2 : light3;
            shadowEnd = light == 0u ? ends.x : light == 1u ? ends.y : light == 2u ? ends.z : ends.w;
            phase = light < lightCount ? kShadow : kDone;
            t = 2.0 * eps;
            // A light behind the surface needs no shadow (Lambert is zero): end it at once.
            tap = dot(r.n, dir) > 0.0 ? 0 : kShadowSteps;
            res = 1.0;
            ph = 1.0e20;
        }
    }
}

// Scene colours are treated as gamma 2 (sRGB, close enough): squared to shade, square-rooted
// back; pow() is slow on CPU drivers. Lambert and Blinn-Phong per light, an ambient term from the
// background, occlusion and shadows from surface().
vec3 shade(vec3 ro, vec3 rd, Trace r, vec3 albedo) {
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

void shadePass() {
    uint slot = gl_WorkGroupID.x * (SDFCSG_RAYMARCH_GROUP_X * SDFCSG_RAYMARCH_GROUP_Y) +
                gl_LocalInvocationIndex;
    if (slot >= count) return;
    uvec2 hit = hits[slot];
    uvec2 pixel;
    vec3 rd;
    sampleRay(sampleCoords(hit.x), pixel, rd);
    vec3 ro = frame.eye.xyz;
    Trace r = Trace(uintBitsToFloat(hit.y), 0u, vec3(0.0), 1.0, vec4(1.0));
    vec3 albedo;
    surface(ro, rd, r, albedo);
    colors[band.colorOffset + hit.x] = packColor(shade(ro, rd, r, albedo));
}

void main() { shadePass(); }
