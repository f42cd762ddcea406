// A report on a triangle mesh from its triangles alone, not from the mesher's bookkeeping: what a
// slicer or a mesh Boolean library checks before it accepts a file (sdfcsg mesh --report).
#pragma once

#include "sdfcsg/eval.h"
#include "sdfcsg/export.h"
#include "sdfcsg/mesh.h"

#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace sdfcsg {

// How a mesh of a scene would print, from the scene's field: walls measured by marching into the
// solid from points of the surface along the triangles' normals until the field changes sign,
// and overhangs, with the scene's +y the build direction (as the 3MF and STL exports put it).
// Along the normal, the end face of a wall measures the wall's length, not its thickness: thin
// walls are found by their sides.
struct Printability {
    float minWall = 0.0f; // the least wall asked for, scene units
    // The thinnest wall measured and where; infinite where no sample found one.
    float thinnestWall = std::numeric_limits<float>::infinity();
    glm::vec3 thinnestAt{0.0f};
    size_t samples = 0;  // points of the surface where walls were measured
    double thinArea = 0; // surface area whose wall is thinner than minWall (from the samples)
    // Area of triangles facing down more than 45 degrees past the vertical (their normal within
    // 45 degrees of -y), but those that lie on the build plate under the mesh.
    double overhangArea = 0;
};

struct MeshReport {
    size_t vertices = 0, triangles = 0;
    // Triangles with an index out of range, a repeated index, or no area.
    size_t degenerateTriangles = 0;
    size_t edges = 0;            // distinct undirected edges
    size_t boundaryEdges = 0;    // used by one triangle: the mesh is open there
    size_t nonManifoldEdges = 0; // used by more than two triangles
    size_t misorientedEdges = 0; // used by two triangles in the same direction
    size_t shells = 0;           // pieces joined by shared vertices
    int64_t euler = 0;           // used vertices - edges + triangles
    // Pairs of triangles that meet where a surface without self-intersections would not let them
    // (crossing, overlapping beyond a common vertex, folded onto a common side, or duplicated).
    size_t selfIntersections = 0;
    double volume = 0; // signed: positive when the triangles face outwards
    double area = 0;
    Aabb bounds; // of the vertices that triangles use
    std::optional<Printability> printability;

    bool closed() const { return boundaryEdges == 0; }
    bool manifold() const { return nonManifoldEdges == 0 && degenerateTriangles == 0; }
    bool oriented() const { return misorientedEdges == 0 && volume > 0.0; }
    // Closed, manifold, oriented outwards and without self-intersections: what slicers and
    // Manifold accept as a solid.
    bool watertight() const {
        return closed() && manifold() && oriented() && selfIntersections == 0 && triangles > 0;
    }
    // Handles of all shells together (the sum of their genera), where the mesh is watertight;
    // -1 elsewhere, where the Euler characteristic does not give it.
    int64_t genus() const { return watertight() ? int64_t(shells) - euler / 2 : -1; }
};

MeshReport reportMesh(const Mesh& mesh);
// 0.8 mm, the least wall that a common 0.4 mm nozzle prints, in scene units where one unit is
// `unit`: the default minWall.
float defaultMinWall(LengthUnit unit = kDefaultLengthUnit);
// The same with the printability of the mesh of the scene that `evaluator` evaluates: walls
// thinner than `minWall` (scene units), measured at up to `samples` triangles spread over the
// mesh (bounded work on any mesh).
MeshReport reportMesh(const Mesh& mesh, const Evaluator& evaluator, float minWall,
                      size_t samples = 20000);

// The wall under each vertex of `mesh` (a mesh of the scene `evaluator` evaluates), measured as
// Printability measures it but along the vertex's normal; infinite where the march does not
// get inside. For colouring thin regions.
std::vector<float> wallThickness(const Mesh& mesh, const Evaluator& evaluator);

// The report as lines of text ("closed: yes"), and as one JSON object.
std::string reportText(const MeshReport& report);
std::string reportJson(const MeshReport& report);

} // namespace sdfcsg
