// Dual contouring's last step, on the host (engine/src/mesh/mesh.cpp, and the CPU reference in the
// tests).
#pragma once

#include "sdfcsg/mesh.h"

namespace sdfcsg::detail {

// `mesh` holds quads as pairs of triangles (a, b, c), (a, c, d), the second rotated to start at
// its k'th corner for a quad around a grid edge along axis k (the quads pass in
// shaders/mesh_triangles.comp). Each quad is split into (a, b, c), (a, c, d) or (a, b, d),
// (b, c, d): seen along its edge, the quad winds once around it, and the split is one whose two
// triangles wind the same way, so that the surface crosses the edge once; where both do, the one
// whose triangles face most like the vertices off the diagonal: at a sharp edge of the solid,
// the diagonal that runs along the edge, so that the fold lies on it.
void foldQuads(Mesh& mesh);

} // namespace sdfcsg::detail
