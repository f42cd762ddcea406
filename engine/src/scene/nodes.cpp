#include "sdfcsg/nodes.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include <algorithm>
#include <cmath>

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
    {"size",
     Vec3,
     Positive,
     0,
     true,
     {},
     "length",
     "Full edge lengths along x, y and z, rounding included."},
    {"radius",
     Number,
     NonNegative,
     3,
     true,
     {},
     "length",
     "Edge rounding radius; at most half the smallest edge length."},
};
constexpr ParamInfo kPlane[] = {
    {"normal",
     Vec3,
     NonZero,
     0,
     false,
     {0, 1, 0},
     "direction",
     "Outward normal; the solid is the half-space behind it. Normalised on load."},
    {"offset",
     Number,
     Any,
     3,
     false,
     {0, 0, 0},
     "length",
     "Signed distance of the plane from the origin along the normal."},
};
constexpr ParamInfo kTriangularPrism[] = {
    {"width", Number, Positive, 0, true, {}, "length", "Base width of the triangle (x)."},
    {"height",
     Number,
     Positive,
     1,
     true,
     {},
     "length",
     "Height of the triangle from base to apex (y)."},
    {"length", Number, Positive, 2, true, {}, "length", "Extrusion length (z)."},
};
constexpr ParamInfo kTorus[] = {
    {"major_radius",
     Number,
     Positive,
     0,
     true,
     {},
     "length",
     "Radius of the ring's centre line, in the xz plane."},
    {"minor_radius", Number, Positive, 1, true, {}, "length", "Radius of the tube."},
};
constexpr ParamInfo kCylinder[] = {
    {"radius", Number, Positive, 0, true, {}, "length", "Radius."},
    {"height", Number, Positive, 1, true, {}, "length", "Full height along y."},
};
constexpr ParamInfo kCone[] = {
    {"radius",
     Number,
     Positive,
     0,
     true,
     {},
     "length",
     "Base radius (at the bottom, y = -height/2)."},
    {"height", Number, Positive, 1, true, {}, "length", "Full height along y."},
    {"top_radius",
     Number,
     NonNegative,
     2,
     false,
     {0, 0, 0},
     "length",
     "Radius at the top (y = +height/2); 0 gives a pointed cone, more a frustum (truncated cone)."},
};
constexpr ParamInfo kCapsule[] = {
    {"a", Vec3, Any, 0, true, {}, "point", "First end point of the axis segment."},
    {"b", Vec3, Any, 3, true, {}, "point", "Second end point of the axis segment."},
    {"radius", Number, Positive, 6, true, {}, "length", "Radius."},
};
constexpr ParamInfo kEllipsoid[] = {
    {"radii", Vec3, Positive, 0, true, {}, "length", "Semi-axes along x, y and z."},
};
constexpr ParamInfo kHexPrism[] = {
    {"radius",
     Number,
     Positive,
     0,
     true,
     {},
     "length",
     "Distance from the axis to the corners of the hexagon (two of them lie on the x axis)."},
    {"height", Number, Positive, 1, true, {}, "length", "Full height along y."},
};
constexpr ParamInfo kOctahedron[] = {
    {"radius", Number, Positive, 0, true, {}, "length", "Distance from the centre to each vertex."},
};
constexpr ParamInfo kPyramid[] = {
    {"width", Number, Positive, 0, true, {}, "length", "Side of the square base (in xz)."},
    {"height", Number, Positive, 1, true, {}, "length", "Height from the base to the apex (y)."},
};
constexpr ParamInfo kRoundedCylinder[] = {
    {"radius", Number, Positive, 0, true, {}, "length", "Radius, rounding included."},
    {"height", Number, Positive, 1, true, {}, "length", "Full height along y, rounding included."},
    {"rounding",
     Number,
     NonNegative,
     2,
     true,
     {},
     "length",
     "Radius of the rounded rims; clamped to the radius and to half the height."},
};
constexpr ParamInfo kRoundCone[] = {
    {"radius", Number, Positive, 0, true, {}, "length", "Radius of the bottom sphere."},
    {"top_radius", Number, Positive, 1, true, {}, "length", "Radius of the top sphere."},
    {"height",
     Number,
     Positive,
     2,
     true,
     {},
     "length",
     "Distance between the two spheres' centres (y); where one sphere holds the other, the "
     "solid is the larger sphere."},
};
constexpr ParamInfo kLink[] = {
    {"length",
     Number,
     NonNegative,
     0,
     true,
     {},
     "length",
     "Length of the straight sides (y); 0 gives a torus standing in the xy plane."},
    {"major_radius",
     Number,
     Positive,
     1,
     true,
     {},
     "length",
     "Radius of the centre line's round ends."},
    {"minor_radius", Number, Positive, 2, true, {}, "length", "Radius of the wire."},
};
constexpr ParamInfo kCappedTorus[] = {
    {"major_radius",
     Number,
     Positive,
     0,
     true,
     {},
     "length",
     "Radius of the ring's centre line, in the xz plane."},
    {"minor_radius", Number, Positive, 1, true, {}, "length", "Radius of the tube."},
    {"angle",
     Number,
     Positive,
     2,
     true,
     {},
     "degrees",
     "Angle the arc spans, centred on +z; 360 closes the ring.",
     360.0f},
};
constexpr ParamInfo kCircle[] = {
    {"radius", Number, Positive, 0, true, {}, "length", "Radius."},
};
constexpr ParamInfo kRectangle[] = {
    {"width", Number, Positive, 0, true, {}, "length", "Width along x."},
    {"height", Number, Positive, 1, true, {}, "length", "Height along y."},
    {"rounding",
     Number,
     NonNegative,
     2,
     false,
     {0, 0, 0},
     "length",
     "Radius of the rounded corners; clamped to half the smaller side."},
};
constexpr ParamInfo kRegularPolygon[] = {
    {"radius",
     Number,
     Positive,
     0,
     true,
     {},
     "length",
     "Distance from the centre to each corner; one edge is flat on top (+y)."},
    {"sides", Number, Count, 1, true, {}, "sides", "Number of sides.", 64.0f, {}, 3.0f},
};
constexpr ParamInfo kPolygon[] = {
    {"points",
     Points,
     Any,
     0,
     true,
     {},
     "points",
     "The corners [[x, y], ...] in order, either way round: 3 to 1024 of them, edges that do "
     "not cross (a simple polygon)."},
};
constexpr ParamInfo kText[] = {
    {"text", Text, Any, 0, true, {}, "characters", "One line of text, at most 256 characters."},
    {"size",
     Number,
     Positive,
     0,
     false,
     {1, 0, 0},
     "length",
     "Font size: the height of the font's em square (capitals are about 0.7 of it). Give "
     "size, width or height, not two of them."},
    {"width",
     Number,
     Positive,
     1,
     false,
     {0, 0, 0},
     "length",
     "The width of the text's ink (its outlines' extents, spaces at the ends left out): the "
     "font size that makes it so, instead of size."},
    {"height",
     Number,
     Positive,
     2,
     false,
     {0, 0, 0},
     "length",
     "The height of the text's ink, from the lowest descender to the highest glyph top of this "
     "text: the font size that makes it so, instead of size."},
    {"font",
     Text,
     Any,
     1,
     false,
     {},
     "font",
     "An installed font family (\"DejaVu Sans\", \"DejaVu Serif\"; `fc-list : family` lists "
     "them), or a TrueType or OpenType file (a name with a slash or a font extension) relative to "
     "the scene file's folder; empty or absent: DejaVu Sans (Debian's fonts-dejavu-core). "
     "Generated scenes name families only."},
};
constexpr ParamInfo kHeightmap[] = {
    {"file",
     Text,
     Any,
     0,
     true,
     {},
     "file",
     "A PNG file relative to the scene file's folder (at most 16 MiB, 4,194,304 pixels and 8192 "
     "on a side), its grey levels the heights, black 0 and white the top; only a file the user "
     "names."},
    {"size",
     Vec3,
     Positive,
     0,
     true,
     {},
     "length",
     "The box the heights fill: the image's width along x, white's height along y (black is at "
     "y = 0) and the image's height along z (its top row at -z)."},
};
constexpr ParamInfo kMesh[] = {
    {"file",
     Text,
     Any,
     0,
     true,
     {},
     "file",
     "A triangle mesh file relative to the scene file's folder: STL, OBJ, PLY, glTF (.glb, or "
     ".gltf with the files it names in its own folder) or 3MF (at most 256 MiB and 8,388,608 "
     "triangles); only a file the user names."},
    {"resolution",
     Number,
     Count,
     0,
     false,
     {128, 0, 0},
     "cells",
     "Cells of its field along the mesh's longest side; the field is exact to interpolation "
     "within about two cells of the surface.",
     1024.0f,
     {},
     8.0f},
    {"fit",
     Vec3,
     Positive,
     1,
     false,
     {0, 0, 0},
     "length",
     "A box [x, y, z] the mesh is made to fit: scaled by one factor on every axis (its "
     "proportions kept) until it touches the box's sides, and centred on the origin. Absent: the "
     "file's own units and place."},
    {"band",
     Number,
     Positive,
     4,
     false,
     {0, 0, 0},
     "length",
     "How far from the surface the field is the exact distance (beyond, a bound). Absent: two "
     "cells. A shell or offset of the mesh, or a smooth blend with it, needs a band wider than "
     "its thickness, distance or blend radius; a wider band holds more of the field's 64 MiB."},
};
constexpr std::string_view kImageInside[] = {"dark", "light"};
constexpr ParamInfo kImage[] = {
    {"file",
     Text,
     Any,
     0,
     true,
     {},
     "file",
     "A PNG file relative to the scene file's folder (at most 16 MiB, 4,194,304 pixels and 8192 "
     "on a side); only a file the user names."},
    {"size",
     Number,
     Positive,
     0,
     false,
     {1, 0, 0},
     "length",
     "The image's longer side. Give size, width or height, not two of them."},
    {"width",
     Number,
     Positive,
     1,
     false,
     {0, 0, 0},
     "length",
     "The image's width, instead of size."},
    {"height",
     Number,
     Positive,
     2,
     false,
     {0, 0, 0},
     "length",
     "The image's height, instead of size."},
    {"threshold",
     Number,
     NonNegative,
     3,
     false,
     {0.5f, 0, 0},
     "fraction",
     "A pixel is inside where its ink (opacity times darkness, or lightness) is at least this.",
     1.0f},
    {"inside",
     Choice,
     Any,
     4,
     false,
     {0, 0, 0},
     "mask",
     "Which pixels are the shape: \"dark\" (dark ink on a light or transparent ground) or "
     "\"light\" (the image inverted).",
     3.4e38f,
     kImageInside},
};
constexpr ParamInfo kExtrude[] = {
    {"height",
     Number,
     Positive,
     0,
     true,
     {},
     "length",
     "Thickness along z, centred on the profile's plane."},
    {"rounding",
     Number,
     NonNegative,
     1,
     false,
     {0, 0, 0},
     "length",
     "Radius of the rounded edges where the sides meet the faces; clamped to half the height."},
};
constexpr ParamInfo kRevolve[] = {
    {"offset",
     Number,
     Any,
     0,
     false,
     {0, 0, 0},
     "length",
     "Distance of the axis from the profile's x = 0: the profile turns about the y axis after "
     "moving +offset along x (a ring from a circle)."},
};
constexpr std::string_view kBlends[] = {"smooth", "round", "chamfer"};
constexpr ParamInfo kOperation[] = {
    {"smooth",
     Number,
     NonNegative,
     0,
     false,
     {0, 0, 0},
     "length",
     "Blend radius where the operands meet; 0 gives sharp edges. Colours blend over the same "
     "width."},
    {"blend",
     Choice,
     Any,
     1,
     false,
     {0, 0, 0},
     "profile",
     "Profile of the blend: \"smooth\" (polynomial smooth minimum/maximum), \"round\" (a "
     "circular fillet, of radius `smooth` where the surfaces meet at a right angle) or "
     "\"chamfer\" (a flat bevel cutting `smooth` off each surface).",
     3.4e38f,
     kBlends},
};

