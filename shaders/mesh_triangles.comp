#version 450
// The mesh-extraction passes that read no scene, one kernel specialised three ways. Each runs
// one workgroup per brick of the batch, one invocation per z-plane of the brick (see
// mesh_rows.glsl).
//   triangles:      marching cubes: the triangles of the brick's cells from the table. Each
//                   corner is the vertex of a crossed edge, numbered by the brick that owns the
//                   edge's lower sample (this one or a neighbour): that brick's first vertex, plus
//                   the number of its row's first vertex, plus the crossed edges before it in the
//                   row (see the classify pass in mesh_field.comp).
//   dual:           dual contouring: one vertex per piece of surface in each cell (the pieces of
//                   its marching-cubes case), where the planes through the piece's edge vertices
//                   along their normals meet best (a quadratic error function), kept in the cell;
//                   then for each crossed edge, the quad that joins the vertices of the four
//                   cells around it, as two triangles. One pass for both: they share the loads
//                   of the brick's rows, and a dispatch and its wait.
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "mesh_common.glsl"
#include "mesh_rows.glsl"
#include "mesh_tables.glsl"

// SDFCSG_MESH_BRICK invocations for the triangles; for the dual passes, whose first
// SDFCSG_MESH_BRICK list the work that all then share, as many or SDFCSG_MESH_GROUP_X (on GPUs).
layout(local_size_x_id = SDFCSG_SPEC_MESH_GROUP) in;

