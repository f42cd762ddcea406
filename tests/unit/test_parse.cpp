// The scene loader: every bundled scene parses; bad input gives exactly the message we promise
// (file, JSON path, what was expected, what was found); hostile input is refused cleanly; toJson
// round-trips.
#include <sdfcsg/scene.h>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace sdfcsg;

namespace {

const fs::path kSource = SDFCSG_SOURCE_DIR;

std::vector<fs::path> jsonFiles(const fs::path& dir) {
    std::vector<fs::path> files;
    if (fs::is_directory(dir))
        for (const auto& entry : fs::directory_iterator(dir))
            if (entry.path().extension() == ".json") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    return files;
}

// Every valid scene we have: the bundled ones, the test fixtures and the legacy twins.
std::vector<fs::path> validScenes() {
    std::vector<fs::path> all = jsonFiles(kSource / "assets/scenes");
    for (const auto& f : jsonFiles(kSource / "tests/data/valid"))
        all.push_back(f);
    return all;
}

// The full message for a text that must fail, or "<parsed>".
std::string errorOf(std::string_view json, const Limits& limits = {}) {
    auto r = parseScene(json, "scene.json", limits);
    return r ? std::string("<parsed>") : r.error().str();
}

std::string scene(std::string_view root) {
    return R"({"version": 1, "root": )" + std::string(root) + "}";
}

std::string unionOf(std::initializer_list<std::string_view> children) {
    std::string out = R"({"type": "union", "children": [)";
    for (std::string_view c : children) {
        if (out.back() != '[') out += ", ";
        out += c;
    }
    return scene(out + "]}");
}

constexpr std::string_view S = R"({"type": "sphere", "radius": 1})";

std::string withSphere(std::string_view before) {
    return "{" + std::string(before) + R"(, "root": {"type": "sphere", "radius": 1}})";
}

struct BadInput {
    const char* name;
    std::string json;
    std::string expected;
};

std::vector<BadInput> badInputs() {
    std::string fiveLights = R"({"direction": [0, -1, 0]})";
    for (int i = 0; i < 4; ++i)
        fiveLights += R"(, {"direction": [0, -1, 0]})";
    // Every kind's name in the table's order, then a use: "sphere, box, ..., revolve or use".
    std::string kinds;
    for (const KindInfo& k : nodeKinds())
        kinds += (kinds.empty() ? "" : ", ") + std::string(k.name);
    kinds += " or use";
    return {
        // JSON syntax: line and column of the first problem.
        {"empty", "", "scene.json:1:1: expected a JSON value, got end of input"},
        {"only whitespace", "  \n  ", "scene.json:2:3: expected a JSON value, got end of input"},
        {"trailing comma in object", R"({"version": 1, "root": {"type": "sphere", "radius": 1},})",
         "scene.json:1:56: expected a key after ',', got '}' (trailing commas are not allowed)"},
        {"trailing comma in array",
         scene(R"({"type": "union", "children": [{"type": "sphere", "radius": 1},]})"),
         "scene.json:1:87: expected a value after ',', got ']' (trailing commas are not allowed)"},
        {"missing comma", "{\"version\": 1\n \"root\": {}}",
         R"(scene.json:2:2: expected ',' or '}' after an object member, got '"')"},
        {"missing colon", R"({"version": 1, "root" {}})",
         "scene.json:1:23: expected ':' after the key, got '{'"},
        {"single quotes", "{'version': 1}",
         R"(scene.json:1:2: expected a key in double quotes, got "'")"},
        {"string across lines",
         "{\"version\": 1, \"root\": {\"type\": \"sphere\n\", \"radius\": 1}}",
         R"(scene.json:1:33: unterminated string: a string must end on the line it starts (write a line break as \n))"},
        {"unterminated string at the end", R"({"version": 1, "root": {"type": "sph)",
         R"(scene.json:1:33: unterminated string: no closing '"')"},
        {"bad escape", scene(R"({"type": "sphere", "name": "a\qb", "radius": 1})"),
         R"(scene.json:1:53: invalid escape '\q' in a string; expected one of \" \\ \/ \b \f \n \r \t \uXXXX)"},
        {"bad unicode escape", scene(R"({"type": "sphere", "name": "\u12g4", "radius": 1})"),
         R"(scene.json:1:52: invalid unicode escape "\u12g4"; expected \u and four hex digits)"},
        {"unpaired surrogate", scene(R"({"type": "sphere", "name": "\ud800x", "radius": 1})"),
         R"(scene.json:1:52: unpaired surrogate "\ud800" in a string)"},
        {"tab inside a string", scene("{\"type\": \"sphere\", \"name\": \"a\tb\", \"radius\": 1}"),
         "scene.json:1:53: control character U+0009 in a string must be escaped"},
        {"invalid UTF-8", scene("{\"type\": \"sphere\", \"name\": \"caf\xE9\", \"radius\": 1}"),
         "scene.json:1:55: invalid UTF-8 byte 0xE9 in a string"},
        {"leading zero", scene(R"({"type": "sphere", "radius": 01})"),
         R"(scene.json:1:53: invalid number "01": leading zeros are not allowed)"},
        {"no digit after the point", scene(R"({"type": "sphere", "radius": 1.})"),
         R"(scene.json:1:53: invalid number "1.": expected a digit after '.')"},
        {"number overflows",
         "{\n  \"version\": 1,\n  \"root\": {\"type\": \"sphere\", \"radius\": 1e999}\n}",
         "scene.json:3:40: number 1e999 is out of range"},
        {"integer beyond 64 bits",
         scene(R"({"type": "sphere", "radius": 123456789012345678901234567890})"),
         "scene.json:1:53: number 123456789012345678901234567890 is out of range"},
        {"NaN", scene(R"({"type": "sphere", "radius": NaN})"),
         "scene.json:1:53: NaN is not a JSON number; numbers must be finite"},
        {"negative infinity", scene(R"({"type": "sphere", "radius": -Infinity})"),
         "scene.json:1:53: -Infinity is not a JSON number; numbers must be finite"},
        {"misspelt literal", scene(R"({"type": "sphere", "radius": 1, "name": nul})"),
         R"(scene.json:1:64: invalid literal "nul"; expected true, false or null)"},
        {"unquoted string", scene(R"({"type": sphere, "radius": 1})"),
         "scene.json:1:33: expected a value, got sphere (strings must be in double quotes)"},
        {"unclosed object",
         "{\n  \"version\": 1,\n  \"root\": {\"type\": \"sphere\", \"radius\": 1}\n",
         "scene.json:4:1: unexpected end of input: the object opened at line 1, column 1 is not "
         "closed"},
        {"text after the document", scene(S) + " x",
         "scene.json:1:57: expected end of input after the JSON value, got 'x'"},

        // The scene object.
        {"top level array", "[1, 2]",
         R"(scene.json: expected a scene (an object with "version" and "root"), got [1, 2])"},
        {"empty object", "{}",
         "scene.json: missing required key \"version\" (the format version, 1)\n"
         "scene.json: missing required key \"root\" (the top node of the scene)"},
        {"future version", withSphere(R"("version": 2)"),
         "scene.json: version: unsupported version 2; expected 1"},
        {"version as a string", withSphere(R"("version": "1")"),
         R"(scene.json: version: expected the number 1, got "1")"},
        {"misspelt top-level key", withSphere(R"("version": 1, "lihgts": [])"),
         R"(scene.json: unknown key "lihgts"; did you mean "lights"?)"},
        {"unknown top-level key", withSphere(R"("version": 1, "author": "me")"),
         "scene.json: unknown key \"author\"; valid keys: version, name, description, camera, "
         "lights, background, definitions and root"},
        {"name too long", withSphere(R"("version": 1, "name": ")" + std::string(201, 'x') + "\""),
         "scene.json: name: expected a string of at most 200 characters, got 201 characters"},
        {"text too long", // 257 characters of two bytes each: counted as characters
         R"({"version": 1, "root": {"type": "extrude", "height": 0.1, "children": [{"type": "text", "text": ")" +
             [] {
                 std::string s;
                 for (int i = 0; i < 257; ++i)
                     s += "\xc3\xa9";
                 return s;
             }() +
             "\"}]}}",
         "scene.json: root.children[0].text: expected a string of at most 256 characters, got 257 "
         "characters"},
        {"camera without target, fov 180",
         withSphere(R"("version": 1, "camera": {"eye": [0, 0, 5], "fov": 180})"),
         "scene.json: camera: missing required key \"target\" (an array of 3 numbers)\n"
         "scene.json: camera.fov: expected an angle in degrees between 0 and 180 (exclusive), got "
         "180"},
        {"camera eye equals target",
         withSphere(R"("version": 1, "camera": {"eye": [1, 2, 3], "target": [1, 2, 3]})"),
         "scene.json: camera.target: expected a point other than camera.eye, got [1, 2, 3]"},
        {"camera looking straight down",
         withSphere(R"("version": 1, "camera": {"eye": [0, 5, 0], "target": [0, 0, 0]})"),
         "scene.json: camera: missing required key \"up\" (the line of sight is vertical, so the "
         "default up [0, 1, 0] cannot be used)"},
        {"camera up along the view",
         withSphere(
             R"("version": 1, "camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 0, 2]})"),
         "scene.json: camera.up: expected a direction not parallel to the line of sight, got [0, "
         "0, 2]"},
        {"five lights", withSphere(R"("version": 1, "lights": [)" + fiveLights + "]"),
         "scene.json: lights: expected at most 4 lights, got 5"},
        {"light problems",
         withSphere(
             R"("version": 1, "lights": [{"direction": [0, 0, 0], "colour": [1, 1, 1], "intensity": -1}])"),
         "scene.json: lights[0]: unknown key \"colour\"; did you mean \"color\"?\n"
         "scene.json: lights[0].direction: expected a non-zero vector, got [0, 0, 0]\n"
         "scene.json: lights[0].intensity: expected a non-negative number, got -1"},
        {"light without direction", withSphere(R"("version": 1, "lights": [{"intensity": 1}])"),
         "scene.json: lights[0]: missing required key \"direction\" (a non-zero vector of 3 "
         "numbers)"},
        {"background by name", withSphere(R"("version": 1, "background": "red")"),
         R"(scene.json: background: expected a colour ([r, g, b] in 0..1 or "#rrggbb"), got "red")"},

        // Nodes.
        {"misspelt key", scene(R"({"type": "sphere", "radus": 1})"),
         "scene.json: root: unknown key \"radus\"; did you mean \"radius\"?\n"
         "scene.json: root: missing required key \"radius\" (a positive number)"},
        {"misspelt type", unionOf({S, S, S, R"({"type": "sphre", "radius": 1})"}),
         R"(scene.json: root.children[3].type: unknown node type "sphre"; did you mean "sphere"?)"},
        {"unknown type", scene(R"({"type": "blob"})"),
         R"(scene.json: root.type: unknown node type "blob"; expected one of )" + kinds},
        {"type missing", scene(R"({"radius": 1})"),
         R"(scene.json: root: missing required key "type" (one of )" + kinds + ")"},
        {"type not a string", scene(R"({"type": 3, "radius": 1})"),
         "scene.json: root.type: expected a node type name, got 3"},
        {"child not an object", unionOf({S, "5"}),
         R"(scene.json: root.children[1]: expected a node (an object with "type"), got 5)"},
        {"negative radius", unionOf({S, R"({"type": "sphere", "radius": -1})"}),
         "scene.json: root.children[1].radius: expected a positive number, got -1"},
        {"nested path",
         unionOf(
             {S, S, R"({"type": "difference", "children": [{"type": "sphere", "radius": 0}]})"}),
         "scene.json: root.children[2].children[0].radius: expected a positive number, got 0"},
        {"size too short", scene(R"({"type": "box", "size": [1, 2]})"),
         "scene.json: root.size: expected an array of 3 positive numbers, got [1, 2]"},
        {"size component zero", scene(R"({"type": "box", "size": [1, 0, 1]})"),
         "scene.json: root.size[1]: expected a positive number, got 0"},
        {"size component a string", scene(R"({"type": "box", "size": [1, "2", 1]})"),
         R"(scene.json: root.size[1]: expected a positive number, got "2")"},
        {"translate with null",
         scene(R"({"type": "sphere", "radius": 1, "translate": [0, null, 0]})"),
         "scene.json: root.translate[1]: expected a number, got null"},
        {"scale zero", scene(R"({"type": "sphere", "radius": 1, "scale": 0})"),
         "scene.json: root.scale: expected a positive number, got 0"},
        {"scale of another type", scene(R"({"type": "sphere", "radius": 1, "scale": "big"})"),
         R"(scene.json: root.scale: expected a positive number or an array of 3 positive numbers, got "big")"},
        {"scale vector with a zero",
         scene(R"({"type": "sphere", "radius": 1, "scale": [1, 0, 1]})"),
         "scene.json: root.scale[1]: expected a positive number, got 0"},
        {"scale vector too short", scene(R"({"type": "sphere", "radius": 1, "scale": [1, 2]})"),
         "scene.json: root.scale: expected an array of 3 positive numbers, got [1, 2]"},
        {"colour out of range", scene(R"({"type": "sphere", "radius": 1, "color": [1, 2, 0]})"),
         "scene.json: root.color[1]: expected a number in 0..1, got 2"},
        {"colour bad hex", scene(R"({"type": "sphere", "radius": 1, "color": "#12345g"})"),
         R"(scene.json: root.color: expected a colour ([r, g, b] in 0..1 or "#rrggbb"), got "#12345g")"},
        {"plane normal zero", scene(R"({"type": "plane", "normal": [0, 0, 0]})"),
         "scene.json: root.normal: expected a non-zero vector, got [0, 0, 0]"},
        {"round box radius too large",
         scene(R"({"type": "round_box", "size": [1, 2, 3], "radius": 0.6})"),
         "scene.json: root.radius: expected at most half the smallest size (0.5), got 0.6"},
        {"repeat spacing 0 along an axis of copies",
         scene(R"({"type": "repeat", "count": [1, 3, 1], "spacing": [1, 0, 0], "children": [
             {"type": "sphere", "radius": 0.2}]})"),
         "scene.json: root.spacing: expected a spacing greater than 0 along y, which has 3 "
         "copies, got 0"},
        {"bend_linear p1 at p0",
         scene(R"({"type": "bend_linear", "p0": [1, 2, 3], "p1": [1, 2, 3], "offset": [0, 1, 0],
             "children": [{"type": "sphere", "radius": 0.2}]})"),
         "scene.json: root.p1: expected a point apart from p0, got [1, 2, 3]"},
        {"bend_linear unknown ease",
         scene(R"({"type": "bend_linear", "p0": [0, 0, 0], "p1": [1, 0, 0], "offset": [0, 1, 0],
             "ease": "smooth", "children": [{"type": "sphere", "radius": 0.2}]})"),
         R"(scene.json: root.ease: expected one of "linear", "smoothstep" or "smootherstep", got "smooth"; did you mean "smoothstep"?)"},
        {"text width and height", scene(R"({"type": "extrude", "height": 0.2, "children": [
             {"type": "text", "text": "A", "width": 1, "height": 1}]})"),
         "scene.json: root.children[0].height: expected one of \"size\", \"width\" and "
         "\"height\" (each sets the text's size), got both \"width\" and \"height\""},
        {"text size and width", scene(R"({"type": "extrude", "height": 0.2, "children": [
             {"type": "text", "text": "A", "size": 1, "width": 1}]})"),
         "scene.json: root.children[0].width: expected one of \"size\", \"width\" and "
         "\"height\" (each sets the text's size), got both \"size\" and \"width\""},
        {"text width zero", scene(R"({"type": "extrude", "height": 0.2, "children": [
             {"type": "text", "text": "A", "width": 0}]})"),
         "scene.json: root.children[0].width: expected a positive number, got 0"},
        {"text height negative", scene(R"({"type": "extrude", "height": 0.2, "children": [
             {"type": "text", "text": "A", "height": -2}]})"),
         "scene.json: root.children[0].height: expected a positive number, got -2"},
        {"repeat spacing negative",
         scene(R"({"type": "repeat", "count": [2, 1, 1], "spacing": [1, -1, 0], "children": [
             {"type": "sphere", "radius": 0.2}]})"),
         "scene.json: root.spacing[1]: expected a non-negative number, got -1"},
        {"capped torus angle beyond a turn",
         scene(R"({"type": "capped_torus", "major_radius": 1, "minor_radius": 0.2, "angle": 400})"),
         "scene.json: root.angle: expected at most 360, got 400"},
        {"capped torus angle missing",
         scene(R"({"type": "capped_torus", "major_radius": 1, "minor_radius": 0.2})"),
         R"(scene.json: root: missing required key "angle" (a positive number up to 360))"},
        {"ellipsoid radii missing", scene(R"({"type": "ellipsoid"})"),
         R"(scene.json: root: missing required key "radii" (an array of 3 positive numbers))"},
        {"ellipsoid radius given as a number", scene(R"({"type": "ellipsoid", "radii": 1})"),
         "scene.json: root.radii: expected an array of 3 positive numbers, got 1"},
        {"link length negative",
         scene(R"({"type": "link", "length": -1, "major_radius": 1, "minor_radius": 0.2})"),
         "scene.json: root.length: expected a non-negative number, got -1"},
        {"hex prism with a misspelt key",
         scene(R"({"type": "hex_prism", "raduis": 1, "height": 1})"),
         "scene.json: root: unknown key \"raduis\"; did you mean \"radius\"?\nscene.json: root: "
         "missing required key \"radius\" (a positive number)"},
        {"misspelt blend",
         scene(
             R"({"type": "union", "smooth": 0.1, "blend": "chamfr", "children": [{"type": "sphere", "radius": 1}]})"),
         R"(scene.json: root.blend: expected one of "smooth", "round" or "chamfer", got "chamfr"; did you mean "chamfer"?)"},
        {"blend not a string",
         scene(
             R"({"type": "union", "smooth": 0.1, "blend": 2, "children": [{"type": "sphere", "radius": 1}]})"),
         R"(scene.json: root.blend: expected one of "smooth", "round" or "chamfer", got 2)"},
        {"primitive with children", scene(R"({"type": "sphere", "radius": 1, "children": []})"),
         "scene.json: root: a sphere takes no \"children\"; only operations (union, intersection, "
         "difference, shell, offset, repeat, polar_repeat, mirror, elongate, twist, bend, "
         "taper, bend_linear, extrude and revolve) do"},
        {"operation without children", scene(R"({"type": "intersection"})"),
         R"(scene.json: root: missing required key "children" (a non-empty array of nodes))"},
        {"empty children", scene(R"({"type": "union", "children": []})"),
         "scene.json: root.children: expected at least one child node, got []"},
        {"children not an array",
         scene(R"({"type": "union", "children": {"type": "sphere", "radius": 1}})"),
         "scene.json: root.children: expected a non-empty array of nodes, got an object"},
        {"duplicate key", scene(R"({"type": "sphere", "radius": 1, "radius": 2})"),
         R"(scene.json: root: duplicate key "radius")"},
        {"negative smooth",
         scene(
             R"({"type": "union", "smooth": -0.5, "children": [{"type": "sphere", "radius": 1}]})"),
         "scene.json: root.smooth: expected a non-negative number, got -0.5"},
        {"beyond single precision", scene(R"({"type": "sphere", "radius": 1e300})"),
         "scene.json: root.radius: expected a positive number, got 1e+300, which is beyond single "
         "precision (about 3.4e+38)"},
        {"rounds to zero", scene(R"({"type": "sphere", "radius": 1e-60})"),
         "scene.json: root.radius: expected a positive number, got 1e-60, which is 0 in single "
         "precision"},
        {"scales multiply beyond single precision",
         scene(
             R"({"type": "union", "scale": 1e30, "children": [{"type": "sphere", "radius": 1, "scale": 1e30}]})"),
         "scene.json: root.children[0]: the scales of this node and the operations above it "
         "multiply to 1e+60, beyond single precision (about 3.4e+38)"},
        {"scale too small to invert", scene(R"({"type": "sphere", "radius": 1, "scale": 1e-40})"),
         "scene.json: root: the scales of this node and the operations above it multiply to "
         "1e-40, too small for single precision (about 1.2e-38)"},
        {"translation beyond single precision in local units",
         scene(R"({"type": "sphere", "radius": 1, "scale": 1e-20, "translate": [1e30, 0, 0]})"),
         "scene.json: root: the translation of this node, in the units of the scales above it, "
         "is beyond single precision (about 3.4e+38)"},
        {"smooth beyond single precision in world units",
         scene(R"({"type": "union", "smooth": 1e30, "scale": 1e10, "children": [)" +
               std::string(S) + "]}"),
         "scene.json: root: smooth times the scales above it is beyond single precision (about "
         "3.4e+38)"},
        {"key of another kind", scene(R"({"type": "sphere", "size": [1, 1, 1], "radius": 1})"),
         "scene.json: root: unknown key \"size\" for a sphere; valid keys: radius, type, name, "
         "translate, rotate, scale and color"},
        {"unknown key with DEL and a C1 control, escaped",
         scene(R"({"type": "sphere", "radius": 1, "\u007f\u009b2J": 1})"),
         "scene.json: root: unknown key \"\\u007f\\u009b2J\" for a sphere; valid keys: radius, "
         "type, name, translate, rotate, scale and color"},
        {"another word for translate",
         scene(R"({"type": "sphere", "radius": 1, "position": [0, 1, 0]})"),
         R"(scene.json: root: unknown key "position"; did you mean "translate"?)"},
        {"words in another order",
         scene(R"({"type": "cone", "radius": 1, "height": 1, "radius_top": 0.5})"),
         R"(scene.json: root: unknown key "radius_top"; did you mean "top_radius"?)"},
        {"optional parameter of the wrong type",
         scene(R"({"type": "cone", "radius": 1, "height": 1, "top_radius": "0.5"})"),
         R"(scene.json: root.top_radius: expected a non-negative number, got "0.5")"},
        {"several problems, all reported",
         unionOf({R"({"type": "sphere"})",
                  R"({"type": "box", "size": [1, 1, -1], "colour": "#fff"})",
                  R"({"type": "torus", "major_radius": 1, "minor_radius": true})"}),
         "scene.json: root.children[0]: missing required key \"radius\" (a positive number)\n"
         "scene.json: root.children[1]: unknown key \"colour\"; did you mean \"color\"?\n"
         "scene.json: root.children[1].size[2]: expected a positive number, got -1\n"
         "scene.json: root.children[2].minor_radius: expected a positive number, got true"},
    };
}

