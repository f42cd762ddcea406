// Scene -> GLSL. Both functions, sceneDistance (float) and sceneSample (vec4: colour, distance),
// come from the same walk, which is the evaluator's walk in eval.cpp written out as code: every
// node is evaluated once into a local, operands fold left to right, and union operands i > 0
// and difference subtrahends sit in a block that is skipped when their bounds say they cannot
// change the value. Output size is linear in the node count; glslang's time too while values
// come from the node buffer (nodeIndex() in nodes.glsl), while each inlined literal is found by
// a search through the earlier ones (hence kInlinedMaxNodes). The walk uses an explicit stack.
#include "sdfcsg/compile.h"

#include "codegen/gpu_nodes.h"
#include "field/bake.h"
#include "field/prune.h"
#include "field/sdf.h"
#include "scene/outline.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <string>
#include <vector>

namespace sdfcsg {
namespace {

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
        : scene_(scene), out_(out), lit_(literals), tests_(boundsTests),
          gridded_(scene.nodes.size(), false) {
        // Whether node i's subtree holds a grid (a gridded outline, outline.h, or an image):
        // children come after their operation.
        for (size_t i = scene.nodes.size(); i-- > 0;) {
            const Node& n = scene.nodes[i];
            bool gridded = n.words && (!hasOutline(n.kind) || (*n.words)[0].x != 0.0f);
            for (uint32_t child : n.children)
                gridded = gridded || gridded_[child];
            gridded_[i] = gridded;
        }
    }

    // The buffer-mode wrappers, e.g. `float boxNode(uint i, vec3 p)`, for the kinds in use; with
    // values inlined, the outlines written out as code.
    void helpers() {
        if (lit_) {
            for (uint32_t i = 0; i < scene_.nodes.size(); ++i)
                if (inlinedOutline(i)) outlineFunction(i);
            return;
        }
        // `function(toLocal(i, p), ARGS` of the kind's parameters in node i.
        const auto call = [&](const KindInfo& info, std::string_view function) {
            out_ += function;
            out_ += "(toLocal(i, p)";
            for (const KernelArg& arg : info.args) {
                out_ += ", nodes[i].";
                out_ += paramVector(arg.slot);
                out_ += '.';
                out_ += swizzle(arg.slot, arg.count);
            }
        };
        std::array<bool, kNodeKindCount> used{};
        for (const Node& n : scene_.nodes)
            used[size_t(n.kind)] = true;
        for (const KindInfo& info : nodeKinds()) {
            if (info.operation || !used[size_t(info.kind)]) continue;
            out_ += "float ";
            out_ += info.name;
            out_ += "Node(uint i, vec3 p) {\n    return floorAtBounds(i, p, ";
            call(info, info.function);
            out_ += ") * nodes[i].color.w);\n}\n";
        }
        // `vec3 meshColor(uint i, vec3 p)` for the kinds with a node that has colours of its own.
        std::array<bool, kNodeKindCount> colored{};
        for (const Node& n : scene_.nodes)
            colored[size_t(n.kind)] = colored[size_t(n.kind)] || ownColors(n.kind, n.words.get());
        for (const KindInfo& info : nodeKinds()) {
            if (!colored[size_t(info.kind)]) continue;
            out_ += "vec3 ";
            out_ += info.name;
            out_ += "Color(uint i, vec3 p) {\n    return ";
            call(info, info.colorFunction);
            out_ += ", nodes[i].color.rgb);\n}\n";
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
                    if (kindInfo(n.kind).role == Role::Domain) depth += openDomain(current, depth);
                    if (taps(current)) depth += openTaps(current, depth);
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
                const Role role = kindInfo(op.kind).role;
                if (role == Role::Domain) {
                    closeDomain(f.node, child, f.depth);
                } else if (taps(f.node)) {
                    closeTaps(f.node, child, f.depth);
                } else if (role == Role::Value) {
                    indent(f.depth);
                    declare(f.node);
                    withDistance(child, "valueOp(" + kindConst(f.node) + ", " + distance(child) +
                                            ", " + param(f.node, 0) + ")");
                    comment(f.node);
                } else if (f.next == 1) {
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
                    if (op.kind != NodeKind::Intersection && !isTransition(op.kind))
                        guard(f.node, current, f.depth);
                    break;
                }
                stack.pop_back();
            }
        }
    }

