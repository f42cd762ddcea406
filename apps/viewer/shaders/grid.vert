#version 450
#extension GL_GOOGLE_include_directive : require
// The ground grid of the ray marcher (sdfcsg::groundGrid, shaders/raymarch.glsl) as a line list
// made from gl_VertexIndex alone: lines pc.grid.w apart on the plane y = pc.grid.z, pc.up.w on
// each side of the middle lines through (pc.grid.x, pc.grid.y), each reaching half a spacing
// past the outermost ones, first those along z, then those along x.
#include "mesh_draw.glsl"

layout(location = 0) out vec3 outWorld;
layout(location = 1) out float outAxis; // 1 on the middle lines

void main() {
    int halfLines = int(pc.up.w), lines = 2 * halfLines + 1;
    int line = gl_VertexIndex / 2;
    bool alongX = line >= lines;
    float offset = float(line % lines - halfLines);
    float along = (gl_VertexIndex % 2 == 0 ? -1.0 : 1.0) * (float(halfLines) + 0.5);
    vec2 q = alongX ? vec2(along, offset) : vec2(offset, along); // in spacings from the centre
    vec3 p = vec3(pc.grid.x + q.x * pc.grid.w, pc.grid.z, pc.grid.y + q.y * pc.grid.w);
    outWorld = p;
    outAxis = offset == 0.0 ? 1.0 : 0.0;
    gl_Position = project(p - pc.eye.xyz);
}
