// Stand-in for the generated scene, used only to syntax-check the kernels at build time: the
// output of engine/src/codegen/codegen.cpp (buffer mode) for a small scene. Keep it in step.

float sphereNode(uint i, vec3 p) {
    return sdSphere(toLocal(i, p), nodes[i].p0.x) * nodes[i].color.w;
}
float boxNode(uint i, vec3 p) {
    return sdBox(toLocal(i, p), nodes[i].p0.xyz) * nodes[i].color.w;
}
float cylinderNode(uint i, vec3 p) {
    return sdCylinder(toLocal(i, p), nodes[i].p0.x, nodes[i].p0.y) * nodes[i].color.w;
}

float sceneDistance(vec3 p) {
        float d1 = sphereNode(1u, p); // ball (sphere)
    float d0 = d1; // root (union)
    if (unionNeeds(nodeBoundsDistance(2u, p), d0, nodeSmooth(0u))) {
            float d3 = boxNode(3u, p); // root.children[1].children[0] (box)
        float d2 = d3; // root.children[1] (difference)
        if (differenceNeeds(nodeBoundsDistance(4u, p), d2, nodeSmooth(2u))) {
            float d4 = cylinderNode(4u, p); // root.children[1].children[1] (cylinder)
            d2 = opDifference(d2, d4, nodeSmooth(2u));
        }
        d0 = opUnion(d0, d2, nodeSmooth(0u));
    }
    return d0;
}

vec4 sceneSample(vec3 p) {
        vec4 s1 = withColor(1u, sphereNode(1u, p)); // ball (sphere)
    vec4 s0 = s1; // root (union)
    if (unionNeeds(nodeBoundsDistance(2u, p), s0.w, nodeSmooth(0u))) {
            vec4 s3 = withColor(3u, boxNode(3u, p)); // root.children[1].children[0] (box)
        vec4 s2 = s3; // root.children[1] (difference)
        if (differenceNeeds(nodeBoundsDistance(4u, p), s2.w, nodeSmooth(2u))) {
            vec4 s4 = withColor(4u, cylinderNode(4u, p)); // root.children[1].children[1] (cylinder)
            s2 = opDifference(s2, s4, nodeSmooth(2u));
        }
        s0 = opUnion(s0, s2, nodeSmooth(0u));
    }
    return s0;
}


// The scene code of large scenes includes the tape machine instead (codegen.cpp).
#define SDFCSG_TAPE_STACK 4
#define SDFCSG_TAPE_KINDS 0xffffffffu
#define SDFCSG_TAPE_OPERATIONS (SDFCSG_BOOLEAN_OPERATION_BITS | SDFCSG_VALUE_OPERATION_BITS)
#define SDFCSG_TAPE_BALLS 1
#define SDFCSG_TAPE_DOMAINS 2
#define SDFCSG_TAPE_COLORS 0xffffffffu
#include "tape.glsl"