// How an offset or shell measures a child whose field is not a distance (bake.h).
constexpr std::string_view kAccuracies[] = {"fast", "exact"};
constexpr ParamInfo kAccuracy = {
    "accuracy",
    Choice,
    Any,
    1,
    false,
    {0, 0, 0},
    "mode",
    "Where the child's field is not a distance (under twist, bend, taper, bend_linear, an uneven "
    "scale or a smooth blend): \"fast\" divides it by its gradient, to first order (about 10% "
    "off over a twist, nothing to pay); \"exact\" bakes the child's distance when the scene "
    "loads, within 2% (seconds of loading and up to 32 MiB for a child the size of the distance "
    "many times over, and frames some 2 to 3 times slower on a CPU device; where it would not "
    "fit, or the child has more than 256 nodes, it stays fast).",
    3.4e38f,
    kAccuracies};
constexpr ParamInfo kShell[] = {
    {"thickness", Number, Positive, 0, true, {}, "length", "Thickness of the skin."},
    kAccuracy,
};
constexpr ParamInfo kOffset[] = {
    {"distance",
     Number,
     Any,
     0,
     true,
     {},
     "length",
     "How far the surface moves outwards; negative moves it inwards."},
    kAccuracy,
};
constexpr ParamInfo kRepeat[] = {
    {"count", Vec3, Count, 0, true, {}, "copies", "Copies along x, y and z (1: no repetition)."},
    {"spacing",
     Vec3,
     NonNegative,
     3,
     true,
     {},
     "length",
     "Distance between neighbouring copies' centres along x, y and z: greater than 0 on an "
     "axis of more than one copy, any on an axis of one."},
};
constexpr ParamInfo kPolarRepeat[] = {
    {"count", Number, Count, 0, true, {}, "copies", "Copies around the axis."},
    {"radius",
     Number,
     Any,
     1,
     false,
     {0, 0, 0},
     "length",
     "How far the child moves along +x before it is copied around the y axis."},
};
constexpr std::string_view kMirrorAxes[] = {"x", "y", "z", "xy", "xz", "yz", "xyz"};
constexpr uint32_t kMirrorMasks[] = {1, 2, 4, 3, 5, 6, 7};
constexpr ParamInfo kMirror[] = {
    {"axes",
     Choice,
     Any,
     0,
     false,
     {0, 0, 0},
     "axes",
     "The axes whose planes through the origin mirror the child: \"x\" keeps x >= 0 and "
     "mirrors it to x < 0, and so on.",
     3.4e38f,
     kMirrorAxes},
    {"smooth",
     Number,
     NonNegative,
     1,
     false,
     {0, 0, 0},
     "length",
     "Blend radius of the seam at each mirror plane; 0 gives the exact mirror image."},
};
constexpr ParamInfo kElongate[] = {
    {"length",
     Vec3,
     NonNegative,
     0,
     true,
     {},
     "length",
     "How far apart the halves move along x, y and z."},
};
constexpr ParamInfo kTwist[] = {
    {"angle",
     Number,
     Any,
     0,
     true,
     {},
     "degrees per unit length",
     "Turn about y per unit of height (positive: counter-clockwise seen from +y)."},
};
constexpr ParamInfo kBend[] = {
    {"angle",
     Number,
     Any,
     0,
     true,
     {},
     "degrees per unit length",
     "Turn in the xy plane per unit along x."},
};
constexpr ParamInfo kTaper[] = {
    {"height",
     Number,
     Positive,
     0,
     true,
     {},
     "length",
     "Height over which the scale changes, centred on y = 0."},
    {"top_scale",
     Number,
     Positive,
     1,
     true,
     {},
     "factor",
     "Scale of x and z at y = +height/2 (1 at y = -height/2)."},
};
constexpr std::string_view kEases[] = {"linear", "smoothstep", "smootherstep"};
constexpr ParamInfo kBendLinear[] = {
    {"p0",
     Vec3,
     Any,
     0,
     false,
     {0, 0, 0},
     "point",
     "Where the offset starts: points whose projection on the line through p0 and p1 falls "
     "before p0 are not moved."},
    {"p1",
     Vec3,
     Any,
     3,
     true,
     {},
     "point",
     "Where the offset is complete: points whose projection falls beyond p1 move by all of it. "
     "Not p0."},
    {"offset", Vec3, Any, 6, true, {}, "length", "How far the child moves at p1 and beyond."},
    {"ease",
     Choice,
     Any,
     9,
     false,
     {1, 0, 0},
     "profile",
     "How the offset grows from p0 to p1: \"linear\" (kinks at both ends), \"smoothstep\" "
     "(an S, 3 t^2 - 2 t^3: steepest, 1.5 times the linear slope, half way) or "
     "\"smootherstep\" (6 t^5 - 15 t^4 + 10 t^3: smoother ends, 1.875 times the slope).",
     3.4e38f,
     kEases},
};

