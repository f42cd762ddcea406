// The node buffer that generated scene code reads. Layout (std430, 128 bytes a node) mirrors
// GpuNode in engine/src/gpu_nodes.h; node i is scene node i.
struct Node {
    vec4 row0, row1, row2; // world -> local affine: local = vec3(dot(row0, vec4(p, 1)), ...)
    vec4 p0, p1;           // parameters, slots 0..7 as in the node kind table
    vec4 color;            // rgb resolved colour; w: accumulated scale (world = scale * local)
    vec4 bmin;             // xyz: world bounds minimum; w: smooth radius in world units
    vec4 bmax;             // xyz: world bounds maximum
};

layout(std430, set = 0, binding = SDFCSG_BINDING_NODES) readonly buffer Nodes {
    Node nodes[];
};

// Off for the benchmark's baseline: every operand is evaluated.
layout(constant_id = SDFCSG_SPEC_BOUNDS_SKIPPING) const bool kBoundsSkipping = true;

vec3 toLocal(uint i, vec3 p) {
    vec4 q = vec4(p, 1.0);
    return vec3(dot(nodes[i].row0, q), dot(nodes[i].row1, q), dot(nodes[i].row2, q));
}

float boundsDistance(vec3 bmin, vec3 bmax, vec3 p) {
    vec3 d = max(max(bmin - p, p - bmax), vec3(0.0));
    return length(d);
}

float nodeBoundsDistance(uint i, vec3 p) {
    return boundsDistance(nodes[i].bmin.xyz, nodes[i].bmax.xyz, p);
}
