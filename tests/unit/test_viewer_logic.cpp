// The viewer's logic without a window: camera, picking, edits, undo, file watching and reload,
// command scripts, preview resolution, mesh drawing, and scene generation against a loopback
// language model (fake_llm_server.h).
#include "document.h"
#include "edit.h"
#include "fake_llm_server.h"
#include "history.h"
#include "orbit_camera.h"
#include "picking.h"
#include "script.h"
#include "workers.h"

#include "render/camera.h" // the renderer's rays, to trace depths as it does

#include <sdfcsg/generate.h>
#include <sdfcsg/io.h>

#include <gtest/gtest.h>

#include <simdjson.h>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

using namespace sdfcsg;
using namespace sdfcsg::viewer;
using sdfcsg::test::FakeServer;
using sdfcsg::test::openAi;
namespace fs = std::filesystem;

namespace {

constexpr const char* kTwoSpheres = R"({
  "version": 1,
  "root": {"type": "union", "name": "all", "children": [
    {"type": "sphere", "name": "left", "radius": 0.5, "translate": [-1, 0, 0]},
    {"type": "difference", "name": "cut", "children": [
      {"type": "box", "name": "block", "size": [1, 1, 1], "translate": [1, 0, 0]},
      {"type": "sphere", "name": "hole", "radius": 0.3, "translate": [1, 0, 0.5]}
    ]}
  ]}
})";

Scene twoSpheres() {
    auto scene = parseScene(kTwoSpheres, "two.json");
    EXPECT_TRUE(scene) << scene.error().str();
    return *scene;
}

void expectNear(glm::vec3 a, glm::vec3 b, float tolerance = 1e-4f) {
    EXPECT_NEAR(a.x, b.x, tolerance);
    EXPECT_NEAR(a.y, b.y, tolerance);
    EXPECT_NEAR(a.z, b.z, tolerance);
}

fs::path tempDir(const std::string& name) {
    fs::path dir = fs::path(SDFCSG_TEST_OUTPUT_DIR) / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

void writeText(const fs::path& path, const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
}

constexpr const char* kRedBall =
    R"({"version": 1, "root": {"type": "sphere", "name": "ball", "radius": 0.75, "color": [1, 0, 0]}})";
constexpr const char* kBadBall = R"({"version": 1, "root": {"type": "sphere", "radius": -1}})";

GenerateOptions fakeModel(const FakeServer& server) {
    GenerateOptions o;
    o.llm.baseUrl = server.url();
    o.llm.proxy = ""; // none from the environment, in front of the loopback
    o.llm.model = "test-model";
    o.llm.timeoutSeconds = 20;
    o.sleep = [](double) {}; // no back-off between retries
    return o;
}

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The worker's result once it has finished; the loopback answers at once, so 30 s is only a
// bound for a stuck test.
std::optional<Result<Generated>> finish(GenerateWorker& worker) {
    const auto start = std::chrono::steady_clock::now();
    while (worker.running() && secondsSince(start) < 30.0)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    return worker.take();
}

// The last message of the n-th request: the request, with the current scene when editing.
std::string userMessage(FakeServer& server, size_t n) {
    simdjson::dom::parser parser;
    simdjson::dom::array messages = parser.parse(server.received().at(n).body)["messages"];
    std::string_view content = messages.at(messages.size() - 1)["content"];
    return std::string(content);
}

Document twoSpheresDocument(const std::string& name) {
    fs::path file = tempDir(name) / "scene.json";
    writeText(file, kTwoSpheres);
    Document doc;
    EXPECT_TRUE(doc.open(file));
    return doc;
}

} // namespace

TEST(ViewerCamera, RoundTripsAScenesCamera) {
    Camera c;
    c.eye = {3, 2, 4};
    c.target = {0.5f, 0.25f, -1};
    c.fov = 40;
    Camera back = toCamera(orbitFromCamera(c));
    expectNear(back.eye, c.eye);
    expectNear(back.target, c.target);
    EXPECT_EQ(back.fov, 40);
}

TEST(ViewerCamera, OrbitKeepsDistanceAndClampsPitch) {
    OrbitCamera c;
    c.distance = 4;
    orbit(c, 1.0f, 0.3f);
    EXPECT_NEAR(glm::length(eyeOf(c) - c.target), 4.0f, 1e-5f);
    orbit(c, 0.0f, 10.0f);
    EXPECT_FLOAT_EQ(c.pitch, kMaxPitch);
    orbit(c, 0.0f, -20.0f);
    EXPECT_FLOAT_EQ(c.pitch, -kMaxPitch);
}

TEST(ViewerCamera, PanMovesTheTargetWithTheCursor) {
    OrbitCamera c; // looking from +z towards -z: right is +x, up is +y
    c.distance = 2;
    c.fov = 90;          // visible height at the target: 2 * 2 * tan(45 deg) = 4
    pan(c, 0.25f, 0.0f); // cursor a quarter of the height to the right: the scene follows it
    expectNear(c.target, {-1, 0, 0});
    pan(c, 0.0f, 0.25f); // and downwards
    expectNear(c.target, {-1, 1, 0});
    expectNear(eyeOf(c), {-1, 1, 2});
}

TEST(ViewerCamera, ZoomAndFrame) {
    OrbitCamera c;
    zoom(c, 0.5f);
    EXPECT_FLOAT_EQ(c.distance, 2.5f);
    zoom(c, 0.0f);
    EXPECT_FLOAT_EQ(c.distance, kMinDistance);
    Aabb box{{1, 1, 1}, {3, 3, 3}};
    frameBox(c, box, 2.0f);
    expectNear(c.target, {2, 2, 2});
    // The bounding sphere fits in the narrower (vertical) field of view.
    float radius = std::sqrt(3.0f);
    EXPECT_NEAR(std::asin(radius / c.distance), glm::radians(c.fov) / 2 / 1.0f, 0.05f);
    EXPECT_GT(std::sin(glm::radians(c.fov) / 2) * c.distance, radius);
    OrbitCamera unchanged = c;
    frameBox(c, Aabb{}, 1.0f); // empty: nothing to frame
    EXPECT_EQ(c.distance, unchanged.distance);
}

TEST(ViewerCamera, FramesTheSolidNotWhatItSubtracts) {
    auto scene = parseScene(R"({"version": 1, "root": {"type": "union", "children": [
        {"type": "plane", "name": "ground"},
        {"type": "difference", "name": "cut", "children": [
          {"type": "box", "size": [1, 1, 1]},
          {"type": "sphere", "name": "far", "radius": 0.5, "translate": [5, 0, 0]}]}]}})",
                            "s.json");
    ASSERT_TRUE(scene) << scene.error().str();
    Evaluator evaluator(*scene);
    Aabb box = framedBounds(evaluator, -1);
    EXPECT_NEAR(box.max.x, 0.5f, 0.01f); // the subtracted sphere at x = 5 is not framed
    EXPECT_NEAR(box.min.x, -0.5f, 0.01f);
    Aabb far = framedBounds(evaluator, int(*findNode(*scene, "far")));
    EXPECT_NEAR(far.min.x, 4.5f, 0.01f); // a selection is framed as it is
    // An unbounded selection (the plane) frames the solid.
    Aabb ground = framedBounds(evaluator, int(*findNode(*scene, "ground")));
    EXPECT_NEAR(ground.max.x, 0.5f, 0.01f);
}

