// Scene -> GLSL. Both functions, sceneDistance (float) and sceneSample (vec4: colour, distance),
// come from the same walk, which is the evaluator's walk in eval.cpp written out as code: every
// node is evaluated once into a local, operands fold left to right, and union operands i > 0
// and difference subtrahends sit in a block that is skipped when their bounds say they cannot
// change the value. Output size and glslang's time are linear in the node count (see
// nodeIndex() in nodes.glsl and kInlineLimit); the walk uses an explicit stack.
#include "sdfcsg/compile.h"

#include "gpu_nodes.h"
#include "prune.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <string>
#include <vector>

namespace sdfcsg {
namespace {

// glslang finds each literal by a linear search through all earlier ones, so inlining every
// value makes compiling quadratic: 1000 inlined spheres take about 3 s, 2000 more than 5 s.
// Larger scenes read their values from the node buffer even when inlining is asked for.
constexpr size_t kInlineLimit = 1024;

// Shortest text that reads back as the same float, always a GLSL float literal.
void appendFloat(std::string& out, float v) {
    char buf[32];
    auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), v);
    std::string_view s(buf, size_t(end - buf));
    out += s;
    if (s.find_first_of(".e") == std::string_view::npos) out += ".0";
}

// Comments must stay on one line and pure ASCII (a trailing backslash would splice lines).
void appendCommentText(std::string& out, std::string_view text) {
    for (char c : text.substr(0, 120))
        out += (c >= 0x20 && c < 0x7f && c != '\\') ? c : '?';
}

// Node i as a uint expression (see nodeIndex in nodes.glsl).
std::string indexExpr(uint32_t i) {
    if (i < 256) return std::to_string(i) + "u";
    return "nodeIndex(" + std::to_string(i / 256) + "u, " + std::to_string(i % 256) + "u)";
}

// Where the value of kernel-parameter slot `first` lives: p0/p1 and the component letters.
std::string_view paramVector(int first) {
    return first < 4 ? "p0" : "p1";
}
std::string_view swizzle(int first, int count) {
    return std::string_view("xyzw").substr(size_t(first % 4), size_t(count));
}

void appendVector(std::string& out, const float* v, int count) {
    if (count > 1) out += "vec" + std::to_string(count) + "(";
    for (int c = 0; c < count; ++c) {
        if (c) out += ", ";
        appendFloat(out, v[c]);
    }
    if (count > 1) out += ")";
}

class Emitter {
  public:
    Emitter(const Scene& scene, std::string& out, const std::vector<detail::GpuNode>* literals,
            bool boundsTests)
        : scene_(scene), out_(out), lit_(literals), tests_(boundsTests) {}

    // The buffer-mode wrappers, e.g. `float boxNode(uint i, vec3 p)`, for the kinds in use (none
    // with values inlined).
    void helpers() {
        if (lit_) return;
        std::array<bool, kNodeKindCount> used{};
        for (const Node& n : scene_.nodes)
            used[size_t(n.kind)] = true;
        for (const KindInfo& info : nodeKinds()) {
            if (info.operation || !used[size_t(info.kind)]) continue;
            out_ += "float ";
            out_ += info.name;
            out_ += "Node(uint i, vec3 p) {\n    return ";
            out_ += info.function;
            out_ += "(toLocal(i, p)";
            for (const KernelArg& arg : info.args) {
                out_ += ", nodes[i].";
                out_ += paramVector(arg.slot);
                out_ += '.';
                out_ += swizzle(arg.slot, arg.count);
            }
            out_ += ") * nodes[i].color.w;\n}\n";
        }
        out_ += '\n';
    }

    void function(bool sample) {
        sample_ = sample;
        out_ += sample ? "vec4 sceneSample(vec3 p) {\n" : "float sceneDistance(vec3 p) {\n";
        struct Frame {
            uint32_t node, next, depth;
        };
        std::vector<Frame> stack;
        uint32_t current = 0, depth = 0;
        for (;;) {
            const Node& n = scene_.nodes[current];
            if (kindInfo(n.kind).operation) {
                const std::vector<uint32_t>& operands = n.children;
                if (!operands.empty()) {
                    stack.push_back({current, 1, depth});
                    current = operands[0];
                    ++depth;
                    continue;
                }
            } else {
                indent(depth);
                declare(current);
                leaf(current);
                comment(current);
            }
            // Fold the finished value into the enclosing operations; descend into the next child.
            for (;;) {
                if (stack.empty()) {
                    out_ += "    return ";
                    var(0);
                    out_ += ";\n}\n";
                    return;
                }
                Frame& f = stack.back();
                const Node& op = scene_.nodes[f.node];
                const std::vector<uint32_t>& operands = op.children;
                const uint32_t child = operands[f.next - 1];
                if (f.next == 1) {
                    indent(f.depth);
                    declare(f.node);
                    var(child);
                    comment(f.node);
                } else {
                    fold(f.node, child, f.depth);
                }
                if (f.next < operands.size()) {
                    current = operands[f.next++];
                    depth = f.depth + 1;
                    if (op.kind != NodeKind::Intersection) guard(f.node, current, f.depth);
                    break;
                }
                stack.pop_back();
            }
        }
    }

