// The tape machine's loop (tape.glsl), included once per value type: TAPE_VALUE (float, or vec4
// with colour), TAPE_RUN (the function's name), TAPE_LEAF(i, d) (a primitive's value),
// TAPE_DIST(v) and TAPE_WITH(v, d) (a value's distance, and v with another). prune.cpp's run() is
// this loop in C++.
//
// The top of the stack stays in `acc`; a primitive that its operation folds in at once (most
// of them: a left fold is primitive, operation, primitive, operation...) goes straight into
// it. On CPU devices this keeps most instructions off the stack array, which every lane
// indexes on its own, and makes nearly every iteration take the same path.
TAPE_VALUE TAPE_RUN(uint begin, uint end, vec3 p) {
#if SDFCSG_TAPE_STACK > 0
    TAPE_VALUE stack[SDFCSG_TAPE_STACK];
    int top = -1;
#endif
    TAPE_VALUE acc = TAPE_VALUE(0.0);
#if SDFCSG_TAPE_DOMAINS > 0
    // Open domain operations: the point outside, the local point, the least candidate value,
    // the candidate, their count, the child's first instruction and the operation's kind.
    vec3 outer[SDFCSG_TAPE_DOMAINS], local[SDFCSG_TAPE_DOMAINS];
    TAPE_VALUE best[SDFCSG_TAPE_DOMAINS];
    uint candidate[SDFCSG_TAPE_DOMAINS], count[SDFCSG_TAPE_DOMAINS];
    uint body[SDFCSG_TAPE_DOMAINS], domainKind[SDFCSG_TAPE_DOMAINS];
    int depth = -1;
#endif
    for (uint at = begin; at < end; ++at) {
        uint ins = field[at];
        uint i = ins & ((1u << SDFCSG_TAPE_NODE_BITS) - 1u);
        uint kind = (ins >> SDFCSG_TAPE_KIND_SHIFT) & 0x3fu;
        if (kind < kTapeUnion) {
            TAPE_VALUE d = TAPE_LEAF(i, tapePrimitive(kind, i, p));
            uint fold = (ins >> SDFCSG_TAPE_FOLD_SHIFT) & 3u;
            if (fold != 0u) {
                acc = tapeOp(fold + kTapeUnion - 1u, acc, d, uintBitsToFloat(field[++at]),
                             ins >> SDFCSG_TAPE_BLEND_SHIFT);
            } else {
#if SDFCSG_TAPE_STACK > 0
                stack[++top] = acc;
#endif
                acc = d;
            }
        }
#if SDFCSG_TAPE_STACK > 0
        else if (kind < kTapeUnion + 3u) {
            acc = tapeOp(kind, stack[top--], acc, nodeSmooth(i), nodeBlend(i));
        }
#endif
#if (SDFCSG_TAPE_OPERATIONS & 24) != 0
        else if (kind < kTapeUnion + 5u) {
            acc = TAPE_WITH(acc, valueOp(kind, TAPE_DIST(acc), nodes[i].p0));
        }
#endif
#if SDFCSG_TAPE_DOMAINS > 0
        else if (kind != uint(SDFCSG_TAPE_DOMAIN_END)) {
            // A domain operation: its child runs next, at the first candidate point.
            ++depth;
            outer[depth] = p;
            local[depth] = toLocal(i, domainClamps(kind) ? clamp(p, nodes[i].bmin.xyz,
                                                                 nodes[i].bmax.xyz)
                                                         : p);
            best[depth] = TAPE_WITH(acc, 1e30);
            candidate[depth] = 0u;
            count[depth] = domainCount(kind, nodes[i].p0, nodes[i].p1);
            body[depth] = at + 1u;
            domainKind[depth] = kind;
            p = domainPoint(kind, local[depth], nodes[i].p0, nodes[i].p1, 0u).xyz;
        } else {
            // The child's value: the least so far; the child again at the next candidate whose
            // bounds could lower it, or the operation's value.
            if (TAPE_DIST(acc) < TAPE_DIST(best[depth])) best[depth] = acc;
            acc = stack[top--];
            uint k = domainKind[depth], child = uint(nodes[i].bmax.w);
            bool again = false;
            while (!again && ++candidate[depth] < count[depth]) {
                vec4 q = domainPoint(k, local[depth], nodes[i].p0, nodes[i].p1, candidate[depth]);
                again = q.w == 0.0 && nodeBoundsDistance(child, q.xyz) < TAPE_DIST(best[depth]);
                if (again) p = q.xyz;
            }
            if (again) {
                at = body[depth] - 1u;
            } else {
                float v = domainFinish(k, local[depth], TAPE_DIST(best[depth]), nodes[i].p0,
                                       nodes[i].p1) * nodes[i].color.w;
                if (domainClamps(k)) v = max(v, nodeBoundsDistance(i, outer[depth]));
                stack[++top] = acc;
                acc = TAPE_WITH(best[depth], v);
                p = outer[depth];
                --depth;
            }
        }
#endif
    }
    return acc;
}
