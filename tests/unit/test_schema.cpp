// The JSON Schema: generated from the node kind table, checked in as assets/scene.schema.json,
// and in agreement with the parser (what the schema requires and bounds, the parser requires
// and bounds too).
#include <sdfcsg/scene.h>

#include <gtest/gtest.h>

#include <simdjson.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using namespace sdfcsg;

namespace {

const fs::path kSchemaFile = fs::path(SDFCSG_SOURCE_DIR) / "assets/scene.schema.json";

std::string readFile(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// The generated schema, parsed (simdjson keeps the parser alive for the element's lifetime).
simdjson::dom::element schema() {
    static simdjson::dom::parser parser;
    static const std::string text = sceneJsonSchema();
    static const simdjson::dom::element root = parser.parse(text);
    return root;
}

std::string numberText(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

// A valid value for a parameter as the schema describes it; numbers at most half the vectors'
// components also keep the one rule a schema cannot state (a round box's radius at most half
// its smallest size).
// `key`: a "file" names the bundled emblem, or for a mesh the gear, which the tests' folder holds
// (tests/CMakeLists.txt).
std::string validValue(simdjson::dom::element property, std::string_view key = {}) {
    if (key == "file")
        return std::string_view(property["description"]).find("mesh") != std::string_view::npos
                   ? "\"gear.stl\""
                   : "\"emblem.png\"";
    if (simdjson::dom::array choices; property["enum"].get(choices) == simdjson::SUCCESS)
        return simdjson::to_string(choices.at(0));
    std::string_view type = property["type"];
    if (type == "number") return "0.5";
    if (type == "integer") return "4";
    if (type == "string") return "\"Ab\"";
    if (std::string_view(property["items"]["type"]) == "array") return "[[0, 0], [1, 0], [0, 1]]";
    return std::string_view(property["items"]["type"]) == "integer" ? "[2, 2, 2]" : "[1, 1, 1]";
}

std::string node(const KindInfo& kind, const std::string& extra) {
    std::string out = R"({"type": ")" + std::string(kind.name) + "\"";
    out += extra;
    if (kind.operation)
        out +=
            isTransition(kind.kind) // two, as the schema says
                ? R"(, "children": [{"type": "sphere", "radius": 1}, {"type": "sphere", "radius": 2}])"
                : R"(, "children": [{"type": "sphere", "radius": 1}])";
    // A 2D profile goes inside an extrude, which the schema cannot require.
    if (isProfile(kind.kind))
        out = R"({"type": "extrude", "height": 1, "children": [)" + out + "}]";
    return R"({"version": 1, "root": )" + out + "}}";
}

} // namespace

TEST(Schema, CheckedInFileIsUpToDate) {
    const std::string generated = sceneJsonSchema();
    if (std::getenv("SDFCSG_UPDATE_SCHEMA"))
        std::ofstream(kSchemaFile, std::ios::binary) << generated;
    if (readFile(kSchemaFile) == generated) return;
    const fs::path actual = fs::path(SDFCSG_TEST_OUTPUT_DIR) / "scene.schema.json";
    fs::create_directories(actual.parent_path());
    std::ofstream(actual, std::ios::binary) << generated;
    FAIL() << kSchemaFile
           << " is out of date with the node kind table (engine/src/scene/nodes.cpp).\n"
           << "Regenerate it with:  sdfcsg schema -o assets/scene.schema.json\n"
           << "or run this test with SDFCSG_UPDATE_SCHEMA=1 set "
           << "(SDFCSG_UPDATE_SCHEMA=1 ctest -R Schema.CheckedInFileIsUpToDate).\n"
           << "The generated schema was written to " << actual;
}

TEST(Schema, IsValidJsonOfDraft2020_12) {
    simdjson::dom::parser parser;
    simdjson::dom::element root;
    const std::string text = readFile(kSchemaFile);
    ASSERT_EQ(parser.parse(text).get(root), simdjson::SUCCESS) << kSchemaFile << " is not JSON";
    EXPECT_EQ(std::string_view(root["$schema"]), "https://json-schema.org/draft/2020-12/schema");
    EXPECT_EQ(std::string_view(schema()["$schema"]),
              "https://json-schema.org/draft/2020-12/schema");
}

TEST(Schema, TopLevel) {
    auto s = schema();
    EXPECT_EQ(simdjson::to_string(s["required"]), R"(["version","root"])");
    EXPECT_FALSE(bool(s["additionalProperties"]));
    EXPECT_EQ(int64_t(s["properties"]["version"]["const"]), kSceneVersion);
    for (const char* key :
         {"name", "description", "camera", "lights", "background", "definitions", "root"})
        EXPECT_EQ(s["properties"][key].error(), simdjson::SUCCESS) << key;
}

TEST(Schema, EveryKindAndParameterOfTheTableAppears) {
    auto defs = schema()["$defs"];
    std::vector<std::string> refs;
    for (auto r : defs["node"]["oneOf"].get_array())
        refs.emplace_back(std::string_view(r["$ref"]));
    ASSERT_EQ(refs.size(), nodeKinds().size() + 1);
    EXPECT_EQ(refs.back(), "#/$defs/use");
    for (const KindInfo& kind : nodeKinds()) {
        SCOPED_TRACE(std::string(kind.name));
        EXPECT_NE(std::find(refs.begin(), refs.end(), "#/$defs/" + std::string(kind.name)),
                  refs.end());
        auto def = defs[kind.name];
        ASSERT_EQ(def.error(), simdjson::SUCCESS);
        EXPECT_EQ(std::string_view(def["description"]), kind.doc);
        EXPECT_FALSE(bool(def["additionalProperties"]));
        auto props = def["properties"];
        EXPECT_EQ(std::string_view(props["type"]["const"]), kind.name);
        std::vector<std::string> required;
        for (auto r : def["required"].get_array())
            required.emplace_back(std::string_view(r));
        size_t expectedProps = 0;
        for (const CommonKey& c : commonNodeKeys()) {
            const bool allowed = c.name != "children" || kind.operation;
            EXPECT_EQ(props[c.name].error() == simdjson::SUCCESS, allowed) << c.name;
            expectedProps += allowed;
        }
        EXPECT_EQ(std::find(required.begin(), required.end(), "children") != required.end(),
                  kind.operation);
        for (const ParamInfo& p : kind.params) {
            SCOPED_TRACE(std::string(p.name));
            ++expectedProps;
            auto prop = props[p.name];
            ASSERT_EQ(prop.error(), simdjson::SUCCESS);
            std::string_view doc = prop["description"];
            EXPECT_TRUE(doc.starts_with(p.doc)) << doc;
            EXPECT_NE(doc.find(p.unit), std::string_view::npos) << "the unit is documented";
            if (p.type == ValueType::Choice) {
                std::vector<std::string> names;
                for (auto c : prop["enum"].get_array())
                    names.emplace_back(std::string_view(c));
                EXPECT_EQ(names, std::vector<std::string>(p.choices.begin(), p.choices.end()));
                EXPECT_EQ(std::string_view(prop["default"]), p.choices[size_t(p.fallback[0])]);
                continue;
            }
            if (p.type == ValueType::Text) {
                EXPECT_EQ(std::string_view(prop["type"]), "string");
                EXPECT_EQ(std::find(required.begin(), required.end(), p.name) != required.end(),
                          p.required);
                continue;
            }
            if (p.type == ValueType::Points) {
                EXPECT_EQ(std::string_view(prop["type"]), "array");
                EXPECT_EQ(int64_t(prop["minItems"]), 3);
                EXPECT_EQ(int64_t(prop["maxItems"]), int64_t(kMaxPolygonPoints));
                EXPECT_EQ(int64_t(prop["items"]["minItems"]), 2);
                EXPECT_EQ(int64_t(prop["items"]["maxItems"]), 2);
                continue;
            }
            const bool count = p.check == Check::Count;
            EXPECT_EQ(std::string_view(prop["type"]),
                      p.type == ValueType::Number ? (count ? "integer" : "number") : "array");
            auto bounds = p.type == ValueType::Number ? prop : prop["items"];
            if (count) {
                EXPECT_EQ(std::string_view(bounds["type"]), "integer");
                EXPECT_EQ(double(bounds["minimum"]), p.least);
                EXPECT_EQ(double(bounds["maximum"]), std::min(double(p.maximum), 1e6));
            }
            EXPECT_EQ(bounds["exclusiveMinimum"].error() == simdjson::SUCCESS,
                      p.check == Check::Positive);
            EXPECT_EQ(bounds["minimum"].error() == simdjson::SUCCESS,
                      p.check == Check::NonNegative || count);
            EXPECT_EQ(prop["not"].error() == simdjson::SUCCESS, p.check == Check::NonZero);
            EXPECT_EQ(std::find(required.begin(), required.end(), p.name) != required.end(),
                      p.required);
            EXPECT_EQ(prop["default"].error() == simdjson::SUCCESS, !p.required);
            if (!p.required && p.type == ValueType::Number) {
                EXPECT_EQ(double(prop["default"]), p.fallback[0]);
            }
            EXPECT_EQ(bounds["maximum"].error() == simdjson::SUCCESS, p.maximum < 3.4e38f || count);
        }
        EXPECT_EQ(def["properties"].get_object().size(), expectedProps) << "nothing else";
    }
}

TEST(Schema, AgreesWithTheParser) {
    auto defs = schema()["$defs"];
    for (const KindInfo& kind : nodeKinds()) {
        SCOPED_TRACE(std::string(kind.name));
        auto def = defs[kind.name];
        // Exactly the schema's required keys, with values inside its bounds: accepted.
        std::string requiredOnly;
        for (auto r : def["required"].get_array()) {
            std::string_view key = r;
            if (key == "type" || key == "children") continue;
            requiredOnly +=
                R"(, ")" + std::string(key) + "\": " + validValue(def["properties"][key], key);
        }
        auto ok = parseScene(node(kind, requiredOnly));
        EXPECT_TRUE(ok) << (ok ? "" : ok.error().str());
        // Each required key left out: refused.
        for (const ParamInfo& p : kind.params) {
            if (!p.required) continue;
            std::string without;
            for (const ParamInfo& q : kind.params)
                if (q.required && q.name != p.name)
                    without += R"(, ")" + std::string(q.name) +
                               "\": " + validValue(def["properties"][q.name], q.name);
            EXPECT_FALSE(parseScene(node(kind, without))) << "without " << p.name;
        }
        // A number at the schema's bound: refused when the bound is exclusive, accepted when not.
        for (const ParamInfo& p : kind.params) {
            if (p.type != ValueType::Number) continue;
            auto prop = def["properties"][p.name];
            double bound = 0;
            const bool exclusive = prop["exclusiveMinimum"].get(bound) == simdjson::SUCCESS;
            const bool inclusive = prop["minimum"].get(bound) == simdjson::SUCCESS;
            if (!exclusive && !inclusive) continue;
            std::string others;
            for (const ParamInfo& q : kind.params)
                if (q.required && q.name != p.name)
                    others += R"(, ")" + std::string(q.name) +
                              "\": " + validValue(def["properties"][q.name], q.name);
            const std::string at =
                others + R"(, ")" + std::string(p.name) + "\": " + numberText(bound);
            const std::string below =
                others + R"(, ")" + std::string(p.name) + "\": " + numberText(bound - 1);
            EXPECT_EQ(bool(parseScene(node(kind, at))), inclusive) << p.name << " = " << bound;
            EXPECT_FALSE(parseScene(node(kind, below))) << p.name << " = " << bound - 1;
        }
    }
}
