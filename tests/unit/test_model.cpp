// The modelling API (sdfcsg/model.h): every kind built by its function is the scene its table
// example loads as (the same JSON out, the same field on the CPU); the operators are the
// explicit operations; transforms chain in order; parts are definitions; errors are the loader's
// own, at the call's source line; scenes convert to shapes and back; values are edited in place.
#include "scene_build_util.h"

#include <sdfcsg/eval.h>
#include <sdfcsg/model.h>
#include <sdfcsg/render.h>

#include "scene/parse_util.h"

#include <gtest/gtest.h>

#include <simdjson.h>

#include <string>
#include <tuple>
#include <vector>

namespace sdfcsg::test {
namespace {

namespace m = sdfcsg::model;

std::string sceneJson(const std::string& root) {
    return R"({"version": 1, "root": )" + root + "}";
}

Scene load(const std::string& json) {
    auto scene = parseScene(json, "<json>");
    if (!scene) ADD_FAILURE() << scene.error().str() << "\n" << json;
    return scene ? *scene : Scene{};
}

Scene build(const m::Shape& shape) {
    auto scene = m::toScene(shape);
    if (!scene) ADD_FAILURE() << scene.error().str();
    return scene ? *scene : Scene{};
}

// The members of a JSON object's text as arguments: {"radius": 0.8} -> {{"radius", 0.8}}.
std::vector<m::Arg> argsOf(const std::string& members) {
    simdjson::dom::parser parser;
    const std::string object = "{" + members + "}";
    simdjson::dom::object parsed = parser.parse(object).get_object().value();
    std::vector<m::Arg> args;
    for (auto [key, value] : parsed)
        args.push_back({std::string(key), m::Value::json(detail::jsonText(value))});
    return args;
}

// Two scenes are one: the same JSON, and the same field and colour at points around them.
void expectSameScene(const Scene& a, const Scene& b) {
    ASSERT_FALSE(a.nodes.empty());
    ASSERT_FALSE(b.nodes.empty());
    EXPECT_EQ(toJson(a), toJson(b));
    Evaluator ea(a), eb(b);
    for (glm::vec3 p : randomPoints(7, 200, 1.5f)) {
        const Sample sa = ea.sample(p), sb = eb.sample(p);
        EXPECT_EQ(sa.distance, sb.distance) << p.x << " " << p.y << " " << p.z;
        EXPECT_EQ(sa.color, sb.color);
    }
}

// The operands that exampleNodeJson() gives each operation, as shapes.
std::vector<m::Shape> exampleChildren(const KindInfo& kind) {
    if (!kind.operation) return {};
    if (kind.kind == NodeKind::Extrude || kind.kind == NodeKind::Revolve) return {m::circle(0.5)};
    if (isTransition(kind.kind)) return {m::sphere(0.5), m::box({0.8, 0.8, 0.8})};
    return {m::sphere(0.5)};
}

// A profile loads inside an extrusion only.
std::string rootOf(const KindInfo& kind, const std::string& node) {
    return isProfile(kind.kind)
               ? R"({"type": "extrude", "height": 0.5, "children": [)" + node + "]}"
               : node;
}
m::Shape rootOf(const KindInfo& kind, const m::Shape& shape) {
    return isProfile(kind.kind) ? m::extrude(shape, 0.5) : shape;
}

TEST(Model, EveryKindByItsFunctionIsItsTableExample) {
    for (const KindInfo& kind : nodeKinds()) {
        SCOPED_TRACE(kind.name);
        const Scene expected = load(sceneJson(rootOf(kind, exampleNodeJson(kind))));
        const std::vector<m::Arg> args = argsOf(std::string(kind.example));
        expectSameScene(build(rootOf(kind, m::byFunction(kind.name, args, exampleChildren(kind)))),
                        expected);
        expectSameScene(build(rootOf(kind, m::shape(kind.name, args, exampleChildren(kind)))),
                        expected);
    }
}

TEST(Model, TypedFunctionsTakeTheTablesValues) {
    const Scene expected = load(sceneJson(R"({"type": "union", "children": [
        {"type": "round_box", "size": [1, 0.5, 2], "radius": 0.1, "color": "#ff8000"},
        {"type": "cone", "radius": 0.5, "height": 1, "top_radius": 0.2, "translate": [0, 1, 0]},
        {"type": "shell", "thickness": 0.05, "children": [{"type": "sphere", "radius": 0.6}]},
        {"type": "mirror", "axes": "xz", "smooth": 0.1, "children": [
            {"type": "twist", "angle": 30, "children": [
                {"type": "box", "size": [0.2, 1, 0.2], "translate": [0.5, 0, 0]}]}]},
        {"type": "extrude", "height": 0.2, "children": [
            {"type": "polygon", "points": [[0, 0], [1, 0], [0, 1]]}]}]})"));
    const m::Shape built =
        m::roundBox({1, 0.5, 2}, 0.1).color("#ff8000") | m::cone(0.5, 1, 0.2).translate({0, 1, 0}) |
        m::sphere(0.6).shell(0.05) |
        m::box({0.2, 1, 0.2}).translate({0.5, 0, 0}).twist(30).mirror("xz", 0.1) |
        m::polygon(std::vector<glm::vec2>{{0, 0}, {1, 0}, {0, 1}}).extrude(0.2);
    expectSameScene(build(built), expected);
}

TEST(Model, OperatorsAreTheExplicitOperations) {
    const m::Shape a = m::sphere(0.5), b = m::box({0.6, 0.6, 0.6}).translate({0.3, 0, 0}),
                   c = m::cylinder(0.2, 2);
    expectSameScene(build(a | b | c), build(m::union_({a, b, c})));
    expectSameScene(build(a & b & c), build(m::intersection({a, b, c})));
    expectSameScene(build(a - b - c), build(m::difference({a, b, c})));
    // Only plain operations take in their operands' children: a blended union stays a node, and
    // the right side of a difference stays whole.
    const m::Shape blended = m::union_({a, b}, 0.1);
    expectSameScene(build(blended | c), build(m::union_({blended, c})));
    expectSameScene(build(a - (b | c)), build(m::difference({a, m::union_({b, c})})));
    expectSameScene(build(m::Shape() | a), build(a));
}

TEST(Model, TransformsApplyInTheOrderCalled) {
    const m::Shape box = m::box({0.2, 0.2, 0.2});
    // Moved along x, then turned a quarter about z: the box ends on +y.
    const Scene turned = build(box.translate({1, 0, 0}).rotate({0, 0, 90}));
    Evaluator eval(turned);
    EXPECT_LT(eval.distance({0, 1, 0}), 0.0f);
    EXPECT_GT(eval.distance({1, 0, 0}), 0.5f);
    // Turned, then scaled by a factor per axis, then moved: the box is 0.2 by 0.6 at (0, 0, 2).
    Evaluator stretched(build(box.rotate({0, 0, 45}).scale({1, 3, 1}).translate({0, 0, 2})));
    EXPECT_LT(stretched.distance({0, 0.25f, 2}), 0.0f);
    EXPECT_GT(stretched.distance({0.25f, 0, 2}), 0.0f);
    // Where the node's own transform holds the chain, there is no wrapper.
    EXPECT_EQ(build(box.scale(2).rotate({0, 30, 0}).translate({1, 2, 3})).nodes.size(), 1u);
    expectSameScene(build(box.scale(2).rotate({0, 30, 0}).translate({1, 2, 3})),
                    load(sceneJson(R"({"type": "box", "size": [0.2, 0.2, 0.2], "scale": 2,
                                       "rotate": [0, 30, 0], "translate": [1, 2, 3]})")));
}

TEST(Model, PartsAreDefinitionsAndUses) {
    const m::Part leg("leg", m::cylinder("$radius", "$height"), {{"height", 1.0}, {"radius", 0.1}});
    const m::Shape table = m::box({1, 0.1, 1}).name("top").translate({0, 0.5, 0}) |
                           leg({{"height", 0.5}}).translate({0.4, 0.2, 0.4}) |
                           leg().name("back").translate({-0.4, 0.2, -0.4});
    const Scene expected = load(R"({"version": 1, "definitions": {
        "leg": {"parameters": {"height": 1.0, "radius": 0.1},
                "node": {"type": "cylinder", "radius": "$radius", "height": "$height"}}},
        "root": {"type": "union", "children": [
            {"type": "box", "name": "top", "size": [1, 0.1, 1], "translate": [0, 0.5, 0]},
            {"type": "use", "definition": "leg", "parameters": {"height": 0.5},
             "translate": [0.4, 0.2, 0.4]},
            {"type": "use", "definition": "leg", "name": "back",
             "translate": [-0.4, 0.2, -0.4]}]}})");
    expectSameScene(build(table), expected);
    // Two different parts of one name are refused.
    const m::Part other("leg", m::sphere(1));
    auto clash = m::toScene(leg() | other());
    ASSERT_FALSE(clash);
    EXPECT_EQ(clash.error().str(), "<model>: two different parts are named \"leg\"");
}