TEST(ViewerPicking, PointFromDepth) {
    Camera camera;
    camera.eye = {0, 0, 5};
    camera.target = {0, 0, 0};
    camera.fov = 45;
    std::vector<PixelInfo> pixels(4 * 4, PixelInfo{-1.0f, 0});
    pixels[1 * 4 + 2] = {4.0f, 10};
    auto p = pickPoint(camera, 4, 4, pixels, 2.3f, 1.9f);
    ASSERT_TRUE(p);
    // The centre of pixel (2, 1): right of and above the image centre, at distance 4.
    EXPECT_NEAR(glm::length(*p - camera.eye), 4.0f, 1e-5f);
    EXPECT_GT(p->x, 0.0f);
    EXPECT_GT(p->y, 0.0f);
    EXPECT_FALSE(pickPoint(camera, 4, 4, pixels, 0.5f, 0.5f)); // a miss
    EXPECT_FALSE(pickPoint(camera, 4, 4, pixels, 4.0f, 0.5f)); // outside
}

TEST(ViewerPicking, PointFromTracedRay) {
    Scene scene = twoSpheres();
    Evaluator evaluator(scene);
    Camera camera;
    camera.eye = {-1, 0, 5};
    camera.target = {-1, 0, 0};
    camera.fov = 45;
    // The image's centre looks at the front of the left sphere (radius 0.5).
    auto p = castRay(evaluator, camera, 64, 48, 32.0f, 24.0f);
    ASSERT_TRUE(p);
    expectNear(*p, {-1.0f, 0.0f, 0.5f}, 1e-3f);
    EXPECT_EQ(nearestPrimitive(evaluator, *p), int(*findNode(scene, "left")));
    EXPECT_FALSE(castRay(evaluator, camera, 64, 48, 1.0f, 1.0f));   // above the spheres: a miss
    EXPECT_FALSE(castRay(evaluator, camera, 64, 48, 64.0f, 24.0f)); // outside
}

TEST(ViewerPicking, NearestPrimitiveIncludingCarvedFaces) {
    Scene scene = twoSpheres();
    Evaluator evaluator(scene);
    EXPECT_EQ(scene.nodes[*findNode(scene, "left")].name, "left");
    EXPECT_EQ(nearestPrimitive(evaluator, {-1.5f, 0, 0}), int(*findNode(scene, "left")));
    EXPECT_EQ(nearestPrimitive(evaluator, {1.5f, 0.2f, 0}), int(*findNode(scene, "block")));
    // Inside the carved hole, on its surface: the sphere that cut it.
    EXPECT_EQ(nearestPrimitive(evaluator, {1.0f, 0.0f, 0.2f}), int(*findNode(scene, "hole")));
}

// Depths as the renderer's march finds them, traced on the CPU along the renderer's rays.
std::vector<PixelInfo> traceDepths(const Evaluator& evaluator, const Camera& camera, uint32_t w,
                                   uint32_t h) {
    detail::RayCamera rc = detail::makeRayCamera(camera, w, h);
    std::vector<PixelInfo> pixels(size_t(w) * h, PixelInfo{-1.0f, 0});
    for (uint32_t j = 0; j < h; ++j)
        for (uint32_t i = 0; i < w; ++i) {
            glm::vec3 dir = detail::rayDirection(rc, float(i) + 0.5f, float(j) + 0.5f, w, h);
            float t = 0.0f;
            for (int step = 0; step < 256 && t < 50.0f; ++step) {
                float d = evaluator.distance(rc.eye + t * dir);
                if (d < detail::hitEpsilon(rc, t)) {
                    pixels[size_t(j) * w + i].depth = t;
                    break;
                }
                t += d;
            }
        }
    return pixels;
}

TEST(ViewerPicking, HighlightCoversTheSelectedSurfaceOnly) {
    Scene scene = twoSpheres();
    Evaluator evaluator(scene);
    Camera camera;
    camera.eye = {0, 0, 6};
    camera.target = {0, 0, 0};
    camera.fov = 40;
    const uint32_t w = 96, h = 64;
    auto pixels = traceDepths(evaluator, camera, w, h);
    auto count = [](const std::vector<uint8_t>& mask) {
        return std::count(mask.begin(), mask.end(), uint8_t(1));
    };
    for (const char* name : {"left", "cut", "hole"}) {
        SCOPED_TRACE(name);
        uint32_t node = *findNode(scene, name);
        PixelRect r = projectedRect(camera, w, h, evaluator.nodes()[node].bounds);
        ASSERT_FALSE(r.empty());
        auto mask = selectionMask(evaluator, node, camera, w, h, pixels);
        long inside = 0;
        for (uint32_t j = 0; j < h; ++j)
            for (uint32_t i = 0; i < w; ++i)
                if (mask[j * w + i]) {
                    // The march takes points within half a pixel of a surface as hits.
                    EXPECT_TRUE(int(i) >= r.x0 - 2 && int(i) < r.x1 + 2 && int(j) >= r.y0 - 2 &&
                                int(j) < r.y1 + 2);
                    ++inside;
                }
        EXPECT_GT(inside, 20) << "the node's visible surface is selected";
    }
    // The left sphere's pixels and the carved block's are apart; the carved face belongs to
    // both the hole and the block's difference.
    auto left = selectionMask(evaluator, *findNode(scene, "left"), camera, w, h, pixels);
    auto cut = selectionMask(evaluator, *findNode(scene, "cut"), camera, w, h, pixels);
    auto hole = selectionMask(evaluator, *findNode(scene, "hole"), camera, w, h, pixels);
    for (size_t k = 0; k < left.size(); ++k) {
        EXPECT_FALSE(left[k] && cut[k]);
        if (hole[k]) {
            EXPECT_TRUE(cut[k]);
        }
    }
    EXPECT_LT(count(hole), count(cut));
    // Every hit pixel belongs to the root.
    auto all = selectionMask(evaluator, 0, camera, w, h, pixels);
    EXPECT_EQ(count(all), std::count_if(pixels.begin(), pixels.end(),
                                        [](const PixelInfo& p) { return p.depth >= 0.0f; }));

    // Tinted inside, outlined around: only pixels in or next to the mask change.
    Image image{w, h, std::vector<uint8_t>(size_t(w) * h * 4, 128)};
    drawHighlight(image, left);
    for (uint32_t j = 0; j < h; ++j)
        for (uint32_t i = 0; i < w; ++i) {
            bool changed = image.rgba[(j * w + i) * 4 + 2] != 128;
            bool near = false;
            for (int dj = -1; dj <= 1; ++dj)
                for (int di = -1; di <= 1; ++di) {
                    int x = int(i) + di, y = int(j) + dj;
                    if ((di == 0 || dj == 0) && x >= 0 && y >= 0 && x < int(w) && y < int(h))
                        near = near || left[size_t(y) * w + x];
                }
            EXPECT_EQ(changed, near) << i << "," << j;
        }
}

