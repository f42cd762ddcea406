// The generated GLSL against the CPU reference evaluator: shaders/probe.comp evaluates
// sceneSample at thousands of points, for every primitive kind, the operations, and every bundled
// scene, with bounds skipping on and off, and with the bounds tests left out of the code.
#include "gpu_probe.h"
#include "gpu_test.h" // tests/gtest_suites.cmake labels the program's fixtures gpu by this line

#include <map>

namespace sdfcsg::test {
namespace {

namespace fs = std::filesystem;

Scene parseOrDie(const std::string& json) {
    auto scene = parseScene(json, "<test>");
    if (!scene) {
        ADD_FAILURE() << scene.error().str() << "\n" << json;
        return Scene{};
    }
    return *scene;
}

class GpuEval : public GpuTest {};

// The kinds of a role, each with its table example's members (KindInfo::example): a new kind is
// tested here as soon as it has its table entry.
std::vector<std::pair<std::string, std::string>> examples(bool (*wanted)(const KindInfo&)) {
    std::vector<std::pair<std::string, std::string>> out;
    for (const KindInfo& kind : nodeKinds())
        if (wanted(kind)) out.emplace_back(std::string(kind.name), std::string(kind.example));
    return out;
}
bool isPrimitive(const KindInfo& k) {
    return k.role == Role::Primitive && !isProfile(k.kind);
}
bool isProfileKind(const KindInfo& k) {
    return isProfile(k.kind);
}
bool isValueOrDomain(const KindInfo& k) {
    return k.role == Role::Value || k.role == Role::Domain;
}

// Each profile extruded (with rounded edges) and revolved, transformed in the plane, beside a
// sphere in a smooth union; their outlines travel after the nodes in the node buffer.
TEST_F(GpuEval, EveryProfileMatchesTheCpu) {
    for (const auto& [type, params] : examples(isProfileKind)) {
        SCOPED_TRACE(type);
        const std::string profile = R"({"type": ")" + type + R"(", )" + params +
                                    R"(, "rotate": [0, 0, 20], "translate": [0.05, 0.1, 0]})";
        Scene scene = parseOrDie(R"({"version": 1, "root": {"type": "union", "smooth": 0.2,
            "children": [
            {"type": "extrude", "height": 0.5, "rounding": 0.05, "rotate": [30, 20, 0],
             "color": [0.9, 0.3, 0.1], "children": [)" +
                                 profile + R"(]},
            {"type": "revolve", "offset": 0.2, "translate": [0, -1.2, 0], "children": [)" +
                                 profile + R"(]},
            {"type": "sphere", "radius": 0.4, "translate": [1.1, 0.6, 0.2], "color": [0.1, 0.4, 0.9]}
            ]}})");
        ASSERT_FALSE(scene.nodes.empty());
        expectGpuMatchesCpu(context(), scene, 4096);
    }
}

TEST_F(GpuEval, EveryPrimitiveMatchesTheCpu) {
    for (const auto& [type, params] : examples(isPrimitive)) {
        SCOPED_TRACE(type);
        // Transformed, inside a transformed smooth union with a sphere of another colour, so
        // transforms, scale and colour blending are all exercised.
        std::string json = R"({"version": 1, "root": {"type": "union", "smooth": 0.3,
            "rotate": [10, -20, 5], "scale": 1.2, "translate": [0.1, 0.2, -0.3], "children": [
            {"type": ")" + type +
                           R"(", )" + params +
                           R"(, "rotate": [20, 35, 10], "scale": 1.3, "translate": [0.2, -0.1, 0.3],
             "color": [0.9, 0.3, 0.1]},
            {"type": "sphere", "radius": 0.4, "translate": [1.1, 0.6, 0.2], "color": [0.1, 0.4, 0.9]}
            ]}})";
        Scene scene = parseOrDie(json);
        ASSERT_FALSE(scene.nodes.empty());
        expectGpuMatchesCpu(context(), scene);
        // And alone at the root, untransformed.
        Scene bare =
            parseOrDie(R"({"version": 1, "root": {"type": ")" + type + R"(", )" + params + R"(}})");
        ASSERT_FALSE(bare.nodes.empty());
        expectGpuMatchesCpu(context(), bare, 1024);
    }
}

