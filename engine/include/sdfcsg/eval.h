// sdfcsg: the CPU reference evaluator.
//
// Evaluates exactly the field that the generated GLSL evaluates (same formulas, same operation
// order), in double-free single precision. Used for bounds, camera framing, tests and any
// host-side query. Thread-safe for concurrent reads once built.
#pragma once

#include "sdfcsg/scene.h"

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

namespace sdfcsg {

struct Aabb {
    glm::vec3 min{std::numeric_limits<float>::infinity()};
    glm::vec3 max{-std::numeric_limits<float>::infinity()};

    bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
    bool finite() const; // no infinite coordinate (false for planes)
    // Euclidean distance from p to the box, 0 inside.
    float distance(glm::vec3 p) const;
    // Signed distance: as distance() outside, minus the distance to the nearest face inside
    // (-infinity inside an unbounded box).
    float signedDistance(glm::vec3 p) const;
};

// The frame of nodes outside every domain operation.
inline constexpr uint32_t kWorldFrame = UINT32_MAX;

// A node with everything resolved to the space of its frame: the world, or for the nodes inside
// a domain operation (repeat, twist, ...) the space that operation evaluates its child in.
// Index-aligned with Scene::nodes.
struct FlatNode {
    NodeKind kind;
    uint32_t frame;    // the domain operation whose child space this node lives in, or
                       // kWorldFrame
    glm::mat3 toLocal; // frame -> local linear part (rotation transposed, divided by scale)
    glm::vec3 offset;  // local = toLocal * frame point + offset
    float scale;       // accumulated uniform scale: frame distance = scale * local distance
    glm::vec3 color;   // resolved (inherited) colour
    float smooth;      // operations: blend radius in world units
    uint32_t blend;    // operations: the blend profile (the "blend" field's index)
    std::array<float, kMaxParams> params; // the kernel's parameters (half extents, unit normal,
                                          // ...): KindInfo::kernel and ::kernelAround
    Aabb bounds; // bounds in the frame; the node's value at p is >= bounds.signedDistance(p)
    // Primitives: the value is the larger of the formula's and bounds.signedDistance(p), which
    // the formula alone would fall below (a scale that differs per axis). Domain operations'
    // values always are.
    bool boundsFloor = false;
    // A primitive with colours of its own (ownColors in sdfcsg/nodes.h, a mesh's): its colour at
    // a point is its kind's colorFunction's, `color` where that has none.
    bool ownColors = false;
    // How far the node's value may fall below the distance: it lies between distance / loss and
    // the distance (1: a distance, as far as the field knows). Twist, bend and taper divide by
    // their Lipschitz bound, a scale that differs per axis multiplies by its smallest factor, an
    // ellipsoid is a bound, a smooth blend counts as 2; a node's is the worst of its own and its
    // children's. An offset or shell over a child with loss above 1 measures from the child's
    // value over its gradient's length (sdf.glsl, valueNormalised) and is a distance again.
    float loss = 1.0f;
    std::vector<uint32_t> children;
    // Polygon, text and image: Node::words; the parameters then come from its first two words
    // (the layout and the extents in slots 2-5).
    std::shared_ptr<const std::vector<glm::vec4>> words;
};

struct Sample {
    float distance;
    glm::vec3 color;
};

class Evaluator;
namespace detail {
struct PrunedField;
// The evaluator's pruned field (field/prune.h), made on the first call and shared by its copies:
// the kernels' tapes and prunedDistance() come from one pruning.
const PrunedField& prunedField(const Evaluator& evaluator);
} // namespace detail

class Evaluator {
  public:
    explicit Evaluator(const Scene& scene);

