// Legacy SDFBooleanEngine scenes: converted files evaluate exactly like hand-written twins in the
// current format, every legacy primitive matches the original engine's formula, and broken
// files are refused with messages that name the node index.
#include <sdfcsg/eval.h>
#include <sdfcsg/scene.h>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <random>
#include <string>

namespace fs = std::filesystem;
using namespace sdfcsg;
using glm::vec2;
using glm::vec3;
using glm::vec4;

namespace {

const fs::path kData = fs::path(SDFCSG_SOURCE_DIR) / "tests/data/legacy";

Scene load(const fs::path& file) {
    auto r = loadScene(file);
    EXPECT_TRUE(r) << (r ? "" : r.error().str());
    return r ? *r : Scene{};
}

std::vector<vec3> samplePoints(vec3 lo, vec3 hi, int count, unsigned seed) {
    std::mt19937 rng(seed);
    std::vector<vec3> points;
    for (int i = 0; i < count; ++i) {
        vec3 p;
        for (int k = 0; k < 3; ++k)
            p[k] = std::uniform_real_distribution<float>(lo[k], hi[k])(rng);
        points.push_back(p);
    }
    return points;
}

// Structure: kinds, names, tree shape, transforms, colours and parameters.
void expectSameStructure(const Scene& a, const Scene& b) {
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    for (size_t i = 0; i < a.nodes.size(); ++i) {
        SCOPED_TRACE("node " + std::to_string(i) + " (" + a.nodes[i].path + ")");
        const Node &x = a.nodes[i], &y = b.nodes[i];
        EXPECT_EQ(x.kind, y.kind);
        EXPECT_EQ(x.children, y.children);
        EXPECT_EQ(x.color.has_value(), y.color.has_value());
        if (x.color && y.color) {
            for (int k = 0; k < 3; ++k)
                EXPECT_NEAR((*x.color)[k], (*y.color)[k], 1e-6f);
        }
        for (int k = 0; k < 3; ++k) {
            EXPECT_NEAR(x.transform.translate[k], y.transform.translate[k], 1e-6f);
            EXPECT_NEAR(x.transform.rotate[k], y.transform.rotate[k], 1e-6f);
        }
        EXPECT_NEAR(glm::distance(x.transform.scale, y.transform.scale), 0.0f, 1e-6f);
        for (int k = 0; k < kMaxParams; ++k)
            EXPECT_NEAR(x.params[k], y.params[k], 1e-6f) << "slot " << k;
    }
}

// Distance and colour of both at 1000 points around the scene.
void expectSameField(const Scene& a, const Scene& b, vec3 lo, vec3 hi) {
    const Evaluator ea(a), eb(b);
    for (vec3 p : samplePoints(lo, hi, 1000, 7)) {
        const Sample sa = ea.sample(p), sb = eb.sample(p);
        ASSERT_NEAR(sa.distance, sb.distance, 1e-5f) << "at " << p.x << ", " << p.y << ", " << p.z;
        for (int k = 0; k < 3; ++k)
            ASSERT_NEAR(sa.color[k], sb.color[k], 1e-5f);
    }
}

std::string legacyNode(int type, vec4 p1, vec4 p2, int left = -1, int right = -1) {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  R"({"type": %d, "left": %d, "right": %d, "param1": [%.9g, %.9g, %.9g, %.9g], )"
                  R"("param2": [%.9g, %.9g, %.9g, %.9g]})",
                  type, left, right, p1.x, p1.y, p1.z, p1.w, p2.x, p2.y, p2.z, p2.w);
    return buf;
}

std::string legacyScene(std::initializer_list<std::string> nodes) {
    std::string out = R"({"nodes": [)";
    for (const std::string& n : nodes)
        out += (out.back() == '[' ? "" : ", ") + n;
    return out + "]}";
}