// A union nested `levels` deep with a sphere at the bottom.
std::string nestedUnions(int levels) {
    std::string json = R"({"version": 1, "root": )";
    for (int i = 0; i < levels; ++i)
        json += R"({"type": "union", "children": [)";
    json += S;
    for (int i = 0; i < levels; ++i)
        json += "]}";
    return json + "}";
}

// 1-based column of the n-th '{' or '[' in a one-line text.
int columnOfOpening(const std::string& text, int n) {
    for (size_t i = 0; i < text.size(); ++i)
        if ((text[i] == '{' || text[i] == '[') && --n == 0) return static_cast<int>(i) + 1;
    return -1;
}

fs::path outputDir() {
    fs::path dir = fs::path(SDFCSG_TEST_OUTPUT_DIR) / "parse";
    fs::create_directories(dir);
    return dir;
}

void expectSameScene(const Scene& a, const Scene& b) {
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    for (size_t i = 0; i < a.nodes.size(); ++i) {
        SCOPED_TRACE("node " + a.nodes[i].path);
        const Node &x = a.nodes[i], &y = b.nodes[i];
        EXPECT_EQ(x.kind, y.kind);
        EXPECT_EQ(x.name, y.name);
        EXPECT_EQ(x.path, y.path);
        EXPECT_EQ(x.transform.translate, y.transform.translate);
        EXPECT_EQ(x.transform.rotate, y.transform.rotate);
        EXPECT_EQ(x.transform.scale, y.transform.scale);
        EXPECT_EQ(x.color, y.color);
        EXPECT_EQ(x.params, y.params);
        EXPECT_EQ(x.children, y.children);
        EXPECT_EQ(x.use, y.use);
    }
    EXPECT_EQ(a.definitions, b.definitions);
    EXPECT_EQ(a.camera.has_value(), b.camera.has_value());
    if (a.camera && b.camera) {
        EXPECT_EQ(a.camera->eye, b.camera->eye);
        EXPECT_EQ(a.camera->target, b.camera->target);
        EXPECT_EQ(a.camera->up, b.camera->up);
        EXPECT_EQ(a.camera->fov, b.camera->fov);
    }
    ASSERT_EQ(a.lights.size(), b.lights.size());
    for (size_t i = 0; i < a.lights.size(); ++i) {
        EXPECT_EQ(a.lights[i].direction, b.lights[i].direction);
        EXPECT_EQ(a.lights[i].color, b.lights[i].color);
        EXPECT_EQ(a.lights[i].intensity, b.lights[i].intensity);
    }
    EXPECT_EQ(a.background, b.background);
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.description, b.description);
}

