// The scene as data: the stack machine that runs a cell's pruned tape (engine/src/field/prune.h), the
// scene code of scenes too large to inline. Kernels built this way are the same for every such
// scene; the tapes, the cells and the node buffer carry everything that is the scene's own.
// PrunedField::distance and sample in engine/src/field/prune.cpp find the cell as tapeCell does
// and run the same loop, tape_run.glsl compiled as C++.
//
// The generated scene code defines, before it includes this file, what the scene's tapes need,
// so that the machine holds no code for the rest (a CPU driver runs every branch of its loop
// for every instruction): SDFCSG_TAPE_STACK (the most values a tape holds at once, rounded up;
// 0 where no instruction reads the stack, when every operation folds in a primitive's value),
// SDFCSG_TAPE_KINDS (a bit for each kind of primitive), SDFCSG_TAPE_OPERATIONS (a bit for each
// kind of operation, less Union: union 1, intersection 2, difference 4, transition_linear 8,
// transition_radial 16, shell 32, offset 64),
// SDFCSG_TAPE_BALLS (1 where every sphere is a ball, detail::isBall, in kernels that may follow
// values, CodegenOptions::inlineParams; KINDS then lacks the sphere's bit),
// SDFCSG_TAPE_DOMAINS (the most domain operations nested in one another, 0 for none) and
// SDFCSG_TAPE_COLORS (a bit for each kind of primitive with a node that has colours of its own,
// ownColors in sdfcsg/nodes.h; 0u for none, which leaves their code out). Only BALLS follows
// values (the spheres' scales): Renderer::updateValues recompiles where it changes; COLORS
// follows the nodes' words, which sameStructure compares.

// Mirrors packField() in engine/src/field/prune.cpp: a header of 12 words (origin xyz and leaf cell
// side as float bits, levels, leaf cells per axis xyz, 1 when bounded, whole-tape length, first
// tape word, first cell word), four words per node (a ball's centre and radius), two words per
// leaf cell, then the tape.
layout(std430, set = 0, binding = SDFCSG_BINDING_FIELD) readonly buffer Field {
    uint field[];
};
// The same buffer as vec4s: node i's ball is vec4 3 + i (the header is three of them).
layout(std430, set = 0, binding = SDFCSG_BINDING_FIELD) readonly buffer FieldBalls {
    vec4 fieldBalls[];
};

// Balls (SDFCSG_TAPE_BALLS: every sphere's scale is the same on every axis) read one vec4, their
// centre and radius (packField: the same value as the sphere's, up to rounding), where other
// primitives read their transform's three rows, their parameters and their scale: most of the
// work of a tape of spheres (molecule_1k), as each is a gather on CPU devices.
float tapePrimitive(uint kind, uint i, vec3 p) {
#if SDFCSG_TAPE_BALLS
    if (kind == kKindSphere || SDFCSG_TAPE_KINDS == 0u) {
        vec4 ball = fieldBalls[3u + i];
        return length(p - ball.xyz) - ball.w;
    }
#endif
    return floorAtBounds(
        i, p, sdPrimitive(kind, toLocal(i, p), nodes[i].p0, nodes[i].p1, SDFCSG_TAPE_KINDS) *
                  nodes[i].color.w);
}

const uint kTapeUnion = kKindUnion, kTapeIntersection = kKindIntersection;
// The operations that tapeOp folds (transitions fold in tape_run.glsl).
const uint kTapeBlendBits = SDFCSG_BOOLEAN_OPERATION_BITS & ~SDFCSG_TRANSITION_OPERATION_BITS;

// One blend for the three operations, which the compiler would otherwise all evaluate and
// select from: intersection(a, b) is -union(-a, -b) and difference(a, b) intersection(a, -b),
// bit for bit as sdf.glsl computes them (negation rounds symmetrically). Kinds that the scene
// lacks fold away (a scene whose only boolean is union has none of the others' bits).
float tapeOp(uint kind, float a, float b, float k, uint blend) {
    if ((SDFCSG_TAPE_OPERATIONS & kTapeBlendBits) <= 1u) kind = kTapeUnion;
    float s = kind == kTapeUnion ? 1.0 : -1.0;
    float c = kind == kTapeIntersection || kind == kTapeUnion ? b : -b;
    return s * opUnion(s * a, s * c, k, blend);
}

