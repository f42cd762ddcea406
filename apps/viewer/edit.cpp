#include "edit.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace sdfcsg::viewer {

namespace {

Error usage(const Scene& scene, uint32_t node, std::string message) {
    return Error(ErrorKind::Usage,
                 Diagnostic{scene.file, scene.nodes[node].path, std::move(message)});
}

// A use's value as JSON text: the shortest text of a float (a value that is not finite reads as
// null, which the loader refuses), a string quoted as JSON.
std::string jsonNumber(float value) {
    if (!std::isfinite(value)) return "null";
    char text[32];
    auto [end, ec] = std::to_chars(text, text + sizeof text, value);
    return std::string(text, end);
}
std::string jsonString(std::string_view text) {
    std::string out = "\"";
    for (char c : text) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
            char escaped[8];
            std::snprintf(escaped, sizeof escaped, "\\u%04x", unsigned(c));
            out += escaped;
        } else {
            out += c;
        }
    }
    return out + "\"";
}

// Refuses an edit of a node that lies in a copy, naming the use that makes it.
std::optional<Error> inCopy(const Scene& scene, uint32_t node) {
    const int use = copyingUse(scene, node);
    if (use < 0) return std::nullopt;
    const Node& u = scene.nodes[use];
    return usage(scene, node,
                 "this node lies in the copy that the use of \"" + u.use->definition + "\" at " +
                     u.path +
                     " makes; change the definitions in the scene file, or the use's parameters");
}

// An operation that may take children: a use's one child is its copy.
bool takesChildren(const Node& node) {
    return kindInfo(node.kind).operation && !node.use;
}

const Definition* definitionOf(const Scene& scene, const Node& node) {
    if (!node.use) return nullptr;
    for (const Definition& d : scene.definitions)
        if (d.name == node.use->definition) return &d;
    return nullptr;
}

// Sets a use's value for a parameter of its definition, as JSON text; false when the definition
// has no such parameter.
bool setArgument(const Scene& scene, Node& node, std::string_view key, std::string json) {
    const Definition* d = definitionOf(scene, node);
    if (!d || std::none_of(d->parameters.begin(), d->parameters.end(),
                           [&](const NamedValue& p) { return p.name == key; }))
        return false;
    for (NamedValue& a : node.use->arguments)
        if (a.name == key) {
            a.json = std::move(json);
            return true;
        }
    node.use->arguments.push_back({std::string(key), std::move(json)});
    return true;
}

// What a use has to set: "translate, ..., color and the parameters of "leg": height, radius".
std::string useValues(const Scene& scene, const Node& node) {
    std::string out = "translate, rotate, scale, color";
    const Definition* d = definitionOf(scene, node);
    if (!d || d->parameters.empty()) return out;
    out += " and the parameters of \"" + node.use->definition + "\": ";
    for (size_t i = 0; i < d->parameters.size(); ++i)
        out += (i ? ", " : "") + d->parameters[i].name;
    return out;
}

Error badNode(const Scene& scene, uint32_t node) {
    return Error::message(ErrorKind::Usage, scene.file,
                          "no node " + std::to_string(node) + " (the scene has " +
                              std::to_string(scene.nodes.size()) + ")");
}

// A new or converted node starts as its kind's example (KindInfo::example), about a unit across.
void defaultParams(Node& node) {
    const KindInfo& info = kindInfo(node.kind);
    std::string root = exampleNodeJson(info);
    if (isProfile(node.kind)) // profiles stand only inside extrude or revolve
        root = R"({"type": "extrude", "height": 1, "children": [)" + root + "]}";
    auto example = parseScene(R"({"version": 1, "root": )" + root + "}", "example");
    if (!example) { // the table is ours: a bad example is a bug
        std::fprintf(stderr, "%s\n", example.error().str().c_str());
        std::abort();
    }
    const Node& n = example->nodes[isProfile(node.kind) ? 1 : 0];
    node.params = n.params;
    node.points = n.points;
    node.strings = n.strings;
}

