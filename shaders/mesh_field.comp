#version 450
// The mesh-extraction passes that evaluate the scene, one kernel specialised three ways:
//   cull:     one invocation per brick; marks the bricks that may hold surface. The field is
//             1-Lipschitz, so a brick whose centre value exceeds its half-diagonal holds none.
//   classify: one workgroup per brick of the batch: its SDFCSG_MESH_CLASSIFY_X invocations
//             sample the brick's block, then one invocation per z-plane (mesh_rows.glsl) finds
//             the crossed edges and the cells the surface passes through, numbers the brick's
//             vertices (by sample, then axis) and counts its triangles. The brick's record
//             keeps, per owned row, the number of its first vertex and its crossed edges, then
//             the block's signs, for the triangle pass.
//   vertices: one invocation per crossed edge of the batch; places the vertex on the edge
//             (linear estimate, then regula falsi on the field), and gives it the field's
//             normal (four-tap tetrahedral differences) and the scene's colour; for dual
//             contouring, also a second normal where the point lies on a sharp edge.
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "sdf.glsl"
#include "nodes.glsl"
#include "mesh_common.glsl"

#include "scene.glsl"
#include "mesh_rows.glsl"
#include "mesh_tables.glsl"

layout(local_size_x_id = SDFCSG_SPEC_MESH_GROUP) in;

