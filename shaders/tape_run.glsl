// The tape machine's loop, one source for both languages: shaders/tape.glsl includes it as GLSL
// once per value type, and engine/src/field/prune.cpp includes it as C++ (tape::Machine, GLM
// standing in for GLSL as in engine/src/field/sdf.h), so the CPU runs the instructions the
// kernels run. It is written in the dialect that sdf.glsl keeps to: float literals with an f
// suffix, no swizzles (TAPE_XYZ(v): v's first three components).
//
// The includer defines TAPE_VALUE (float, or vec4 with colour), TAPE_RUN (the function's name),
// TAPE_LEAF(kind, i, p, d) (primitive i's value from its distance d at p), TAPE_DIST(v) and
// TAPE_WITH(v, d) (a value's distance, and v with another), TAPE_ARRAY(T, name, n) (a local array of n T; in C++ one of the machine's
// own, sized for its tapes), what the loop reads of node i (TAPE_A(i) and TAPE_B(i): its kernel
// parameters; TAPE_SCALE(i); TAPE_MIN(i) and TAPE_MAX(i): its bounds; TAPE_CHILD(i): a domain
// operation's child), field[] (the instructions), tapePrimitive, tapeOp, kTapeUnion and the node
// helpers of nodes.glsl, and the counts SDFCSG_TAPE_STACK, SDFCSG_TAPE_OPERATIONS and
// SDFCSG_TAPE_DOMAINS (tape.glsl). The C++ side compiles every branch in and runs the unpacked
// tapes, where no primitive carries a fold: every operation takes its left operand off the stack.
//
// The top of the stack stays in `acc`; a primitive that its operation folds in at once (most
// of them: a left fold is primitive, operation, primitive, operation...) goes straight into
// it. On CPU devices this keeps most instructions off the stack array, which every lane
// indexes on its own, and makes nearly every iteration take the same path.
TAPE_VALUE TAPE_RUN(uint begin, uint end, vec3 p) {
#if SDFCSG_TAPE_STACK > 0
    TAPE_ARRAY(TAPE_VALUE, stack, SDFCSG_TAPE_STACK);
    int top = -1;
#endif
    TAPE_VALUE acc = TAPE_VALUE(0.0f);
#if SDFCSG_TAPE_DOMAINS > 0
    // Open domain operations (and normalising offsets and shells): the point outside, the local
    // point, the least candidate value, the candidate, their count, the child's first
    // instruction and the operation's kind.
    TAPE_ARRAY(vec3, outer, SDFCSG_TAPE_DOMAINS);
    TAPE_ARRAY(vec3, local, SDFCSG_TAPE_DOMAINS);
    TAPE_ARRAY(TAPE_VALUE, best, SDFCSG_TAPE_DOMAINS);
    TAPE_ARRAY(uint, candidate, SDFCSG_TAPE_DOMAINS);
    TAPE_ARRAY(uint, count, SDFCSG_TAPE_DOMAINS);
    TAPE_ARRAY(uint, body, SDFCSG_TAPE_DOMAINS);
    TAPE_ARRAY(uint, domainKind, SDFCSG_TAPE_DOMAINS);
    TAPE_ARRAY(vec4, taps, SDFCSG_TAPE_DOMAINS); // offsets' and shells' tap sums

    int depth = -1;
#endif
    for (uint at = begin; at < end; ++at) {
        uint ins = field[at];
        uint i = ins & ((1u << SDFCSG_TAPE_NODE_BITS) - 1u);
        uint kind = (ins >> SDFCSG_TAPE_KIND_SHIFT) & 0x3fu;
        if (kind < kTapeUnion) {
            TAPE_VALUE d = TAPE_LEAF(kind, i, p, tapePrimitive(kind, i, p));
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
        else if (kind < kKindFirstValueOperation) {
#if (SDFCSG_TAPE_OPERATIONS & SDFCSG_TRANSITION_OPERATION_BITS) != 0
            if (kind >= kKindTransitionLinear) {
                // A transition (never folded into a primitive): eval.cpp's morph and floor.
                float w = transitionWeight(kind, toLocal(i, p), TAPE_A(i), TAPE_B(i));
                TAPE_VALUE t = opTransition(stack[top--], acc, w, TAPE_B(i));
                acc = TAPE_WITH(t, max(TAPE_DIST(t), nodeBoundsDistance(i, p)));
            } else
#endif
                acc = tapeOp(kind, stack[top--], acc, nodeSmooth(i), nodeBlend(i));
        }
#endif
#if (SDFCSG_TAPE_OPERATIONS & SDFCSG_VALUE_OPERATION_BITS) != 0
        else if (kind < kKindFirstDomainOperation) {
#if SDFCSG_TAPE_DOMAINS > 0
            if (((ins >> SDFCSG_TAPE_FOLD_SHIFT) & 3u) == 3u) {
                // An offset or shell over a field that is not a distance (sdf.glsl,
                // valueNormalised): its child runs next at the four taps, as a domain
                // operation's at its candidates, up to the end that names it.
                ++depth;
                outer[depth] = p;
                best[depth] = acc;
                taps[depth] = vec4(0.0f);
                candidate[depth] = 0u;
                count[depth] = 4u;
                body[depth] = at + 1u;
                domainKind[depth] = kind;
                p = valueTap(p, TAPE_A(i).y, 0u);
            } else
#endif
                acc = TAPE_WITH(acc, valueOp(kind, TAPE_DIST(acc), TAPE_A(i)));
        }
#endif
#if SDFCSG_TAPE_DOMAINS > 0
        else if (kind != uint(SDFCSG_TAPE_DOMAIN_END)) {
            // A domain operation: its child runs next, at the first candidate point.
            ++depth;
            outer[depth] = p;
            local[depth] =
                toLocal(i, domainClamps(kind) ? clamp(p, TAPE_MIN(i), TAPE_MAX(i)) : p);
            best[depth] = TAPE_WITH(acc, 1e30f);
            candidate[depth] = 0u;
            count[depth] = domainCount(kind, TAPE_A(i), TAPE_B(i));
            body[depth] = at + 1u;
            domainKind[depth] = kind;
            p = TAPE_XYZ(domainPoint(kind, local[depth], TAPE_A(i), TAPE_B(i), 0u));
        } else if (domainKind[depth] < kKindFirstDomainOperation) {
            // An offset's or shell's tap: summed; the child again at the next tap, or its value.
            uint c = candidate[depth];
            taps[depth] = valueTapSum(taps[depth], TAPE_DIST(acc), c);
            if (c == 0u) best[depth] = acc; // the colour
            acc = stack[top--];
            if (++candidate[depth] < count[depth]) {
                p = valueTap(outer[depth], TAPE_A(i).y, candidate[depth]);
                at = body[depth] - 1u;
            } else {
                uint k = domainKind[depth];
                float v = valueOpNormalised(k, taps[depth], TAPE_A(i));
                v = max(v, nodeBoundsDistance(i, outer[depth])); // eval.cpp's floor
                stack[++top] = acc;
                acc = TAPE_WITH(best[depth], v);
                p = outer[depth];
                --depth;
            }
        } else {
            // The child's value: the least so far; the child again at the next candidate whose
            // bounds could lower it, or the operation's value.
            if (TAPE_DIST(acc) < TAPE_DIST(best[depth])) best[depth] = acc;
            acc = stack[top--];
            uint k = domainKind[depth], child = TAPE_CHILD(i);
            bool again = false;
            while (!again && ++candidate[depth] < count[depth]) {
                vec4 q = domainPoint(k, local[depth], TAPE_A(i), TAPE_B(i), candidate[depth]);
                again = q.w == 0.0f &&
                        nodeBoundsDistance(child, TAPE_XYZ(q)) < TAPE_DIST(best[depth]);
                if (again) p = TAPE_XYZ(q);
            }
            if (again) {
                at = body[depth] - 1u;
            } else {
                float v = domainFinish(k, local[depth], TAPE_DIST(best[depth]), TAPE_A(i),
                                       TAPE_B(i)) * TAPE_SCALE(i);
                v = max(v, nodeBoundsDistance(i, outer[depth])); // eval.cpp's floor
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
