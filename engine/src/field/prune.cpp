// Per-region pruning (see prune.h): the tape, the octree walk that prunes it per cell, and the
// stack machine that runs it on the CPU, shaders/tape_run.glsl itself compiled as C++.
#include "field/prune.h"

#include "field/sdf.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <thread>

namespace sdfcsg::detail {
namespace {

bool isOperation(NodeKind kind) {
    return kindInfo(kind).operation;
}

uint32_t instruction(uint32_t node, NodeKind kind) {
    return node | uint32_t(kind) << kTapeKindShift;
}

NodeKind opcode(uint32_t instruction) {
    return NodeKind((instruction >> kTapeKindShift) & 0x3fu);
}

// An offset or shell that normalises its child's field (eval.cpp) opens like a domain operation:
// its instruction before its child's, marked by both fold bits, and an end after.
constexpr uint32_t kTapeOpens = 3u << kTapeFoldShift;
bool opens(uint32_t ins) {
    return (ins & kTapeOpens) == kTapeOpens && (ins >> kTapeKindShift) != kTapeDomainEnd;
}

template <class V> V opValue(const FlatNode& op, V a, V b) {
    return op.kind == NodeKind::Union          ? sdf::opUnion(a, b, op.smooth, op.blend)
           : op.kind == NodeKind::Intersection ? sdf::opIntersection(a, b, op.smooth, op.blend)
                                               : sdf::opDifference(a, b, op.smooth, op.blend);
}

// Whether an offset or shell normalises its child's field (eval.cpp, FlatNode::loss).
bool normalises(const FlatNode& n) {
    return kindInfo(n.kind).role == Role::Value && n.params[1] > 0.0f;
}

// Looked up for every instruction of every cell's pass: a table of their own.
Role roleOf(NodeKind kind) {
    static const std::array<Role, kNodeKindCount> roles = [] {
        std::array<Role, kNodeKindCount> r{};
        for (int k = 0; k < kNodeKindCount; ++k)
            r[k] = kindInfo(NodeKind(k)).role;
        return r;
    }();
    return roles[size_t(kind)];
}

bool isDomainEnd(uint32_t ins) {
    return (ins >> kTapeKindShift) == kTapeDomainEnd;
}

glm::vec4 kernelA(const FlatNode& n) {
    return {n.params[0], n.params[1], n.params[2], n.params[3]};
}
glm::vec4 kernelB(const FlatNode& n) {
    return {n.params[4], n.params[5], n.params[6], n.params[7]};
}

float distanceOf(float v) {
    return v;
}
float distanceOf(glm::vec4 v) {
    return v.w;
}
float withDistance(float, float d) {
    return d;
}
glm::vec4 withDistance(glm::vec4 v, float d) {
    return {glm::vec3(v), d};
}

// The tape machine, shaders/tape_run.glsl compiled as C++ in the dialect that sdf.h compiles
// sdf.glsl in: what the loop reads of the kernels' globals (the tape in field[], the node buffer,
// the helpers of tape.glsl and nodes.glsl) it reads here of the tape and the FlatNodes. Every
// branch is compiled in; the tapes it runs are unpacked (no primitive carries its operation's
// fold, packField), so every operation takes its left operand off the stack. V: float (the
// distance) or vec4 (colour, the distance in w).
namespace tape {

using namespace sdf;

template <class V> class Machine {
  public:
    // Runs tape[0, length) at p. stack: the most values it holds at once; domains: the most
    // domain operations open at once (PrunedField::stackDepth, domainDepth).
    V run(const std::vector<FlatNode>& nodes, const uint32_t* tape, uint32_t length, uint32_t stack,
          uint32_t domains, vec3 p) {
        nodes_ = nodes.data();
        field = tape;
        if (stack_.size() < stack) stack_.resize(stack);
        if (best_.size() < domains) {
            outer_.resize(domains);
            local_.resize(domains);
            best_.resize(domains);
            candidate_.resize(domains);
            taps_.resize(domains);
            count_.resize(domains);
            body_.resize(domains);
            domainKind_.resize(domains);
        }
        return execute(0u, length, p);
    }

  private:
    static constexpr uint kTapeUnion = kKindUnion, kTapeIntersection = kKindIntersection;

    const FlatNode* nodes_ = nullptr;
    const uint32_t* field = nullptr;
    std::vector<V> stack_, best_;
    std::vector<vec3> outer_, local_;
    std::vector<vec4> taps_;
    std::vector<uint> candidate_, count_, body_, domainKind_;

    float tapePrimitive(uint, uint i, vec3 p) const { return primitiveValue(nodes_[i], p); }
    // The three operations as eval.cpp folds them; tape.glsl's one blend for all three gives
    // the same bits.
    static V tapeOp(uint kind, V a, V b, float k, uint blend) {
        return kind == kTapeUnion          ? opUnion(a, b, k, blend)
               : kind == kTapeIntersection ? opIntersection(a, b, k, blend)
                                           : opDifference(a, b, k, blend);
    }
    static float uintBitsToFloat(uint bits) { return std::bit_cast<float>(bits); }
    vec3 toLocal(uint i, vec3 p) const { return nodeLocalPoint(nodes_[i], p); }
    float nodeSmooth(uint i) const { return nodes_[i].smooth; }
    uint nodeBlend(uint i) const { return nodes_[i].blend; }
    float nodeBoundsDistance(uint i, vec3 p) const { return nodes_[i].bounds.signedDistance(p); }
    V leaf(uint i, vec3 p, float d) const {
        if constexpr (std::is_same_v<V, float>)
            return d;
        else
            return vec4(primitiveColor(nodes_[i], p), d);
    }

    // Every branch compiled in: the stack, every operation, domain operations. The arrays are
    // the machine's own, sized in run().
#define SDFCSG_TAPE_STACK 1
#define SDFCSG_TAPE_OPERATIONS (SDFCSG_BOOLEAN_OPERATION_BITS | SDFCSG_VALUE_OPERATION_BITS)
#define SDFCSG_TAPE_DOMAINS 1
#define TAPE_A(i) kernelA(nodes_[i])
#define TAPE_B(i) kernelB(nodes_[i])
#define TAPE_SCALE(i) nodes_[i].scale
#define TAPE_MIN(i) nodes_[i].bounds.min
#define TAPE_MAX(i) nodes_[i].bounds.max
#define TAPE_CHILD(i) nodes_[i].children[0]
#define TAPE_ARRAY(T, name, n) T* const name = name##_.data()
#define TAPE_XYZ(v) vec3(v)
#define TAPE_VALUE V
// Flattened: else GCC calls domainPoint out of line at both its sites, which costs the pruning
// of a scene of repetitions (chain.json) 9% more instructions.
#define TAPE_RUN execute [[gnu::flatten]]
#define TAPE_LEAF(kind, i, p, d) leaf(i, p, d)
#define TAPE_DIST(v) distanceOf(v)
#define TAPE_WITH(v, d) withDistance(v, d)
#include "../../shaders/tape_run.glsl"
#undef SDFCSG_TAPE_STACK
#undef SDFCSG_TAPE_OPERATIONS
#undef SDFCSG_TAPE_DOMAINS
#undef TAPE_A
#undef TAPE_B
#undef TAPE_SCALE
#undef TAPE_MIN
#undef TAPE_MAX
#undef TAPE_CHILD
#undef TAPE_ARRAY
#undef TAPE_XYZ
#undef TAPE_VALUE
#undef TAPE_RUN
#undef TAPE_LEAF
#undef TAPE_DIST
#undef TAPE_WITH
};

// Runs tape[0, length) at p on this thread's machine.
template <class V>
V run(const std::vector<FlatNode>& nodes, const uint32_t* tape, uint32_t length, uint32_t stack,
      uint32_t domains, vec3 p) {
    thread_local Machine<V> machine;
    return machine.run(nodes, tape, length, stack, domains, p);
}

} // namespace tape

// Prunes `in` for cells of centre c and radius r (see prune.h), appending each cell's tape to
// `out`. The first pass runs the tape at c and notes, per operation, the least (union) or
// greatest (intersection) value of its operands. The second drops the operands that cannot
// matter anywhere in the cell, where each value lies within v +- r, widened by `slack` for the
// rounding of single precision (at c here, at p on the GPU):
//  - of a union, an operand whose lower bound is at least 3k above the least upper bound (k:
//    the blend radius); of an intersection, the mirror image. Sharp (k = 0), the result is the
//    same bits. Smooth, an operand 3k above the least one changes the left-to-right fold only
//    through a chain of blends each of which passes on at most half of a change (the tests
//    check 1e-5 absolute near the surface; at 2k, cells of 2^19 in the bounds strayed to 2e-5);
//  - a subtrahend b of a difference where a + b >= k over the cell (max(a, -b) is a), and the
//    running union a or operand b where they lie k apart (opUnion returns the other).
// A domain operation's instructions (its own, its child's and the end) stay whole: the pruner
// takes its value at c like a primitive's and keeps or drops it as one; so do those of an offset
// or shell that normalises its child's field (opens()).
struct Pruner {
    // The cells pruned together: the children of one parent, which share its tape. The first
    // pass reads each node once for all of them.
    static constexpr uint32_t kLanes = 8;