  private:
    void indent(uint32_t depth) { out_.append(4 * (depth + 1), ' '); }

    // Whether node i's outline (polygon, text) is written out as code: a small one, listed by
    // contour (outline.h) in at most kInlinedOutlineWords, whose loops would read every segment
    // from the node buffer, which costs a CPU device (lavapipe) about ten times the frame
    // (a revolved polygon of 12 or 35 points), while written out they are literals. A larger
    // one is read from the buffer: written out, the code grows faster than the loop's cost
    // (a 13-character text took 4 to 16 s and 500 MB to compile, and drew slower than the loop).
    bool inlinedOutline(uint32_t i) const {
        const Node& n = scene_.nodes[i];
        return lit_ && hasOutline(n.kind) && n.words && (*n.words)[0].x == 0.0f &&
               n.words->size() <= detail::kInlinedOutlineWords;
    }

    static std::string vec2Literal(float x, float y) {
        std::string s;
        const float v[2] = {x, y};
        appendVector(s, v, 2);
        return s;
    }

    // sdOutline (shaders/sdf.glsl) unrolled over node i's outline: `float outline<i>(vec3 p)`.
    void outlineFunction(uint32_t i) {
        const glm::vec4* w = scene_.nodes[i].words->data() + 2; // the contours
        out_ += "float outline" + std::to_string(i) +
                "(vec3 p3) {\n    vec2 p = p3.xy;\n    float best = 1e30, winding = 0.0;\n"
                "    bool holds;\n";
        const uint32_t contours = uint32_t(w[1].z);
        for (uint32_t g = 0; g < contours; ++g) {
            const glm::vec4 box = w[2 * g], range = w[2 * g + 1];
            out_ += "    holds = all(greaterThanEqual(p, " + vec2Literal(box.x, box.y) +
                    ")) && all(lessThanEqual(p, " + vec2Literal(box.z, box.w) + "));\n";
            uint32_t at = uint32_t(range.x);
            for (uint32_t s = 0; s < uint32_t(range.y); ++s, ++at) {
                const std::string a = vec2Literal(w[at].x, w[at].y),
                                  b = vec2Literal(w[at].z, w[at].w);
                out_ += "    if (holds) winding += lineCrossing(p, " + a + ", " + b + ");\n";
                out_ += "    best = min(best, sqSegment2(p, " + a + ", " + b + "));\n";
            }
            for (uint32_t s = 0; s < uint32_t(range.w); ++s, at += 2) {
                const std::string a = vec2Literal(w[at].x, w[at].y),
                                  b = vec2Literal(w[at].z, w[at].w),
                                  c = vec2Literal(w[at + 1].x, w[at + 1].y);
                out_ += "    if (holds) winding += quadraticCrossing(p, " + a + ", " + c + ", " +
                        b + ");\n";
                out_ += "    best = min(best, sqQuadratic2(p, " + a + ", " + c + ", " + b + "));\n";
            }
        }
        out_ += "    return winding != 0.0 ? -sqrt(best) : sqrt(best);\n}\n\n";
    }

    // The point the code at hand evaluates at: p, or inside domain operations the candidate
    // point of the innermost one.
    const std::string& point() const { return points_.back(); }

    std::string kindConst(uint32_t i) const {
        return std::to_string(uint32_t(scene_.nodes[i].kind)) + "u";
    }

    // Node i's kernel parameters a (0) or b (1), as literals or read from the node buffer.
    std::string param(uint32_t i, int which) const {
        if (!lit_) return "nodes[" + indexExpr(i) + "]." + (which == 0 ? "p0" : "p1");
        std::string s;
        const glm::vec4& v = which == 0 ? (*lit_)[i].p0 : (*lit_)[i].p1;
        appendVector(s, &v.x, 4);
        return s;
    }

