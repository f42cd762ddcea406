// The modelling API (sdfcsg/model.h): shapes are written as the scene format's JSON and read by
// the loader, so that a shape and its file are one scene, checked by one set of rules.
#include "sdfcsg/model.h"

#include "field/bake.h"
#include "scene/json_writer.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace sdfcsg::model {
namespace {

using detail::formatFloat;
using detail::formatNumber;
using detail::jsonQuote;

std::string number(double v) {
    return std::isfinite(v) ? formatNumber(v) : "null";
}
std::string number(float v) {
    return std::isfinite(v) ? formatFloat(v) : "null";
}

bool isPlain(const ShapeData& d, std::string_view type) {
    return d.type == type && d.args.empty() && d.name.empty() && d.color.absent() && !d.part &&
           d.parts.empty() && d.transform.translate == glm::vec3(0.0f) &&
           d.transform.rotate == glm::vec3(0.0f) && d.transform.scale == glm::vec3(1.0f);
}

bool isEmpty(const Shape& s) {
    return isPlain(s.data(), "union") && s.data().children.empty();
}

Shape make(ShapeData data) {
    return Shape(std::make_shared<const ShapeData>(std::move(data)));
}

// A union of one child that holds a transform the child's own cannot.
ShapeData wrapped(const Shape& child, Where where) {
    ShapeData d;
    d.type = "union";
    d.children = {child};
    d.where = where;
    return d;
}

// a op b, each operand's children taken in where it is a plain node of the same kind.
Shape boolean(std::string_view type, const Shape& a, const Shape& b, bool flattenRight) {
    if (type == "union" && isEmpty(a)) return b;
    if (type == "union" && isEmpty(b)) return a;
    ShapeData d;
    d.type = std::string(type);
    for (int side = 0; side < 2; ++side) {
        const Shape& s = side == 0 ? a : b;
        if (isPlain(s.data(), type) && (side == 0 || flattenRight) && !s.data().children.empty())
            d.children.insert(d.children.end(), s.data().children.begin(), s.data().children.end());
        else
            d.children.push_back(s);
    }
    return make(std::move(d));
}

// Copies of one part (each use holds one), or parts of equal JSON.
bool samePart(const Part& a, const Part& b) {
    if (a.parameters().size() != b.parameters().size()) return false;
    for (size_t i = 0; i < a.parameters().size(); ++i)
        if (a.parameters()[i].name != b.parameters()[i].name ||
            a.parameters()[i].value != b.parameters()[i].value)
            return false;
    if (a.node() && b.node()) return &a.node()->data() == &b.node()->data();
    return !a.node() && !b.node() && a.nodeJson() == b.nodeJson();
}

// How deep the paths of nodes are kept: past the loader's depth limit.
constexpr size_t kPathDepth = 2 * Limits{}.maxDepth;

// The JSON of a shape and the parts it uses, with each node's path and where it was made.
class Writer {
  public:
    std::map<std::string, std::string> made; // JSON path -> "file:line" where its node was made

    // The document: {"version": 1, settings..., "definitions": ..., "root": ...}.
    Result<std::string> scene(const Shape& root, const std::vector<Arg>& settings = {}) {
        std::string rootJson = tree(root, "root");
        std::string out = "{\"version\": 1";
        for (const Arg& s : settings) {
            if (s.name == "version" || s.name == "root" || s.name == "definitions")
                return Error::message(ErrorKind::Usage, "<model>",
                                      "the scene's " + s.name + " comes from its shape");
            if (!s.value.absent()) out += ", " + jsonQuote(s.name) + ": " + s.value.json();
        }
        if (!parts_.empty()) {
            out += ", \"definitions\": {";
            for (size_t i = 0; i < partJson_.size(); ++i)
                out += (i ? ", " : "") + partJson_[i];
            out += "}";
        }
        if (!error_.empty()) return Error::message(ErrorKind::Usage, "<model>", error_);
        return out + ", \"root\": " + rootJson + "}";
    }

  private:
    std::map<std::string, const Part*> parts_;
    std::vector<std::string> partJson_;
    std::string error_;

