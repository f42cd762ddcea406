// What the language model is told: the system prompt, made from the node kind table (through
// sceneFormatReference()) and the bundled example scenes, the user and repair messages, and the
// strict-mode variant of the scene JSON Schema. All generated, so none can drift from the parser.
#include "sdfcsg/generate.h"

#include "codegen/embedded_shaders.h"
#include "scene/json_writer.h"
#include "scene/parse_util.h"

#include <simdjson.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace sdfcsg {
namespace {

using detail::asArray;
using detail::asObject;
using detail::formatNumber;
using detail::jsonQuote;
namespace dom = simdjson::dom;

constexpr std::string_view kRules = R"(## How to build a scene

- Every primitive is centred at the origin. Place it with "translate" [x, y, z], turn it with
  "rotate" [x, y, z] (degrees, about x, then y, then z), and size it with its own fields; use
  "scale" only to resize a whole group.
- A transform on an operation moves, turns and scales its whole subtree; the children's
  transforms are relative to it.
- Build an object as a "union" of named parts. Parts of one object touch or overlap a little;
  nothing floats unless the request says so.
- "difference" keeps its first child and removes all the others from it, so the removed parts
  must overlap the first child. "intersection" keeps what all its children have in common.
- "smooth" blends the children of an operation over that distance; leave it out for sharp edges.
- y is up. Objects rest on the ground or on a floor part; a typical object is 1 to 10 units tall.
- "color" is [r, g, b] with components from 0 to 1; children without a colour inherit their
  parent's. Colour the parts as the request says, with plausible colours otherwise.
- Give every part a short "name". Keep a scene under 200 nodes: suggest details, do not model
  them one by one.
- "camera" is optional: without one the scene is framed automatically. Leave out optional
  keys you do not need (or set them to null).
- Repeated parts are one node, not many: "repeat" makes a grid of copies of its one child
  (count and spacing per axis), "polar_repeat" makes count copies around the y axis (the child
  moved radius along +x first): gear teeth, a ring of pillars, holes on a bolt circle.
- "mirror" makes a symmetric shape from one half; "shell" hollows its child (cut it open with
  a difference); "offset" grows or shrinks it; "twist", "bend" and "taper" deform their child.
- Lathe-turned shapes (vases, chess pieces, bottles) are a "revolve" of a "polygon" profile
  whose points [x, y] have x >= 0 (x is the distance from the axis). Flat plates and lettering
  are an "extrude" (thickness along z) of a 2D profile: "circle", "rectangle",
  "regular_polygon", "polygon" or "text". 2D profiles exist only inside extrude or revolve.
- "image" (a 2D profile) and "heightmap" read a PNG file: use them only when the request names
  such a file, with that name, never a name of your own.
- "blend" chooses the profile of "smooth": "smooth", "round" (a fillet) or "chamfer" (a bevel).
- A part that recurs in other sizes or places (the legs of a table and of its chairs, the
  windows of a house) can be written once under "definitions", with parameters and their
  defaults, and placed by {"type": "use", "definition": NAME, "parameters": {...}} nodes, each
  with its own translate, rotate, scale, color and name. Inside a definition's node, a value
  "$name" stands for the parameter's value. Equal copies in a grid or a ring are cheaper as
  "repeat" or "polar_repeat".
- No other keys exist: an unknown key is an error.
)";

std::string diagnosticLine(const Diagnostic& d) {
    if (!d.path.empty()) return d.path + ": " + d.message;
    if (d.line > 0)
        return "line " + std::to_string(d.line) + ", column " + std::to_string(d.column) + ": " +
               d.message;
    return d.message;
}

// ---- The strict schema, derived from sceneJsonSchema() ----
//
// Strict mode wants every key of every object listed, so it cannot say that the keys of
// "definitions" and of a use's "parameters" are names of the scene's choosing: the strict schema
// leaves out definitions and uses, and a model held to it writes each part out. Without a schema
// (JSON mode, plain text) a model may write them, and the loader reads them as from a file.

