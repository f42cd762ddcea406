// toJson: the current format, written so that parseScene reads back an equal scene. Only values
// that differ from their defaults are written, in a fixed key order.
#include "sdfcsg/scene.h"

#include "scene/json_writer.h"
#include "scene/parse_util.h"

#include <simdjson.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace sdfcsg {
namespace {

using detail::JsonWriter;

void vec3(JsonWriter& w, std::string_view key, glm::vec3 v) {
    w.key(key);
    w.beginArray(JsonWriter::Layout::Inline);
    for (int i = 0; i < 3; ++i)
        w.number(v[i]);
    w.endArray();
}

// "#rrggbb" when every channel is exactly k/255 as the parser makes it from hex, so colours
// written as hex stay hex; [r, g, b] otherwise.
void color(JsonWriter& w, std::string_view key, glm::vec3 c) {
    char hex[8] = "#";
    for (int i = 0; i < 3; ++i) {
        const float k = std::round(c[i] * 255.0f);
        if (!(k >= 0.0f && k <= 255.0f) || k / 255.0f != c[i]) return vec3(w, key, c);
        std::snprintf(hex + 1 + 2 * i, 3, "%02x", static_cast<unsigned>(k));
    }
    w.key(key);
    w.string(hex);
}

// Writes JSON text (a definition's node, a parameter's value) in the writer's layout; null
// where it is not JSON, which the loader refuses with a message.
void jsonValue(JsonWriter& w, std::string_view text, bool inlined) {
    simdjson::dom::parser parser;
    simdjson::dom::element value;
    auto error = parser.parse(text.data(), text.size()).get(value);
    if (error == simdjson::DEPTH_ERROR && parser.allocate(text.size(), text.size() / 2 + 2) ==
                                              simdjson::SUCCESS) // deeper than simdjson's default
        error = parser.parse(text.data(), text.size()).get(value);
    if (error)
        w.null();
    else
        detail::writeJson(w, value, inlined);
}

// "parameters" of a definition or a use: {"name": value, ...} on one line.
void namedValues(JsonWriter& w, const std::vector<NamedValue>& values) {
    w.key("parameters");
    w.beginObject(JsonWriter::Layout::Inline);
    for (const NamedValue& v : values) {
        w.key(v.name);
        jsonValue(w, v.json, true);
    }
    w.endObject();
}

void definitions(JsonWriter& w, const std::vector<Definition>& list) {
    w.key("definitions");
    w.beginObject();
    for (const Definition& d : list) {
        w.key(d.name);
        w.beginObject();
        if (!d.parameters.empty()) namedValues(w, d.parameters);
        w.key("node");
        jsonValue(w, d.node, false);
        w.endObject();
    }
    w.endObject();
}

// Writes a node's own members, leaving the object open; "children" is written by the caller. A
// use is written as the use, not as the union that holds its copy.
void nodeMembers(JsonWriter& w, const Node& node) {
    const KindInfo& kind = kindInfo(node.kind);
    w.key("type");
    w.string(node.use ? std::string_view("use") : kind.name);
    if (!node.name.empty()) {
        w.key("name");
        w.string(node.name);
    }
    if (node.use) {
        w.key("definition");
        w.string(node.use->definition);
        if (!node.use->arguments.empty()) namedValues(w, node.use->arguments);
    }
    for (const ParamInfo& p : node.use ? std::span<const ParamInfo>() : kind.params) {
        if (p.type == ValueType::Text) {
            if (p.required || !node.strings[p.slot].empty()) {
                w.key(p.name);
                w.string(node.strings[p.slot]);
            }
            continue;
        }
        if (p.type == ValueType::Points) {
            w.key(p.name);
            w.beginArray(JsonWriter::Layout::Inline);
            for (glm::vec2 q : node.points) {
                w.beginArray(JsonWriter::Layout::Inline);
                w.number(q.x);
                w.number(q.y);
                w.endArray();
            }
            w.endArray();
            continue;
        }
        const float* v = node.params.data() + p.slot;
        const int n = p.type == ValueType::Vec3 ? 3 : 1;
        if (!p.required && std::equal(v, v + n, p.fallback)) continue;
        if (p.type == ValueType::Choice) {
            w.key(p.name);
            w.string(p.choices[std::min(size_t(v[0]), p.choices.size() - 1)]);
        } else if (n == 3) {
            vec3(w, p.name, glm::vec3(v[0], v[1], v[2]));
        } else {
            w.key(p.name);
            w.number(v[0]);
        }
    }
    const Transform& t = node.transform;
    if (t.translate != glm::vec3(0.0f)) vec3(w, "translate", t.translate);
    if (t.rotate != glm::vec3(0.0f)) vec3(w, "rotate", t.rotate);
    if (t.scale.x == t.scale.y && t.scale.y == t.scale.z) {
        if (t.scale.x != 1.0f) {
            w.key("scale");
            w.number(t.scale.x);
        }
    } else {
        vec3(w, "scale", t.scale);
    }
    if (node.color) color(w, "color", *node.color);
}

// Iterative, so that a deep tree built in code cannot overflow the stack. Children are
// followed only forwards (a parent precedes its children) and at most nodes.size() nodes are
// written, so a malformed tree cannot loop or blow up either.
void writeTree(JsonWriter& w, const std::vector<Node>& nodes) {
    struct Frame {
        uint32_t node;
        size_t next;
    };
    std::vector<Frame> stack;
    size_t written = 0;
    auto open = [&](uint32_t i) {
        ++written;
        w.beginObject();
        nodeMembers(w, nodes[i]);
        if (!kindInfo(nodes[i].kind).operation || nodes[i].use) {
            w.endObject();
            return;
        }
        w.key("children");
        w.beginArray();
        stack.push_back({i, 0});
    };
    open(0);
    while (!stack.empty()) {
        Frame& top = stack.back();
        const std::vector<uint32_t>& children = nodes[top.node].children;
        if (top.next == children.size()) {
            w.endArray();
            w.endObject();
            stack.pop_back();
            continue;
        }
        const uint32_t child = children[top.next++];
        if (child > top.node && child < nodes.size() && written < nodes.size()) open(child);
    }
}

} // namespace