// The original engine's formulas (Inigo Quilez's), on legacy parameters.
float legacySphere(vec3 p, vec4 a, vec4 b) {
    return glm::length(p - vec3(a)) - b.x;
}
float legacyBox(vec3 p, vec4 a, vec4 b) {
    vec3 q = glm::abs(p - vec3(a)) - vec3(b);
    return glm::length(glm::max(q, 0.0f)) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0f);
}
float legacyPlane(vec3 p, vec4 a, vec4 b) {
    return glm::dot(p - vec3(a), vec3(b)) + b.w;
}
float legacyTriPrism(vec3 p, vec4 a, vec4 h) {
    p -= vec3(a);
    vec3 q = glm::abs(p);
    return std::max(q.z - h.y, std::max(q.x * 0.866025f + p.y * 0.5f, -p.y) - h.x * 0.5f);
}
float legacyTorus(vec3 p, vec4 a, vec4 t) {
    p -= vec3(a);
    vec2 q(glm::length(vec2(p.x, p.z)) - t.x, p.y);
    return glm::length(q) - t.y;
}
float legacyCylinder(vec3 p, vec4 a, vec4 b) {
    p -= vec3(a);
    vec2 d = glm::abs(vec2(glm::length(vec2(p.x, p.z)), p.y)) - vec2(b.y, b.x);
    return std::min(std::max(d.x, d.y), 0.0f) + glm::length(glm::max(d, 0.0f));
}
float legacyCone(vec3 p, vec4 apex, vec4 b) {
    p -= vec3(apex);
    const vec2 c(b.x, b.y);
    const float h = b.z;
    vec2 q = h * vec2(c.x / c.y, -1.0f);
    vec2 w(glm::length(vec2(p.x, p.z)), p.y);
    vec2 e = w - q * glm::clamp(glm::dot(w, q) / glm::dot(q, q), 0.0f, 1.0f);
    vec2 f = w - q * vec2(glm::clamp(w.x / q.x, 0.0f, 1.0f), 1.0f);
    float k = q.y > 0 ? 1.0f : -1.0f;
    float d = std::min(glm::dot(e, e), glm::dot(f, f));
    float s = std::max(k * (w.x * q.y - w.y * q.x), k * (w.y - q.y));
    return std::sqrt(d) * (s > 0 ? 1.0f : -1.0f);
}
float legacyCapsule(vec3 p, vec4 a4, vec4 b4) {
    vec3 a(a4), b(b4);
    vec3 pa = p - a, ba = b - a;
    float h = glm::clamp(glm::dot(pa, ba) / glm::dot(ba, ba), 0.0f, 1.0f);
    return glm::length(pa - ba * h) - b4.w;
}

struct LegacyPrimitive {
    const char* name;
    int type;
    vec4 p1, p2;
    std::function<float(vec3, vec4, vec4)> reference;
    float scale = 1.0f; // the legacy value is this times the true distance
    bool exact = true;  // the legacy prism is a bound: only its sign is the true one
};

} // namespace

TEST(Legacy, FixturesMatchTheirHandWrittenTwins) {
    struct Pair {
        const char* name;
        vec3 lo, hi;
    };
    for (const Pair& pair :
         {Pair{"primitives", vec3(-4, -2, -4), vec3(4, 4, 4)}, Pair{"csg", vec3(-2), vec3(2)},
          Pair{"shared", vec3(-2, -2, -2), vec3(4, 3, 2)}}) {
        SCOPED_TRACE(pair.name);
        const Scene legacy = load(kData / (std::string(pair.name) + ".json"));
        const Scene twin = load(kData / (std::string(pair.name) + ".twin.json"));
        expectSameStructure(legacy, twin);
        expectSameField(legacy, twin, pair.lo, pair.hi);
    }
}

TEST(Legacy, ConvertedNodesAreNamedByLegacyIndex) {
    const Scene s = load(kData / "csg.json");
    std::vector<std::string> paths;
    for (const Node& n : s.nodes)
        paths.push_back(n.path);
    // The root is the last node; the chain of differences 8, 7, 6 merges into one.
    EXPECT_EQ(paths, (std::vector<std::string>{"nodes[8]", "nodes[5]", "nodes[0]", "nodes[1]",
                                               "nodes[2]", "nodes[3]", "nodes[4]"}));
    const Scene shared = load(kData / "shared.json");
    EXPECT_EQ(std::count_if(shared.nodes.begin(), shared.nodes.end(),
                            [](const Node& n) { return n.path == "nodes[0]"; }),
              2)
        << "a node used twice is copied";
}

