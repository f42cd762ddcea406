#version 450
#extension GL_GOOGLE_include_directive : require
// The extracted mesh with the ray marcher's camera (engine/src/camera.h), so the mesh lies on
// the ray-marched surface pixel for pixel. Vertices are pulled from storage buffers: the shaded
// view draws indexed (gl_VertexIndex is the vertex), the wireframe draws three vertices per
// triangle (gl_VertexIndex is the corner), which gives each corner its own barycentric
// coordinates without a geometry shader or a barycentric extension.
#include "mesh_draw.glsl"

// Tightly packed xyz triples: float arrays, since vec3 arrays would take 16 bytes a vertex.
layout(std430, set = 0, binding = 0) readonly buffer Positions { float positions[]; };
layout(std430, set = 0, binding = 1) readonly buffer Normals { float normals[]; };
layout(std430, set = 0, binding = 2) readonly buffer Colors { float colors[]; };
layout(std430, set = 0, binding = 3) readonly buffer Indices { uint indices[]; };

layout(location = 0) out vec3 outNormal;
layout(location = 1) out vec3 outColor;
layout(location = 2) out vec3 outView; // from the eye to the point, for the lighting
layout(location = 3) out vec3 outBarycentric;

#define FETCH(array, i) vec3(array[3u * (i)], array[3u * (i) + 1u], array[3u * (i) + 2u])

void main() {
    bool wire = pc.forward.w > 0.5;
    uint corner = uint(gl_VertexIndex);
    uint i = wire ? indices[corner] : corner;
    vec3 p = FETCH(positions, i);
    outNormal = FETCH(normals, i);
    outColor = FETCH(colors, i);
    vec3 d = p - pc.eye.xyz;
    outView = d;
    uint k = corner % 3u;
    outBarycentric = wire ? vec3(k == 0u, k == 1u, k == 2u) : vec3(1.0);
    // Vulkan's y points down the image as the ray marcher's pixel rows do, hence -up. Depth is
    // reversed (near / distance: 1 at the near plane, towards 0 far away), which keeps float
    // depth precise at every distance and needs no far plane.
    gl_Position = vec4(dot(d, pc.right.xyz), -dot(d, pc.up.xyz), pc.eye.w, dot(d, pc.forward.xyz));
}
