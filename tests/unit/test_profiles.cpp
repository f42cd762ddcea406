// 2D profiles, extrude and revolve on the CPU: each against the 3D primitive it makes (an
// extruded circle is a cylinder, a revolved circle a torus), polygons and text against brute
// force over their outlines, and the font's outlines against their own geometry.
#include "scene/font.h"
#include "scene/json_writer.h"
#include "scene/outline.h"
#include "scene/parse_util.h"

#include "scene_build_util.h"

#include <sdfcsg/eval.h>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace sdfcsg {
namespace {

using test::parseRoot;
using test::randomPoints;

std::string errorOf(const std::string& root) {
    auto scene = parseScene(R"({"version": 1, "root": )" + root + "}", "test.json");
    return scene ? "accepted" : scene.error().str();
}

// Both fields agree within `tolerance` everywhere in the cube of half side `reach`.
void expectSameField(const std::string& a, const std::string& b, float reach, float tolerance) {
    SCOPED_TRACE(a);
    Evaluator ea(parseRoot(a)), eb(parseRoot(b));
    for (glm::vec3 p : randomPoints(3, 4000, reach))
        ASSERT_NEAR(ea.distance(p), eb.distance(p), tolerance) << p.x << " " << p.y << " " << p.z;
}

TEST(Profiles, ExtrudedCircleIsACylinder) {
    expectSameField(R"({"type": "extrude", "height": 0.6, "children": [
                        {"type": "circle", "radius": 0.4}]})",
                    R"({"type": "cylinder", "radius": 0.4, "height": 0.6, "rotate": [90, 0, 0]})",
                    1.2f, 2e-5f);
}

TEST(Profiles, ExtrudedRectangleIsABox) {
    expectSameField(R"({"type": "extrude", "height": 0.6, "children": [
                        {"type": "rectangle", "width": 0.8, "height": 0.5}]})",
                    R"({"type": "box", "size": [0.8, 0.5, 0.6]})", 1.2f, 2e-5f);
    // Rounded corners and rounded edges: a round box.
    expectSameField(R"({"type": "extrude", "height": 0.6, "rounding": 0.1, "children": [
                        {"type": "rectangle", "width": 0.8, "height": 0.5, "rounding": 0.1}]})",
                    R"({"type": "round_box", "size": [0.8, 0.5, 0.6], "radius": 0.1})", 1.2f,
                    2e-5f);
}

TEST(Profiles, ExtrudedHexagonIsAHexPrism) {
    expectSameField(R"({"type": "extrude", "height": 0.4, "children": [
                        {"type": "regular_polygon", "radius": 0.5, "sides": 6}]})",
                    R"({"type": "hex_prism", "radius": 0.5, "height": 0.4, "rotate": [90, 0, 0]})",
                    1.2f, 2e-5f);
}

TEST(Profiles, RevolvedCircleIsATorus) {
    expectSameField(R"({"type": "revolve", "offset": 0.6, "children": [
                        {"type": "circle", "radius": 0.2}]})",
                    R"({"type": "torus", "major_radius": 0.6, "minor_radius": 0.2})", 1.2f, 2e-5f);
    // A profile moved off the axis instead of the offset: the same ring.
    expectSameField(R"({"type": "revolve", "children": [
                        {"type": "circle", "radius": 0.2, "translate": [0.6, 0, 0]}]})",
                    R"({"type": "torus", "major_radius": 0.6, "minor_radius": 0.2})", 1.2f, 2e-5f);
}