    void part(const Part& p) {
        if (auto it = parts_.find(p.name()); it != parts_.end()) {
            if (!samePart(*it->second, p))
                error_ = "two different parts are named " + jsonQuote(p.name());
            return;
        }
        parts_[p.name()] = &p;
        // In the order first reached: a part's slot is taken before the parts its node uses.
        const size_t slot = partJson_.size();
        partJson_.emplace_back();
        const std::string path = "definitions." + p.name();
        std::string json = jsonQuote(p.name()) + ": {";
        if (!p.parameters().empty()) {
            json += "\"parameters\": {";
            for (size_t i = 0; i < p.parameters().size(); ++i)
                json += (i ? ", " : "") + jsonQuote(p.parameters()[i].name) + ": " +
                        valueJson(p.parameters()[i].value);
            json += "}, ";
        }
        json += "\"node\": " + (p.node() ? tree(*p.node(), path + ".node") : p.nodeJson()) + "}";
        partJson_[slot] = std::move(json);
    }

    static std::string valueJson(const Value& v) { return v.absent() ? "null" : v.json(); }

    // One node's members, "children" left open for the caller.
    std::string members(const ShapeData& d) {
        for (const auto& p : d.parts)
            part(*p);
        std::string out = "{\"type\": " + jsonQuote(d.type);
        if (!d.name.empty()) out += ", \"name\": " + jsonQuote(d.name);
        if (d.part) {
            part(*d.part);
            out += ", \"definition\": " + jsonQuote(d.part->name());
            if (!d.args.empty()) {
                out += ", \"parameters\": {";
                for (size_t i = 0; i < d.args.size(); ++i)
                    out += (i ? ", " : "") + jsonQuote(d.args[i].name) + ": " +
                           valueJson(d.args[i].value);
                out += "}";
            }
        } else {
            for (const Arg& a : d.args)
                out += ", " + jsonQuote(a.name) + ": " + valueJson(a.value);
        }
        const Transform& t = d.transform;
        if (t.translate != glm::vec3(0.0f)) out += ", \"translate\": " + Value(t.translate).json();
        if (t.rotate != glm::vec3(0.0f)) out += ", \"rotate\": " + Value(t.rotate).json();
        if (t.scale != glm::vec3(1.0f)) out += ", \"scale\": " + Value(t.scale).json();
        if (!d.color.absent()) out += ", \"color\": " + d.color.json();
        return out;
    }