  private:
    void indent(uint32_t depth) { out_.append(4 * (depth + 1), ' '); }

    void var(uint32_t i) {
        out_ += sample_ ? 's' : 'd';
        out_ += std::to_string(i);
    }

    void declare(uint32_t i) {
        out_ += sample_ ? "vec4 " : "float ";
        var(i);
        out_ += " = ";
    }

    void comment(uint32_t i) {
        const Node& n = scene_.nodes[i];
        out_ += "; // ";
        if (!n.name.empty())
            appendCommentText(out_, n.name);
        else if (!n.path.empty())
            appendCommentText(out_, n.path);
        else
            out_ += "node " + std::to_string(i);
        out_ += " (";
        out_ += kindInfo(n.kind).name;
        out_ += ")\n";
    }

    void smooth(uint32_t op) {
        if (lit_)
            appendFloat(out_, (*lit_)[op].bmin.w);
        else
            out_ += "nodeSmooth(" + indexExpr(op) + ")";
    }

    void leaf(uint32_t i) {
        if (!lit_) {
            const std::string index = indexExpr(i);
            if (sample_) out_ += "withColor(" + index + ", ";
            out_ += kindInfo(scene_.nodes[i].kind).name;
            out_ += "Node(" + index + ", p)";
            if (sample_) out_ += ')';
            return;
        }
        const detail::GpuNode& g = (*lit_)[i];
        if (sample_) {
            out_ += "vec4(";
            appendVector(out_, &g.color.x, 3);
            out_ += ", ";
        }
        const KindInfo& info = kindInfo(scene_.nodes[i].kind);
        out_ += info.function;
        out_ += '(';
        localPoint(g);
        const float params[8] = {g.p0.x, g.p0.y, g.p0.z, g.p0.w, g.p1.x, g.p1.y, g.p1.z, g.p1.w};
        for (const KernelArg& arg : info.args) {
            out_ += ", ";
            appendVector(out_, params + arg.slot, arg.count);
        }
        out_ += ')';
        if (g.color.w != 1.0f) { // x * 1 is x: leaving it out changes no bit
            out_ += " * ";
            appendFloat(out_, g.color.w);
        }
        if (sample_) out_ += ')';
    }

    // The local point as a literal affine map; identities and pure translations are written
    // shorter, which gives the same bits.
    void localPoint(const detail::GpuNode& g) {
        bool linearIdentity = g.row0.x == 1 && g.row0.y == 0 && g.row0.z == 0 && g.row1.x == 0 &&
                              g.row1.y == 1 && g.row1.z == 0 && g.row2.x == 0 && g.row2.y == 0 &&
                              g.row2.z == 1;
        const float offset[3] = {g.row0.w, g.row1.w, g.row2.w};
        if (linearIdentity && offset[0] == 0 && offset[1] == 0 && offset[2] == 0) {
            out_ += "p";
        } else if (linearIdentity) {
            out_ += "(p + ";
            appendVector(out_, offset, 3);
            out_ += ")";
        } else {
            out_ += "affine(";
            for (const glm::vec4* row : {&g.row0, &g.row1, &g.row2}) {
                appendVector(out_, &row->x, 4);
                out_ += ", ";
            }
            out_ += "p)";
        }
    }

    // Opens the block of operand `child` of union/difference `op`, entered only when the
    // operand can change the running value (without bounds tests, a plain block).
    void guard(uint32_t op, uint32_t child, uint32_t depth) {
        indent(depth);
        if (!tests_) {
            out_ += "{\n";
            return;
        }
        out_ +=
            scene_.nodes[op].kind == NodeKind::Union ? "if (unionNeeds(" : "if (differenceNeeds(";
        if (lit_) {
            out_ += "boundsDistance(";
            appendVector(out_, &(*lit_)[child].bmin.x, 3);
            out_ += ", ";
            appendVector(out_, &(*lit_)[child].bmax.x, 3);
            out_ += ", p)";
        } else {
            out_ += "nodeBoundsDistance(" + indexExpr(child) + ", p)";
        }
        out_ += ", ";
        var(op);
        if (sample_) out_ += ".w";
        out_ += ", ";
        smooth(op);
        out_ += ")) {\n";
    }

