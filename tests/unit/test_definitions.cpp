// Definitions and uses: a use is its definition's node copied under a union, with the use's
// values in place of the parameters; the copies evaluate as the same tree written out does (on
// the CPU, and on the GPU against the CPU); every refusal names its path and, inside a copy, the
// uses that made it; recursion and copies past the node limit are refused before any copy is
// made; toJson writes the definitions and uses back, not the copies.
#include "gpu_probe.h"
#include "gpu_test.h" // tests/gtest_suites.cmake labels the program's fixtures gpu by this line

#include <sdfcsg/eval.h>
#include <sdfcsg/scene.h>

#include <gtest/gtest.h>

#include <chrono>
#include <random>
#include <string>
#include <vector>

namespace sdfcsg::test {
namespace {

namespace fs = std::filesystem;

// The full message for a text that must fail, or "<parsed>".
std::string errorOf(std::string_view json, const Limits& limits = {}) {
    auto r = parseScene(json, "scene.json", limits);
    return r ? std::string("<parsed>") : r.error().str();
}

Scene parseOrFail(std::string_view json) {
    auto r = parseScene(json, "scene.json");
    if (!r) {
        ADD_FAILURE() << r.error().str() << "\n" << json;
        return Scene{};
    }
    return *r;
}

std::string withDefinitions(std::string_view definitions, std::string_view root) {
    return R"({"version": 1, "definitions": )" + std::string(definitions) + R"(, "root": )" +
           std::string(root) + "}";
}

// A leg and a chair that uses it, with parameters of every JSON type: numbers, an array and a
// colour string.
constexpr std::string_view kFurniture = R"({
    "leg": {"parameters": {"height": 1.0, "radius": 0.1},
            "node": {"type": "cylinder", "height": "$height", "radius": "$radius"}},
    "chair": {"parameters": {"leg_height": 0.4, "seat": [1, 0.1, 1], "wood": "#806040"},
              "node": {"type": "union", "color": "$wood", "children": [
                  {"type": "box", "name": "seat", "size": "$seat", "translate": [0, 0.45, 0]},
                  {"type": "use", "definition": "leg", "name": "front",
                   "parameters": {"height": "$leg_height"}, "translate": [0.4, 0.2, 0.4]},
                  {"type": "use", "definition": "leg",
                   "parameters": {"height": "$leg_height", "radius": 0.05},
                   "translate": [-0.4, 0.2, -0.4]}]}}})";

// The same scene written out: each use a union of one child holding the copy.
constexpr std::string_view kWrittenOut = R"({"version": 1, "root": {"type": "union", "children": [
    {"type": "union", "name": "front leg", "translate": [1, 0, 0], "color": [1, 0, 0],
     "children": [{"type": "cylinder", "height": 2, "radius": 0.1}]},
    {"type": "union", "translate": [-1, 0, 0], "children": [
        {"type": "cylinder", "height": 1, "radius": 0.1}]},
    {"type": "union", "translate": [0, 0, 2], "rotate": [0, 30, 0], "scale": 1.5, "children": [
        {"type": "union", "color": "#806040", "children": [
            {"type": "box", "name": "seat", "size": [1.2, 0.1, 0.8], "translate": [0, 0.45, 0]},
            {"type": "union", "name": "front", "translate": [0.4, 0.2, 0.4], "children": [
                {"type": "cylinder", "height": 0.5, "radius": 0.1}]},
            {"type": "union", "translate": [-0.4, 0.2, -0.4], "children": [
                {"type": "cylinder", "height": 0.5, "radius": 0.05}]}]}]},
    {"type": "union", "translate": [0, 0, -2], "color": [0, 0.5, 1], "children": [
        {"type": "union", "color": "#806040", "children": [
            {"type": "box", "name": "seat", "size": [1, 0.1, 1], "translate": [0, 0.45, 0]},
            {"type": "union", "name": "front", "translate": [0.4, 0.2, 0.4], "children": [
                {"type": "cylinder", "height": 0.4, "radius": 0.1}]},
            {"type": "union", "translate": [-0.4, 0.2, -0.4], "children": [
                {"type": "cylinder", "height": 0.4, "radius": 0.05}]}]}]}]}})";