// A lathe profile that meets the axis along an edge turns into a solid with the axis inside it,
// not on a surface: the field is the distance to the solid's surface there too (a rectangle
// against the axis is a cylinder), also with the axis moved by an offset or a shift.
TEST(Profiles, RevolvedProfileAgainstTheAxisIsSolidThere) {
    const char* cylinder = R"({"type": "cylinder", "radius": 0.5, "height": 1.6})";
    expectSameField(R"({"type": "revolve", "children": [{"type": "polygon", "points":
                        [[0, -0.8], [0.5, -0.8], [0.5, 0.8], [0, 0.8], [0, 0.2]]}]})",
                    cylinder, 1.2f, 2e-5f);
    expectSameField(R"({"type": "revolve", "offset": 0.3, "children": [{"type": "polygon",
                        "points": [[-0.3, -0.8], [0.2, -0.8], [0.2, 0.8], [-0.3, 0.8]]}]})",
                    cylinder, 1.2f, 2e-5f);
    expectSameField(
        R"({"type": "revolve", "children": [{"type": "polygon", "translate": [-0.1, 0, 0],
                        "points": [[0.1, 0.8], [0.1, -0.8], [0.6, -0.8], [0.6, 0.8]]}]})",
        cylinder, 1.2f, 2e-5f);
    // Touching the axis at a point only, the profile keeps its own outline: the field is 0 on
    // the axis where it touches.
    Evaluator cone(parseRoot(R"({"type": "revolve", "children": [{"type": "polygon",
                                 "points": [[0, 0], [0.5, -0.5], [0.5, 0.5]]}]})"));
    EXPECT_EQ(cone.distance(glm::vec3(0.0f)), 0.0f);
}

TEST(Profiles, PolygonSquareIsARectangle) {
    expectSameField(R"({"type": "extrude", "height": 0.6, "children": [
                        {"type": "polygon", "points": [[-0.4, -0.25], [0.4, -0.25], [0.4, 0.25], [-0.4, 0.25]]}]})",
                    R"({"type": "box", "size": [0.8, 0.5, 0.6]})", 1.2f, 2e-5f);
}

// The exact distance to a 2D polyline, and the crossing parity, by brute force.
struct Brute {
    std::vector<std::pair<glm::vec2, glm::vec2>> edges;
    float distance(glm::vec2 p) const {
        float best = INFINITY;
        bool inside = false;
        for (auto [a, b] : edges) {
            const glm::vec2 pa = p - a, ba = b - a;
            const float h = glm::clamp(glm::dot(pa, ba) / glm::dot(ba, ba), 0.0f, 1.0f);
            best = std::min(best, glm::length(pa - ba * h));
            if ((a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y))
                inside = !inside;
        }
        return inside ? -best : best;
    }
};