    // Iterative: a shape built in a loop may be deeper than the stack allows recursion.
    std::string tree(const Shape& root, const std::string& rootPath) {
        struct Frame {
            const ShapeData* node;
            std::string path; // empty below kPathDepth
            size_t next = 0;
        };
        std::string out;
        std::vector<Frame> stack;
        auto open = [&](const ShapeData& d, std::string path) {
            if (!path.empty())
                made.emplace(path, !d.origin.empty() || d.where.line() == 0
                                       ? d.origin
                                       : std::string(d.where.file_name()) + ":" +
                                             std::to_string(d.where.line()));
            out += members(d);
            if (d.part) { // a use's node has no children of its own in the file
                out += "}";
                return;
            }
            out += ", \"children\": [";
            stack.push_back({&d, std::move(path)});
        };
        open(root.data(), rootPath);
        while (!stack.empty()) {
            Frame& top = stack.back();
            if (top.next == top.node->children.size()) {
                // A primitive has no "children" key: the loader refuses one, even empty.
                const std::string empty = ", \"children\": [";
                if (top.node->children.empty() && out.ends_with(empty))
                    out.resize(out.size() - empty.size());
                else
                    out += "]";
                out += "}";
                stack.pop_back();
                continue;
            }
            const size_t i = top.next++;
            if (i) out += ", ";
            // Paths of nodes deeper than the loader takes would only cost quadratic memory.
            std::string path = top.path.empty() || stack.size() > kPathDepth
                                   ? std::string()
                                   : top.path + ".children[" + std::to_string(i) + "]";
            open(top.node->children[i].data(), std::move(path));
        }
        return out;
    }
};

// Where the node of the value at `path` was made: that of the longest node path that begins it.
const std::string* madeAt(const std::map<std::string, std::string>& made, const std::string& path) {
    const std::string* best = nullptr;
    size_t bestLength = 0;
    for (const auto& [nodePath, origin] : made) {
        const bool begins = path.starts_with(nodePath) &&
                            (path.size() == nodePath.size() || path[nodePath.size()] == '.' ||
                             path[nodePath.size()] == '[');
        if (begins && nodePath.size() >= bestLength) best = &origin, bestLength = nodePath.size();
    }
    return best && !best->empty() ? best : nullptr;
}

Result<Scene> parseShape(const Shape& root, const ParseOptions& options,
                         const std::vector<Arg>& settings = {}) {
    Writer writer;
    auto json = writer.scene(root, settings);
    if (!json) return json.error();
    auto scene = parseScene(*json, "<model>", options);
    if (scene) return scene;
    Error error = scene.error();
    for (Diagnostic& d : error.diagnostics)
        if (const std::string* origin = madeAt(writer.made, d.path)) d.file = *origin;
    return error;
}

// A node's parameters as toJson writes them: optional ones only where they differ from their
// default.
std::vector<Arg> nodeArgs(const Node& node) {
    std::vector<Arg> args;
    for (const ParamInfo& p : kindInfo(node.kind).params) {
        if (p.type == ValueType::Text) {
            if (p.required || !node.strings[p.slot].empty())
                args.push_back({std::string(p.name), Value(node.strings[p.slot])});
            continue;
        }
        if (p.type == ValueType::Points) {
            args.push_back({std::string(p.name), Value(node.points)});
            continue;
        }
        const float* v = node.params.data() + p.slot;
        const int n = p.type == ValueType::Vec3 ? 3 : 1;
        if (!p.required && std::equal(v, v + n, p.fallback)) continue;
        const Value value = p.type == ValueType::Choice
                                ? Value(p.choices[std::min(size_t(v[0]), p.choices.size() - 1)])
                            : n == 3 ? Value(glm::vec3(v[0], v[1], v[2]))
                                     : Value(v[0]);
        args.push_back({std::string(p.name), value});
    }
    return args;
}

// A node of a scene with the given children (a use: its part and arguments, no children).
ShapeData nodeData(const Node& node,
                   const std::map<std::string, std::shared_ptr<const Part>>& parts,
                   std::vector<Shape> children) {
    ShapeData d;
    d.name = node.name;
    d.transform = node.transform;
    if (node.color) d.color = Value(*node.color);
    if (node.use) {
        d.type = "use";
        if (auto it = parts.find(node.use->definition); it != parts.end()) d.part = it->second;
        for (const NamedValue& a : node.use->arguments)
            d.args.push_back({a.name, Value::json(a.json)});
        return d;
    }
    d.type = std::string(kindInfo(node.kind).name);
    d.args = nodeArgs(node);
    d.children = std::move(children);
    return d;
}

std::map<std::string, std::shared_ptr<const Part>> sceneParts(const Scene& scene) {
    std::map<std::string, std::shared_ptr<const Part>> parts;
    for (const Definition& d : scene.definitions)
        parts[d.name] = std::make_shared<const Part>(d);
    return parts;
}

} // namespace

Value::Value(double v) : json_(number(v)) {}
Value::Value(float v) : json_(number(v)) {}
Value::Value(std::string_view text) : json_(jsonQuote(text)) {}
Value::Value(glm::vec3 v)
    : json_("[" + number(v.x) + ", " + number(v.y) + ", " + number(v.z) + "]") {}
Value::Value(glm::vec2 v) : json_("[" + number(v.x) + ", " + number(v.y) + "]") {}
Value::Value(const std::vector<glm::vec2>& points) : json_("[") {
    for (size_t i = 0; i < points.size(); ++i)
        json_ += (i ? ", " : "") + Value(points[i]).json_;
    json_ += "]";
}
Value::Value(std::initializer_list<Value> items) : json_("[") {
    size_t i = 0;
    for (const Value& v : items)
        json_ += (i++ ? ", " : "") + (v.absent() ? std::string("null") : v.json_);
    json_ += "]";
}
Value Value::json(std::string text) {
    Value v;
    v.json_ = std::move(text);
    return v;
}

ShapeData::~ShapeData() {
    // Children held only here are taken apart one level at a time, from a list, not the stack.
    std::vector<std::shared_ptr<const ShapeData>> pending;
    auto take = [&](const std::vector<Shape>& from) {
        for (const Shape& s : from)
            if (s.data_.use_count() == 1) pending.push_back(std::move(s.data_));
    };
    take(children);
    while (!pending.empty()) {
        std::shared_ptr<const ShapeData> d = std::move(pending.back());
        pending.pop_back();
        take(d->children);
    }
}