layout(constant_id = SDFCSG_SPEC_MESH_PASS) const uint kPass = SDFCSG_MESH_PASS_TRIANGLES;

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_MAP) readonly buffer MeshMap {
    uint map[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_RECORDS) readonly buffer MeshRecords {
    uint records[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_BASES) readonly buffer MeshBases {
    uvec4 bases[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_INDICES) writeonly buffer MeshIndices {
    uint indices[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_COUNTS) readonly buffer MeshCounts {
    uvec4 counts[];
};

// Every edge point, as the vertices pass in mesh_field.comp wrote it.
layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_HERMITE) readonly buffer MeshHermite {
    vec4 hermite[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_VERTICES) writeonly buffer MeshVertices {
    float vertices[];
};

// The vertex numbering of every row of samples the brick's cells reach: rows (y, z) of the
// block, each split into its samples x < 8 (brick (0, y / 8, z / 8) from this one) and x = 8
// (brick (1, ...)): the number of the part's first vertex, and its crossed edges as in the
// records (x edges in bits 0-7, y in 8-15, z in 16-23). Filled once per brick, so that each
// triangle corner reads shared memory instead of four buffers.
shared uvec2 rowVertices[2u * kSignRows];

void loadRowVertices(uint slot, uvec3 brick) {
    for (uint i = gl_LocalInvocationID.x; i < 2u * kSignRows; i += gl_WorkGroupSize.x) {
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

void loadBrick(uint slot, uvec3 b) {
    for (uint r = gl_LocalInvocationID.x; r < kSignRows; r += gl_WorkGroupSize.x)
        insideRows[r] = records[slot * SDFCSG_MESH_RECORD + kRecordSigns + r];
    loadRowVertices(slot, b);
    barrier();
}

void emitTriangles(uint slot, uvec3 brick) {
    uint plane = gl_LocalInvocationID.x;
    uint planeTotal = 0u;
    for (uint y = 0u; y < SDFCSG_MESH_BRICK; ++y)
        for (uint cells = rowAt(brick + uvec3(0u, y, plane), y, plane).cells; cells != 0u;
             cells &= cells - 1u)
            planeTotal += triangleCountOf(cellCase(findLSB(cells), y, plane));
    uvec2 total;
    uint next = bases[slot].y - push.triangleBase + planePrefix(uvec2(planeTotal, 0u), total).x;
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

// The symmetric 3x3 matrix a as V diag(lambda) V^T, by cyclic Jacobi rotations; lambda is
// returned in a's diagonal, V in v (columns).
void eigenSymmetric(inout mat3 a, out mat3 v) {
    v = mat3(1.0);
    for (int sweep = 0; sweep < 4; ++sweep)
        for (int k = 0; k < 3; ++k) {
            int p = k == 2 ? 1 : 0, q = k == 0 ? 1 : 2;
            float apq = a[p][q];
            if (abs(apq) < 1e-12) continue;
            float theta = (a[q][q] - a[p][p]) / (2.0 * apq);
            float t = (theta >= 0.0 ? 1.0 : -1.0) / (abs(theta) + sqrt(theta * theta + 1.0));
            float c = inversesqrt(t * t + 1.0), s = t * c;
            // a = J^T (a J) and v = v J, for J the rotation in the (p, q) plane: a J mixes
            // columns p and q, J^T then rows p and q.
            vec3 ap = a[p], aq = a[q];
            a[p] = c * ap - s * aq;
            a[q] = s * ap + c * aq;
            for (int i = 0; i < 3; ++i) {
                float bp = a[i][p], bq = a[i][q];
                a[i][p] = c * bp - s * bq;
                a[i][q] = s * bp + c * bq;
            }
            vec3 vp = v[p], vq = v[q];
            v[p] = c * vp - s * vq;
            v[q] = s * vp + c * vq;
        }
}

// The point of the cell [lo, lo + h] nearest, in the least-squares sense, to the planes through
// points p_k with normals n_k, from the sums ata = sum n n^T, atb = sum n (n . (p - mass)) and
// the mass point (the mean of the p_k). Directions in which the planes barely constrain it
// (eigenvalues under a hundredth of the largest) keep the mass point's coordinate, so flat and
// curved pieces stay where their points are. Where the best point lies outside the cell, it
// moves along the least constrained direction into the cell if it can, so that a vertex meant
// for a sharp edge that only clips the cell stays on that edge; otherwise it is clamped, or for
// a slab (normals that face nearly opposite ways) it is the mass point.
vec3 solveQef(mat3 ata, vec3 atb, vec3 mass, vec3 lo, float h, bool slab) {
    mat3 v;
    eigenSymmetric(ata, v);
    vec3 lambda = vec3(ata[0][0], ata[1][1], ata[2][2]);
    float largest = max(lambda.x, max(lambda.y, lambda.z));
    int weakest = lambda.x <= lambda.y && lambda.x <= lambda.z ? 0 : lambda.y <= lambda.z ? 1 : 2;
    vec3 x = vec3(0.0);
    int rank = 0;
    for (int k = 0; k < 3; ++k)
        if (lambda[k] > 0.01 * largest && lambda[k] > 1e-12) {
            if (k != weakest) x += v[k] * (dot(v[k], atb) / lambda[k]);
            ++rank;
        }
    vec3 best = mass + x + (rank == 3 ? v[weakest] * (dot(v[weakest], atb) / lambda[weakest]) : vec3(0.0));
    vec3 hi = lo + h;
    if (all(greaterThanEqual(best, lo)) && all(lessThanEqual(best, hi))) return best;
    if (rank >= 2) {
        // Along the weakest direction from the best point with it left free.
        vec3 base = mass + x, dir = v[weakest];
        float s0 = -1e30, s1 = 1e30;
        for (int i = 0; i < 3; ++i) {
            if (abs(dir[i]) < 1e-6) {
                if (base[i] < lo[i] || base[i] > hi[i]) s0 = 1e30;
                continue;
            }
            float a = (lo[i] - base[i]) / dir[i], b = (hi[i] - base[i]) / dir[i];
            s0 = max(s0, min(a, b));
            s1 = min(s1, max(a, b));
        }
        float wanted = rank == 3 ? dot(v[weakest], atb) / lambda[weakest] : 0.0;
        if (s0 <= s1) return clamp(base + dir * clamp(wanted, s0, s1), lo, hi);
    }
    // Sheets that face nearly opposite ways and meet outside the cell bound a slab thinner than
    // the cell: no point of the cell lies on both, and clamping would pull the vertex to the
    // cell's side nearest their meeting line, folding the quads of the two sheets over each
    // other. The mass point lies between them.
    if (slab) return mass;
    return clamp(best, lo, hi);
}


// Pieces whose normals all lie within this cosine of the first one's are placed without the
// eigenvectors: with a hundredth of the largest eigenvalue as the cut (solveQef), all but the
// normal direction would be dropped anyway.
const float kFlat = 0.995;

// Pieces with two normals further apart than this cosine (143 degrees) are slabs for solveQef().
const float kSlab = -0.8;

// Vertices keep this fraction of a cell from the faces of their cell: vertices of neighbouring
// cells then never coincide (a pinch in the surface), and seen along its edge the four of each
// quad lie strictly around it, so that foldQuads() on the host finds a diagonal whose triangles
// both wind around the edge.
const float kInset = 0.005;

// The dual passes' work items, listed by the first SDFCSG_MESH_BRICK invocations: the dual
// vertices (owned cell | piece << 9 | case << 11) or the quads (owned sample | axis << 9 |
// 1 << 11 when its lower end is inside).
shared uint workList[4u * SDFCSG_MESH_BRICK * SDFCSG_MESH_BRICK * SDFCSG_MESH_BRICK];

uvec3 ownedCoords(uint owned) {
    return uvec3(owned % SDFCSG_MESH_BRICK, (owned / SDFCSG_MESH_BRICK) % SDFCSG_MESH_BRICK,
                 owned / (SDFCSG_MESH_BRICK * SDFCSG_MESH_BRICK));
}

void emitDualVertices(uint slot, uvec3 brick) {
    uint plane = gl_LocalInvocationID.x;
    if (plane < SDFCSG_MESH_BRICK)
        for (uint y = 0u; y < SDFCSG_MESH_BRICK; ++y) {
            uint next = records[slot * SDFCSG_MESH_RECORD + kRecordDual + y +
                                SDFCSG_MESH_BRICK * plane];
            for (uint cells = rowAt(brick + uvec3(0u, y, plane), y, plane).cells; cells != 0u;
                 cells &= cells - 1u) {
                uint x = findLSB(cells), c = cellCase(x, y, plane);
                for (uint piece = 0u; piece < patchCountOf(c); ++piece)
                    workList[next++] = ownedIndex(uvec3(x, y, plane)) | piece << 9 | c << 11;
            }
        }
    barrier();

    uint first = bases[slot].z - push.vertexBase;
    for (uint i = gl_LocalInvocationID.x; i < counts[slot].z; i += gl_WorkGroupSize.x) {
        uint item = workList[i];
        uvec3 l = ownedCoords(item & 511u);
        uint piece = (item >> 9) & 3u, c = item >> 11;
        // One pass, in coordinates from the cell's corner lo:
        // sum n (n . (p - mass)) = sum n (n . p) - (sum n n^T) mass.
        vec3 lo = samplePosition(brick + l);
        vec3 mass = vec3(0.0), normal = vec3(0.0), color = vec3(0.0), atp = vec3(0.0);
        mat3 ata = mat3(0.0);
        uint n = 0u;
        float leastCos = 1.0; // between any normal and the first
        vec3 first0 = vec3(0.0);
        bool mixed = false; // the edge points have more than one colour
        for (uint edges = pieceEdges(c, piece); edges != 0u; edges &= edges - 1u) {
            uint h = vertexIndex(l, findLSB(edges));
            vec4 a = hermite[3u * h], b = hermite[3u * h + 1u], d = hermite[3u * h + 2u];
            vec3 point = a.xyz - lo, n0 = b.xyz, n1 = d.xyz;
            vec3 rgb = vec3(a.w, b.w, d.w);
            if (n == 0u) {
                first0 = n0;
                color = rgb;
            }
            mixed = mixed || rgb != color;
            leastCos = min(leastCos, min(dot(n0, first0), dot(n1, first0)));
            mass += point;
            normal += n0 + n1;
            ata += outerProduct(n0, n0) + outerProduct(n1, n1);
            atp += n0 * dot(n0, point) + n1 * dot(n1, point);
            ++n;
        }
        mass /= float(n);
        vec3 atb = atp - ata * mass;
        vec3 p;
        if (leastCos > kFlat) {
            // A flat or gently curved piece: the mass point moved onto the mean plane.
            vec3 mean = normalize(normal);
            p = lo + clamp(mass + mean * (dot(mean, atb) / dot(mean, ata * mean)), vec3(0.0),
                           vec3(grid.origin.w));
        } else {
            p = lo + solveQef(ata, atb, mass, vec3(0.0), grid.origin.w, leastCos < kSlab);
        }
        p = clamp(p, lo + kInset * grid.origin.w, lo + (1.0 - kInset) * grid.origin.w);
        // Where the normals of a piece nearly cancel (a sheet thinner than a cell), the first one.
        normal = length(normal) > 0.1 ? normalize(normal) : first0;
        // The colour of the nearest edge point: a mean would blend the colours of two operands
        // into one that the scene does not have.
        float nearest = 1e30;
        for (uint edges = mixed ? pieceEdges(c, piece) : 0u; edges != 0u; edges &= edges - 1u) {
            uint h = vertexIndex(l, findLSB(edges));
            vec4 a = hermite[3u * h];
            vec3 d = a.xyz - p;
            if (dot(d, d) < nearest) {
                nearest = dot(d, d);
                color = vec3(a.w, hermite[3u * h + 1u].w, hermite[3u * h + 2u].w);
            }
        }
        // The mean of the edge points, where the host moves vertices whose quads fold.
        vec3 centre = clamp(lo + mass, lo + kInset * grid.origin.w,
                            lo + (1.0 - kInset) * grid.origin.w);
        uint o = (first + i) * 12u;
        vertices[o + 0u] = p.x;
        vertices[o + 1u] = p.y;
        vertices[o + 2u] = p.z;
        vertices[o + 3u] = normal.x;
        vertices[o + 4u] = normal.y;
        vertices[o + 5u] = normal.z;
        vertices[o + 6u] = color.r;
        vertices[o + 7u] = color.g;
        vertices[o + 8u] = color.b;
        vertices[o + 9u] = centre.x;
        vertices[o + 10u] = centre.y;
        vertices[o + 11u] = centre.z;
    }
}

// The rows of cells that the quads of the brick's edges reach, (y, z) in -1..7 (index
// (y + 1) + 9 (z + 1)), each split into its cell x = -1 (part 0, from the brick before this one
// along x) and its cells 0..7 (part 1, index 2 row + part): the first dual vertex of the row in
// its brick (0xffffffff where the brick was skipped), a byte per cell x of its dual vertices
// before it in the row (two words), and a byte per cell x of its case (two words).
shared uint dualFirst[162];
shared uvec4 dualCells[162];

void loadDualCells(uint slot, uvec3 b) {
    for (uint i = gl_LocalInvocationID.x; i < 2u * 81u; i += gl_WorkGroupSize.x) {
        uint r = i >> 1, part = i & 1u;
        uint y = r % 9u, z = r / 9u; // cell y - 1, z - 1
        uvec3 before = uvec3(1u - part, y == 0u ? 1u : 0u, z == 0u ? 1u : 0u);
        uint owner = SDFCSG_MESH_NO_BRICK;
        if (all(greaterThanEqual(b, before))) {
            uvec3 nb = b - before;
            owner = before == uvec3(0u) ? slot
                                        : map[nb.x + grid.bricks.x * (nb.y + grid.bricks.y * nb.z)];
        }
        uint ly = before.y == 1u ? 7u : y - 1u, lz = before.z == 1u ? 7u : z - 1u;
        uint first = 0xffffffffu;
        uvec4 cells = uvec4(0u);
        if (owner != SDFCSG_MESH_NO_BRICK) {
            uint record = owner * SDFCSG_MESH_RECORD, row = ly + SDFCSG_MESH_BRICK * lz;
            uint signs = record + kRecordSigns + ly + kSide * lz;
            uint r00 = records[signs], r10 = records[signs + 1u];
            uint r01 = records[signs + kSide], r11 = records[signs + kSide + 1u];
            first = bases[owner].z + records[record + kRecordDual + row];
            cells.xy = uvec2(records[record + kRecordOffsets + 2u * row],
                             records[record + kRecordOffsets + 2u * row + 1u]);
            // The eight cases, a byte each: bits x and x + 1 of the row words are cell x's.
            for (uint k = 0u; k < 4u; ++k) {
                uint lo = 8u * k;
                uint c0 = (r00 >> k & 3u) | (r10 >> k & 3u) << 2 | (r01 >> k & 3u) << 4 |
                          (r11 >> k & 3u) << 6;
                uint c1 = (r00 >> (k + 4u) & 3u) | (r10 >> (k + 4u) & 3u) << 2 |
                          (r01 >> (k + 4u) & 3u) << 4 | (r11 >> (k + 4u) & 3u) << 6;
                cells.z |= c0 << lo;
                cells.w |= c1 << lo;
            }
        }
        dualFirst[i] = first;
        dualCells[i] = cells;
    }
}

// The dual vertex of cell c (brick-local, -1..7 per axis) on its edge from the corner at offset
// `corner` along `axis`.
uint dualVertex(ivec3 c, uvec3 corner, uint axis) {
    uint part = c.x < 0 ? 0u : 1u, x = c.x < 0 ? 7u : uint(c.x);
    uint entry = 2u * uint(c.y + 1 + 9 * (c.z + 1)) + part;
    uint first = dualFirst[entry];
    if (first == 0xffffffffu) {
        status[1] = 1u; // the field is not 1-Lipschitz here; the host meshes again
        return 0u;
    }
    uvec4 cells = dualCells[entry];
    uint shift = 8u * (x & 3u);
    uint before = ((x < 4u ? cells.x : cells.y) >> shift) & 255u;
    uint cellCase = ((x < 4u ? cells.z : cells.w) >> shift) & 255u;
    return first + before + patchOf(cellCase, edgeAt(corner, axis));
}

void emitQuads(uint slot, uvec3 brick) {
    uint plane = gl_LocalInvocationID.x;
    if (plane < SDFCSG_MESH_BRICK) {
        uint planeTotal = 0u;
        for (uint y = 0u; y < SDFCSG_MESH_BRICK; ++y) {
            uvec3 quads = quadEdges(rowAt(brick + uvec3(0u, y, plane), y, plane),
                                    brick + uvec3(0u, y, plane));
            planeTotal += bitCount(quads.x) + bitCount(quads.y) + bitCount(quads.z);
        }
        planeTotals[plane] = uvec2(planeTotal, 0u);
    }
    barrier();
    if (plane < SDFCSG_MESH_BRICK) {
        uint next = 0u;
        for (uint k = 0u; k < plane; ++k)
            next += planeTotals[k].x;
        for (uint y = 0u; y < SDFCSG_MESH_BRICK; ++y) {
            uvec3 quads = quadEdges(rowAt(brick + uvec3(0u, y, plane), y, plane),
                                    brick + uvec3(0u, y, plane));
            uint inside = insideRows[y + kSide * plane];
            for (uint any = quads.x | quads.y | quads.z; any != 0u; any &= any - 1u) {
                uint x = findLSB(any);
                for (uint axis = 0u; axis < 3u; ++axis)
                    if ((quads[axis] & (1u << x)) != 0u)
                        workList[next++] = ownedIndex(uvec3(x, y, plane)) | axis << 9 |
                                           ((inside >> x) & 1u) << 11;
            }
        }
    }
    barrier();

    uint first = bases[slot].w - push.triangleBase;
    for (uint i = gl_LocalInvocationID.x; i < counts[slot].w / 2u; i += gl_WorkGroupSize.x) {
        uint item = workList[i];
        ivec3 l = ivec3(ownedCoords(item & 511u));
        uint axis = (item >> 9) & 3u;
        bool inside = (item >> 11) != 0u;
        // The four cells around the edge, counter-clockwise seen from its upper end.
        ivec3 u = ivec3(equal(uvec3((axis + 1u) % 3u), uvec3(0, 1, 2)));
        ivec3 v = ivec3(equal(uvec3((axis + 2u) % 3u), uvec3(0, 1, 2)));
        uint q0 = dualVertex(l - u - v, uvec3(u + v), axis);
        uint q1 = dualVertex(l - v, uvec3(v), axis);
        uint q2 = dualVertex(l, uvec3(0u), axis);
        uint q3 = dualVertex(l - u, uvec3(u), axis);
        // Outward (towards d > 0) is along the axis when the lower end is inside. As (a, b, c),
        // (a, c, d), the second starting at its axis'th corner: the host reads the edge's axis
        // from it and may split the quad along b-d instead (foldQuads in mesh_dual.cpp).
        uvec3 t0 = inside ? uvec3(q0, q1, q2) : uvec3(q0, q3, q2);
        uvec3 t1 = inside ? uvec3(q0, q2, q3) : uvec3(q0, q2, q1);
        t1 = axis == 0u ? t1 : axis == 1u ? t1.yzx : t1.zxy;
        // Seven words per quad: its triangles, then its edge point's number in the edge data,
        // which the host splits the quad at where its triangles cross others
        // (separateCrossings in mesh_dual.cpp).
        uint o = (first / 2u + i) * 7u;
        indices[o + 0u] = t0.x;
        indices[o + 1u] = t0.y;
        indices[o + 2u] = t0.z;
        indices[o + 3u] = t1.x;
        indices[o + 4u] = t1.y;
        indices[o + 5u] = t1.z;
        indices[o + 6u] = vertexIndex(uvec3(l), edgeAt(uvec3(0u), axis));
    }
}

void main() {
    if (gl_WorkGroupID.x >= push.count) return; // uniform in the workgroup
    uint slot = push.first + gl_WorkGroupID.x;
    uvec3 b = brickCoords(activeBricks[slot]);
    uvec3 brick = b * SDFCSG_MESH_BRICK;
    if (kPass == SDFCSG_MESH_PASS_TRIANGLES) {
        loadBrick(slot, b);
        emitTriangles(slot, brick);
        return;
    }
    loadDualCells(slot, b);
    loadBrick(slot, b);
    emitDualVertices(slot, brick);
    barrier(); // the quads reuse the work list
    emitQuads(slot, brick);
}