vec4 tapeOp(uint kind, vec4 a, vec4 b, float k, uint blend) {
    if ((SDFCSG_TAPE_OPERATIONS & kTapeBlendBits) <= 1u) kind = kTapeUnion;
    float s = kind == kTapeUnion ? 1.0 : -1.0;
    float c = kind == kTapeIntersection || kind == kTapeUnion ? b.w : -b.w;
    vec4 u = opUnion(vec4(a.rgb, s * a.w), vec4(b.rgb, s * c), k, blend);
    return vec4(u.rgb, s * u.w);
}

// What the loop reads of node i in the node buffer (nodes.glsl), and its arrays.
#define TAPE_A(i) nodes[i].p0
#define TAPE_B(i) nodes[i].p1
#define TAPE_SCALE(i) nodes[i].color.w
#define TAPE_MIN(i) nodes[i].bmin.xyz
#define TAPE_MAX(i) nodes[i].bmax.xyz
#define TAPE_CHILD(i) uint(nodes[i].bmax.w)
#define TAPE_ARRAY(T, name, n) T name[n]
// A swizzle, one shuffle; vec3(v) compiles to three extracts and a construct.
#define TAPE_XYZ(v) (v).xyz

// A primitive's value with its colour: the node's, or for the kinds in SDFCSG_TAPE_COLORS their
// formula's (sdPrimitiveColor), which gives the node's colour where the node has none of its own.
vec4 tapeColored(uint kind, uint i, vec3 p, float d) {
    if (((SDFCSG_TAPE_COLORS >> kind) & 1u) == 0u) return withColor(i, d);
    return vec4(sdPrimitiveColor(kind, toLocal(i, p), nodes[i].p0, nodes[i].p1, nodes[i].color.rgb,
                                 SDFCSG_TAPE_COLORS),
                d);
}

#define TAPE_VALUE float
#define TAPE_RUN tapeDistanceRun
#define TAPE_LEAF(kind, i, p, d) (d)
#define TAPE_DIST(v) (v)
#define TAPE_WITH(v, d) (d)
#include "tape_run.glsl"
#undef TAPE_VALUE
#undef TAPE_RUN
#undef TAPE_LEAF
#undef TAPE_DIST
#undef TAPE_WITH

#define TAPE_VALUE vec4
#define TAPE_RUN tapeSampleRun
#define TAPE_LEAF(kind, i, p, d) tapeColored(kind, i, p, d)
#define TAPE_DIST(v) (v).w
#define TAPE_WITH(v, d) vec4((v).rgb, d)
#include "tape_run.glsl"
#undef TAPE_VALUE
#undef TAPE_RUN
#undef TAPE_LEAF
#undef TAPE_DIST
#undef TAPE_WITH