std::string toJson(const Scene& scene) {
    JsonWriter w;
    w.beginObject();
    w.key("version");
    w.number(static_cast<double>(kSceneVersion));
    if (!scene.name.empty()) {
        w.key("name");
        w.string(scene.name);
    }
    if (!scene.description.empty()) {
        w.key("description");
        w.string(scene.description);
    }
    if (scene.camera) {
        const Camera& c = *scene.camera;
        const Camera defaults;
        w.key("camera");
        w.beginObject();
        vec3(w, "eye", c.eye);
        vec3(w, "target", c.target);
        if (c.up != defaults.up) vec3(w, "up", c.up);
        if (c.fov != defaults.fov) {
            w.key("fov");
            w.number(c.fov);
        }
        w.endObject();
    }
    if (!scene.lights.empty()) {
        const Light defaults;
        w.key("lights");
        w.beginArray();
        for (const Light& light : scene.lights) {
            w.beginObject();
            vec3(w, "direction", light.direction);
            if (light.color != defaults.color) color(w, "color", light.color);
            if (light.intensity != defaults.intensity) {
                w.key("intensity");
                w.number(light.intensity);
            }
            w.endObject();
        }
        w.endArray();
    }
    if (scene.background != Scene{}.background) color(w, "background", scene.background);
    if (!scene.definitions.empty()) definitions(w, scene.definitions);
    if (!scene.nodes.empty()) {
        w.key("root");
        writeTree(w, scene.nodes);
    }
    w.endObject();
    return w.finish();
}

} // namespace sdfcsg
