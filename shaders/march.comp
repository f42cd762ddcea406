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

// The sort pass (clip.comp) reads the result from the sample's range and does the rest: the
// pixel's info, the hit list, the colour of the samples that need no shading. Out of this
// kernel, which every new scene compiles, that work cost the house's march kernel about a fifth
// of its compile on lavapipe.
void marchPass() {
    uvec2 s;
    uint sampleIndex;
    if (!tileSample(s, sampleIndex)) return;
    vec4 ray = ranges[2u * sampleIndex]; // from the clip pass
    Trace r = march(frame.eye.xyz, ray.xyz, ray.w, ranges[2u * sampleIndex + 1u].x);
    ranges[2u * sampleIndex + 1u].xy = vec2(r.t, float(r.steps));
}

void main() { marchPass(); }