TEST_F(GpuEval, OperationsMatchTheCpu) {
    Scene scene = parseOrDie(R"({"version": 1, "root": {"type": "union", "children": [
        {"type": "difference", "smooth": 0.1, "color": [0.8, 0.8, 0.2], "children": [
            {"type": "intersection", "smooth": 0.15, "children": [
                {"type": "box", "size": [1.5, 1.5, 1.5], "color": [1, 0, 0]},
                {"type": "sphere", "radius": 1.0, "color": [0, 1, 0]}]},
            {"type": "cylinder", "radius": 0.4, "height": 3, "color": [0, 0, 1]},
            {"type": "cylinder", "radius": 0.4, "height": 3, "rotate": [90, 0, 0]},
            {"type": "cylinder", "radius": 0.4, "height": 3, "rotate": [0, 0, 90]}]},
        {"type": "union", "smooth": 0.4, "translate": [2.5, 0, 0], "scale": 0.7, "children": [
            {"type": "sphere", "radius": 0.6, "color": [0.2, 0.9, 0.4]},
            {"type": "torus", "major_radius": 0.8, "minor_radius": 0.2, "color": [0.9, 0.2, 0.4]},
            {"type": "capsule", "a": [0, -1, 0], "b": [0, 1, 0], "radius": 0.2}]},
        {"type": "intersection", "translate": [-2.5, 0, 0], "children": [
            {"type": "plane", "normal": [0, 1, 0], "offset": 0.2},
            {"type": "round_box", "size": [1, 1, 1], "radius": 0.1, "color": [0.5, 0.5, 0.9]}]}
        ]}})");
    ASSERT_FALSE(scene.nodes.empty());
    expectGpuMatchesCpu(context(), scene, 4096);
}

// Node `op` (JSON) in a smooth union beside a sphere, and nested in a repeat: GPU against CPU.
void expectInUnionAndRepeatMatchesCpu(Context& context, const std::string& op) {
    Scene scene = parseOrDie(R"({"version": 1, "root": {"type": "union", "smooth": 0.2,
        "children": [)" + op +
                             R"(,
        {"type": "sphere", "radius": 0.4, "translate": [1.1, 0.6, 0.2], "color": [0.1, 0.4, 0.9]}]}})");
    ASSERT_FALSE(scene.nodes.empty());
    expectGpuMatchesCpu(context, scene, 4096);
    Scene nested = parseOrDie(R"({"version": 1, "root": {"type": "repeat", "count": [2, 1, 2],
        "spacing": [4, 1, 4], "children": [)" +
                              op + "]}}");
    ASSERT_FALSE(nested.nodes.empty());
    expectGpuMatchesCpu(context, nested, 2048);
}

// Every value and domain operation, around a child that shows what they do.
TEST_F(GpuEval, EveryValueAndDomainOperationMatchesTheCpu) {
    for (const auto& [type, params] : examples(isValueOrDomain)) {
        SCOPED_TRACE(type);
        // Transformed itself, around a transformed child, inside a smooth union, and with a
        // repeat around it so that domains nest.
        const std::string op =
            R"({"type": ")" + type + R"(", )" + params +
            R"(, "rotate": [10, 25, -5], "scale": 0.9, "translate": [0.1, -0.2, 0.1],
              "children": [{"type": "round_box", "size": [0.5, 0.8, 0.3], "radius": 0.05,
                 "translate": [0.2, 0.1, -0.1], "rotate": [0, 30, 10], "scale": [1, 1.2, 0.9],
                 "color": [0.9, 0.3, 0.1]}]})";
        expectInUnionAndRepeatMatchesCpu(context(), op);
    }
}

// Each transition from its table example, transformed, its children coloured and one of them an
// operation, inside a smooth union and nested in a repeat (on tapes, which take it from the
// stack).
TEST_F(GpuEval, TransitionsMatchTheCpu) {
    for (const auto& [type, params] :
         examples([](const KindInfo& k) { return isTransition(k.kind); })) {
        SCOPED_TRACE(type);
        const std::string op =
            R"({"type": ")" + type + R"(", )" + params +
            R"(, "rotate": [10, 25, -5], "scale": [0.9, 1.1, 1], "translate": [0.1, -0.2, 0.1],
              "children": [{"type": "round_box", "size": [0.5, 0.8, 0.3], "radius": 0.05,
                 "translate": [0.2, 0.1, -0.1], "rotate": [0, 30, 10], "color": [0.9, 0.3, 0.1]},
                {"type": "union", "smooth": 0.1, "color": [0.1, 0.8, 0.3], "children": [
                    {"type": "sphere", "radius": 0.4},
                    {"type": "torus", "major_radius": 0.5, "minor_radius": 0.1}]}]})";
        expectInUnionAndRepeatMatchesCpu(context(), op);
    }
}