TEST(Profiles, PolygonIsTheExactDistanceToItsEdges) {
    const std::vector<glm::vec2> pts = {{-0.5f, -0.5f}, {0.5f, -0.5f}, {0.5f, 0.0f}, {0.0f, 0.0f},
                                        {0.1f, 0.4f},   {-0.3f, 0.6f}, {-0.5f, 0.1f}};
    std::string json;
    Brute brute;
    for (size_t i = 0; i < pts.size(); ++i) {
        json +=
            (i ? ", [" : "[") + std::to_string(pts[i].x) + ", " + std::to_string(pts[i].y) + "]";
        brute.edges.push_back({pts[i], pts[(i + 1) % pts.size()]});
    }
    // Clockwise or not, the same solid.
    for (bool reversed : {false, true}) {
        std::string list = json;
        if (reversed) {
            list.clear();
            for (size_t i = pts.size(); i-- > 0;)
                list += (list.empty() ? "[" : ", [") + std::to_string(pts[i].x) + ", " +
                        std::to_string(pts[i].y) + "]";
        }
        Evaluator e(parseRoot(R"({"type": "extrude", "height": 100, "children": [
            {"type": "polygon", "points": [)" +
                              list + "]}]}"));
        for (glm::vec3 p : randomPoints(9, 3000, 0.9f)) {
            const float expected = brute.distance({p.x, p.y});
            ASSERT_NEAR(e.distance(glm::vec3(p.x, p.y, 0.0f)), expected, 2e-5f)
                << p.x << " " << p.y << (reversed ? " reversed" : "");
        }
    }
}

TEST(Profiles, BadProfilesGiveExactMessages) {
    EXPECT_EQ(
        errorOf(R"({"type": "circle", "radius": 1})"),
        "test.json: root: a circle is a 2D profile: it must be inside an extrude or a revolve");
    EXPECT_EQ(errorOf(R"({"type": "extrude", "height": 1, "children": [
                  {"type": "polygon", "points": [[0, 0], [1, 0]]}]})"),
              "test.json: root.children[0].points: expected an array of 3 to 1024 points [x, y], "
              "got 2 points");
    EXPECT_EQ(errorOf(R"({"type": "extrude", "height": 1, "children": [
                  {"type": "polygon", "points": [[0, 0], [1, 1], [1, 0], [0, 1]]}]})"),
              "test.json: root.children[0].points: edges 0 and 2 cross (an edge joins a point to "
              "the next); expected a simple polygon");
    EXPECT_EQ(errorOf(R"({"type": "extrude", "height": 1, "children": [
                  {"type": "polygon", "points": [[0, 0], [1, 0], [1, 0], [0, 1]]}]})"),
              "test.json: root.children[0].points: points 1 and 2 are the same; expected a simple "
              "polygon");
    EXPECT_EQ(errorOf(R"({"type": "extrude", "height": 1, "children": [
                  {"type": "polygon", "points": [[0, 0], [1], [0, 1]]}]})"),
              "test.json: root.children[0].points[1]: expected a point [x, y], got [1]");
    EXPECT_EQ(errorOf(R"({"type": "extrude", "height": 1, "children": [
                  {"type": "regular_polygon", "radius": 1, "sides": 2}]})"),
              "test.json: root.children[0].sides: expected at least 3, got 2");
    EXPECT_EQ(errorOf(R"({"type": "extrude", "height": 1, "children": [
                  {"type": "regular_polygon", "radius": 1, "sides": 65}]})"),
              "test.json: root.children[0].sides: expected at most 64, got 65");
    EXPECT_EQ(errorOf(R"({"type": "extrude", "height": 1, "children": [
                  {"type": "text", "text": 5}]})"),
              "test.json: root.children[0].text: expected a string, got 5");
    EXPECT_EQ(errorOf(R"({"type": "extrude", "height": 1, "children": [
                  {"type": "text", "text": "a\u000ab"}]})"),
              "test.json: root.children[0].text: text is one line: it may not hold a line break");
    EXPECT_EQ(errorOf(R"({"type": "extrude", "height": 1, "children": [
                  {"type": "text", "text": "\ue000"}]})"),
              "test.json: root.children[0].text: the font "
              "\"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf\" has no glyph for (U+E000)");
    EXPECT_EQ(errorOf(R"({"type": "extrude", "height": 1, "children": [
                  {"type": "text", "text": "   "}]})"),
              "test.json: root.children[0].text: expected text with something to see, got only "
              "spaces");
    EXPECT_EQ(errorOf(R"({"type": "extrude", "height": 1, "children": [
                  {"type": "text", "text": "a", "font": "/nonexistent.ttf"}]})"),
              "test.json: root.children[0].font: cannot load font \"/nonexistent.ttf\": no such "
              "file");
    EXPECT_EQ(
        errorOf(R"({"type": "extrude", "height": 1, "children": [
                  {"type": "text", "text": "a", "font": "/dev/zero"}]})"),
        "test.json: root.children[0].font: cannot load font \"/dev/zero\": not a regular file");
    EXPECT_EQ(errorOf(R"({"type": "extrude", "height": 1, "children": [
                  {"type": "text", "text": "a", "font": ")" SDFCSG_SOURCE_DIR R"(/LICENSE"}]})"),
              "test.json: root.children[0].font: cannot load font \"" SDFCSG_SOURCE_DIR
              "/LICENSE\": not a font FreeType can read");
    EXPECT_EQ(errorOf(R"({"type": "extrude", "height": 1, "children": [{"type": "plane"}]})"),
              "test.json: root: an extrude needs a bounded child, and its child reaches infinity "
              "(a plane does)");
}

// Outlines are bounded per scene, not only per node.
std::string textScene(const std::string& font) {
    return R"({"version": 1, "root": {"type": "extrude", "height": 0.2, "children": [
        {"type": "text", "text": "Ab", "font": )" +
           detail::jsonQuote(font) + "}]}}";
}

// The working directory for as long as it lives.
struct InFolder {
    std::filesystem::path before = std::filesystem::current_path();
    explicit InFolder(const std::filesystem::path& folder) {
        std::filesystem::current_path(folder);
    }
    ~InFolder() { std::filesystem::current_path(before); }
};