constexpr std::string_view kEaseDoc =
    "How the weight grows from the first child to the second: \"linear\", \"smoothstep\" "
    "(3 t^2 - 2 t^3: steepest, 1.5 times the linear slope, half way) or \"smootherstep\" "
    "(6 t^5 - 15 t^4 + 10 t^3: smoother ends, 1.875 times the slope).";
constexpr ParamInfo kTransitionLinear[] = {
    {"p0",
     Vec3,
     Any,
     0,
     false,
     {0, 0, 0},
     "point",
     "Where the morph starts: points whose projection on the line through p0 and p1 falls "
     "before p0 are the first child's."},
    {"p1",
     Vec3,
     Any,
     3,
     true,
     {},
     "point",
     "Where the morph ends: points whose projection falls beyond p1 are the second child's. Not "
     "p0."},
    {"ease", Choice, Any, 6, false, {1, 0, 0}, "profile", kEaseDoc, 3.4e38f, kEases},
};
constexpr ParamInfo kTransitionRadial[] = {
    {"center", Vec3, Any, 0, false, {0, 0, 0}, "point", "The centre of the morph's spheres."},
    {"r0",
     Number,
     NonNegative,
     3,
     false,
     {0, 0, 0},
     "length",
     "Within this distance of the centre, the first child."},
    {"r1",
     Number,
     Positive,
     4,
     true,
     {},
     "length",
     "From this distance of the centre on, the second child. Not r0; below r0 it turns the "
     "morph inside out (the second child within r1, the first beyond r0)."},
    {"ease", Choice, Any, 5, false, {1, 0, 0}, "profile", kEaseDoc, 3.4e38f, kEases},
};

// Kernel parameters and local bounds (see KindInfo::kernel and ::bounds).
using glm::vec3;
Params halve3(const Params& v) {
    return {0.5f * v[0], 0.5f * v[1], 0.5f * v[2]};
}
bool symmetric(vec3 half, vec3& lo, vec3& hi) {
    return lo = -half, hi = half, true;
}
float radians(float degrees) {
    return float(double(degrees) * 3.14159265358979323846 / 180.0);
}

// The largest distance from the y axis (reach) or from the z axis (reachXY) over a box.
float reach(vec3 lo, vec3 hi) {
    const float x = std::max(-lo.x, hi.x), z = std::max(-lo.z, hi.z);
    return std::sqrt(x * x + z * z);
}
float reachXY(vec3 lo, vec3 hi) {
    const float x = std::max(-lo.x, hi.x), y = std::max(-lo.y, hi.y);
    return std::sqrt(x * x + y * y);
}

// The box of the rectangle [lo, hi] of a plane turned by every angle from a0 to a1 (radians,
// a0 <= a1, from the first axis towards the second: (u cos t - v sin t, u sin t + v cos t)):
// the box of its corners' arcs, each reaching its ends and the axis directions it passes. Exact,
// since the turned rectangle lies within the hull of its turned corners at every angle.
void sweptRectangle(glm::vec2 lo, glm::vec2 hi, double a0, double a1, glm::vec2& outLo,
                    glm::vec2& outHi) {
    constexpr double kTurn = 2.0 * 3.14159265358979323846;
    glm::dvec2 l(INFINITY), h(-INFINITY);
    for (int c = 0; c < 4; ++c) {
        const glm::dvec2 corner(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y);
        const double r = std::sqrt(corner.x * corner.x + corner.y * corner.y);
        const double phi = std::atan2(corner.y, corner.x);
        auto reach = [&](double t) {
            const glm::dvec2 q(r * std::cos(t), r * std::sin(t));
            l = glm::min(l, q), h = glm::max(h, q);
        };
        if (a1 - a0 >= kTurn) {
            l = glm::min(l, glm::dvec2(-r)), h = glm::max(h, glm::dvec2(r));
            continue;
        }
        reach(phi + a0);
        reach(phi + a1);
        for (int quarter = 0; quarter < 4; ++quarter) {
            const double t = quarter * 0.25 * kTurn;
            const double first = t + std::ceil((phi + a0 - t) / kTurn) * kTurn;
            if (first <= phi + a1) reach(first);
        }
    }
    outLo = glm::vec2(l), outHi = glm::vec2(h);
}

// The largest singular value of the identity plus a column of length a, a bound of the twist's
// and the bend's Jacobians where the turn per unit times the distance from the axis is a.
float stretch(float a) {
    return 0.5f * (a + std::sqrt(a * a + 4.0f)) * (1.0f + 1e-6f);
}

// Repeat: spacing s, count n, and per axis the copies either side of the nearest that can reach
// a point (M, packed a byte each); the evaluation takes the nearest copy, M more either side and
// one more towards the point, or all n when that is as many (shaders/sdf.glsl, domainCandidate).
// When some axis needs M > 0, copies further away are at least G away, and the value is at most
// G (so that it stays continuous and 1-Lipschitz); with M = 0 everywhere it is exact.
Params repeatKernel(const Params& v, vec3 lo, vec3 hi) {
    // An axis of one copy has no spacing to speak of (the scene may give 0); 1 keeps the
    // candidate's index finite.
    Params k{v[0] > 1.0f ? v[3] : 1.0f,
             v[1] > 1.0f ? v[4] : 1.0f,
             v[2] > 1.0f ? v[5] : 1.0f,
             3.4e38f,
             v[0],
             v[1],
             v[2],
             0.0f};
    uint32_t packed = 0;
    for (int a = 0; a < 3; ++a) {
        const float s = k[a], n = v[a], ext = std::max(-lo[a], hi[a]);
        const float m = std::clamp(std::ceil(ext / s - 0.5f), 0.0f, 255.0f);
        packed |= uint32_t(m) << (8 * a);
        if (n > 1.0f && 2.0f * m + 2.0f < n && m > 0.0f)
            k[3] = std::min(k[3], (m + 1.0f) * s - ext);
    }
    k[7] = float(packed);
    return k;
}

