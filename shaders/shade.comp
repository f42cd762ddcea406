#version 450
// The shade pass of the ray march (shaders/raymarch.glsl): one invocation per listed hit, whose
// findings the light pass (light.comp) turns into a colour.
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "sdf.glsl"
#include "nodes.glsl"
#include "raymarch.glsl"
#include "scene.glsl"

// Soft shadows after Quilez's penumbra estimate with penetration ("soft shadows with negative
// distances", 2020): each step takes min(res, sharpness * d / t), also where d < 0 inside an
// occluder, and the ray ends at res = -1; the result maps [-1, 1] to [0, 1] smoothly, so the
// geometric shadow edge is mid-penumbra. A hit that zeroes the light at once, or a step as long
// as d, made the penumbra depend on where each pixel's samples fell: on concave walls, where
// shadow rays run along the surface, that drew streaks. So steps are half of |d| (inside, |d|
// is still the distance to the occluder's far side), between kShadowStepMin and kShadowStepMax
// of the shadow reach (the scene's size), and 64 of them reach past the scene. Inside an
// occluder the estimate falls kShadowInside times faster: a plate's depth is at most half its
// thickness, and a table top would otherwise cast a pale shadow.
const int kShadowSteps = 64;
const float kShadowSharpness = 10.0;
const float kShadowInside = 4.0;
const float kShadowStepMin = 0.002, kShadowStepMax = 0.05, kShadowStart = 0.004;

// The shade pass: colour, normal, occlusion and shadows at the hit r.t. All scene evaluations
// go through one call of sceneSample in one loop, driven by a small state machine: the colour
// at the hit (shaded mode), four normal taps, five occlusion taps and one shadow ray per light,
// each evaluating the scene at origin + dir * t. Two reasons, both about lavapipe: its compiler
// inlines every call site, so one site keeps the JIT compile short (the colour's own call cost
// the house about 50 ms of compile); and a lane that has finished its occlusion taps evaluates
// its shadow steps in the same instructions as its neighbours' taps instead of idling through
// them.
const uint kColor = 0u, kNormal = 1u, kOcclusion = 2u, kShadow = 3u, kDone = 4u;

void surface(vec3 ro, vec3 rd, vec4 ends, inout Trace r, out vec3 albedo) {
    uint mode = control.size.z;
    uint flags = control.size.w;
    uint lightCount = (flags & SDFCSG_FLAG_SHADOWS) != 0u ? control.counts.y : 0u;
    float aoScale = frame.distances.z;

    // For the loop below, whose lanes may be on different lights (see nextLight).
    vec3 light0 = frame.lights[0].direction.xyz, light1 = frame.lights[1].direction.xyz;
    vec3 light2 = frame.lights[2].direction.xyz, light3 = frame.lights[3].direction.xyz;

    float eps = hitEpsilon(r.t);
    vec3 p = ro + rd * r.t; // the hit, then the hit lifted off the surface

    uint phase = mode == SDFCSG_MODE_SHADED ? kColor : kNormal;
    vec3 origin = p, dir = tetraTap(0);
    float t = phase == kColor ? 0.0 : eps; // the colour is taken at the hit itself
    albedo = vec3(0.0);
    int tap = 0;
    float weight = 1.0;
    uint light = 0u;
    float res = 1.0, shadowEnd = 0.0, reach = frame.distances.w; // shadow ray

    while (phase != kDone) {
#ifdef SDFCSG_TAPE_STACK
        // Tapes: the one call site matters not (the scene is a loop, not inlined code), and
        // only the colour needs the colour stack.
        vec4 s;
        if (phase == kColor)
            s = sceneSample(origin + dir * t);
        else
            s = tapeTap(origin + dir * t, dir);
#else
        vec4 s = sceneSample(origin + dir * t);
#endif
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
            // In a far cell (tape.glsl), the field's estimate along its direction of ascent.
            r.ao += (t - (s.r < 0.0 ? s.b : d)) * weight;
            weight *= 0.95;
            tap += 1;
            t += aoScale * 0.03;
            if (tap == 5) {
                r.ao = clamp(1.0 - 3.0 * r.ao / aoScale, 0.0, 1.0);
                nextLight = true;
            }
        } else { // kShadow
            if (s.r < 0.0) {
                // A bound from a cell far from every surface (tape.glsl): the ray steps as far
                // as the cell's reach along it (s.g with tapes), a step that does not count
                // against the steps (each is at least a cell's radius), and is never a hit. The
                // penumbra takes the field's estimate there (s.b with tapes): the bound would
                // narrow its cone and darken lit surfaces, and no sample at all lightened them
                // where far cells lie near the surface.
#ifdef SDFCSG_TAPE_STACK
                res = min(res, kShadowSharpness * s.b / t);
                t += max(s.g, eps);
#else
                t += max(d, eps);
#endif
                tap -= 1;
            } else {
                res = min(res, kShadowSharpness * (d < 0.0 ? kShadowInside * d : d) / t);
                t += clamp(0.5 * abs(d), kShadowStepMin * reach, kShadowStepMax * reach);
            }
            tap += 1;
            if (res < -1.0 || t >= shadowEnd || tap >= kShadowSteps) {
                float c = max(res, -1.0);
                r.shadow = mix(r.shadow, vec4(0.25 * (1.0 + c) * (1.0 + c) * (2.0 - c)),
                               equal(uvec4(0u, 1u, 2u, 3u), uvec4(light)));
                light += 1u;
                nextLight = true;
            }
        }

        if (nextLight) {
            // Light directions come from locals with selects. Indexing the uniform array by the
            // lane's light instead compiles about a tenth faster on lavapipe, but that load
            // gathers in every iteration of this loop on CPU drivers: a fifth more time per
            // frame for the small scenes (csg_part, mesh_a).
            dir = light == 0u ? light0 : light == 1u ? light1 : light == 2u ? light2 : light3;
            shadowEnd = light == 0u ? ends.x : light == 1u ? ends.y : light == 2u ? ends.z : ends.w;
            phase = light < lightCount ? kShadow : kDone;
            t = max(2.0 * eps, kShadowStart * reach);
            // A light behind the surface needs no shadow (Lambert is zero): end it at once.
            tap = dot(r.n, dir) > 0.0 ? 0 : kShadowSteps;
            res = 1.0;
        }
    }
}

void shadePass() {
    uint slot = hitSlot();
    if (slot >= count) return;
    vec4 ray = surfaces[4u * slot + 1u]; // from the march pass
    vec3 rd = ray.xyz;
    float t = ray.w;
    vec3 ro = frame.eye.xyz;
    Trace r = Trace(t, 0u, vec3(0.0), 1.0, vec4(1.0));
    vec3 albedo;
    surface(ro, rd, surfaces[4u * slot], r, albedo);
    surfaces[4u * slot + 1u] = vec4(r.n, r.ao);
    surfaces[4u * slot + 2u] = r.shadow;
    surfaces[4u * slot + 3u] = vec4(albedo, 0.0);
}

void main() { shadePass(); }