// Whether the node is an extrude or a revolve or lies inside one (where 2D profiles may go).
bool cutsProfiles(const Scene& scene, int node) {
    for (; node >= 0; node = parentOf(scene, uint32_t(node))) {
        const NodeKind kind = scene.nodes[node].kind;
        if (kind == NodeKind::Extrude || kind == NodeKind::Revolve) return true;
    }
    return false;
}

// About half the width of a primitive, from its bounds.
float halfExtent(const Node& node) {
    const KindInfo& info = kindInfo(node.kind);
    glm::vec3 lo, hi;
    if (!info.bounds || !info.bounds(info.kernel(node.params), lo, hi))
        return 0.5f; // unbounded (a plane): the defaults' scale
    const glm::vec3 half = 0.5f * (hi - lo);
    return std::max({half.x, half.y, half.z});
}

// Sizes a primitive to about `h` across each half, in the proportions of defaultParams().
void sizeLike(Node& node, float h) {
    if (!(h > 0.0f) || !std::isfinite(h) || kindInfo(node.kind).operation) return;
    defaultParams(node);
    const float factor = h / halfExtent(node);
    for (const ParamInfo& p : kindInfo(node.kind).params)
        if (p.unit == "length" || p.unit == "point")
            for (int k = 0; k < (p.type == ValueType::Vec3 ? 3 : 1); ++k)
                node.params[p.slot + k] *= factor;
}

const ParamInfo* findParam(NodeKind kind, std::string_view name) {
    for (const ParamInfo& p : kindInfo(kind).params)
        if (p.name == name) return &p;
    return nullptr;
}

// Visits the subtree in depth-first order.
template <class F> void forSubtree(const Scene& scene, uint32_t node, F&& f) {
    std::vector<uint32_t> stack{node};
    while (!stack.empty()) {
        uint32_t n = stack.back();
        stack.pop_back();
        f(n);
        for (auto it = scene.nodes[n].children.rbegin(); it != scene.nodes[n].children.rend(); ++it)
            stack.push_back(*it);
    }
}

// The index the loader gives a node: its place in depth-first order from the root.
uint32_t loadedIndex(const Scene& scene, uint32_t node) {
    uint32_t order = 0, found = 0;
    forSubtree(scene, 0, [&](uint32_t n) {
        if (n == node) found = order;
        ++order;
    });
    return found;
}

// The scene with its nodes in the loader's order, which toJson needs (it follows a child only
// when it comes after its parent): after a node moved to another parent it may not be.
Scene inLoadedOrder(const Scene& scene) {
    std::vector<uint32_t> order, index(scene.nodes.size(), 0);
    forSubtree(scene, 0, [&](uint32_t n) {
        index[n] = uint32_t(order.size());
        order.push_back(n);
    });
    Scene sorted = scene;
    sorted.nodes.clear();
    for (uint32_t n : order) {
        sorted.nodes.push_back(scene.nodes[n]);
        for (uint32_t& c : sorted.nodes.back().children)
            c = index[c];
    }
    return sorted;
}

} // namespace

std::string nodeLabel(const Scene& scene, uint32_t node) {
    const Node& n = scene.nodes[node];
    std::string kind = n.use ? "use of " + n.use->definition : std::string(kindInfo(n.kind).name);
    return n.name.empty() ? kind : n.name + " (" + kind + ")";
}

int copyingUse(const Scene& scene, uint32_t node) {
    if (node >= scene.nodes.size()) return -1;
    int outermost = -1;
    for (int n = parentOf(scene, node); n >= 0; n = parentOf(scene, uint32_t(n)))
        if (scene.nodes[n].use) outermost = n;
    return outermost;
}

int parentOf(const Scene& scene, uint32_t node) {
    for (uint32_t i = 0; i < scene.nodes.size(); ++i)
        for (uint32_t c : scene.nodes[i].children)
            if (c == node) return int(i);
    return -1;
}