Shape::Shape() {
    ShapeData d;
    d.type = "union";
    data_ = std::make_shared<const ShapeData>(std::move(d));
}

Shape Shape::translate(glm::vec3 offset, Where) const {
    ShapeData d = *data_;
    d.transform.translate += offset;
    return make(std::move(d));
}

Shape Shape::rotate(glm::vec3 degrees, Where where) const {
    const Transform& t = data_->transform;
    ShapeData d = t.translate == glm::vec3(0.0f) && t.rotate == glm::vec3(0.0f)
                      ? *data_
                      : wrapped(*this, where);
    d.transform.rotate = degrees;
    return make(std::move(d));
}

Shape Shape::scale(float factor, Where where) const {
    return scale(glm::vec3(factor), where);
}

Shape Shape::scale(glm::vec3 factors, Where where) const {
    const Transform& t = data_->transform;
    // Scaling after a rotation keeps the node's order only where it scales every axis alike.
    const bool uniform = factors.x == factors.y && factors.y == factors.z;
    ShapeData d = t.rotate == glm::vec3(0.0f) || uniform ? *data_ : wrapped(*this, where);
    d.transform.scale *= factors;
    d.transform.translate *= factors;
    return make(std::move(d));
}

Shape Shape::color(Value color, Where) const {
    ShapeData d = *data_;
    d.color = std::move(color);
    return make(std::move(d));
}

Shape Shape::name(std::string name) const {
    ShapeData d = *data_;
    d.name = std::move(name);
    return make(std::move(d));
}

Shape Shape::set(std::string_view parameter, Value value, Where) const {
    ShapeData d = *data_;
    std::erase_if(d.args, [&](const Arg& a) { return a.name == parameter; });
    if (!value.absent()) d.args.push_back({std::string(parameter), std::move(value)});
    return make(std::move(d));
}

Part::Part(std::string name, Shape node, std::vector<Arg> parameters)
    : name_(std::move(name)), parameters_(std::move(parameters)), node_(std::move(node)) {}

Part::Part(Definition definition)
    : name_(std::move(definition.name)), nodeJson_(std::move(definition.node)) {
    for (NamedValue& p : definition.parameters)
        parameters_.push_back({std::move(p.name), Value::json(std::move(p.json))});
}

Shape Part::operator()(std::vector<Arg> arguments, Where where) const {
    ShapeData d;
    d.type = "use";
    d.part = std::make_shared<const Part>(*this);
    std::erase_if(arguments, [](const Arg& a) { return a.value.absent(); });
    d.args = std::move(arguments);
    d.where = where;
    return make(std::move(d));
}

Shape shape(std::string_view type, std::vector<Arg> args, std::vector<Shape> children,
            Where where) {
    ShapeData d;
    d.type = std::string(type);
    std::erase_if(args, [](const Arg& a) { return a.value.absent(); });
    d.args = std::move(args);
    d.children = std::move(children);
    d.where = where;
    return make(std::move(d));
}

Shape operator|(const Shape& a, const Shape& b) {
    return boolean("union", a, b, true);
}
Shape operator&(const Shape& a, const Shape& b) {
    return boolean("intersection", a, b, true);
}
Shape operator-(const Shape& a, const Shape& b) {
    return boolean("difference", a, b, false);
}

Result<Scene> toScene(const Shape& root) {
    return parseShape(root, {});
}

Result<Scene> toScene(const Shape& root, const std::vector<Arg>& settings) {
    return parseShape(root, {}, settings);
}

Result<std::string> toJson(const Shape& root) {
    auto scene = toScene(root);
    if (!scene) return scene.error();
    return toJson(*scene);
}