TEST(ViewerPicking, ProjectedRectOfBoxes) {
    Camera camera;
    camera.eye = {0, 0, 5};
    camera.target = {0, 0, 0};
    camera.fov = 90;
    // A box at the centre, half as wide as the view at its depth.
    PixelRect r = projectedRect(camera, 100, 100, Aabb{{-1, -1, 0}, {1, 1, 0}});
    EXPECT_NEAR(r.x0, 40, 1); // rounded outwards
    EXPECT_NEAR(r.x1, 60, 1);
    EXPECT_NEAR(r.y0, 40, 1);
    EXPECT_NEAR(r.y1, 60, 1);
    EXPECT_TRUE(projectedRect(camera, 100, 100, Aabb{}).empty());
    EXPECT_TRUE(projectedRect(camera, 100, 100, Aabb{{20, 0, 0}, {21, 1, 1}}).empty());
    PixelRect behind = projectedRect(camera, 100, 100, Aabb{{-1, -1, 4}, {1, 1, 6}});
    EXPECT_EQ(behind.x1 - behind.x0, 100);
}

TEST(ViewerEdit, SetValuesValidatesLikeTheLoader) {
    Scene scene = twoSpheres();
    uint32_t left = *findNode(scene, "left");
    float r[] = {0.75f};
    auto edited = setValue(scene, left, "radius", r);
    ASSERT_TRUE(edited) << edited.error().str();
    EXPECT_FLOAT_EQ(edited->nodes[left].params[0], 0.75f);
    EXPECT_TRUE(sameStructure(scene, *edited));
    float t[] = {0, 2, 0};
    edited = setValue(scene, left, "translate", t);
    ASSERT_TRUE(edited);
    EXPECT_EQ(edited->nodes[left].transform.translate, glm::vec3(0, 2, 0));
    float c[] = {1, 0, 0};
    edited = setValue(scene, left, "color", c);
    ASSERT_TRUE(edited);
    EXPECT_EQ(edited->nodes[left].color, glm::vec3(1, 0, 0));
    edited = setValue(*edited, left, "color", {});
    ASSERT_TRUE(edited);
    EXPECT_FALSE(edited->nodes[left].color);

    float bad[] = {-1.0f};
    auto refused = setValue(scene, left, "radius", bad);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().str(),
              "two.json: root.children[0].radius: expected a positive number, got -1");
    refused = setValue(scene, left, "size", bad);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().str(),
              "two.json: root.children[0]: a sphere has no value \"size\" (it has translate, "
              "rotate, scale, color, radius)");
    refused = setValue(scene, left, "translate", bad);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().str(),
              "two.json: root.children[0]: translate: expected 3 numbers, got 1");
}

TEST(ViewerEdit, StructuralEditsKeepTheSceneValid) {
    Scene scene = twoSpheres();
    uint32_t cut = *findNode(scene, "cut");
    uint32_t added = 0;
    auto grown = addChild(scene, 0, NodeKind::Torus, &added);
    ASSERT_TRUE(grown) << grown.error().str();
    EXPECT_FALSE(sameStructure(scene, *grown));
    EXPECT_EQ(grown->nodes.size(), scene.nodes.size() + 1);
    EXPECT_EQ(grown->nodes[added].kind, NodeKind::Torus);
    EXPECT_EQ(parentOf(*grown, added), 0);

    auto removed = removeNode(scene, *findNode(scene, "hole"));
    ASSERT_TRUE(removed);
    EXPECT_EQ(removed->nodes.size(), scene.nodes.size() - 1);
    EXPECT_FALSE(findNode(*removed, "hole"));
    auto rootRemoved = removeNode(scene, 0);
    ASSERT_FALSE(rootRemoved);
    EXPECT_EQ(rootRemoved.error().str(), "two.json: root: the root cannot be removed");

    auto kind = changeKind(scene, *findNode(scene, "left"), NodeKind::Box);
    ASSERT_TRUE(kind) << kind.error().str();
    EXPECT_EQ(kind->nodes[*findNode(*kind, "left")].kind, NodeKind::Box);
    // Comparable sizes, not the example's: the sphere of radius 0.5 becomes a box 1 across at
    // its widest, and back to a sphere of radius 0.5; a box 1 across becomes a torus about as
    // wide.
    Evaluator sized(*kind);
    Aabb box = sized.nodes()[*findNode(*kind, "left")].bounds;
    const glm::vec3 across = box.max - box.min;
    EXPECT_NEAR(std::max({across.x, across.y, across.z}), 1.0f, 0.01f);
    auto back = changeKind(*kind, *findNode(*kind, "left"), NodeKind::Sphere);
    ASSERT_TRUE(back);
    EXPECT_FLOAT_EQ(back->nodes[*findNode(*back, "left")].params[0], 0.5f);
    float small = 0.1f;
    auto tiny = setValue(scene, *findNode(scene, "left"), "radius", std::span(&small, 1));
    auto tinyBox = changeKind(*tiny, *findNode(*tiny, "left"), NodeKind::Box);
    ASSERT_TRUE(tinyBox);
    const Params& tinySize = tinyBox->nodes[*findNode(*tinyBox, "left")].params;
    EXPECT_FLOAT_EQ(std::max({tinySize[0], tinySize[1], tinySize[2]}), 0.2f);
    auto torus = changeKind(scene, *findNode(scene, "block"), NodeKind::Torus);
    ASSERT_TRUE(torus);
    Aabb ring = Evaluator(*torus).nodes()[*findNode(*torus, "block")].bounds;
    EXPECT_NEAR(ring.max.x - ring.min.x, 1.0f, 0.05f);
    auto op = changeKind(scene, cut, NodeKind::Intersection);
    ASSERT_TRUE(op);
    EXPECT_EQ(op->nodes[cut].kind, NodeKind::Intersection);
    auto mixed = changeKind(scene, cut, NodeKind::Sphere);
    ASSERT_FALSE(mixed);
    EXPECT_EQ(mixed.error().str(),
              "two.json: root.children[1]: an operation can only become another operation");

    uint32_t moved = 0;
    auto reordered = moveNode(scene, *findNode(scene, "hole"), -1, &moved);
    ASSERT_TRUE(reordered);
    EXPECT_EQ(reordered->nodes[moved].name, "hole");
    EXPECT_EQ(reordered->nodes[reordered->nodes[cut].children[0]].name, "hole");
}

TEST(ViewerEdit, EveryKindCanBeAddedWithItsDefaults) {
    const Scene scene = twoSpheres();
    for (const KindInfo& kind : nodeKinds()) {
        SCOPED_TRACE(std::string(kind.name));
        uint32_t added = 0;
        auto grown = addChild(scene, 0, kind.kind, &added);
        ASSERT_TRUE(grown) << grown.error().str();
        EXPECT_EQ(grown->nodes[added].kind, kind.kind);
        // A value or domain operation takes one child: a second is refused by the validator.
        if (kind.operation && kind.role != Role::Boolean) {
            auto second = addChild(*grown, added, NodeKind::Sphere);
            ASSERT_FALSE(second);
            EXPECT_NE(second.error().str().find("expected exactly one child node"),
                      std::string::npos)
                << second.error().str();
        }
    }
}

constexpr const char* kGroups = R"({
  "version": 1,
  "root": {"type": "union", "name": "all", "children": [
    {"type": "sphere", "name": "a", "radius": 0.5},
    {"type": "union", "name": "group", "translate": [0, 1, 0], "children": [
      {"type": "sphere", "name": "b", "radius": 0.4},
      {"type": "intersection", "name": "inner", "children": [
        {"type": "sphere", "name": "c", "radius": 0.5},
        {"type": "box", "name": "d", "size": [0.6, 0.6, 0.6]}
      ]}
    ]},
    {"type": "difference", "name": "cut", "children": [
      {"type": "box", "name": "block", "size": [1, 1, 1]},
      {"type": "sphere", "name": "hole", "radius": 0.3}
    ]},
    {"type": "union", "name": "solo", "children": [{"type": "sphere", "name": "e", "radius": 0.2}]}
  ]}
})";

