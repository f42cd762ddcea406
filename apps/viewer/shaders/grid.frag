#version 450
#extension GL_GOOGLE_include_directive : require
// As gridCoverage() in shaders/raymarch.glsl: the middle lines darker, and every line fading out
// where a pixel spans so much of the spacing that the lines would alias.
#include "mesh_draw.glsl"

layout(location = 0) in vec3 inWorld;
layout(location = 1) in float inAxis;
layout(location = 0) out vec4 outColor;

void main() {
    vec3 d = inWorld - pc.eye.xyz;
    float t = length(d);
    float width = t * pc.right.w / pc.grid.w; // a pixel, in spacings, across the ray
    float along = width / max(abs(d.y / t), 0.05);
    outColor = vec4(vec3(0.12), (inAxis > 0.5 ? 0.7 : 0.4) * (1.0 - smoothstep(0.1, 0.3, along)));
}