Shape fromScene(const Scene& scene) {
    if (scene.nodes.empty()) return Shape();
    const auto parts = sceneParts(scene);
    // A parent precedes its children, so going backwards every child is made before its parent.
    std::vector<std::optional<Shape>> shapes(scene.nodes.size());
    for (size_t i = scene.nodes.size(); i-- > 0;) {
        const Node& node = scene.nodes[i];
        std::vector<Shape> children;
        if (!node.use)
            for (uint32_t c : node.children)
                if (c > i && c < shapes.size() && shapes[c]) children.push_back(*shapes[c]);
        shapes[i] = make(nodeData(node, parts, std::move(children)));
        for (uint32_t c : node.children) // released as soon as the parent holds them
            if (c > i && c < shapes.size()) shapes[c].reset();
    }
    ShapeData root = shapes[0]->data();
    for (const Definition& d : scene.definitions)
        root.parts.push_back(parts.at(d.name));
    return make(std::move(root));
}

Result<Shape> fromJson(std::string_view json, std::string_view file) {
    auto scene = parseScene(json, file);
    if (!scene) return scene.error();
    return fromScene(*scene);
}

Result<uint32_t> findNode(const Scene& scene, std::string_view nameOrPath) {
    for (size_t i = 0; i < scene.nodes.size(); ++i)
        if (scene.nodes[i].name == nameOrPath) return uint32_t(i);
    for (size_t i = 0; i < scene.nodes.size(); ++i)
        if (scene.nodes[i].path == nameOrPath && !scene.nodes[i].path.starts_with("definitions."))
            return uint32_t(i);
    return Error::message(ErrorKind::Usage, scene.file,
                          "no node is named " + jsonQuote(nameOrPath) + " or has that path");
}

Status setValue(Scene& scene, uint32_t index, std::string_view key, const Value& value) {
    if (index >= scene.nodes.size())
        return Error::message(ErrorKind::Usage, scene.file,
                              "no node " + std::to_string(index) + " in a scene of " +
                                  std::to_string(scene.nodes.size()));
    Node& node = scene.nodes[index];
    if (node.path.starts_with("definitions."))
        return Error(ErrorKind::Usage,
                     Diagnostic{scene.file, node.path,
                                "is part of a use's copy of a definition: set the use's "
                                "arguments instead"});
    // The node alone, with stand-ins for its children, the new value in place of its own.
    std::vector<Shape> children;
    const Shape sphere = shape("sphere", {{"radius", 0.5}});
    if (node.kind == NodeKind::Extrude || node.kind == NodeKind::Revolve)
        children = {shape("circle", {{"radius", 0.5}})};
    else if (isTransition(node.kind))
        children = {sphere, sphere};
    else if (kindInfo(node.kind).operation && !node.use)
        children = {sphere};
    ShapeData d = nodeData(node, {}, std::move(children));
    if (node.use) { // the values of its union, which the loader reads as a union's
        d.type = "union";
        d.part = nullptr;
        d.args.clear();
        d.children = {sphere};
    }
    if (key == "translate") d.transform.translate = glm::vec3(0.0f);
    if (key == "rotate") d.transform.rotate = glm::vec3(0.0f);
    if (key == "scale") d.transform.scale = glm::vec3(1.0f);
    if (key == "color") d.color = Value();
    if (key == "name") d.name.clear();
    std::erase_if(d.args, [&](const Arg& a) { return a.name == key; });
    if (!value.absent()) d.args.push_back({std::string(key), value});
    Shape alone = make(std::move(d));
    // A profile is loaded inside an extrusion, as it may only be.
    const bool profile = isProfile(node.kind);
    if (profile) alone = shape("extrude", {{"height", 1}}, {alone});
    ParseOptions options;
    options.files = scene.files;
    auto parsed = parseShape(alone, options);
    if (!parsed) {
        Error error = parsed.error();
        const std::string root = profile ? "root.children[0]" : "root";
        for (Diagnostic& diag : error.diagnostics) {
            diag.file = scene.file;
            if (diag.path.starts_with(root)) diag.path = node.path + diag.path.substr(root.size());
        }
        return error;
    }
    const Node& edited = parsed->nodes[profile ? 1 : 0];
    node.name = edited.name;
    node.transform = edited.transform;
    node.color = edited.color;
    if (!node.use) {
        node.params = edited.params;
        node.points = edited.points;
        node.strings = edited.strings;
        node.words = edited.words;
    }
    // A value may change the field of an offset's or shell's child, which bakes it (bake.h).
    detail::bakeOffsets(scene);
    return Ok{};
}

} // namespace sdfcsg::model