const ParamInfo& param(NodeKind kind, std::string_view name) {
    for (const ParamInfo& p : kindInfo(kind).params)
        if (p.name == name) return p;
    throw std::runtime_error("no parameter " + std::string(name));
}

} // namespace

TEST(Parse, EveryBundledSceneAndFixtureParses) {
    const auto bundled = jsonFiles(kSource / "assets/scenes");
    EXPECT_GE(bundled.size(), 6u) << "assets/scenes should hold the bundled scenes";
    for (const fs::path& file : validScenes()) {
        auto r = loadScene(file);
        EXPECT_TRUE(r) << file << ":\n" << (r ? "" : r.error().str());
        if (!r) continue;
        EXPECT_FALSE(r->nodes.empty());
        EXPECT_EQ(r->file, file.string());
    }
}

TEST(Parse, BadInputsGiveExactMessages) {
    const auto cases = badInputs();
    EXPECT_GE(cases.size(), 40u);
    for (const BadInput& c : cases) {
        SCOPED_TRACE(c.name);
        EXPECT_EQ(errorOf(c.json), c.expected);
    }
}

TEST(Parse, ErrorKinds) {
    auto kindOf = [](std::string_view json, const Limits& limits = {}) {
        auto r = parseScene(json, "scene.json", limits);
        EXPECT_FALSE(r);
        return r ? ErrorKind::Usage : r.error().kind;
    };
    EXPECT_EQ(kindOf("{"), ErrorKind::Syntax);
    EXPECT_EQ(kindOf(scene(R"({"type": "sphere", "radius": -1})")), ErrorKind::Validation);
    EXPECT_EQ(kindOf(nestedUnions(3), Limits{.maxDepth = 2}), ErrorKind::Limit);
    EXPECT_EQ(kindOf(std::string(2000, '[')), ErrorKind::Limit);
    auto r = parseScene("{\n  }", "scene.json");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().diagnostics[0].line, 0) << "validation errors carry a path, not a position";
    auto s = parseScene("{\n  x", "scene.json");
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error().diagnostics[0].line, 2);
    EXPECT_EQ(s.error().diagnostics[0].column, 3);
}