std::string furnitureScene() {
    return withDefinitions(kFurniture, R"({"type": "union", "children": [
        {"type": "use", "definition": "leg", "parameters": {"height": 2.0},
         "translate": [1, 0, 0], "color": [1, 0, 0], "name": "front leg"},
        {"type": "use", "definition": "leg", "translate": [-1, 0, 0]},
        {"type": "use", "definition": "chair", "translate": [0, 0, 2], "rotate": [0, 30, 0],
         "scale": 1.5, "parameters": {"leg_height": 0.5, "seat": [1.2, 0.1, 0.8]}},
        {"type": "use", "definition": "chair", "translate": [0, 0, -2], "color": [0, 0.5, 1]}]})");
}

std::vector<glm::vec3> randomPoints(size_t count, float reach) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-reach, reach);
    std::vector<glm::vec3> points(count);
    for (glm::vec3& p : points)
        p = glm::vec3(u(rng), u(rng), u(rng));
    return points;
}

TEST(Definitions, CopiesAreTheTreeWrittenOut) {
    const Scene used = parseOrFail(furnitureScene());
    const Scene written = parseOrFail(kWrittenOut);
    ASSERT_EQ(used.nodes.size(), written.nodes.size());
    for (size_t i = 0; i < used.nodes.size(); ++i) {
        SCOPED_TRACE(written.nodes[i].path);
        const Node &a = used.nodes[i], &b = written.nodes[i];
        EXPECT_EQ(a.kind, b.kind);
        EXPECT_EQ(a.name, b.name);
        EXPECT_EQ(a.params, b.params);
        EXPECT_EQ(a.transform.translate, b.transform.translate);
        EXPECT_EQ(a.transform.rotate, b.transform.rotate);
        EXPECT_EQ(a.transform.scale, b.transform.scale);
        EXPECT_EQ(a.color, b.color);
        EXPECT_EQ(a.children, b.children);
    }
    // The same field, to the bit: the copies are evaluated as any other nodes.
    const Evaluator a(used), b(written);
    for (glm::vec3 p : randomPoints(4000, 3.0f)) {
        const Sample x = a.sample(p), y = b.sample(p);
        ASSERT_EQ(x.distance, y.distance) << p.x << ", " << p.y << ", " << p.z;
        ASSERT_EQ(x.color, y.color);
    }
}

