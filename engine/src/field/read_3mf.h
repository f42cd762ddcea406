// The triangles and colours of a 3MF file, read for a mesh node (readTriangleMesh): 3MF
// Consortium, "3MF Core Specification" 1.3 (objects, meshes, components, the build) and the
// colours of its "Materials and Properties Extension" 1.2 (base materials' display colours,
// colour groups), from the ZIP container of the Open Packaging Conventions (ECMA-376 part 2).
#pragma once

#include "sdfcsg/error.h"

#include <glm/vec3.hpp>

#include <cstdint>
#include <functional>
#include <string_view>

namespace sdfcsg::detail {

// Where the triangles go: `begin` once, with how many triangles follow, then `corner` three
// times per triangle (counter-clockwise seen from outside), each with its colour as 0xRRGGBB
// (sRGB, as 3MF's colours are) or kNoColor.
struct ThreeMfCorners {
    std::function<void(size_t triangles)> begin;
    std::function<void(glm::vec3 position, uint32_t color)> corner;
};

// Reads `file`, a 3MF package: its root model part (the one _rels/.rels names, else
// 3D/3dmodel.model) and the model parts its components and build items name by p:path (3MF
// Production Extension 1.2), each unpacked and parsed as it is inflated, never held whole. Each
// build item's object is given z up, its components' and the item's transforms applied, in units
// of `unitMillimetres` mm: the root model's unit (millimetres where it names none) converted, and
// a part of another unit converted to the root's. Objects of a type other than "model" (supports)
// give no triangles. A triangle's colour is its corner's (p1, p2, p3) or the whole triangle's (p1
// alone), from the object's pid and pindex where it names none; one whose property group is not
// of colours (textures, composites) has none. Elements of namespaces other than the core's and
// the materials' are skipped, as the specification asks, unless requiredextensions names theirs.
// Refused, with the reason for the caller to place: model parts over `maxModelBytes` unpacked
// together (counted as they are inflated, whatever the ZIP directory declares), more than
// `maxTriangles` triangles, a ZIP or XML that cannot be read (named with the part and line), a
// missing or out-of-range index, a NaN or infinite vertex, an object or property group named
// before it is defined (as the specification requires they are not), a p:path that names no
// model part of the package or is used outside the root model, an extension required but not
// read (beam lattices, slices, secure content).
Status readThreeMf(std::string_view file, const ThreeMfCorners& out, size_t maxTriangles,
                   uint64_t maxModelBytes, double unitMillimetres);

} // namespace sdfcsg::detail
