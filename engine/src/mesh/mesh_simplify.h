// The simplifier's ways in for tests (engine/src/mesh/mesh_simplify.cpp).
#pragma once

#include "sdfcsg/mesh.h"

#include <glm/vec3.hpp>

namespace sdfcsg::detail {

// Where a triangle (a, b, c) is held to the field, as barycentric weights: its centre, the
// middles of its sides and the points halfway from the centre to each corner. Unlike its
// corners, these see a triangle that cuts across a sharp edge or corner of the solid. The
// simplifier's checks, `sdfcsg bench --mesh --error` and the tests sample the same points.
inline const glm::vec3 kTriangleSamples[7] = {glm::vec3(1.0f / 3),
                                              glm::vec3(0.5f, 0.5f, 0.0f),
                                              glm::vec3(0.0f, 0.5f, 0.5f),
                                              glm::vec3(0.5f, 0.0f, 0.5f),
                                              glm::vec3(2, 0.5f, 0.5f) / 3.0f,
                                              glm::vec3(0.5f, 2, 0.5f) / 3.0f,
                                              glm::vec3(0.5f, 0.5f, 2) / 3.0f};

// simplifyMesh, which simplifies the whole mesh first and in blocks only where that cannot be
// mended; with wholeFirst false, in blocks from the start.
Result<Mesh> simplifyMesh(const Mesh& mesh, const Evaluator& evaluator,
                          const SimplifyOptions& options, MeshStats* stats, bool wholeFirst);

} // namespace sdfcsg::detail
