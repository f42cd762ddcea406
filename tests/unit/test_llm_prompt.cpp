// What the language model is told and what is done with its answer, without a network: the
// prompt made from the node table and the example scenes, the strict schema, the extraction
// of JSON from an answer, the repair message, and the geometric sanity warnings.
#include <sdfcsg/generate.h>

#include "codegen/embedded_shaders.h"
#include "shared.h"

#include <gtest/gtest.h>

#include <simdjson.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using namespace sdfcsg;

namespace {

std::string readFile(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

Scene parse(std::string_view json) {
    auto scene = parseScene(json, "test.json");
    EXPECT_TRUE(scene) << scene.error().str();
    return scene ? *scene : Scene{};
}

std::vector<std::string> warnings(std::string_view json) {
    std::vector<std::string> out;
    for (const Diagnostic& d : sceneSanityWarnings(parse(json)))
        out.push_back(d.path + ": " + d.message);
    return out;
}

} // namespace

TEST(LlmPrompt, ExamplesAreBundledScenesThatValidate) {
    auto examples = detail::embeddedExampleScenes();
    ASSERT_GE(examples.size(), 2u);
    ASSERT_LE(examples.size(), 3u);
    const std::vector<std::string> requests = sceneExampleRequests();
    ASSERT_EQ(requests.size(), examples.size());
    for (size_t i = 0; i < examples.size(); ++i) {
        const detail::EmbeddedFile& example = examples[i];
        SCOPED_TRACE(std::string(example.name));
        EXPECT_EQ(example.text, readFile(fs::path(SDFCSG_SOURCE_DIR) / "assets/scenes" /
                                         std::string(example.name)));
        auto scene = parseScene(example.text, example.name);
        ASSERT_TRUE(scene) << scene.error().str();
        EXPECT_FALSE(scene->description.empty()); // it is the example's request
        EXPECT_EQ(requests[i], scene->description);
        EXPECT_TRUE(sceneSanityWarnings(*scene).empty());
        EXPECT_NE(sceneSystemPrompt().find("Request: " + scene->description + "\nAnswer:\n" +
                                           std::string(example.text)),
                  std::string::npos);
    }
}

TEST(LlmPrompt, SystemPromptHoldsTheGeneratedReference) {
    const std::string prompt = sceneSystemPrompt();
    EXPECT_NE(prompt.find(sceneFormatReference()), std::string::npos);
    for (const KindInfo& kind : nodeKinds()) {
        EXPECT_NE(prompt.find("| `" + std::string(kind.name) + "` |"), std::string::npos)
            << kind.name;
        for (const ParamInfo& p : kind.params)
            EXPECT_NE(prompt.find("`" + std::string(p.name) + "` (" + std::string(p.unit)),
                      std::string::npos)
                << kind.name << "." << p.name;
    }
}

// The top-level keys come from the scene schema: every one is listed with its shape, and so are
// the limits that the schema states (the number of lights).
TEST(LlmPrompt, SystemPromptListsEveryTopLevelKey) {
    const std::string prompt = sceneSystemPrompt();
    const std::string schema = sceneJsonSchema();
    simdjson::dom::parser parser;
    simdjson::dom::element top = parser.parse(schema);
    for (auto [key, value] : simdjson::dom::object(top["properties"]))
        EXPECT_NE(prompt.find("\n- \"" + std::string(key) + "\": "), std::string::npos) << key;
    for (const char* def : {"camera", "light"})
        for (auto [key, value] : simdjson::dom::object(top["$defs"][def]["properties"]))
            EXPECT_NE(prompt.find("\"" + std::string(key) + "\": "), std::string::npos)
                << def << "." << key;
    EXPECT_NE(prompt.find("- \"lights\": up to " + std::to_string(SDFCSG_MAX_LIGHTS) +
                          " of {\"direction\": [x, y, z], \"color\": [r, g, b], \"intensity\": "
                          "number}. "),
              std::string::npos);
    EXPECT_NE(prompt.find("- \"camera\": {\"eye\": [x, y, z], \"target\": [x, y, z], \"up\": "
                          "[x, y, z], \"fov\": degrees}. "),
              std::string::npos);
}

TEST(LlmPrompt, UserPromptForAnEdit) {
    EXPECT_EQ(sceneUserPrompt("a red sphere"), "Request: a red sphere");
    EXPECT_EQ(sceneUserPrompt("make it blue", "{\"version\": 1}"),
              "Here is the current scene:\n{\"version\": 1}\n\nChange it as follows: make it "
              "blue\nAnswer with the whole changed scene. Keep the names, and everything that the "
              "change does not concern, as they are.");
}

TEST(LlmPrompt, RepairPromptQuotesTheValidator) {
    auto bad = parseScene(
        R"({"version": 1, "root": {"type": "sphere", "radius": -1, "colour": 1}})", "answer");
    ASSERT_FALSE(bad);
    EXPECT_EQ(sceneRepairPrompt(bad.error()),
              "Your scene does not load. The validator reported:\n"
              "- root: unknown key \"colour\"; did you mean \"color\"?\n"
              "- root.radius: expected a positive number, got -1\n"
              "Answer with the whole corrected scene as one JSON object, and nothing else.");
    auto broken = parseScene("{\"version\": 1,\n \"root\": }", "answer");
    ASSERT_FALSE(broken);
    const Diagnostic& d = broken.error().diagnostics[0];
    EXPECT_EQ(
        sceneRepairPrompt(broken.error()),
        "Your scene does not load. The validator reported:\n- line 2, column 10: " + d.message +
            "\nAnswer with the whole corrected scene as one JSON object, and nothing else.");
}

TEST(LlmPrompt, ExtractJson) {
    const std::string scene = R"({"version": 1, "root": {"type": "sphere", "radius": 1}})";
    EXPECT_EQ(extractJson(scene), scene);
    EXPECT_EQ(extractJson("  \n" + scene + "\n"), scene);
    EXPECT_EQ(extractJson("Here you are:\n```json\n" + scene + "\n```\nEnjoy {it}!"), scene);
    EXPECT_EQ(extractJson("```\n" + scene + "\n```"), scene);
    EXPECT_EQ(extractJson("<think>A {sphere}? ```no```</think>\n" + scene), scene);
    EXPECT_EQ(extractJson("<think>\nfirst</think><think>second {</think>```json\n" + scene + "```"),
              scene);
    // The template opened the block, so only its end is in the answer.
    EXPECT_EQ(extractJson("so a sphere {r=1}.\n</think>\n\n" + scene), scene);
    EXPECT_EQ(extractJson("Sure! " + scene + " Anything else?"), scene);
    EXPECT_EQ(extractJson("  I cannot help with that.  "), "I cannot help with that.");
}

// OpenAI's strict mode: every object lists all its keys as required and allows no others, and
// only a core of keywords is used. Every $ref resolves, and every kind and field is there.
TEST(LlmPrompt, LlmSchemaIsStrict) {
    const std::string text = sceneLlmSchema();
    simdjson::dom::parser parser;
    simdjson::dom::element top = parser.parse(text);
    const std::set<std::string_view> allowed = {
        "type",  "description", "properties", "required", "additionalProperties",
        "items", "enum",        "anyOf",      "$ref",     "$defs"};
    simdjson::dom::object defs = top["$defs"];
    std::vector<simdjson::dom::element> todo = {top};
    size_t objects = 0;
    while (!todo.empty()) {
        simdjson::dom::element e = todo.back();
        todo.pop_back();
        if (e.is_array()) {
            for (auto item : e.get_array())
                todo.push_back(item);
            continue;
        }
        if (!e.is_object()) continue;
        simdjson::dom::object o = e;
        for (auto [key, value] : o) {
            EXPECT_TRUE(allowed.count(key)) << "keyword " << key;
            if (key == "$ref") {
                std::string_view ref = value;
                ASSERT_TRUE(ref.starts_with("#/$defs/")) << ref;
                simdjson::dom::element target;
                EXPECT_FALSE(defs[ref.substr(8)].get(target)) << ref;
            }
            if (key == "properties") {
                ++objects;
                std::vector<std::string_view> keys, required;
                for (auto [name, schema] : simdjson::dom::object(value)) {
                    keys.push_back(name);
                    todo.push_back(schema);
                }
                for (auto name : o["required"].get_array())
                    required.push_back(name.get_string());
                EXPECT_EQ(keys, required);
                EXPECT_FALSE(bool(o["additionalProperties"].get_bool().value()));
            } else if (key == "$defs") {
                for (auto [name, schema] : simdjson::dom::object(value))
                    todo.push_back(schema);
            } else if (value.is_object() || value.is_array()) {
                todo.push_back(value);
            }
        }
    }
    EXPECT_GE(objects, size_t(kNodeKindCount));
    // Strict mode cannot list the names a scene chooses: no definitions, no uses.
    simdjson::dom::element absent;
    EXPECT_TRUE(top["properties"]["definitions"].get(absent));
    for (const char* name : {"definition", "parameter_value", "use"})
        EXPECT_TRUE(defs[name].get(absent)) << name;
    EXPECT_EQ(text.find("#/$defs/use"), std::string::npos);
    for (const KindInfo& kind : nodeKinds()) {
        simdjson::dom::object properties = defs[kind.name]["properties"];
        std::string_view type = properties["type"]["enum"].at(0);
        EXPECT_EQ(type, kind.name);
        for (const ParamInfo& p : kind.params) {
            simdjson::dom::element e;
            EXPECT_FALSE(properties[p.name].get(e)) << kind.name << "." << p.name;
        }
        for (const CommonKey& c : commonNodeKeys()) {
            simdjson::dom::element e;
            EXPECT_EQ(properties[c.name].get(e) == simdjson::SUCCESS,
                      c.name != "children" || kind.operation)
                << kind.name << "." << c.name;
        }
    }
}

TEST(LlmSanity, BundledScenesPass) {
    for (const auto& entry :
         fs::directory_iterator(fs::path(SDFCSG_SOURCE_DIR) / "assets/scenes")) {
        if (entry.path().extension() != ".json") continue; // the images they name
        auto scene = loadScene(entry.path());
        ASSERT_TRUE(scene) << scene.error().str();
        std::vector<std::string> found;
        for (const Diagnostic& d : sceneSanityWarnings(*scene))
            found.push_back(d.path + ": " + d.message);
        // Its showcases hover above their stage: rightly called apart.
        std::vector<std::string> expected;
        if (entry.path().filename() == "smooth_blend.json")
            for (int i = 1; i <= 3; ++i)
                expected.push_back("root.children[" + std::to_string(i) +
                                   "]: floats apart: it touches no part of the main group");
        EXPECT_EQ(found, expected) << entry.path();
    }
}

TEST(LlmSanity, EmptySolid) {
    EXPECT_EQ(warnings(R"({"version": 1, "root": {"type": "intersection", "children": [
        {"type": "sphere", "radius": 1}, {"type": "sphere", "radius": 1, "translate": [5, 0, 0]}]}})"),
              std::vector<std::string>{"root: the solid is empty: no point lies inside it"});
}