TEST(Model, ErrorsAreTheLoadersAtTheCallsLine) {
    const int line = __LINE__ + 1;
    const m::Shape bad = m::sphere(1) | m::box({1, -2, 1}).translate({1, 0, 0});
    auto scene = m::toScene(bad);
    ASSERT_FALSE(scene);
    auto loaded = parseScene(sceneJson(R"({"type": "union", "children": [
        {"type": "sphere", "radius": 1},
        {"type": "box", "size": [1, -2, 1], "translate": [1, 0, 0]}]})"),
                             "<json>");
    ASSERT_FALSE(loaded);
    ASSERT_EQ(scene.error().diagnostics.size(), loaded.error().diagnostics.size());
    const Diagnostic& got = scene.error().diagnostics[0];
    const Diagnostic& want = loaded.error().diagnostics[0];
    EXPECT_EQ(got.path, "root.children[1].size[1]");
    EXPECT_EQ(got.path, want.path);
    EXPECT_EQ(got.message, want.message);
    EXPECT_EQ(got.file, std::string(__FILE__) + ":" + std::to_string(line));
    EXPECT_EQ(scene.error().kind, loaded.error().kind);
    // A kind that does not exist, by the generic function: the loader's message too.
    auto unknown = m::toScene(m::shape("sphre", {{"radius", 1}}));
    ASSERT_FALSE(unknown);
    auto unknownLoaded = parseScene(sceneJson(R"({"type": "sphre", "radius": 1})"), "<json>");
    ASSERT_FALSE(unknownLoaded);
    EXPECT_EQ(unknown.error().diagnostics[0].message, unknownLoaded.error().diagnostics[0].message);
}

