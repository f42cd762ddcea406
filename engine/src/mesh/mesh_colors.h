// Crisp colour regions: the mesh split along the borders where the scene's colour jumps, and a
// colour per triangle (engine/src/mesh/mesh.cpp calls it after extraction, the simplifier keeps
// it).
#pragma once

#include "sdfcsg/eval.h"
#include "sdfcsg/mesh.h"

#include <cstddef>

namespace sdfcsg::detail {

// Two colours are one where no channel differs by more than this (half of 1/255, so that
// colours that differ in a file's 8-bit channels always count as two).
inline constexpr float kColourTolerance = 1.0f / 512.0f;

// Whether the scene's primitives have more than one colour between them (nothing else can make
// a colour border). Cheap: one look at each node.
bool hasSeveralColours(const Evaluator& evaluator);

// Splits `mesh` (closed or open, welded, from a grid of cells of edge `h`) along the borders where
// the field's colour jumps, and sets Mesh::triangleColors (sdfcsg/mesh.h says what they hold).
// Only edges whose ends the GPU or the evaluator colour differently are searched: between the
// ends' points on the surface, the middle is moved onto the surface by Newton steps along the
// field's gradient and taken as the new end on the side whose colour it has, until the ends lie
// 1e-3 cells apart. Where their colours still differ, the colour jumps there: a new vertex,
// shared by both triangles of the edge, so the mesh stays welded and manifold. A smooth blend's
// colours meet instead, and its edges stay whole. A point within 0.02 cells of an end is that
// end; a split that would turn a triangle over or leave one without area is dropped. Each
// triangle is cut along the points on its sides (with a point on the surface at its centre where
// all three have one); its colour is the field's at its centre moved onto the surface, or, where
// all its corners came out of the extraction in one colour, that colour. Runs on two threads;
// the result does not depend on them. Returns how many edges were split.
size_t splitColourBorders(Mesh& mesh, const Evaluator& evaluator, float h);

// The field's colour at a point of a triangle, moved onto the surface by a few Newton steps
// (the colour splitColourBorders and the simplifier give a triangle that needs the field).
glm::vec3 surfaceColour(const Evaluator& evaluator, glm::vec3 p, float h);

} // namespace sdfcsg::detail