// The names of a node's children, in order.
std::vector<std::string> childNames(const Scene& scene, std::string_view node) {
    std::vector<std::string> names;
    for (uint32_t c : scene.nodes[*findNode(scene, node)].children)
        names.push_back(scene.nodes[c].name);
    return names;
}

using Names = std::vector<std::string>;

TEST(ViewerEdit, ReparentMovesASubtreeIntoAnotherOperation) {
    auto loaded = parseScene(kGroups, "g.json");
    ASSERT_TRUE(loaded) << loaded.error().str();
    const Scene& s = *loaded;
    auto at = [&](std::string_view name) { return *findNode(s, name); };

    // Into a sibling union, last: the new index is the moved node's, its path the new one.
    uint32_t moved = 0;
    auto edited = reparentNode(s, at("a"), at("group"), kLastChild, &moved);
    ASSERT_TRUE(edited) << edited.error().str();
    EXPECT_EQ(edited->nodes[moved].name, "a");
    EXPECT_EQ(edited->nodes[moved].path, "root.children[0].children[2]");
    EXPECT_EQ(childNames(*edited, "group"), (Names{"b", "inner", "a"}));
    EXPECT_EQ(childNames(*edited, "all"), (Names{"group", "cut", "solo"}));
    // The transform stays the node's own, now relative to the new parent.
    EXPECT_EQ(edited->nodes[moved].transform.translate, glm::vec3(0));

    // Into a different subtree, with its own subtree, at a position.
    edited = reparentNode(s, at("inner"), at("cut"), 1, &moved);
    ASSERT_TRUE(edited) << edited.error().str();
    EXPECT_EQ(edited->nodes[moved].name, "inner");
    EXPECT_EQ(edited->nodes[moved].path, "root.children[2].children[1]");
    EXPECT_EQ(childNames(*edited, "cut"), (Names{"block", "inner", "hole"}));
    EXPECT_EQ(childNames(*edited, "inner"), (Names{"c", "d"}));
    EXPECT_EQ(childNames(*edited, "group"), (Names{"b"}));

    // At position 0 of a difference: the node becomes what the others are cut from.
    edited = reparentNode(s, at("a"), at("cut"), 0, &moved);
    ASSERT_TRUE(edited) << edited.error().str();
    EXPECT_EQ(edited->nodes[moved].path, "root.children[1].children[0]");
    EXPECT_EQ(childNames(*edited, "cut"), (Names{"a", "block", "hole"}));
    EXPECT_FALSE(sameStructure(s, *edited));

    // Within its own parent, a reorder; the last position counts the moved node.
    edited = reparentNode(s, at("hole"), at("cut"), 0, &moved);
    ASSERT_TRUE(edited) << edited.error().str();
    EXPECT_EQ(childNames(*edited, "cut"), (Names{"hole", "block"}));
    edited = reparentNode(s, at("block"), at("cut"), 1);
    ASSERT_TRUE(edited) << edited.error().str();
    EXPECT_EQ(childNames(*edited, "cut"), (Names{"hole", "block"}));
}

TEST(ViewerEdit, ReparentRefusals) {
    auto loaded = parseScene(kGroups, "g.json");
    ASSERT_TRUE(loaded) << loaded.error().str();
    const Scene& s = *loaded;
    auto at = [&](std::string_view name) { return *findNode(s, name); };
    auto refused = [&](std::string_view node, std::string_view parent, uint32_t position) {
        auto r = reparentNode(s, at(node), at(parent), position);
        return r ? std::string("accepted") : r.error().str();
    };
    EXPECT_EQ(refused("all", "group", kLastChild), "g.json: root: the root cannot be moved");
    EXPECT_EQ(refused("group", "group", kLastChild),
              "g.json: root.children[1]: a node cannot be moved into itself");
    EXPECT_EQ(refused("group", "inner", 0),
              "g.json: root.children[1]: a node cannot be moved into its own subtree "
              "(root.children[1].children[1])");
    EXPECT_EQ(refused("a", "b", kLastChild),
              "g.json: root.children[1].children[0]: only an operation can take children");
    EXPECT_EQ(refused("e", "cut", kLastChild),
              "g.json: root.children[3].children[0]: an operation needs at least one child; "
              "move or remove the operation instead");
    EXPECT_EQ(refused("a", "cut", 3), "g.json: root.children[2]: child position 3 is past the "
                                      "end (0 to 2)");
    EXPECT_EQ(refused("hole", "cut", 2), "g.json: root.children[2]: child position 2 is past "
                                         "the end (0 to 1)");
    auto missing = reparentNode(s, 99, 0, kLastChild);
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().str(), "g.json: no node 99 (the scene has 12)");
}

TEST(ViewerEdit, DropReparentsOrReorders) {
    auto loaded = parseScene(kGroups, "g.json");
    ASSERT_TRUE(loaded) << loaded.error().str();
    const Scene& s = *loaded;
    auto at = [&](std::string_view name) { return *findNode(s, name); };
    uint32_t moved = 0;
    // Onto an operation: its last child.
    auto edited = dropNode(s, at("hole"), at("group"), &moved);
    ASSERT_TRUE(edited) << edited.error().str();
    EXPECT_EQ(edited->nodes[moved].name, "hole");
    EXPECT_EQ(childNames(*edited, "group"), (Names{"b", "inner", "hole"}));
    // Onto a primitive: just before it, from another parent or from the same one, either way.
    edited = dropNode(s, at("a"), at("hole"), &moved);
    ASSERT_TRUE(edited) << edited.error().str();
    EXPECT_EQ(edited->nodes[moved].name, "a");
    EXPECT_EQ(childNames(*edited, "cut"), (Names{"block", "a", "hole"}));
    edited = dropNode(s, at("hole"), at("block"));
    ASSERT_TRUE(edited) << edited.error().str();
    EXPECT_EQ(childNames(*edited, "cut"), (Names{"hole", "block"}));
    edited = dropNode(s, at("a"), at("solo"));
    ASSERT_TRUE(edited) << edited.error().str();
    EXPECT_EQ(childNames(*edited, "all"), (Names{"group", "cut", "solo"}));
    EXPECT_EQ(childNames(*edited, "solo"), (Names{"e", "a"}));
    edited = dropNode(s, at("c"), at("b"));
    ASSERT_TRUE(edited) << edited.error().str();
    EXPECT_EQ(childNames(*edited, "group"), (Names{"c", "b", "inner"}));
    EXPECT_EQ(childNames(*edited, "inner"), (Names{"d"}));
    // A drop that would put an operation inside itself is refused as reparenting is.
    auto refused = dropNode(s, at("inner"), at("c"));
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().str(),
              "g.json: root.children[1].children[1]: a node cannot be moved into itself");
}

TEST(ViewerEdit, UndoRestoresTheSceneBeforeAReparent) {
    auto loaded = parseScene(kGroups, "g.json");
    ASSERT_TRUE(loaded) << loaded.error().str();
    const std::string before = toJson(*loaded);
    History history(*loaded);
    auto edited = reparentNode(history.current(), *findNode(history.current(), "inner"),
                               *findNode(history.current(), "cut"), 0);
    ASSERT_TRUE(edited) << edited.error().str();
    history.push(std::move(*edited));
    EXPECT_NE(toJson(history.current()), before);
    ASSERT_TRUE(history.undo());
    EXPECT_EQ(toJson(history.current()), before);
    ASSERT_TRUE(history.redo());
    EXPECT_EQ(childNames(history.current(), "cut"), (Names{"inner", "block", "hole"}));
}