std::optional<uint32_t> findNode(const Scene& scene, std::string_view nameOrIndex) {
    for (uint32_t i = 0; i < scene.nodes.size(); ++i)
        if (scene.nodes[i].name == nameOrIndex) return i;
    uint32_t index = 0;
    auto [end, ec] =
        std::from_chars(nameOrIndex.data(), nameOrIndex.data() + nameOrIndex.size(), index);
    if (ec == std::errc() && end == nameOrIndex.data() + nameOrIndex.size() &&
        index < scene.nodes.size())
        return index;
    return std::nullopt;
}

std::optional<uint32_t> sameNode(const Scene& before, uint32_t node, const Scene& after) {
    if (node >= before.nodes.size()) return std::nullopt;
    const Node& n = before.nodes[node];
    for (uint32_t i = 0; i < after.nodes.size(); ++i)
        if (n.name.empty() ? after.nodes[i].path == n.path && after.nodes[i].kind == n.kind
                           : after.nodes[i].name == n.name)
            return i;
    return std::nullopt;
}

Result<Scene> revalidate(const Scene& scene) {
    // Under the rule the scene was loaded by: a generated scene's fonts stay untrusted, and a
    // file's relative names still resolve beside it.
    ParseOptions options;
    options.files = scene.files;
    auto parsed = parseScene(toJson(scene), scene.file, options);
    if (parsed) parsed->file = scene.file;
    return parsed;
}

Result<Scene> setValue(const Scene& scene, uint32_t node, std::string_view key,
                       std::span<const float> values) {
    if (node >= scene.nodes.size()) return badNode(scene, node);
    if (auto refused = inCopy(scene, node)) return *refused;
    Scene edited = scene;
    Node& n = edited.nodes[node];
    auto expect = [&](size_t count) -> std::optional<Error> {
        if (values.size() == count) return std::nullopt;
        return usage(scene, node,
                     std::string(key) + ": expected " + std::to_string(count) +
                         (count == 1 ? " number" : " numbers") + ", got " +
                         std::to_string(values.size()));
    };
    if (key == "translate" || key == "rotate") {
        if (auto e = expect(3)) return *e;
        (key == "translate" ? n.transform.translate : n.transform.rotate) =
            glm::vec3(values[0], values[1], values[2]);
    } else if (key == "scale") {
        if (values.size() == 1) {
            n.transform.scale = glm::vec3(values[0]);
        } else {
            if (auto e = expect(3)) return *e;
            n.transform.scale = glm::vec3(values[0], values[1], values[2]);
        }
    } else if (key == "color") {
        if (values.empty()) {
            n.color.reset();
        } else {
            if (auto e = expect(3)) return *e;
            n.color = glm::vec3(values[0], values[1], values[2]);
        }
    } else if (n.use) {
        std::string json;
        if (values.size() == 3) {
            json = "[";
            for (size_t i = 0; i < 3; ++i)
                json += (i ? ", " : "") + jsonNumber(values[i]);
            json += "]";
        } else if (!values.empty()) {
            if (auto e = expect(1)) return *e;
            json = jsonNumber(values[0]);
        }
        if (values.empty() || !setArgument(scene, n, key, json))
            return usage(scene, node,
                         "a use has no value \"" + std::string(key) + "\" (it has " +
                             useValues(scene, n) + ")");
    } else if (const ParamInfo* p = findParam(n.kind, key); p && p->type == ValueType::Points) {
        if (auto e = expect(2 * n.points.size())) return *e; // moves the points it has
        for (size_t i = 0; i < n.points.size(); ++i)
            n.points[i] = glm::vec2(values[2 * i], values[2 * i + 1]);
    } else if (p && p->type != ValueType::Text) {
        if (auto e = expect(p->type == ValueType::Vec3 ? 3 : 1)) return *e;
        std::copy(values.begin(), values.end(), n.params.begin() + p->slot);
    } else {
        std::string known = "translate, rotate, scale, color";
        for (const ParamInfo& q : kindInfo(n.kind).params)
            known += ", " + std::string(q.name);
        return usage(scene, node,
                     "a " + std::string(kindInfo(n.kind).name) + " has no value \"" +
                         std::string(key) + "\" (it has " + known + ")");
    }
    return revalidate(edited);
}

