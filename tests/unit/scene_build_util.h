// Scenes built in code for the evaluator and code generator tests: a small tree literal that
// flattens into Scene's pre-order node array, seeded random scene generators (of Booleans over
// common primitives, and as JSON of every kind of the node table), a scene from its root node's
// JSON, and seeded random points.
#pragma once

#include <sdfcsg/eval.h>
#include <sdfcsg/scene.h>

#include <gtest/gtest.h>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <random>
#include <string>
#include <vector>

namespace sdfcsg::test {

// The scene whose root node is the JSON text `root`, as "test.json"; a failure, and an empty
// scene, where it does not parse.
inline Scene parseRoot(const std::string& root) {
    auto scene = parseScene(R"({"version": 1, "root": )" + root + "}", "test.json");
    if (!scene) ADD_FAILURE() << scene.error().str();
    return scene ? *scene : Scene{};
}

// `count` points uniform in the cube of half side `reach`, the same for the same seed.
inline std::vector<glm::vec3> randomPoints(uint32_t seed, int count, float reach) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-reach, reach);
    std::vector<glm::vec3> points;
    for (int i = 0; i < count; ++i)
        points.push_back({u(rng), u(rng), u(rng)});
    return points;
}

// One node and its subtree. Parameters are the table's values (full sizes), by slot.
struct Tree {
    NodeKind kind = NodeKind::Sphere;
    std::array<float, kMaxParams> params{};
    Transform transform;
    std::optional<glm::vec3> color;
    std::string name;
    std::vector<Tree> children;

    Tree& at(float x, float y, float z) {
        transform.translate = {x, y, z};
        return *this;
    }
    Tree& rotated(float x, float y, float z) {
        transform.rotate = {x, y, z};
        return *this;
    }
    Tree& scaled(float s) {
        transform.scale = glm::vec3(s);
        return *this;
    }
    Tree& colored(float r, float g, float b) {
        color = glm::vec3(r, g, b);
        return *this;
    }
    Tree& named(std::string n) {
        name = std::move(n);
        return *this;
    }
};

inline Tree leaf(NodeKind kind, std::initializer_list<float> params) {
    Tree t;
    t.kind = kind;
    int i = 0;
    for (float v : params)
        t.params[size_t(i++)] = v;
    return t;
}
inline Tree sphere(float r) {
    return leaf(NodeKind::Sphere, {r});
}
inline Tree box(float x, float y, float z) {
    return leaf(NodeKind::Box, {x, y, z});
}
inline Tree roundBox(float x, float y, float z, float r) {
    return leaf(NodeKind::RoundBox, {x, y, z, r});
}
inline Tree plane(glm::vec3 n, float offset) {
    return leaf(NodeKind::Plane, {n.x, n.y, n.z, offset});
}
inline Tree prism(float w, float h, float l) {
    return leaf(NodeKind::TriangularPrism, {w, h, l});
}
inline Tree torus(float major, float minor) {
    return leaf(NodeKind::Torus, {major, minor});
}
inline Tree cylinder(float r, float h) {
    return leaf(NodeKind::Cylinder, {r, h});
}
inline Tree cone(float r, float h, float top = 0.0f) {
    return leaf(NodeKind::Cone, {r, h, top});
}
inline Tree capsule(glm::vec3 a, glm::vec3 b, float r) {
    return leaf(NodeKind::Capsule, {a.x, a.y, a.z, b.x, b.y, b.z, r});
}
inline Tree op(NodeKind kind, std::vector<Tree> children, float smooth = 0.0f) {
    Tree t;
    t.kind = kind;
    t.params[0] = smooth;
    t.children = std::move(children);
    return t;
}
inline Tree unite(std::vector<Tree> c, float k = 0.0f) {
    return op(NodeKind::Union, std::move(c), k);
}
inline Tree intersect(std::vector<Tree> c, float k = 0.0f) {
    return op(NodeKind::Intersection, std::move(c), k);
}
inline Tree subtract(std::vector<Tree> c, float k = 0.0f) {
    return op(NodeKind::Difference, std::move(c), k);
}

inline void appendTree(Scene& scene, const Tree& t, const std::string& path) {
    const uint32_t index = uint32_t(scene.nodes.size());
    Node n;
    n.kind = t.kind;
    n.name = t.name;
    n.path = path;
    n.transform = t.transform;
    n.color = t.color;
    n.params = t.params;
    scene.nodes.push_back(std::move(n));
    for (size_t i = 0; i < t.children.size(); ++i) {
        scene.nodes[index].children.push_back(uint32_t(scene.nodes.size()));
        appendTree(scene, t.children[i], path + ".children[" + std::to_string(i) + "]");
    }
}