// Polar repeat: count N, radius, sector angle, and the copies either side of the nearest that
// can reach a point (M), from the child's angular half extent beta seen from the axis. Beyond
// them the copies are at least gamma = (M + 1) sector - beta away in angle, at least x0 (the
// child's nearest x, moved out by the radius) from the axis and within the child's heights:
// slot 3 holds cos(gamma) when M > 0, else 2 (exact), slots 5 to 7 x0 and the heights
// (shaders/sdf.glsl, domainFinish). A child that reaches the axis takes every copy.
Params polarKernel(const Params& v, vec3 lo, vec3 hi) {
    const float n = v[0], sector = float(2.0 * 3.14159265358979323846 / double(v[0]));
    const float x0 = lo.x + v[1], z = std::max(-lo.z, hi.z);
    const float beta = x0 > 0.0f ? std::atan2(z, x0) : 3.14159265f;
    float m = std::ceil(beta / sector - 0.5f);
    if (2.0f * m + 2.0f >= n) m = n; // every copy
    float c = 2.0f;
    // The angle a hair smaller, so that rounding keeps the region around the copies left out.
    if (m > 0.0f && m < n)
        c = std::cos(std::min((m + 1.0f) * sector - beta, 3.14159265f) * (1.0f - 1e-6f));
    return {n, v[1], sector, c, m, std::max(x0, 0.0f), lo.y, hi.y};
}

// Profiles reach this far along z, in both directions: as fields of space they are prisms, and
// a finite reach keeps their bounds free of inf * 0 when transformed.
constexpr float kProfileReach = 1e30f;
bool profile(float x, float y, vec3& lo, vec3& hi) {
    return symmetric({x, y, kProfileReach}, lo, hi);
}
// Polygon, text and image: the outline's or image's extents in slots 2-5 (Evaluator, from
// Node::words).
bool outlineBounds(const Params& k, vec3& lo, vec3& hi) {
    lo = vec3(k[2], k[3], -kProfileReach), hi = vec3(k[4], k[5], kProfileReach);
    return true;
}

constexpr KernelArg kA0[] = {{0, 1}};
constexpr KernelArg kA3[] = {{0, 3}};
constexpr KernelArg kA3A1[] = {{0, 3}, {3, 1}};
constexpr KernelArg kA0A1[] = {{0, 1}, {1, 1}};
constexpr KernelArg kHeightmapArgs[] = {{0, 1}, {1, 1}, {2, 1}, {3, 1}, {4, 1}, {6, 1}, {7, 1}};
constexpr KernelArg kMeshArgs[] = {{0, 1}, {1, 1}, {2, 1}, {3, 1}, {4, 1}, {5, 1}, {6, 1}, {7, 1}};
constexpr KernelArg kOutlineArgs[] = {{0, 1}, {1, 1}, {2, 2}, {4, 2}, {6, 1}, {7, 1}};
constexpr KernelArg kA0A1A2[] = {{0, 1}, {1, 1}, {2, 1}};
constexpr KernelArg kA0A1A2A3[] = {{0, 1}, {1, 1}, {2, 1}, {3, 1}};
constexpr KernelArg kCapsuleArgs[] = {{0, 3}, {4, 3}, {3, 1}};
constexpr KernelArg kRoundConeArgs[] = {{0, 1}, {1, 1}, {2, 1}, {3, 1}, {4, 1}};

