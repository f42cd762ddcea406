// sdfcsg: scenes built in code (docs/cpp-api.md).
//
//     namespace m = sdfcsg::model;
//     m::Shape part = m::roundBox({2, 1, 1}, 0.1) - m::cylinder(0.3, 2).rotate({90, 0, 0});
//     part = part.color("#d08030") | m::sphere(0.5).translate({0, 1, 0});
//     sdfcsg::Result<sdfcsg::Scene> scene = m::toScene(part);
//
// A Shape is a value: a node of the scene and its subtree, immutable and shared, so copying one
// is cheap and no change to a copy reaches another. model_kinds.h, which the build writes from
// the node table, has a function for every kind (sphere(radius), box(size), union_(children,
// smooth, blend), shell(child, thickness), ...) taking its parameters in the table's units and
// names, the required ones first; an optional one left out takes the loader's default. Every
// operation of one child is also a method (shape.shell(0.05), shape.twist(30)).
//
// Values are checked where the shape becomes a scene (toScene, toJson), by the loader itself: a
// shape builds exactly the scene that its JSON loads, and its errors are the loader's, each with
// the JSON path of the value and, as its file, the source line of the call that made the node.
#pragma once

#include "sdfcsg/error.h"
#include "sdfcsg/nodes.h"
#include "sdfcsg/scene.h"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace sdfcsg::model {

// Where a call that made a node stands in the caller's source, for errors. As a default argument,
// Where::current() is the caller's line. (The compilers' builtins rather than std::source_location,
// which clang before 15 cannot compile with GCC's standard library.)
struct Where {
    static constexpr Where current(const char* file = __builtin_FILE(),
                                   unsigned line = __builtin_LINE()) {
        return {file, line};
    }
    const char* file_name() const { return file_; }
    unsigned line() const { return line_; }

    const char* file_ = "";
    unsigned line_ = 0;
};

// A value of the scene format, kept as its JSON text: a number, a vector ({1, 2, 3} or a
// glm::vec3), a string (a choice such as "round", a text, a colour "#rrggbb", or "$name", a
// parameter of a part), a polygon's points, or absent (the default of an optional parameter).
class Value {
  public:
    Value() = default; // absent
    Value(double v);
    Value(float v); // as the writer writes floats: the shortest text that reads back as v
    Value(int v) : Value(double(v)) {}
    Value(const char* text) : Value(std::string_view(text)) {}
    Value(std::string_view text);
    Value(const std::string& text) : Value(std::string_view(text)) {}
    Value(glm::vec3 v);
    Value(glm::vec2 v);
    Value(const std::vector<glm::vec2>& points);
    Value(std::initializer_list<Value> items); // an array
    // Any JSON text, as it is.
    static Value json(std::string text);

    bool absent() const { return json_.empty(); }
    const std::string& json() const { return json_; }
    bool operator==(const Value&) const = default;

  private:
    std::string json_;
};

// A parameter or an argument by name: {"radius", 0.5}.
struct Arg {
    std::string name;
    Value value;
};

class Part;
struct ShapeData;

class Shape {
  public:
    // A union of no children: what operators start from (empty | a is a).
    Shape();
    explicit Shape(std::shared_ptr<const ShapeData> data) : data_(std::move(data)) {}

    // Transforms, applied after everything the shape already has: translate(a).rotate(r) turns
    // the moved shape about the origin. Where the node's own transform (scale, then rotate, then
    // translate) cannot hold the result, the shape is wrapped in a union of one child.
    Shape translate(glm::vec3 offset, Where where = Where::current()) const;
    Shape rotate(glm::vec3 degrees, Where where = Where::current()) const; // x, then y, then z
    Shape scale(float factor, Where where = Where::current()) const;
    Shape scale(glm::vec3 factors, Where where = Where::current()) const;
    // [r, g, b] in 0..1 or "#rrggbb"; children that set none inherit it.
    Shape color(Value color, Where where = Where::current()) const;
    Shape name(std::string name) const;
    // One parameter by its JSON name (set("radius", 2)); absent removes it.
    Shape set(std::string_view parameter, Value value, Where where = Where::current()) const;

#include "sdfcsg/model_methods.inc"

    const ShapeData& data() const {
        return *data_;
    }

  private:
    friend struct ShapeData;
    mutable std::shared_ptr<const ShapeData> data_; // mutable: released by ~ShapeData only
};

