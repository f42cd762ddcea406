// Per-region pruning of the CSG tree (after Lipschitz Pruning, Barbier et al., Eurographics
// 2025; the per-tile "tapes" of Keeter's MPR, SIGGRAPH 2020).
//
// The tree becomes a tape: its nodes in post order, one instruction per primitive and one per
// fold of an operation (operands fold left to right, as eval.cpp and the generated code do), run
// by a small stack machine (shaders/tape_run.glsl, which prune.cpp compiles as C++ for
// PrunedField::distance and sample, and shaders/tape.glsl runs on the GPU). A cube
// around the solid is refined as an octree; each cell runs its parent's tape once at its centre
// c, and since every node's value is 1-Lipschitz, a node whose value is v at c lies within
// [v - r, v + r] in the cell (r: the cell's half-diagonal). A fold whose operands are that far
// apart that the operator returns one of them unchanged (opUnion returns a once b - a >= k,
// exactly, with k the blend radius) keeps only that operand, so within the cell the pruned tape
// gives the same bits as the whole tree. A cell whose root value exceeds its radius holds no
// surface: it stores that value, and evaluation answers there with the bound
// v - |p - c| (outside) or v + |p - c| (inside), never larger in magnitude than the field.
// Cells that hold surface are refined down to the leaf level, which keeps their pruned tapes.
#pragma once