TEST(Definitions, UsesKeepWhatTheyWereWrittenWith) {
    const Scene scene = parseOrFail(furnitureScene());
    ASSERT_EQ(scene.definitions.size(), 2u);
    EXPECT_EQ(scene.definitions[0].name, "leg");
    EXPECT_EQ(scene.definitions[0].parameters,
              (std::vector<NamedValue>{{"height", "1"}, {"radius", "0.1"}}));
    EXPECT_EQ(scene.definitions[0].node,
              R"({"type": "cylinder", "height": "$height", "radius": "$radius"})");
    EXPECT_EQ(scene.definitions[1].parameters[1], (NamedValue{"seat", "[1, 0.1, 1]"}));
    EXPECT_EQ(scene.definitions[1].parameters[2], (NamedValue{"wood", "\"#806040\""}));

    const Node& front = scene.nodes[1];
    EXPECT_EQ(front.path, "root.children[0]");
    EXPECT_EQ(front.kind, NodeKind::Union);
    EXPECT_EQ(front.name, "front leg");
    ASSERT_TRUE(front.use);
    EXPECT_EQ(front.use->definition, "leg");
    EXPECT_EQ(front.use->arguments, (std::vector<NamedValue>{{"height", "2"}}));
    ASSERT_EQ(front.children.size(), 1u);
    // The copy: at the definition's path, with the use's value and else the default.
    const Node& copy = scene.nodes[front.children[0]];
    EXPECT_EQ(copy.path, "definitions.leg.node");
    EXPECT_EQ(copy.kind, NodeKind::Cylinder);
    EXPECT_FALSE(copy.use);
    EXPECT_FLOAT_EQ(copy.params[0], 0.1f); // radius: the default
    EXPECT_FLOAT_EQ(copy.params[1], 2.0f); // height: the use's

    // A use inside a copy passes the chair's parameter on to the leg.
    const Node& chair = scene.nodes[scene.nodes[0].children[2]];
    const Node& body = scene.nodes[chair.children[0]];
    const Node& innerUse = scene.nodes[body.children[1]];
    EXPECT_EQ(innerUse.path, "definitions.chair.node.children[1]");
    ASSERT_TRUE(innerUse.use);
    EXPECT_EQ(innerUse.use->arguments, (std::vector<NamedValue>{{"height", "\"$leg_height\""}}));
    const Node& innerLeg = scene.nodes[innerUse.children[0]];
    EXPECT_EQ(innerLeg.path, "definitions.leg.node");
    EXPECT_FLOAT_EQ(innerLeg.params[1], 0.5f);
    EXPECT_EQ(scene.nodes[body.children[0]].path, "definitions.chair.node.children[0]");
}

TEST(Definitions, TextAndChoiceParameters) {
    const Scene scene = parseOrFail(withDefinitions(R"({"label": {
        "parameters": {"text": "Hi", "blend": "round", "depth": 0.1},
        "node": {"type": "union", "smooth": 0.05, "blend": "$blend", "children": [
            {"type": "extrude", "height": "$depth", "children": [
                {"type": "text", "text": "$text", "size": 0.5}]}]}}})",
                                                    R"({"type": "union", "children": [
        {"type": "use", "definition": "label"},
        {"type": "use", "definition": "label", "translate": [0, 1, 0],
         "parameters": {"text": "$5 off", "blend": "chamfer"}}]})"));
    ASSERT_EQ(scene.nodes.size(), 9u);
    EXPECT_EQ(scene.nodes[4].strings[0], "Hi");
    EXPECT_FLOAT_EQ(scene.nodes[2].params[1], 1.0f); // "round"
    // "$5 off" names no parameter: a string like any other.
    EXPECT_EQ(scene.nodes[8].strings[0], "$5 off");
    EXPECT_FLOAT_EQ(scene.nodes[6].params[1], 2.0f); // "chamfer"
}

TEST(Definitions, RoundTripKeepsDefinitionsAndUses) {
    const Scene first = parseOrFail(furnitureScene());
    const std::string text = toJson(first);
    EXPECT_NE(text.find("\"definitions\": {"), std::string::npos) << text;
    // Three cylinders in the copies, one in the file.
    size_t cylinders = 0;
    for (size_t at = 0; (at = text.find("\"cylinder\"", at)) != std::string::npos; ++at)
        ++cylinders;
    EXPECT_EQ(cylinders, 1u) << text;
    auto second = parseScene(text, "round-trip.json");
    ASSERT_TRUE(second) << second.error().str() << "\n" << text;
    EXPECT_EQ(second->definitions, first.definitions);
    ASSERT_EQ(second->nodes.size(), first.nodes.size());
    for (size_t i = 0; i < first.nodes.size(); ++i) {
        EXPECT_EQ(second->nodes[i].use, first.nodes[i].use);
        EXPECT_EQ(second->nodes[i].path, first.nodes[i].path);
        EXPECT_EQ(second->nodes[i].params, first.nodes[i].params);
    }
    EXPECT_EQ(toJson(*second), text);

    // The layout: definitions before the root, a node's members as written, uses as written.
    const Scene small = parseOrFail(withDefinitions(
        R"({"leg": {"parameters": {"height": 1.0, "at": [0, 0.5, 0]},
                    "node": {"type": "cylinder", "radius": 0.1, "height": "$height",
                             "translate": "$at"}}})",
        R"({"type": "use", "definition": "leg", "name": "left", "parameters": {"height": 2.5},
            "translate": [1, 0, 0], "color": "#ff0000"})"));
    EXPECT_EQ(toJson(small), R"({
  "version": 1,
  "definitions": {
    "leg": {
      "parameters": {"height": 1, "at": [0, 0.5, 0]},
      "node": {
        "type": "cylinder",
        "radius": 0.1,
        "height": "$height",
        "translate": "$at"
      }
    }
  },
  "root": {
    "type": "use",
    "name": "left",
    "definition": "leg",
    "parameters": {"height": 2.5},
    "translate": [1, 0, 0],
    "color": "#ff0000"
  }
}
)");
}

