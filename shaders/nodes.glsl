// The node buffer that generated scene code reads. Layout (std430, 128 bytes a node) mirrors
// GpuNode in engine/src/codegen/gpu_nodes.h; node i is scene node i.
struct Node {
    vec4 row0, row1, row2; // world -> local affine: local = vec3(dot(row0, vec4(p, 1)), ...)
    vec4 p0, p1;           // kernel parameters (half extents etc.), see kernelParams() in sdf.h
    vec4 color;            // rgb resolved colour; w: accumulated scale (world = scale * local)
    vec4 bmin;             // xyz: world bounds minimum; w: smooth radius in world units
                           // (primitives: 1 where the value is floored at the bounds)
    vec4 bmax;             // xyz: world bounds maximum; w: blend profile (sdf.glsl)
};

layout(std430, set = 0, binding = SDFCSG_BINDING_NODES) readonly buffer Nodes {
    Node nodes[];
};

// Off for the benchmark's baseline: every operand is evaluated.
layout(constant_id = SDFCSG_SPEC_BOUNDS_SKIPPING) const bool kBoundsSkipping = true;

vec3 affine(vec4 row0, vec4 row1, vec4 row2, vec3 p) {
    vec4 q = vec4(p, 1.0);
    return vec3(dot(row0, q), dot(row1, q), dot(row2, q));
}

vec3 toLocal(uint i, vec3 p) { return affine(nodes[i].row0, nodes[i].row1, nodes[i].row2, p); }

// Signed distance to a box: a lower bound of the value of every node inside it (outside, the
// solid is no nearer than its box; inside, its boundary is no farther than the box's). Same
// formula as Aabb::signedDistance in engine/src/field/eval.cpp.
float boundsDistance(vec3 bmin, vec3 bmax, vec3 p) {
    vec3 q = max(bmin - p, p - bmax);
    return length(max(q, 0.0)) + min(max(q.x, max(q.y, q.z)), 0.0);
}

float nodeBoundsDistance(uint i, vec3 p) {
    return boundsDistance(nodes[i].bmin.xyz, nodes[i].bmax.xyz, p);
}

// Primitive i's value d at p, floored at its bounds' signed distance where it is flagged (a scale
// that differs per axis: FlatNode::boundsFloor in sdfcsg/eval.h). A branch, not a select: the
// flag is the same for every lane, and most primitives lack it.
float floorAtBounds(uint i, vec3 p, float d) {
    if (nodes[i].bmin.w != 0.0) d = max(d, nodeBoundsDistance(i, p));
    return d;
}

// Helpers for the generated scene code (engine/src/codegen/codegen.cpp), which also defines one
// `float <kind>Node(uint i, vec3 p)` per primitive kind it uses.
float nodeSmooth(uint i) { return nodes[i].bmin.w; }
uint nodeBlend(uint i) { return uint(nodes[i].bmax.w); }
vec4 withColor(uint i, float d) { return vec4(nodes[i].color.rgb, d); }

// Node indices of 256 and up are spelt nodeIndex(i / 256, i % 256): glslang looks up every
// literal among all earlier ones, which made compile time quadratic in the node count.
uint nodeIndex(uint page, uint offset) { return page * 256u + offset; }

// Bounds skipping: must operand b of a union (subtrahend b of a difference) be evaluated, given
// its bounds' signed distance, the running value d and the blend radius k? Written exactly as
// eval.cpp tests it, so skipping an operand never changes a bit of the result. The code tests
// an operand with a gridded outline even where skipping is off (codegen.cpp: Emitter::guard).
bool unionChanges(float bounds, float d, float k) { return bounds - d < k; }
bool differenceChanges(float bounds, float d, float k) { return bounds + d < k; }
bool unionNeeds(float bounds, float d, float k) {
    return !kBoundsSkipping || unionChanges(bounds, d, k);
}
bool differenceNeeds(float bounds, float d, float k) {
    return !kBoundsSkipping || differenceChanges(bounds, d, k);
}