// The parts of the scene schema that the strict schema leaves out.
bool leftOutOfStrict(std::string_view name) {
    return name == "definitions" || name == "definition" || name == "parameter_value" ||
           name == "use" || name == "#/$defs/use";
}

std::string constType(dom::element value) {
    if (value.is_string()) return "string";
    if (value.is_bool()) return "boolean";
    if (value.is_int64() || value.is_uint64()) return "integer";
    return "number";
}

std::string jsonText(dom::element value) {
    if (value.is_string()) return jsonQuote(value.get_string().value_unsafe());
    if (value.is_bool()) return value.get_bool().value_unsafe() ? "true" : "false";
    if (value.is_int64()) return std::to_string(value.get_int64().value_unsafe());
    return formatNumber(value.get_double().value_unsafe());
}

// The table's schema is ours and a few levels deep, so plain recursion is fine here.
std::string strictSchema(dom::element s, bool nullable, bool described = true);

std::string strictSchema(dom::element s, bool nullable, bool described) {
    dom::object o = asObject(s);
    std::string description;
    if (std::string_view d; described && !o["description"].get(d)) description = jsonQuote(d);
    auto open = [&] {
        return "{" + (description.empty() ? std::string() : "\"description\":" + description + ",");
    };

    dom::element e;
    if (!o["$ref"].get(e)) {
        std::string ref = R"({"$ref":)" + jsonQuote(e.get_string().value_unsafe()) + "}";
        return nullable ? open() + R"("anyOf":[)" + ref + R"(,{"type":"null"}]})" : ref;
    }
    if (!o["oneOf"].get(e) || !o["anyOf"].get(e)) {
        std::string out = open() + R"("anyOf":[)";
        bool first = true;
        for (dom::element option : asArray(e)) {
            if (std::string_view ref; !option["$ref"].get(ref) && leftOutOfStrict(ref)) continue;
            out += (first ? "" : ",") + strictSchema(option, false);
            first = false;
        }
        return out + (nullable ? R"(,{"type":"null"}]})" : "]}");
    }

    std::string type;
    if (std::string_view t; !o["type"].get(t)) type = t;
    dom::element constant;
    const bool hasConst = !o["const"].get(constant);
    if (hasConst && type.empty()) type = constType(constant);
    std::string out =
        open() + "\"type\":" + (nullable ? "[" + jsonQuote(type) + ",\"null\"]" : jsonQuote(type));
    if (hasConst) out += ",\"enum\":[" + jsonText(constant) + "]";
    if (!o["items"].get(e)) out += ",\"items\":" + strictSchema(e, false);
    if (!o["properties"].get(e)) {
        std::vector<std::string_view> required;
        if (dom::element r; !o["required"].get(r))
            for (dom::element name : asArray(r))
                required.push_back(name.get_string().value_unsafe());
        std::string names;
        out += ",\"properties\":{";
        for (auto [key, value] : asObject(e)) {
            if (leftOutOfStrict(key)) continue;
            const bool optional =
                std::find(required.begin(), required.end(), key) == required.end();
            if (!names.empty()) {
                names += ",";
                out += ",";
            }
            names += jsonQuote(key);
            out += jsonQuote(key) + ":" + strictSchema(value, optional);
        }
        out += "},\"required\":[" + names + "],\"additionalProperties\":false";
    }
    return out + "}";
}

// ---- The top-level keys, from sceneJsonSchema() ----

dom::element parsedSceneSchema(dom::parser& parser) {
    static const std::string full = sceneJsonSchema();
    dom::element top;
    if (parser.parse(full).get(top)) {
        std::fprintf(stderr, "%s:%d: sceneJsonSchema() is not valid JSON\n", __FILE__, __LINE__);
        std::abort(); // generated by us: a bug
    }
    return top;
}