// A scene built in code: definitions as JSON text, uses as the loader would make them.
TEST(Definitions, ToJsonOfASceneBuiltInCode) {
    Scene scene;
    scene.definitions.push_back({"ball", {{"r", "0.5"}}, R"({"type":"sphere","radius":"$r"})"});
    scene.nodes.resize(1);
    scene.nodes[0].kind = NodeKind::Union;
    scene.nodes[0].use = Use{"ball", {{"r", "2"}}};
    auto parsed = parseScene(toJson(scene));
    ASSERT_TRUE(parsed) << parsed.error().str();
    ASSERT_EQ(parsed->nodes.size(), 2u);
    EXPECT_FLOAT_EQ(parsed->nodes[1].params[0], 2.0f);
    // Text that is not JSON is written as null, which the loader refuses.
    scene.definitions[0].node = "{not json";
    EXPECT_EQ(errorOf(toJson(scene)),
              "scene.json: definitions.ball.node: expected a node (an object with \"type\"), got "
              "null");
}

struct BadDefinition {
    const char* name;
    std::string json;
    std::string expected;
};

std::vector<BadDefinition> badDefinitions() {
    const std::string leg = R"({"leg": {"parameters": {"height": 1.0, "radius": 0.1},
        "node": {"type": "cylinder", "height": "$height", "radius": "$radius"}}})";
    auto useLeg = [&](std::string_view members) {
        return withDefinitions(leg, R"({"type": "union", "children": [)" +
                                        std::string(R"({"type": "sphere", "radius": 1}, )") +
                                        R"({"type": "use", "definition": "leg")" +
                                        std::string(members) + "}]}");
    };
    return {
        {"unknown definition", useLeg("").replace(useLeg("").find("\"leg\"}"), 5, "\"lge\""),
         R"(scene.json: root.children[1].definition: unknown definition "lge"; did you mean "leg"?)"},
        {"unknown definition, none close",
         useLeg("").replace(useLeg("").find("\"leg\"}"), 5, "\"table\""),
         R"(scene.json: root.children[1].definition: unknown definition "table"; the scene defines leg)"},
        {"a use without definitions",
         R"({"version": 1, "root": {"type": "use", "definition": "leg"}})",
         R"(scene.json: root.definition: unknown definition "leg"; the scene has no "definitions")"},
        {"a use without a definition",
         withDefinitions(leg, R"({"type": "use", "translate": [1, 0, 0]})"),
         R"(scene.json: root: missing required key "definition" (the name of one of the scene's "definitions"))"},
        {"unknown parameter", useLeg(R"(, "parameters": {"heigth": 2})"),
         R"(scene.json: root.children[1].parameters: unknown parameter "heigth" of "leg"; did you mean "height"?)"},
        {"unknown parameter, none close", useLeg(R"(, "parameters": {"colour_of_wood": 2})"),
         R"(scene.json: root.children[1].parameters: unknown parameter "colour_of_wood" of "leg"; it has height and radius)"},
        {"a parameter of the wrong type", useLeg(R"(, "parameters": {"height": "tall"})"),
         R"(scene.json: root.children[1].parameters.height: expected a number, as the default of "height" in "leg" is, got "tall")"},
        {"an array for a number", useLeg(R"(, "parameters": {"radius": [1, 2, 3]})"),
         R"(scene.json: root.children[1].parameters.radius: expected a number, as the default of "radius" in "leg" is, got [1, 2, 3])"},
        {"parameters not an object", useLeg(R"(, "parameters": [2])"),
         R"(scene.json: root.children[1].parameters: expected an object of parameter values, got [2])"},
        {"children on a use", useLeg(R"(, "children": [])"),
         R"(scene.json: root.children[1]: unknown key "children" for a use; valid keys: definition, parameters, type, name, translate, rotate, scale and color)"},
        {"a value out of range in the copy", useLeg(R"(, "parameters": {"height": -1})"),
         R"(scene.json: definitions.leg.node.height: expected a positive number, got -1 (in the use of "leg" at root.children[1]))"},
        {"a reference to no parameter",
         withDefinitions(R"({"leg": {"parameters": {"height": 1.0, "radius": 0.1},
            "node": {"type": "cylinder", "height": "$height", "radius": "$raduis"}}})",
                         R"({"type": "use", "definition": "leg"})"),
         R"(scene.json: definitions.leg.node.radius: "$raduis" names no parameter of "leg"; did you mean "radius"?)"},
        {"a reference in a definition without parameters",
         withDefinitions(R"({"ball": {"node": {"type": "sphere", "radius": "$r"}}})",
                         R"({"type": "use", "definition": "ball"})"),
         R"(scene.json: definitions.ball.node.radius: "$r" names no parameter of "ball"; it has none)"},
        {"a reference outside a definition",
         R"({"version": 1, "root": {"type": "sphere", "radius": "$r"}})",
         R"(scene.json: root.radius: "$r" refers to a parameter, and only the nodes of definitions have parameters)"},
        {"a default of no parameter's type",
         withDefinitions(R"({"leg": {"parameters": {"height": true},
            "node": {"type": "cylinder", "height": "$height", "radius": 1}}})",
                         R"({"type": "sphere", "radius": 1})"),
         R"(scene.json: definitions.leg.parameters.height: expected a default value (a number, a string or an array), got true)"},
        {"a default that refers",
         withDefinitions(R"({"leg": {"parameters": {"height": "$h"},
            "node": {"type": "sphere", "radius": 1}}})",
                         R"({"type": "sphere", "radius": 1})"),
         R"(scene.json: definitions.leg.parameters.height: expected a default value, got "$h", a reference (a default cannot refer to a parameter))"},
        {"a definition name with a space",
         withDefinitions(R"({"front leg": {"node": {"type": "sphere", "radius": 1}}})",
                         R"({"type": "sphere", "radius": 1})"),
         R"(scene.json: definitions: expected a definition name of letters, digits and underscores, not starting with a digit, got "front leg")"},
        {"a parameter name with a digit first",
         withDefinitions(
             R"({"leg": {"parameters": {"2x": 1}, "node": {"type": "sphere", "radius": 1}}})",
             R"({"type": "sphere", "radius": 1})"),
         R"(scene.json: definitions.leg.parameters: expected a parameter name of letters, digits and underscores, not starting with a digit, got "2x")"},
        {"a definition without a node",
         withDefinitions(R"({"leg": {"parameters": {"h": 1}}})",
                         R"({"type": "sphere", "radius": 1})"),
         R"(scene.json: definitions.leg: missing required key "node" (the node that uses copy, whose values may be "$name" references to the parameters))"},
        {"a definition that is no object",
         withDefinitions(R"({"leg": [1]})", R"({"type": "sphere", "radius": 1})"),
         R"(scene.json: definitions.leg: expected a definition (an object with "node" and optionally "parameters"), got [1])"},
        {"definitions not an object",
         withDefinitions(R"([])", R"({"type": "sphere", "radius": 1})"),
         R"(scene.json: definitions: expected an object of named definitions, each {"parameters": {...}, "node": NODE}, got [])"},
        {"an error in an unused definition",
         withDefinitions(R"({"leg": {"node": {"type": "cylinder", "height": 1, "raduis": 1}}})",
                         R"({"type": "sphere", "radius": 1})"),
         "scene.json: definitions.leg.node: unknown key \"raduis\"; did you mean \"radius\"?\n"
         "scene.json: definitions.leg.node: missing required key \"radius\" (a positive number)"},
        {"recursion, direct",
         withDefinitions(R"({"a": {"node": {"type": "union", "children": [
            {"type": "sphere", "radius": 1}, {"type": "use", "definition": "a"}]}}})",
                         R"({"type": "use", "definition": "a"})"),
         R"(scene.json: definitions.a.node.children[1]: recursive use: "a" uses itself)"},
        {"recursion through another definition",
         withDefinitions(R"({"a": {"node": {"type": "use", "definition": "b"}},
                             "b": {"node": {"type": "union", "children": [
                                 {"type": "use", "definition": "c"}]}},
                             "c": {"node": {"type": "use", "definition": "a", "scale": 0.5}}})",
                         R"({"type": "use", "definition": "c"})"),
         R"(scene.json: definitions.c.node: recursive use: "c" uses "a", which uses "b", which uses "c")"},
        {"a 2D profile copied outside an extrude",
         withDefinitions(R"({"disc": {"node": {"type": "circle", "radius": 1}}})",
                         R"({"type": "union", "children": [{"type": "sphere", "radius": 1},
                             {"type": "use", "definition": "disc"}]})"),
         R"(scene.json: definitions.disc.node: a circle is a 2D profile: it must be inside an extrude or a revolve (in the use of "disc" at root.children[1]))"},
    };
}