inline Scene makeScene(const Tree& root, std::string file = "<test>") {
    Scene scene;
    scene.file = std::move(file);
    appendTree(scene, root, "root");
    return scene;
}

// Every primitive once, spread out on a grid, some turned and scaled.
inline Scene primitiveGallery() {
    std::vector<Tree> all = {
        sphere(0.6f).at(-3, 0, 0).colored(0.9f, 0.2f, 0.2f),
        box(1.0f, 0.8f, 1.2f).at(-1.5f, 0, 0).rotated(10, 20, 30),
        roundBox(1.0f, 1.0f, 0.6f, 0.2f).at(0, 0, 0).scaled(1.3f),
        prism(1.2f, 0.9f, 1.0f).at(1.5f, 0, 0).rotated(0, 45, 0),
        torus(0.5f, 0.15f).at(3, 0, 0).rotated(90, 0, 0),
        cylinder(0.4f, 1.2f).at(-3, 0, 2),
        cone(0.5f, 1.0f).at(-1.5f, 0, 2),
        cone(0.5f, 1.0f, 0.2f).at(0, 0, 2).rotated(0, 0, 180),
        capsule({-0.3f, -0.4f, 0}, {0.3f, 0.4f, 0.1f}, 0.2f).at(1.5f, 0, 2),
        plane({0, 1, 0}, -1.0f).colored(0.5f, 0.5f, 0.5f),
    };
    return makeScene(unite(std::move(all)), "<gallery>");
}

// A random scene of about `count` nodes: every kind, random transforms, colours and smooth radii,
// operations nested up to `maxDepth`. Planes only when `planes` is set.
inline Scene randomScene(uint32_t seed, int count, int maxDepth = 6, bool planes = false) {
    std::mt19937 rng(seed);
    auto uni = [&](float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng); };
    auto pick = [&](int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng); };
    int budget = count;
    auto transform = [&](Tree& t) {
        if (pick(3) > 0) t.at(uni(-1.5f, 1.5f), uni(-1.5f, 1.5f), uni(-1.5f, 1.5f));
        if (pick(2) > 0) t.rotated(uni(-180, 180), uni(-180, 180), uni(-180, 180));
        if (pick(3) == 0) t.scaled(uni(0.5f, 1.8f));
        if (pick(3) == 0) t.colored(uni(0, 1), uni(0, 1), uni(0, 1));
    };
    auto primitive = [&]() {
        Tree t;
        switch (pick(planes ? 9 : 8)) {
        case 0:
            t = sphere(uni(0.2f, 1.0f));
            break;
        case 1:
            t = box(uni(0.2f, 2), uni(0.2f, 2), uni(0.2f, 2));
            break;
        case 2: {
            float x = uni(0.3f, 2), y = uni(0.3f, 2), z = uni(0.3f, 2);
            t = roundBox(x, y, z, uni(0.0f, 0.5f) * std::min(x, std::min(y, z)));
            break;
        }
        case 3:
            t = prism(uni(0.3f, 2), uni(0.3f, 2), uni(0.3f, 2));
            break;
        case 4:
            t = torus(uni(0.4f, 1.0f), uni(0.1f, 0.35f));
            break;
        case 5:
            t = cylinder(uni(0.2f, 1), uni(0.3f, 2));
            break;
        case 6:
            t = cone(uni(0.2f, 1), uni(0.3f, 2), pick(2) ? 0.0f : uni(0.0f, 1.0f));
            break;
        case 7:
            t = capsule({uni(-1, 1), uni(-1, 1), uni(-1, 1)}, {uni(-1, 1), uni(-1, 1), uni(-1, 1)},
                        uni(0.1f, 0.5f));
            break;
        default: {
            glm::vec3 n(uni(-1, 1), uni(0.2f, 1), uni(-1, 1));
            t = plane(n / std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z), uni(-3, -1));
        }
        }
        transform(t);
        return t;
    };
    // Recursion is fine here: maxDepth is small.
    auto build = [&](auto&& self, int depth) -> Tree {
        --budget;
        if (depth >= maxDepth || budget <= 1 || pick(3) == 0) return primitive();
        int n = 1 + pick(4);
        std::vector<Tree> children;
        for (int i = 0; i < n && budget > 0; ++i)
            children.push_back(self(self, depth + 1));
        static constexpr NodeKind kinds[] = {NodeKind::Union, NodeKind::Union,
                                             NodeKind::Intersection, NodeKind::Difference};
        Tree t = op(kinds[pick(4)], std::move(children), pick(2) ? 0.0f : uni(0.05f, 0.6f));
        transform(t);
        return t;
    };
    std::vector<Tree> top;
    while (budget > 0)
        top.push_back(build(build, 1));
    return makeScene(unite(std::move(top), uni(0.0f, 0.3f)),
                     "<random " + std::to_string(seed) + ">");
}