// How a value of schema `s` is written in the prompt: 1, TEXT, [x, y, z], NODE,
// {"eye": [x, y, z], ...}, up to 4 of {...}. The schema is ours and a few levels deep.
std::string shape(dom::element s, dom::object defs) {
    dom::object o = asObject(s);
    dom::element e;
    if (std::string_view ref; !o["$ref"].get(ref)) {
        const std::string_view name = ref.substr(ref.rfind('/') + 1);
        if (name == "color") return "[r, g, b]"; // an array or "#rrggbb": the array reads best
        if (name == "node") return "NODE";
        return shape(defs[name].value_unsafe(), defs);
    }
    if (!o["const"].get(e)) return jsonText(e);
    std::string_view type;
    if (o["type"].get(type)) return "VALUE";
    if (type == "string") {
        uint64_t most = 0;
        return !o["maxLength"].get(most) ? "TEXT (at most " + std::to_string(most) + " characters)"
                                         : "TEXT";
    }
    if (type == "number") {
        // "... Unit: degrees." names the unit; points and directions are vectors.
        std::string_view d;
        if (!o["description"].get(d))
            if (size_t at = d.find("Unit: "); at != std::string_view::npos) {
                std::string_view unit = d.substr(at + 6);
                return std::string(unit.substr(0, unit.find('.')));
            }
        return "number";
    }
    if (type == "array" && !o["items"].get(e)) {
        uint64_t least = 0, most = 0;
        if (!o["minItems"].get(least) && !o["maxItems"].get(most) && least == 3 && most == 3 &&
            shape(e, defs) == "number")
            return "[x, y, z]"; // a point or a direction
        return (!o["maxItems"].get(most) ? "up to " + std::to_string(most) + " of "
                                         : std::string("a list of ")) +
               shape(e, defs);
    }
    if (type == "object" && !o["properties"].get(e)) {
        std::string out = "{";
        for (auto [key, value] : asObject(e))
            out += (out.size() > 1 ? ", " : "") + jsonQuote(key) + ": " + shape(value, defs);
        return out + "}";
    }
    if (type == "object" && !o["additionalProperties"].get(e) && e.is_object())
        return "{NAME: " + shape(e, defs) + "}"; // keys of the scene's choosing
    if (dom::array required; type == "object" && !o["required"].get(required) &&
                             required.size() == 1 && required.at(0).is_string() &&
                             required.at(0).get_string().value_unsafe() == "type")
        return "NODE"; // a definition's node, which the schema checks only for its type
    return std::string(type);
}

// One line per top-level key of the scene schema, with its shape and its description, so that
// the prompt names every key the parser reads, with today's limits (the number of lights).
std::string topLevelKeys() {
    dom::parser parser;
    const dom::element top = parsedSceneSchema(parser);
    const dom::object defs = asObject(top["$defs"].value_unsafe());
    std::string required;
    for (dom::element name : asArray(top["required"].value_unsafe()))
        required += std::string(required.empty() ? "" : " and ") +
                    jsonQuote(name.get_string().value_unsafe());
    std::string out = "A scene is one JSON object with these keys, of which only " + required +
                      " are required:\n";
    for (auto [key, value] : asObject(top["properties"].value_unsafe())) {
        out += "- " + jsonQuote(key) + ": " + shape(value, defs);
        if (std::string_view d; !value["description"].get(d)) out += ". " + std::string(d);
        out += "\n";
    }
    return out;
}

} // namespace

std::string sceneSystemPrompt() {
    std::string out =
        "You design 3D scenes for sdfcsg, a constructive solid geometry engine on signed "
        "distance fields. You answer with one scene as a single JSON object, and nothing else: "
        "no prose, no code fences.\n\n## The scene format\n\n";
    out += topLevelKeys();
    out += "A NODE is a primitive, an operation or a use of a definition, chosen by \"type\". "
           "Operations (union, intersection, difference) hold their operands in \"children\"; "
           "primitives are leaves. "
           "Lengths are in scene units, angles in degrees, colours in 0..1.\n\n";
    out += sceneFormatReference();
    out += "\n";
    out += kRules;
    out += "\n## Examples\n";
    const std::vector<std::string> requests = sceneExampleRequests();
    const auto examples = detail::embeddedExampleScenes();
    for (size_t i = 0; i < examples.size(); ++i) {
        out += "\nRequest: " + requests[i] + "\nAnswer:\n" + std::string(examples[i].text);
        if (!examples[i].text.ends_with('\n')) out += "\n";
    }
    return out;
}

