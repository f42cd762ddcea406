// Marching-cubes tables (Lorensen and Cline, "Marching cubes: a high resolution 3D surface
// construction algorithm", SIGGRAPH 1987), shared by the mesh kernels, which receive them as a
// buffer, and by the CPU reference in the tests.
//
// Corners and edges are numbered as in Paul Bourke, "Polygonising a scalar field" (1994,
// https://paulbourke.net/geometry/polygonise/); his triangle table is not used. Ours is derived
// case by case from one rule that makes every mesh closed and manifold:
// - Each cube face that the surface crosses holds one or two segments between its crossed edges.
//   On an ambiguous face (two inside corners on a diagonal) the inside corners are always cut
//   off separately, as in Montani, Scateni and Scopigno, "A modified look-up table for implicit
//   disambiguation of Marching Cubes", The Visual Computer 10(6), 1994. The choice depends on the
//   face's four samples alone, so the two cells sharing a face make the same segments.
// - A case's segments close into loops, and each loop is cut into triangles by diagonals that
//   never join two vertices lying on one cube face, so no other cell holds such a diagonal: every
//   mesh edge belongs to exactly two triangles.
// tests/unit/test_mesh_reference.cpp checks these properties for all 256 cases.
//
// Inside means d < 0. Bit c of a cell's case is set when corner c is inside; the triangles of
// case c are kTriTable[c][0 .. 3 * kTriCount[c]), counter-clockwise seen from outside (from
// where d > 0), followed by -1.
#pragma once

#include <cstdint>

namespace sdfcsg::detail {

// Corner c of the cell whose lowest corner is sample s sits at sample s + kCornerOffset[c].
inline constexpr int kCornerOffset[8][3] = {
    {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1},
};

// The two corners of each edge, the lower one first: edge e runs from corner kEdgeCorners[e][0]
// along axis kEdgeAxis[e], so (offset of that corner, axis) names the grid edge, and with it the
// vertex, that neighbouring cells share.
inline constexpr int kEdgeCorners[12][2] = {
    {0, 1}, {1, 2}, {3, 2}, {0, 3}, {4, 5}, {5, 6}, {7, 6}, {4, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7},
};
inline constexpr int kEdgeAxis[12] = {0, 1, 0, 1, 0, 1, 0, 1, 2, 2, 2, 2};

// At most five triangles per case: 15 edge indices and the terminating -1.
extern const int8_t kTriTable[256][16];
extern const uint8_t kTriCount[256];

// The separate pieces of surface in a cell of one case, for dual contouring (one vertex per
// piece): triangles that share an edge belong to one piece. Pieces are numbered in the order of
// their lowest edge; patch[e] is the piece of crossed edge e, or -1 when e is not crossed.
struct CellPatches {
    int count = 0; // 0..4
    int8_t patch[12] = {-1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1};
};
CellPatches cellPatches(unsigned cellCase);

} // namespace sdfcsg::detail