    const std::vector<FlatNode>& nodes;
    const std::vector<uint32_t>& spans; // per domain node: its instructions, the end included
    float slack;
    uint32_t stackDepth, domainDepth; // PrunedField's, for the tape machine
    // Its own machine: in position-independent code every use of a thread_local is a call.
    tape::Machine<float> machine;
    std::vector<float> value;   // per instruction of `in` and cell: the value of its subtree
    std::vector<float> extreme; // per node and cell: least (union) / greatest operand value
    std::vector<uint32_t> touched;
    std::vector<uint32_t> ends; // first pass: the stack, as the instructions that end its values
    struct Segment {
        uint32_t start; // in out
        uint32_t end;   // its last instruction in `in` (value[end] is its value at c)
        bool empty;     // all of it dropped
    };
    std::vector<Segment> stack;

    // Whether the fold at `in[i]` of operation u is its first (its left operand is operand 0).
    static bool firstFold(const uint32_t* in, uint32_t leftEnd, uint32_t instructionAt) {
        return in[leftEnd] != in[instructionAt];
    }

    // The first pass, for `lanes` cells of centres c: runs the tape at each centre, noting per
    // operation the least (union) or greatest (intersection) value of its operands. Returns the
    // root values in `roots`.
    void evaluate(const uint32_t* in, uint32_t length, const glm::vec3* c, uint32_t lanes,
                  float* roots) {
        if (value.size() < size_t(length) * kLanes) value.resize(size_t(length) * kLanes);
        if (extreme.size() < nodes.size() * kLanes) extreme.assign(nodes.size() * kLanes, NAN);
        ends.clear();
        for (uint32_t i = 0; i < length; ++i) {
            const uint32_t node = in[i] & kTapeNodeMask;
            const FlatNode& n = nodes[node];
            const NodeKind kind = opcode(in[i]);
            const Role role = roleOf(kind);
            float* v = &value[size_t(i) * kLanes];
            if (role == Role::Primitive) {
                primitiveValues(n, c, lanes, v);
                ends.push_back(i);
                continue;
            }
            if (role == Role::Domain || opens(in[i])) {
                const uint32_t end = i + spans[node] - 1;
                for (uint32_t l = 0; l < lanes; ++l)
                    value[size_t(end) * kLanes + l] =
                        machine.run(nodes, in + i, spans[node], stackDepth, domainDepth, c[l]);
                ends.push_back(end);
                i = end;
                continue;
            }
            if (role == Role::Value) {
                const float* from = &value[size_t(ends.back()) * kLanes];
                for (uint32_t l = 0; l < lanes; ++l)
                    v[l] = sdf::valueOp(uint32_t(kind), from[l], kernelA(n));
                ends.back() = i;
                continue;
            }
            const uint32_t b = ends.back();
            ends.pop_back();
            const uint32_t a = ends.back();
            const float* va = &value[size_t(a) * kLanes];
            const float* vb = &value[size_t(b) * kLanes];
            if (isTransition(kind)) {
                for (uint32_t l = 0; l < lanes; ++l)
                    v[l] = transitionValue(n, c[l], va[l], vb[l]);
                ends.back() = i;
                continue;
            }
            if (kind != NodeKind::Difference) {
                float* e = &extreme[size_t(node) * kLanes];
                if (std::isnan(e[0])) {
                    touched.push_back(node);
                    std::copy_n(va, lanes, e);
                }
                const bool least = kind == NodeKind::Union;
                const bool first = firstFold(in, a, i);
                for (uint32_t l = 0; l < lanes; ++l) {
                    if (first) e[l] = least ? std::min(e[l], va[l]) : std::max(e[l], va[l]);
                    e[l] = least ? std::min(e[l], vb[l]) : std::max(e[l], vb[l]);
                }
            }
            for (uint32_t l = 0; l < lanes; ++l)
                v[l] = opValue(n, va[l], vb[l]);
            ends.back() = i;
        }
        std::copy_n(&value[size_t(length - 1) * kLanes], lanes, roots);
    }