std::vector<std::string> sceneExampleRequests() {
    std::vector<std::string> out;
    for (const detail::EmbeddedFile& example : detail::embeddedExampleScenes()) {
        // Each example's request is its own description.
        std::string request = "a scene";
        simdjson::dom::parser parser;
        simdjson::dom::element top;
        if (!parser.parse(example.text.data(), example.text.size()).get(top)) {
            std::string_view d;
            if (!top["description"].get(d)) request = d;
        }
        out.push_back(std::move(request));
    }
    return out;
}

std::string sceneUserPrompt(std::string_view request, std::string_view currentScene) {
    if (currentScene.empty()) return "Request: " + std::string(request);
    std::string scene(currentScene);
    if (!scene.ends_with('\n')) scene += '\n';
    return "Here is the current scene:\n" + scene +
           "\nChange it as follows: " + std::string(request) +
           "\nAnswer with the whole changed scene. Keep the names, and everything that the "
           "change does not concern, as they are.";
}

std::string sceneRepairPrompt(const Error& problems) {
    std::string out = "Your scene does not load. The validator reported:\n";
    for (const Diagnostic& d : problems.diagnostics)
        out += "- " + diagnosticLine(d) + "\n";
    out += "Answer with the whole corrected scene as one JSON object, and nothing else.";
    return out;
}

std::string sceneLlmSchema() {
    static const std::string schema = [] {
        simdjson::dom::parser parser;
        const simdjson::dom::element top = parsedSceneSchema(parser);
        // The top-level description speaks of the file format, not of an answer.
        std::string body = strictSchema(top, false, false);
        std::string defs = ",\"$defs\":{";
        bool first = true;
        for (auto [key, value] : asObject(top["$defs"].value_unsafe())) {
            if (leftOutOfStrict(key)) continue;
            defs += (first ? "" : ",") + jsonQuote(key) + ":" + strictSchema(value, false);
            first = false;
        }
        body.insert(body.size() - 1, defs + "}");
        return body;
    }();
    return schema;
}

std::string extractJson(std::string_view answer) {
    std::string text(answer);
    // Reasoning models wrap their thoughts in <think> blocks; some templates open the block in
    // the prompt, so the answer holds only its end.
    for (size_t open; (open = text.find("<think>")) != std::string::npos;) {
        size_t close = text.find("</think>", open);
        text.erase(open, close == std::string::npos ? std::string::npos : close + 8 - open);
    }
    if (size_t close = text.rfind("</think>"); close != std::string::npos) text.erase(0, close + 8);

    if (size_t fence = text.find("```"); fence != std::string::npos) {
        size_t start = text.find('\n', fence);
        size_t end = start == std::string::npos ? start : text.find("```", start);
        if (end != std::string::npos) {
            std::string inside = text.substr(start + 1, end - start - 1);
            if (inside.find('{') != std::string::npos) text = inside;
        }
    }
    size_t first = text.find('{'), last = text.rfind('}');
    if (first != std::string::npos && last != std::string::npos && first < last)
        return text.substr(first, last - first + 1);
    auto blank = [](unsigned char c) { return std::isspace(c) != 0; };
    text.erase(text.begin(), std::find_if_not(text.begin(), text.end(), blank));
    text.erase(std::find_if_not(text.rbegin(), text.rend(), blank).base(), text.end());
    return text;
}

std::string_view outputModeName(OutputMode mode) {
    switch (mode) {
    case OutputMode::JsonSchema:
        return "json_schema";
    case OutputMode::JsonObject:
        return "json_object";
    case OutputMode::Text:
        return "text";
    }
    return "text";
}

} // namespace sdfcsg