// A use is edited as the file has it: its transform, colour and parameters; its copy, made by the
// loader from the definition, is refused.
TEST(ViewerEdit, UsesAreEditedAndTheirCopiesRefused) {
    auto loaded = parseScene(R"({"version": 1,
      "definitions": {"leg": {"parameters": {"height": 1.0, "radius": 0.1},
                              "node": {"type": "cylinder", "height": "$height", "radius": "$radius"}}},
      "root": {"type": "union", "children": [
        {"type": "use", "definition": "leg", "name": "front leg", "translate": [1, 0, 0]},
        {"type": "use", "definition": "leg", "translate": [-1, 0, 0]},
        {"type": "sphere", "name": "ball", "radius": 0.3}]}})",
                             "uses.json");
    ASSERT_TRUE(loaded) << loaded.error().str();
    const Scene scene = *loaded;
    const uint32_t front = *findNode(scene, "front leg");
    const uint32_t copy = scene.nodes[front].children[0];
    const uint32_t other = scene.nodes[0].children[1];
    EXPECT_EQ(nodeLabel(scene, front), "front leg (use of leg)");
    EXPECT_EQ(nodeLabel(scene, other), "use of leg");
    EXPECT_EQ(copyingUse(scene, copy), int(front));
    EXPECT_EQ(copyingUse(scene, front), -1);

    float height[] = {2.5f};
    auto taller = setValue(scene, front, "height", height);
    ASSERT_TRUE(taller) << taller.error().str();
    EXPECT_FLOAT_EQ(taller->nodes[taller->nodes[front].children[0]].params[1], 2.5f);
    EXPECT_EQ(taller->nodes[front].use->arguments, (std::vector<NamedValue>{{"height", "2.5"}}));
    EXPECT_FLOAT_EQ(taller->nodes[taller->nodes[other].children[0]].params[1], 1.0f);
    EXPECT_EQ(taller->definitions, scene.definitions);
    float t[] = {0, 2, 0};
    auto moved = setValue(scene, front, "translate", t);
    ASSERT_TRUE(moved);
    EXPECT_EQ(moved->nodes[front].transform.translate, glm::vec3(0, 2, 0));
    float negative[] = {-1.0f};
    auto refused = setValue(scene, front, "radius", negative);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().str(), "uses.json: definitions.leg.node.radius: expected a positive "
                                     "number, got -1 (in the use of \"leg\" at root.children[0])");
    refused = setValue(scene, front, "smooth", height);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().str(),
              "uses.json: root.children[0]: a use has no value \"smooth\" (it has translate, "
              "rotate, scale, color and the parameters of \"leg\": height, radius)");

    const std::string inCopy =
        "uses.json: definitions.leg.node: this node lies in the copy that the use of \"leg\" at "
        "root.children[0] makes; change the definitions in the scene file, or the use's "
        "parameters";
    refused = setValue(scene, copy, "height", height);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().str(), inCopy);
    EXPECT_EQ(removeNode(scene, copy).error().str(), inCopy);
    EXPECT_EQ(changeKind(scene, copy, NodeKind::Box).error().str(), inCopy);
    EXPECT_EQ(moveNode(scene, copy, 1).error().str(), inCopy);
    EXPECT_EQ(reparentNode(scene, copy, 0, kLastChild).error().str(), inCopy);
    EXPECT_EQ(addChild(scene, front, NodeKind::Sphere).error().str(),
              "uses.json: root.children[0]: only an operation can take children");
    EXPECT_EQ(changeKind(scene, front, NodeKind::Intersection).error().str(),
              "uses.json: root.children[0]: a use is a copy of its definition and has no kind to "
              "change");

    // Dropped on a use, a node goes before it; the use itself moves and goes like any node.
    uint32_t dropped = 0;
    auto before = dropNode(scene, *findNode(scene, "ball"), front, &dropped);
    ASSERT_TRUE(before) << before.error().str();
    EXPECT_EQ(before->nodes[before->nodes[0].children[0]].name, "ball");
    auto removed = removeNode(scene, front);
    ASSERT_TRUE(removed) << removed.error().str();
    EXPECT_EQ(removed->nodes.size(), scene.nodes.size() - 2);
    EXPECT_NE(toJson(*removed).find("\"definitions\""), std::string::npos);
}

TEST(ViewerEdit, SameNodeAfterAReload) {
    Scene before = twoSpheres();
    // Named nodes are found by name wherever they moved; unnamed ones by their JSON path.
    auto after = parseScene(R"({"version": 1, "root": {"type": "union", "children": [
        {"type": "box", "name": "block", "size": [1, 1, 1]},
        {"type": "sphere", "radius": 1},
        {"type": "sphere", "name": "left", "radius": 0.5}]}})",
                            "two.json");
    ASSERT_TRUE(after);
    EXPECT_EQ(sameNode(before, *findNode(before, "left"), *after), findNode(*after, "left"));
    EXPECT_EQ(sameNode(before, *findNode(before, "block"), *after), findNode(*after, "block"));
    EXPECT_FALSE(sameNode(before, *findNode(before, "hole"), *after));
    auto unnamed = parseScene(R"({"version": 1, "root": {"type": "union", "children": [
        {"type": "sphere", "radius": 1}, {"type": "box", "size": [1, 1, 1]}]}})",
                              "u.json");
    ASSERT_TRUE(unnamed);
    float r = 2.0f;
    auto resized = setValue(*unnamed, 1, "radius", std::span(&r, 1));
    EXPECT_EQ(sameNode(*unnamed, 1, *resized), 1u);
    EXPECT_EQ(sameNode(*unnamed, 2, *resized), 2u);
    EXPECT_FALSE(sameNode(*unnamed, 2, *after)); // root.children[1] is a sphere there
}

TEST(ViewerHistory, UndoRedoAndMergedSteps) {
    Scene a = twoSpheres();
    History history(a);
    EXPECT_FALSE(history.canUndo());
    float r = 0.6f;
    for (int i = 0; i < 5; ++i, r += 0.1f) // one slider drag
        history.push(*setValue(history.current(), 1, "radius", std::span(&r, 1)), "1radius");
    history.endMerge();
    EXPECT_EQ(history.size(), 2u);
    EXPECT_FLOAT_EQ(history.current().nodes[1].params[0], 1.0f);
    history.push(*removeNode(history.current(), *findNode(history.current(), "hole")));
    EXPECT_EQ(history.size(), 3u);
    ASSERT_TRUE(history.undo());
    EXPECT_TRUE(findNode(history.current(), "hole"));
    ASSERT_TRUE(history.undo());
    EXPECT_FLOAT_EQ(history.current().nodes[1].params[0], 0.5f);
    EXPECT_FALSE(history.undo());
    ASSERT_TRUE(history.redo());
    EXPECT_FLOAT_EQ(history.current().nodes[1].params[0], 1.0f);
    // A new step drops what could be redone.
    history.push(a);
    EXPECT_FALSE(history.canRedo());
    EXPECT_EQ(history.size(), 3u);
}