// A scene and the font beside it move together: the font's relative name resolves in the
// scene file's folder, whatever the working directory.
TEST(Profiles, FontBesideTheSceneLoadsFromAnotherWorkingDirectory) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::path(SDFCSG_TEST_OUTPUT_DIR) / "font-beside" / "scenes";
    fs::remove_all(dir.parent_path());
    fs::create_directories(dir / "fonts");
    fs::copy_file(detail::defaultFontFile(), dir / "fonts" / "Beside.ttf");
    std::ofstream(dir / "scene.json") << textScene("fonts/Beside.ttf");
    std::ofstream(dir / "missing.json") << textScene("fonts/Missing.ttf");
    {
        InFolder elsewhere("/");
        auto scene = loadScene(dir / "scene.json");
        ASSERT_TRUE(scene) << scene.error().str();
        EXPECT_EQ(scene->files.folder, dir);
        EXPECT_TRUE(scene->files.trusted);
        EXPECT_EQ(scene->nodes[1].strings[1], "fonts/Beside.ttf");
        auto missing = loadScene(dir / "missing.json");
        ASSERT_FALSE(missing);
        EXPECT_EQ(missing.error().str(),
                  (dir / "missing.json").string() + ": root.children[0].font: cannot load font \"" +
                      (dir / "fonts" / "Missing.ttf").string() + "\": no such file");
    }
    {
        InFolder parent(dir.parent_path());
        auto scene = loadScene("scenes/scene.json");
        ASSERT_TRUE(scene) << scene.error().str();
        // The same font as the default, so the same outline.
        auto reference = parseScene(textScene(""));
        ASSERT_TRUE(reference);
        EXPECT_EQ(*scene->nodes[1].words, *reference->nodes[1].words);
        // An edited copy parses under the same rule.
        ParseOptions options;
        options.files = scene->files;
        EXPECT_TRUE(parseScene(toJson(*scene), scene->file, options));
    }
}

// Fonts by family, through fontconfig: matched ignoring case and blanks, and never parsed as a
// fontconfig pattern.
TEST(Profiles, FontsByFamily) {
    auto sans = parseScene(textScene("DejaVu Sans"));
    ASSERT_TRUE(sans) << sans.error().str();
    auto reference = parseScene(textScene(""));
    ASSERT_TRUE(reference);
    EXPECT_EQ(*sans->nodes[1].words, *reference->nodes[1].words);
    auto lower = parseScene(textScene("dejavu sans"));
    ASSERT_TRUE(lower) << lower.error().str();
    EXPECT_EQ(*lower->nodes[1].words, *reference->nodes[1].words);
    auto serif = parseScene(textScene("DejaVu Serif"));
    ASSERT_TRUE(serif) << serif.error().str();
    EXPECT_NE(*serif->nodes[1].words, *reference->nodes[1].words);

    for (const char* family : {"No Such Family", "DejaVu Sans:style=Bold"}) {
        auto unknown = parseScene(textScene(family), "test.json");
        ASSERT_FALSE(unknown);
        EXPECT_EQ(unknown.error().str(),
                  std::string("test.json: root.children[0].font: cannot load font \"") + family +
                      "\": no installed font family has that name (fc-list : family lists them)");
    }
}

