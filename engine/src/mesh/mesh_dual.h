// Dual contouring's last step, on the host (engine/src/mesh/mesh.cpp, and the CPU reference in the
// tests).
#pragma once

#include "sdfcsg/mesh.h"

namespace sdfcsg::detail {

// `mesh` holds quads as pairs of triangles (a, b, c), (a, c, d). Each quad is split along the
// diagonal whose two triangles face most like the vertices off it: at a sharp edge of the
// solid, the diagonal that runs along the edge, so that the fold lies on it.
void foldQuads(Mesh& mesh);

} // namespace sdfcsg::detail