TEST(Parse, NodeDepthLimitNamesTheNode) {
    const Limits limits{.maxDepth = 2};
    EXPECT_EQ(errorOf(nestedUnions(2), limits), "<parsed>") << "two nested operations are allowed";
    EXPECT_EQ(errorOf(nestedUnions(3), limits),
              "scene.json: root.children[0].children[0]: nesting too deep: more than 2 nested "
              "operations");
    // With the default limit the message still names the node, however long its path.
    std::string path = "root";
    for (int i = 0; i < 64; ++i)
        path += ".children[0]";
    EXPECT_EQ(errorOf(nestedUnions(64)), "<parsed>");
    EXPECT_EQ(errorOf(nestedUnions(65)),
              "scene.json: " + path + ": nesting too deep: more than 64 nested operations");
}

TEST(Parse, NodeCountLimit) {
    const Limits limits{.maxNodes = 4};
    EXPECT_EQ(errorOf(unionOf({S, S, S}), limits), "<parsed>");
    EXPECT_EQ(errorOf(unionOf({S, S, S, S}), limits),
              "scene.json: root.children[3]: too many nodes: a scene may have at most 4");
}

TEST(Parse, NestingHundredThousandDeepIsRefused) {
    // Plain arrays, and a tree of nodes: both stop at the JSON depth limit with a position.
    const std::string arrays = std::string(100000, '[') + std::string(100000, ']');
    EXPECT_EQ(errorOf(arrays),
              "scene.json:1:1025: nesting too deep: more than 1024 levels of arrays and objects");
    const std::string nodes = nestedUnions(100000);
    EXPECT_EQ(errorOf(nodes),
              "scene.json:1:" + std::to_string(columnOfOpening(nodes, 1025)) +
                  ": nesting too deep: more than 1024 levels of arrays and objects");
    // The same through a file.
    const fs::path file = outputDir() / "deep.json";
    std::ofstream(file, std::ios::binary) << arrays;
    auto r = loadScene(file);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().str(), file.string() + ":1:1025: nesting too deep: more than 1024 levels "
                                               "of arrays and objects");
}