TEST(ViewerHistory, KeepsAtMostTheLimit) {
    History history(twoSpheres(), 4);
    for (int i = 0; i < 10; ++i)
        history.push(twoSpheres());
    EXPECT_EQ(history.size(), 4u);
    int undos = 0;
    while (history.undo())
        ++undos;
    EXPECT_EQ(undos, 3);
}

TEST(ViewerFiles, WatcherReportsEachChangeOnce) {
    fs::path dir = tempDir("viewer_watch");
    fs::path file = dir / "scene.json";
    writeText(file, "one");
    FileWatcher watcher(file);
    EXPECT_FALSE(watcher.poll());
    writeText(file, "three"); // a different size, whatever the clock's resolution
    EXPECT_TRUE(watcher.poll());
    EXPECT_FALSE(watcher.poll());
    fs::last_write_time(file, fs::last_write_time(file) + std::chrono::seconds(5));
    EXPECT_TRUE(watcher.poll());
    fs::remove(file);
    EXPECT_FALSE(watcher.poll()); // gone: nothing to load
    writeText(file, "back");
    EXPECT_TRUE(watcher.poll());
}

TEST(ViewerFiles, ReloadKeepsTheLastGoodScene) {
    fs::path dir = tempDir("viewer_reload");
    fs::path file = dir / "scene.json";
    writeText(file, kTwoSpheres);
    Document doc;
    ASSERT_TRUE(doc.open(file));
    EXPECT_EQ(doc.scene().nodes.size(), 5u);
    EXPECT_FALSE(doc.pollReload());

    // Broken on disk: the scene stays, the error is kept.
    writeText(file, R"({"version": 1, "root": {"type": "sphere", "radius": -2}})");
    uint64_t before = doc.version();
    EXPECT_TRUE(doc.pollReload());
    EXPECT_GT(doc.version(), before);
    ASSERT_TRUE(doc.error());
    EXPECT_EQ(doc.error()->str(),
              file.string() + ": root.radius: expected a positive number, got -2");
    EXPECT_EQ(doc.scene().nodes.size(), 5u);

    // Fixed on disk: loaded, and the change can be undone.
    writeText(file, R"({"version": 1, "root": {"type": "sphere", "radius": 2}})");
    EXPECT_TRUE(doc.pollReload());
    EXPECT_FALSE(doc.error());
    EXPECT_EQ(doc.scene().nodes.size(), 1u);
    ASSERT_TRUE(doc.history().undo());
    EXPECT_EQ(doc.scene().nodes.size(), 5u);
}

// An ASCII STL of the tetrahedron of the origin and the three axes' points at `size`.
std::string tetrahedronStl(float size) {
    const std::string a = "0 0 0", b = std::to_string(size) + " 0 0",
                      c = "0 " + std::to_string(size) + " 0", d = "0 0 " + std::to_string(size);
    std::string stl = "solid t\n";
    for (const auto& [p, q, r] : {std::array{a, c, b}, {a, b, d}, {a, d, c}, {b, c, d}})
        stl += "facet normal 0 0 0\nouter loop\nvertex " + p + "\nvertex " + q + "\nvertex " + r +
               "\nendloop\nendfacet\n";
    return stl + "endsolid t\n";
}

TEST(ViewerFiles, AChangedMeshFileParsesTheSceneAgain) {
    fs::path dir = tempDir("viewer_reads");
    writeText(dir / "part.stl", tetrahedronStl(1));
    writeText(dir / "scene.json", R"({"version": 1, "root": {"type": "union", "children": [
        {"type": "sphere", "radius": 0.2},
        {"type": "mesh", "file": "part.stl", "resolution": 16}]}})");
    Document doc;
    ASSERT_TRUE(doc.open(dir / "scene.json"));
    EXPECT_EQ(filesRead(doc.scene()), std::vector<fs::path>{dir / "part.stl"});
    const auto before = doc.scene().nodes[2].words;
    ASSERT_TRUE(before);
    EXPECT_FALSE(doc.pollReload()); // the first poll starts watching the mesh
    EXPECT_FALSE(doc.pollReload());

    // Another mesh in the file: the node's field is made again, as one more step.
    writeText(dir / "part.stl", tetrahedronStl(2));
    fs::last_write_time(dir / "part.stl",
                        fs::last_write_time(dir / "part.stl") + std::chrono::seconds(5));
    EXPECT_TRUE(doc.pollReload());
    EXPECT_FALSE(doc.error());
    ASSERT_TRUE(doc.scene().nodes[2].words);
    EXPECT_NE(*doc.scene().nodes[2].words, *before);
    EXPECT_FALSE(doc.pollReload());
    ASSERT_TRUE(doc.history().undo());
    EXPECT_EQ(doc.scene().nodes[2].words, before);

    // A broken mesh keeps the scene, and says why.
    writeText(dir / "part.stl", "solid t\nendsolid t\n");
    EXPECT_TRUE(doc.pollReload());
    ASSERT_TRUE(doc.error());
    EXPECT_NE(doc.error()->str().find("root.children[1].file: cannot load mesh"), std::string::npos)
        << doc.error()->str();
    EXPECT_EQ(doc.scene().nodes[2].words, before);
}

TEST(ViewerFiles, SaveIsAtomicAndNotReloaded) {
    fs::path dir = tempDir("viewer_save");
    fs::path file = dir / "scene.json";
    writeText(file, kTwoSpheres);
    Document doc;
    ASSERT_TRUE(doc.open(file));
    float r = 0.25f;
    doc.history().push(*setValue(doc.scene(), 1, "radius", std::span(&r, 1)));
    ASSERT_TRUE(doc.save());
    EXPECT_FALSE(doc.pollReload()); // our own write is not a change from outside
    auto back = loadScene(file);
    ASSERT_TRUE(back);
    EXPECT_FLOAT_EQ(back->nodes[1].params[0], 0.25f);
    for (const auto& e : fs::directory_iterator(dir))
        EXPECT_EQ(e.path().filename(), "scene.json");

    auto failed = doc.save(dir / "missing" / "x.json");
    ASSERT_FALSE(failed);
    EXPECT_EQ(failed.error().kind, ErrorKind::Io);
}

TEST(ViewerFiles, OpenFailureKeepsTheCurrentSceneAndItsFile) {
    fs::path dir = tempDir("viewer_open");
    writeText(dir / "good.json", kTwoSpheres);
    writeText(dir / "bad.json", "{");
    Document doc;
    ASSERT_TRUE(doc.open(dir / "good.json"));
    EXPECT_FALSE(doc.open(dir / "bad.json"));
    EXPECT_TRUE(doc.error());
    EXPECT_EQ(doc.scene().nodes.size(), 5u);
    EXPECT_EQ(doc.path(), dir / "good.json");

    // Saving writes the scene on screen to its own file, never over the broken one, and
    // the stale load error goes.
    ASSERT_TRUE(doc.save());
    EXPECT_FALSE(doc.error());
    std::ifstream bad(dir / "bad.json");
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(bad), {}), "{");
    EXPECT_TRUE(loadScene(dir / "good.json"));

    // The scene's file is still the one watched.
    writeText(dir / "bad.json", R"({"version": 1, "root": {"type": "box", "size": 1}})");
    EXPECT_FALSE(doc.pollReload());
    writeText(dir / "good.json", R"({"version": 1, "root": {"type": "sphere", "radius": 1}})");
    EXPECT_TRUE(doc.pollReload());
    EXPECT_FALSE(doc.error());
    EXPECT_EQ(doc.scene().nodes.size(), 1u);
}