Result<Scene> setText(const Scene& scene, uint32_t node, std::string_view key,
                      std::string_view text) {
    if (node >= scene.nodes.size()) return badNode(scene, node);
    if (auto refused = inCopy(scene, node)) return *refused;
    Scene edited = scene;
    Node& n = edited.nodes[node];
    if (n.use) {
        if (!setArgument(scene, n, key, jsonString(text)))
            return usage(scene, node,
                         "a use has no text \"" + std::string(key) + "\" (it has " +
                             useValues(scene, n) + ")");
        return revalidate(edited);
    }
    const ParamInfo* p = findParam(n.kind, key);
    if (!p || p->type != ValueType::Text)
        return usage(scene, node,
                     "a " + std::string(kindInfo(n.kind).name) + " has no text \"" +
                         std::string(key) + "\"");
    n.strings[p->slot] = std::string(text);
    return revalidate(edited);
}

Result<Scene> addChild(const Scene& scene, uint32_t parent, NodeKind kind, uint32_t* newIndex) {
    if (parent >= scene.nodes.size()) return badNode(scene, parent);
    if (auto refused = inCopy(scene, parent)) return *refused;
    if (!takesChildren(scene.nodes[parent]))
        return usage(scene, parent, "only an operation can take children");
    Scene edited = scene;
    if (isProfile(kind) && !cutsProfiles(scene, int(parent))) { // a profile comes extruded
        Node extrude;
        extrude.kind = NodeKind::Extrude;
        defaultParams(extrude);
        extrude.params[0] = 0.2f;
        edited.nodes.push_back(extrude);
        edited.nodes[parent].children.push_back(uint32_t(edited.nodes.size() - 1));
        parent = uint32_t(edited.nodes.size() - 1);
    }
    Node child;
    child.kind = kind;
    defaultParams(child);
    edited.nodes.push_back(child);
    edited.nodes[parent].children.push_back(uint32_t(edited.nodes.size() - 1));
    if (kindInfo(kind).operation) { // an operation needs an operand, a transition two
        const uint32_t op = uint32_t(edited.nodes.size() - 1);
        for (NodeKind operand : {NodeKind::Sphere, NodeKind::Box}) {
            if (operand == NodeKind::Box && !isTransition(kind)) break;
            Node leaf;
            leaf.kind = operand;
            defaultParams(leaf);
            edited.nodes.push_back(leaf);
            edited.nodes[op].children.push_back(uint32_t(edited.nodes.size() - 1));
        }
    }
    if (newIndex) *newIndex = loadedIndex(edited, edited.nodes[parent].children.back());
    return revalidate(edited);
}

Result<Scene> removeNode(const Scene& scene, uint32_t node) {
    if (node >= scene.nodes.size()) return badNode(scene, node);
    if (auto refused = inCopy(scene, node)) return *refused;
    int parent = parentOf(scene, node);
    if (parent < 0) return usage(scene, node, "the root cannot be removed");
    if (scene.nodes[parent].children.size() == 1)
        return usage(scene, node,
                     "an operation needs at least one child; remove the operation instead");
    // Unlinking is enough: toJson writes only what the root reaches.
    Scene edited = scene;
    auto& siblings = edited.nodes[parent].children;
    siblings.erase(std::find(siblings.begin(), siblings.end(), node));
    return revalidate(edited);
}

Result<Scene> changeKind(const Scene& scene, uint32_t node, NodeKind kind) {
    if (node >= scene.nodes.size()) return badNode(scene, node);
    if (auto refused = inCopy(scene, node)) return *refused;
    if (scene.nodes[node].use)
        return usage(scene, node, "a use is a copy of its definition and has no kind to change");
    Scene edited = scene;
    Node& n = edited.nodes[node];
    bool wasOperation = kindInfo(n.kind).operation;
    if (wasOperation != kindInfo(kind).operation)
        return usage(scene, node,
                     std::string(wasOperation ? "an operation" : "a primitive") +
                         " can only become another " + (wasOperation ? "operation" : "primitive"));
    Node old = n;
    n.kind = kind;
    defaultParams(n);
    if (!wasOperation) sizeLike(n, halfExtent(old));
    for (const ParamInfo& p : kindInfo(kind).params)
        if (const ParamInfo* q = findParam(old.kind, p.name); q && q->type == p.type)
            std::copy_n(old.params.begin() + q->slot, p.type == ValueType::Vec3 ? 3 : 1,
                        n.params.begin() + p.slot);
    return revalidate(edited);
}