    // The second pass for cell `lane` of the last evaluate(), of centre radius r: appends its
    // tape to `out`.
    void prune(const uint32_t* in, uint32_t length, uint32_t lane, float r,
               std::vector<uint32_t>& out) {
        const auto valueAt = [&](uint32_t i) { return value[size_t(i) * kLanes + lane]; };
        stack.clear();
        for (uint32_t i = 0; i < length; ++i) {
            const uint32_t ins = in[i];
            const NodeKind kind = opcode(ins);
            const Role role = roleOf(kind);
            if (role == Role::Primitive || role == Role::Domain || opens(ins)) {
                const uint32_t span = role == Role::Primitive ? 1 : spans[ins & kTapeNodeMask];
                stack.push_back({uint32_t(out.size()), i + span - 1, false});
                out.insert(out.end(), in + i, in + i + span);
                i += span - 1;
                continue;
            }
            if (role == Role::Value) {
                if (!stack.back().empty) out.push_back(ins);
                stack.back().end = i;
                continue;
            }
            const uint32_t u = ins & kTapeNodeMask;
            const float k = nodes[u].smooth;
            Segment b = stack.back();
            stack.pop_back();
            Segment& a = stack.back();
            const float va = valueAt(a.end), vb = valueAt(b.end);
            const float gap = 2.0f * r + slack + 1e-5f * (std::abs(va) + std::abs(vb));
            bool dropA = false, dropB = false;
            if (isTransition(kind)) {
                // Both children count everywhere: neither is dropped.
            } else if (kind == NodeKind::Difference) {
                dropB = va + vb >= gap + k;
            } else {
                const float sign = kind == NodeKind::Union ? 1.0f : -1.0f;
                // Far from the operation's extreme operand; or k beyond the running value.
                const float e = sign * extreme[size_t(u) * kLanes + lane] + 3.0f * k + gap;
                dropB = sign * vb >= e || sign * (vb - va) >= gap + k;
                dropA = (firstFold(in, a.end, i) && sign * va >= e) || sign * (va - vb) >= gap + k;
                if (dropA && dropB) dropA = false; // keep one (only rounding could ask for both)
            }
            const bool keepA = !a.empty && !dropA, keepB = !b.empty && !dropB;
            if (!keepB && !b.empty) out.resize(b.start); // b's instructions are the last ones
            if (!keepA && !a.empty)
                out.erase(out.begin() + a.start,
                          keepB ? out.begin() + b.start : out.end()); // b then starts at a.start
            if (keepA && keepB) out.push_back(ins);
            a.empty = !keepA && !keepB;
            if (a.empty) a.start = uint32_t(out.size());
            a.end = i;
        }
        if (stack.back().empty) { // cannot happen but through rounding: keep everything
            out.resize(stack.back().start);
            out.insert(out.end(), in, in + length);
        }
    }

