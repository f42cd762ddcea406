// Offsets and shells over fields that are not distances, made distances: at load, the child's
// distance is baked into a field of bricks (MeshField::fromField, sdMesh's layout) that the
// offset or shell carries as its words (Node::words) and reads in place of its child, whose
// subtree is then not evaluated (the Evaluator turns the child's FlatNode into a mesh node in
// its frame; codegen walks bakedView). Derived data: never written to JSON, made again by every
// load and edit (model.cpp's setValue, the viewer's revalidation through the loader).
//
// The rule: the cell is a sixteenth of the distance the node moves its surface by (the offset's
// |distance|, half the shell's thickness, in its frame's units), grown by a quarter at a time
// until the field fits kMaxBakeBytes (and what the scene's words have left, kMaxOutlineWords),
// first with the colours where the child has several, then without; the band reaches that
// distance and two cells more. A node whose field would not fit at a quarter of the distance
// keeps the first-order division by the gradient (sdf.glsl, valueNormalised), as does one whose
// child reaches infinity (a plane), has more than kMaxBakedNodes nodes, or is a distance
// already. What remains: the distance to points of the surface a cell apart exceeds the
// surface's by at most (cell / sqrt 2)^2 / 2d, under 0.2% at 16 cells and 0.8% at 4, and
// trilinear interpolation rounds the creases of the offset's own surface (where the nearest
// point jumps: a shell's inner skin at its child's convex edges, the inside corners of an
// inward offset) by up to about half a cell (tests/unit/test_offsets.cpp).
#pragma once

#include "sdfcsg/nodes.h"
#include "sdfcsg/scene.h"

#include <cstddef>

namespace sdfcsg::detail {

// The most one node's baked field may take, of the scene's kMaxOutlineWords (64 MiB); and the
// most nodes its child's subtree may have, whose evaluation at each of up to millions of points
// the load waits for (a child of 256 spheres smoothly united takes some seconds).
inline constexpr size_t kMaxBakeBytes = size_t(32) << 20;
inline constexpr size_t kMaxBakedNodes = 256;

// An offset's or shell's "accuracy" (nodes.cpp): its slot and the value of "exact", which asks
// for the bake; "fast" (0, the default) keeps the first-order division.
inline constexpr int kAccuracySlot = 1;
inline constexpr float kAccuracyExact = 1.0f;

// Whether node n is an offset or shell that reads its child's baked distance from its words.
inline bool baked(const Node& n) {
    return kindInfo(n.kind).role == Role::Value && n.words != nullptr;
}

// Bakes, anew, the child of every offset and shell that asks for it ("accuracy": "exact") and
// whose child's field is not a distance (its FlatNode::loss above 1), innermost first, within the
// scene's words; the others' words are cleared. Never fails: a node that cannot be baked keeps the
// first-order correction.
void bakeOffsets(Scene& scene);

// The scene as the code generator walks it: the child of each baked node a mesh node with the
// baked words and no children (the Evaluator's FlatNodes hold its frame and parameters). The
// scene itself where nothing is baked.
const Scene& bakedView(const Scene& scene, Scene& storage);

} // namespace sdfcsg::detail