// An untrusted scene (a model's answer) may name files inside its folder only, and whatever is
// wrong with a font it names, the message is the same and tells nothing of the file system.
TEST(Profiles, UntrustedScenesNameNoFilesOutsideTheirFolder) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::path(SDFCSG_TEST_OUTPUT_DIR) / "font-untrusted";
    fs::remove_all(dir);
    fs::create_directories(dir / "fonts");
    fs::copy_file(detail::defaultFontFile(), dir / "fonts" / "Inside.ttf");
    fs::create_symlink("/etc/passwd", dir / "fonts" / "out.ttf");
    fs::create_symlink(fs::absolute(dir / "fonts" / "Inside.ttf"), dir / "fonts" / "in.ttf");
    ParseOptions options;
    options.files = {dir, false};
    for (const char* font : {"fonts/Inside.ttf", "fonts/in.ttf", "DejaVu Serif"}) {
        auto scene = parseScene(textScene(font), "answer", options);
        EXPECT_TRUE(scene) << font << ": " << scene.error().str();
        if (scene) {
            EXPECT_FALSE(scene->files.trusted);
        }
    }
    const std::string inside = (dir / "fonts" / "Inside.ttf").string();
    for (const std::string& font :
         std::vector<std::string>{"/etc/passwd", "/etc", "/dev/zero", "/nonexistent.ttf", inside,
                                  "../font-untrusted/fonts/Inside.ttf", "fonts/out.ttf",
                                  "fonts/missing.ttf", "fonts", "No Such Family"}) {
        auto scene = parseScene(textScene(font), "answer", options);
        ASSERT_FALSE(scene) << font;
        EXPECT_EQ(scene.error().str(),
                  "answer: root.children[0].font: unknown font " + detail::quote(font) +
                      ": name an installed font family, such as \"DejaVu Sans\", or leave it out");
    }
    // Without a folder, families only.
    options.files.folder.clear();
    EXPECT_FALSE(parseScene(textScene("fonts/Inside.ttf"), "answer", options));
    EXPECT_TRUE(parseScene(textScene("DejaVu Sans"), "answer", options));
    // A glyph the font lacks is named by the font's name in the scene, not its file.
    auto glyph = parseScene(R"({"version": 1, "root": {"type": "extrude", "height": 0.2,
        "children": [{"type": "text", "text": "\ue000", "font": "DejaVu Sans"}]}})",
                            "answer", options);
    ASSERT_FALSE(glyph);
    EXPECT_EQ(glyph.error().str(), "answer: root.children[0].text: the font \"DejaVu Sans\" has "
                                   "no glyph for (U+E000)");
}

TEST(Profiles, OutlinesOfAllNodesAreBounded) {
    std::string kids;
    for (int i = 0; i < 200; ++i)
        kids += std::string(i ? ", " : "") + R"({"type": "text", "text": ")" +
                std::string(256, '@') + "\"}";
    const std::string error =
        errorOf(R"({"type": "extrude", "height": 1, "children": [{"type": "union", "children": [)" +
                kids + "]}]}");
    EXPECT_NE(error.find("the scene's outlines, images and meshes exceed 64 MiB in all, the limit"),
              std::string::npos)
        << error.substr(0, 300);
}

// The font's outlines: closed contours, "B" three of them and "o" two, outer ones wound one
// way and holes the other; extents that hold every point and that the points reach.
TEST(Profiles, FontOutlinesAreClosedContours) {
    auto text = detail::textOutline("Bo", detail::defaultFontFile(), 1.0f);
    ASSERT_TRUE(text) << text.error().str();
    std::vector<double> areas;
    double area = 0.0;
    for (size_t i = 0; i < text->segments.size(); ++i) {
        const detail::GlyphSegment& s = text->segments[i];
        area += 0.5 * (double(s.a.x) * s.b.y - double(s.b.x) * s.a.y);
        if (s.quadratic) // the curve's area beyond its chord: 2/3 of the control triangle's
            area +=
                (2.0 / 3.0) * 0.5 *
                ((s.c.x - s.a.x) * double(s.b.y - s.a.y) - (s.b.x - s.a.x) * double(s.c.y - s.a.y));
        const bool last = i + 1 == text->segments.size() || text->segments[i + 1].a != s.b;
        if (last) {
            areas.push_back(area);
            area = 0.0;
        }
    }
    ASSERT_EQ(areas.size(), 5u);
    int positive = 0;
    for (double a : areas)
        positive += a > 0;
    EXPECT_TRUE(positive == 2 || positive == 3) << "outer and inner contours wind apart";
    for (const auto& s : text->segments)
        for (glm::vec2 q : {s.a, s.b}) {
            EXPECT_GE(q.x, text->min.x - 1e-5f);
            EXPECT_LE(q.y, text->max.y + 1e-5f);
        }
    EXPECT_GT(text->advance, text->max.x - 0.2f);
    EXPECT_GT(text->max.y, 0.5f); // cap height about 0.73 em
    EXPECT_LT(text->min.y, 0.0f); // the "o" overshoots the baseline
    // Twice the size: twice every coordinate.
    auto big = detail::textOutline("Bo", detail::defaultFontFile(), 2.0f);
    ASSERT_EQ(big->segments.size(), text->segments.size());
    for (size_t i = 0; i < text->segments.size(); ++i)
        EXPECT_NEAR(glm::distance(big->segments[i].b, 2.0f * text->segments[i].b), 0.0f, 1e-5f);
    EXPECT_NEAR(big->advance, 2.0f * text->advance, 1e-5f);
    // Kerning pulls "AV" together.
    auto a = detail::textOutline("A", detail::defaultFontFile(), 1.0f);
    auto v = detail::textOutline("V", detail::defaultFontFile(), 1.0f);
    auto av = detail::textOutline("AV", detail::defaultFontFile(), 1.0f);
    EXPECT_LT(av->advance, a->advance + v->advance);
}