constexpr KindInfo kKinds[] = {
    {NodeKind::Sphere, "sphere", false, kSphere, "Sphere centred at the origin.",
     R"("radius": 0.8)", "sdSphere", kA0, [](const Params& v) -> Params { return {v[0]}; },
     [](const Params& k, vec3& lo, vec3& hi) { return symmetric(vec3(k[0]), lo, hi); }},
    {NodeKind::Box, "box", false, kBox, "Axis-aligned box centred at the origin.",
     R"("size": [1.2, 0.7, 1.6])", "sdBox", kA3, halve3,
     [](const Params& k, vec3& lo, vec3& hi) {
         return symmetric({k[0], k[1], k[2]}, lo, hi);
     }},
    {NodeKind::RoundBox, "round_box", false, kRoundBox,
     "Box with rounded edges, centred at the origin.", R"("size": [1.2, 0.9, 1.4], "radius": 0.2)",
     "sdRoundBox", kA3A1,
     [](const Params& v) -> Params {
         vec3 b = 0.5f * vec3(v[0], v[1], v[2]);
         return {b.x, b.y, b.z, std::min(v[3], std::min(b.x, std::min(b.y, b.z)))};
     },
     [](const Params& k, vec3& lo, vec3& hi) {
         return symmetric({k[0], k[1], k[2]}, lo, hi);
     }},
    {NodeKind::Plane, "plane", false, kPlane, "Half-space bounded by a plane (infinite).",
     R"("normal": [0.2, 1, 0.3], "offset": 0.25)", "sdPlane", kA3A1,
     [](const Params& v) -> Params {
         vec3 n(v[0], v[1], v[2]);
         float len = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
         n = len > 0.0f ? n / len : vec3(0.0f, 1.0f, 0.0f);
         return {n.x, n.y, n.z, v[3]};
     },
     [](const Params&, vec3&, vec3&) { return false; }},
    {NodeKind::TriangularPrism, "triangular_prism", false, kTriangularPrism,
     "Isosceles triangle in the xy plane (apex up, +y) extruded along z, its bounding box centred "
     "at "
     "the origin. A gable roof is one of these.",
     R"("width": 1.4, "height": 1.1, "length": 1.8)", "sdTriangularPrism", kA0A1A2,
     [](const Params& v) -> Params {
         return {0.5f * v[0], v[1], 0.5f * v[2]};
     },
     [](const Params& k, vec3& lo, vec3& hi) {
         return symmetric({k[0], 0.5f * k[1], k[2]}, lo, hi);
     }},
    {NodeKind::Torus, "torus", false, kTorus, "Ring around the y axis, centred at the origin.",
     R"("major_radius": 0.9, "minor_radius": 0.25)", "sdTorus", kA0A1,
     [](const Params& v) -> Params {
         return {v[0], v[1]};
     },
     [](const Params& k, vec3& lo, vec3& hi) {
         return symmetric({k[0] + k[1], k[1], k[0] + k[1]}, lo, hi);
     }},
    {NodeKind::Cylinder, "cylinder", false, kCylinder,
     "Capped cylinder along y, centred at the origin.", R"("radius": 0.6, "height": 1.5)",
     "sdCylinder", kA0A1,
     [](const Params& v) -> Params {
         return {v[0], 0.5f * v[1]};
     },
     [](const Params& k, vec3& lo, vec3& hi) {
         return symmetric({k[0], k[1], k[0]}, lo, hi);
     }},
    {NodeKind::Cone, "cone", false, kCone,
     "Capped cone along y, base at the bottom, centred at the origin (half way up).",
     R"("radius": 0.7, "height": 1.3, "top_radius": 0.2)", "sdCone", kA0A1A2,
     [](const Params& v) -> Params {
         return {v[0], 0.5f * v[1], v[2]};
     },
     [](const Params& k, vec3& lo, vec3& hi) {
         float r = std::max(k[0], k[2]);
         return symmetric({r, k[1], r}, lo, hi);
     }},
    {NodeKind::Capsule, "capsule", false, kCapsule, "Segment from a to b swept by a sphere.",
     R"("a": [-0.5, -0.3, 0.1], "b": [0.6, 0.4, -0.2], "radius": 0.3)", "sdCapsule", kCapsuleArgs,
     [](const Params& v) -> Params { return {v[0], v[1], v[2], v[6], v[3], v[4], v[5]}; },
     [](const Params& k, vec3& lo, vec3& hi) {
         vec3 a(k[0], k[1], k[2]), b(k[4], k[5], k[6]);
         lo = vec3(std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)) - k[3];
         hi = vec3(std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)) + k[3];
         return true;
     }},
    {NodeKind::Ellipsoid, "ellipsoid", false, kEllipsoid,
     "Ellipsoid centred at the origin. Its field is a bound, not the exact distance: never above "
     "it, and at least the distance times the smallest over the largest radius.",
     R"("radii": [0.9, 0.5, 0.7])", "sdEllipsoid", kA3A1,
     [](const Params& v) -> Params {
         return {1.0f / v[0], 1.0f / v[1], 1.0f / v[2], std::min(v[0], std::min(v[1], v[2]))};
     },
     [](const Params& k, vec3& lo, vec3& hi) {
         return symmetric({1.0f / k[0], 1.0f / k[1], 1.0f / k[2]}, lo, hi);
     }},
    {NodeKind::HexPrism, "hex_prism", false, kHexPrism,
     "Regular hexagonal prism along y, centred at the origin (a nut, a bolt head, a pencil).",
     R"("radius": 0.7, "height": 1.2)", "sdHexPrism", kA0A1,
     [](const Params& v) -> Params {
         return {v[0] * 0.8660254f, 0.5f * v[1]};
     },
     [](const Params& k, vec3& lo, vec3& hi) {
         return symmetric({k[0] / 0.8660254f, k[1], k[0]}, lo, hi);
     }},
    {NodeKind::Octahedron, "octahedron", false, kOctahedron,
     "Regular octahedron with its vertices on the axes, centred at the origin.", R"("radius": 0.9)",
     "sdOctahedron", kA0, [](const Params& v) -> Params { return {v[0]}; },
     [](const Params& k, vec3& lo, vec3& hi) { return symmetric(vec3(k[0]), lo, hi); }},
    {NodeKind::Pyramid, "pyramid", false, kPyramid,
     "Square pyramid, base at the bottom, apex up (+y), its bounding box centred at the origin.",
     R"("width": 1.2, "height": 1.1)", "sdPyramid", kA0A1A2,
     [](const Params& v) -> Params {
         return {v[0], v[1] / v[0], 0.5f * v[1]};
     },
     [](const Params& k, vec3& lo, vec3& hi) {
         return symmetric({0.5f * k[0], k[2], 0.5f * k[0]}, lo, hi);
     }},
    {NodeKind::RoundedCylinder, "rounded_cylinder", false, kRoundedCylinder,
     "Cylinder along y with rounded rims, centred at the origin.",
     R"("radius": 0.6, "height": 1.4, "rounding": 0.15)", "sdRoundedCylinder", kA0A1A2,
     [](const Params& v) -> Params {
         float rr = std::min(v[2], std::min(v[0], 0.5f * v[1]));
         return {v[0] - rr, 0.5f * v[1] - rr, rr};
     },
     [](const Params& k, vec3& lo, vec3& hi) {
         float r = k[0] + k[2];
         return symmetric({r, k[1] + k[2], r}, lo, hi);
     }},
    {NodeKind::RoundCone, "round_cone", false, kRoundCone,
     "Two spheres on the y axis and the cone that joins them (their convex hull), the spheres' "
     "centres at -height/2 and +height/2.",
     R"("radius": 0.5, "top_radius": 0.2, "height": 1.1)", "sdRoundCone", kRoundConeArgs,
     [](const Params& v) -> Params {
         // Where one sphere holds the other the smaller one shrinks to just inside the larger,
         // which keeps the formula's slope defined and the solid the larger sphere.
         float r1 = v[0], r2 = v[1], h = v[2];
         const float gap = 0.999f * h;
         if (r1 - r2 > gap) r2 = r1 - gap;
         if (r2 - r1 > gap) r1 = r2 - gap;
         float b = (r1 - r2) / h;
         return {r1, r2, h, b, std::sqrt(std::max(1.0f - b * b, 0.0f))};
     },
     [](const Params& k, vec3& lo, vec3& hi) {
         float r = std::max(k[0], k[1]);
         lo = vec3(-r, -0.5f * k[2] - k[0], -r);
         hi = vec3(r, 0.5f * k[2] + k[1], r);
         return true;
     }},
    {NodeKind::Link, "link", false, kLink,
     "Chain link standing in the xy plane, long along y, centred at the origin.",
     R"("length": 0.6, "major_radius": 0.4, "minor_radius": 0.12)", "sdLink", kA0A1A2,
     [](const Params& v) -> Params {
         return {0.5f * v[0], v[1], v[2]};
     },
     [](const Params& k, vec3& lo, vec3& hi) {
         return symmetric({k[1] + k[2], k[0] + k[1] + k[2], k[2]}, lo, hi);
     }},
    {NodeKind::Heightmap, "heightmap", false, kHeightmap,
     "A PNG image's grey levels as heights over a rectangle in the xz plane, centred on the origin "
     "(only where the user names a file); the solid below them. Its field is a bound: the height "
     "difference over the Lipschitz bound of the heights' bilinear interpolation.",
     R"("file": "terrain.png", "size": [1.6, 0.4, 1.6])", "sdHeightmap", kHeightmapArgs, nullptr,
     [](const Params& k, vec3& lo, vec3& hi) {
         lo = vec3(-k[2], 0.0f, -k[3]), hi = vec3(k[2], k[4], k[3]);
         return true;
     }},
    {NodeKind::Mesh, "mesh", false, kMesh,
     "A triangle mesh read from a file, in the file's units (a 3MF's converted to centimetres, "
     "the scene unit sdfcsg writes 3MF in) or scaled to fit a box, STL and 3MF turned from z up "
     "to y up "
     "(only where the user names a file). "
     "Its field is the distance to the triangles, exact near the surface (sampled in bricks, "
     "interpolated) and a bound beyond; the inside is what the generalised winding number "
     "says, so meshes with holes or flipped triangles still have one. "
     "Its colour is the file's where it has colours: per vertex (PLY, OBJ, glTF, a binary STL's), "
     "per material (an OBJ's .mtl beside it, glTF's base colour) or per triangle or corner (3MF's "
     "base materials and colour groups), that of the surface nearest to the point within a cell; "
     "elsewhere, and for files without colours, the node's.",
     R"("file": "gear.stl", "resolution": 96)", "sdMesh", kMeshArgs, nullptr,
     [](const Params& k, vec3& lo, vec3& hi) {
         // The box of the mesh's inside (buildMesh()) at its place in the field's grid, and a
         // cell more: the interpolated field's surface may pass it by up to a cell.
         lo = vec3(k[2], k[3], k[4]) + (k[11] - k[5]);
         hi = lo + vec3(k[8], k[9], k[10]) + 2.0f * k[5];
         return true;
     },
     Role::Primitive, nullptr, nullptr, nullptr, "colorMesh",
     [](std::span<const glm::vec4> words) {
         return words.size() > 2 && words[2].x != 0.0f; // sdMesh's layout
     },
     true},
    {NodeKind::CappedTorus, "capped_torus", false, kCappedTorus,
     "Arc of a ring around the y axis (a horseshoe, a handle), centred on +z.",
     R"("major_radius": 0.8, "minor_radius": 0.2, "angle": 250)", "sdCappedTorus", kA0A1A2A3,
     [](const Params& v) -> Params {
         const double half = 0.5 * double(v[2]) * 3.14159265358979323846 / 180.0;
         return {v[0], v[1], float(std::sin(half)), float(std::cos(half))};
     },
     [](const Params& k, vec3& lo, vec3& hi) {
         float r = k[0] + k[1];
         return symmetric({r, k[1], r}, lo, hi);
     }},
    {NodeKind::Circle, "circle", false, kCircle,
     "2D profile: a circle in the xy plane, centred at the origin.", R"("radius": 0.5)", "sdCircle",
     kA0, [](const Params& v) -> Params { return {v[0]}; },
     [](const Params& k, vec3& lo, vec3& hi) { return profile(k[0], k[0], lo, hi); }},
    {NodeKind::Rectangle, "rectangle", false, kRectangle,
     "2D profile: a rectangle in the xy plane, optionally with rounded corners, centred at the "
     "origin.",
     R"("width": 0.9, "height": 0.6, "rounding": 0.1)", "sdRectangle", kA0A1A2,
     [](const Params& v) -> Params {
         return {0.5f * v[0], 0.5f * v[1], std::min(v[2], 0.5f * std::min(v[0], v[1]))};
     },
     [](const Params& k, vec3& lo, vec3& hi) { return profile(k[0], k[1], lo, hi); }},
    {NodeKind::RegularPolygon, "regular_polygon", false, kRegularPolygon,
     "2D profile: a regular polygon in the xy plane, centred at the origin, an edge on top.",
     R"("radius": 0.6, "sides": 5)", "sdRegularPolygon", kA0A1A2A3,
     [](const Params& v) -> Params {
         const double half = 3.14159265358979323846 / std::max(double(v[1]), 3.0);
         return {v[0], float(half), float(std::cos(half)), float(std::sin(half))};
     },
     [](const Params& k, vec3& lo, vec3& hi) { return profile(k[0], k[0], lo, hi); }},
    {NodeKind::Polygon, "polygon", false, kPolygon,
     "2D profile: a polygon in the xy plane from its corners, exact distance.",
     R"("points": [[-0.5, -0.4], [0.6, -0.4], [0.1, 0.0], [0.3, 0.5], [-0.4, 0.3]])", "sdOutline",
     kOutlineArgs, nullptr, outlineBounds},
    {NodeKind::Text, "text", false, kText,
     "2D profile: a line of text in the xy plane, set in a TrueType or OpenType font through "
     "FreeType and centred on the origin (the middle of its outlines' extents); exact distance "
     "to the glyphs' outlines.",
     R"("text": "Bo sdfg", "size": 0.5)", "sdOutline", kOutlineArgs, nullptr, outlineBounds},
    {NodeKind::Image, "image", false, kImage,
     "2D profile: a PNG image's mask in the xy plane, centred on the origin (only where the user "
     "names a file); the exact distance to the mask's pixel edges at the pixels' centres, "
     "interpolated between them.",
     R"("file": "emblem.png", "size": 1)", "sdImage", kOutlineArgs, nullptr, outlineBounds},
    {NodeKind::Union,
     "union",
     true,
     kOperation,
     "All children together.",
     R"("smooth": 0.2)",
     {},
     {},
     nullptr,
     nullptr,
     Role::Boolean},
    {NodeKind::Intersection,
     "intersection",
     true,
     kOperation,
     "What all children have in common.",
     R"("smooth": 0.1, "blend": "round")",
     {},
     {},
     nullptr,
     nullptr,
     Role::Boolean},
    {NodeKind::Difference,
     "difference",
     true,
     kOperation,
     "The first child minus all the others.",
     R"("smooth": 0.05, "blend": "chamfer")",
     {},
     {},
     nullptr,
     nullptr,
     Role::Boolean},
    {NodeKind::TransitionLinear,
     "transition_linear",
     true,
     kTransitionLinear,
     "A morph between its two children along the line from p0 to p1: the first child before "
     "p0, the second beyond p1, and between them the surface of (1 - w) a + w b, w the ease of "
     "the clamped position t of the point's projection from p0 to p1. Exactly two children. The "
     "field is that mix with b - a clamped to +-D and divided by 1 + D W (D twice the diagonal "
     "of the children's bounds, W the weight's steepest slope, ease' / |p1 - p0|), which keeps "
     "it a distance bound.",
     R"("p0": [-0.6, 0, 0], "p1": [0.6, 0, 0], "ease": "smoothstep")",
     {},
     {},
     nullptr,
     nullptr,
     Role::Boolean,
     [](const Params& v, vec3, vec3) -> Params {
         const vec3 p0(v[0], v[1], v[2]), axis = vec3(v[3], v[4], v[5]) - p0;
         const vec3 u = axis / glm::dot(axis, axis);
         return {u.x, u.y, u.z, glm::dot(p0, u), 0.0f, v[6]};
     },
     [](const Params&, vec3 lo, vec3 hi, vec3& outLo, vec3& outHi) { outLo = lo, outHi = hi; }},
    {NodeKind::TransitionRadial,
     "transition_radial",
     true,
     kTransitionRadial,
     "A morph between its two children by the distance from a centre: the first child within "
     "r0 of it, the second beyond r1, and between them the surface of (1 - w) a + w b, w the "
     "ease of the clamped fraction t of the way from r0 to r1. Exactly two children. The field "
     "is divided as transition_linear's, with W = ease' / |r1 - r0|.",
     R"("center": [0, 0, 0], "r0": 0.2, "r1": 0.7, "ease": "smootherstep")",
     {},
     {},
     nullptr,
     nullptr,
     Role::Boolean,
     [](const Params& v, vec3, vec3) -> Params {
         return {v[0], v[1], v[2], v[3], 1.0f / (v[4] - v[3]), v[5]};
     },
     [](const Params&, vec3 lo, vec3 hi, vec3& outLo, vec3& outHi) { outLo = lo, outHi = hi; }},
    {NodeKind::Shell,
     "shell",
     true,
     kShell,
     "Its child hollowed to a skin of the given thickness, centred on the child's surface (an "
     "onion). Cut it open with a difference to see inside.",
     R"("thickness": 0.1)",
     {},
     {},
     nullptr,
     nullptr,
     Role::Value,
     [](const Params& v, vec3, vec3) -> Params { return {0.5f * v[0]}; },
     [](const Params& k, vec3 lo, vec3 hi, vec3& outLo, vec3& outHi) {
         outLo = lo - k[0], outHi = hi + k[0];
     }},
    {NodeKind::Offset,
     "offset",
     true,
     kOffset,
     "Its child grown by a distance (rounding its edges), or shrunk by a negative one.",
     R"("distance": 0.15)",
     {},
     {},
     nullptr,
     nullptr,
     Role::Value,
     [](const Params& v, vec3, vec3) -> Params { return {v[0]}; },
     [](const Params& k, vec3 lo, vec3 hi, vec3& outLo, vec3& outHi) {
         outLo = lo - std::max(k[0], 0.0f), outHi = hi + std::max(k[0], 0.0f);
     }},
    {NodeKind::Repeat,
     "repeat",
     true,
     kRepeat,
     "A grid of copies of its child, centred on the origin: count copies along each axis, "
     "spacing apart. Costs about one copy to evaluate, however many there are.",
     R"("count": [3, 2, 4], "spacing": [1.1, 0.9, 0.8])",
     {},
     {},
     nullptr,
     nullptr,
     Role::Domain,
     repeatKernel,
     [](const Params& k, vec3 lo, vec3 hi, vec3& outLo, vec3& outHi) {
         const vec3 span = 0.5f * (vec3(k[4], k[5], k[6]) - 1.0f) * vec3(k[0], k[1], k[2]);
         outLo = lo - span, outHi = hi + span;
     }},
    {NodeKind::PolarRepeat,
     "polar_repeat",
     true,
     kPolarRepeat,
     "Copies of its child around the y axis, evenly spaced: the child moved radius along +x, "
     "then turned about y by each multiple of 360 / count degrees. Costs about one copy.",
     R"("count": 7, "radius": 1.2)",
     {},
     {},
     nullptr,
     nullptr,
     Role::Domain,
     polarKernel,
     [](const Params& k, vec3 lo, vec3 hi, vec3& outLo, vec3& outHi) {
         // The box of the copies' turned boxes; past 64 copies, close to the circle they reach.
         const vec3 from = lo + vec3(k[1], 0, 0), to = hi + vec3(k[1], 0, 0);
         const float r = reach(from, to);
         outLo = vec3(-r, lo.y, -r), outHi = vec3(r, hi.y, r);
         if (k[0] > 64.0f) return;
         glm::vec2 l(INFINITY), h(-INFINITY);
         for (int i = 0; i < int(k[0]); ++i) {
             glm::vec2 cl, ch;
             const double a = double(i) * double(k[2]);
             sweptRectangle({from.x, from.z}, {to.x, to.z}, a, a, cl, ch);
             l = glm::min(l, cl), h = glm::max(h, ch);
         }
         outLo = vec3(l.x, lo.y, l.y), outHi = vec3(h.x, hi.y, h.y);
     }},
    {NodeKind::Mirror,
     "mirror",
     true,
     kMirror,
     "Its child's part on the positive side of each chosen axis plane, and that part's mirror "
     "image (a symmetric shape from one half).",
     R"("axes": "xz", "smooth": 0.1)",
     {},
     {},
     nullptr,
     nullptr,
     Role::Domain,
     [](const Params& v, vec3, vec3) -> Params {
         const uint32_t mask = kMirrorMasks[size_t(v[0])];
         return {float(mask & 1), float(mask >> 1 & 1), float(mask >> 2 & 1), v[1]};
     },
     [](const Params& k, vec3 lo, vec3 hi, vec3& outLo, vec3& outHi) {
         // The child is taken at sqrt(p^2 + smooth^2) (|p| when sharp), which reaches its hi
         // at |p| = sqrt(hi^2 - smooth^2).
         for (int a = 0; a < 3; ++a) {
             const float h = std::max(hi[a], 0.0f);
             const float e = k[3] > 0.0f ? std::sqrt(std::max(h * h - k[3] * k[3], 0.0f)) : h;
             outLo[a] = k[a] != 0.0f ? -e : lo[a];
             outHi[a] = k[a] != 0.0f ? e : hi[a];
         }
     }},
    {NodeKind::Elongate,
     "elongate",
     true,
     kElongate,
     "Its child cut through its centre planes and stretched apart by the given lengths: a sphere "
     "becomes a capsule or a rounded box, a torus a stadium-shaped ring.",
     R"("length": [0.6, 0.2, 0.4])",
     {},
     {},
     nullptr,
     nullptr,
     Role::Domain,
     [](const Params& v, vec3, vec3) -> Params {
         return {0.5f * v[0], 0.5f * v[1], 0.5f * v[2]};
     },
     [](const Params& k, vec3 lo, vec3 hi, vec3& outLo, vec3& outHi) {
         outLo = lo - vec3(k[0], k[1], k[2]), outHi = hi + vec3(k[0], k[1], k[2]);
     }},
    {NodeKind::Twist,
     "twist",
     true,
     kTwist,
     "Its child twisted about the y axis, turning by the given angle per unit of height. The "
     "field is divided by the twist's Lipschitz bound, so it stays safe to trace.",
     R"("angle": 60)",
     {},
     {},
     nullptr,
     nullptr,
     Role::Domain,
     [](const Params& v, vec3, vec3) -> Params { return {radians(v[0])}; },
     [](const Params& k, vec3 lo, vec3 hi, vec3& outLo, vec3& outHi) {
         // The child's xz rectangle turned by the angle times every height it spans.
         const double a0 = double(k[0]) * lo.y, a1 = double(k[0]) * hi.y;
         glm::vec2 l, h;
         sweptRectangle({lo.x, lo.z}, {hi.x, hi.z}, std::min(a0, a1), std::max(a0, a1), l, h);
         outLo = vec3(l.x, lo.y, l.y), outHi = vec3(h.x, hi.y, h.y);
     },
     [](const Params& k, vec3 lo, vec3 hi) { return stretch(std::abs(k[0]) * reach(lo, hi)); }},
    {NodeKind::Bend,
     "bend",
     true,
     kBend,
     "Its child bent in the xy plane: each point is turned about the z axis by minus the angle "
     "times its x before the child is evaluated, so a bar along x curls towards +y (for a "
     "positive angle) into a U, its point at x = s landing s from the z axis, turned by the "
     "angle times its new x: bent by 90 degrees per unit, the bar's first unit ends at (0.59, "
     "0.80). Not an arc of one radius; near the axis, where the turn is small, close to "
     "y = angle x^2 (the angle in radians). The field is divided by the bend's Lipschitz "
     "bound.",
     R"("angle": 30)",
     {},
     {},
     nullptr,
     nullptr,
     Role::Domain,
     [](const Params& v, vec3, vec3) -> Params { return {radians(v[0])}; },
     [](const Params& k, vec3 lo, vec3 hi, vec3& outLo, vec3& outHi) {
         // A point at p is the child's turned by the angle times p.x, so within the circle of
         // the child's reach; and if p.x lies in [x0, x1], within the child's xy rectangle turned
         // by every angle between the angle times x0 and x1. Each round takes the last box's x
         // range, and the solid stays within every box.
         const float r = reachXY(lo, hi);
         glm::vec2 l(-r), h(r);
         for (int round = 0; round < 4; ++round) {
             const double a0 = double(k[0]) * l.x, a1 = double(k[0]) * h.x;
             glm::vec2 sl, sh;
             sweptRectangle({lo.x, lo.y}, {hi.x, hi.y}, std::min(a0, a1), std::max(a0, a1), sl, sh);
             l = glm::max(l, sl), h = glm::min(h, sh);
         }
         outLo = vec3(l, lo.z), outHi = vec3(h, hi.z);
     },
     [](const Params& k, vec3 lo, vec3 hi) { return stretch(std::abs(k[0]) * reachXY(lo, hi)); }},
    {NodeKind::Taper,
     "taper",
     true,
     kTaper,
     "Its child scaled in x and z by a factor that changes linearly with height: 1 at y = "
     "-height/2, top_scale at y = +height/2, constant beyond. The field is divided by the "
     "taper's Lipschitz bound.",
     R"("height": 1.2, "top_scale": 0.4)",
     {},
     {},
     nullptr,
     nullptr,
     Role::Domain,
     [](const Params& v, vec3, vec3) -> Params {
         return {0.5f * v[0], v[1]};
     },
     [](const Params& k, vec3 lo, vec3 hi, vec3& outLo, vec3& outHi) {
         // x and z times the scale, which is monotonic in y: its extremes over the child's
         // heights are at their ends.
         auto scale = [&](float y) {
             return 1.0f + (k[1] - 1.0f) * std::clamp((y + k[0]) / (2.0f * k[0]), 0.0f, 1.0f);
         };
         const float s0 = std::min(scale(lo.y), scale(hi.y));
         const float s1 = std::max(scale(lo.y), scale(hi.y));
         outLo = vec3(std::min(lo.x * s0, lo.x * s1), lo.y, std::min(lo.z * s0, lo.z * s1));
         outHi = vec3(std::max(hi.x * s0, hi.x * s1), hi.y, std::max(hi.z * s0, hi.z * s1));
     },
     [](const Params& k, vec3 lo, vec3 hi) {
         // q = (x / s, y, z / s): diag(1/s, 1, 1/s) plus the column of d/dy, of length
         // r |s'| / s^2; s is linear in y, so its least value over the box is at an end.
         const float hh = k[0], top = k[1];
         auto scale = [&](float y) {
             return 1.0f + (top - 1.0f) * std::clamp((y + hh) / (2.0f * hh), 0.0f, 1.0f);
         };
         const float least = std::min({scale(lo.y), scale(hi.y), 1.0f, top});
         const float slope = std::abs(top - 1.0f) / (2.0f * hh);
         return std::max(1.0f / least, 1.0f) + reach(lo, hi) * slope / (least * least);
     }},
    {NodeKind::BendLinear,
     "bend_linear",
     true,
     kBendLinear,
     "Its child moved by part of the offset that grows, along the line from p0 to p1, from none "
     "to all of it: an S-shaped jog in a bar, a kink in a pipe. A point whose projection on "
     "that line lies the fraction t of the way from p0 to p1 (clamped to 0..1) sees the child "
     "at itself less offset times ease(t). The field is divided by the map's Lipschitz bound, "
     "1 + |offset| ease' / |p1 - p0| (ease' the ease's steepest slope).",
     R"("p0": [-0.5, 0, 0], "p1": [0.5, 0, 0], "offset": [0, 0.4, 0], "ease": "smoothstep")",
     {},
     {},
     nullptr,
     nullptr,
     Role::Domain,
     [](const Params& v, vec3, vec3) -> Params {
         const vec3 p0(v[0], v[1], v[2]), axis = vec3(v[3], v[4], v[5]) - p0;
         const vec3 u = axis / glm::dot(axis, axis);
         return {u.x, u.y, u.z, glm::dot(p0, u), v[6], v[7], v[8], v[9]};
     },
     [](const Params& k, vec3 lo, vec3 hi, vec3& outLo, vec3& outHi) {
         // The child's points move by the offset times ease(t), which lies in 0..1.
         const vec3 offset(k[4], k[5], k[6]);
         outLo = glm::min(lo, lo + offset), outHi = glm::max(hi, hi + offset);
     }},
    {NodeKind::Extrude,
     "extrude",
     true,
     kExtrude,
     "The cross-section of its child in the plane z = 0 (a 2D profile: circle, rectangle, "
     "polygon, text...) swept along z to the given thickness. Exact where the child's field is.",
     R"("height": 0.4, "rounding": 0.05)",
     {},
     {},
     nullptr,
     nullptr,
     Role::Domain,
     [](const Params& v, vec3, vec3) -> Params {
         return {0.5f * v[0], std::min(v[1], 0.5f * v[0])};
     },
     [](const Params& k, vec3 lo, vec3 hi, vec3& outLo, vec3& outHi) {
         outLo = vec3(lo.x, lo.y, -k[0]), outHi = vec3(hi.x, hi.y, k[0]);
     }},
    {NodeKind::Revolve,
     "revolve",
     true,
     kRevolve,
     "The cross-section of its child in the plane z = 0, its part at x >= -offset, turned about "
     "the y axis (a lathe): a vase, a chess piece, a ring.",
     R"("offset": 0.3)",
     {},
     {},
     nullptr,
     nullptr,
     Role::Domain,
     [](const Params& v, vec3, vec3) -> Params { return {v[0]}; },
     [](const Params& k, vec3 lo, vec3 hi, vec3& outLo, vec3& outHi) {
         const float r = std::max(hi.x + k[0], 0.0f);
         outLo = vec3(-r, lo.y, -r), outHi = vec3(r, hi.y, r);
     }},
};
static_assert(sizeof(kKinds) / sizeof(kKinds[0]) == kNodeKindCount);

