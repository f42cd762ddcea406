// The marching-cubes tables (engine/src/mc_tables.cpp), as packed by engine/src/mesh.cpp.
layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_TABLES) readonly buffer MeshTables {
    // Cases have corners in canonical order (see cellCase() in mesh_rows.glsl).
    // [0, 256): triangles per case; [256, 1280): per case, 4 words of edge numbers, one byte
    // each, 3 per triangle; [1280, 1292): per edge, the offset of its lower corner
    // (x | y << 1 | z << 2) | axis << 3.
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