TEST(LlmSanity, DifferenceThatRemovesNothing) {
    EXPECT_EQ(warnings(R"({"version": 1, "root": {"type": "difference", "children": [
        {"type": "box", "name": "block", "size": [1, 1, 1]},
        {"type": "sphere", "radius": 0.3, "translate": [0.6, 0, 0]},
        {"type": "sphere", "radius": 0.3, "translate": [3, 0, 0]}]}})"),
              std::vector<std::string>{"root.children[2]: removes nothing: it does not reach "
                                       "root.children[0] (\"block\"), the part it is subtracted "
                                       "from"});
}

// A name is the model's text: quoted and escaped as the validator quotes strings.
TEST(LlmSanity, NamesAreQuotedAndEscaped) {
    EXPECT_EQ(warnings(R"({"version": 1, "root": {"type": "difference", "children": [
        {"type": "box", "name": "block\u001b[2J\nroot: fine \"", "size": [1, 1, 1]},
        {"type": "sphere", "radius": 0.3, "translate": [3, 0, 0]}]}})"),
              std::vector<std::string>{"root.children[1]: removes nothing: it does not reach "
                                       "root.children[0] (\"block\\u001b[2J\\nroot: fine \\\"\"), "
                                       "the part it is subtracted from"});
}

TEST(LlmSanity, PartsFloatingApart) {
    EXPECT_EQ(
        warnings(R"({"version": 1, "root": {"type": "union", "children": [{"type": "union",
        "children": [{"type": "box", "size": [2, 1, 1]}, {"type": "sphere", "radius": 0.5,
        "translate": [0, 0.9, 0]}, {"type": "sphere", "name": "moon", "radius": 0.2,
        "translate": [0, 3, 0]}]}]}})"),
        std::vector<std::string>{
            "root.children[0].children[2]: floats apart: it touches no part of the main group"});
}

