// The marching-cubes tables (engine/src/mesh/mc_tables.cpp), as packed by engine/src/mesh/mesh.cpp.
layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_TABLES) readonly buffer MeshTables {
    // Cases have corners in canonical order (see cellCase() in mesh_rows.glsl).
    // [0, 256): triangles per case; [256, 1280): per case, 4 words of edge numbers, one byte
    // each, 3 per triangle; [1280, 1292): per edge, the offset of its lower corner
    // (x | y << 1 | z << 2) | axis << 3; [1292, 1548): per case, its pieces of surface
    // (mc_tables.h, CellPatches): the count in bits 0-2, the piece of edge e in bits 3 + 2e;
    // [1548, 1572): the edge from the corner at offset bits o along axis a, at 1548 + 8a + o;
    // [1572, 2596): per case and piece (4 c + k), the piece's edges, bit e for edge e.
    uint tables[];
};

uint triangleCountOf(uint cellCase) {
    return tables[cellCase];
}

// Edge number k (0 <= k < 3 * triangles) of a case's triangle list.
uint triangleEdge(uint cellCase, uint k) {
    return (tables[256u + cellCase * 4u + k / 4u] >> (8u * (k % 4u))) & 0xffu;
}

uvec3 offsetBits(uint bits) {
    return uvec3(bits & 1u, (bits >> 1) & 1u, (bits >> 2) & 1u);
}

// Dual contouring: a case's pieces of surface, and the piece that crossed edge `edge` belongs to.
uint patchCountOf(uint cellCase) {
    return tables[1292u + cellCase] & 7u;
}

uint patchOf(uint cellCase, uint edge) {
    return (tables[1292u + cellCase] >> (3u + 2u * edge)) & 3u;
}

uint edgeAt(uvec3 offset, uint axis) {
    return tables[1548u + 8u * axis + offset.x + 2u * offset.y + 4u * offset.z];
}

uint pieceEdges(uint cellCase, uint piece) {
    return tables[1572u + 4u * cellCase + piece];
}
