// sdfcsg: the one table of node kinds.
//
// The parser, the validator, the JSON Schema, the documentation, the CPU evaluator and the GLSL
// emitter are all driven by this table, so adding a primitive starts here (and in the two
// formula files, engine/src/sdf.h and shaders/sdf.glsl, which tests hold to each other).
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

namespace sdfcsg {

enum class NodeKind : uint8_t {
    Sphere,
    Box,
    RoundBox,
    Plane,
    TriangularPrism,
    Torus,
    Cylinder,
    Cone,
    Capsule,
    Union,
    Intersection,
    Difference,
};
inline constexpr int kNodeKindCount = 12;

// Every node stores its numeric parameters in this many float slots (see ParamInfo::slot).
inline constexpr int kMaxParams = 8;

enum class ValueType : uint8_t { Number, Vec3 };
enum class Check : uint8_t {
    Any,         // any finite value
    Positive,    // > 0 (each component for vectors)
    NonNegative, // >= 0
    NonZero,     // a vector of non-zero length (normalised on load)
};

struct ParamInfo {
    std::string_view name; // JSON key
    ValueType type;
    Check check;
    uint8_t slot;          // first float slot in Node::params (a Vec3 takes three)
    bool required;
    float fallback[3];     // value when an optional parameter is absent
    std::string_view unit; // "length", "unit vector", ...
    std::string_view doc;
};

struct KindInfo {
    NodeKind kind;
    std::string_view name; // JSON "type"
    bool operation;        // has "children"
    std::span<const ParamInfo> params;
    std::string_view doc;
};

// Keys every node may carry besides its parameters.
struct CommonKey {
    std::string_view name;
    std::string_view schemaType; // JSON Schema fragment, e.g. {"type":"string"}
    std::string_view doc;
};

std::span<const KindInfo> nodeKinds();
const KindInfo& kindInfo(NodeKind kind);
const KindInfo* findKind(std::string_view name); // nullptr when unknown
// type, name, translate, rotate, scale, color and (operations only) children.
std::span<const CommonKey> commonNodeKeys();

} // namespace sdfcsg
