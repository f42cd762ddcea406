// sdfcsg: the one table of node kinds.
//
// The parser, the validator, the JSON Schema, the documentation, the language-model prompt, the
// viewer, the CPU evaluator and the GLSL emitter are all driven by this table, so adding a
// primitive is its line in sdfcsg/kinds.h, its entry in the table (engine/src/scene/nodes.cpp)
// and its formula in shaders/sdf.glsl, which both the CPU and the GPU compile
// (docs/vocabulary.md).
#pragma once

#include "sdfcsg/kinds.h"

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace sdfcsg {

// Every kind of node, numbered in the order of sdfcsg/kinds.h.
enum class NodeKind : uint8_t {
#define SDFCSG_KIND_ENUM(name) name,
    SDFCSG_NODE_KINDS(SDFCSG_KIND_ENUM)
#undef SDFCSG_KIND_ENUM
};

#define SDFCSG_KIND_COUNT(name) +1
inline constexpr int kNodeKindCount = 0 SDFCSG_NODE_KINDS(SDFCSG_KIND_COUNT);
// The first kind of each group after the primitives (kinds.h keeps the groups in this order).
inline constexpr NodeKind kFirstProfile = NodeKind(0 SDFCSG_PRIMITIVE_KINDS(SDFCSG_KIND_COUNT));
inline constexpr NodeKind kFirstOperation =
    NodeKind(int(kFirstProfile) SDFCSG_PROFILE_KINDS(SDFCSG_KIND_COUNT));
inline constexpr NodeKind kFirstValueOperation =
    NodeKind(int(kFirstOperation) SDFCSG_BOOLEAN_KINDS(SDFCSG_KIND_COUNT));
inline constexpr NodeKind kFirstDomainOperation =
    NodeKind(int(kFirstValueOperation) SDFCSG_VALUE_KINDS(SDFCSG_KIND_COUNT));
#undef SDFCSG_KIND_COUNT

// Every node stores its numeric parameters in this many float slots (see ParamInfo::slot). A
// kind's kernel parameters, which the shaders take as two vec4s, use the first eight.
inline constexpr int kMaxParams = 12;
using Params = std::array<float, kMaxParams>;

// Choice: one of ParamInfo::choices by name, stored as its index.
// Points: [[x, y], ...] in Node::points; Text: a string in Node::strings[slot].
enum class ValueType : uint8_t { Number, Vec3, Choice, Points, Text };
enum class Check : uint8_t {
    Any,         // any finite value
    Positive,    // > 0 (each component for vectors)
    NonNegative, // >= 0
    NonZero,     // a vector of non-zero length (normalised on load)
    Count,       // a whole number >= 1 (each component for vectors)
};

struct ParamInfo {
    std::string_view name; // JSON key
    ValueType type;
    Check check;
    uint8_t slot; // first float slot in Node::params (a Vec3 takes three)
    bool required;
    float fallback[3];     // value when an optional parameter is absent
    std::string_view unit; // "length", "unit vector", ...
    std::string_view doc;
    float maximum = 3.4e38f;                     // Number: the largest value accepted
    std::span<const std::string_view> choices{}; // Choice: the names, in stored order
    float least = 1.0f;                          // Count: the smallest value accepted
};

// How the inlined GLSL calls a primitive's formula: the kernel parameters after the local point,
// as (first slot, component count).
struct KernelArg {
    uint8_t slot, count;
};

// What a kind is: a primitive, a Boolean operation of any number of children, an operation on
// one child's value, or one on the space its one child is evaluated in.
enum class Role : uint8_t { Primitive, Boolean, Value, Domain };

// 2D profiles are primitives of the xy plane: as fields of space they are prisms along z, and
// only extrude and revolve, which cut them at z = 0, may hold them.
inline constexpr bool isProfile(NodeKind kind) {
    return kind >= kFirstProfile && kind < kFirstOperation;
}
// Transition_linear and transition_radial: the Boolean kinds of exactly two children, a morph
// from the first to the second by a weight that follows the point.
inline constexpr bool isTransition(NodeKind kind) {
    return kind == NodeKind::TransitionLinear || kind == NodeKind::TransitionRadial;
}
// Polygon and text: their outlines' segments live beside the node (Node::words).
inline constexpr bool hasOutline(NodeKind kind) {
    return kind == NodeKind::Polygon || kind == NodeKind::Text;
}
// The kinds whose data follows them in the node buffer (Node::words): outlines and images.
inline constexpr bool hasWords(NodeKind kind) {
    return hasOutline(kind) || kind == NodeKind::Image || kind == NodeKind::Heightmap ||
           kind == NodeKind::Mesh;
}
// A polygon's points, at most; and the vec4s of every node's words in a scene (outlines, a large
// one listing its segments per cell of a grid, and images), so that they stay within 64 MiB of
// the node buffer.
inline constexpr size_t kMaxPolygonPoints = 1024;
inline constexpr size_t kMaxOutlineWords = size_t(1) << 22;

struct KindInfo {
    NodeKind kind;
    std::string_view name; // JSON "type"
    bool operation;        // has "children"
    std::span<const ParamInfo> params;
    std::string_view doc;
    // The JSON members of a typical node of this kind, about a unit across (what an editor adds,
    // the schema's and the prompt's example, the tests' instance): `"radius": 0.8`.
    std::string_view example;
    // Primitives only. The formula in shaders/sdf.glsl and its arguments after the point.
    std::string_view function{};
    std::span<const KernelArg> args{};
    // What the formula takes, from the JSON values (half extents and the like), so that the
    // shaders do no arithmetic on them.
    Params (*kernel)(const Params& values) = nullptr;
    // The exact local bounding box of the solid, from the kernel parameters; false when it has
    // none (a plane).
    bool (*bounds)(const Params& kernel, glm::vec3& lo, glm::vec3& hi) = nullptr;
    Role role = Role::Primitive;
    // Value and domain operations. What the formulas take, from the JSON values and the child's
    // bounds in the space it is evaluated in; and the node's own bounds from those.
    Params (*kernelAround)(const Params& values, glm::vec3 childLo, glm::vec3 childHi) = nullptr;
    void (*boundsAround)(const Params& kernel, glm::vec3 childLo, glm::vec3 childHi, glm::vec3& lo,
                         glm::vec3& hi) = nullptr;
    // Domain operations that stretch space (twist, bend, taper): a Lipschitz bound of the map
    // from the node's local space to its child's over the box [lo, hi] of that local space. The
    // child's value is divided by it, and the map only sees points clamped into the node's
    // bounds (the formula in shaders/sdf.glsl, domainFinish).
    float (*lipschitz)(const Params& kernel, glm::vec3 lo, glm::vec3 hi) = nullptr;
    // Primitives whose nodes may have colours of their own (a mesh's vertex or material colours):
    // the formula in shaders/sdf.glsl of the colour at a local point, which takes the point, the
    // arguments of `function` and the node's colour (what it gives where it has none); and
    // whether a node's words (Node::words) hold colours. A node whose words hold none takes its
    // node's colour, and the code calls no formula for it (ownColors).
    std::string_view colorFunction{};
    bool (*colored)(std::span<const glm::vec4> words) = nullptr;
    // Primitives whose field may fall below their box's signed distance far from the solid (a
    // mesh's, whose grid of bricks reaches past its box: beyond the grid the field is the
    // distance to the grid plus the band). Their value is floored at that distance, as an
    // unevenly scaled node's is (FlatNode::boundsFloor): it stays a bound, since the surface lies
    // within the box.
    bool floored = false;
};

// Keys every node may carry besides its parameters.
struct CommonKey {
    std::string_view name;
    std::string_view schemaType; // JSON Schema fragment, e.g. {"type":"string"}
    std::string_view doc;
};

std::span<const KindInfo> nodeKinds();
// A kind's example as a whole node: {"type": name, example members}, and for an operation
// "children" with one operand (a sphere; a circle under extrude and revolve).
std::string exampleNodeJson(const KindInfo& kind);
const KindInfo& kindInfo(NodeKind kind);
// Whether a node of this kind with these words (Node::words, may be null) has colours of its own
// (KindInfo::colored), which its kind's colorFunction gives.
inline bool ownColors(NodeKind kind, const std::vector<glm::vec4>* words) {
    const KindInfo& info = kindInfo(kind);
    return info.colored && words && info.colored(*words);
}

// A kind's parameters in the order the modelling API (sdfcsg/model.h) and the Python module take
// them by position: the required ones first, then the optional ones, each in the table's order.
inline std::vector<const ParamInfo*> positionalParams(const KindInfo& kind) {
    std::vector<const ParamInfo*> out;
    for (int pass = 0; pass < 2; ++pass)
        for (const ParamInfo& p : kind.params)
            if (p.required == (pass == 0)) out.push_back(&p);
    return out;
}
const KindInfo* findKind(std::string_view name); // nullptr when unknown
// type, name, translate, rotate, scale, color and (operations only) children.
std::span<const CommonKey> commonNodeKeys();

} // namespace sdfcsg