TEST(Definitions, RefusalsGiveExactMessages) {
    for (const BadDefinition& c : badDefinitions()) {
        SCOPED_TRACE(c.name);
        EXPECT_EQ(errorOf(c.json), c.expected);
    }
}

// An error in a copy inside a copy names both uses, innermost first.
TEST(Definitions, AnErrorInANestedCopyNamesEveryUse) {
    const std::string json = withDefinitions(kFurniture, R"({"type": "union", "children": [
        {"type": "sphere", "radius": 1},
        {"type": "use", "definition": "chair", "parameters": {"leg_height": -2}}]})");
    EXPECT_EQ(errorOf(json),
              "scene.json: definitions.leg.node.height: expected a positive number, got -2 (in the "
              "use of \"leg\" at definitions.chair.node.children[1], in the use of \"chair\" at "
              "root.children[1])\n"
              "scene.json: definitions.leg.node.height: expected a positive number, got -2 (in the "
              "use of \"leg\" at definitions.chair.node.children[2], in the use of \"chair\" at "
              "root.children[1])");
}

TEST(Definitions, UsesCountTowardsTheDepthLimit) {
    Limits limits;
    limits.maxDepth = 3;
    const std::string defs = R"({"inner": {"node": {"type": "union", "children": [
        {"type": "sphere", "radius": 1}]}}})";
    EXPECT_EQ(errorOf(withDefinitions(defs, R"({"type": "union", "children": [
        {"type": "use", "definition": "inner"}]})"),
                      limits),
              "<parsed>");
    EXPECT_EQ(errorOf(withDefinitions(defs, R"({"type": "union", "children": [
        {"type": "union", "children": [{"type": "use", "definition": "inner"}]}]})"),
                      limits),
              "scene.json: definitions.inner.node: nesting too deep: more than 3 nested operations "
              "(in the use of \"inner\" at root.children[0].children[0])");
}