// A node: its kind ("sphere", or "use" for a use of a part), parameters as written, children, and
// the common keys.
struct ShapeData {
    std::string type;
    std::vector<Arg> args;
    std::vector<Shape> children;
    std::string name;
    Transform transform;
    Value color;
    std::shared_ptr<const Part> part; // a use's
    // Parts the scene defines besides those its uses reach, first and in this order (a loaded
    // scene's definitions, which fromScene() keeps on the root).
    std::vector<std::shared_ptr<const Part>> parts;
    Where where;
    // Where it was made as errors name it, "file:line", where `where` cannot say (bindings for
    // other languages set their caller's line); empty: from `where`.
    std::string origin;
    ShapeData() = default;
    ShapeData(const ShapeData&) = default;
    // Deep trees are released without deep recursion.
    ~ShapeData();
};

// A definition ("definitions" in a file, docs/scene-format.md): a named shape whose values may be
// "$name" references to its parameters, used any number of times with other arguments. A scene
// made from a shape holds every part that its uses reach.
class Part {
  public:
    // `parameters`: each with its default value.
    Part(std::string name, Shape node, std::vector<Arg> parameters = {});
    // A part whose node is JSON text (as Scene::definitions keep them).
    Part(Definition definition);
    // A use of the part: a union of one child, its copy with these arguments.
    Shape operator()(std::vector<Arg> arguments = {}, Where where = Where::current()) const;

    const std::string& name() const { return name_; }
    const std::vector<Arg>& parameters() const { return parameters_; }
    const std::optional<Shape>& node() const { return node_; } // unset: nodeJson()
    const std::string& nodeJson() const { return nodeJson_; }

  private:
    std::string name_;
    std::vector<Arg> parameters_;
    std::optional<Shape> node_;
    std::string nodeJson_;
};

// A node of any kind by its JSON name, with its parameters by name, and children for an
// operation: shape("sphere", {{"radius", 1}}). Absent values are left out.
Shape shape(std::string_view type, std::vector<Arg> args, std::vector<Shape> children = {},
            Where where = Where::current());

// Booleans of two shapes, flattening chains: a | b | c is one union of three children, as is
// a - b - c one difference. Equal to union_({a, b}) and the like.
Shape operator|(const Shape& a, const Shape& b);
Shape operator&(const Shape& a, const Shape& b);
Shape operator-(const Shape& a, const Shape& b);

// The scene of a shape, through the loader (parseScene), with every part its uses reach as a
// definition: its errors are the loader's, with the JSON path in the scene and, as the file, the
// source line ("main.cpp:12") of the call that made the node at fault ("<model>" when none did).
Result<Scene> toScene(const Shape& root);
// The same, with the scene's settings besides its tree as JSON values by their keys: "name",
// "description", "camera", "lights", "background" (docs/scene-format.md), checked by the loader.
Result<Scene> toScene(const Shape& root, const std::vector<Arg>& settings);
// The scene's JSON (toJson(Scene)): parseScene() of it gives back the scene.
Result<std::string> toJson(const Shape& root);
// The shape of a scene's root (every node with its values as toJson writes them, uses as uses of
// parts made from the scene's definitions); toScene() of it gives back an equal scene.
Shape fromScene(const Scene& scene);
// The shape of a scene's JSON text.
Result<Shape> fromJson(std::string_view json, std::string_view file = "<input>");

// The scene as a Python program that builds it with the module sdfcsg (docs/python.md): its
// definitions as parts, its tree as calls of the kinds' functions and methods, its settings
// through sdfcsg.scene(). Run, it saves the scene's JSON to its first argument, else to `output`;
// that JSON is toJson(scene).
std::string toPython(const Scene& scene, std::string_view output = "scene.json");
// The Python module's name for a kind's function, and for a value or domain operation its method:
// its JSON type, with a trailing underscore where the module or Shape has that name already
// (mesh_).
std::string pythonName(const KindInfo& kind);

// Editing a loaded scene in place, for Renderer::updateValues (sdfcsg/render.h), which then
// uploads or rebuilds as the change needs.
//
// The node whose name is `nameOrPath`, else whose JSON path is ("root.children[1]"); a Usage error
// naming it where there is none (a name used twice finds the first in the file's order).
Result<uint32_t> findNode(const Scene& scene, std::string_view nameOrPath);
// Sets one value of node `node`: a parameter by its JSON name, or translate, rotate, scale, color
// or name. The node, with the new value, goes through the loader's checks; an error is the
// loader's, at the node's JSON path, and leaves the scene as it was. The structure (kinds and
// children) never changes. Nodes inside a use's copy are refused (set the use's arguments).
Status setValue(Scene& scene, uint32_t node, std::string_view key, const Value& value);

} // namespace sdfcsg::model

#include "sdfcsg/model_kinds.h"
