#version 450
// Mesh extraction, classify pass: one workgroup per brick of the batch, one invocation per
// z-plane of the brick (see mesh_scan.glsl). For each owned sample, finds the crossed edges that
// start there and the marching-cubes case of the cell that starts there, numbers the brick's
// vertices (in order of sample, then axis) and counts its triangles.
//
// The signs of the brick's block are first packed into one word per row of samples along x, so
// a row's crossed edges are a few bit operations.
//
// meta (per owned sample): bits 0-10 the brick-local number of the sample's first vertex,
// 11-13 which of its x, y, z edges are crossed, 14-21 the case of its cell (0 outside the grid).
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "mesh_common.glsl"
#include "mesh_scan.glsl"
#include "mesh_tables.glsl"

layout(local_size_x = SDFCSG_MESH_BRICK) in;

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_SAMPLES) readonly buffer MeshSamples {
    float samples[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_META) writeonly buffer MeshMeta {
    uint meta[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_COUNTS) writeonly buffer MeshCounts {
    uvec2 counts[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_EDGES) writeonly buffer MeshEdges {
    uint edges[];
};

const uint kSide = SDFCSG_MESH_BRICK_SAMPLES;
const uint kRows = kSide * kSide;

// Bit x of insideRows[y + kSide * z] is set when sample (x, y, z) of the block is inside.
shared uint insideRows[kRows];

// Bits 0 .. count-1 set, for count in 0..32.
uint lowBits(uint count) {
    return count >= 32u ? 0xffffffffu : (1u << count) - 1u;
}

// Which edges and cells of row y of this invocation's plane lie in the grid, as bit masks
// over x: x edges, y edges, z edges, cells.
uvec4 rowMasks(uvec3 s0) {
    uvec3 left = uvec3(grid.cells.xyz) - min(s0, grid.cells.xyz); // cells from s0 to the far side
    bool rowIn = s0.y <= grid.cells.y && s0.z <= grid.cells.z;
    uint samplesIn = rowIn ? lowBits(left.x + 1u) : 0u;
    uint edgesX = rowIn ? lowBits(left.x) : 0u;
    uint edgesY = left.y > 0u ? samplesIn : 0u;
    uint edgesZ = left.z > 0u ? samplesIn : 0u;
    uint cells = left.y > 0u && left.z > 0u ? edgesX : 0u;
    uint owned = lowBits(SDFCSG_MESH_BRICK);
    return uvec4(edgesX, edgesY, edgesZ, cells) & owned;
}

// The owned samples of the row starting at s0 that lie on the grid's boundary, over x.
uint boundarySamples(uvec3 s0) {
    if (s0.y > grid.cells.y || s0.z > grid.cells.z) return 0u;
    uint inGrid = lowBits(min(grid.cells.x - s0.x + 1u, SDFCSG_MESH_BRICK)); // s0.x <= cells.x
    if (s0.y == 0u || s0.y == grid.cells.y || s0.z == 0u || s0.z == grid.cells.z) return inGrid;
    uint ends = s0.x == 0u ? 1u : 0u;
    if (grid.cells.x - s0.x < SDFCSG_MESH_BRICK) ends |= 1u << (grid.cells.x - s0.x);
    return ends & inGrid;
}

void main() {
    uint batchSlot = gl_WorkGroupID.x;
    if (batchSlot >= push.count) return; // uniform in the workgroup
    uint slot = push.first + batchSlot;
    uint block = batchSlot * SDFCSG_MESH_BRICK_BLOCK;
    uvec3 brick = brickCoords(activeBricks[slot]) * SDFCSG_MESH_BRICK;
    uint plane = gl_LocalInvocationID.x;

    for (uint r = plane; r < kRows; r += SDFCSG_MESH_BRICK) {
        uint bits = 0u;
        for (uint x = 0u; x < kSide; ++x)
            if (samples[block + r * kSide + x] < 0.0) bits |= 1u << x;
        insideRows[r] = bits;
    }
    barrier();

    uvec3 corners[8];
    for (uint c = 0u; c < 8u; ++c)
        corners[c] = cornerOffset(c);

    // First walk: counts. Second walk: numbers, meta and the edge list.
    uint planeTotal = 0u; // vertices | triangles << 16
    bool cut = false;
    for (uint y = 0u; y < SDFCSG_MESH_BRICK; ++y) {
        uvec3 s0 = brick + uvec3(0u, y, plane);
        uvec4 m = rowMasks(s0);
        uint row = insideRows[y + kSide * plane];
        uint crossedX = (row ^ (row >> 1)) & m.x;
        uint crossedY = (row ^ insideRows[y + 1u + kSide * plane]) & m.y;
        uint crossedZ = (row ^ insideRows[y + kSide * (plane + 1u)]) & m.z;
        planeTotal += bitCount(crossedX) + bitCount(crossedY) + bitCount(crossedZ);
        for (uint x = 0u; x < SDFCSG_MESH_BRICK; ++x) {
            uint cellCase = 0u;
            for (uint c = 0u; c < 8u; ++c)
                cellCase |= ((insideRows[y + corners[c].y + kSide * (plane + corners[c].z)] >>
                              (x + corners[c].x)) & 1u) << c;
            if ((m.w & (1u << x)) != 0u) planeTotal += triangleCountOf(cellCase) << 16;
        }
        cut = cut || (row & boundarySamples(s0)) != 0u;
    }
    if (cut) status[0] = 1u;

    uint total;
    uint next = planePrefix(planeTotal, total) & 0xffffu; // brick-local number of the next vertex
    for (uint y = 0u; y < SDFCSG_MESH_BRICK; ++y) {
        uvec3 s0 = brick + uvec3(0u, y, plane);
        uvec4 m = rowMasks(s0);
        uint row = insideRows[y + kSide * plane];
        uint crossedX = (row ^ (row >> 1)) & m.x;
        uint crossedY = (row ^ insideRows[y + 1u + kSide * plane]) & m.y;
        uint crossedZ = (row ^ insideRows[y + kSide * (plane + 1u)]) & m.z;
        for (uint x = 0u; x < SDFCSG_MESH_BRICK; ++x) {
            uint cellCase = 0u;
            if ((m.w & (1u << x)) != 0u)
                for (uint c = 0u; c < 8u; ++c)
                    cellCase |= ((insideRows[y + corners[c].y + kSide * (plane + corners[c].z)] >>
                                  (x + corners[c].x)) & 1u) << c;
            uint crossed = ((crossedX >> x) & 1u) | ((crossedY >> x) & 1u) << 1 |
                           ((crossedZ >> x) & 1u) << 2;
            uint o = ownedIndex(uvec3(x, y, plane));
            meta[slot * SDFCSG_MESH_BRICK * SDFCSG_MESH_BRICK * SDFCSG_MESH_BRICK + o] =
                next | (crossed << 11) | (cellCase << 14);
            for (uint axis = 0u; axis < 3u; ++axis)
                if ((crossed & (1u << axis)) != 0u)
                    edges[batchSlot * SDFCSG_MESH_BRICK_EDGES + next++] = o * 3u + axis;
        }
    }
    if (plane == 0u) counts[slot] = uvec2(total & 0xffffu, total >> 16);
}