// 2^40 nodes if copied: refused at the first definition whose copy passes the limit, before a
// single copy is made, in far less time than copying would take.
TEST(Definitions, CopiesPastTheNodeLimitAreRefusedBeforeCopying) {
    std::string defs = R"({"d0": {"node": {"type": "sphere", "radius": 1}})";
    for (int i = 1; i <= 40; ++i)
        defs += ", \"d" + std::to_string(i) +
                R"(": {"node": {"type": "union", "children": [{"type": "use", "definition": "d)" +
                std::to_string(i - 1) + R"("}, {"type": "use", "definition": "d)" +
                std::to_string(i - 1) + R"(", "translate": [1, 0, 0]}]}})";
    defs += "}";
    const auto start = std::chrono::steady_clock::now();
    // Sizes 2^(i+2) - 3: d13 is the first past 16384.
    EXPECT_EQ(errorOf(withDefinitions(defs, R"({"type": "use", "definition": "d40"})")),
              "scene.json: definitions.d13: too many nodes: a copy of this definition, with the "
              "copies its uses make, would have more than 16384, the most a scene may have");
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
    auto r = parseScene(withDefinitions(defs, R"({"type": "use", "definition": "d40"})"));
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().kind, ErrorKind::Limit);

    // A definition of 1000 uses, used 1000 times: each copy fits, all of them do not; refused
    // where the count passes the limit.
    std::string row = R"({"type": "union", "children": [)";
    std::string rows = row;
    for (int i = 0; i < 1000; ++i) {
        row += std::string(i ? ", " : "") + R"({"type": "use", "definition": "leaf"})";
        rows += std::string(i ? ", " : "") + R"({"type": "use", "definition": "row"})";
    }
    row += "]}";
    rows += "]}";
    const std::string json = withDefinitions(
        R"({"leaf": {"node": {"type": "sphere", "radius": 1}}, "row": {"node": )" + row + "}}",
        rows);
    // 1 + 2001 nodes in each copy of row, with its use: the ninth passes 16384.
    EXPECT_EQ(errorOf(json),
              "scene.json: root.children[8]: too many nodes: a scene may have at most 16384, "
              "counting the copies that uses make, and the copy of \"row\" here passes that");
}