    // Signed distance (a lower bound away from the surface, exact near it for exact primitives).
    float distance(glm::vec3 p) const;
    // Distance and blended colour.
    Sample sample(glm::vec3 p) const;
    // The same for the subtree rooted at nodes()[node] alone (picking, per-node tests); for a
    // node inside a domain operation, the outermost such operation's subtree.
    float distance(glm::vec3 p, uint32_t node) const;
    Sample sample(glm::vec3 p, uint32_t node) const;
    // The field evaluated per region from pruned tapes, as the GPU kernels of large scenes
    // evaluate it (docs/scale.md): distance() to 1e-5 near the surface, elsewhere a bound of the
    // same sign and no larger magnitude. Far faster than distance() on scenes of thousands of
    // nodes, for many points; the first call prunes (about 0.1 s for 1,000 nodes) unless the
    // kernels' tapes were made from this evaluator or a copy (detail::prunedField).
    float prunedDistance(glm::vec3 p) const;
    // The same with the colour, which is -1 where the value is a bound (far from every surface).
    Sample prunedSample(glm::vec3 p) const;
    // Bounds of the whole solid; infinite along axes where a plane reaches. The evaluation
    // skips by them: the field is at least their box's signed distance.
    const Aabb& bounds() const { return nodes_[0].bounds; }
    // The box the solid lies in, within bounds() and tighter where the operations allow: an
    // intersection within the overlap of its operands' boxes, clipped by the half-spaces of its
    // planes; a difference within its first operand's, less what a subtracted box or plane
    // removes from it; a twist or polar repetition within its child's radius about the y axis.
    // The field may be below its signed distance, so nothing skips by it; framing and the mesh
    // grid take it.
    const Aabb& solidBounds() const { return solidBounds_; }
    // The finite box the solid lies in, as tight as the bounds know it: bounds() on every side
    // where they are finite (a difference lies within its first operand, whatever it subtracts),
    // elsewhere the box around the finite primitives (a ground plane makes bounds() infinite);
    // those primitives' box alone where bounds() is empty, and the cube from -1 to 1 where there
    // are none. What the mesher meshes by default (with a margin) and what the ground grid lies
    // under.
    Aabb finiteBounds() const;
    const std::vector<FlatNode>& nodes() const { return nodes_; }

    // With skipping on, union and difference operands whose bounds cannot change the result are
    // not evaluated, exactly as the generated GLSL does; the value is the same either way.
    void setBoundsSkipping(bool on) { skipping_ = on; }

  private:
    friend const detail::PrunedField& detail::prunedField(const Evaluator& evaluator);
    struct Pruned; // eval.cpp
    std::vector<FlatNode> nodes_;
    Aabb solidBounds_;
    bool skipping_ = true;
    std::shared_ptr<Pruned> pruned_;
};

// Where a scene's field stops being a distance, and an operation that moves or blends by its
// values depends on it: an `offset` or `shell` (which place the surface at a value), or a smooth
// union, intersection, difference or mirror (whose blend width is measured in values). A field
// stops being a distance under twist, bend and taper (divided by their Lipschitz bound), a
// scale that differs between axes (the smallest factor), an ellipsoid, and within a smooth
// blend's radius. One note per dependent node, naming it by its JSON path, in the file's order;
// then one at the root where the renderer's ambient occlusion and soft shadows, which read the
// field as a distance, show the loss (a factor of 2 or more). Among them, in the file's order,
// one per mesh node whose file is not a closed, consistently oriented surface (open edges, edges
// of three or more triangles, flipped or degenerate triangles), with the counts, since its inside
// comes from the winding number rather than from the file's orientation.
struct FieldNote {
    std::string path;    // the dependent node or mesh, e.g. "root.children[1]"
    std::string message; // what it depends on, where that stops being a distance, and how much
};
std::vector<FieldNote> fieldNotes(const Scene& scene, const Evaluator& evaluator);

// Whether the solid is certainly empty: its bounds are empty, or finite and split into boxes
// whose centres each lie outside, farther from the surface than the box's half-diagonal (every
// field is 1-Lipschitz). False where some point is inside, or a few thousand values do not
// settle it.
bool provablyEmpty(const Evaluator& evaluator);

// A camera looking at the box the solid lies in (Evaluator::finiteBounds()) from a three-quarter
// view of that box's largest face (the front unless the top or the side is a quarter larger),
// from the right, above and in front, as near as it can be with every corner of the box within
// the view, a tenth inside its edges. `aspect` is the image's width over its height, `fov` the
// vertical field of view in degrees.
Camera frameCamera(const Evaluator& evaluator, float aspect, float fov = 45.0f);

} // namespace sdfcsg
