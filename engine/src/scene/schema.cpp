// sceneJsonSchema: the JSON Schema (draft 2020-12) of the current format, generated from the node
// kind table so that the schema, the parser and the documentation cannot drift apart.
// What a schema cannot say (a round box's radius at most half its smallest size, a camera's up
// not along its line of sight) is left to the parser and mentioned in the descriptions.
#include "sdfcsg/scene.h"

#include "scene/json_writer.h"
#include "scene/parse_util.h"
#include "shared.h"

#include <simdjson.h>

#include <cstdio>
#include <cstdlib>

namespace sdfcsg {
namespace {

using detail::asArray;
using detail::asObject;
using detail::JsonWriter;
using Layout = JsonWriter::Layout;

// Copies a small JSON value from the table (CommonKey::schemaType). The fragments are ours and a
// few levels deep, so plain recursion is fine here.
void copyValue(JsonWriter& w, simdjson::dom::element e) {
    using simdjson::dom::element_type;
    switch (e.type()) {
    case element_type::OBJECT: {
        // Small flat objects ({"type": "number"}) read better on one line.
        size_t members = 0;
        bool flat = true;
        for (auto [key, value] : asObject(e)) {
            ++members;
            flat = flat && !value.is_array() && !value.is_object();
        }
        w.beginObject(flat && members <= 3 ? Layout::Inline : Layout::Block);
        for (auto [key, value] : asObject(e)) {
            w.key(key);
            copyValue(w, value);
        }
        w.endObject();
        break;
    }
    case element_type::ARRAY: {
        bool scalars = true;
        for (auto item : asArray(e))
            scalars = scalars && !item.is_array() && !item.is_object();
        w.beginArray(scalars ? Layout::Inline : Layout::Block);
        for (auto item : asArray(e))
            copyValue(w, item);
        w.endArray();
        break;
    }
    case element_type::STRING:
        w.string(e.get_string().value_unsafe());
        break;
    case element_type::BOOL:
        w.boolean(e.get_bool().value_unsafe());
        break;
    default:
        w.number(e.get_double().value_unsafe());
        break;
    }
}

// A fragment from the table with "description" added in front of its members.
void fragment(JsonWriter& w, std::string_view json, std::string_view description) {
    simdjson::dom::parser parser;
    simdjson::dom::element e;
    if (parser.parse(json.data(), json.size()).get(e) || !e.is_object()) {
        std::fprintf(stderr, "%s:%d: bad schema fragment in the node table: %.*s\n", __FILE__,
                     __LINE__, static_cast<int>(json.size()), json.data());
        std::abort(); // the table is ours: a bad fragment is a bug
    }
    w.beginObject();
    w.key("description");
    w.string(description);
    for (auto [key, value] : asObject(e)) {
        w.key(key);
        copyValue(w, value);
    }
    w.endObject();
}

void strings(JsonWriter& w, std::initializer_list<std::string_view> items) {
    w.beginArray(Layout::Inline);
    for (std::string_view s : items)
        w.string(s);
    w.endArray();
}

void ref(JsonWriter& w, std::string_view key, std::string_view target, std::string_view doc = {}) {
    w.key(key);
    w.beginObject(doc.empty() ? Layout::Inline : Layout::Block);
    if (!doc.empty()) {
        w.key("description");
        w.string(doc);
    }
    w.key("$ref");
    w.string(target);
    w.endObject();
}

// {"type":"number"} with the bound of a Check.
void numberBody(JsonWriter& w, Check check, double least = 1.0, double most = 1e6) {
    w.key("type");
    w.string(check == Check::Count ? "integer" : "number");
    if (check == Check::Count) {
        w.key("minimum");
        w.number(least);
        w.key("maximum");
        w.number(most);
    } else if (check == Check::Positive) {
        w.key("exclusiveMinimum");
        w.number(0.0);
    } else if (check == Check::NonNegative) {
        w.key("minimum");
        w.number(0.0);
    }
}

void vec3Body(JsonWriter& w, Check check) {
    w.key("type");
    w.string("array");
    w.key("items");
    w.beginObject(Layout::Inline);
    numberBody(w, check == Check::NonZero ? Check::Any : check);
    w.endObject();
    w.key("minItems");
    w.number(3.0);
    w.key("maxItems");
    w.number(3.0);
    if (check == Check::NonZero) {
        w.key("not");
        w.beginObject(Layout::Inline);
        w.key("const");
        w.beginArray(Layout::Inline);
        for (int i = 0; i < 3; ++i)
            w.number(0.0);
        w.endArray();
        w.endObject();
    }
}

void param(JsonWriter& w, const ParamInfo& p) {
    w.key(p.name);
    w.beginObject();
    w.key("description");
    w.string(std::string(p.doc) + " Unit: " + std::string(p.unit) + ".");
    if (p.type == ValueType::Choice) {
        w.key("enum");
        w.beginArray(Layout::Inline);
        for (std::string_view c : p.choices)
            w.string(c);
        w.endArray();
    } else if (p.type == ValueType::Text) {
        w.key("type");
        w.string("string");
    } else if (p.type == ValueType::Points) {
        w.key("type");
        w.string("array");
        w.key("items");
        w.beginObject(Layout::Inline);
        w.key("type");
        w.string("array");
        w.key("items");
        w.beginObject(Layout::Inline);
        w.key("type");
        w.string("number");
        w.endObject();
        w.key("minItems");
        w.number(2.0);
        w.key("maxItems");
        w.number(2.0);
        w.endObject();
        w.key("minItems");
        w.number(3.0);
        w.key("maxItems");
        w.number(double(kMaxPolygonPoints));
    } else if (p.type == ValueType::Number) {
        numberBody(w, p.check, p.least, std::min(double(p.maximum), 1e6));
        if (p.maximum < 3.4e38f && p.check != Check::Count) {
            w.key("maximum");
            w.number(p.maximum);
        }
    } else {
        vec3Body(w, p.check);
    }
    if (!p.required) {
        w.key("default");
        if (p.type == ValueType::Choice) {
            w.string(p.choices[size_t(p.fallback[0])]);
        } else if (p.type == ValueType::Text) {
            w.string("");
        } else if (p.type == ValueType::Number) {
            w.number(p.fallback[0]);
        } else {
            w.beginArray(Layout::Inline);
            for (int i = 0; i < 3; ++i)
                w.number(p.fallback[i]);
            w.endArray();
        }
    }
    w.endObject();
}

void kind(JsonWriter& w, const KindInfo& k) {
    w.key(k.name);
    w.beginObject();
    w.key("description");
    w.string(k.doc);
    w.key("type");
    w.string("object");
    w.key("properties");
    w.beginObject();
    for (const CommonKey& c : commonNodeKeys()) {
        if (c.name == "type") {
            w.key("type");
            w.beginObject();
            w.key("description");
            w.string(c.doc);
            w.key("const");
            w.string(k.name);
            w.endObject();
        } else if (c.name == "children" && isTransition(k.kind)) {
            w.key("children"); // the shapes it morphs between
            w.beginObject(Layout::Inline);
            w.key("$ref");
            w.string("#/$defs/children");
            w.key("minItems");
            w.number(2.0);
            w.key("maxItems");
            w.number(2.0);
            w.endObject();
        } else if (c.name != "children" || k.operation) {
            ref(w, c.name, "#/$defs/" + std::string(c.name));
        }
    }
    for (const ParamInfo& p : k.params)
        param(w, p);
    w.endObject();
    w.key("required");
    w.beginArray(Layout::Inline);
    w.string("type");
    for (const ParamInfo& p : k.params)
        if (p.required) w.string(p.name);
    if (k.operation) w.string("children");
    w.endArray();
    w.key("additionalProperties");
    w.boolean(false);
    w.key("examples");
    w.beginArray();
    const std::string example = exampleNodeJson(k);
    simdjson::dom::parser parser;
    simdjson::dom::element e;
    if (parser.parse(example).get(e)) {
        std::fprintf(stderr, "%s:%d: bad example in the node table: %s\n", __FILE__, __LINE__,
                     example.c_str());
        std::abort(); // the table is ours: a bad example is a bug
    }
    copyValue(w, e);
    w.endArray();
    w.endObject();
}

} // namespace

namespace {

// Definition and parameter names (what follows "$" in a reference): a string schema as an
// object of its own, or (`inlined` false) its members in the object the caller has open.
void nameBody(JsonWriter& w, bool inlined = true) {
    if (inlined) w.beginObject(Layout::Inline);
    w.key("type");
    w.string("string");
    w.key("pattern");
    w.string("^[A-Za-z_][A-Za-z0-9_]*$");
    w.key("maxLength");
    w.number(200.0);
    if (inlined) w.endObject();
}

// The scene object's own keys.
void topProperties(JsonWriter& w) {
    w.key("properties");
    w.beginObject();
    w.key("version");
    w.beginObject();
    w.key("description");
    w.string("Format version; must be " + std::to_string(kSceneVersion) + ".");
    w.key("const");
    w.number(static_cast<double>(kSceneVersion));
    w.endObject();
    w.key("name");
    w.beginObject();
    w.key("description");
    w.string("Optional title of the scene.");
    w.key("type");
    w.string("string");
    w.key("maxLength");
    w.number(200.0);
    w.endObject();
    w.key("description");
    w.beginObject();
    w.key("description");
    w.string("Optional free text about the scene.");
    w.key("type");
    w.string("string");
    w.endObject();
    ref(w, "camera", "#/$defs/camera",
        "Optional camera; when absent the scene is framed automatically from its bounds.");
    w.key("lights");
    w.beginObject();
    w.key("description");
    w.string("Optional lights; when absent or empty a warm key light and a cool fill light.");
    w.key("type");
    w.string("array");
    w.key("maxItems");
    w.number(static_cast<double>(SDFCSG_MAX_LIGHTS));
    ref(w, "items", "#/$defs/light");
    w.endObject();
    ref(w, "background", "#/$defs/color", "Background colour.");
    w.key("definitions");
    w.beginObject();
    w.key("description");
    w.string("Optional named subtrees that \"use\" nodes copy, each with parameters that its "
             "node refers to as \"$name\".");
    w.key("type");
    w.string("object");
    w.key("propertyNames");
    nameBody(w);
    ref(w, "additionalProperties", "#/$defs/definition");
    w.endObject();
    ref(w, "root", "#/$defs/node", "The top node of the scene tree.");
    w.endObject();
}

// A definition: its parameters with their defaults, and its node. The node is checked only as an
// object with a type here: its values may be "$name" references, which the loader reads with each
// use's values in place, and which a schema of the kinds' fields would refuse.
void definitionDef(JsonWriter& w) {
    w.key("definition");
    w.beginObject();
    w.key("description");
    w.string("A named subtree that \"use\" nodes copy. Inside its node, a string \"$name\" in "
             "place of a value stands for the parameter of that name: the use's value, else the "
             "default. It must be valid with its defaults.");
    w.key("type");
    w.string("object");
    w.key("properties");
    w.beginObject();
    w.key("parameters");
    w.beginObject();
    w.key("description");
    w.string("The parameters and their default values: numbers, strings or arrays.");
    w.key("type");
    w.string("object");
    w.key("propertyNames");
    nameBody(w);
    w.key("maxProperties");
    w.number(64.0);
    ref(w, "additionalProperties", "#/$defs/parameter_value");
    w.endObject();
    w.key("node");
    w.beginObject();
    w.key("description");
    w.string("The subtree: a node whose values may be \"$name\" references to the parameters; "
             "the loader checks it with each use's values.");
    w.key("type");
    w.string("object");
    w.key("required");
    strings(w, {"type"});
    w.endObject();
    w.endObject();
    w.key("required");
    strings(w, {"node"});
    w.key("additionalProperties");
    w.boolean(false);
    w.endObject();

    w.key("parameter_value");
    w.beginObject();
    w.key("description");
    w.string("A parameter's value: of the same JSON type as its default.");
    w.key("anyOf");
    w.beginArray();
    for (std::string_view type : {"number", "string", "array"}) {
        w.beginObject(Layout::Inline);
        w.key("type");
        w.string(type);
        w.endObject();
    }
    w.endArray();
    w.endObject();
}

// A use: the name of a definition, values for some of its parameters, and the keys every node
// may have besides children.
void useDef(JsonWriter& w) {
    w.key("use");
    w.beginObject();
    w.key("description");
    w.string("A copy of a definition's node, with the given values in place of its parameters "
             "(the defaults for the others), moved, coloured and named by the use's own keys.");
    w.key("type");
    w.string("object");
    w.key("properties");
    w.beginObject();
    w.key("type");
    w.beginObject();
    w.key("description");
    w.string("\"use\": a copy of a definition.");
    w.key("const");
    w.string("use");
    w.endObject();
    w.key("definition");
    w.beginObject();
    w.key("description");
    w.string("The name of one of the scene's definitions.");
    nameBody(w, false);
    w.endObject();
    w.key("parameters");
    w.beginObject();
    w.key("description");
    w.string("Values for some of the definition's parameters, each of the JSON type of its "
             "default.");
    w.key("type");
    w.string("object");
    w.key("propertyNames");
    nameBody(w);
    ref(w, "additionalProperties", "#/$defs/parameter_value");
    w.endObject();
    for (const CommonKey& c : commonNodeKeys())
        if (c.name != "type" && c.name != "children")
            ref(w, c.name, "#/$defs/" + std::string(c.name));
    w.endObject();
    w.key("required");
    strings(w, {"type", "definition"});
    w.key("additionalProperties");
    w.boolean(false);
    w.key("examples");
    w.beginArray();
    w.beginObject(Layout::Inline);
    w.key("type");
    w.string("use");
    w.key("definition");
    w.string("leg");
    w.key("parameters");
    w.beginObject(Layout::Inline);
    w.key("height");
    w.number(0.8);
    w.endObject();
    w.key("translate");
    w.beginArray(Layout::Inline);
    for (double v : {0.5, 0.0, 0.5})
        w.number(v);
    w.endArray();
    w.endObject();
    w.endArray();
    w.endObject();
}

void cameraDef(JsonWriter& w) {
    w.key("camera");
    w.beginObject();
    w.key("description");
    w.string("A pinhole camera. up must not be parallel to the line of sight.");
    w.key("type");
    w.string("object");
    w.key("properties");
    w.beginObject();
    ref(w, "eye", "#/$defs/vec3", "Camera position. Unit: point.");
    ref(w, "target", "#/$defs/vec3", "Point looked at; must differ from eye. Unit: point.");
    w.key("up");
    w.beginObject();
    w.key("description");
    w.string("Up direction. Unit: direction.");
    vec3Body(w, Check::NonZero);
    w.key("default");
    w.beginArray(Layout::Inline);
    for (float v : {0.0f, 1.0f, 0.0f})
        w.number(v);
    w.endArray();
    w.endObject();
    w.key("fov");
    w.beginObject();
    w.key("description");
    w.string("Vertical field of view. Unit: degrees.");
    w.key("type");
    w.string("number");
    w.key("exclusiveMinimum");
    w.number(0.0);
    w.key("exclusiveMaximum");
    w.number(180.0);
    w.key("default");
    w.number(Camera{}.fov);
    w.endObject();
    w.endObject();
    w.key("required");
    strings(w, {"eye", "target"});
    w.key("additionalProperties");
    w.boolean(false);
    w.endObject();
}

void lightDef(JsonWriter& w) {
    w.key("light");
    w.beginObject();
    w.key("description");
    w.string("A directional light.");
    w.key("type");
    w.string("object");
    w.key("properties");
    w.beginObject();
    w.key("direction");
    w.beginObject();
    w.key("description");
    w.string("Direction the light travels, towards the scene. Unit: direction.");
    vec3Body(w, Check::NonZero);
    w.endObject();
    ref(w, "color", "#/$defs/color", "Light colour.");
    w.key("intensity");
    w.beginObject();
    w.key("description");
    w.string("Brightness multiplier.");
    numberBody(w, Check::NonNegative);
    w.key("default");
    w.number(Light{}.intensity);
    w.endObject();
    w.endObject();
    w.key("required");
    strings(w, {"direction"});
    w.key("additionalProperties");
    w.boolean(false);
    w.endObject();
}

// A node: one of the kinds, each defined by kind().
void nodeDef(JsonWriter& w) {
    w.key("node");
    w.beginObject();
    w.key("description");
    w.string("A primitive, an operation or a use of a definition, chosen by \"type\".");
    w.key("oneOf");
    w.beginArray();
    for (const KindInfo& k : nodeKinds()) {
        w.beginObject(Layout::Inline);
        w.key("$ref");
        w.string("#/$defs/" + std::string(k.name));
        w.endObject();
    }
    w.beginObject(Layout::Inline);
    w.key("$ref");
    w.string("#/$defs/use");
    w.endObject();
    w.endArray();
    w.endObject();
    for (const KindInfo& k : nodeKinds())
        kind(w, k);
    useDef(w);
}

} // namespace

std::string sceneJsonSchema() {
    JsonWriter w;
    w.beginObject();
    w.key("$schema");
    w.string("https://json-schema.org/draft/2020-12/schema");
    w.key("title");
    w.string("sdfcsg scene");
    w.key("description");
    w.string("An sdfcsg scene, format version " + std::to_string(kSceneVersion) +
             ". Lengths are in scene units, angles in degrees, colours in 0..1. Generated from "
             "the node kind table by sceneJsonSchema() (`sdfcsg schema`); do not edit by hand.");
    w.key("type");
    w.string("object");
    topProperties(w);
    w.key("required");
    strings(w, {"version", "root"});
    w.key("additionalProperties");
    w.boolean(false);

    w.key("$defs");
    w.beginObject();
    w.key("vec3");
    w.beginObject();
    vec3Body(w, Check::Any);
    w.endObject();
    // The keys every node may have, referenced from each kind.
    for (const CommonKey& c : commonNodeKeys()) {
        if (c.name == "type") continue;
        w.key(c.name);
        fragment(w, c.schemaType, c.doc);
    }

    cameraDef(w);
    lightDef(w);
    definitionDef(w);
    nodeDef(w);
    w.endObject();

    w.endObject();
    return w.finish();
}

} // namespace sdfcsg
