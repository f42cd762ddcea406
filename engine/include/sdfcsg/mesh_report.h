// A report on a triangle mesh from its triangles alone, not from the mesher's bookkeeping: what a
// slicer or a mesh Boolean library checks before it accepts a file (sdfcsg mesh --report).
#pragma once

#include "sdfcsg/eval.h"
#include "sdfcsg/mesh.h"

#include <cstddef>
#include <cstdint>
#include <string>

namespace sdfcsg {

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

// The report as lines of text ("closed: yes"), and as one JSON object.
std::string reportText(const MeshReport& report);
std::string reportJson(const MeshReport& report);

} // namespace sdfcsg