TEST(ViewerFiles, RecentFilesPersist) {
    fs::path dir = tempDir("viewer_recent");
    fs::path file = dir / "config" / "sdfcsg" / "recent";
    EXPECT_TRUE(loadRecent(file).empty());
    saveRecent(file, {"/a/one.json", "two.json"});
    EXPECT_EQ(loadRecent(file), (std::vector<std::string>{"/a/one.json", "two.json"}));
    EXPECT_EQ(loadRecent(file, 1), std::vector<std::string>{"/a/one.json"});
    writeText(dir / "blocker", "a file, not a folder");
    saveRecent(dir / "blocker" / "recent", {"a"}); // cannot be written: ignored
    EXPECT_EQ(recentFilesPath((dir / "config").c_str(), "/home/someone"), file);
    EXPECT_EQ(recentFilesPath("", "/home/someone"), "/home/someone/.config/sdfcsg/recent");
    EXPECT_EQ(recentFilesPath(nullptr, nullptr), fs::path());
}

TEST(ViewerFiles, ABrokenFirstFileIsWatched) {
    fs::path dir = tempDir("viewer_open_first");
    writeText(dir / "bad.json", "{");
    Document doc;
    EXPECT_FALSE(doc.open(dir / "bad.json"));
    EXPECT_FALSE(doc.loaded());
    // Nothing else to show: fixing the file on disk loads it.
    writeText(dir / "bad.json", R"({"version": 1, "root": {"type": "sphere", "radius": 1}})");
    EXPECT_TRUE(doc.pollReload());
    EXPECT_FALSE(doc.error());
    EXPECT_EQ(doc.scene().nodes.size(), 1u);
}

TEST(ViewerScript, ParsesCommands) {
    auto script = parseScript("# a comment\nselect nose\n\nset translate 0 1 -2.5  # move\n"
                              "mode depth\norbit 30 -10\nscreenshot out.png\n",
                              "s.txt");
    ASSERT_TRUE(script) << script.error().str();
    ASSERT_EQ(script->size(), 5u);
    EXPECT_EQ((*script)[0].verb, "select");
    EXPECT_EQ((*script)[0].args, std::vector<std::string>{"nose"});
    EXPECT_EQ((*script)[1].line, 4);
    EXPECT_EQ((*script)[1].args[0], "translate");
    EXPECT_EQ((*script)[1].numbers, (std::vector<float>{0, 1, -2.5f}));
    EXPECT_EQ((*script)[3].numbers, (std::vector<float>{30, -10}));
}

TEST(ViewerScript, ReportsEveryProblem) {
    auto script = parseScript("mode shiny\nfly away\nset radius big\nzoom\nundo now\n", "s.txt");
    ASSERT_FALSE(script);
    EXPECT_EQ(script.error().str(),
              "s.txt:1:1: mode: expected one of shaded, normals, depth, steps, got \"shiny\"\n"
              "s.txt:2:1: unknown command \"fly\" (known: select, set, mode, shadows, ao, grid, "
              "boxes, orbit, drag, zoom, frame, reset, undo, redo, save, screenshot, generate, "
              "edit-scene, add, remove, kind, op, move, parent, open, pick, wait-reload, ui, "
              "expect-error, expect-selected, print-bounds, print-notes, mesh, view, wireframe, "
              "thin-walls)\n"
              "s.txt:3:1: set: expected a finite number, got \"big\"\n"
              "s.txt:4:1: zoom: expected 1 arguments, got 0\n"
              "s.txt:5:1: undo: expected 0 arguments, got 1");
}

TEST(ViewerScript, RefusesNumbersThatAreNotFinite) {
    auto script = parseScript("orbit nan nan\nzoom inf\nset radius -inf\npick 1e99 2\nzoom 0\n"
                              "op sphere\nkind union\nadd torus\nmove up\n",
                              "s.txt");
    ASSERT_FALSE(script);
    EXPECT_EQ(script.error().str(),
              "s.txt:1:1: orbit: expected a finite number, got \"nan\"\n"
              "s.txt:2:1: zoom: expected a finite number, got \"inf\"\n"
              "s.txt:3:1: set: expected a finite number, got \"-inf\"\n"
              "s.txt:4:1: pick: expected a finite number, got \"1e99\"\n"
              "s.txt:5:1: zoom: expected a positive factor, got \"0\"\n"
              "s.txt:6:1: op: expected one of union, intersection, "
              "difference, transition_linear, transition_radial, shell, offset, repeat, "
              "polar_repeat, mirror, "
              "elongate, twist, bend, taper, bend_linear, extrude, revolve, got "
              "\"sphere\"");
}

TEST(ViewerScript, ParentTakesANodeAndAPosition) {
    auto script = parseScript("parent group\nparent cut 0\n", "s.txt");
    ASSERT_TRUE(script) << script.error().str();
    ASSERT_EQ(script->size(), 2u);
    EXPECT_EQ((*script)[0].args, std::vector<std::string>{"group"});
    EXPECT_TRUE((*script)[0].numbers.empty());
    EXPECT_EQ((*script)[1].numbers, std::vector<float>{0});
    auto bad = parseScript("parent\nparent cut -1\nparent cut 1.5\nparent cut 1 2\n", "s.txt");
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().str(),
              "s.txt:1:1: parent: expected 1 to 2 arguments, got 0\n"
              "s.txt:2:1: parent: expected a whole number for the child's position, got \"-1\"\n"
              "s.txt:3:1: parent: expected a whole number for the child's position, got \"1.5\"\n"
              "s.txt:4:1: parent: expected 1 to 2 arguments, got 3");
}

TEST(ViewerScript, GenerateTakesTheRestOfTheLine) {
    auto script = parseScript("generate a red  ball on a box   # not sent\n"
                              "edit-scene\tmake the ball blue\r\n",
                              "s.txt");
    ASSERT_TRUE(script) << script.error().str();
    ASSERT_EQ(script->size(), 2u);
    EXPECT_EQ((*script)[0].verb, "generate");
    EXPECT_EQ((*script)[0].text, "a red  ball on a box");
    EXPECT_EQ((*script)[1].verb, "edit-scene");
    EXPECT_EQ((*script)[1].text, "make the ball blue");
}

TEST(ViewerScript, GenerateNeedsADescription) {
    auto script = parseScript("generate\nedit-scene    # nothing to say\n", "s.txt");
    ASSERT_FALSE(script);
    EXPECT_EQ(script.error().str(), "s.txt:1:1: generate: expected a description of the scene\n"
                                    "s.txt:2:1: edit-scene: expected a description of the change");
}

TEST(ViewerGenerate, WorkerYieldsTheSceneAndChangesNothingItself) {
    FakeServer server;
    server.script({openAi(kRedBall)});
    Document doc = twoSpheresDocument("viewer_generate");
    const std::string before = toJson(doc.scene());
    const uint64_t version = doc.version();
    GenerateWorker worker;
    ASSERT_TRUE(worker.start("a red ball", "", fakeModel(server)));
    auto done = finish(worker);
    ASSERT_TRUE(done);
    ASSERT_TRUE(*done) << done->error().str();
    EXPECT_EQ((*done)->json, toJson(*parseScene(kRedBall)));
    EXPECT_EQ((*done)->scene.nodes.size(), 1u);
    EXPECT_FALSE(worker.take()); // handed over once
    EXPECT_FALSE(worker.running());
    EXPECT_EQ(worker.status().message, "asking test-model (json_schema)");
    EXPECT_TRUE(worker.stats().firstTryValid);
    EXPECT_EQ(userMessage(server, 0), sceneUserPrompt("a red ball"));
    EXPECT_EQ(toJson(doc.scene()), before);
    EXPECT_EQ(doc.version(), version);
}