TEST(Legacy, EveryPrimitiveMatchesTheOriginalFormula) {
    const LegacyPrimitive primitives[] = {
        {"sphere", 0, {0.5f, 1, -0.5f, 0}, {0.8f, 0, 0, 0}, legacySphere},
        {"box", 1, {0, 1, 0, 0}, {0.5f, 0.25f, 1.0f, 0}, legacyBox},
        {"plane", 2, {0, -1, 0.5f, 0}, {1, 2, -0.5f, 0.3f}, legacyPlane, std::sqrt(5.25f)},
        {"triangular prism", 3, {0.2f, 0.3f, 0, 0}, {0.8f, 0.6f, 0, 0}, legacyTriPrism, 1, false},
        {"torus", 4, {0, 0.5f, 0, 0}, {1.0f, 0.25f, 0, 0}, legacyTorus},
        {"cylinder", 5, {0.3f, 0, 0, 0}, {0.75f, 0.4f, 0, 0}, legacyCylinder},
        {"cone", 6, {0, 1, 0, 0}, {0.6f, 0.8f, 1.5f, 0}, legacyCone},
        {"capsule", 7, {-0.5f, 0, 0, 0}, {0.5f, 0.8f, 0.2f, 0.3f}, legacyCapsule},
    };
    for (const LegacyPrimitive& prim : primitives) {
        SCOPED_TRACE(prim.name);
        auto r = parseScene(legacyScene({legacyNode(prim.type, prim.p1, prim.p2)}), "legacy.json");
        ASSERT_TRUE(r) << r.error().str();
        const Evaluator evaluator(*r);
        int checked = 0;
        for (vec3 p : samplePoints(vec3(-2.5f), vec3(2.5f), 1000, 11)) {
            const float expected = prim.reference(p, prim.p1, prim.p2) / prim.scale;
            const float actual = evaluator.distance(p);
            if (prim.exact) {
                ASSERT_NEAR(actual, expected, 2e-5f * std::max(1.0f, std::abs(expected)))
                    << "at " << p.x << ", " << p.y << ", " << p.z;
                ++checked;
            } else if (std::abs(expected) > 1e-3f) {
                // The legacy prism is a bound, not a distance: the solid is the same.
                ASSERT_EQ(actual < 0, expected < 0) << "at " << p.x << ", " << p.y << ", " << p.z;
                ++checked;
            }
        }
        EXPECT_GT(checked, 900);
    }
}

TEST(Legacy, OperationsMatchTheOriginalFormulas) {
    const vec4 c1(0, 0, 0, 0), s1(1, 0, 0, 0), c2(0.7f, 0.2f, 0, 0), h2(0.6f, 0.5f, 0.7f, 0);
    auto a = [&](vec3 p) { return legacySphere(p, c1, s1); };
    auto b = [&](vec3 p) { return legacyBox(p, c2, h2); };
    const std::pair<int, std::function<float(vec3)>> ops[] = {
        {10, [&](vec3 p) { return std::min(a(p), b(p)); }},
        {11, [&](vec3 p) { return std::max(a(p), b(p)); }},
        {12, [&](vec3 p) { return std::max(a(p), -b(p)); }},
    };
    for (const auto& [code, reference] : ops) {
        SCOPED_TRACE(code);
        auto r = parseScene(legacyScene({legacyNode(0, c1, s1), legacyNode(1, c2, h2),
                                         legacyNode(code, {}, {}, 0, 1)}),
                            "legacy.json");
        ASSERT_TRUE(r) << r.error().str();
        const Evaluator evaluator(*r);
        for (vec3 p : samplePoints(vec3(-2), vec3(2), 1000, 5))
            ASSERT_NEAR(evaluator.distance(p), reference(p), 1e-5f);
    }
}

TEST(Legacy, LongChainsMergeAndSharedNodesAreBounded) {
    // 2000 spheres united one by one: a chain 1999 deep in the legacy file, one union here.
    std::vector<std::string> nodes;
    for (int i = 0; i < 2000; ++i)
        nodes.push_back(legacyNode(0, vec4(float(i), 0, 0, 0), vec4(0.4f, 0, 0, 0)));
    nodes.push_back(legacyNode(10, {}, {}, 0, 1));
    for (int i = 2; i < 2000; ++i)
        nodes.push_back(legacyNode(10, {}, {}, int(nodes.size()) - 1, i));
    std::string json = R"({"nodes": [)";
    for (const std::string& n : nodes)
        json += (json.back() == '[' ? "" : ", ") + n;
    json += "]}";
    auto r = parseScene(json, "chain.json");
    ASSERT_TRUE(r) << r.error().str();
    EXPECT_EQ(r->nodes.size(), 2001u);
    EXPECT_EQ(r->nodes[0].children.size(), 2000u);

    // Each union uses the previous one twice: 2^40 copies if expanded. Refused at the limit,
    // quickly.
    std::string dag = R"({"nodes": [)" + legacyNode(0, {}, vec4(1, 0, 0, 0));
    for (int i = 1; i <= 40; ++i)
        dag += ", " + legacyNode(i % 2 ? 10 : 11, {}, {}, i - 1, i - 1);
    dag += "]}";
    const auto start = std::chrono::steady_clock::now();
    auto d = parseScene(dag, "dag.json");
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
    ASSERT_FALSE(d);
    EXPECT_EQ(d.error().kind, ErrorKind::Limit);
    EXPECT_TRUE(d.error().str().ends_with(": too many nodes: a scene may have at most 16384 (a "
                                          "node used by several operations counts once per use)"))
        << d.error().str();

    // Alternating operations cannot merge, so depth is limited as in the current format.
    std::string deep = R"({"nodes": [)" + legacyNode(0, {}, vec4(1, 0, 0, 0)) + ", " +
                       legacyNode(0, vec4(1, 0, 0, 0), vec4(1, 0, 0, 0));
    for (int i = 2; i < 70; ++i)
        deep += ", " + legacyNode(i % 2 ? 10 : 11, {}, {}, i == 2 ? 0 : i - 1, 1);
    deep += "]}";
    auto e = parseScene(deep, "deep.json");
    ASSERT_FALSE(e);
    EXPECT_EQ(e.error().str(),
              "deep.json: nodes[5]: nesting too deep: more than 64 nested operations");
}

