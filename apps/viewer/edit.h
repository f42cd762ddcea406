// Edits of a scene in memory, as the viewer's inspector and command scripts make them. Every
// edit returns a new scene that has been through the loader's validation (the scene is written
// to JSON and parsed back), so an edit can never leave an invalid scene behind, and node indices
// are renumbered in the loader's order (a parent before its children, depth first).
#pragma once

#include <sdfcsg/error.h>
#include <sdfcsg/scene.h>

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace sdfcsg::viewer {

// "name (kind)", or the kind alone for an unnamed node; "use of leg" for a use.
std::string nodeLabel(const Scene& scene, uint32_t node);

// The outermost use whose copy holds `node` (the one written in the file), or -1 for a node in no
// copy. A copy is made by the loader from its definition, so the edits below refuse to change
// anything inside one: the definition, or the use's parameters, are what to change.
int copyingUse(const Scene& scene, uint32_t node);

// The parent of a node, or -1 for the root.
int parentOf(const Scene& scene, uint32_t node);

// A node by name (first in file order) or by index; nullopt if there is none.
std::optional<uint32_t> findNode(const Scene& scene, std::string_view nameOrIndex);

// The node of `after` that is `node` of `before`, across a reload or an outside edit: the first
// node of the same name when it has one, else the node of the same kind at the same JSON path;
// nullopt if gone.
std::optional<uint32_t> sameNode(const Scene& before, uint32_t node, const Scene& after);

// Validates through the loader: parseScene(toJson(scene)).
Result<Scene> revalidate(const Scene& scene);

// Sets one value of a node: a parameter of its kind ("radius", "size", "smooth", ...),
// "translate", "rotate" or "scale", or "color" (no values: inherit the parent's colour again).
// On a use, a parameter of its definition sets the use's value for it (one number, or three as an
// array). Errors name the key and what it expects.
Result<Scene> setValue(const Scene& scene, uint32_t node, std::string_view key,
                       std::span<const float> values);
// A text value (a text node's string or font; on a use, a parameter of its definition).
Result<Scene> setText(const Scene& scene, uint32_t node, std::string_view key,
                      std::string_view text);

// Structural edits (a renderer must recompile after these).
// Adds a node of `kind` with default sizes as the last child of an operation (an operation gets
// a sphere to operate on). *newIndex receives the new node's index.
Result<Scene> addChild(const Scene& scene, uint32_t parent, NodeKind kind,
                       uint32_t* newIndex = nullptr);
// Removes a node and its subtree; the root and an operation's only child cannot be removed.
Result<Scene> removeNode(const Scene& scene, uint32_t node);
// Turns a primitive into another primitive (parameters of the same name are kept, the others
// sized to the old primitive's extent: a sphere of radius 0.1 becomes a box 0.2 across) or an
// operation into another operation.
Result<Scene> changeKind(const Scene& scene, uint32_t node, NodeKind kind);
// Moves a node among its siblings by `delta` places (the first child of a difference is what
// the others are cut from, so order matters). *newIndex receives the node's index afterwards.
Result<Scene> moveNode(const Scene& scene, uint32_t node, int delta, uint32_t* newIndex = nullptr);

// For reparentNode's position: after the operation's other children.
inline constexpr uint32_t kLastChild = UINT32_MAX;
// Moves a node with its subtree to become child number `position` of the operation `parent`,
// counted among the children it will have (0 puts it first, kLastChild last; its own parent is
// a legal `parent`, which reorders). There is no default position: at 0 of a difference the
// node becomes what the others are cut from. The node's transform and colour stay as they are,
// so it now sits relative to the new parent and inherits that parent's colour where it sets
// none. Refused for the root, for a `parent` that is not an operation or lies in the node's
// own subtree, for a position past the end, and when it would leave its old parent without
// children. *newIndex receives the node's index afterwards.
Result<Scene> reparentNode(const Scene& scene, uint32_t node, uint32_t parent, uint32_t position,
                           uint32_t* newIndex = nullptr);
// What dropping `node` onto `target` in the scene tree does: onto an operation, the node
// becomes its last child; onto anything else, it goes just before `target` among the target's
// siblings. So a drag both reparents and reorders. *newIndex as for reparentNode.
Result<Scene> dropNode(const Scene& scene, uint32_t node, uint32_t target,
                       uint32_t* newIndex = nullptr);

} // namespace sdfcsg::viewer