    // The distance from `at` to node i's bounds.
    std::string boundsDistanceOf(uint32_t i, const std::string& at) const {
        if (!lit_) return "nodeBoundsDistance(" + indexExpr(i) + ", " + at + ")";
        std::string s = "boundsDistance(";
        appendVector(s, &(*lit_)[i].bmin.x, 3);
        s += ", ";
        appendVector(s, &(*lit_)[i].bmax.x, 3);
        return s + ", " + at + ")";
    }

    // Node i's bounds' least (max false) or greatest corner.
    std::string boundsCorner(uint32_t i, bool max) const {
        if (!lit_) return "nodes[" + indexExpr(i) + "]." + (max ? "bmax" : "bmin") + ".xyz";
        std::string s;
        appendVector(s, max ? &(*lit_)[i].bmax.x : &(*lit_)[i].bmin.x, 3);
        return s;
    }

    std::string distance(uint32_t i) const {
        return (sample_ ? "s" : "d") + std::to_string(i) + (sample_ ? ".w" : "");
    }

    // Node `like`'s value with distance d: d, or its colour and d.
    void withDistance(uint32_t like, const std::string& d) {
        if (!sample_) {
            out_ += d;
            return;
        }
        out_ += "vec4(";
        var(like);
        out_ += ".rgb, " + d + ")";
    }

    // Domain operation i (shaders/sdf.glsl, and tape_run.glsl for the same steps on tapes): its
    // child's code runs inside a block, in a loop over the candidates for repetitions, at the
    // candidate point p<level>; a candidate after the first runs only where its bounds could
    // lower the least value so far, which is why N copies cost about one. Returns the child's
    // code's extra indentation.
    uint32_t openDomain(uint32_t i, uint32_t depth) {
        const Node& n = scene_.nodes[i];
        const uint32_t kind = uint32_t(n.kind);
        const std::string level = std::to_string(points_.size());
        const std::string local = "l" + level, best = "b" + level, c = "c" + level, q = "q" + level;
        openBlock(i, depth);
        indent(depth + 1);
        out_ += "vec3 " + local + " = ";
        std::string at = point();
        if (sdf::domainClamps(kind))
            at = "clamp(" + at + ", " + boundsCorner(i, false) + ", " + boundsCorner(i, true) + ")";
        localPoint(i, at);
        out_ += ";\n";
        indent(depth + 1);
        out_ += (sample_ ? "vec4 " : "float ") + best +
                (sample_ ? " = vec4(0.0, 0.0, 0.0, 1e30);\n" : " = 1e30;\n");
        const std::string a = param(i, 0), b = param(i, 1);
        std::string count = "domainCount(" + kindConst(i) + ", " + a + ", " + b + ")";
        if (lit_)
            count = std::to_string(sdf::domainCount(kind, (*lit_)[i].p0, (*lit_)[i].p1)) + "u";
        const bool loops =
            lit_ ? count != "1u" : n.kind == NodeKind::Repeat || n.kind == NodeKind::PolarRepeat;
        const std::string candidate = "domainPoint(" + kindConst(i) + ", " + local + ", " + a +
                                      ", " + b + ", " + (loops ? c : std::string("0u")) + ")";
        points_.push_back("p" + std::to_string(points_.size()));
        loops_.push_back(loops);
        if (!loops) {
            indent(depth + 1);
            out_ += "vec3 " + point() + " = " + candidate + ".xyz;\n";
            return 0;
        }
        indent(depth + 1);
        out_ += "for (uint " + c + " = 0u; " + c + " < " + count + "; ++" + c + ") {\n";
        indent(depth + 2);
        out_ += "vec4 " + q + " = " + candidate + ";\n";
        indent(depth + 2);
        out_ += "if (" + c + " > 0u && (" + q + ".w != 0.0 || " +
                boundsDistanceOf(n.children[0], q + ".xyz") + " >= " + best +
                (sample_ ? ".w" : "") + ")) continue;\n";
        indent(depth + 2);
        out_ += "vec3 " + point() + " = " + q + ".xyz;\n";
        return 1;
    }

