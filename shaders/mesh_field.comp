#version 450
// The mesh-extraction passes that evaluate the scene, one kernel specialised three ways:
//   cull:     one invocation per brick; marks the bricks that may hold surface. The field is
//             1-Lipschitz, so a brick whose centre value exceeds its half-diagonal holds none.
//   sample:   one invocation per value of each brick's block of the batch.
//   vertices: one workgroup per brick of the batch, one invocation per crossed edge; places the
//             vertex on the edge (linear estimate, then regula falsi on the field), and gives it
//             the field's normal (four-tap tetrahedral differences) and the scene's colour.
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "sdf.glsl"
#include "nodes.glsl"
#include "scene.glsl"
#include "mesh_common.glsl"

layout(local_size_x = SDFCSG_MESH_GROUP_X) in;

layout(constant_id = SDFCSG_SPEC_MESH_PASS) const uint kPass = SDFCSG_MESH_PASS_CULL;

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_MAP) writeonly buffer MeshMap {
    uint map[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_SAMPLES) buffer MeshSamples {
    float samples[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_COUNTS) readonly buffer MeshCounts {
    uvec2 counts[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_BASES) readonly buffer MeshBases {
    uvec2 bases[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_EDGES) readonly buffer MeshEdges {
    uint edges[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_VERTICES) writeonly buffer MeshVertices {
    float vertices[];
};

void cull() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count) return;
    uint brick = push.first + i;
    uvec3 b = brickCoords(brick);
    uvec3 s0 = b * SDFCSG_MESH_BRICK;
    vec3 centre = samplePosition(s0) + 0.5 * SDFCSG_MESH_BRICK * grid.origin.w;
    float d = sceneDistance(centre);
    map[brick] = abs(d) <= grid.cull.x ? 1u : 0u;
    // A skipped brick wholly inside the solid that reaches the grid boundary: the solid is cut.
    uvec3 s1 = min(s0 + SDFCSG_MESH_BRICK, grid.cells.xyz);
    if (d < -grid.cull.x && (any(equal(s0, uvec3(0))) || any(equal(s1, grid.cells.xyz))))
        status[0] = 1u;
}

void sampleBlock() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count * SDFCSG_MESH_BRICK_BLOCK) return;
    uint slot = push.first + i / SDFCSG_MESH_BRICK_BLOCK;
    uint local = i % SDFCSG_MESH_BRICK_BLOCK;
    uvec3 l = uvec3(local % SDFCSG_MESH_BRICK_SAMPLES,
                    (local / SDFCSG_MESH_BRICK_SAMPLES) % SDFCSG_MESH_BRICK_SAMPLES,
                    local / (SDFCSG_MESH_BRICK_SAMPLES * SDFCSG_MESH_BRICK_SAMPLES));
    uvec3 s = brickCoords(activeBricks[slot]) * SDFCSG_MESH_BRICK + l;
    samples[i] = sceneDistance(samplePosition(s));
}

vec3 normalAt(vec3 p, vec3 edgeDirection) {
    const vec2 k = vec2(1.0, -1.0);
    float e = 0.05 * grid.origin.w;
    vec3 g = k.xyy * sceneDistance(p + k.xyy * e) + k.yyx * sceneDistance(p + k.yyx * e) +
             k.yxy * sceneDistance(p + k.yxy * e) + k.xxx * sceneDistance(p + k.xxx * e);
    return length(g) > 1e-20 ? normalize(g) : edgeDirection;
}

void placeVertices() {
    uint batchSlot = gl_WorkGroupID.x;
    if (batchSlot >= push.count) return;
    uint slot = push.first + batchSlot;
    uvec3 b = brickCoords(activeBricks[slot]) * SDFCSG_MESH_BRICK;
    uint count = counts[slot].x;
    uint first = bases[slot].x - push.vertexBase;
    for (uint v = gl_LocalInvocationID.x; v < count; v += SDFCSG_MESH_GROUP_X) {
        uint edge = edges[batchSlot * SDFCSG_MESH_BRICK_EDGES + v];
        uint owned = edge / 3u, axis = edge % 3u;
        uvec3 l = uvec3(owned % SDFCSG_MESH_BRICK, (owned / SDFCSG_MESH_BRICK) % SDFCSG_MESH_BRICK,
                        owned / (SDFCSG_MESH_BRICK * SDFCSG_MESH_BRICK));
        uvec3 step = uvec3(equal(uvec3(axis), uvec3(0, 1, 2)));
        uint block = batchSlot * SDFCSG_MESH_BRICK_BLOCK;
        float da = samples[block + blockIndex(l)];
        float db = samples[block + blockIndex(l + step)];
        vec3 pa = samplePosition(b + l);
        vec3 pb = samplePosition(b + l + step);

        float t = da / (da - db);
        float lo = 0.0, hi = 1.0, dlo = da, dhi = db;
        for (uint k = 0u; k < grid.cells.w; ++k) {
            float d = sceneDistance(pa + (pb - pa) * t);
            if ((d < 0.0) == (dlo < 0.0)) {
                lo = t;
                dlo = d;
            } else {
                hi = t;
                dhi = d;
            }
            t = lo + (hi - lo) * (dlo / (dlo - dhi));
        }
        vec3 p = pa + (pb - pa) * t;
        vec3 n = normalAt(p, vec3(step) * (db > da ? 1.0 : -1.0));
        vec3 c = sceneSample(p).rgb;

        uint o = (first + v) * 9u;
        vertices[o + 0u] = p.x;
        vertices[o + 1u] = p.y;
        vertices[o + 2u] = p.z;
        vertices[o + 3u] = n.x;
        vertices[o + 4u] = n.y;
        vertices[o + 5u] = n.z;
        vertices[o + 6u] = c.r;
        vertices[o + 7u] = c.g;
        vertices[o + 8u] = c.b;
    }
}

void main() {
    if (kPass == SDFCSG_MESH_PASS_CULL) cull();
    else if (kPass == SDFCSG_MESH_PASS_SAMPLE) sampleBlock();
    else placeVertices();
}