    void fold(uint32_t op, uint32_t child, uint32_t depth) {
        const NodeKind kind = scene_.nodes[op].kind;
        const bool guarded = kind != NodeKind::Intersection;
        // A literal blend radius of 0 takes the sharp form: the same bits, much less code.
        const bool sharp = lit_ && (*lit_)[op].bmin.w == 0.0f;
        indent(depth + (guarded ? 1 : 0));
        var(op);
        out_ += sharp ? " = sharp" : " = op";
        out_ += kind == NodeKind::Union          ? "Union("
                : kind == NodeKind::Intersection ? "Intersection("
                                                 : "Difference(";
        var(op);
        out_ += ", ";
        var(child);
        if (!sharp) {
            out_ += ", ";
            smooth(op);
            // The profile is part of the code, as the kind is: a plain blend keeps its short call.
            if (const uint32_t blend = uint32_t(scene_.nodes[op].params[1]); blend != 0)
                out_ += ", " + std::to_string(blend) + "u";
        }
        out_ += ");\n";
        if (guarded) {
            indent(depth);
            out_ += "}\n";
        }
    }

    const Scene& scene_;
    std::string& out_;
    const std::vector<detail::GpuNode>* lit_; // null: values come from the node buffer
    bool tests_;                                  // CodegenOptions::boundsTests
    bool sample_ = false;
};

} // namespace

// Scenes with value or domain operations (shell, repeat, extrude, ...) always run on tapes,
// whatever was asked: only the tape machine evaluates those (and the 2D profiles they hold).
bool usesTapes(const Scene& scene, Evaluation evaluation) {
    for (const Node& n : scene.nodes)
        if (const Role role = kindInfo(n.kind).role; role == Role::Value || role == Role::Domain)
            return true;
    return evaluation == Evaluation::Tapes ||
           (evaluation == Evaluation::Auto && scene.nodes.size() >= kTapeMinNodes);
}

namespace {

// The most domain operations nested in one another on any path from the root.
uint32_t domainNesting(const Scene& scene) {
    std::vector<uint32_t> depth(scene.nodes.size(), 0);
    uint32_t most = 0;
    for (size_t i = 0; i < scene.nodes.size(); ++i) { // parents come first
        const Node& n = scene.nodes[i];
        const uint32_t own = depth[i] + (kindInfo(n.kind).role == Role::Domain ? 1 : 0);
        most = std::max(most, own);
        for (uint32_t c : n.children)
            depth[c] = own;
    }
    return most;
}

} // namespace

std::string generateSceneGlsl(const Scene& scene, const CodegenOptions& options) {
    if (!scene.nodes.empty() && usesTapes(scene, options.evaluation)) {
        uint32_t depth = 0;
        detail::fullTape(Evaluator(scene).nodes(), depth);
        // Stacks in powers of two: scenes of similar depth share their kernels.
        const uint32_t stack = std::max(4u, std::bit_ceil(depth));
        uint32_t kinds = 0;
        for (const Node& n : scene.nodes)
            if (!kindInfo(n.kind).operation) kinds |= 1u << uint32_t(n.kind);
        std::string out = "// Generated by sdfcsg from ";
        appendCommentText(out, scene.file.empty() ? std::string_view("<scene>") : scene.file);
        out += " (" + std::to_string(scene.nodes.size()) +
               " nodes, evaluated per region from pruned tapes: shaders/tape.glsl).\n"
               "#define SDFCSG_TAPE_STACK " + std::to_string(stack) +
               "\n#define SDFCSG_TAPE_KINDS " + std::to_string(kinds) +
               "u\n#define SDFCSG_TAPE_DOMAINS " + std::to_string(domainNesting(scene)) +
               "\n#include \"tape.glsl\"\n"
               "float sceneDistance(vec3 p) { return tapeDistance(p); }\n"
               "vec4 sceneSample(vec3 p) { return tapeSample(p); }\n";
        return out;
    }
    const bool inlined = options.inlineParams && scene.nodes.size() <= kInlineLimit;
    std::string out = "// Generated by sdfcsg from ";
    appendCommentText(out, scene.file.empty() ? std::string_view("<scene>") : scene.file);
    out += " (" + std::to_string(scene.nodes.size()) + " nodes, ";
    out += inlined ? "values inlined" : "values read from the node buffer";
    out += ").\n// One line per node, named by its name or JSON path. Children are indented one\n"
           "// level deeper than their operation, whose line follows its first child; later\n"
           "// children fold in left to right. Do not edit.\n\n";
    if (scene.nodes.empty()) {
        out += "float sceneDistance(vec3 p) { return 1e30; }\n"
               "vec4 sceneSample(vec3 p) { return vec4(0.0, 0.0, 0.0, 1e30); }\n";
        return out;
    }
    Evaluator evaluator(scene);
    std::vector<detail::GpuNode> literals;
    if (inlined) literals = detail::packNodes(evaluator);
    out.reserve(out.size() + scene.nodes.size() * (inlined ? 500 : 200));
    Emitter emitter(scene, out, inlined ? &literals : nullptr, options.boundsTests);
    emitter.helpers();
    emitter.function(false);
    out += '\n';
    emitter.function(true);
    return out;
}

} // namespace sdfcsg