TEST(Parse, FiftyMegabyteFileIsRefusedBeforeReading) {
    const fs::path file = outputDir() / "huge.json";
    {
        std::ofstream out(file, std::ios::binary);
        out << R"({"version": 1, "root": {"type": "sphere", "radius": 1}, "description": ")";
        const std::string chunk(1 << 20, 'a');
        for (int i = 0; i < 50; ++i)
            out << chunk;
        out << "\"}";
    }
    const auto size = fs::file_size(file);
    ASSERT_GT(size, 50u << 20);
    auto r = loadScene(file);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().kind, ErrorKind::Limit);
    EXPECT_EQ(r.error().str(), file.string() + ": file too large: " + std::to_string(size) +
                                   " bytes (the limit is 16777216 bytes)");
    std::string text(50u << 20, ' ');
    EXPECT_EQ(errorOf(text),
              "scene.json: file too large: 52428800 bytes (the limit is 16777216 bytes)");
    fs::remove(file);
}

TEST(Parse, LargeInputWithinTheLimitIsHandledQuickly) {
    // 15 MB of numbers where a string belongs: one clear message, no crash, no crawl.
    std::string json = R"({"version": 1, "root": {"type": "sphere", "radius": 1}, "name": [)";
    while (json.size() < (15u << 20))
        json += "1.5, ";
    json += "1]}";
    const auto start = std::chrono::steady_clock::now();
    const std::string message = errorOf(json);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_TRUE(message.starts_with("scene.json: name: expected a string, got an array of "))
        << message;
    EXPECT_LT(seconds, 5.0);
}