// What randomTreeJson() draws besides its trees of every kind.
struct TreeOptions {
    bool scalesPerAxis = false; // half the nodes scaled by a factor per axis
    bool planes = false;        // planes that intersections and differences cut by
};

// A random tree of every kind of the node table but the plane (unbounded; with options.planes,
// an operand of intersections and differences), the text (slow to compile), the image, the
// heightmap and the mesh (they read files; tests/unit/test_images.cpp, test_mesh_field.cpp), each
// from its example in the table
// (sdfcsg/nodes.h), turned, moved and scaled at random: operations over random subtrees (Booleans
// sharp or with their example's blend), 2D profiles under extrude or revolve, primitives at the
// leaves.
inline std::string randomTreeJson(std::mt19937& rng, int depth, const TreeOptions& options = {}) {
    auto uni = [&](float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng); };
    std::vector<const KindInfo*> primitives, profiles, operations;
    for (const KindInfo& k : nodeKinds()) {
        if (k.kind == NodeKind::Plane || k.kind == NodeKind::Text || k.kind == NodeKind::Image ||
            k.kind == NodeKind::Heightmap || k.kind == NodeKind::Mesh)
            continue;
        (isProfile(k.kind) ? profiles : k.operation ? operations : primitives).push_back(&k);
    }
    auto pick = [&](const std::vector<const KindInfo*>& from) { return from[rng() % from.size()]; };
    // A profile moves and turns in its plane only: its cross-section at z = 0 is what counts.
    auto node = [&](const KindInfo& k, const std::string& members, const std::string& children) {
        const bool flat = isProfile(k.kind);
        char transform[200];
        std::snprintf(transform, sizeof transform,
                      R"(, "translate": [%.3f, %.3f, %.3f], "rotate": [%.1f, %.1f, %.1f], )"
                      R"("scale": %.3f)",
                      uni(-0.4f, 0.4f), uni(-0.4f, 0.4f), flat ? 0.0f : uni(-0.4f, 0.4f),
                      flat ? 0.0f : uni(-180, 180), flat ? 0.0f : uni(-180, 180), uni(-180, 180),
                      uni(0.45f, 0.8f));
        std::string json = R"({"type": ")" + std::string(k.name) + "\"";
        if (!members.empty()) json += ", " + members;
        if (!children.empty()) json += R"(, "children": [)" + children + "]";
        json += transform;
        if (options.scalesPerAxis && rng() % 2) {
            // The factors of the last two axes, after the first's (a profile's z scales nothing).
            char factors[64];
            std::snprintf(factors, sizeof factors, ", %.3f, %.3f]", uni(0.45f, 0.8f),
                          uni(0.45f, 0.8f));
            json.insert(json.rfind(' ') + 1, "[");
            json += factors;
        }
        return json + "}";
    };
    if (depth == 0 || rng() % 3 == 0) {
        const KindInfo& leaf = *pick(primitives);
        return node(leaf, std::string(leaf.example), "");
    }
    const KindInfo& op = *pick(operations);
    if (op.kind == NodeKind::Extrude || op.kind == NodeKind::Revolve) {
        const KindInfo& profile = *pick(profiles);
        return node(op, std::string(op.example), node(profile, std::string(profile.example), ""));
    }
    std::string children = randomTreeJson(rng, depth - 1, options);
    std::string members(op.example);
    if (op.role == Role::Boolean) {
        children += ", " + randomTreeJson(rng, depth - 1, options);
        if (rng() % 2 && !isTransition(op.kind)) members.clear(); // sharp
        // A plane where it clips (it would leave a union, and the domain operations over it,
        // unbounded; a transition has two children, both bounded).
        if (options.planes && op.kind != NodeKind::Union && !isTransition(op.kind) && rng() % 2) {
            const KindInfo& plane = kindInfo(NodeKind::Plane);
            children += ", " + node(plane, std::string(plane.example), "");
        }
    }
    return node(op, members, children);
}

// A scene of four random trees of depth 3 (randomTreeJson) side by side in a union, as JSON.
inline std::string randomTreesJson(uint32_t seed, const TreeOptions& options = {}) {
    std::mt19937 rng(seed);
    std::string json = R"({"version": 1, "root": {"type": "union", "children": [)";
    for (int part = 0; part < 4; ++part) {
        char at[96];
        std::snprintf(at, sizeof at, R"({"type": "union", "translate": [%d, %d, 0], "children": [)",
                      part % 2 * 2 - 1, part / 2 * 2 - 1);
        json += (part ? ", " : "") + std::string(at) + randomTreeJson(rng, 3, options) + "]}";
    }
    return json + "]}}";
}

