// Import of the original SDFBooleanEngine format: {"nodes": [{"type": int, "left": i, "right": j,
// "param1": [4], "param2": [4], "color": [3]}, ...]}, binary operations whose operands are
// indices into the array, the last node the root. Each primitive is rewritten into the current
// kind with the same surface and the same field (see the formulas in convertPrimitive).
// Chains of the same operation become one n-ary operation, which gives the same field (min and
// max fold left to right) and keeps long legacy union chains within Limits::maxDepth.
#include "scene/legacy.h"

#include "scene/json_writer.h"

#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

#include <algorithm>
#include <cmath>

namespace sdfcsg::detail {
namespace {

namespace dom = simdjson::dom;

struct LegacyType {
    int code;
    NodeKind kind;
    std::string_view name;
    // What the first components of param2 mean, for those that must be positive.
    std::array<std::string_view, 4> positive;
};

constexpr LegacyType kTypes[] = {
    {0, NodeKind::Sphere, "sphere", {"the radius"}},
    {1,
     NodeKind::Box,
     "box",
     {"the half extent along x", "the half extent along y", "the half extent along z"}},
    {2, NodeKind::Plane, "plane", {}},
    {3,
     NodeKind::TriangularPrism,
     "triangular prism",
     {"h.x, the triangle's size", "h.y, the half length"}},
    {4, NodeKind::Torus, "torus", {"the major radius", "the minor radius"}},
    {5, NodeKind::Cylinder, "cylinder", {"the half height", "the radius"}},
    {6,
     NodeKind::Cone,
     "cone",
     {"the sine of the half angle", "the cosine of the half angle", "the height"}},
    {7, NodeKind::Capsule, "capsule", {"", "", "", "the radius"}},
    {10, NodeKind::Union, "union", {}},
    {11, NodeKind::Intersection, "intersection", {}},
    {12, NodeKind::Difference, "difference", {}},
};

constexpr std::string_view kTypeList =
    "0 sphere, 1 box, 2 plane, 3 triangular prism, 4 torus, 5 cylinder, 6 cone, 7 capsule, "
    "10 union, 11 intersection or 12 difference";

struct LegacyNode {
    enum class Field : uint8_t { Absent, Bad, Ok };
    const LegacyType* type = nullptr;
    int64_t operand[2] = {-1, -1}; // left, right
    Field operandField[2] = {Field::Absent, Field::Absent};
    std::array<float, 4> p1{}, p2{};
    bool p2Ok = false; // read, so its values can be judged
    std::optional<glm::vec3> color;
    bool operation() const { return type && type->code >= 10; }
};

std::string nodePath(size_t i) {
    return item("nodes", i);
}

std::optional<int64_t> readInteger(element value, const std::string& path, std::string_view what,
                                   Problems& problems) {
    if (value.is_int64()) return value.get_int64().value_unsafe();
    if (value.is_number()) {
        double d = value.get_double().value_unsafe();
        if (d == std::floor(d) && std::fabs(d) < 9e15) return static_cast<int64_t>(d);
    }
    problems.add(path, "expected " + std::string(what) + ", got " + describe(value));
    return std::nullopt;
}

std::optional<std::array<float, 4>> readParams(element value, const std::string& path,
                                               Problems& problems) {
    if (!value.is_array() || asArray(value).size() != 4) {
        problems.add(path, "expected an array of 4 numbers, got " + describe(value));
        return std::nullopt;
    }
    std::array<float, 4> out{};
    bool ok = true;
    size_t i = 0;
    for (element e : asArray(value)) {
        auto n = readNumber(e, item(path, i), Check::Any, problems);
        if (n) out[i] = static_cast<float>(*n);
        ok = ok && n.has_value();
        ++i;
    }
    if (!ok) return std::nullopt;
    return out;
}

// Reads the fields of one legacy node; operand indices are checked later, once all types are
// known.
LegacyNode readNode(element value, size_t index, Problems& problems) {
    LegacyNode node;
    const std::string path = nodePath(index);
    if (!value.is_object()) {
        problems.add(path,
                     "expected a legacy node (an object with \"type\"), got " + describe(value));
        return node;
    }
    static constexpr std::string_view kKeys[] = {"type",   "left",   "right",
                                                 "param1", "param2", "color"};
    auto v =
        readMembers(asObject(value), path, kKeys, std::size(kKeys), " for a legacy node", problems);
    if (!v[0]) {
        problems.add(path, "missing required key \"type\" (" + std::string(kTypeList) + ")");
    } else if (auto code =
                   readInteger(*v[0], member(path, "type"), "an integer type code", problems)) {
        for (const LegacyType& t : kTypes)
            if (t.code == *code) node.type = &t;
        if (!node.type)
            problems.add(member(path, "type"), "unknown legacy node type " + std::to_string(*code) +
                                                   "; expected " + std::string(kTypeList));
    }
    for (int k = 0; k < 2; ++k) {
        if (!v[1 + k]) continue;
        auto i = readInteger(*v[1 + k], member(path, kKeys[1 + k]), "a node index or -1", problems);
        node.operand[k] = i.value_or(-1);
        node.operandField[k] = i ? LegacyNode::Field::Ok : LegacyNode::Field::Bad;
    }
    for (int k = 0; k < 2; ++k) {
        if (v[3 + k]) {
            auto p = readParams(*v[3 + k], member(path, kKeys[3 + k]), problems);
            if (p) (k == 0 ? node.p1 : node.p2) = *p;
            if (k == 1) node.p2Ok = p.has_value();
        } else if (node.type && !node.operation()) {
            problems.add(path, "missing required key \"" + std::string(kKeys[3 + k]) +
                                   "\" (an array of 4 numbers)");
        }
    }
    if (v[5]) node.color = readColor(*v[5], member(path, "color"), problems);
    return node;
}

// Checks that operands match the node's type and that its parameters describe a real shape.
void checkNode(const LegacyNode& node, size_t index, size_t count, Problems& problems) {
    if (!node.type) return;
    const std::string path = nodePath(index);
    const std::string named = std::string(node.type->code == 11 ? "an " : "a ") +
                              std::string(node.type->name) + " (type " +
                              std::to_string(node.type->code) + ")";
    const std::string range = "a node index in 0.." + std::to_string(count - 1);
    for (int k = 0; k < 2; ++k) {
        const std::string key = k == 0 ? "left" : "right";
        const int64_t i = node.operand[k];
        if (node.operandField[k] == LegacyNode::Field::Bad) continue;
        if (node.operation() && node.operandField[k] == LegacyNode::Field::Absent) {
            problems.add(path, "missing required key \"" + key + "\" (the index of the " +
                                   (k == 0 ? "first" : "second") + " operand)");
        } else if (!node.operation() && i != -1) {
            problems.add(member(path, key),
                         named + " takes no operands; expected -1, got " + std::to_string(i));
        } else if (node.operation() && i == -1) {
            problems.add(member(path, key),
                         named + " needs two operands; expected " + range + ", got -1");
        } else if (node.operation() && (i < 0 || i >= static_cast<int64_t>(count))) {
            problems.add(member(path, key), "expected " + range + ", got " + std::to_string(i));
        }
    }
    if (!node.p2Ok) return;
    for (size_t k = 0; k < 4; ++k)
        if (!node.type->positive[k].empty() && !(node.p2[k] > 0.0f))
            problems.add(item(member(path, "param2"), k), "expected a positive number (" +
                                                              std::string(node.type->positive[k]) +
                                                              "), got " + formatFloat(node.p2[k]));
    if (node.type->code == 2 && node.p2[0] == 0.0f && node.p2[1] == 0.0f && node.p2[2] == 0.0f)
        problems.add(member(path, "param2"), "expected a non-zero plane normal in the first three "
                                             "numbers, got [0, 0, 0, " +
                                                 formatFloat(node.p2[3]) + "]");
}

void setParam(Node& node, std::string_view name, float value) {
    for (const ParamInfo& p : kindInfo(node.kind).params)
        if (p.name == name) node.params[p.slot] = value;
}
void setParam(Node& node, std::string_view name, glm::vec3 value) {
    for (const ParamInfo& p : kindInfo(node.kind).params)
        if (p.name == name) std::copy_n(&value.x, 3, node.params.data() + p.slot);
}

Node convert(const LegacyNode& in, size_t index) {
    Node out;
    out.kind = in.type->kind;
    out.path = nodePath(index);
    out.color = in.color;
    const glm::vec3 c(in.p1[0], in.p1[1], in.p1[2]);
    const glm::vec4 h(in.p2[0], in.p2[1], in.p2[2], in.p2[3]);
    switch (in.type->code) {
    case 0:
        out.transform.translate = c;
        setParam(out, "radius", h.x);
        break;
    case 1:
        out.transform.translate = c;
        setParam(out, "size", 2.0f * glm::vec3(h));
        break;
    case 2: {
        // Legacy: dot(p - c, n) + w. With n scaled to unit length the value scales by 1/|n|,
        // which keeps the surface; offset is then dot(c, n) - w along the unit normal.
        const glm::dvec3 n(h.x, h.y, h.z);
        const double len = glm::length(n);
        setParam(out, "normal", glm::vec3(n / len));
        setParam(out, "offset", static_cast<float>(glm::dot(glm::dvec3(c), n) / len - h.w / len));
        break;
    }
    case 3:
        // IQ's sdTriPrism(p, h): an equilateral triangle with inradius h.x/2 around its
        // centroid, y from -h.x/2 to h.x, extruded by +-h.y along z. Ours is isosceles with its
        // bounding box centred, so the box centre moves up by h.x/4.
        out.transform.translate = c + glm::vec3(0.0f, 0.25f * h.x, 0.0f);
        setParam(out, "width", std::sqrt(3.0f) * h.x);
        setParam(out, "height", 1.5f * h.x);
        setParam(out, "length", 2.0f * h.y);
        break;
    case 4:
        out.transform.translate = c;
        setParam(out, "major_radius", h.x);
        setParam(out, "minor_radius", h.y);
        break;
    case 5:
        out.transform.translate = c;
        setParam(out, "radius", h.y);
        setParam(out, "height", 2.0f * h.x);
        break;
    case 6:
        // IQ's sdCone(p, c, h): apex at the origin, opening downward to height h, base radius
        // h * tan(angle). Ours is centred half way up.
        out.transform.translate = c - glm::vec3(0.0f, 0.5f * h.z, 0.0f);
        setParam(out, "radius", h.z * h.x / h.y);
        setParam(out, "height", h.z);
        setParam(out, "top_radius", 0.0f);
        break;
    case 7:
        setParam(out, "a", c);
        setParam(out, "b", glm::vec3(h));
        setParam(out, "radius", h.w);
        break;
    default:
        break; // operations: no parameters, smooth 0
    }
    return out;
}

bool finiteNode(const Node& n) {
    return std::all_of(n.params.begin(), n.params.end(),
                       [](float v) { return std::isfinite(v); }) &&
           std::isfinite(n.transform.translate.x) && std::isfinite(n.transform.translate.y) &&
           std::isfinite(n.transform.translate.z);
}

// Reports the first cycle reachable from the root; iterative depth-first search.
bool findCycle(const std::vector<LegacyNode>& nodes, size_t root, Problems& problems) {
    enum : uint8_t { White, Grey, Black };
    std::vector<uint8_t> mark(nodes.size(), White);
    std::vector<std::pair<size_t, int>> stack{{root, 0}};
    mark[root] = Grey;
    while (!stack.empty()) {
        auto& [u, k] = stack.back();
        if (!nodes[u].operation() || k == 2) {
            mark[u] = Black;
            stack.pop_back();
            continue;
        }
        const auto v = static_cast<size_t>(nodes[u].operand[k]);
        const std::string path = member(nodePath(u), k == 0 ? "left" : "right");
        ++k;
        if (mark[v] == Grey) {
            problems.add(path, v == u ? "refers to node " + std::to_string(v) + " itself (a cycle)"
                                      : "refers to node " + std::to_string(v) +
                                            ", which contains node " + std::to_string(u) +
                                            " (a cycle)");
            return true;
        }
        if (mark[v] == White) {
            mark[v] = Grey;
            stack.push_back({v, 0});
        }
    }
    return false;
}

struct Operand {
    size_t legacy;
    std::optional<glm::vec3> color; // from a flattened operation in between, if any
};

// The operands of operation x once nested operations of the same kind are merged into it:
// union(union(a, b), c) -> union(a, b, c); difference only along its first operand. A merged
// operation's colour passes to those of its operands that have none, as it would have by
// inheritance. Returns false when more than `budget` operands come out (shared subtrees can
// multiply).
bool flatOperands(const std::vector<LegacyNode>& nodes, size_t x, size_t budget,
                  std::vector<Operand>& out) {
    out.clear();
    const int code = nodes[x].type->code;
    auto inherit = [&](size_t m, std::optional<glm::vec3> carried) {
        return nodes[m].color ? nodes[m].color : carried;
    };
    if (code == 12) {
        std::vector<Operand> rights;
        size_t c = x;
        std::optional<glm::vec3> carried;
        for (;;) {
            rights.push_back({static_cast<size_t>(nodes[c].operand[1]), carried});
            size_t left = static_cast<size_t>(nodes[c].operand[0]);
            if (!nodes[left].type || nodes[left].type->code != code) {
                out.push_back({left, carried});
                break;
            }
            c = left;
            carried = inherit(c, carried);
            if (rights.size() > budget) return false;
        }
        out.insert(out.end(), rights.rbegin(), rights.rend());
        return out.size() <= budget;
    }
    std::vector<Operand> stack{{static_cast<size_t>(nodes[x].operand[1]), {}},
                               {static_cast<size_t>(nodes[x].operand[0]), {}}};
    while (!stack.empty()) {
        Operand o = stack.back();
        stack.pop_back();
        if (nodes[o.legacy].type->code == code) {
            auto carried = inherit(o.legacy, o.color);
            stack.push_back({static_cast<size_t>(nodes[o.legacy].operand[1]), carried});
            stack.push_back({static_cast<size_t>(nodes[o.legacy].operand[0]), carried});
        } else {
            out.push_back(o);
            if (out.size() > budget) return false;
        }
    }
    return true;
}

} // namespace

bool isLegacyScene(element top) {
    if (!top.is_object()) return false;
    dom::object object = asObject(top);
    element ignored;
    return object.at_key("nodes").get(ignored) == simdjson::SUCCESS &&
           object.at_key("version").get(ignored) != simdjson::SUCCESS;
}

Scene convertLegacy(dom::object top, const Limits& limits, Problems& problems) {
    Scene scene;
    static constexpr std::string_view kKeys[] = {"nodes"};
    auto v = readMembers(top, {}, kKeys, 1, " in a legacy scene", problems);
    if (!v[0]->is_array()) {
        problems.add("nodes", "expected an array of legacy nodes, got " + describe(*v[0]));
        return scene;
    }
    dom::array array = asArray(*v[0]);
    if (array.size() == 0) {
        problems.add("nodes", "expected at least one node, got []");
        return scene;
    }
    if (array.size() > limits.maxNodes) {
        problems.add("nodes",
                     "too many nodes: a scene may have at most " + std::to_string(limits.maxNodes),
                     ErrorKind::Limit);
        return scene;
    }
    std::vector<LegacyNode> nodes;
    for (element e : array)
        nodes.push_back(readNode(e, nodes.size(), problems));
    for (size_t i = 0; i < nodes.size(); ++i)
        checkNode(nodes[i], i, nodes.size(), problems);
    const size_t root = nodes.size() - 1;
    if (!problems.empty() || findCycle(nodes, root, problems)) return scene;

    // Pre-order build with an explicit stack. A node reachable along several paths is copied
    // for each; the node limit bounds the copies.
    struct Frame {
        uint32_t out;
        uint32_t depth;
        std::vector<Operand> operands;
        size_t next = 0;
    };
    std::vector<Frame> stack;
    std::vector<Operand> operands;
    auto tooManyNodes = [&](const std::string& path) {
        problems.add(path,
                     "too many nodes: a scene may have at most " + std::to_string(limits.maxNodes) +
                         " (a node used by several operations counts once per use)",
                     ErrorKind::Limit);
        return false;
    };
    auto emit = [&](Operand o, std::optional<uint32_t> parent, uint32_t depth) {
        const std::string path = nodePath(o.legacy);
        if (scene.nodes.size() >= limits.maxNodes) return tooManyNodes(path);
        Node node = convert(nodes[o.legacy], o.legacy);
        if (!node.color) node.color = o.color;
        if (!finiteNode(node)) {
            problems.add(path, "the parameters give a shape too large for single precision");
            return false;
        }
        const auto index = static_cast<uint32_t>(scene.nodes.size());
        scene.nodes.push_back(std::move(node));
        if (parent) scene.nodes[*parent].children.push_back(index);
        if (!nodes[o.legacy].operation()) return true;
        if (depth + 1 > limits.maxDepth) {
            problems.add(path,
                         "nesting too deep: more than " + std::to_string(limits.maxDepth) +
                             " nested operations",
                         ErrorKind::Limit);
            return false;
        }
        if (!flatOperands(nodes, o.legacy, limits.maxNodes - scene.nodes.size(), operands))
            return tooManyNodes(path);
        stack.push_back({index, depth + 1, operands});
        return true;
    };
    if (!emit({root, {}}, std::nullopt, 0)) return scene;
    while (!stack.empty()) {
        Frame& frame = stack.back();
        if (frame.next == frame.operands.size()) {
            stack.pop_back();
            continue;
        }
        const Operand o = frame.operands[frame.next++];
        const uint32_t parent = frame.out, depth = frame.depth;
        if (!emit(o, parent, depth)) return scene;
    }
    return scene;
}

} // namespace sdfcsg::detail