TEST(Parse, ProblemsAreCapped) {
    std::string json = R"({"version": 1, "root": {"type": "union", "children": [)";
    for (int i = 0; i < 60; ++i)
        json += std::string(i ? ", " : "") + R"({"type": "sphere", "radius": -1})";
    json += "]}}";
    auto r = parseScene(json, "scene.json");
    ASSERT_FALSE(r);
    ASSERT_EQ(r.error().diagnostics.size(), 51u);
    EXPECT_EQ(r.error().diagnostics[49].str(),
              "scene.json: root.children[49].radius: expected a positive number, got -1");
    EXPECT_EQ(r.error().diagnostics[50].str(), "scene.json: 10 more problems not shown");
}

TEST(Parse, IoErrors) {
    const fs::path missing = outputDir() / "no-such-scene.json";
    auto r = loadScene(missing);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().kind, ErrorKind::Io);
    EXPECT_EQ(r.error().str(), missing.string() + ": cannot read file: No such file or directory");
    auto d = loadScene(outputDir());
    ASSERT_FALSE(d);
    EXPECT_EQ(d.error().kind, ErrorKind::Io);
}

TEST(Parse, ValuesLandInTheTableSlots) {
    auto r = loadScene(kSource / "tests/data/valid/everything.json");
    ASSERT_TRUE(r) << r.error().str();
    const Scene& s = *r;
    EXPECT_EQ(s.name, "Every field");
    ASSERT_EQ(s.nodes.size(), 13u);
    // Pre-order: every parent before its children, children in file order.
    std::vector<NodeKind> kinds;
    for (const Node& n : s.nodes)
        kinds.push_back(n.kind);
    using K = NodeKind;
    EXPECT_EQ(kinds, (std::vector<K>{K::Union, K::Plane, K::Sphere, K::Box, K::RoundBox,
                                     K::TriangularPrism, K::Torus, K::Difference, K::Cylinder,
                                     K::Cone, K::Intersection, K::Capsule, K::Cone}));
    EXPECT_EQ(s.nodes[0].children, (std::vector<uint32_t>{1, 2, 3, 4, 5, 6, 7, 10}));
    EXPECT_EQ(s.nodes[7].children, (std::vector<uint32_t>{8, 9}));
    EXPECT_EQ(s.nodes[10].children, (std::vector<uint32_t>{11, 12}));
    EXPECT_EQ(s.nodes[8].path, "root.children[6].children[0]");
    EXPECT_EQ(s.nodes[12].path, "root.children[7].children[1]");

    auto at = [&](size_t node, std::string_view name) {
        return s.nodes[node].params[param(s.nodes[node].kind, name).slot];
    };
    EXPECT_EQ(at(0, "smooth"), 0.05f);
    // The plane's normal [0, 2, 0] is normalised; the offset stays as written.
    EXPECT_EQ(at(1, "normal"), 0.0f);
    EXPECT_EQ(s.nodes[1].params[param(K::Plane, "normal").slot + 1], 1.0f);
    EXPECT_EQ(at(1, "offset"), -1.0f);
    EXPECT_EQ(at(4, "radius"), 0.1f);
    EXPECT_EQ(s.nodes[4].transform.scale, glm::vec3(0.8f));
    EXPECT_EQ(at(5, "height"), 0.8f);
    EXPECT_EQ(at(9, "top_radius"), 0.1f);
    EXPECT_EQ(at(12, "top_radius"), 0.0f)
        << "an absent optional parameter takes the table's fallback";
    EXPECT_EQ(s.nodes[11].params[param(K::Capsule, "b").slot + 1], 0.5f);
    EXPECT_EQ(at(11, "radius"), 0.3f);
    EXPECT_EQ(s.nodes[3].transform.rotate, glm::vec3(0, 30, 0));
    // Colours: arrays, hex, and unset (inherited).
    EXPECT_EQ(s.nodes[0].color, glm::vec3(0.8f));
    EXPECT_EQ(s.nodes[2].color, glm::vec3(1, 0, 0));
    EXPECT_FALSE(s.nodes[3].color);
    EXPECT_EQ(s.background, glm::vec3(0x20, 0x30, 0x40) / 255.0f);
    ASSERT_TRUE(s.camera);
    EXPECT_EQ(s.camera->fov, 50.0f);
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_EQ(s.lights[1].color, glm::vec3(0x80, 0x90, 0xff) / 255.0f);
    EXPECT_EQ(s.lights[0].intensity, 1.2f);
}

