// Brick-wide prefix sums for the classify and triangle passes. Their workgroups have one
// invocation per z-plane of the brick (SDFCSG_MESH_BRICK of them), each walking its plane's
// owned samples in order, so a brick needs one barrier, not one per step of a tree scan: CPU
// drivers run such a workgroup as one SIMD row, where every barrier costs a context switch.
shared uint planeTotals[SDFCSG_MESH_BRICK];

// Returns the sum of `planeTotal` over the planes before this invocation's; `total` gets the
// sum over all planes. Every invocation of the workgroup must call it.
uint planePrefix(uint planeTotal, out uint total) {
    uint plane = gl_LocalInvocationID.x;
    planeTotals[plane] = planeTotal;
    barrier();
    uint before = 0u;
    total = 0u;
    for (uint k = 0u; k < SDFCSG_MESH_BRICK; ++k) {
        if (k < plane) before += planeTotals[k];
        total += planeTotals[k];
    }
    return before;
}

// Brick-local coordinates of the i-th owned sample of a plane (x fastest).
uvec3 planeSample(uint i) {
    return uvec3(i % SDFCSG_MESH_BRICK, i / SDFCSG_MESH_BRICK, gl_LocalInvocationID.x);
}

uint ownedIndex(uvec3 l) {
    return l.x + SDFCSG_MESH_BRICK * (l.y + SDFCSG_MESH_BRICK * l.z);
}
