#version 450
#extension GL_GOOGLE_include_directive : require
// Lambert from the eye plus ambient, as the CPU preview of meshes did, and for the wireframe the
// distance to the triangle's edges in pixels from the barycentric coordinates' screen-space
// derivatives: lines keep their width at every distance.
#include "mesh_draw.glsl"

layout(location = 0) in vec3 inNormal;
layout(location = 1) in vec3 inColor;
layout(location = 2) in vec3 inView;
layout(location = 3) in vec3 inBarycentric;
layout(location = 0) out vec4 outColor;

void main() {
    vec3 n = normalize(inNormal);
    vec3 view = normalize(inView);
    vec3 colour = inColor * (0.25 + 0.75 * max(0.0, -dot(n, view)));
    if (pc.forward.w > 0.5) {
        vec3 perPixel = max(fwidth(inBarycentric), vec3(1e-6));
        vec3 distance = inBarycentric / perPixel; // pixels to the edge opposite each corner
        float nearest = min(distance.x, min(distance.y, distance.z));
        float coverage = 1.0 - smoothstep(0.5 * pc.line.a - 0.5, 0.5 * pc.line.a + 0.5, nearest);
        // 1 / perPixel is the triangle's height over each edge in pixels. Below a few pixels the
        // lines would cover the whole triangle and a dense mesh would turn black: fade them to a
        // tint that still shows where the mesh is dense.
        float height = 1.0 / max(perPixel.x, max(perPixel.y, perPixel.z));
        float strength = mix(0.15, 1.0, smoothstep(2.0, 8.0, height));
        colour = mix(colour, pc.line.rgb, coverage * strength);
    }
    outColor = vec4(colour, 1.0);
}