TEST(Parse, ByteOrderMarkAndVersionAsFloat) {
    EXPECT_EQ(errorOf("\xEF\xBB\xBF" + scene(S)), "<parsed>");
    EXPECT_EQ(errorOf(R"({"version": 1.0, "root": {"type": "sphere", "radius": 1}})"), "<parsed>");
}

TEST(Parse, RoundTripThroughToJson) {
    std::vector<fs::path> files = validScenes();
    for (const auto& f : jsonFiles(kSource / "tests/data/legacy"))
        files.push_back(f);
    for (const fs::path& file : files) {
        SCOPED_TRACE(file.string());
        auto first = loadScene(file);
        ASSERT_TRUE(first) << first.error().str();
        const std::string text = toJson(*first);
        auto second = parseScene(text, "round-trip.json");
        ASSERT_TRUE(second) << second.error().str() << "\n" << text;
        if (file.parent_path().filename() == "legacy") {
            // Converted nodes are named by legacy index; the written file gives tree paths.
            for (size_t i = 0; i < first->nodes.size(); ++i)
                first->nodes[i].path = second->nodes[i].path;
        }
        expectSameScene(*first, *second);
        EXPECT_EQ(toJson(*second), text) << "toJson is stable";
    }
}

TEST(Parse, ToJsonFormat) {
    Scene s;
    s.nodes.resize(3);
    s.nodes[0].kind = NodeKind::Difference;
    s.nodes[0].name = "part";
    s.nodes[0].children = {1, 2};
    s.nodes[1].kind = NodeKind::Box;
    s.nodes[1].params = {1, 2, 0.5f};
    s.nodes[1].color = glm::vec3(1.0f, 0.5f, 0.0f);
    s.nodes[2].kind = NodeKind::Cone;
    s.nodes[2].params = {0.25f, 3, 0};
    s.nodes[2].transform.translate = {0, 1, 0};
    s.nodes[2].transform.scale = glm::vec3(2);
    s.background = {0, 0, 0};
    // 2-space indentation; vectors on one line; keys in a fixed order; defaults left out
    // (smooth 0, top_radius 0, zero rotation, unit scale, no camera or lights); colours that
    // are exact 8-bit values as hex.
    EXPECT_EQ(toJson(s), R"({
  "version": 1,
  "background": "#000000",
  "root": {
    "type": "difference",
    "name": "part",
    "children": [
      {
        "type": "box",
        "size": [1, 2, 0.5],
        "color": [1, 0.5, 0]
      },
      {
        "type": "cone",
        "radius": 0.25,
        "height": 3,
        "translate": [0, 1, 0],
        "scale": 2
      }
    ]
  }
}
)");
}

