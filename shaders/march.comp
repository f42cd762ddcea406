#version 450
// The march pass of the ray march (shaders/raymarch.glsl): one invocation per sample of the
// listed workgroups traces its ray to the first hit.
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "sdf.glsl"
#include "nodes.glsl"
#include "raymarch.glsl"
#include "scene.glsl"

// The march pass: the first hit along the ray, from t to tFar (the clip pass's range).
Trace march(vec3 ro, vec3 rd, float t, float tFar) {
    Trace r = Trace(-1.0, 0u, vec3(0.0), 1.0, vec4(1.0));
    bool marching = t <= tFar;
    while (marching) {
#ifdef SDFCSG_TAPE_STACK
        // Tapes: through a cell far from every surface, the step goes as far as the cell's
        // reach along the ray (tape.glsl), farther than its bound. Such a cell holds no surface:
        // its bound is never a hit, however small beside the hit epsilon (the solid's inside
        // aside).
        float step;
        bool far;
        float d = tapeDistanceAlong(ro + rd * t, rd, step, far);
        float epsilon = far ? 0.0 : hitEpsilon(t);
#else
        float d = sceneDistance(ro + rd * t), step = d;
        float epsilon = hitEpsilon(t);
#endif
        r.steps += 1u;
        if (d < epsilon) {
            r.t = t;
            marching = false;
        } else {
            t += step;
            marching = t <= tFar && r.steps < SDFCSG_MAX_STEPS;
        }
    }
    return r;
}

void marchPass() {
    uvec2 s;
    uint sampleIndex;
    if (!tileSample(s, sampleIndex)) return;
    vec4 ray = ranges[2u * sampleIndex]; // from the clip pass
    Trace r = march(frame.eye.xyz, ray.xyz, ray.w, ranges[2u * sampleIndex + 1u].x);
    uint aa = max(control.counts.x, 1u);
    uvec2 pixel = uvec2((vec2(s) + 0.5) / float(aa)); // in the band, as sampleRay() finds it
    if (all(equal(s, pixel * aa))) // the pixel's first sample
        info[(pixel.y + band.firstRow) * control.size.x + pixel.x] = vec2(r.t, float(r.steps));
    if (needsShading(r)) {
        uint slot = atomicAdd(count, 1u);
        if (slot % (SDFCSG_RAYMARCH_GROUP_X * SDFCSG_RAYMARCH_GROUP_Y) == 0u) atomicAdd(groups, 1u);
        hits[slot] = uvec2(sampleIndex, floatBitsToUint(r.t));
        surfaces[4u * slot + 1u] = vec4(ray.xyz, r.t);
    } else {
        colors[band.colorOffset + sampleIndex] = packColor(plainColor(r));
    }
}

void main() { marchPass(); }
