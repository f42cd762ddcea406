// Dual contouring's last step, on the host (engine/src/mesh/mesh.cpp, and the CPU reference in the
// tests).
#pragma once

#include "sdfcsg/mesh.h"

#include <functional>

namespace sdfcsg::detail {

// `mesh` holds quads as pairs of triangles (a, b, c), (a, c, d), the second rotated to start at
// its k'th corner for a quad around a grid edge along axis k (the quads pass in
// shaders/mesh_triangles.comp). Each quad is split into (a, b, c), (a, c, d) or (a, b, d),
// (b, c, d): seen along its edge, the quad winds once around it, and the split is one whose two
// triangles wind the same way, so that the surface crosses the edge once; where both do, the one
// whose triangles face most like the vertices off the diagonal: at a sharp edge of the solid,
// the diagonal that runs along the edge, so that the fold lies on it. A triangle folds where it
// faces nearly a right angle or more away from its vertices' normals, or, where `distance` is
// set and it faces more than 30 degrees away from one of them, where it does not face the
// field's gradient at its centre (differences a hundredth of the cell edge `h` wide) by a margin;
// there the other split is taken if it winds too and its triangles face the field better. Where
// a triangle still folds, as where a sharp edge of the solid passes along a cell's face or edge
// and the vertices of the cells on both sides land on it and cross over, or where the vertices
// miss a sheet thinner than a cell, the quad's vertices move to `smooth` (per vertex: the mean of
// its edge points, where surface nets put it, which seldom folds), and the quads around them are
// split again. Last, each moved vertex goes back where the QEF placed it wherever that turns no
// quad around it over (most moved only for being a folding quad's corner), so that sharp
// features stay sharp. `distance`, the scene's field, is called from two threads.
using Distance = std::function<float(glm::vec3)>;
void foldQuads(Mesh& mesh, const std::vector<glm::vec3>& smooth, const Distance& distance, float h);

// Where a cell's one vertex for a piece of surface serves two sheets that touch across an
// ambiguous face (each of the face's four crossed edges in one piece on both sides), the edge
// between the two cells' vertices joins four triangles. Each such edge is cut into one per sheet:
// around it, a triangle running against the edge's direction and the next running along it (the
// solid lies between them) form a sheet; then each vertex at the end of a cut edge is copied for
// every further fan of triangles around it, so that every edge joins two triangles in opposite
// directions. The copies keep the vertex's position: the sheets still touch there. Returns how
// many edges were cut.
size_t splitTouchingSheets(Mesh& mesh);

// A point where a grid edge crosses the surface, as the vertices pass writes it
// (shaders/mesh_field.comp): its position and colour, its normal, and a second normal where it
// lies on a sharp edge.
struct EdgePoint {
    glm::vec3 position;
    float red;
    glm::vec3 normal;
    float green;
    glm::vec3 other;
    float blue;
};
static_assert(sizeof(EdgePoint) == 48);

// Vertices that may lie farther than half a cell `h` from the surface move toward it along the
// field's gradient (two Newton steps), inside their cells: those with no edge point within half a
// cell (nearer, the field is within half a cell there) and with the field `distance` 0.45 of a
// cell or more, that were clamped to their cell's side (as where the QEF's point lay outside the
// cell: a corner of a feature thinner than a cell), or, unless `clampedOnly`, that lie a fifth of
// a cell or more off one of their edge points' tangent planes (as the mean of the edge points of
// a piece curved within its cell). `positions` are the QEF's points (clampedOnly: those inside
// their cells lie on their planes) or the means that foldQuads() moves folding vertices to;
// `indices` holds the quads as the quads pass wrote them, `quadEdges` their edge points in
// `points`, and `origin` is the grid's corner. Does nothing without a field. Returns how many
// vertices moved.
size_t pullToSurface(std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices,
                     const std::vector<uint32_t>& quadEdges, const EdgePoint* points,
                     glm::vec3 origin, float h, const Distance& distance, bool clampedOnly);

// What separateCrossings() did: its rounds, the cells it split, and the pairs of triangles that
// still cross (in cells it could not make embedded, as one vertex serving two sheets).
struct Separation {
    size_t rounds = 0, cells = 0, remaining = 0;
};

// Splits the quads around crossing triangles into pieces that each lie in one cell (Ju and
// Udeshi, "Intersection-free contouring on an octree grid", 2006), where the check finds
// crossings. `mesh` holds the quads as foldQuads() and splitTouchingSheets() left them, two
// triangles each, and from `copiesFrom` on the copies that splitTouchingSheets() made;
// `quadEdges` numbers each quad's edge point in `points` (kept off the ends of its grid edge);
// `origin` and `h` are the grid's corner and cell edge.
// A marked cell's quads become fans from their edge point E around the polygon of their four
// vertices with, between two vertices of which one lies in a marked cell, the point F on the
// face between the two cells, halfway between the edge points of the two quads that share that
// side: each triangle (E, F, v) then lies in v's cell, and the triangles of one vertex form a fan
// from a point inside its (convex) cell to a loop of chords on the cell's faces, which is
// embedded. A marked cell's vertices, where it has several, move to the means of their loops'
// edge points, so that loops whose hulls are apart give fans that are apart. Triangles (E, v, w)
// of two unmarked vertices stay in the box of their two cells, and quads with no marked cell keep
// their two triangles, sharp features included. Rounds repeat, marking the cells of the vertices
// of triangles that still cross, until none do or a few rounds have passed. Only the quads around
// cells of several vertices and around vertices whose quads may cross (starWedges() in
// mesh_dual.cpp) are checked, so that meshes with nothing to fix pay little. Where a fan triangle
// folds (by its vertices' normals, and where `distance` is set by the field, as in foldQuads()),
// a marked cell's lone vertex in it moves once to the point of its cell, of a few, that its fan
// faces best from, and the next round checks it.
Separation separateCrossings(Mesh& mesh, size_t copiesFrom, const std::vector<uint32_t>& quadEdges,
                             const EdgePoint* points, glm::vec3 origin, float h,
                             const Distance& distance);

// Where a triangle still faces against the field after the steps above (by the field's gradient
// at its centre, as the tests judge it), as where a cell's one vertex serves two pieces of
// surface that the grid joins across an ambiguous face, or a fan's points lie about a feature
// thinner than a cell, each of its vertices moves, one at a time, to a point of its cell (where
// it is or the mean of its neighbours, or one of a lattice, each moved onto the surface along
// the field's gradient or as it is) from which none of its triangles faces against the field,
// or failing that fewest, no farther from the surface than 0.45 of a cell or than it was; a
// fan's edge and face points stay on the cell's edge or face they lie on. A move is kept only
// where its triangles then meet no more others (findSelfIntersections) than before. The field is
// asked only of triangles that face more than 10 degrees away from one of their vertices'
// normals, and a capped number of times per vertex and per mesh. Does nothing without a field
// `distance`; `origin` and `h` are the grid's corner and cell edge. Then each vertex still
// farther than 0.45 of a cell from the surface (one value of the field per vertex finds them)
// moves toward it, within its cell or the face it lies on: along the field's gradient (two
// Newton steps), all the way or a share of it, or else a quarter or half of the way toward one
// of its neighbours where that lies within 0.45 of a cell; the first point from which none of
// its triangles faces against the field that did not and they meet no more others. Returns how
// many vertices moved.
size_t unfoldVertices(Mesh& mesh, glm::vec3 origin, float h, const Distance& distance);

} // namespace sdfcsg::detail
