#version 450
#extension GL_GOOGLE_include_directive : require
// The extracted mesh through fixed-function vertex input: on a CPU device such as lavapipe the
// driver's vertex fetch is much faster than loads from storage buffers, which it runs lane by
// lane with bounds checks. The shaded view draws the welded vertices indexed; the wireframe
// draws a copy with three vertices per triangle (gl_VertexIndex is the corner), which gives
// each corner its own barycentric coordinates without a geometry shader or a barycentric
// extension, and on lavapipe costs far less than drawing the edges as lines.
#include "mesh_draw.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec3 inColor;

layout(location = 0) out vec3 outNormal;
layout(location = 1) out vec3 outColor;
layout(location = 2) out vec3 outView; // from the eye to the point, for the lighting
layout(location = 3) out vec3 outBarycentric;

void main() {
    vec3 d = inPosition - pc.eye.xyz;
    outNormal = inNormal;
    outColor = inColor;
    outView = d;
    uint k = uint(gl_VertexIndex) % 3u;
    outBarycentric = pc.forward.w > 0.5 ? vec3(k == 0u, k == 1u, k == 2u) : vec3(1.0);
    gl_Position = project(d);
}