// kindInfo() indexes the table by kind, and the groups of sdfcsg/kinds.h are roles.
constexpr bool tableFollowsTheKinds() {
    for (int i = 0; i < kNodeKindCount; ++i) {
        const KindInfo& k = kKinds[i];
        const bool operation = k.kind >= kFirstOperation;
        const Role role = k.kind < kFirstOperation         ? Role::Primitive
                          : k.kind < kFirstValueOperation  ? Role::Boolean
                          : k.kind < kFirstDomainOperation ? Role::Value
                                                           : Role::Domain;
        if (k.kind != NodeKind(i) || k.operation != operation || k.role != role) return false;
    }
    return true;
}
static_assert(tableFollowsTheKinds(),
              "kKinds lists the kinds in NodeKind's order (sdfcsg/kinds.h), each with its group's "
              "role");

constexpr CommonKey kCommonKeys[] = {
    {"type", R"({"type":"string"})", "Node kind: a primitive or an operation name."},
    {"name", R"({"type":"string","maxLength":200})",
     "Optional label, shown in errors and in generated GLSL."},
    {"translate", R"({"type":"array","items":{"type":"number"},"minItems":3,"maxItems":3})",
     "Translation [x, y, z] in parent units, applied after rotation and scale."},
    {"rotate", R"({"type":"array","items":{"type":"number"},"minItems":3,"maxItems":3})",
     "Rotation in degrees about x, then y, then z."},
    {"scale",
     R"({"oneOf":[{"type":"number","exclusiveMinimum":0},{"type":"array","items":{"type":"number","exclusiveMinimum":0},"minItems":3,"maxItems":3}]})",
     "Scale factor (> 0), one for every axis or [x, y, z]. Where the factors differ the field "
     "is scaled by the smallest, a lower bound of the distance: sphere tracing stays safe, "
     "but takes more steps."},
    {"color",
     R"({"oneOf":[{"type":"array","items":{"type":"number","minimum":0,"maximum":1},"minItems":3,"maxItems":3},{"type":"string","pattern":"^#[0-9a-fA-F]{6}$"}]})",
     "Colour as [r, g, b] in 0..1 or \"#rrggbb\"; inherited by children that set none."},
    {"children", R"({"type":"array","minItems":1,"items":{"$ref":"#/$defs/node"}})",
     "Operations only: the operands, at least one."},
};

} // namespace

std::span<const KindInfo> nodeKinds() {
    return kKinds;
}

const KindInfo& kindInfo(NodeKind kind) {
    return kKinds[static_cast<int>(kind)];
}

const KindInfo* findKind(std::string_view name) {
    for (const KindInfo& k : kKinds)
        if (k.name == name) return &k;
    return nullptr;
}

std::span<const CommonKey> commonNodeKeys() {
    return kCommonKeys;
}

std::string exampleNodeJson(const KindInfo& kind) {
    std::string json = "{\"type\": \"" + std::string(kind.name) + "\"";
    if (!kind.example.empty()) json += ", " + std::string(kind.example);
    if (kind.operation) {
        const bool cuts = kind.kind == NodeKind::Extrude || kind.kind == NodeKind::Revolve;
        json += cuts                      ? R"(, "children": [{"type": "circle", "radius": 0.5}])"
                : isTransition(kind.kind) ? R"(, "children": [{"type": "sphere", "radius": 0.5}, )"
                                            R"({"type": "box", "size": [0.8, 0.8, 0.8]}])"
                                          : R"(, "children": [{"type": "sphere", "radius": 0.5}])";
    }
    return json + "}";
}

} // namespace sdfcsg