TEST(ViewerGenerate, AnEditIsOneUndoStep) {
    FakeServer server;
    server.script({openAi(kRedBall)});
    Document doc = twoSpheresDocument("viewer_generate_edit");
    const fs::path file = doc.path();
    const std::string before = toJson(doc.scene());
    GenerateWorker worker;
    ASSERT_TRUE(worker.start("make it one red ball", before, fakeModel(server)));
    auto done = finish(worker);
    ASSERT_TRUE(done && *done);
    EXPECT_EQ(userMessage(server, 0), sceneUserPrompt("make it one red ball", before));

    const uint64_t version = doc.version();
    const std::string generated = (*done)->json;
    doc.replace(std::move((*done)->scene));
    EXPECT_EQ(toJson(doc.scene()), generated);
    EXPECT_GT(doc.version(), version);
    EXPECT_EQ(doc.path(), file); // saving still writes the file that was opened
    ASSERT_TRUE(doc.history().undo());
    EXPECT_EQ(toJson(doc.scene()), before);
    ASSERT_TRUE(doc.history().redo());
    EXPECT_EQ(toJson(doc.scene()), generated);

    // A viewer started without a file: the generated scene is where its history begins.
    Document empty;
    empty.replace(*parseScene(kRedBall));
    EXPECT_TRUE(empty.loaded());
    EXPECT_EQ(toJson(empty.scene()), generated);
    EXPECT_FALSE(empty.history().canUndo());
}

TEST(ViewerGenerate, AnAnswerThatNeverLoadsIsAnError) {
    FakeServer server;
    server.script({openAi(kBadBall), openAi(kBadBall)});
    Document doc = twoSpheresDocument("viewer_generate_bad");
    const std::string before = toJson(doc.scene());
    const uint64_t version = doc.version();
    GenerateOptions o = fakeModel(server);
    o.maxRepairs = 1;
    GenerateWorker worker;
    ASSERT_TRUE(worker.start("a ball", before, o));
    auto done = finish(worker);
    ASSERT_TRUE(done);
    ASSERT_FALSE(*done);
    EXPECT_EQ(done->error().kind, ErrorKind::Validation);
    EXPECT_EQ(done->error().str(),
              "answer: no answer loaded after 1 repair round; the last one's problems:\n"
              "answer: root.radius: expected a positive number, got -1");
    EXPECT_EQ(server.received().size(), 2u);
    EXPECT_EQ(toJson(doc.scene()), before);
    EXPECT_EQ(doc.version(), version);
    EXPECT_FALSE(doc.history().canUndo());
}

TEST(ViewerGenerate, CancelStopsAWaitingRequest) {
    FakeServer server;
    server.script({{200, "{}", "", true}}); // answers only after 20 s
    GenerateWorker worker;
    ASSERT_TRUE(worker.start("a ball", "", fakeModel(server)));
    ASSERT_TRUE(server.awaitRequests(1));
    EXPECT_TRUE(worker.running());
    EXPECT_FALSE(worker.start("another ball", "", fakeModel(server))); // one at a time
    const auto start = std::chrono::steady_clock::now();
    worker.cancel();
    auto done = finish(worker);
    EXPECT_LT(secondsSince(start), 10.0); // libcurl asks about once a second
    ASSERT_TRUE(done);
    ASSERT_FALSE(*done);
    EXPECT_EQ(done->error().kind, ErrorKind::Cancelled);
    EXPECT_EQ(done->error().str(), server.url() + "/chat/completions: cancelled");
}

TEST(ViewerResolution, PreviewScaleAimsAtTheTargetTime) {
    // 0.4 s for a full 1000 x 1000 frame: 0.1 s wants a quarter of the pixels, half of each axis.
    EXPECT_NEAR(previewScale(0.4, 1000000, 1000000, 0.1), 0.5f, 1e-6f);
    EXPECT_FLOAT_EQ(previewScale(0.001, 1000000, 1000000, 0.1), 1.0f);
    EXPECT_FLOAT_EQ(previewScale(100.0, 1000000, 1000000, 0.1), 0.125f);
    EXPECT_FLOAT_EQ(previewScale(0.0, 0, 1000000, 0.1), 0.5f);
}

TEST(ViewerScript, MeshCommands) {
    auto script = parseScript("mesh extract 64\nview mesh\nwireframe on\nmesh export out.obj\n"
                              "view march\nmesh extract 96 mc\nmesh extract 32 dc 0.25\n",
                              "s.txt");
    ASSERT_TRUE(script) << script.error().str();
    ASSERT_EQ(script->size(), 7u);
    EXPECT_EQ((*script)[0].numbers, (std::vector<float>{64, 0}));
    EXPECT_EQ((*script)[3].args, (std::vector<std::string>{"export", "out.obj"}));
    EXPECT_EQ((*script)[5].args[2], "mc");
    EXPECT_EQ((*script)[6].numbers, (std::vector<float>{32, 0.25f}));
    auto bad = parseScript("mesh extract fine\nmesh extract 2.5\nmesh render x\nview both\n"
                           "mesh extract 64 qd\nmesh extract 64 dc 0\nmesh export a b\n",
                           "s.txt");
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().str(),
              "s.txt:1:1: mesh extract: expected a whole number of cells, got \"fine\"\n"
              "s.txt:2:1: mesh extract: expected a whole number of cells, got \"2.5\"\n"
              "s.txt:3:1: mesh: expected one of extract, export, got \"render\"\n"
              "s.txt:4:1: view: expected one of mesh, march, got \"both\"\n"
              "s.txt:5:1: mesh extract: expected the method dc or mc, got \"qd\"\n"
              "s.txt:6:1: mesh extract: expected a simplification error in cells greater than 0, "
              "got \"0\"\n"
              "s.txt:7:1: mesh export: expected a file name");
}

TEST(ViewerExport, WritesOnItsOwnThread) {
    auto mesh = std::make_shared<Mesh>(); // one triangle
    mesh->positions = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
    mesh->normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    mesh->colors = {{1, 0, 0}, {1, 0, 0}, {1, 0, 0}};
    mesh->indices = {0, 1, 2};
    fs::path dir = tempDir("viewer_export");
    ExportWorker worker;
    auto finished = [&] {
        const auto start = std::chrono::steady_clock::now();
        while (worker.running() && secondsSince(start) < 30.0)
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        return worker.take();
    };
    ASSERT_TRUE(worker.start(mesh, dir / "tri.obj", MeshFormat::Obj));
    mesh.reset(); // the worker holds its own reference
    auto written = finished();
    ASSERT_TRUE(written);
    EXPECT_TRUE(*written) << written->error().str();
    std::ifstream in(dir / "tri.obj");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("f 1//1 2//2 3//3"), std::string::npos) << text;
    EXPECT_FALSE(worker.take()); // once

    ASSERT_TRUE(worker.start(std::make_shared<Mesh>(), dir / "missing" / "x.ply", MeshFormat::Ply));
    written = finished();
    ASSERT_TRUE(written);
    EXPECT_FALSE(*written);
}
