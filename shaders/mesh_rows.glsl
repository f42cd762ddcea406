// Brick-wide work of the classify and triangle passes. In their workgroups one invocation per
// z-plane of the brick (the first SDFCSG_MESH_BRICK of them) walks its plane's rows of owned
// samples along x. A row's signs are one word (bit x: sample x is inside), so its crossed edges
// and the cells that the surface passes through are a few bit operations; and a brick needs one
// barrier for its prefix sum, not one per step of a tree scan (CPU drivers run such a workgroup
// as one SIMD row, where a barrier costs a context switch).

const uint kSide = SDFCSG_MESH_BRICK_SAMPLES;
const uint kSignRows = kSide * kSide;
const uint kRecordDual = 2u * SDFCSG_MESH_BRICK * SDFCSG_MESH_BRICK;  // offsets in a record
const uint kRecordSigns = 3u * SDFCSG_MESH_BRICK * SDFCSG_MESH_BRICK;
const uint kRecordOffsets = kRecordSigns + kSignRows;

// Bit x of insideRows[y + kSide * z] is set when sample (x, y, z) of the block is inside.
shared uint insideRows[kSignRows];
shared uvec2 planeTotals[SDFCSG_MESH_BRICK];

// Returns the sum of `planeTotal` over the planes before this invocation's; `total` gets the
// sum over all planes. Every invocation of the workgroup must call it; those past the planes'
// have no total.
uvec2 planePrefix(uvec2 planeTotal, out uvec2 total) {
    uint plane = gl_LocalInvocationID.x;
    if (plane < SDFCSG_MESH_BRICK) planeTotals[plane] = planeTotal;
    barrier();
    uvec2 before = uvec2(0u);
    total = uvec2(0u);
    for (uint k = 0u; k < SDFCSG_MESH_BRICK; ++k) {
        if (k < plane) before += planeTotals[k];
        total += planeTotals[k];
    }
    return before;
}

// Bits 0 .. count-1 set, for count in 0..32.
uint lowBits(uint count) {
    return count >= 32u ? 0xffffffffu : (1u << count) - 1u;
}

uint ownedIndex(uvec3 l) {
    return l.x + SDFCSG_MESH_BRICK * (l.y + SDFCSG_MESH_BRICK * l.z);
}

// The row of owned samples starting at grid sample s0 (x = 0 of its brick).
struct Row {
    uvec3 crossed; // per axis, over x: the edge from sample x along that axis is crossed
    uint cells;    // over x: the cell at sample x lies in the grid and the surface crosses it
};

Row rowAt(uvec3 s0, uint y, uint z) {
    uint r00 = insideRows[y + kSide * z], r10 = insideRows[y + 1u + kSide * z];
    uint r01 = insideRows[y + kSide * (z + 1u)], r11 = insideRows[y + 1u + kSide * (z + 1u)];
    // What lies in the grid, over x.
    uvec3 left = grid.cells.xyz - min(s0, grid.cells.xyz); // cells from s0 to the far side
    bool rowIn = s0.y <= grid.cells.y && s0.z <= grid.cells.z;
    uint owned = lowBits(SDFCSG_MESH_BRICK);
    uint samplesIn = rowIn ? lowBits(left.x + 1u) & owned : 0u;
    uint edgesX = rowIn ? lowBits(left.x) & owned : 0u;
    uint cellsIn = left.y > 0u && left.z > 0u ? edgesX : 0u;
    Row row;
    row.crossed = uvec3((r00 ^ (r00 >> 1)) & edgesX, left.y > 0u ? (r00 ^ r10) & samplesIn : 0u,
                        left.z > 0u ? (r00 ^ r01) & samplesIn : 0u);
    uint any = r00 | (r00 >> 1) | r10 | (r10 >> 1) | r01 | (r01 >> 1) | r11 | (r11 >> 1);
    uint all = r00 & (r00 >> 1) & r10 & (r10 >> 1) & r01 & (r01 >> 1) & r11 & (r11 >> 1);
    row.cells = any & ~all & cellsIn;
    return row;
}

// The marching-cubes case of the cell at sample x of row (y, z), with corners in canonical
// order (bit ox + 2 oy + 4 oz for the corner at offset (ox, oy, oz)); engine/src/mesh/mesh.cpp packs
// the tables in that order.
uint cellCase(uint x, uint y, uint z) {
    uint r00 = insideRows[y + kSide * z] >> x, r10 = insideRows[y + 1u + kSide * z] >> x;
    uint r01 = insideRows[y + kSide * (z + 1u)] >> x;
    uint r11 = insideRows[y + 1u + kSide * (z + 1u)] >> x;
    return (r00 & 3u) | (r10 & 3u) << 2 | (r01 & 3u) << 4 | (r11 & 3u) << 6;
}

// Dual contouring: the crossed edges of a row that get a quad, over x per axis: those whose four
// cells all lie in the grid (the others are on its boundary, where the surface is cut).
uvec3 quadEdges(Row row, uvec3 s0) {
    uvec3 c = grid.cells.xyz;
    bvec3 rowInner = bvec3(true, s0.y >= 1u && s0.y < c.y, s0.z >= 1u && s0.z < c.z);
    uint xInner = (s0.x < c.x ? lowBits(c.x - s0.x) : 0u) & (s0.x == 0u ? ~1u : ~0u);
    return uvec3(rowInner.y && rowInner.z ? row.crossed.x : 0u,
                 rowInner.z ? row.crossed.y & xInner : 0u,
                 rowInner.y ? row.crossed.z & xInner : 0u);
}
