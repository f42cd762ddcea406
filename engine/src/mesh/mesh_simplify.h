// The simplifier's ways in for tests (engine/src/mesh/mesh_simplify.cpp).
#pragma once

#include "sdfcsg/mesh.h"

#include <glm/vec3.hpp>

namespace sdfcsg::detail {

// The points where triangles are held to the field (public: sdfcsg/mesh.h).
using sdfcsg::kTriangleSamples;

// simplifyMesh, which simplifies the whole mesh first and in blocks only where that cannot be
// mended; with wholeFirst false, in blocks from the start.
Result<Mesh> simplifyMesh(const Mesh& mesh, const Evaluator& evaluator,
                          const SimplifyOptions& options, MeshStats* stats, bool wholeFirst);

} // namespace sdfcsg::detail