#include "sdfcsg/eval.h"
#include "shared.h"

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace sdfcsg::detail {

// Instruction: node index | NodeKind << kTapeKindShift. A primitive pushes its value; an
// operation pops b, then a, and pushes op(a, b) with its blend radius and profile.
inline constexpr uint32_t kTapeNodeBits = SDFCSG_TAPE_NODE_BITS;
inline constexpr uint32_t kTapeKindShift = SDFCSG_TAPE_KIND_SHIFT;
// A domain operation's child is the tape between the operation's own instruction (which sets
// the point the child is evaluated at) and this one (which takes the child's value, and runs the
// child again at the operation's next candidate point, if any: sdf.glsl, domainPoint). Pruning
// keeps the two and all between them whole. A value operation (shell, offset) is one
// instruction after its child's.
inline constexpr uint32_t kTapeDomainEnd = SDFCSG_TAPE_DOMAIN_END;
static_assert(kNodeKindCount <= int(kTapeDomainEnd), "an instruction's kind has 6 bits");
inline constexpr uint32_t kTapeNodeMask = (1u << kTapeNodeBits) - 1u;
// A leaf cell entry (x, y): near a surface, the cell's tape [x, x + y) in PrunedField::tape;
// far from every surface, x holds the root value at the centre of the cell of level
// y & 0xff that was found far, y has kFarCell set and, with bit 30, the field's direction of
// ascent there in bits 8 to 29 (for shading; farGradientBits in prune.cpp).
inline constexpr uint32_t kFarCell = 0x80000000u;

struct PruneOptions {
    uint32_t levels = 5;       // octree levels below the top grid's cells; 0: no pruning
    uint32_t cells = 1u << 19; // about this many leaf cells in the bounds
    // At most about this many tape words (4 bytes each) per level: where the tree prunes too
    // little for that, refinement stops and the leaf cells run their coarser parents' tapes.
    size_t maxWords = size_t(1) << 24;
};

struct PrunedField {
    glm::vec3 origin{0.0f};   // the grid's minimum corner
    float cell = 1.0f;        // leaf cell side
    uint32_t levels = 0;      // a top cell holds 2^levels leaf cells per axis
    glm::uvec3 dims{0};       // leaf cells per axis
    bool bounded = false;     // outside the grid, the field is at least its distance to it
    uint32_t fullLength = 0;  // tape[0, fullLength) is the whole tree
    uint32_t stackDepth = 0;  // the most values any tape holds at once
    uint32_t domainDepth = 0; // the most domain operations open at once in any tape
    std::vector<uint32_t> tape;
    std::vector<glm::uvec2> cells; // x + dims.x * (y + dims.y * z)

    // The field at p, as sceneDistance()/sceneSample() in shaders/tape.glsl compute it (a ball
    // there rounds otherwise, isBall); where the value is a bound, the sample's colour is -1.
    float distance(const std::vector<FlatNode>& nodes, glm::vec3 p) const;
    Sample sample(const std::vector<FlatNode>& nodes, glm::vec3 p) const;
    // Instructions that the leaf cell holding p runs (the whole tape outside the cube), 0 in a
    // far cell.
    uint32_t activeLength(glm::vec3 p) const;
    // The mean of the instructions that the leaf cells near a surface run (0 when none is).
    double meanActiveLength() const;
};

// The work bound: a scene whose cells near the surface run more instructions than this on
// average is refused before it renders or meshes (a smooth union of hundreds of primitives that
// all overlap; on lavapipe, a 1280 x 720 frame at this mean takes about half a minute).
inline constexpr uint32_t kMaxMeanCellInstructions = 1024;

// The whole tree as a tape, and the most values it holds at once.
std::vector<uint32_t> fullTape(const std::vector<FlatNode>& nodes, uint32_t& stackDepth);

PrunedField pruneField(const Evaluator& evaluator, const PruneOptions& options = {});

// A sphere whose transform is a rotation and a uniform scale (none differs per axis): its value
// is the distance to its centre less its radius, which the tape machine reads as one vec4 where
// every sphere of the scene is a ball (SDFCSG_TAPE_BALLS, shaders/tape.glsl): the same value up
// to rounding.
bool isBall(const FlatNode& node);
// The scene has spheres and every one is a ball: what SDFCSG_TAPE_BALLS asks of kernels that may
// follow values (CodegenOptions::inlineParams).
bool allSpheresAreBalls(const std::vector<FlatNode>& nodes);

// What shaders/tape.glsl reads, as one buffer of 32-bit words: a header of 12 words (origin,
// cell, levels, dims, 1 when bounded, full tape length, first tape word, first cell word), four
// words per node (a ball's centre and radius in its frame, zeros for other nodes), the cells
// (two words each), then the tape.
inline constexpr uint32_t kFieldHeaderWords = 12;
// In the packed tapes only: a primitive whose operation is the next instruction carries that
// operation (union 1, intersection 2, difference 3) at this bit and its blend profile at
// SDFCSG_TAPE_BLEND_SHIFT, and the next word is then the operation's blend radius, as float
// bits (tape.glsl).
inline constexpr uint32_t kTapeFoldShift = SDFCSG_TAPE_FOLD_SHIFT;
std::vector<uint32_t> packField(const PrunedField& field, const std::vector<FlatNode>& nodes);

// Value of a primitive node at p (eval.cpp): the kernel at the local point, times the scale.
float primitiveValue(const FlatNode& node, glm::vec3 p);
// The same at `count` points.
void primitiveValues(const FlatNode& node, const glm::vec3* p, uint32_t count, float* values);
// Value of a transition at p from its children's values a and b, floored at its bounds (eval.cpp).
float transitionValue(const FlatNode& op, glm::vec3 p, float a, float b);
// p in the node's local space, as nodes.glsl's toLocal computes it (eval.cpp).
glm::vec3 nodeLocalPoint(const FlatNode& node, glm::vec3 p);
// A primitive's colour at p: its own (FlatNode::ownColors) or the node's (eval.cpp).
glm::vec3 primitiveColor(const FlatNode& node, glm::vec3 p);
// Node `node`'s subtree alone at a point of its frame (FlatNode::frame), as its parent passes it
// (eval.cpp): its value, and its colour.
float subtreeValue(const Evaluator& evaluator, uint32_t node, glm::vec3 p);
glm::vec3 subtreeColor(const Evaluator& evaluator, uint32_t node, glm::vec3 p);

} // namespace sdfcsg::detail