TEST(Definitions, ALimitJustMet) {
    const std::string json =
        withDefinitions(R"({"leg": {"node": {"type": "sphere", "radius": 1}}})",
                        R"({"type": "union", "children": [
        {"type": "use", "definition": "leg"}, {"type": "use", "definition": "leg"}]})");
    Limits limits;
    limits.maxNodes = 5;
    EXPECT_EQ(errorOf(json, limits), "<parsed>");
    limits.maxNodes = 4;
    EXPECT_EQ(errorOf(json, limits),
              "scene.json: root.children[1]: too many nodes: a scene may have at most 4, counting "
              "the copies that uses make, and the copy of \"leg\" here passes that");
}

TEST(Definitions, TheBundledSceneUsesThem) {
    const Scene scene =
        loadOrDie(fs::path(SDFCSG_SOURCE_DIR) / "assets/scenes/table_and_chairs.json");
    ASSERT_FALSE(scene.nodes.empty());
    size_t uses = 0, chairs = 0;
    for (const Node& n : scene.nodes) {
        uses += n.use.has_value();
        chairs += n.use && n.use->definition == "chair";
    }
    EXPECT_EQ(chairs, 4u);
    EXPECT_EQ(uses, 1 + 1 + 4 * 3u); // the table and its leg, each chair and two legs
}

class DefinitionsGpu : public GpuTest {};

// The copies on the GPU, held to the CPU as every other tree is.
TEST_F(DefinitionsGpu, CopiesMatchTheCpu) {
    expectGpuMatchesCpu(context(), parseOrFail(furnitureScene()), 2048);
    expectGpuMatchesCpu(
        context(), loadOrDie(fs::path(SDFCSG_SOURCE_DIR) / "assets/scenes/table_and_chairs.json"),
        2048);
}

} // namespace
} // namespace sdfcsg::test
