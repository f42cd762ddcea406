#version 450
// Mesh extraction, triangle pass: one workgroup per brick of the batch, one invocation per
// z-plane of the brick (see mesh_rows.glsl). Emits the triangles of the brick's cells from the
// marching-cubes table. Each corner is the vertex of a crossed edge, numbered by the brick that
// owns the edge's lower sample (this one or a neighbour): that brick's first vertex, plus the
// number of its row's first vertex, plus the crossed edges before it in the row (see the
// classify pass in mesh_field.comp).
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "mesh_common.glsl"
#include "mesh_rows.glsl"
#include "mesh_tables.glsl"

layout(local_size_x = SDFCSG_MESH_BRICK) in;

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_MAP) readonly buffer MeshMap {
    uint map[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_RECORDS) readonly buffer MeshRecords {
    uint records[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_BASES) readonly buffer MeshBases {
    uvec2 bases[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_INDICES) writeonly buffer MeshIndices {
    uint indices[];
};

// The vertex numbering of every row of samples the brick's cells reach: rows (y, z) of the
// block, each split into its samples x < 8 (brick (0, y / 8, z / 8) from this one) and x = 8
// (brick (1, ...)): the number of the part's first vertex, and its crossed edges as in the
// records (x edges in bits 0-7, y in 8-15, z in 16-23). Filled once per brick, so that each
// triangle corner reads shared memory instead of four buffers.
shared uvec2 rowVertices[2u * kSignRows];

void loadRowVertices(uint slot, uvec3 brick) {
    for (uint i = gl_LocalInvocationID.x; i < 2u * kSignRows; i += SDFCSG_MESH_BRICK) {
        uint r = i >> 1, part = i & 1u;
        uvec3 o = uvec3(part * SDFCSG_MESH_BRICK, r % kSide, r / kSide);
        uvec3 next = uvec3(greaterThanEqual(o, uvec3(SDFCSG_MESH_BRICK)));
        // Branch-free: CPU drivers run both sides of a branch in their SIMD lanes anyway.
        uvec3 nb = min(brick + next, grid.bricks.xyz - 1u);
        uint neighbour = map[nb.x + grid.bricks.x * (nb.y + grid.bricks.y * nb.z)];
        uint owner = any(notEqual(next, uvec3(0))) ? neighbour : slot;
        uvec2 v = uvec2(0u);
        if (owner != SDFCSG_MESH_NO_BRICK) {
            o -= next * SDFCSG_MESH_BRICK;
            uint row = owner * SDFCSG_MESH_RECORD + 2u * (o.y + SDFCSG_MESH_BRICK * o.z);
            v = uvec2(bases[owner].x + records[row], records[row + 1u]);
        } else {
            v = uvec2(0u, 0xffffffffu); // a crossed edge here means the brick was skipped wrongly
        }
        rowVertices[i] = v;
    }
}

uint vertexIndex(uvec3 l, uint edge) {
    uint info = tables[1280u + edge];
    uint axis = info >> 3;
    uvec3 o = l + offsetBits(info);
    uint part = o.x >> 3; // 1 when x = 8
    uvec2 v = rowVertices[2u * (o.y + kSide * o.z) + part];
    if (v.y == 0xffffffffu) {
        status[1] = 1u; // the field is not 1-Lipschitz here; the host meshes again
        return 0u;
    }
    uint x = o.x & 7u;
    uint earlier = v.y & (lowBits(x) * 0x10101u); // edges of earlier samples, all axes
    uint here = (v.y >> x) & 0x10101u;            // this sample's x, y, z edges
    uint axesBefore = axis == 0u ? 0u : axis == 1u ? 1u : 0x101u;
    return v.x + bitCount(earlier) + bitCount(here & axesBefore);
}

void main() {
    if (gl_WorkGroupID.x >= push.count) return; // uniform in the workgroup
    uint slot = push.first + gl_WorkGroupID.x;
    uvec3 b = brickCoords(activeBricks[slot]);
    uvec3 brick = b * SDFCSG_MESH_BRICK;
    uint plane = gl_LocalInvocationID.x;
    for (uint r = plane; r < kSignRows; r += SDFCSG_MESH_BRICK)
        insideRows[r] = records[slot * SDFCSG_MESH_RECORD + kRecordSigns + r];
    loadRowVertices(slot, b);
    barrier();

    uint planeTotal = 0u;
    for (uint y = 0u; y < SDFCSG_MESH_BRICK; ++y)
        for (uint cells = rowAt(brick + uvec3(0u, y, plane), y, plane).cells; cells != 0u;
             cells &= cells - 1u)
            planeTotal += triangleCountOf(cellCase(findLSB(cells), y, plane));
    uint total;
    uint next = bases[slot].y - push.triangleBase + planePrefix(planeTotal, total);
    for (uint y = 0u; y < SDFCSG_MESH_BRICK; ++y)
        for (uint cells = rowAt(brick + uvec3(0u, y, plane), y, plane).cells; cells != 0u;
             cells &= cells - 1u) {
            uvec3 l = uvec3(findLSB(cells), y, plane);
            uint c = cellCase(l.x, y, plane);
            uint triangles = triangleCountOf(c);
            for (uint k = 0u; k < 3u * triangles; ++k)
                indices[next * 3u + k] = vertexIndex(l, triangleEdge(c, k));
            next += triangles;
        }
}