Result<Scene> moveNode(const Scene& scene, uint32_t node, int delta, uint32_t* newIndex) {
    if (node >= scene.nodes.size()) return badNode(scene, node);
    if (auto refused = inCopy(scene, node)) return *refused;
    int parent = parentOf(scene, node);
    if (parent < 0) return usage(scene, node, "the root has no siblings");
    Scene edited = scene;
    auto& siblings = edited.nodes[parent].children;
    int from = int(std::find(siblings.begin(), siblings.end(), node) - siblings.begin());
    int to = std::clamp(from + delta, 0, int(siblings.size()) - 1);
    uint32_t moved = siblings[from];
    siblings.erase(siblings.begin() + from);
    siblings.insert(siblings.begin() + to, moved);
    if (newIndex) *newIndex = loadedIndex(edited, node);
    return revalidate(edited);
}

Result<Scene> reparentNode(const Scene& scene, uint32_t node, uint32_t parent, uint32_t position,
                           uint32_t* newIndex) {
    if (node >= scene.nodes.size()) return badNode(scene, node);
    if (parent >= scene.nodes.size()) return badNode(scene, parent);
    if (auto refused = inCopy(scene, node)) return *refused;
    if (auto refused = inCopy(scene, parent)) return *refused;
    int from = parentOf(scene, node);
    if (from < 0) return usage(scene, node, "the root cannot be moved");
    if (!takesChildren(scene.nodes[parent]))
        return usage(scene, parent, "only an operation can take children");
    bool inside = false;
    forSubtree(scene, node, [&](uint32_t n) { inside = inside || n == parent; });
    if (inside)
        return usage(scene, node,
                     parent == node ? std::string("a node cannot be moved into itself")
                                    : "a node cannot be moved into its own subtree (" +
                                          scene.nodes[parent].path + ")");
    if (uint32_t(from) != parent && scene.nodes[from].children.size() == 1)
        return usage(scene, node,
                     "an operation needs at least one child; move or remove the operation "
                     "instead");
    Scene edited = scene;
    auto& old = edited.nodes[from].children;
    old.erase(std::find(old.begin(), old.end(), node));
    auto& siblings = edited.nodes[parent].children;
    if (position == kLastChild) position = uint32_t(siblings.size());
    if (position > siblings.size())
        return usage(scene, parent,
                     "child position " + std::to_string(position) + " is past the end (0 to " +
                         std::to_string(siblings.size()) + ")");
    siblings.insert(siblings.begin() + position, node);
    if (newIndex) *newIndex = loadedIndex(edited, node);
    return revalidate(inLoadedOrder(edited));
}

Result<Scene> dropNode(const Scene& scene, uint32_t node, uint32_t target, uint32_t* newIndex) {
    if (target >= scene.nodes.size()) return badNode(scene, target);
    if (takesChildren(scene.nodes[target]))
        return reparentNode(scene, node, target, kLastChild, newIndex);
    int parent = parentOf(scene, target);
    if (parent < 0) return usage(scene, target, "the root has no siblings");
    // Positions count the children without the moved node, so a node that now comes before
    // the target leaves a gap that the target's position closes.
    const auto& siblings = scene.nodes[parent].children;
    auto at = [&](uint32_t n) {
        return uint32_t(std::find(siblings.begin(), siblings.end(), n) - siblings.begin());
    };
    uint32_t position = at(target);
    if (parentOf(scene, node) == parent && at(node) < position) --position;
    return reparentNode(scene, node, uint32_t(parent), position, newIndex);
}

} // namespace sdfcsg::viewer