layout(constant_id = SDFCSG_SPEC_MESH_PASS) const uint kPass = SDFCSG_MESH_PASS_CULL;

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_MAP) writeonly buffer MeshMap {
    uint map[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_SAMPLES) buffer MeshSamples {
    float samples[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_COUNTS) buffer MeshCounts {
    uvec4 counts[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_RECORDS) writeonly buffer MeshRecords {
    uint records[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_BASES) readonly buffer MeshBases {
    uvec4 bases[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_EDGES) buffer MeshEdges {
    uint edges[];
};

// Per edge point: (position, colour.r), (normal, colour.g), (second normal, colour.b).
layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_VERTICES) writeonly buffer MeshVertices {
    vec4 vertices[];
};

void cull() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count) return;
    uint brick = push.first + i;
    uvec3 s0 = brickCoords(brick) * SDFCSG_MESH_BRICK;
    vec3 centre = samplePosition(s0) + 0.5 * SDFCSG_MESH_BRICK * grid.origin.w;
    float d = sceneDistance(centre);
    map[brick] = abs(d) <= grid.cull.x ? 1u : 0u;
    // A skipped brick wholly inside the solid that reaches the grid boundary: the solid is cut.
    uvec3 s1 = min(s0 + SDFCSG_MESH_BRICK, grid.cells.xyz);
    if (d < -grid.cull.x && (any(equal(s0, uvec3(0))) || any(equal(s1, grid.cells.xyz))))
        status[0] = 1u;
}

// The owned samples of the row starting at grid sample s0 that lie on the grid's boundary,
// over x.
uint boundarySamples(uvec3 s0) {
    if (s0.y > grid.cells.y || s0.z > grid.cells.z) return 0u;
    uint inGrid = lowBits(min(grid.cells.x - s0.x + 1u, SDFCSG_MESH_BRICK)); // s0.x <= cells.x
    if (s0.y == 0u || s0.y == grid.cells.y || s0.z == 0u || s0.z == grid.cells.z) return inGrid;
    uint ends = s0.x == 0u ? 1u : 0u;
    if (grid.cells.x - s0.x < SDFCSG_MESH_BRICK) ends |= 1u << (grid.cells.x - s0.x);
    return ends & inGrid;
}

void classify() {
    uint batchSlot = gl_WorkGroupID.x;
    if (batchSlot >= push.count) return; // uniform in the workgroup
    uint slot = push.first + batchSlot;
    uint block = batchSlot * SDFCSG_MESH_BRICK_BLOCK;
    uint record = slot * SDFCSG_MESH_RECORD;
    uvec3 brick = brickCoords(activeBricks[slot]) * SDFCSG_MESH_BRICK;
    uint plane = gl_LocalInvocationID.x;

    // The samples, up to three rows per invocation (SDFCSG_MESH_CLASSIFY_X of them): llvmpipe
    // ends every loop of an invocation for good once they have run 65535 rounds together (over
    // all loops, the scene's own included), so no invocation evaluates the scene more than 27
    // times.
    for (uint r = plane; r < kSignRows; r += gl_WorkGroupSize.x) {
        uvec3 s = brick + uvec3(0u, r % kSide, r / kSide);
        uint bits = 0u;
        float d = 0.0;
        for (uint x = 0u; x < kSide; ++x) {
            // The field is 1-Lipschitz: a cell edge h on from a value beyond 2h, this sample's
            // value has the same sign and exceeds h, so no crossed edge ends here and only its
            // sign is ever read. A lower bound serves; the exact values near the surface are
            // evaluated as before (molecule_1k at 256: the pass takes a fifth less time).
            if (x > 0u && abs(d) > 2.01 * grid.origin.w)
                d -= sign(d) * grid.origin.w;
            else
                d = sceneDistance(samplePosition(s + uvec3(x, 0u, 0u)));
            samples[block + r * kSide + x] = d;
            if (d < 0.0) bits |= 1u << x;
        }
        insideRows[r] = bits;
        records[record + kRecordSigns + r] = bits;
    }
    barrier();

    // The first SDFCSG_MESH_BRICK invocations walk a z-plane each. First walk: counts (edge
    // vertices | marching-cubes triangles << 16, dual vertices | dual triangles << 16). Second
    // walk: vertex numbers, records and the edge list.
    const bool walks = plane < SDFCSG_MESH_BRICK;
    uvec2 planeTotal = uvec2(0u);
    bool cut = false;
    for (uint y = 0u; walks && y < SDFCSG_MESH_BRICK; ++y) {
        uvec3 s0 = brick + uvec3(0u, y, plane);
        Row row = rowAt(s0, y, plane);
        planeTotal.x +=
            bitCount(row.crossed.x) + bitCount(row.crossed.y) + bitCount(row.crossed.z);
        for (uint cells = row.cells; cells != 0u; cells &= cells - 1u) {
            uint c = cellCase(findLSB(cells), y, plane);
            planeTotal += uvec2(triangleCountOf(c) << 16, patchCountOf(c));
        }
        uvec3 quads = quadEdges(row, s0);
        planeTotal.y += (bitCount(quads.x) + bitCount(quads.y) + bitCount(quads.z)) << 17;
        cut = cut || (insideRows[y + kSide * plane] & boundarySamples(s0)) != 0u;
    }
    if (cut) status[0] = 1u;

    uvec2 total;
    uvec2 before = planePrefix(planeTotal, total);
    uint next = before.x & 0xffffu; // brick-local number of the next edge vertex
    uint nextDual = before.y & 0xffffu;
    for (uint y = 0u; walks && y < SDFCSG_MESH_BRICK; ++y) {
        Row row = rowAt(brick + uvec3(0u, y, plane), y, plane);
        uint r = y + SDFCSG_MESH_BRICK * plane;
        records[record + 2u * r] = next;
        records[record + 2u * r + 1u] = row.crossed.x | row.crossed.y << 8 | row.crossed.z << 16;
        records[record + kRecordDual + r] = nextDual;
        uvec2 offsets = uvec2(0u); // byte x: the row's dual vertices before cell x
        uint before = 0u;
        for (uint cells = row.cells; cells != 0u; cells &= cells - 1u) {
            uint x = findLSB(cells);
            if (x < 4u) offsets.x |= before << (8u * x);
            else offsets.y |= before << (8u * (x - 4u));
            before += patchCountOf(cellCase(x, y, plane));
        }
        nextDual += before;
        records[record + kRecordOffsets + 2u * r] = offsets.x;
        records[record + kRecordOffsets + 2u * r + 1u] = offsets.y;
        for (uint any = row.crossed.x | row.crossed.y | row.crossed.z; any != 0u;
             any &= any - 1u) {
            uint x = findLSB(any);
            for (uint axis = 0u; axis < 3u; ++axis)
                if ((row.crossed[axis] & (1u << x)) != 0u)
                    edges[batchSlot * SDFCSG_MESH_BRICK_EDGES + next++] =
                        ownedIndex(uvec3(x, y, plane)) * 3u + axis;
        }
    }
    if (plane == 0u)
        counts[slot] = uvec4(total.x & 0xffffu, total.x >> 16, total.y & 0xffffu, total.y >> 16);
}

void placeVertices() {
    // One crossed edge of the batch per invocation, not a loop over a brick's edges: llvmpipe
    // ends every loop of an invocation for good once they have run 65535 rounds together (its
    // "loop limiter", counted over all loops, nested or not), and a scene's own loops (repeats,
    // outlines) times such a loop reached that, leaving edge points unwritten. The edge's brick
    // is the last of the batch whose first edge is not past it.
    if (push.count == 0u) return;
    uint e = gl_GlobalInvocationID.x, batchFirst = bases[push.first].x;
    uint batchSlot = 0u;
    for (uint span = push.count; span > 1u;) {
        uint part = span / 2u;
        if (bases[push.first + batchSlot + part].x - batchFirst <= e) batchSlot += part;
        span -= part;
    }
    uint slot = push.first + batchSlot;
    uint count = counts[slot].x;
    uint v = e - (bases[slot].x - batchFirst); // the edge's number in its brick
    uint first = bases[slot].x - push.vertexBase;
    if (v < count) {
        uvec3 b = brickCoords(activeBricks[slot]) * SDFCSG_MESH_BRICK;
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

        // Regula falsi on the field (grid.cells.w steps from the linear estimate; for dual
        // contouring, after each step the value at the end that stays is halved, as in the
        // Illinois variant, so that it closes in from both sides where the field bends, as at a
        // sharp edge: the planes through these points place the vertex there), then the
        // normal's four tetrahedral taps around the vertex, all through one call of the scene
        // in one loop: lavapipe's compiler inlines every call site, each a copy of the scene to
        // compile (six of them took the house's kernel three times as long). Dual contouring
        // also takes the taps around two centres a little off the point either way along
        // kNormalOffset where the point lies on a sharp edge of the solid: there the taps around
        // it straddle the edge and see a blend of both faces' normals, a plane of neither that
        // would cut the edge off, while those off it see one face each. The blend is shorter
        // than the gradient of either face, which tells those points; elsewhere (most of them)
        // four taps are all it takes.
        const uint steps = grid.cells.w;
        const bool dual = grid.cull.y > 0.0;
        uint taps = 4u;
        const float keep = dual ? 0.5 : 1.0; // the factor on the value of the end that stays
        const float e = grid.cull.z * grid.origin.w;
        const vec3 offset = grid.cull.y * grid.origin.w * kNormalOffset;
        float t = da / (da - db);
        float lo = 0.0, hi = 1.0, dlo = da, dhi = db;
        vec3 p = pa + (pb - pa) * t;
        vec3 g = vec3(0.0), gradients[3];
        for (uint k = 0u; k < steps + taps; ++k) {
            uint tap = k - steps;
            vec3 at = p;
            if (k >= steps) {
                uint centre = tap / 4u;
                at += tetraTap(int(tap % 4u)) * e +
                      (centre == 0u ? vec3(0.0) : centre == 1u ? offset : -offset);
            }
            float d = sceneDistance(at);
            if (k < steps) {
                if ((d < 0.0) == (dlo < 0.0)) {
                    lo = t;
                    dlo = d;
                    dhi *= keep;
                } else {
                    hi = t;
                    dhi = d;
                    dlo *= keep;
                }
                t = lo + (hi - lo) * (dlo / (dlo - dhi));
                p = pa + (pb - pa) * t;
            } else {
                g += tetraTap(int(tap % 4u)) * d;
                if (tap % 4u == 3u) {
                    gradients[tap / 4u] = g;
                    // The taps sum to 4 e times the gradient, whose length is 1 on a face.
                    if (dual && tap == 3u && abs(length(g) - 4.0 * e) > kBlendedGradient * 4.0 * e)
                        taps = 12u;
                    g = vec3(0.0);
                }
            }
        }
        // Dual contouring: where the gradients off the point either way disagree, the point lies
        // on a sharp edge, and they are the normals of its two faces.
        vec3 g0 = gradients[0], other = g0;
        if (taps > 4u) {
            vec3 a = normalize(gradients[1]), b = normalize(gradients[2]);
            if (dot(a, b) < 0.98) {
                g0 = a;
                other = b;
            }
        }
        vec3 n = length(g0) > 1e-20 ? normalize(g0) : vec3(step) * (db > da ? 1.0 : -1.0);
        other = length(other) > 1e-20 ? normalize(other) : n;
        vec3 c = sceneSample(p).rgb;

        uint o = (first + v) * 3u;
        vertices[o] = vec4(p, c.r);
        vertices[o + 1u] = vec4(n, c.g);
        vertices[o + 2u] = vec4(other, c.b);
    }
}

void main() {
    if (kPass == SDFCSG_MESH_PASS_CULL) cull();
    else if (kPass == SDFCSG_MESH_PASS_CLASSIFY) classify();
    else placeVertices();
}
