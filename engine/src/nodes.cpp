#include "sdfcsg/nodes.h"

namespace sdfcsg {
namespace {

using enum ValueType;
using enum Check;

constexpr ParamInfo kSphere[] = {
    {"radius", Number, Positive, 0, true, {}, "length", "Radius."},
};
constexpr ParamInfo kBox[] = {
    {"size", Vec3, Positive, 0, true, {}, "length", "Full edge lengths along x, y and z."},
};
constexpr ParamInfo kRoundBox[] = {
    {"size", Vec3, Positive, 0, true, {}, "length", "Full edge lengths along x, y and z, rounding included."},
    {"radius", Number, NonNegative, 3, true, {}, "length",
     "Edge rounding radius; at most half the smallest edge length."},
};
constexpr ParamInfo kPlane[] = {
    {"normal", Vec3, NonZero, 0, false, {0, 1, 0}, "direction",
     "Outward normal; the solid is the half-space behind it. Normalised on load."},
    {"offset", Number, Any, 3, false, {0, 0, 0}, "length",
     "Signed distance of the plane from the origin along the normal."},
};
constexpr ParamInfo kTriangularPrism[] = {
    {"width", Number, Positive, 0, true, {}, "length", "Base width of the triangle (x)."},
    {"height", Number, Positive, 1, true, {}, "length", "Height of the triangle from base to apex (y)."},
    {"length", Number, Positive, 2, true, {}, "length", "Extrusion length (z)."},
};
constexpr ParamInfo kTorus[] = {
    {"major_radius", Number, Positive, 0, true, {}, "length",
     "Radius of the ring's centre line, in the xz plane."},
    {"minor_radius", Number, Positive, 1, true, {}, "length", "Radius of the tube."},
};
constexpr ParamInfo kCylinder[] = {
    {"radius", Number, Positive, 0, true, {}, "length", "Radius."},
    {"height", Number, Positive, 1, true, {}, "length", "Full height along y."},
};
constexpr ParamInfo kCone[] = {
    {"radius", Number, Positive, 0, true, {}, "length", "Base radius (at the bottom, y = -height/2)."},
    {"height", Number, Positive, 1, true, {}, "length", "Full height along y."},
    {"top_radius", Number, NonNegative, 2, false, {0, 0, 0}, "length",
     "Radius at the top (y = +height/2); 0 gives a pointed cone, more a frustum (truncated cone)."},
};
constexpr ParamInfo kCapsule[] = {
    {"a", Vec3, Any, 0, true, {}, "point", "First end point of the axis segment."},
    {"b", Vec3, Any, 3, true, {}, "point", "Second end point of the axis segment."},
    {"radius", Number, Positive, 6, true, {}, "length", "Radius."},
};
constexpr ParamInfo kOperation[] = {
    {"smooth", Number, NonNegative, 0, false, {0, 0, 0}, "length",
     "Blend radius of the polynomial smooth minimum/maximum; 0 gives sharp edges. "
     "Colours blend by the same factor."},
};

constexpr KindInfo kKinds[] = {
    {NodeKind::Sphere, "sphere", false, kSphere, "Sphere centred at the origin."},
    {NodeKind::Box, "box", false, kBox, "Axis-aligned box centred at the origin."},
    {NodeKind::RoundBox, "round_box", false, kRoundBox, "Box with rounded edges, centred at the origin."},
    {NodeKind::Plane, "plane", false, kPlane, "Half-space bounded by a plane (infinite)."},
    {NodeKind::TriangularPrism, "triangular_prism", false, kTriangularPrism,
     "Isosceles triangle in the xy plane (apex up, +y) extruded along z, its bounding box centred at "
     "the origin. A gable roof is one of these."},
    {NodeKind::Torus, "torus", false, kTorus, "Ring around the y axis, centred at the origin."},
    {NodeKind::Cylinder, "cylinder", false, kCylinder, "Capped cylinder along y, centred at the origin."},
    {NodeKind::Cone, "cone", false, kCone,
     "Capped cone along y, base at the bottom, centred at the origin (half way up)."},
    {NodeKind::Capsule, "capsule", false, kCapsule, "Segment from a to b swept by a sphere."},
    {NodeKind::Union, "union", true, kOperation, "All children together."},
    {NodeKind::Intersection, "intersection", true, kOperation, "What all children have in common."},
    {NodeKind::Difference, "difference", true, kOperation, "The first child minus all the others."},
};
static_assert(sizeof(kKinds) / sizeof(kKinds[0]) == kNodeKindCount);

constexpr CommonKey kCommonKeys[] = {
    {"type", R"({"type":"string"})", "Node kind: a primitive or an operation name."},
    {"name", R"({"type":"string","maxLength":200})", "Optional label, shown in errors and in generated GLSL."},
    {"translate", R"({"type":"array","items":{"type":"number"},"minItems":3,"maxItems":3})",
     "Translation [x, y, z] in parent units, applied after rotation and scale."},
    {"rotate", R"({"type":"array","items":{"type":"number"},"minItems":3,"maxItems":3})",
     "Rotation in degrees about x, then y, then z."},
    {"scale", R"({"type":"number","exclusiveMinimum":0})", "Uniform scale factor (> 0)."},
    {"color", R"({"oneOf":[{"type":"array","items":{"type":"number","minimum":0,"maximum":1},"minItems":3,"maxItems":3},{"type":"string","pattern":"^#[0-9a-fA-F]{6}$"}]})",
     "Colour as [r, g, b] in 0..1 or \"#rrggbb\"; inherited by children that set none."},
    {"children", R"({"type":"array","minItems":1,"items":{"$ref":"#/$defs/node"}})",
     "Operations only: the operands, at least one."},
};

} // namespace

std::span<const KindInfo> nodeKinds() { return kKinds; }

const KindInfo& kindInfo(NodeKind kind) { return kKinds[static_cast<int>(kind)]; }

const KindInfo* findKind(std::string_view name) {
    for (const KindInfo& k : kKinds)
        if (k.name == name) return &k;
    return nullptr;
}

std::span<const CommonKey> commonNodeKeys() { return kCommonKeys; }

} // namespace sdfcsg