TEST(Parse, NegativeZeroIsWrittenAsZero) {
    // The legacy reader keeps -0.0 as a float; simdjson may read "-0" back as the integer 0, so
    // a signed zero in the output would change on the next load and save.
    auto legacy = parseScene(R"({"nodes": [{"type": 7, "left": -1, "right": -1,
        "param1": [-0.0, 0, 0, 0], "param2": [0.5, 0.8, 0.2, 0.3]}]})",
                             "legacy.json");
    ASSERT_TRUE(legacy) << legacy.error().str();
    const std::string text = toJson(*legacy);
    EXPECT_NE(text.find(R"("a": [0, 0, 0])"), std::string::npos) << text;
    auto again = parseScene(text, "again.json");
    ASSERT_TRUE(again) << again.error().str();
    EXPECT_EQ(toJson(*again), text);
}

TEST(Parse, DefaultLights) {
    const auto lights = defaultLights();
    ASSERT_EQ(lights.size(), 2u);
    EXPECT_GT(lights[0].intensity, lights[1].intensity) << "key brighter than fill";
    EXPECT_GT(lights[0].color.r, lights[0].color.b) << "warm key";
    EXPECT_LT(lights[1].color.r, lights[1].color.b) << "cool fill";
    // The key comes from the upper front left, so it travels right, down and back.
    EXPECT_GT(lights[0].direction.x, 0.0f);
    EXPECT_LT(lights[0].direction.y, 0.0f);
    EXPECT_LT(lights[0].direction.z, 0.0f);
    for (const Light& l : lights)
        EXPECT_NEAR(glm::length(l.direction), 1.0f, 1e-6f);
}

TEST(Parse, SmallScenesParseWellUnderAMillisecond) {
#if defined(__SANITIZE_ADDRESS__) // GCC; clang says so through __has_feature
    GTEST_SKIP() << "AddressSanitizer makes parsing several times slower";
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
    GTEST_SKIP() << "AddressSanitizer makes parsing several times slower";
#endif
#endif
    std::ifstream in(kSource / "assets/scenes/house.json", std::ios::binary);
    ASSERT_TRUE(in);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    constexpr int kRuns = 200;
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < kRuns; ++i)
        ASSERT_TRUE(parseScene(text, "house.json"));
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count() /
        kRuns;
    std::printf("house.json (%zu bytes): %.3f ms per parse\n", text.size(), ms);
    EXPECT_LT(ms, 1.0);
}
