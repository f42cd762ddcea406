#version 450
// Mesh extraction, triangle pass: one workgroup per brick of the batch, one invocation per
// z-plane of the brick (see mesh_scan.glsl). Emits the cell's triangles from the marching-cubes table; each corner is the vertex of a
// crossed edge, numbered by the brick that owns the edge's lower sample (this one or a
// neighbour): that brick's first vertex + the edge's number within it (see mesh_classify.comp).
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "mesh_common.glsl"
#include "mesh_scan.glsl"
#include "mesh_tables.glsl"

layout(local_size_x = SDFCSG_MESH_BRICK) in;

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_MAP) readonly buffer MeshMap {
    uint map[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_META) readonly buffer MeshMeta {
    uint meta[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_BASES) readonly buffer MeshBases {
    uvec2 bases[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_INDICES) writeonly buffer MeshIndices {
    uint indices[];
};

const uint kOwned = SDFCSG_MESH_BRICK * SDFCSG_MESH_BRICK * SDFCSG_MESH_BRICK;

uint vertexIndex(uint slot, uvec3 brick, uvec3 l, uint edge) {
    uint info = tables[1288u + edge];
    uint axis = info >> 3;
    uvec3 o = l + offsetBits(info);
    uvec3 next = uvec3(greaterThanEqual(o, uvec3(SDFCSG_MESH_BRICK)));
    // Branch-free: CPU drivers run both sides of a branch in their SIMD lanes anyway.
    uvec3 nb = brick + next;
    uint neighbour = map[nb.x + grid.bricks.x * (nb.y + grid.bricks.y * nb.z)];
    uint owner = any(notEqual(next, uvec3(0))) ? neighbour : slot;
    if (owner == SDFCSG_MESH_NO_BRICK) {
        status[1] = 1u; // the field is not 1-Lipschitz here; the host meshes again
        return 0u;
    }
    o -= next * SDFCSG_MESH_BRICK;
    uint m = meta[owner * kOwned + o.x + SDFCSG_MESH_BRICK * (o.y + SDFCSG_MESH_BRICK * o.z)];
    uint crossed = (m >> 11) & 7u;
    return bases[owner].x + (m & 0x7ffu) + bitCount(crossed & ((1u << axis) - 1u));
}

void main() {
    if (gl_WorkGroupID.x >= push.count) return; // uniform in the workgroup
    uint slot = push.first + gl_WorkGroupID.x;
    uvec3 brick = brickCoords(activeBricks[slot]);
    const uint kPlane = SDFCSG_MESH_BRICK * SDFCSG_MESH_BRICK;
    uint planeTotal = 0u;
    for (uint i = 0u; i < kPlane; ++i)
        planeTotal += triangleCountOf((meta[slot * kOwned + ownedIndex(planeSample(i))] >> 14) & 0xffu);
    uint total;
    uint next = bases[slot].y - push.triangleBase + planePrefix(planeTotal, total);
    for (uint i = 0u; i < kPlane; ++i) {
        uvec3 l = planeSample(i);
        uint cellCase = (meta[slot * kOwned + ownedIndex(l)] >> 14) & 0xffu;
        uint triangles = triangleCountOf(cellCase);
        for (uint k = 0u; k < 3u * triangles; ++k)
            indices[next * 3u + k] = vertexIndex(slot, brick, l, triangleEdge(cellCase, k));
        next += triangles;
    }
}