    void closeDomain(uint32_t i, uint32_t child, uint32_t depth) {
        points_.pop_back();
        const std::string level = std::to_string(points_.size());
        const std::string local = "l" + level, best = "b" + level;
        const bool loops = loops_.back();
        loops_.pop_back();
        indent(depth + (loops ? 2 : 1));
        if (sample_) {
            out_ += "if (" + distance(child) + " < " + best + ".w) " + best + " = ";
            var(child);
            out_ += ";\n";
        } else {
            out_ += best + " = min(" + best + ", " + distance(child) + ");\n";
        }
        if (loops) {
            indent(depth + 1);
            out_ += "}\n";
        }
        std::string value = "domainFinish(" + kindConst(i) + ", " + local + ", " + best +
                            (sample_ ? ".w" : "") + ", " + param(i, 0) + ", " + param(i, 1) + ")";
        if (!lit_)
            value += " * nodes[" + indexExpr(i) + "].color.w";
        else if ((*lit_)[i].color.w != 1.0f) {
            value += " * ";
            appendFloat(value, (*lit_)[i].color.w);
        }
        value = "max(" + value + ", " + boundsDistanceOf(i, point()) + ")"; // eval.cpp's floor
        indent(depth + 1);
        var(i);
        out_ += " = ";
        if (sample_)
            out_ += "vec4(" + best + ".rgb, " + value + ")";
        else
            out_ += value;
        out_ += ";\n";
        indent(depth);
        out_ += "}\n";
    }

    // Whether offset or shell i runs its child at four taps (sdf.glsl, valueNormalised): with
    // values inlined, where its child's field is not a distance (FlatNode::loss); read from the
    // node buffer, always, at one tap where it is one (a value edit may change which).
    bool taps(uint32_t i) const {
        if (kindInfo(scene_.nodes[i].kind).role != Role::Value) return false;
        return !lit_ || (*lit_)[i].p0.y > 0.0f;
    }

    // Offset or shell i over its child at the taps: the child's code in a loop, at p<level>.
    // Returns the child's code's extra indentation.
    uint32_t openTaps(uint32_t i, uint32_t depth) {
        const std::string level = std::to_string(points_.size());
        const std::string c = "c" + level;
        openBlock(i, depth);
        indent(depth + 1);
        out_ += "vec4 t" + level + " = vec4(0.0);\n";
        if (sample_) {
            indent(depth + 1);
            out_ += "vec4 f" + level + " = vec4(0.0);\n";
        }
        std::string step = "nodes[" + indexExpr(i) + "].p0.y", count = "4u";
        if (lit_) {
            step.clear();
            appendFloat(step, (*lit_)[i].p0.y);
        } else {
            count = "(" + step + " > 0.0 ? 4u : 1u)";
        }
        indent(depth + 1);
        out_ += "for (uint " + c + " = 0u; " + c + " < " + count + "; ++" + c + ") {\n";
        indent(depth + 2);
        out_ += "vec3 p" + level + " = valueTap(" + point() + ", " + step + ", " + c + ");\n";
        points_.push_back("p" + level);
        return 1;
    }

    void closeTaps(uint32_t i, uint32_t child, uint32_t depth) {
        points_.pop_back();
        const std::string level = std::to_string(points_.size());
        const std::string t = "t" + level, c = "c" + level;
        indent(depth + 2);
        out_ += t + " = valueTapSum(" + t + ", " + distance(child) + ", " + c + ");\n";
        if (sample_) {
            indent(depth + 2);
            out_ += "if (" + c + " == 0u) f" + level + " = ";
            var(child);
            out_ += ";\n";
        }
        indent(depth + 1);
        out_ += "}\n";
        const std::string a = param(i, 0);
        std::string value = "valueOpNormalised(" + kindConst(i) + ", " + t + ", " + a + ")";
        // eval.cpp's floor, where the node normalises.
        if (lit_)
            value = "max(" + value + ", " + boundsDistanceOf(i, point()) + ")";
        else
            value = "(" + a + ".y > 0.0 ? max(" + value + ", " + boundsDistanceOf(i, point()) +
                    ") : " + value + ")";
        indent(depth + 1);
        var(i);
        out_ += " = ";
        out_ += sample_ ? "vec4(f" + level + ".rgb, " + value + ")" : value;
        out_ += ";\n";
        indent(depth);
        out_ += "}\n";
    }