TEST(Model, BundledScenesConvertToShapesAndBack) {
    for (const auto& path : bundledScenePaths()) {
        SCOPED_TRACE(path.string());
        auto scene = loadScene(path);
        ASSERT_TRUE(scene) << scene.error().str();
        const m::Shape shape = m::fromScene(*scene);
        auto json = m::toJson(shape);
        ASSERT_TRUE(json) << json.error().str();
        Scene again = *scene;
        again.camera.reset(), again.lights.clear(), again.background = Scene{}.background;
        again.name.clear(), again.description.clear();
        EXPECT_EQ(*json, toJson(again));
        auto back = m::fromJson(*json);
        ASSERT_TRUE(back) << back.error().str();
        EXPECT_EQ(*m::toJson(*back), *json);
    }
}

// Settings of the top level go through the loader, and definitions keep the scene's order, even
// where one uses a part defined after it.
TEST(Model, SettingsAndDefinitionsInTheScenesOrder) {
    const Scene scene = load(R"({"version": 1, "name": "set",
        "camera": {"eye": [3, 2, 4], "target": [0, 0.5, 0]}, "background": "#102030",
        "definitions": {
          "chair": {"node": {"type": "use", "definition": "leg", "translate": [0.3, 0, 0]}},
          "leg": {"node": {"type": "cylinder", "radius": 0.1, "height": 1}}},
        "root": {"type": "use", "definition": "chair"}})");
    auto built =
        m::toScene(m::fromScene(scene),
                   {{"name", "set"},
                    {"camera", m::Value::json(R"({"eye": [3, 2, 4], "target": [0, 0.5, 0]})")},
                    {"background", "#102030"}});
    ASSERT_TRUE(built) << built.error().str();
    EXPECT_EQ(toJson(*built), toJson(scene));
    auto bad = m::toScene(m::sphere(1), {{"camera", m::Value::json(R"({"eye": [0, 0, 0]})")}});
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().diagnostics[0].path.substr(0, 6), "camera");
    auto root = m::toScene(m::sphere(1), {{"root", m::Value::json("{}")}});
    ASSERT_FALSE(root);
    EXPECT_EQ(root.error().str(), "<model>: the scene's root comes from its shape");
}

