// Pairs of triangles of a mesh that meet where a surface embedded without self-intersections
// would not let them: the check of the mesh report (sdfcsg/mesh_report.h) and of the tests.
#pragma once

#include <sdfcsg/mesh.h>

#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace sdfcsg::detail {

struct SelfIntersections {
    size_t crossing = 0;    // pairs with no vertex in common that meet
    size_t overlapping = 0; // pairs with one vertex in common that also meet away from it
    size_t folded = 0;      // pairs with a side in common that lie folded onto each other
    size_t duplicates = 0;  // pairs with all three vertices in common
    std::string first;      // the first pair found

    size_t total() const { return crossing + overlapping + folded + duplicates; }
    std::string str() const {
        std::ostringstream s;
        s << crossing << " pairs of triangles crossing, " << overlapping
          << " overlapping beyond a common vertex, " << folded << " folded onto a common side, "
          << duplicates << " duplicated";
        if (!first.empty()) s << "; first: " << first;
        return s.str();
    }
};

// Pairs of triangles that meet where a surface embedded without self-intersections would not let
// them: by vertex numbers, triangles with no vertex in common must not come within `tolerance` of
// each other (distinct vertices at one position count: the surface is pinched there). Two with
// one vertex v in common meet at v; they meet elsewhere as well exactly when the side opposite v
// in one comes within the tolerance of the other (their intersection is convex and holds v, so
// it is v alone or reaches from v to a point on such a side). Two with a side in common meet
// beyond it only when they lie in one plane on the same side of it, folded onto each other: when
// the angle between them at the side is under `foldAngle` radians. Triangles without a plane
// (see Triangle in self_intersections.cpp) are judged by their sides alone, and pairs with a side
// in common of which one has no plane not at all: the tests' checkTriangleFacing() counts them
// as degenerate. `tolerance` defaults to 1e-6 of the diagonal of the mesh's bounds, above the
// rounding of float positions and far below any feature a mesher should make. `pairs`, if
// given, receives every pair found (triangle numbers), in the same order however many threads
// search (two, on meshes of some 10,000 triangles or more). Most pairs near each other are told
// apart by a plane between them, by quick proofs that skip only pairs the exact tests would pass;
// `quick` false leaves every pair to the exact tests (for the tests to compare).
SelfIntersections findSelfIntersections(const Mesh& mesh, double tolerance = -1.0,
                                        double foldAngle = 1e-3,
                                        std::vector<std::pair<uint32_t, uint32_t>>* pairs = nullptr,
                                        bool quick = true);

} // namespace sdfcsg::detail