TEST(Legacy, BrokenFilesNameTheNode) {
    auto sphere = [](const char* radius = "1", const char* extra = "") {
        return std::string(
                   R"({"type": 0, "left": -1, "right": -1, "param1": [0, 0, 0, 0], "param2": [)") +
               radius + ", 0, 0, 0]" + extra + "}";
    };
    auto op = [](int type, const char* left, const char* right) {
        return R"({"type": )" + std::to_string(type) + R"(, "left": )" + left + R"(, "right": )" +
               right + "}";
    };
    const std::string types = "0 sphere, 1 box, 2 plane, 3 triangular prism, 4 torus, 5 cylinder, "
                              "6 cone, 7 capsule, 10 union, 11 intersection or 12 difference";
    const std::pair<std::string, std::string> cases[] = {
        {R"({"nodes": {}})", "legacy.json: nodes: expected an array of legacy nodes, got {}"},
        {R"({"nodes": []})", "legacy.json: nodes: expected at least one node, got []"},
        {legacyScene({sphere(), "[1, 2]"}),
         R"(legacy.json: nodes[1]: expected a legacy node (an object with "type"), got [1, 2])"},
        {legacyScene({R"({"type": 8, "param1": [0, 0, 0, 0], "param2": [1, 0, 0, 0]})"}),
         "legacy.json: nodes[0].type: unknown legacy node type 8; expected " + types},
        {legacyScene({R"({"type": 1.5, "param1": [0, 0, 0, 0], "param2": [1, 0, 0, 0]})"}),
         "legacy.json: nodes[0].type: expected an integer type code, got 1.5"},
        {legacyScene({R"({"param1": [0, 0, 0, 0], "param2": [1, 0, 0, 0]})"}),
         "legacy.json: nodes[0]: missing required key \"type\" (" + types + ")"},
        {legacyScene({sphere(), sphere(), op(10, "0", "7")}),
         "legacy.json: nodes[2].right: expected a node index in 0..2, got 7"},
        {legacyScene({sphere(), sphere(), op(12, "-2", "1")}),
         "legacy.json: nodes[2].left: expected a node index in 0..2, got -2"},
        {legacyScene({sphere(), op(10, "0", "-1")}),
         "legacy.json: nodes[1].right: a union (type 10) needs two operands; expected a node index "
         "in 0..1, got -1"},
        {legacyScene({sphere(), R"({"type": 11})"}),
         "legacy.json: nodes[1]: missing required key \"left\" (the index of the first operand)\n"
         "legacy.json: nodes[1]: missing required key \"right\" (the index of the second operand)"},
        {legacyScene(
             {sphere(),
              R"({"type": 0, "left": 0, "right": -1, "param1": [0, 0, 0, 0], "param2": [1, 0, 0, 0]})"}),
         "legacy.json: nodes[1].left: a sphere (type 0) takes no operands; expected -1, got 0"},
        {legacyScene({sphere(), sphere(), op(10, "\"0\"", "1")}),
         R"(legacy.json: nodes[2].left: expected a node index or -1, got "0")"},
        {legacyScene({R"({"type": 0, "param1": [0, 0, 0], "param2": [1, 0, 0, 0]})"}),
         "legacy.json: nodes[0].param1: expected an array of 4 numbers, got [0, 0, 0]"},
        {legacyScene({R"({"type": 0, "param1": [0, 0, 0, 0], "param2": ["1", 0, 0, 0]})"}),
         R"(legacy.json: nodes[0].param2[0]: expected a number, got "1")"},
        {legacyScene({R"({"type": 0, "param1": [0, 0, 0, 0]})"}),
         R"(legacy.json: nodes[0]: missing required key "param2" (an array of 4 numbers))"},
        {legacyScene({sphere("-1")}),
         "legacy.json: nodes[0].param2[0]: expected a positive number (the radius), got -1"},
        {legacyScene({R"({"type": 1, "param1": [0, 0, 0, 0], "param2": [1, 0, 1, 0]})"}),
         "legacy.json: nodes[0].param2[1]: expected a positive number (the half extent along y), "
         "got 0"},
        {legacyScene({R"({"type": 6, "param1": [0, 0, 0, 0], "param2": [1, 0, 1, 0]})"}),
         "legacy.json: nodes[0].param2[1]: expected a positive number (the cosine of the half "
         "angle), got 0"},
        {legacyScene({R"({"type": 2, "param1": [0, 0, 0, 0], "param2": [0, 0, 0, 1]})"}),
         "legacy.json: nodes[0].param2: expected a non-zero plane normal in the first three "
         "numbers, got [0, 0, 0, 1]"},
        {legacyScene({R"({"type": 7, "param1": [0, 0, 0, 0], "param2": [1, 0, 0, 0]})"}),
         "legacy.json: nodes[0].param2[3]: expected a positive number (the radius), got 0"},
        {legacyScene({sphere(), op(10, "0", "1")}),
         "legacy.json: nodes[1].right: refers to node 1 itself (a cycle)"},
        {legacyScene({sphere(), op(10, "0", "2"), op(11, "1", "0")}),
         "legacy.json: nodes[1].right: refers to node 2, which contains node 1 (a cycle)"},
        {legacyScene({sphere("1", R"(, "colour": [1, 0, 0])")}),
         R"(legacy.json: nodes[0]: unknown key "colour"; did you mean "color"?)"},
        {legacyScene({sphere("1", R"(, "name": "ball")")}),
         "legacy.json: nodes[0]: unknown key \"name\" for a legacy node; valid keys: type, left, "
         "right, param1, param2 and color"},
        {R"({"nodes": [)" + sphere() + R"(], "camera": {}})",
         "legacy.json: unknown key \"camera\" in a legacy scene; valid keys: nodes"},
        {legacyScene({sphere("1", R"(, "color": [255, 0, 0])")}),
         "legacy.json: nodes[0].color[0]: expected a number in 0..1, got 255"},
        {legacyScene({sphere("0"), op(10, "0", "5"),
                      R"({"type": 3, "param1": [0, 0, 0, 0], "param2": [1, -1, 0, 0]})"}),
         "legacy.json: nodes[0].param2[0]: expected a positive number (the radius), got 0\n"
         "legacy.json: nodes[1].right: expected a node index in 0..2, got 5\n"
         "legacy.json: nodes[2].param2[1]: expected a positive number (h.y, the half length), got "
         "-1"},
    };
    for (const auto& [json, expected] : cases) {
        SCOPED_TRACE(json);
        auto r = parseScene(json, "legacy.json");
        ASSERT_FALSE(r);
        EXPECT_EQ(r.error().str(), expected);
    }
}

TEST(Legacy, AVersionMeansTheCurrentFormat) {
    auto r = parseScene(R"({"version": 1, "nodes": []})", "scene.json");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().str(),
              "scene.json: unknown key \"nodes\"; valid keys: version, name, description, camera, "
              "lights, background, definitions and root\n"
              "scene.json: missing required key \"root\" (the top node of the scene)");
}

TEST(Legacy, ConvertWritesTheCurrentFormat) {
    // What `sdfcsg convert` does: load the legacy file, write it out, read that back.
    for (const char* name : {"primitives", "csg", "shared"}) {
        SCOPED_TRACE(name);
        const Scene legacy = load(kData / (std::string(name) + ".json"));
        const std::string text = toJson(legacy);
        auto converted = parseScene(text, "converted.json");
        ASSERT_TRUE(converted) << converted.error().str();
        expectSameStructure(legacy, *converted);
        expectSameField(legacy, *converted, vec3(-3), vec3(3));
    }
}