// The box of the points of a grid of n + 1 points a side over `within` where the field is below
// 0 (empty where none is); `spacing` is the grid's largest step, within which of the solid's
// true box the result lies where the solid is not thinner than that.
inline Aabb sampledSolid(const Evaluator& eval, const Aabb& within, int n, float& spacing) {
    Aabb solid;
    const glm::vec3 step = (within.max - within.min) / float(n);
    spacing = std::max(step.x, std::max(step.y, step.z));
    for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j)
            for (int k = 0; k <= n; ++k) {
                const glm::vec3 p = within.min + glm::vec3(i, j, k) * step;
                if (eval.distance(p) >= 0.0f) continue;
                solid.min = glm::min(solid.min, p);
                solid.max = glm::max(solid.max, p);
            }
    return solid;
}

// Scenes whose solid is far smaller than their operands' boxes, as a user writes them: an
// intersection of two boxes grown by an offset and moved apart; a woven mat of radius 12 (a
// repeated weave cut by a tall cylinder, a rim cut from a tall tube by a slab of two planes,
// smoothly); a storage box 2 high (a shelled rounded box opened by a plane, dividers 11 high cut
// down by a slab of planes). Their true boxes are about [-0.2, 1.2] x [-0.7, 1.2] x [-0.5, 1.2],
// 24 x 1 x 24 and 4.1 x 1.85 x 3.1.
inline std::vector<Scene> clippedScenes() {
    const char* const roots[] = {
        R"({"type": "intersection", "children": [
            {"type": "offset", "distance": 0.2, "children": [{"type": "box", "size": [2, 2, 2]}]},
            {"type": "offset", "distance": 0.2, "children": [
                {"type": "box", "size": [2, 2, 2], "translate": [1, 0.5, 0.7]}]}]})",
        R"({"type": "union", "children": [
            {"type": "intersection", "name": "weave", "children": [
                {"type": "union", "children": [
                    {"type": "repeat", "count": [8, 1, 4], "spacing": [2.7, 1, 5.4], "children": [
                        {"type": "polar_repeat", "count": 3, "radius": 1.5, "children": [
                            {"type": "round_box", "size": [3.2, 0.25, 1], "radius": 0.1}]}]},
                    {"type": "repeat", "count": [8, 1, 4], "spacing": [2.7, 1, 5.4],
                     "translate": [1.35, 0, 2.7], "children": [
                        {"type": "polar_repeat", "count": 3, "radius": 1.5, "children": [
                            {"type": "round_box", "size": [3.2, 0.25, 1], "radius": 0.1}]}]}]},
                {"type": "cylinder", "radius": 10, "height": 40}]},
            {"type": "intersection", "name": "rim", "smooth": 0.25, "children": [
                {"type": "difference", "children": [
                    {"type": "cylinder", "radius": 12, "height": 40},
                    {"type": "cylinder", "radius": 10, "height": 41}]},
                {"type": "plane", "normal": [0, 1, 0], "offset": 0.5},
                {"type": "plane", "normal": [0, -1, 0], "offset": 0.5}]}]})",
        R"({"type": "union", "children": [
            {"type": "intersection", "name": "tray", "children": [
                {"type": "shell", "thickness": 0.1, "children": [
                    {"type": "round_box", "size": [4, 2, 3], "radius": 0.2}]},
                {"type": "plane", "normal": [0, 1, 0], "offset": 0.8}]},
            {"type": "intersection", "name": "dividers", "children": [
                {"type": "union", "children": [
                    {"type": "repeat", "count": [3, 1, 1], "spacing": [1, 1, 1], "children": [
                        {"type": "box", "size": [0.08, 11, 2.95]}]},
                    {"type": "box", "size": [3.95, 11, 0.08]}]},
                {"type": "plane", "normal": [0, 1, 0], "offset": 0.7},
                {"type": "plane", "normal": [0, -1, 0], "offset": 0.95}]}]})",
    };
    const char* const names[] = {"<offset boxes>", "<woven mat>", "<storage box>"};
    std::vector<Scene> scenes;
    for (int i = 0; i < 3; ++i) {
        auto scene =
            parseScene(R"({"version": 1, "root": )" + std::string(roots[i]) + "}", names[i]);
        EXPECT_TRUE(scene) << scene.error().str();
        if (scene) scenes.push_back(std::move(*scene));
    }
    return scenes;
}

// The bundled scenes, assets/scenes/*.json, sorted by name.
inline std::vector<std::filesystem::path> bundledScenePaths() {
    std::vector<std::filesystem::path> paths;
    for (const auto& entry : std::filesystem::directory_iterator(
             std::filesystem::path(SDFCSG_SOURCE_DIR) / "assets/scenes"))
        if (entry.path().extension() == ".json") paths.push_back(entry.path());
    std::sort(paths.begin(), paths.end());
    return paths;
}

} // namespace sdfcsg::test