    void resetExtremes() {
        for (uint32_t u : touched)
            std::fill_n(&extreme[size_t(u) * kLanes], kLanes, NAN);
        touched.clear();
    }
};

// A far cell's direction of ascent, octahedral in two 11-bit numbers at bits 8 and 19, with bit
// 30 set (0: none), as tapeCell() in shaders/tape.glsl reads it.
uint32_t farGradientBits(glm::vec3 g) {
    const float sum = std::abs(g.x) + std::abs(g.y) + std::abs(g.z);
    if (!(sum > 0.0f)) return 0;
    glm::vec2 o = glm::vec2(g.x, g.y) / sum;
    if (g.z < 0.0f)
        o = (1.0f - glm::abs(glm::vec2(o.y, o.x))) *
            glm::vec2(o.x >= 0.0f ? 1.0f : -1.0f, o.y >= 0.0f ? 1.0f : -1.0f);
    const glm::uvec2 q = glm::uvec2(glm::round((o * 0.5f + 0.5f) * 2047.0f));
    return 1u << 30 | q.y << 19 | q.x << 8;
}

// A cell is far from every surface when its centre value exceeds its radius and this many leaf
// radii less one: its bound is then at least a leaf cell's radius everywhere in it, which keeps
// the soft shadows' ratio of distance to travel (and so the shading) what the whole tree gives
// (at 1.25 leaf radii, shadow rays crossing cell corners darkened lit surfaces in blotches). A
// coarse cell needs no more than that, so it stops refining as soon as it holds no surface
// (forest_10k: a third less pruning time, the same leaf tapes).
constexpr float kFarRadii = 2.0f;

// The grid that the octrees divide: the finite part of the bounds (all finite leaves' boxes where
// a plane makes the root unbounded) and a leaf cell more on every side, so that outside it a
// bounded field is at least half a cell more than the distance to it. Leaf cells are cubes sized
// so that the box holds about options.cells of them; the top level is a grid of cubes of
// 2^levels leaf cells, each the root of an octree.
bool fieldGrid(const Evaluator& evaluator, const PruneOptions& options, PrunedField& f) {
    Aabb box = evaluator.bounds();
    f.bounded = box.finite();
    if (!f.bounded) {
        box = Aabb{};
        for (const FlatNode& n : evaluator.nodes())
            if (!isOperation(n.kind) && n.bounds.finite() && n.frame == kWorldFrame) {
                box.min = glm::min(box.min, n.bounds.min);
                box.max = glm::max(box.max, n.bounds.max);
            }
    }
    if (box.empty()) return false;
    const glm::vec3 extent = box.max - box.min;
    const float largest = std::max(std::max(extent.x, extent.y), std::max(extent.z, 1e-6f));
    // Thin boxes: at least a 64th of the largest extent on every axis, so the cells stay few.
    const glm::vec3 padded = glm::max(extent, glm::vec3(largest / 64.0f));
    f.cell = std::cbrt(padded.x * padded.y * padded.z / float(options.cells));
    const float top = f.cell * float(1u << options.levels);
    const glm::uvec3 tops = glm::uvec3(glm::ceil((extent + 2.0f * f.cell) / top));
    f.levels = options.levels;
    f.dims = tops * (1u << f.levels);
    f.origin = 0.5f * (box.min + box.max) - 0.5f * glm::vec3(f.dims) * f.cell;
    return true;
}

} // namespace

std::vector<uint32_t> fullTape(const std::vector<FlatNode>& nodes, uint32_t& stackDepth) {
    std::vector<uint32_t> tape;
    stackDepth = 0;
    if (nodes.empty()) return tape;
    tape.reserve(2 * nodes.size());
    // Explicit stack of (node, next child); depth of the value stack alongside.
    struct Frame {
        uint32_t node, next;
    };
    std::vector<Frame> frames{{0, 0}};
    uint32_t depth = 0;
    while (!frames.empty()) {
        Frame& f = frames.back();
        const FlatNode& n = nodes[f.node];
        const Role role = roleOf(n.kind);
        if (role == Role::Primitive) {
            tape.push_back(instruction(f.node, n.kind));
            stackDepth = std::max(stackDepth, ++depth);
            frames.pop_back();
        } else if (f.next < n.children.size()) {
            if (role == Role::Domain) tape.push_back(instruction(f.node, n.kind));
            if (normalises(n)) tape.push_back(instruction(f.node, n.kind) | kTapeOpens);
            if (f.next >= 2) tape.push_back(instruction(f.node, n.kind)), --depth;
            const uint32_t child = n.children[f.next++];
            frames.push_back({child, 0});
        } else {
            if (role == Role::Domain || normalises(n))
                tape.push_back(f.node | kTapeDomainEnd << kTapeKindShift);
            else if (role == Role::Value)
                tape.push_back(instruction(f.node, n.kind));
            if (n.children.size() >= 2) tape.push_back(instruction(f.node, n.kind)), --depth;
            frames.pop_back();
        }
    }
    return tape;
}

namespace {

// The length of every domain operation's stretch of the full tape, from its instruction to its
// end, by node; sets field.domainDepth, the deepest nesting of those stretches.
std::vector<uint32_t> domainSpans(PrunedField& field, size_t nodeCount) {
    std::vector<uint32_t> spans(nodeCount, 0), begins;
    for (uint32_t i = 0; i < field.fullLength; ++i) {
        const uint32_t ins = field.tape[i];
        if (isDomainEnd(ins)) {
            spans[ins & kTapeNodeMask] = i + 1 - begins.back();
            begins.pop_back();
        } else if (roleOf(opcode(ins)) == Role::Domain || opens(ins)) {
            begins.push_back(i);
            field.domainDepth = std::max(field.domainDepth, uint32_t(begins.size()));
        }
    }
    return spans;
}

} // namespace

PrunedField pruneField(const Evaluator& evaluator, const PruneOptions& options) {
    const std::vector<FlatNode>& nodes = evaluator.nodes();
    PrunedField field;
    field.tape = fullTape(nodes, field.stackDepth);
    field.fullLength = uint32_t(field.tape.size());
    const std::vector<uint32_t> spans = domainSpans(field, nodes.size());
    if (nodes.empty() || options.levels < 1 || !fieldGrid(evaluator, options, field)) {
        field.levels = 0;
        field.bounded = false;
        field.cells.assign(1, glm::uvec2(0, field.fullLength));
        return field;
    }
    const glm::uvec3 dims = field.dims;
    field.cells.assign(size_t(dims.x) * dims.y * dims.z, glm::uvec2(0));
    const float slack =
        1e-5f * (field.cell * float(dims.x + dims.y + dims.z) + glm::length(field.origin));

    // Sets every leaf entry under the cell `at` of `level` (in cells of its level).
    auto fillLeaves = [&](glm::uvec3 at, uint32_t level, glm::uvec2 entry) {
        const uint32_t span = 1u << (field.levels - level);
        for (uint32_t z = 0; z < span; ++z)
            for (uint32_t y = 0; y < span; ++y) {
                const glm::uvec3 l = at * span + glm::uvec3(0, y, z);
                std::fill_n(field.cells.begin() + (l.x + dims.x * (l.y + dims.y * l.z)), span,
                            entry);
            }
    };
    // Level by level: the cells that may hold surface, each with its tape in `tapes`.
    struct Cell {
        glm::uvec3 at; // in cells of its level
        uint32_t begin, length;
    };
    std::vector<Cell> cells;
    const glm::uvec3 tops = dims >> field.levels;
    for (uint32_t z = 0; z < tops.z; ++z)
        for (uint32_t y = 0; y < tops.y; ++y)
            for (uint32_t x = 0; x < tops.x; ++x)
                cells.push_back({glm::uvec3(x, y, z), 0, field.fullLength});
    std::vector<uint32_t> tapes = field.tape;
    const unsigned threads = std::max(1u, std::min(8u, std::thread::hardware_concurrency()));
    for (uint32_t level = 0; level <= field.levels; ++level) {
        const float size = field.cell * float(1u << (field.levels - level));
        const float r = 0.5f * std::sqrt(3.0f) * size;
        const float leafR = 0.5f * std::sqrt(3.0f) * field.cell;
        const bool leaf = level == field.levels;
        // This level's cells are the children of the last level's (the top cells themselves at
        // the root), pruned in groups that share a tape: a cell's eight children; at the root,
        // eight top cells at a time (they all run the whole tape).
        const uint32_t lanes = Pruner::kLanes;
        const size_t groups = level == 0 ? (cells.size() + lanes - 1) / lanes : cells.size();
        struct Out {
            std::vector<Cell> cells;
            std::vector<uint32_t> tapes;
        };
        const unsigned used = groups * lanes > 64 ? threads : 1;
        std::vector<Out> outs(used);
        std::atomic<bool> overBudget{false};
        auto work = [&](unsigned t) {
            Pruner pruner{nodes, spans, slack, field.stackDepth, field.domainDepth, {}};
            Out& out = outs[t];
            glm::uvec3 at[lanes];
            glm::vec3 centres[lanes];
            float roots[lanes];
            for (size_t g = t; g < groups && !overBudget; g += used) {
                const Cell& parent = cells[level == 0 ? g * lanes : g];
                const uint32_t count =
                    level == 0 ? uint32_t(std::min<size_t>(lanes, cells.size() - g * lanes))
                               : lanes;
                for (uint32_t l = 0; l < count; ++l) {
                    at[l] = level == 0 ? cells[g * lanes + l].at
                                       : parent.at * 2u + glm::uvec3(l & 1, l >> 1 & 1, l >> 2);
                    centres[l] = field.origin + (glm::vec3(at[l]) + 0.5f) * size;
                }
                const uint32_t* tape = tapes.data() + parent.begin;
                pruner.evaluate(tape, parent.length, centres, count, roots);
                const float far = r + (kFarRadii - 1.0f) * leafR + slack;
                // The field's direction of ascent over the eight siblings (their differences
                // along each axis), which far cells carry for shading (farGradientBits).
                uint32_t ascent = 0;
                if (level > 0) {
                    glm::vec3 rise(0.0f);
                    for (uint32_t l = 0; l < lanes; ++l)
                        rise += glm::vec3(l & 1 ? 1.0f : -1.0f, l & 2 ? 1.0f : -1.0f,
                                          l & 4 ? 1.0f : -1.0f) *
                                roots[l];
                    ascent = farGradientBits(rise);
                }
                for (uint32_t l = 0; l < count; ++l) {
                    const float v = roots[l];
                    if (std::abs(v) > far) { // no surface: fill its leaf cells
                        fillLeaves(
                            at[l], level,
                            glm::uvec2(std::bit_cast<uint32_t>(v), kFarCell | ascent | level));
                        continue;
                    }
                    const uint32_t begin = uint32_t(out.tapes.size());
                    pruner.prune(tape, parent.length, l, r, out.tapes);
                    out.cells.push_back({at[l], begin, uint32_t(out.tapes.size()) - begin});
                }
                pruner.resetExtremes();
                if (out.tapes.size() > options.maxWords / used) overBudget = true;
            }
        };
        std::vector<std::thread> pool;
        for (unsigned t = 1; t < used; ++t)
            pool.emplace_back(work, t);
        work(0);
        for (std::thread& t : pool)
            t.join();
        if (overBudget) {
            // Tapes that prune this little would exceed the budget: the parents' tapes serve
            // their leaf cells (the top cells': the whole tape). Every bound written so far
            // holds; the parents' cells only run longer tapes.
            const uint32_t base = uint32_t(field.tape.size());
            if (level > 0) field.tape.insert(field.tape.end(), tapes.begin(), tapes.end());
            for (const Cell& c : cells)
                fillLeaves(c.at, level == 0 ? 0 : level - 1,
                           level > 0 ? glm::uvec2(base + c.begin, c.length)
                                     : glm::uvec2(0, field.fullLength));
            return field;
        }
        // Gather.
        std::vector<Cell> next;
        std::vector<uint32_t> nextTapes;
        for (Out& out : outs) {
            const uint32_t base = uint32_t(nextTapes.size());
            nextTapes.insert(nextTapes.end(), out.tapes.begin(), out.tapes.end());
            for (Cell c : out.cells) {
                c.begin += base;
                next.push_back(c);
            }
        }
        if (leaf) {
            const uint32_t base = field.fullLength;
            field.tape.insert(field.tape.end(), nextTapes.begin(), nextTapes.end());
            for (const Cell& c : next)
                field.cells[c.at.x + dims.x * (c.at.y + dims.y * c.at.z)] =
                    glm::uvec2(base + c.begin, c.length);
        }
        cells = std::move(next);
        tapes = std::move(nextTapes);
    }
    return field;
}

double PrunedField::meanActiveLength() const {
    double sum = 0.0;
    size_t near = 0;
    for (const glm::uvec2& c : cells)
        if (!(c.y & kFarCell)) sum += c.y, ++near;
    return near ? sum / double(near) : 0.0;
}

namespace {

// The leaf cell of p, or nullptr outside the cube.
const glm::uvec2* cellAt(const PrunedField& f, glm::vec3 p, glm::uvec3& at) {
    const glm::vec3 q = glm::floor((p - f.origin) / f.cell);
    const glm::vec3 n(f.dims);
    if (f.levels == 0 || !(q.x >= 0 && q.y >= 0 && q.z >= 0 && q.x < n.x && q.y < n.y && q.z < n.z))
        return nullptr;
    at = glm::uvec3(q);
    return &f.cells[at.x + f.dims.x * (at.y + f.dims.y * at.z)];
}

// The bound of a far cell at p.
float farBound(const PrunedField& f, glm::uvec2 e, glm::uvec3 at, glm::vec3 p) {
    const uint32_t shift = f.levels - (e.y & 0xffu);
    const float size = f.cell * float(1u << shift);
    const glm::vec3 c = f.origin + (glm::vec3(at >> shift) + 0.5f) * size;
    const float v = std::bit_cast<float>(e.x);
    const float away = glm::length(p - c);
    return v > 0.0f ? v - away : v + away;
}

// Outside the cube of a bounded field.
float outsideBound(const PrunedField& f, glm::vec3 p) {
    Aabb cube{f.origin, f.origin + f.cell * glm::vec3(f.dims)};
    return cube.signedDistance(p) + 0.5f * f.cell;
}

} // namespace

float PrunedField::distance(const std::vector<FlatNode>& nodes, glm::vec3 p) const {
    glm::uvec3 at;
    const glm::uvec2* e = cellAt(*this, p, at);
    if (!e) {
        if (bounded) return outsideBound(*this, p);
        return tape::run<float>(nodes, tape.data(), fullLength, stackDepth, domainDepth, p);
    }
    if (e->y & kFarCell) return farBound(*this, *e, at, p);
    return tape::run<float>(nodes, tape.data() + e->x, e->y, stackDepth, domainDepth, p);
}

Sample PrunedField::sample(const std::vector<FlatNode>& nodes, glm::vec3 p) const {
    glm::uvec3 at;
    const glm::uvec2* e = cellAt(*this, p, at);
    glm::vec4 v;
    if (!e && bounded)
        v = glm::vec4(-1.0f, -1.0f, -1.0f, outsideBound(*this, p));
    else if (!e)
        v = tape::run<glm::vec4>(nodes, tape.data(), fullLength, stackDepth, domainDepth, p);
    else if (e->y & kFarCell)
        v = glm::vec4(-1.0f, -1.0f, -1.0f, farBound(*this, *e, at, p));
    else
        v = tape::run<glm::vec4>(nodes, tape.data() + e->x, e->y, stackDepth, domainDepth, p);
    return {v.w, glm::vec3(v)};
}

uint32_t PrunedField::activeLength(glm::vec3 p) const {
    glm::uvec3 at;
    const glm::uvec2* e = cellAt(*this, p, at);
    if (!e) return bounded ? 0 : fullLength;
    return e->y & kFarCell ? 0 : e->y;
}

bool isBall(const FlatNode& n) {
    if (n.kind != NodeKind::Sphere) return false;
    // Its transform times its scale is a rotation (to rounding) unless a scale differs per axis.
    const glm::dmat3 m = glm::dmat3(n.toLocal) * double(n.scale);
    const glm::dmat3 g = glm::transpose(m) * m;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
            if (std::abs(g[c][r] - (c == r ? 1.0 : 0.0)) > 1e-6) return false;
    return true;
}

bool allSpheresAreBalls(const std::vector<FlatNode>& nodes) {
    bool spheres = false;
    for (const FlatNode& n : nodes) {
        if (n.kind != NodeKind::Sphere) continue;
        if (!isBall(n)) return false;
        spheres = true;
    }
    return spheres;
}

std::vector<uint32_t> packField(const PrunedField& f, const std::vector<FlatNode>& nodes) {
    const uint32_t cellStart = uint32_t(kFieldHeaderWords + 4 * nodes.size());
    const uint32_t tapeStart = uint32_t(cellStart + 2 * f.cells.size());
    std::vector<uint32_t> out(tapeStart + f.tape.size());
    auto put = [&](size_t at, float v) { out[at] = std::bit_cast<uint32_t>(v); };
    put(0, f.origin.x);
    put(1, f.origin.y);
    put(2, f.origin.z);
    put(3, f.cell);
    out[4] = f.levels;
    out[5] = f.levels ? f.dims.x : 0;
    out[6] = f.dims.y;
    out[7] = f.dims.z;
    out[8] = f.bounded ? 1u : 0u;
    out[9] = f.fullLength;
    out[10] = tapeStart;
    out[11] = cellStart;
    // A ball's value (|M p + o| - r) s, with M its rotation divided by its scale s, is
    // |p - c| - r s with c = -M^-1 o: the shader reads the centre and that radius, one vec4,
    // in place of the transform's three rows (SDFCSG_TAPE_BALLS, tape.glsl).
    for (size_t i = 0; i < nodes.size(); ++i) {
        const FlatNode& n = nodes[i];
        if (!isBall(n)) continue;
        const glm::dvec3 c = -(glm::inverse(glm::dmat3(n.toLocal)) * glm::dvec3(n.offset));
        for (int a = 0; a < 3; ++a)
            put(kFieldHeaderWords + 4 * i + a, float(c[a]));
        put(kFieldHeaderWords + 4 * i + 3, n.params[0] * n.scale);
    }
    std::memcpy(out.data() + cellStart, f.cells.data(), f.cells.size() * 8);
    uint32_t* tape = out.data() + tapeStart;
    std::copy(f.tape.begin(), f.tape.end(), tape);
    // Within each tape, a primitive whose operation follows at once carries the operation, so
    // that the shader folds it into the running value without the stack (shaders/tape.glsl).
    std::vector<bool> marked(f.tape.size() + 1, false); // by first word: cells share tapes
    auto mark = [&](uint32_t begin, uint32_t length) {
        if (marked[begin]) return;
        marked[begin] = true;
        for (uint32_t t = begin; t + 1 < begin + length; ++t)
            if (!isDomainEnd(f.tape[t]) && !isDomainEnd(f.tape[t + 1]) &&
                roleOf(opcode(f.tape[t])) == Role::Primitive &&
                roleOf(opcode(f.tape[t + 1])) == Role::Boolean &&
                !isTransition(opcode(f.tape[t + 1]))) { // the fold's 2 bits: the first three
                const FlatNode& op = nodes[f.tape[t + 1] & kTapeNodeMask];
                tape[t] |= (uint32_t(op.kind) - uint32_t(NodeKind::Union) + 1u) << kTapeFoldShift |
                           op.blend << SDFCSG_TAPE_BLEND_SHIFT;
                tape[t + 1] = std::bit_cast<uint32_t>(op.smooth);
            }
    };
    mark(0, f.fullLength);
    for (const glm::uvec2& c : f.cells)
        if (!(c.y & kFarCell)) mark(c.x, c.y);
    return out;
}

} // namespace sdfcsg::detail