    void var(uint32_t i) {
        out_ += sample_ ? 's' : 'd';
        out_ += std::to_string(i);
    }

    // Node i's variable, declared with its comment, and the block that computes it.
    void openBlock(uint32_t i, uint32_t depth) {
        indent(depth);
        out_ += sample_ ? "vec4 " : "float ";
        var(i);
        comment(i);
        indent(depth);
        out_ += "{\n";
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

    // Node i's value with its colour: the node's, or its own where it has colours of its own
    // (ownColors), by its kind's colorFunction at the same point, from the same arguments.
    void leaf(uint32_t i) {
        const Node& n = scene_.nodes[i];
        const KindInfo& info = kindInfo(n.kind);
        const bool colored = sample_ && ownColors(n.kind, n.words.get());
        if (!lit_) {
            const std::string index = indexExpr(i);
            if (colored)
                out_ +=
                    "vec4(" + std::string(info.name) + "Color(" + index + ", " + point() + "), ";
            else if (sample_)
                out_ += "withColor(" + index + ", ";
            out_ += info.name;
            out_ += "Node(" + index + ", " + point() + ")";
            if (sample_) out_ += ')';
            return;
        }
        const detail::GpuNode& g = (*lit_)[i];
        const bool outline = inlinedOutline(i); // its data is in the function's code
        // The local point and the formula's arguments after it.
        const size_t mark = out_.size();
        localPoint(i, point());
        const float params[8] = {g.p0.x, g.p0.y, g.p0.z, g.p0.w, g.p1.x, g.p1.y, g.p1.z, g.p1.w};
        for (const KernelArg& arg : outline ? std::span<const KernelArg>{} : info.args) {
            out_ += ", ";
            appendVector(out_, params + arg.slot, arg.count);
        }
        const std::string args = out_.substr(mark);
        out_.resize(mark);
        if (sample_) {
            out_ += "vec4(";
            if (colored) out_ += std::string(info.colorFunction) + "(" + args + ", ";
            appendVector(out_, &g.color.x, 3);
            out_ += colored ? "), " : ", ";
        }
        const bool floored = g.bmin.w != 0.0f; // FlatNode::boundsFloor
        if (floored) out_ += "max(";
        out_ += outline ? "outline" + std::to_string(i) : std::string(info.function);
        out_ += '(' + args + ')';
        if (g.color.w != 1.0f) { // x * 1 is x: leaving it out changes no bit
            out_ += " * ";
            appendFloat(out_, g.color.w);
        }
        if (floored) out_ += ", " + boundsDistanceOf(i, point()) + ")";
        if (sample_) out_ += ')';
    }

    // The local point as a literal affine map; identities and pure translations are written
    // shorter, which gives the same bits.
    void localPoint(uint32_t i, const std::string& at) {
        if (!lit_) {
            out_ += "toLocal(" + indexExpr(i) + ", " + at + ")";
            return;
        }
        const detail::GpuNode& g = (*lit_)[i];
        bool linearIdentity = g.row0.x == 1 && g.row0.y == 0 && g.row0.z == 0 && g.row1.x == 0 &&
                              g.row1.y == 1 && g.row1.z == 0 && g.row2.x == 0 && g.row2.y == 0 &&
                              g.row2.z == 1;
        const float offset[3] = {g.row0.w, g.row1.w, g.row2.w};
        if (linearIdentity && offset[0] == 0 && offset[1] == 0 && offset[2] == 0) {
            out_ += at;
        } else if (linearIdentity) {
            out_ += "(" + at + " + ";
            appendVector(out_, offset, 3);
            out_ += ")";
        } else {
            out_ += "affine(";
            for (const glm::vec4* row : {&g.row0, &g.row1, &g.row2}) {
                appendVector(out_, &row->x, 4);
                out_ += ", ";
            }
            out_ += at + ")";
        }
    }

    // Opens the block of operand `child` of union/difference `op`, entered only when the
    // operand can change the running value (without bounds tests, a plain block). An operand
    // with a gridded outline is always tested: its loops cost more than the test, even on a CPU
    // device that runs both sides of the branch where its lanes disagree.
    void guard(uint32_t op, uint32_t child, uint32_t depth) {
        indent(depth);
        if (!tests_ && !gridded_[child]) {
            out_ += "{\n";
            return;
        }
        const bool unionOp = scene_.nodes[op].kind == NodeKind::Union;
        out_ += gridded_[child] ? (unionOp ? "if (unionChanges(" : "if (differenceChanges(")
                                : (unionOp ? "if (unionNeeds(" : "if (differenceNeeds(");
        out_ += boundsDistanceOf(child, point());
        out_ += ", ";
        var(op);
        if (sample_) out_ += ".w";
        out_ += ", ";
        smooth(op);
        out_ += ")) {\n";
    }

    // A transition's second child into its first (eval.cpp: the morph at the node's local point,
    // floored at its bounds).
    void transition(uint32_t op, uint32_t child, uint32_t depth) {
        const std::string a = param(op, 0), b = param(op, 1), w = "w" + std::to_string(op);
        indent(depth);
        out_ += "float " + w + " = transitionWeight(" + kindConst(op) + ", ";
        localPoint(op, point());
        out_ += ", " + a + ", " + b + ");\n";
        indent(depth);
        var(op);
        out_ += " = opTransition(";
        var(op);
        out_ += ", ";
        var(child);
        out_ += ", " + w + ", " + b + ");\n";
        indent(depth);
        var(op);
        out_ += " = ";
        withDistance(op, "max(" + distance(op) + ", " + boundsDistanceOf(op, point()) + ")");
        out_ += ";\n";
    }

    void fold(uint32_t op, uint32_t child, uint32_t depth) {
        const NodeKind kind = scene_.nodes[op].kind;
        if (isTransition(kind)) return transition(op, child, depth);
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
            // Literal, the profile is part of the code, as the kind is: a plain blend keeps its
            // short call. Read from the buffer it is a value, as the radius is, so that
            // Renderer::updateValues keeps the kernel (sameStructure does not compare it).
            if (!lit_)
                out_ += ", nodeBlend(" + std::to_string(op) + "u)";
            else if (const uint32_t blend = uint32_t(scene_.nodes[op].params[1]); blend != 0)
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
    bool tests_;                              // CodegenOptions::boundsTests
    std::vector<bool> gridded_;               // per node, see the constructor
    bool sample_ = false;
    std::vector<std::string> points_{"p"}; // see point()
    std::vector<bool> loops_;              // per open domain operation: whether it loops
};

} // namespace

bool usesTapes(const Scene& scene, Evaluation evaluation) {
    return evaluation == Evaluation::Tapes ||
           (evaluation == Evaluation::Auto && scene.nodes.size() >= kTapeMinNodes);
}

Status checkEvaluation(const Scene& scene, Evaluation evaluation) {
    if (evaluation != Evaluation::Inlined || scene.nodes.size() <= kInlinedMaxNodes) return Ok{};
    return Error(ErrorKind::Limit,
                 Diagnostic{scene.file, "root",
                            "inlined evaluation takes at most " + std::to_string(kInlinedMaxNodes) +
                                " nodes and this scene has " + std::to_string(scene.nodes.size()) +
                                "; evaluate it from tapes (--evaluation tapes or auto)"});
}

namespace {

// The most domain operations nested in one another on any path from the root.
uint32_t domainNesting(const Scene& scene) {
    std::vector<uint32_t> depth(scene.nodes.size(), 0);
    uint32_t most = 0;
    for (size_t i = 0; i < scene.nodes.size(); ++i) { // parents come first
        const Node& n = scene.nodes[i];
        // Offsets and shells may normalise their child's field (eval.cpp), which the tape
        // machine runs as it runs a domain operation's child.
        const Role role = kindInfo(n.kind).role;
        const uint32_t own = depth[i] + (role == Role::Domain || role == Role::Value ? 1 : 0);
        most = std::max(most, own);
        for (uint32_t c : n.children)
            depth[c] = own;
    }
    return most;
}

} // namespace

std::string generateSceneGlsl(const Scene& scene, const CodegenOptions& options) {
    if (!scene.nodes.empty() && usesTapes(scene, options.evaluation)) {
        const Evaluator evaluator(scene);
        const std::vector<FlatNode>& nodes = evaluator.nodes();
        uint32_t depth = 0;
        detail::fullTape(nodes, depth);
        // What the tape machine needs, so that it holds no code for the rest: lavapipe runs
        // every branch of its loop at every instruction, taken or not (molecule_1k's frame was
        // a third shorter without the operations' own branch). The kinds of primitive and of
        // operation (less Union); and whether an operation may fold in a value that is not a
        // primitive's, which is the only one to read the stack (a domain operation saves on it
        // too): else every operation folds in the primitive before it at once (tape.glsl), and
        // pruning keeps that so. All follow the structure, not values, so that a value edit
        // stays an upload (every blend profile is kept: a profile is a value), but for one:
        uint32_t kinds = 0, operations = 0, colors = 0;
        Scene storage;
        const uint32_t domains = domainNesting(detail::bakedView(scene, storage));
        bool stackRead = domains > 0;
        for (const FlatNode& n : nodes) {
            const Role role = kindInfo(n.kind).role;
            if (role == Role::Primitive) kinds |= 1u << uint32_t(n.kind);
            if (n.ownColors) colors |= 1u << uint32_t(n.kind);
            if (role == Role::Boolean || role == Role::Value)
                operations |= 1u << (uint32_t(n.kind) - uint32_t(NodeKind::Union));
            if (role != Role::Boolean) continue;
            stackRead |= isTransition(n.kind); // never folded into a primitive's instruction
            for (size_t c = 1; c < n.children.size(); ++c)
                stackRead |= kindInfo(nodes[n.children[c]].kind).role != Role::Primitive;
        }
        // spheres read as balls (detail::isBall) where all of them are and values may be baked
        // in: a sphere scaled differently per axis changes that (Renderer::updateValues then
        // recompiles). Kernels that take every value from buffers read spheres as the others.
        const uint32_t sphere = 1u << uint32_t(NodeKind::Sphere);
        const bool balls = options.inlineParams && detail::allSpheresAreBalls(nodes);
        if (balls) kinds &= ~sphere;
        // Stacks in powers of two: scenes of similar depth share their kernels.
        const uint32_t stack = stackRead ? std::max(4u, std::bit_ceil(depth)) : 0u;
        std::string out = "// Generated by sdfcsg from ";
        appendCommentText(out, scene.file.empty() ? std::string_view("<scene>") : scene.file);
        out += " (" + std::to_string(scene.nodes.size()) +
               " nodes, evaluated per region from pruned tapes: shaders/tape.glsl).\n"
               "#define SDFCSG_TAPE_STACK " +
               std::to_string(stack) + "\n#define SDFCSG_TAPE_KINDS " + std::to_string(kinds) +
               "u\n#define SDFCSG_TAPE_OPERATIONS " + std::to_string(operations) +
               "\n#define SDFCSG_TAPE_BALLS " + (balls ? "1" : "0") +
               "\n#define SDFCSG_TAPE_DOMAINS " + std::to_string(domains) +
               "\n#define SDFCSG_TAPE_COLORS " + std::to_string(colors) + "u" +
               "\n#include \"tape.glsl\"\n"
               "float sceneDistance(vec3 p) { return tapeDistance(p); }\n"
               "vec4 sceneSample(vec3 p) { return tapeSample(p); }\n";
        return out;
    }
    const bool inlined = options.inlineParams;
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
    // A baked offset's child is a mesh node, its subtree left out (field/bake.h).
    Scene storage;
    Emitter emitter(detail::bakedView(scene, storage), out, inlined ? &literals : nullptr,
                    options.boundsTests);
    emitter.helpers();
    emitter.function(false);
    out += '\n';
    emitter.function(true);
    return out;
}

} // namespace sdfcsg
