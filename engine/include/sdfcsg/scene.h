// sdfcsg: scenes, their JSON format, and loading with strict validation.
//
// The format is documented in docs/scene-format.md and assets/scene.schema.json.
// Lengths are in scene units (metres by convention), angles in degrees, colours in 0..1.
#pragma once

#include "sdfcsg/error.h"
#include "sdfcsg/nodes.h"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace sdfcsg {

inline constexpr int kSceneVersion = 1;

struct Transform {
    glm::vec3 translate{0.0f};
    glm::vec3 rotate{0.0f}; // degrees about x, then y, then z
    glm::vec3 scale{1.0f};  // per axis, > 0; "scale": 2 in a file is [2, 2, 2]
};

// A parameter of a definition or an argument of a use: its name and its value as JSON text
// ("2", "[1, 0, 0]", "\"#ff8000\""), which may be a number, a string or an array.
struct NamedValue {
    std::string name;
    std::string json;
    bool operator==(const NamedValue&) const = default;
};

// A named subtree that "use" nodes copy ("definitions" in a file; docs/scene-format.md,
// "Definitions and uses"). Its node is kept as written, as JSON text, since its values may be
// "$name" references to its parameters; the loader reads it again for each use.
struct Definition {
    std::string name;
    std::vector<NamedValue> parameters; // in the order written, each with its default
    std::string node; // JSON text of the node; toJson writes null if it is not JSON
    bool operator==(const Definition&) const = default;
};

// A node written as {"type": "use", "definition": ...}. The loader makes it a union of one child,
// a copy of the definition's node with the use's arguments, else the defaults, in place of the
// "$name" references; the use's name, transform and colour are the union's. toJson writes the
// use back, not its copy.
struct Use {
    std::string definition;            // a name in Scene::definitions
    std::vector<NamedValue> arguments; // the parameters it sets, in the order written
    bool operator==(const Use&) const = default;
};

struct Node {
    NodeKind kind = NodeKind::Sphere;
    std::string name; // optional label
    // JSON path in the source, e.g. "root.children[1]"; in the copy that a use makes, the path in
    // the definition ("definitions.leg.node.children[0]"), the same for every copy.
    std::string path;
    Transform transform;
    std::optional<glm::vec3> color;         // unset: inherited from the parent
    std::array<float, kMaxParams> params{}; // laid out by the kind's ParamInfo::slot
    std::vector<uint32_t> children;         // indices into Scene::nodes, operations only
    // Polygon: its points; text: its string and font (ParamInfo::slot indexes strings).
    std::vector<glm::vec2> points;
    std::array<std::string, 2> strings;
    // The data that follows the node in the node buffer, made by the loader and shared by copies
    // of the scene: polygon and text, the outline's records and segments (sdOutline's layout,
    // scene/outline.h); image, its grid of distances (sdImage's, scene/image.h).
    std::shared_ptr<const std::vector<glm::vec4>> words;
    // Set on a use of a definition: this union's one child, and everything below it, is the copy.
    std::optional<Use> use;
};

struct Camera {
    glm::vec3 eye{0.0f, 0.0f, 5.0f};
    glm::vec3 target{0.0f};
    glm::vec3 up{0.0f, 1.0f, 0.0f};
    float fov = 45.0f; // vertical field of view, degrees
};

struct Light {
    glm::vec3 direction{-0.4f, -1.0f, -0.3f}; // direction the light travels (towards the scene)
    glm::vec3 color{1.0f};
    float intensity = 1.0f;
};

// Where the files that a scene names may come from: today a text node's "font", tomorrow any node
// that reads a file. One rule for all of them, applied by the loader:
//  - A relative name resolves in `folder`; loadScene() sets the scene file's folder, so a scene
//    and the files beside it move together. An empty folder is the working directory for a
//    trusted scene, and no folder at all for an untrusted one.
//  - A trusted scene (one the user loads) may name any file, absolute paths and ".." included,
//    and a problem with the file says what it is ("no such file", "not a regular file", ...).
//  - An untrusted scene (a language model's answer: generateScene() parses every answer so) may
//    name only files inside `folder` (no absolute path, no "..", none where the folder is empty),
//    and every problem with a file it names reads the same, "unknown font" for a font: its
//    messages, which go back to the model, tell nothing about the file system.
// Fonts named by family ("DejaVu Sans") come from fontconfig under either rule.
struct SceneFiles {
    std::filesystem::path folder;
    bool trusted = true;
};

struct Scene {
    std::string file;        // where it came from, for messages
    SceneFiles files;        // the rule it was loaded under, for parsing an edited copy
    std::vector<Node> nodes; // nodes[0] is the root; a parent always precedes its children
    std::vector<Definition> definitions; // in the order written; the uses in `nodes` are expanded
    std::optional<Camera> camera;        // unset: framed automatically from the scene's bounds
    std::vector<Light> lights;           // empty: the default two-light rig (defaultLights())
    glm::vec3 background{0.60f, 0.72f, 0.85f};
    std::string name;        // optional title ("name" in the file)
    std::string description; // optional free text ("description" in the file)
};

// Limits enforced while loading, before any work that depends on the input's size.
struct Limits {
    size_t maxFileBytes = 16u << 20; // 16 MiB
    // Counted with every use expanded, before any copy is made.
    uint32_t maxNodes = 16384;
    uint32_t maxDepth = 64; // operations nested inside operations
};

struct ParseOptions {
    Limits limits;
    SceneFiles files; // default: trusted, relative names in the working directory
};

// Parses and validates a scene in either the current format or the legacy SDFBooleanEngine
// format (detected by its top-level "nodes" array). `file` is used in messages only.
// Every problem found is reported (up to a few dozen), each with its JSON path.
Result<Scene> parseScene(std::string_view json, std::string_view file, const ParseOptions& options);
// The same, trusted, with relative file names in the working directory.
Result<Scene> parseScene(std::string_view json, std::string_view file = "<input>",
                         const Limits& limits = {});

// Reads and parses a file, trusted, with relative file names in the file's folder; I/O errors
// and oversize files are reported like any other.
Result<Scene> loadScene(const std::filesystem::path& path, const Limits& limits = {});

// The files that the scene's nodes read (an image's, a heightmap's or a mesh's "file"), each
// once, in the order of the nodes, joined to scene.files' folder as the loader joins them: what a
// viewer watches to load them again when they change.
std::vector<std::filesystem::path> filesRead(const Scene& scene);

// Serialises to the current format (2-space indent, stable key order). parseScene(toJson(s))
// gives back an equal scene.
std::string toJson(const Scene& scene);

std::vector<Light> defaultLights();

// The JSON Schema (draft 2020-12) of the current format, generated from the node kind table.
// assets/scene.schema.json holds a copy; a test keeps the two equal.
std::string sceneJsonSchema();

// The Markdown reference of every node kind and field (units, defaults, meaning), generated from
// the same table; docs/scene-format.md embeds it and a test keeps the two equal.
std::string sceneFormatReference();

} // namespace sdfcsg