TEST(LlmSanity, AbsurdBounds) {
    EXPECT_EQ(warnings(R"({"version": 1, "root": {"type": "sphere", "radius": 5000}})"),
              std::vector<std::string>{
                  "root: absurd bounds: the scene is 10000 units across (expected 0.001 to 1000)"});
    EXPECT_EQ(warnings(R"({"version": 1, "root": {"type": "sphere", "radius": 1,
        "translate": [0, 0, 4000]}})"),
              std::vector<std::string>{"root: absurd bounds: the scene lies 4000 units from the "
                                       "origin"});
}

// Bounds at the edge of single precision and beyond it: the size or the distance that the scene
// really has, never an empty solid or silence.
TEST(LlmSanity, AbsurdBoundsBeyondSinglePrecision) {
    EXPECT_EQ(warnings(R"({"version": 1, "root": {"type": "sphere", "radius": 3e38}})"),
              std::vector<std::string>{
                  "root: absurd bounds: the scene is 6e+38 units across (expected 0.001 to 1000)"});
    EXPECT_EQ(warnings(R"({"version": 1, "root": {"type": "sphere", "radius": 1,
        "translate": [3e38, 0, 0]}})"),
              std::vector<std::string>{
                  "root: absurd bounds: the scene lies 3e+38 units from the origin"});
    EXPECT_EQ(warnings(R"({"version": 1, "root": {"type": "sphere", "radius": 1e30,
        "scale": 1e30}})"),
              std::vector<std::string>{
                  "root: absurd bounds: the scene is 2e+60 units across (expected 0.001 to 1000)"});
    // With a plane, whose bounds are infinite anyway.
    EXPECT_EQ(warnings(R"({"version": 1, "root": {"type": "union", "children": [
        {"type": "plane", "normal": [0, 1, 0]},
        {"type": "sphere", "radius": 1e30, "scale": 1e30, "translate": [0, 1e-29, 0]}]}})"),
              std::vector<std::string>{
                  "root: absurd bounds: the scene is 2e+60 units across (expected 0.001 to 1000)"});
}