TEST(Model, PythonNamesAreTheKindsUnlessTaken) {
    EXPECT_EQ(m::pythonName(kindInfo(NodeKind::Sphere)), "sphere");
    EXPECT_EQ(m::pythonName(kindInfo(NodeKind::Mesh)), "mesh_");
    EXPECT_EQ(m::pythonName(kindInfo(NodeKind::Shell)), "shell");
}

TEST(Model, ADeepChainIsWrittenAndReleasedWithoutRecursion) {
    m::Shape s = m::sphere(1);
    for (int i = 0; i < 100000; ++i)
        s = s.offset(0.001);
    auto scene = m::toScene(s); // refused by the loader's depth limit, not by the stack
    ASSERT_FALSE(scene);
    EXPECT_EQ(scene.error().kind, ErrorKind::Limit);
}

TEST(Model, EditsGoThroughTheLoadersChecks) {
    Scene scene = build(m::sphere(0.5).name("ball") |
                        m::box({1, 1, 1}).translate({2, 0, 0}).shell(0.1).name("cup"));
    scene.file = "scene.json";
    const Scene before = scene;
    auto ball = m::findNode(scene, "ball");
    ASSERT_TRUE(ball) << ball.error().str();
    EXPECT_EQ(*ball, 1u);
    EXPECT_EQ(*m::findNode(scene, "root.children[1].children[0]"), 3u);
    EXPECT_EQ(m::findNode(scene, "nothing").error().str(),
              "scene.json: no node is named \"nothing\" or has that path");

    ASSERT_TRUE(m::setValue(scene, *ball, "radius", 0.7));
    ASSERT_TRUE(m::setValue(scene, *ball, "translate", {0, 1, 0}));
    ASSERT_TRUE(m::setValue(scene, 2, "thickness", 0.2));
    ASSERT_TRUE(m::setValue(scene, 2, "color", "#00ff00"));
    EXPECT_TRUE(sameStructure(scene, before));
    expectSameScene(
        scene,
        build(m::sphere(0.7).name("ball").translate({0, 1, 0}) |
              m::box({1, 1, 1}).translate({2, 0, 0}).shell(0.2).name("cup").color("#00ff00")));

    // A bad value: the loader's message at the node's path, and the scene as it was.
    const Scene edited = scene;
    auto bad = m::setValue(scene, 3, "size", {1, 0, 1});
    ASSERT_FALSE(bad);
    auto loaded = parseScene(sceneJson(R"({"type": "box", "size": [1, 0, 1]})"), "scene.json");
    ASSERT_FALSE(loaded);
    EXPECT_EQ(bad.error().str(), "scene.json: root.children[1].children[0].size[1]: " +
                                     loaded.error().diagnostics[0].message);
    EXPECT_EQ(toJson(scene), toJson(edited));
    EXPECT_FALSE(m::setValue(scene, 1, "radius", m::Value()));
}

// An exact offset over a twist reads the twist's distance baked at load (field/bake.h): an edit of
// the twist, or of the offset, bakes it again, to the field the edited scene's file loads with; the
// words are never written to JSON.
TEST(Model, EditsBakeOffsetsAgain) {
    const auto offset = [](float distance, float angle) {
        return R"({"type": "offset", "distance": )" + std::to_string(distance) +
               R"(, "accuracy": "exact", "children": [{"type": "twist", "angle": )" +
               std::to_string(angle) + R"(, "children": [{"type": "box", "size": [1, 2, 1]}]}]})";
    };
    Scene scene = parseRoot(offset(0.3f, 90.0f));
    ASSERT_NE(scene.nodes[0].words, nullptr);
    EXPECT_EQ(toJson(scene).find("words"), std::string::npos);
    for (const auto& [node, key, value, distance, angle] :
         {std::tuple{1u, "angle", 45.0f, 0.3f, 45.0f}, {0u, "distance", 0.2f, 0.2f, 45.0f}}) {
        SCOPED_TRACE(key);
        ASSERT_TRUE(m::setValue(scene, node, key, value));
        const Scene loaded = parseRoot(offset(distance, angle));
        ASSERT_NE(scene.nodes[0].words, nullptr);
        ASSERT_NE(loaded.nodes[0].words, nullptr);
        EXPECT_TRUE(*scene.nodes[0].words == *loaded.nodes[0].words);
        const Evaluator edited(scene), fresh(loaded);
        for (const glm::vec3& p : randomPoints(3, 200, 1.5f))
            EXPECT_EQ(edited.distance(p), fresh.distance(p));
    }
}

} // namespace
} // namespace sdfcsg::test
