// Declarations shared by the mesh-extraction kernels (engine/src/mesh/mesh.cpp drives them). The grid
// has cells.xyz cells of edge origin.w; sample s (0 <= s <= cells) lies at origin.xyz + s * w.
// Inside is d < 0. See engine/include/sdfcsg/mesh.h for the algorithm.

// Mirrors MeshGrid in engine/src/mesh/mesh.cpp (std140).
layout(std140, set = 0, binding = SDFCSG_BINDING_MESH_GRID) uniform MeshGrid {
    vec4 origin; // xyz: position of sample 0; w: cell edge length
    uvec4 cells; // xyz: cells per axis; w: root-finding steps per vertex
    uvec4 bricks; // xyz: bricks per axis
    // x: a brick whose centre value exceeds this in magnitude holds no surface; y: for dual
    // contouring, how far (in cells, along kNormalOffset) two more centres of the taps of an
    // edge point's normal lie off it, 0 for marching cubes; z: the taps' size, in cells
    vec4 cull;
} grid;

// A direction away from the planes x = +-y, y = +-z, z = +-x and the axis planes (by 0.15 or
// more), where sharp edges of CSG solids often lie, exactly on grid edges of a symmetric grid.
const vec3 kNormalOffset = vec3(0.218218, 0.436436, 0.872872); // (1, 2, 4) / sqrt(21)
// Where the field's gradient has length 1 on every face, taps whose gradient is longer or
// shorter than that by more than this fraction straddle a sharp edge (or lie in a blend, or on a
// field that is not a distance, where extra taps cost time but no accuracy).
const float kBlendedGradient = 0.001;

layout(push_constant) uniform MeshPush {
    uint first;         // cull: first brick; others: slot of the batch's first brick
    uint count;         // bricks in this dispatch
    uint vertexBase;    // first vertex of the batch (the vertex buffer holds the batch's only)
    uint triangleBase;  // first triangle of the batch
} push;

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_ACTIVE) readonly buffer MeshActive {
    uint activeBricks[];
};

layout(std430, set = 0, binding = SDFCSG_BINDING_MESH_STATUS) buffer MeshStatus {
    uint status[]; // [0]: an inside sample lies on the grid boundary; [1]: see triangles
};

uvec3 brickCoords(uint brick) {
    return uvec3(brick % grid.bricks.x, (brick / grid.bricks.x) % grid.bricks.y,
                 brick / (grid.bricks.x * grid.bricks.y));
}

vec3 samplePosition(uvec3 s) {
    return grid.origin.xyz + vec3(s) * grid.origin.w;
}

// Index in a brick's block of SDFCSG_MESH_BRICK_SAMPLES^3 values.
uint blockIndex(uvec3 l) {
    return l.x + SDFCSG_MESH_BRICK_SAMPLES * (l.y + SDFCSG_MESH_BRICK_SAMPLES * l.z);
}

bool onGridBoundary(uvec3 s) {
    return any(equal(s, uvec3(0))) || any(equal(s, grid.cells.xyz));
}