// A text's outline as a dense polyline (64 lines to a curve), centred as the text node centres it.
Brute textBrute(const detail::TextOutline& text) {
    const glm::vec2 shift = -0.5f * (text.min + text.max);
    Brute brute;
    for (const auto& s : text.segments) {
        const int n = s.quadratic ? 64 : 1;
        glm::vec2 prev = s.a + shift;
        for (int k = 1; k <= n; ++k) {
            const float t = float(k) / n;
            const glm::vec2 q = (1 - t) * (1 - t) * s.a + 2 * t * (1 - t) * s.c + t * t * s.b;
            brute.edges.push_back({prev, q + shift});
            prev = q + shift;
        }
    }
    return brute;
}

// A gridded outline (outline.h) against `brute` in the rectangle of half sides `reach`: exact
// within `tolerance` on the grid; beyond it a lower bound, positive and never below the
// distance to the outline's box; and 1-Lipschitz everywhere, across cells and the grid's edge.
void expectGridField(const std::string& root, const Brute& brute, glm::vec2 reach,
                     float tolerance) {
    SCOPED_TRACE(root);
    Evaluator e(parseRoot(root));
    const Params& k = e.nodes()[1].params;
    ASSERT_GT(k[1], 0.0f) << "not gridded";
    const glm::vec2 lo(k[2], k[3]), hi(k[4], k[5]), corner = lo - 2.0f * k[7];
    const glm::vec2 far = corner + glm::vec2(k[1], k[6]) * k[7];
    auto field = [&](glm::vec2 p) { return e.distance(glm::vec3(p, 0.0f)); };
    int on = 0, beyond = 0, inside = 0;
    const std::vector<glm::vec3> at = randomPoints(5, 4000, 1.0f),
                                 steps = randomPoints(6, 4000, 1.0f);
    for (size_t i = 0; i < at.size(); ++i) {
        const glm::vec2 p = reach * glm::vec2(at[i]);
        SCOPED_TRACE(std::to_string(p.x) + " " + std::to_string(p.y));
        const float got = field(p), exact = brute.distance(p);
        if (glm::all(glm::greaterThanEqual(p, corner)) && glm::all(glm::lessThanEqual(p, far))) {
            ASSERT_NEAR(got, exact, tolerance);
            ++on;
            inside += got < 0;
        } else {
            ASSERT_LE(got, exact + tolerance);
            const glm::vec2 out = glm::max(glm::max(lo - p, p - hi), 0.0f);
            ASSERT_GE(got, glm::length(out) * (1.0f - 1e-6f));
            ++beyond;
        }
        // A step of up to a tenth of the reach.
        const glm::vec2 q = p + 0.1f * reach * glm::vec2(steps[i]);
        ASSERT_LE(std::abs(field(q) - got), glm::length(q - p) * 1.0001f + 1e-6f) << "step";
    }
    EXPECT_GT(on, 500);
    EXPECT_GT(beyond, 500);
    EXPECT_GT(inside, 50);
}