// Where p's value comes from: x: 0 to run the tape [y, z), 1 for the bound w. Far from every
// surface, `reach` is how far a ray from p along the unit vector dir may step without meeting
// one: to where it leaves the ball of radius |v| around the centre c of the cell found far (no
// surface lies nearer to c than its value v), at least the bound v - |p - c| and often a few
// cells more (the bound alone, near a far cell's entry side, is about a leaf cell's radius).
uvec3 tapeCell(vec3 p, vec3 dir, out float bound, out float reach, out float estimate) {
    vec3 origin = vec3(uintBitsToFloat(field[0]), uintBitsToFloat(field[1]),
                       uintBitsToFloat(field[2]));
    float cell = uintBitsToFloat(field[3]);
    uint levels = field[4], tapeStart = field[10];
    uvec3 dims = uvec3(field[5], field[6], field[7]);
    vec3 q = floor((p - origin) / cell);
    bound = 0.0;
    reach = 0.0;
    estimate = 0.0;
    if (dims.x == 0u || any(lessThan(q, vec3(0.0))) || any(greaterThanEqual(q, vec3(dims)))) {
        if (field[8] == 0u) return uvec3(0u, tapeStart, tapeStart + field[9]); // the whole tape
        // Bounded: the grid holds the bounds and a cell more on every side.
        vec3 top = origin + cell * vec3(dims);
        bound = boundsDistance(origin, top, p) + 0.5 * cell;
        reach = bound;
        estimate = bound;
        return uvec3(1u, 0u, 0u);
    }
    uvec3 at = uvec3(q);
    uint entry = field[11] + 2u * (at.x + dims.x * (at.y + dims.y * at.z));
    uint x = field[entry], y = field[entry + 1u];
    if ((y & 0x80000000u) == 0u) return uvec3(0u, tapeStart + x, tapeStart + x + y);
    // Far from every surface: the root value v at the centre of the cell found far.
    uint shift = levels - (y & 0xffu);
    float size = cell * float(1u << shift);
    vec3 away = p - (origin + (vec3(at >> shift) + 0.5) * size);
    float v = uintBitsToFloat(x), distance = length(away);
    bound = v > 0.0 ? v - distance : v + distance;
    float b = dot(away, dir);
    reach = max(sqrt(max(b * b + (v * v - distance * distance), 0.0)) - b, abs(bound));
    // For shading: the field's value estimated along its direction of ascent over the cell's
    // siblings, never nearer zero than the bound.
    estimate = bound;
    if ((y & 0x40000000u) != 0u) {
        vec2 o = vec2(uvec2(y >> 8, y >> 19) & 2047u) / 2047.0 * 2.0 - 1.0;
        vec3 g = vec3(o, 1.0 - abs(o.x) - abs(o.y));
        if (g.z < 0.0)
            g.xy = (1.0 - abs(g.yx)) * vec2(g.x >= 0.0 ? 1.0 : -1.0, g.y >= 0.0 ? 1.0 : -1.0);
        float linear = v + dot(normalize(g), away);
        estimate = v > 0.0 ? max(linear, bound) : min(linear, bound);
    }
    return uvec3(1u, 0u, 0u);
}

// The side of a leaf cell (1 where the field is not pruned).
float tapeLeafSide() { return field[4] == 0u ? 1e30 : uintBitsToFloat(field[3]); }

float tapeDistance(vec3 p) {
    float bound, reach, estimate;
    uvec3 c = tapeCell(p, vec3(0.0), bound, reach, estimate);
    return c.x == 1u ? bound : tapeDistanceRun(c.y, c.z, p);
}

// For a ray from p along the unit vector dir: the field at p, and how far the ray may step
// (the field's value, or a far cell's reach); `far` where the value is a bound (no surface in
// the cell, or outside the grid).
float tapeDistanceAlong(vec3 p, vec3 dir, out float step, out bool far) {
    float bound, estimate;
    uvec3 c = tapeCell(p, dir, bound, step, estimate);
    far = c.x == 1u;
    if (far) return bound;
    step = tapeDistanceRun(c.y, c.z, p);
    return step;
}

// For the shade pass's taps, which need no colour: the distance in w, and r -1 where it is a
// bound (as tapeSample gives), then with g the reach along dir and b the estimate for shading
// (tapeCell), else 0. The float stack is about half the work of the colour one.
vec4 tapeTap(vec3 p, vec3 dir) {
    float bound, reach, estimate;
    uvec3 c = tapeCell(p, dir, bound, reach, estimate);
    return c.x == 1u ? vec4(-1.0, reach, estimate, bound)
                     : vec4(0.0, 0.0, 0.0, tapeDistanceRun(c.y, c.z, p));
}

// Where the value is a bound, the colour is -1: the shade pass's soft shadows tell the two apart.
vec4 tapeSample(vec3 p) {
    float bound, reach, estimate;
    uvec3 c = tapeCell(p, vec3(0.0), bound, reach, estimate);
    return c.x == 1u ? vec4(-1.0, -1.0, -1.0, bound) : tapeSampleRun(c.y, c.z, p);
}