// Each blend profile on each operation, in the inlined, buffer and tape kernels alike (and a
// scale per axis).
TEST_F(GpuEval, BlendProfilesMatchTheCpu) {
    for (const char* blend : {"round", "chamfer"}) {
        SCOPED_TRACE(blend);
        const std::string b = std::string(R"("blend": ")") + blend + "\"";
        Scene scene = parseOrDie(R"({"version": 1, "root": {"type": "union", "smooth": 0.2, )" + b +
                                 R"(, "children": [
            {"type": "difference", "smooth": 0.15, )" +
                                 b + R"(, "color": [0.8, 0.8, 0.2], "children": [
                {"type": "intersection", "smooth": 0.2, )" +
                                 b + R"(, "children": [
                    {"type": "box", "size": [1.5, 1.5, 1.5], "color": [1, 0, 0]},
                    {"type": "sphere", "radius": 1.0, "scale": [1.2, 0.9, 1], "color": [0, 1, 0]}]},
                {"type": "cylinder", "radius": 0.4, "height": 3, "color": [0, 0, 1]}]},
            {"type": "box", "size": [0.6, 2.4, 0.6], "translate": [0.9, 0, 0], "color": [0.2, 0.9, 0.4]}
            ]}})");
        ASSERT_FALSE(scene.nodes.empty());
        expectGpuMatchesCpu(context(), scene, 4096);
    }
}

// An operation scaled per axis and turned: its operands' fields are their local ones times the
// smallest factor, below their boxes' distance but for the floor of the bounds, so that the
// kernels that skip by those boxes, those that do not and the CPU agree; and a repetition whose
// copies reach past their neighbours (its value capped by the copies it leaves out).
TEST_F(GpuEval, ScalesPerAxisAndRepetitionsMatchTheCpu) {
    Scene scene = parseOrDie(R"({"version": 1, "root": {"type": "union", "children": [
        {"type": "union", "scale": [1, 0.5, 2], "rotate": [20, 35, 10], "children": [
            {"type": "box", "size": [1, 0.6, 0.8], "color": [0.9, 0.3, 0.1]},
            {"type": "sphere", "radius": 0.5, "translate": [1, 0.5, 0]},
            {"type": "torus", "major_radius": 0.6, "minor_radius": 0.2, "translate": [-0.8, 0, 0.5]}
            ]},
        {"type": "repeat", "count": [6, 1, 1], "spacing": [0.5, 1, 1], "translate": [0, 2, 0],
         "children": [{"type": "box", "size": [0.9, 0.3, 0.3], "color": [0.1, 0.4, 0.9]}]}]}})");
    ASSERT_FALSE(scene.nodes.empty());
    expectGpuMatchesCpu(context(), scene, 4096);
}

// Offsets and shells over twist, bend, taper and a smooth union that ask for "exact" read their
// child's distance baked at load (field/bake.h) as a mesh node's field, their child's code left
// out, in every mode; one left "fast" (the default) divides by its child's gradient from four
// taps (sdf.glsl, valueNormalised): the child's code in a loop in the inlined kernels, and opened
// as a domain operation on tapes.
TEST_F(GpuEval, OffsetsOverStretchedFieldsMatchTheCpu) {
    Scene scene = parseOrDie(R"({"version": 1, "root": {"type": "union", "children": [
        {"type": "offset", "distance": 0.3, "accuracy": "exact", "children": [
            {"type": "twist", "angle": 90, "children": [
                {"type": "box", "size": [1, 2, 1], "color": [0.9, 0.3, 0.1]}]}]},
        {"type": "shell", "thickness": 0.1, "accuracy": "exact", "translate": [2, 0, 0],
         "children": [
            {"type": "bend", "angle": 40, "children": [{"type": "box", "size": [1.5, 0.4, 0.6]}]}]},
        {"type": "offset", "distance": -0.05, "accuracy": "exact", "translate": [-2, 0, 0],
         "children": [
            {"type": "taper", "height": 1.5, "top_scale": 0.4, "children": [
                {"type": "union", "smooth": 0.2, "children": [
                    {"type": "box", "size": [1, 1.5, 1], "color": [0.1, 0.4, 0.9]},
                    {"type": "sphere", "radius": 0.5, "translate": [0.5, 0, 0]}]}]}]},
        {"type": "offset", "distance": 0.1, "translate": [0, 0, 2], "children": [
            {"type": "twist", "angle": 90, "children": [{"type": "box", "size": [1, 2, 1]}]}]}]}})");
    ASSERT_FALSE(scene.nodes.empty());
    for (const uint32_t offset : {1u, 4u, 7u})
        EXPECT_NE(scene.nodes[offset].words, nullptr) << scene.nodes[offset].path;
    EXPECT_EQ(scene.nodes[12].words, nullptr); // "fast"
    expectGpuMatchesCpu(context(), scene, 4096);
}

class BundledEval : public GpuTest, public ::testing::WithParamInterface<fs::path> {};

TEST_P(BundledEval, MatchesTheCpu) {
    Scene scene = loadOrDie(GetParam());
    ASSERT_FALSE(scene.nodes.empty());
    expectGpuMatchesCpu(context(), scene, 4096);
}

INSTANTIATE_TEST_SUITE_P(Bundled, BundledEval, ::testing::ValuesIn(bundledScenes()), sceneTestName);

} // namespace
} // namespace sdfcsg::test