// Text: the field is the exact distance to the glyphs' curves (sampled densely here), negative
// inside them, and its bounds are the outline's extents, centred.
TEST(Profiles, TextIsTheExactDistanceToItsGlyphs) {
    auto text = detail::textOutline("Bo", detail::defaultFontFile(), 1.0f);
    ASSERT_TRUE(text);
    const Brute brute = textBrute(*text);
    Evaluator e(parseRoot(R"({"type": "extrude", "height": 100, "children": [
        {"type": "text", "text": "Bo"}]})"));
    const Aabb& box = e.nodes()[1].bounds;
    const glm::vec2 half = 0.5f * (text->max - text->min);
    for (int k = 0; k < 2; ++k) { // within the bounds' outward rounding
        EXPECT_GE(box.max[k], half[k]);
        EXPECT_LE(box.min[k], -half[k]);
        EXPECT_NEAR(box.max[k], half[k], 5e-5f);
        EXPECT_NEAR(box.min[k], -half[k], 5e-5f);
    }
    int inside = 0;
    for (glm::vec3 p : randomPoints(4, 4000, 0.8f)) {
        const float expected = brute.distance({p.x, p.y});
        const float got = e.distance(glm::vec3(p.x, p.y, 0.0f));
        ASSERT_NEAR(got, expected, 2e-4f) << p.x << " " << p.y; // the polyline's sag
        inside += got < 0;
    }
    EXPECT_GT(inside, 200);
}

// "width" and "height" set a text's size by its ink: its outlines' extents are that wide or that
// tall, and the field is the text's at the font size that makes them so.
TEST(Profiles, TextFitsAWidthOrAHeight) {
    auto unit = detail::textOutline("Fit me", detail::defaultFontFile(), 1.0f);
    ASSERT_TRUE(unit);
    const glm::vec2 ink = unit->max - unit->min;
    for (int axis = 0; axis < 2; ++axis) {
        const std::string key = axis == 0 ? "width" : "height";
        const float want = axis == 0 ? 2.5f : 0.4f;
        const std::string fit = R"({"type": "extrude", "height": 0.3, "children": [
            {"type": "text", "text": "Fit me", ")" +
                                key + R"(": )" + std::to_string(want) + "}]}";
        Evaluator e(parseRoot(fit));
        const Aabb& box = e.nodes()[1].bounds; // the extents, rounded outwards
        EXPECT_NEAR(box.max[axis] - box.min[axis], want, 1e-4f) << key;
        expectSameField(fit,
                        R"({"type": "extrude", "height": 0.3, "children": [
            {"type": "text", "text": "Fit me", "size": )" +
                            std::to_string(want / ink[axis]) + "}]}",
                        1.5f, 1e-4f);
    }
}

// Outlines too large to loop over carry a grid of cells, each listing the segments
// that can be nearest in it.
TEST(Profiles, GriddedTextIsExactOnItsGrid) {
    auto text = detail::textOutline("sdfcsg gear", detail::defaultFontFile(), 0.6f);
    ASSERT_TRUE(text);
    expectGridField(R"({"type": "extrude", "height": 100, "children": [
        {"type": "text", "text": "sdfcsg gear", "size": 0.6}]})",
                    textBrute(*text), {2.5f, 0.6f}, 2e-4f);
}

TEST(Profiles, GriddedPolygonIsExactOnItsGrid) {
    // A star of 300 points, 150 spikes.
    std::string list;
    Brute brute;
    std::vector<glm::vec2> pts;
    for (int i = 0; i < 300; ++i) {
        const float angle = 6.2831853f * float(i) / 300.0f, r = i % 2 ? 0.5f : 0.8f;
        pts.push_back({r * std::cos(angle), r * std::sin(angle)});
        list += (i ? ", [" : "[") + std::to_string(pts.back().x) + ", " +
                std::to_string(pts.back().y) + "]";
    }
    // The points as the parser reads them back from their text.
    for (glm::vec2& p : pts)
        p = {std::stof(std::to_string(p.x)), std::stof(std::to_string(p.y))};
    for (size_t i = 0; i < pts.size(); ++i)
        brute.edges.push_back({pts[i], pts[(i + 1) % pts.size()]});
    expectGridField(R"({"type": "extrude", "height": 100, "children": [
        {"type": "polygon", "points": [)" +
                        list + "]}]}",
                    brute, {1.2f, 1.2f}, 2e-5f);
}

} // namespace
} // namespace sdfcsg
