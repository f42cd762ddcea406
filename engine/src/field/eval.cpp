// The CPU reference evaluator. Flattening resolves transforms, colours, smooth radii and bounds
// to world space once; evaluation then walks the pre-order node array with an explicit stack,
// in exactly the order (and with exactly the skipping rules) of the code that codegen.cpp
// generates, so the CPU and GPU fields agree to rounding.
#include "sdfcsg/eval.h"

#include "field/bake.h"
#include "field/prune.h"
#include "field/sdf.h"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec4.hpp>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numbers>
#include <type_traits>

namespace sdfcsg {

bool Aabb::finite() const {
    for (int i = 0; i < 3; ++i)
        if (!std::isfinite(min[i]) || !std::isfinite(max[i])) return false;
    return true;
}

float Aabb::distance(glm::vec3 p) const {
    return glm::length(glm::max(glm::max(min - p, p - max), glm::vec3(0.0f)));
}

// Same formula as boundsDistance() in shaders/nodes.glsl. A node's value is never below it:
// outside, the solid is no nearer than its box; inside, the solid's boundary is no farther than
// the box's. (The unsigned distance would not do: 0 inside the box says nothing about a value
// that may be negative there.)
float Aabb::signedDistance(glm::vec3 p) const {
    glm::vec3 q = glm::max(min - p, p - max);
    return glm::length(glm::max(q, 0.0f)) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0f);
}

namespace {

constexpr glm::vec3 kDefaultColor{0.8f, 0.8f, 0.8f};

bool isOperation(NodeKind kind) {
    return kindInfo(kind).operation;
}

// cos and sin of an angle in degrees, exact for multiples of 90 so that quarter turns keep
// boxes axis-aligned to the last bit.
glm::dvec2 cosSin(double degrees) {
    double r = std::fmod(degrees, 360.0);
    if (r < 0) r += 360.0;
    if (r == 0.0) return {1, 0};
    if (r == 90.0) return {0, 1};
    if (r == 180.0) return {-1, 0};
    if (r == 270.0) return {0, -1};
    double a = r * std::numbers::pi / 180.0;
    return {std::cos(a), std::sin(a)};
}

// R = Rz * Ry * Rx: rotate about x first, then y, then z.
glm::dmat3 rotation(glm::vec3 degrees) {
    glm::dvec2 x = cosSin(degrees.x), y = cosSin(degrees.y), z = cosSin(degrees.z);
    glm::dmat3 rx(1, 0, 0, 0, x[0], x[1], 0, -x[1], x[0]); // columns
    glm::dmat3 ry(y[0], 0, -y[1], 0, 1, 0, y[1], 0, y[0]);
    glm::dmat3 rz(z[0], z[1], 0, -z[1], z[0], 0, 0, 0, 1);
    return rz * ry * rx;
}

// Float bounds that contain the double ones: round outwards, then pad a little so that the
// single-precision fields evaluated against them still never undercut them.
Aabb outwardBox(glm::dvec3 lo, glm::dvec3 hi) {
    // Sizes from the axes a 2D profile's prism does not reach along (nodes.cpp, kProfileReach):
    // its 1e30 would pad the others by 1e25.
    glm::dvec3 l = lo, h = hi;
    for (int i = 0; i < 3; ++i)
        if (std::max(std::abs(l[i]), std::abs(h[i])) >= 1e29) l[i] = h[i] = 0.0;
    double pad = 1e-5 * (glm::length(h - l) + glm::length(h + l) * 0.5) + 1e-6;
    Aabb box;
    for (int i = 0; i < 3; ++i) {
        box.min[i] = std::nextafter(float(lo[i] - pad), -INFINITY);
        box.max[i] = std::nextafter(float(hi[i] + pad), INFINITY);
    }
    return box;
}

Aabb infiniteBox() {
    return Aabb{glm::vec3(-INFINITY), glm::vec3(INFINITY)};
}

// How far a union's smooth blend reaches beyond its operands' boxes. Each fold goes at most k/4
// below the smaller operand (k/2 chamfered, k (1 - 1/sqrt 2) round), and however many operands,
// the fold never goes more than k below their minimum: every blend grows with each operand, and
// blends m - k and m to m - k, so from operands >= m every fold stays >= m - k. Boxes widened by
// the lesser of the two then bound it.
float smoothGrowth(const FlatNode& n) {
    if (!(n.smooth > 0.0f)) return 0.0f;
    const float folds = float(n.children.size() - 1);
    const float dip = n.blend == 2 ? 0.5f : n.blend == 1 ? 0.29289322f : 0.25f;
    return n.smooth * std::min(1.0f, dip * folds) * (1.0f + 1e-5f);
}

// A loss (FlatNode::loss) above this is not a distance; and what a smooth blend counts as: the
// field of a polynomial smooth minimum of two distances whose gradients meet at up to 120
// degrees has a gradient of length at least 1/2.
constexpr float kExactLoss = 1.001f;
constexpr float kBlendLoss = 2.0f;

// The tap step of an offset or shell over a field that is not a distance (sdf.glsl,
// valueNormalised): a thousandth of its child's box, far below the detail the offset moves by,
// and far enough above single precision's rounding of the child's values (about 1e-7 of the
// box) to leave the gradient good to about 1e-4.
float normalisedStep(const Aabb& child) {
    return child.finite() ? 1e-3f * std::max(glm::length(child.max - child.min), 1e-6f) : 1e-3f;
}

// Whether a linear map takes each axis onto an axis (turns by right angles, mirrors, scales).
bool axisAligned(const glm::dmat3& m) {
    for (int c = 0; c < 3; ++c) {
        int along = 0;
        const double largest = std::max({std::abs(m[c].x), std::abs(m[c].y), std::abs(m[c].z)});
        for (int r = 0; r < 3; ++r)
            along += std::abs(m[c][r]) > 1e-9 * largest;
        if (along != 1) return false;
    }
    return true;
}

float volume(const Aabb& b) {
    glm::vec3 e = b.max - b.min;
    return e.x * e.y * e.z;
}

// The half-space dot(normal, p) <= offset of a frame, normal of unit length, and a node's value
// is at least slope times p's signed distance from it (an exact distance's slope is 1).
struct HalfSpace {
    glm::dvec3 normal;
    double offset;
    double slope;
};

// The most half-spaces a node's boxes are clipped by; more are left out (the box then holds
// more than the solid, never less), so that a long chain of intersections stays linear.
constexpr size_t kMaxClipSpaces = 16;

// The half-space dot(local, axis) < k of node n, local = toLocal p + offset: its value there is
// the local one times its scale, and the local value dot(local, axis) - k is the frame's
// distance times the length of toLocal's transpose times the axis.
HalfSpace localSpace(const FlatNode& n, glm::dvec3 axis, double k) {
    const glm::dvec3 across = glm::transpose(glm::dmat3(n.toLocal)) * axis;
    const double length = glm::length(across);
    return {across / length, (k - glm::dot(glm::dvec3(n.offset), axis)) / length,
            length * double(n.scale)};
}

// The half-spaces a primitive's value is at least its slope times the distance from: a plane's
// own, and a box's (rounded or not) faces where it is turned off the axes (else its bounds are
// its faces).
void primitiveSpaces(const FlatNode& n, std::vector<HalfSpace>& out) {
    if (n.kind == NodeKind::Plane) {
        out.push_back(localSpace(n, {n.params[0], n.params[1], n.params[2]}, n.params[3]));
    } else if ((n.kind == NodeKind::Box || n.kind == NodeKind::RoundBox) &&
               !axisAligned(glm::dmat3(n.toLocal))) {
        for (int a = 0; a < 3; ++a) {
            glm::dvec3 axis(0.0);
            axis[a] = 1.0;
            out.push_back(localSpace(n, axis, n.params[a]));
            out.push_back(localSpace(n, -axis, n.params[a]));
        }
    }
}

// How far from its local y axis a primitive reaches, for the kinds that reach less far than
// their box's corners (round about the axis, or nearly), from their kernel parameters; else
// infinity.
double axisRadius(NodeKind kind, const Params& k) {
    switch (kind) {
    case NodeKind::Sphere:
    case NodeKind::Cylinder:
    case NodeKind::Octahedron:
        return k[0];
    case NodeKind::Cone:
    case NodeKind::RoundCone:
        return std::max(k[0], k[kind == NodeKind::Cone ? 2 : 1]);
    case NodeKind::RoundedCylinder:
    case NodeKind::Torus:
    case NodeKind::CappedTorus:
        return double(k[0]) + k[kind == NodeKind::RoundedCylinder ? 2 : 1];
    case NodeKind::HexPrism:
        return k[0] / 0.8660254; // the apothem's corner
    case NodeKind::Ellipsoid:
        return 1.0 / std::min(k[0], k[2]);
    case NodeKind::Pyramid:
        return 0.5 * std::sqrt(2.0) * k[0];
    default:
        return INFINITY;
    }
}

// How far from the y axis the points of a box reach.
double boxRadius(const Aabb& b) {
    const double x = std::max(std::abs(double(b.min.x)), std::abs(double(b.max.x)));
    const double z = std::max(std::abs(double(b.min.z)), std::abs(double(b.max.z)));
    return std::sqrt(x * x + z * z);
}

// A box and half-spaces: the solid below value r lies in the box grown by r along each axis and
// in each half-space moved out by r over its slope, when the value is at least the largest of
// the Chebyshev distance to the box (the largest of the distances along each axis, which the
// signed distance of bounds is never below) and the half-spaces' slopes times their distances.
struct Region {
    Aabb box;
    std::vector<HalfSpace> spaces;
};

void addSpaces(Region& to, const std::vector<HalfSpace>& spaces) {
    for (const HalfSpace& h : spaces)
        if (to.spaces.size() < kMaxClipSpaces) to.spaces.push_back(h);
}

Region grown(Region region, float r) {
    region.box.min -= r, region.box.max += r;
    for (HalfSpace& h : region.spaces)
        h.offset += double(r) / h.slope;
    return region;
}

// The box of the part of `box` in every half-space: the box of that polytope's corners, the
// points where three of its planes (the box's faces and the half-spaces' boundaries) meet and
// that lie in all the others (a few thousand small solves for 16 half-spaces). Where the box is
// unbounded, only half-spaces across an axis clip it, until it is bounded. Rounded outwards.
Aabb clipBox(const Aabb& box, const std::vector<HalfSpace>& spaces) {
    Aabb out = box;
    for (const HalfSpace& h : spaces)
        for (int a = 0; a < 3; ++a) {
            if (h.normal[(a + 1) % 3] != 0.0 || h.normal[(a + 2) % 3] != 0.0) continue;
            const float at = float(h.offset / h.normal[a]);
            if (h.normal[a] > 0.0)
                out.max[a] = std::min(out.max[a], std::nextafter(at, INFINITY));
            else
                out.min[a] = std::max(out.min[a], std::nextafter(at, -INFINITY));
        }
    if (out.empty() || !out.finite()) return out;
    std::vector<HalfSpace> planes = spaces;
    double size = 0.0;
    for (int a = 0; a < 3; ++a) {
        glm::dvec3 axis(0.0);
        axis[a] = 1.0;
        planes.push_back({axis, double(out.max[a]), 1.0});
        planes.push_back({-axis, -double(out.min[a]), 1.0});
        size = std::max({size, std::abs(double(out.min[a])), std::abs(double(out.max[a]))});
    }
    const double slack = 1e-9 * (size + 1.0);
    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    const size_t m = planes.size();
    for (size_t i = 0; i < m; ++i)
        for (size_t j = i + 1; j < m; ++j)
            for (size_t k = j + 1; k < m; ++k) {
                const HalfSpace &a = planes[i], &b = planes[j], &c = planes[k];
                const glm::dvec3 bc = glm::cross(b.normal, c.normal);
                const double det = glm::dot(a.normal, bc);
                if (std::abs(det) < 1e-12) continue; // two of them parallel, or all three
                const glm::dvec3 corner =
                    (a.offset * bc + b.offset * glm::cross(c.normal, a.normal) +
                     c.offset * glm::cross(a.normal, b.normal)) /
                    det;
                bool inside = true;
                for (size_t l = 0; l < m && inside; ++l)
                    inside = glm::dot(planes[l].normal, corner) <= planes[l].offset + slack;
                if (inside) lo = glm::min(lo, corner), hi = glm::max(hi, corner);
            }
    if (lo.x > hi.x) return Aabb{}; // nothing of the box is in every half-space
    return outwardBox(lo, hi);
}

// local = toLocal * p + offset, associated as dot(row, vec4(p, 1)) in nodes.glsl.
glm::vec3 localPoint(const FlatNode& n, glm::vec3 p) {
    const glm::mat3& m = n.toLocal;
    return {m[0][0] * p.x + m[1][0] * p.y + m[2][0] * p.z + n.offset.x,
            m[0][1] * p.x + m[1][1] * p.y + m[2][1] * p.z + n.offset.y,
            m[0][2] * p.x + m[1][2] * p.y + m[2][2] * p.z + n.offset.z};
}

// A primitive's own colour at p (FlatNode::ownColors).
glm::vec3 ownColor(const FlatNode& n, glm::vec3 p) {
    return sdf::sdPrimitiveColor(uint32_t(n.kind), localPoint(n, p),
                                 {n.params[0], n.params[1], n.params[2], n.params[3]},
                                 {n.params[4], n.params[5], n.params[6], n.params[7]}, n.color,
                                 sdf::kAllKinds, n.words->data());
}

// The value types of sceneDistance (float) and sceneSample (vec4: colour, distance in w).
template <class V> V leaf(const FlatNode& n, glm::vec3 p) {
    float d = sdf::evalPrimitive(n.kind, localPoint(n, p), n.params,
                                 n.words ? n.words->data() : nullptr) *
              n.scale;
    if (n.boundsFloor) d = std::max(d, n.bounds.signedDistance(p));
    if constexpr (std::is_same_v<V, float>)
        return d;
    else
        return glm::vec4(n.ownColors ? ownColor(n, p) : n.color, d);
}
template <class V> float dist(const V& v) {
    if constexpr (std::is_same_v<V, float>)
        return v;
    else
        return v.w;
}

// The kernel parameters of a kind with words (Node::words) come from its first two: slot 0 is
// the first word's index (0 here; the node buffer rebases it), then word 0's x, word 1, word 0's
// y and z. Polygon and text, sdOutline's (outline.h): its grid's cells per row (0 for an outline
// listed by contour), its box, and the grid's rows and cell side (or the number of contours);
// image, sdImage's (image.h): the same of its grid of distances; heightmap, sdHeightmap's: its
// samples per row, half extents along x and z, height, 0, rows and 1 / its Lipschitz bound.
// Mesh, sdMesh's (mesh_field.h): its bricks along x, the grid's corner and cell, its bricks along
// y and z; then, for its bounds, the mesh's size and its least corner's distance from the grid's
// (from the word before the last).
Params wordsParams(NodeKind kind, const std::vector<glm::vec4>* words) {
    if (!words || words->size() < 2) return Params{};
    const glm::vec4 layout = (*words)[0], box = (*words)[1];
    Params k{0.0f, layout.x, box.x, box.y, box.z, box.w, layout.y, layout.z};
    if (kind == NodeKind::Mesh && words->size() >= 4) {
        const glm::vec4 mesh = (*words)[words->size() - 2];
        k[8] = mesh.x, k[9] = mesh.y, k[10] = mesh.z, k[11] = mesh.w;
    }
    return k;
}

Role roleOf(NodeKind kind) {
    return kindInfo(kind).role;
}

// Whether an offset or shell measures from its child's value over its gradient's length
// (FlatNode::loss).
bool normalises(const FlatNode& n) {
    return roleOf(n.kind) == Role::Value && n.params[1] > 0.0f;
}

glm::vec4 kernelA(const FlatNode& n) {
    return {n.params[0], n.params[1], n.params[2], n.params[3]};
}
glm::vec4 kernelB(const FlatNode& n) {
    return {n.params[4], n.params[5], n.params[6], n.params[7]};
}

template <class V> V withDistance(V v, float d) {
    if constexpr (std::is_same_v<V, float>)
        return d;
    else
        return glm::vec4(glm::vec3(v), d);
}

// A transition's value from its children's a and b at p (sdf.glsl, opTransition), floored at its
// bounds' signed distance: the mix divided by its Lipschitz bound grows more slowly than that
// distance outside the bounds (where it is positive, as both children are).
template <class V> V transition(const FlatNode& op, glm::vec3 p, V a, V b) {
    const float w =
        sdf::transitionWeight(uint32_t(op.kind), localPoint(op, p), kernelA(op), kernelB(op));
    const V v = sdf::opTransition(a, b, w, kernelB(op));
    return withDistance(v, std::max(dist(v), op.bounds.signedDistance(p)));
}

// The generated code's walk, iteratively: a frame per open operation holds the running fold
// and the next child to visit. Operand i > 0 of a union is skipped when its bounds lie at least
// k beyond the running value, a subtrahend when they lie at least k beyond its negation; with
// sdf.glsl's exact operator ends, the skipped operand could not have changed the result. A
// domain operation evaluates its child at each of its candidate points (sdf.glsl, domainPoint)
// whose bounds could lower the least value so far, as shaders/tape.glsl does, and its value is
// floored at its bounds' signed distance: a repetition's is capped by the distance to the
// copies it leaves out, a stretching operation's divided by its Lipschitz bound, a scale per
// axis multiplies any by its smallest factor, and every one of them grows more slowly than the
// box's distance somewhere. The floor keeps the value a distance bound of the same sign (the
// box holds the solid), and makes it what the skipping above relies on.
template <class V>
V evaluate(const std::vector<FlatNode>& nodes, uint32_t root, glm::vec3 p, bool skipping) {
    struct Frame {
        uint32_t node, next;
        V acc;
        glm::vec3 outer{0.0f}, local{0.0f}; // domain operations: the point outside, and local
        uint32_t candidate = 0, count = 0;  // domain operations and normalising value ones
        glm::vec4 taps{0.0f};               // normalising value operations: valueTapSum's
    };
    thread_local std::vector<Frame> stack;
    stack.clear();
    uint32_t current = root;
    for (;;) {
        const FlatNode& n = nodes[current];
        if (isOperation(n.kind)) {
            Frame f{current, 1, V{}};
            if (roleOf(n.kind) == Role::Domain) {
                const uint32_t kind = uint32_t(n.kind);
                f.outer = p;
                f.local = localPoint(
                    n, sdf::domainClamps(kind) ? glm::clamp(p, n.bounds.min, n.bounds.max) : p);
                f.count = sdf::domainCount(kind, kernelA(n), kernelB(n));
                f.acc = withDistance(V{}, INFINITY);
                p = glm::vec3(sdf::domainPoint(kind, f.local, kernelA(n), kernelB(n), 0));
            } else if (normalises(n)) {
                f.outer = p;
                f.count = 4;
                p = sdf::valueTap(p, n.params[1], 0);
            }
            stack.push_back(f);
            current = n.children[0];
            continue;
        }
        V value = leaf<V>(n, p);
        // Deliver the value to the enclosing operations until one has another child to visit.
        for (;;) {
            if (stack.empty()) return value;
            Frame& f = stack.back();
            const FlatNode& op = nodes[f.node];
            const Role role = roleOf(op.kind);
            if (role == Role::Value) {
                float d = dist(value);
                if (normalises(op)) {
                    f.taps = sdf::valueTapSum(f.taps, d, f.candidate);
                    if (f.candidate == 0) f.acc = value; // the colour
                    if (++f.candidate < f.count) {
                        p = sdf::valueTap(f.outer, op.params[1], f.candidate);
                        current = op.children[0];
                        break;
                    }
                    d = sdf::valueOpNormalised(uint32_t(op.kind), f.taps, kernelA(op));
                    d = std::max(d, op.bounds.signedDistance(f.outer));
                    value = withDistance(f.acc, d);
                    p = f.outer;
                    stack.pop_back();
                    continue;
                }
                d = sdf::valueOp(uint32_t(op.kind), d, kernelA(op));
                value = withDistance(value, d);
                stack.pop_back();
                continue;
            }
            if (role == Role::Domain) {
                const uint32_t kind = uint32_t(op.kind);
                if (dist(value) < dist(f.acc)) f.acc = value;
                const FlatNode& child = nodes[op.children[0]];
                bool again = false;
                while (!again && ++f.candidate < f.count) {
                    const glm::vec4 q =
                        sdf::domainPoint(kind, f.local, kernelA(op), kernelB(op), f.candidate);
                    again = q.w == 0.0f &&
                            (!skipping || child.bounds.signedDistance(glm::vec3(q)) < dist(f.acc));
                    if (again) p = glm::vec3(q);
                }
                if (again) {
                    current = op.children[0];
                    break;
                }
                float d = sdf::domainFinish(kind, f.local, dist(f.acc), kernelA(op), kernelB(op)) *
                          op.scale;
                d = std::max(d, op.bounds.signedDistance(f.outer));
                value = withDistance(f.acc, d);
                p = f.outer;
                stack.pop_back();
                continue;
            }
            if (f.next == 1) {
                f.acc = value;
            } else if (isTransition(op.kind)) {
                f.acc = transition(op, p, f.acc, value);
            } else if (op.kind == NodeKind::Union) {
                f.acc = sdf::opUnion(f.acc, value, op.smooth, op.blend);
            } else if (op.kind == NodeKind::Intersection) {
                f.acc = sdf::opIntersection(f.acc, value, op.smooth, op.blend);
            } else {
                f.acc = sdf::opDifference(f.acc, value, op.smooth, op.blend);
            }
            // A transition needs both of its children everywhere.
            while (f.next < op.children.size() && skipping && op.kind != NodeKind::Intersection &&
                   !isTransition(op.kind)) {
                float bd = nodes[op.children[f.next]].bounds.signedDistance(p);
                float d = dist(f.acc);
                bool skip = op.kind == NodeKind::Union ? bd - d >= op.smooth : bd + d >= op.smooth;
                if (!skip) break;
                ++f.next;
            }
            if (f.next < op.children.size()) {
                current = op.children[f.next++];
                break;
            }
            value = f.acc;
            stack.pop_back();
        }
    }
}

} // namespace

namespace detail {

float primitiveValue(const FlatNode& node, glm::vec3 p) {
    return leaf<float>(node, p);
}

float transitionValue(const FlatNode& op, glm::vec3 p, float a, float b) {
    return transition(op, p, a, b);
}

void primitiveValues(const FlatNode& node, const glm::vec3* p, uint32_t count, float* values) {
    for (uint32_t i = 0; i < count; ++i)
        values[i] = leaf<float>(node, p[i]);
}

glm::vec3 nodeLocalPoint(const FlatNode& node, glm::vec3 p) {
    return localPoint(node, p);
}

glm::vec3 primitiveColor(const FlatNode& node, glm::vec3 p) {
    return node.ownColors ? ownColor(node, p) : node.color;
}

float subtreeValue(const Evaluator& evaluator, uint32_t node, glm::vec3 p) {
    return evaluate<float>(evaluator.nodes(), node, p, true);
}

glm::vec3 subtreeColor(const Evaluator& evaluator, uint32_t node, glm::vec3 p) {
    return glm::vec3(evaluate<glm::vec4>(evaluator.nodes(), node, p, true));
}

} // namespace detail

struct Evaluator::Pruned {
    std::once_flag once;
    detail::PrunedField field;
};

Evaluator::Evaluator(const Scene& scene) : pruned_(std::make_shared<Pruned>()) {
    const size_t count = scene.nodes.size();
    nodes_.resize(count);
    if (count == 0) return;

    // Pass 1, parents first: transforms (accumulated in double), colours, parameters.
    struct Acc {
        glm::dmat3 toLocal{1.0}, toWorld{1.0};
        glm::dvec3 offset{0.0},
            origin{0.0}; // local = toLocal*p + offset; world = toWorld*l + origin
        double scale = 1.0;
        bool uneven = false;  // some scale on the way differs per axis
        double stretch = 1.0; // the product of largest over smallest factor on the way
    };
    const Acc identity;
    std::vector<Acc> acc(count);
    std::vector<uint32_t> parent(count, UINT32_MAX);
    std::vector<float> offsetReach(count, 0.0f);
    for (size_t i = 0; i < count; ++i) {
        const Node& src = scene.nodes[i];
        for (uint32_t c : src.children)
            parent[c] = uint32_t(i);
        const bool hasParent = parent[i] != UINT32_MAX;
        const FlatNode* upNode = hasParent ? &nodes_[parent[i]] : nullptr;
        // A domain operation's child starts a frame: its transforms act in the child space.
        const bool opensFrame = upNode && roleOf(upNode->kind) == Role::Domain;
        const Acc& up = hasParent && !opensFrame ? acc[parent[i]] : identity;

        glm::dmat3 r = rotation(src.transform.rotate);
        // p = R S l + t. Where S differs per axis the distance in the parent is at least the
        // local one times the smallest factor (S's least singular value; a product's is at
        // least the product of its factors'), which is exact for uniform scales.
        const glm::dvec3 s(src.transform.scale);
        glm::dvec3 t(src.transform.translate);
        const glm::dmat3 scaling(glm::dvec3(s.x, 0, 0), glm::dvec3(0, s.y, 0),
                                 glm::dvec3(0, 0, s.z));
        const glm::dmat3 unscaling(glm::dvec3(1 / s.x, 0, 0), glm::dvec3(0, 1 / s.y, 0),
                                   glm::dvec3(0, 0, 1 / s.z));
        glm::dmat3 inv = unscaling * glm::transpose(r);
        Acc& a = acc[i];
        a.toLocal = inv * up.toLocal;
        a.offset = inv * (up.offset - t);
        a.toWorld = up.toWorld * (r * scaling);
        a.origin = up.toWorld * t + up.origin;
        a.scale = up.scale * std::min({s.x, s.y, s.z});
        a.uneven = up.uneven || s.x != s.y || s.y != s.z;
        a.stretch = up.stretch * std::max({s.x, s.y, s.z}) / std::min({s.x, s.y, s.z});

        FlatNode& n = nodes_[i];
        n.kind = src.kind;
        n.frame = !upNode ? kWorldFrame : opensFrame ? parent[i] : upNode->frame;
        n.toLocal = glm::mat3(a.toLocal);
        n.offset = glm::vec3(a.offset);
        n.scale = float(a.scale);
        // Times the smallest factor, a field grows more slowly than its box's distance along
        // the other axes (at 1/2 of it along the largest of factors 1 and 2); and some kinds'
        // fields do so of themselves (KindInfo::floored).
        n.boundsFloor = !isOperation(src.kind) && (a.uneven || kindInfo(src.kind).floored);
        n.color = src.color ? *src.color : upNode ? upNode->color : kDefaultColor;
        n.params = sdf::kernelParams(src.kind, src.params);
        if (hasWords(src.kind)) {
            n.words = src.words;
            n.params = wordsParams(src.kind, src.words.get());
            n.ownColors = ownColors(src.kind, src.words.get());
        }
        // Transitions keep other values in those slots.
        const bool boolean = roleOf(src.kind) == Role::Boolean && !isTransition(src.kind);
        n.smooth = boolean ? float(double(src.params[0]) * a.scale) : 0.0f;
        n.blend = boolean ? uint32_t(src.params[1]) : 0u;
        n.children = src.children;
        // The child of a baked offset or shell (field/bake.h) is its baked distance: a mesh node
        // in the frame's space, its subtree left unvisited.
        if (hasParent && detail::baked(scene.nodes[parent[i]])) {
            a = Acc{};
            n.kind = NodeKind::Mesh;
            n.toLocal = glm::mat3(1.0f);
            n.offset = glm::vec3(0.0f);
            n.scale = 1.0f;
            n.boundsFloor = kindInfo(NodeKind::Mesh).floored;
            n.words = scene.nodes[parent[i]].words;
            n.params = wordsParams(NodeKind::Mesh, n.words.get());
            n.ownColors = ownColors(NodeKind::Mesh, n.words.get());
            n.smooth = 0.0f;
            n.blend = 0;
            n.children.clear();
        }
        // How far out an offset or shell above reads its child (see pass 2), in this frame.
        if (hasParent) {
            const Node& above = scene.nodes[parent[i]];
            const float units = float(acc[parent[i]].scale);
            float read = offsetReach[parent[i]];
            if (above.kind == NodeKind::Offset) read += std::max(above.params[0], 0.0f) * units;
            if (above.kind == NodeKind::Shell) read += 0.5f * above.params[0] * units;
            offsetReach[i] = opensFrame ? read / units : read;
        }
    }

    // Pass 2, children first: bounds, and the kernel parameters of the operations that take
    // their child's bounds.
    auto toFrame = [&](size_t i, glm::vec3 lo, glm::vec3 hi) {
        glm::dvec3 wlo(INFINITY), whi(-INFINITY);
        for (int c = 0; c < 8; ++c) {
            glm::dvec3 corner(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
            glm::dvec3 w = acc[i].toWorld * corner + acc[i].origin;
            wlo = glm::min(wlo, w);
            whi = glm::max(whi, w);
        }
        return outwardBox(wlo, whi);
    };
    // How far node i's value may fall below the distance (FlatNode::loss), once its children's
    // and its own parameters are known.
    auto lossOf = [&](size_t i) {
        const FlatNode& n = nodes_[i];
        const Node& src = scene.nodes[i];
        if (roleOf(n.kind) == Role::Value) return 1.0f;
        float loss = float(acc[i].stretch);
        for (uint32_t c : n.children)
            loss = std::max(loss, nodes_[c].loss);
        // A heightmap's value is the height difference over its Lipschitz bound (slot 7: 1 / it).
        if (n.kind == NodeKind::Heightmap && n.params[7] > 0.0f)
            loss = std::max(loss, 1.0f / n.params[7]);
        if (n.kind == NodeKind::Ellipsoid) {
            const float lo = std::min({src.params[0], src.params[1], src.params[2]});
            const float hi = std::max({src.params[0], src.params[1], src.params[2]});
            loss = std::max(loss, hi / lo);
        }
        if (roleOf(n.kind) == Role::Domain) {
            // The child's frame starts afresh: the node's own stretch is not in its leaves'.
            loss *= float(acc[i].stretch);
            if (kindInfo(n.kind).lipschitz && n.params[7] > 0.0f) loss /= n.params[7];
        }
        if (n.smooth > 0.0f) loss = std::max(loss, kBlendLoss);
        return loss;
    };
    for (size_t i = count; i-- > 0;) {
        FlatNode& n = nodes_[i];
        const KindInfo& info = kindInfo(n.kind);
        if (!isOperation(n.kind)) {
            glm::vec3 lo, hi;
            n.bounds =
                sdf::localBounds(n.kind, n.params, lo, hi) ? toFrame(i, lo, hi) : infiniteBox();
        } else if (info.role == Role::Value) {
            // Lengths in the frame's units, as the child's values are.
            Params values = scene.nodes[i].params;
            values[0] = float(double(values[0]) * acc[i].scale);
            const Aabb& child = nodes_[n.children[0]].bounds;
            n.params = info.kernelAround(values, child.min, child.max);
            if (nodes_[n.children[0]].loss > kExactLoss) {
                n.params[1] = normalisedStep(child);
                n.params[2] = 1.0f / nodes_[n.children[0]].loss;
            }
            n.bounds = child;
            if (child.finite())
                info.boundsAround(n.params, child.min, child.max, n.bounds.min, n.bounds.max);
        } else if (info.role == Role::Domain) {
            const Aabb& child = nodes_[n.children[0]].bounds;
            if (!child.finite()) { // refused by the parser, but for mirror and elongate
                n.params = info.kernelAround(scene.nodes[i].params, glm::vec3(0), glm::vec3(0));
                n.bounds = infiniteBox();
                n.loss = lossOf(i);
                continue;
            }
            n.params = info.kernelAround(scene.nodes[i].params, child.min, child.max);
            glm::vec3 lo, hi;
            info.boundsAround(n.params, child.min, child.max, lo, hi);
            n.bounds = toFrame(i, lo, hi);
            if (info.lipschitz) {
                // Twist, bend and taper evaluate their child at points clamped to their bounds,
                // below which their value is the bounds' distance: a bound, far below the
                // distance at the box's corners. Under an offset or shell the box reaches as far
                // as the offset reads (and the taps a little more), so the field is the child's
                // wherever the offset's surface may lie.
                if (offsetReach[i] > 0.0f) {
                    const float grow = 1.01f * offsetReach[i] + 4.0f * normalisedStep(n.bounds);
                    n.bounds.min -= grow, n.bounds.max += grow;
                }
                // Over the node's bounds (which the child's points are clamped to) in local space.
                glm::vec3 llo(INFINITY), lhi(-INFINITY);
                for (int c = 0; c < 8; ++c) {
                    const glm::vec3 corner(c & 1 ? n.bounds.max.x : n.bounds.min.x,
                                           c & 2 ? n.bounds.max.y : n.bounds.min.y,
                                           c & 4 ? n.bounds.max.z : n.bounds.min.z);
                    const glm::vec3 l = localPoint(n, corner);
                    llo = glm::min(llo, l), lhi = glm::max(lhi, l);
                }
                n.params[7] = 1.0f / info.lipschitz(n.params, llo, lhi);
            }
        } else if (n.kind == NodeKind::Union || isTransition(n.kind)) {
            Aabb box;
            for (uint32_t c : n.children) {
                box.min = glm::min(box.min, nodes_[c].bounds.min);
                box.max = glm::max(box.max, nodes_[c].bounds.max);
            }
            box.min -= smoothGrowth(n);
            box.max += smoothGrowth(n);
            n.bounds = box;
            if (isTransition(n.kind)) {
                // Both children's surfaces lie in the box U, so within it neither value is
                // farther from 0 than its diagonal, nor their difference from 2 diag(U) = D: the
                // clamp of opTransition leaves the mix whole there. The mix grows at most
                // 1 + D W fast (W: the weight's slope in the frame's units, the node's scale
                // shrinking its local units), the clamped difference's term included.
                n.params = info.kernelAround(scene.nodes[i].params, box.min, box.max);
                const float reach = 2.0f * glm::length(box.max - box.min);
                const float slope =
                    sdf::transitionSlope(uint32_t(n.kind), kernelA(n), kernelB(n)) / n.scale;
                n.params[6] = reach;
                n.params[7] = 1.0f / (1.0f + reach * slope);
            }
        } else if (n.kind == NodeKind::Intersection) {
            // A smooth maximum is never below the sharp one, so any operand's box bounds it.
            const Aabb* best = &nodes_[n.children[0]].bounds;
            for (uint32_t c : n.children)
                if (volume(nodes_[c].bounds) < volume(*best)) best = &nodes_[c].bounds;
            n.bounds = *best;
        } else {
            n.bounds = nodes_[n.children[0]].bounds;
        }
        n.loss = lossOf(i);
    }

    // Pass 3, children first: the box the solid lies in, as tight as the operations allow
    // (solidBounds()). The bounds above stand in for a node's value wherever the evaluation
    // skips it, so they must stay below that value; this box need not. An intersection lies
    // within the overlap of its operands' boxes, yet its value may be below that overlap's
    // distance (near a corner of it), so only here does it take the overlap, and half-spaces
    // clip it. Each node has
    //  - a reach, a Region its value bounds (see Region): the bounds; a plane's half-space and
    //    a turned box's faces; for an intersection the overlap of its operands' boxes and all
    //    their half-spaces (the largest of the operands' values is at least the largest of
    //    their distances, and the Chebyshev distance to an overlap is the largest of those to
    //    the boxes); for a difference its first operand's and the half-spaces its planes leave;
    //    for a union the box around its operands' grown by what its blend adds; an offset or a
    //    shell grows it by its distance. What a blend or an offset grows by needs it: an offset
    //    of a difference wraps round the edges of the box it subtracts, beyond the cut box;
    //  - a solid box, within the reach's: its operands' solid boxes cut by its half-spaces and
    //    by subtracted boxes, and carried through domain operations.
    //  - a radius about its frame's y axis that the solid lies within, for twist and
    //    polar_repeat, which turn about that axis: a cylinder twisted stays within its radius,
    //    whose box's corners reach further.
    std::vector<Region> reach(count);
    std::vector<Aabb> solid(count);
    std::vector<double> radial(count, INFINITY);
    // A radius about node i's local y axis, about its frame's: where its transform keeps the y
    // axis upright and scales x and z alike, the radius scaled, and the distance of its axis.
    auto frameRadius = [&](size_t i, double local) {
        const glm::dmat3& m = acc[i].toWorld;
        const double sx = glm::length(m[0]), sz = glm::length(m[2]);
        const bool upright = m[1].x == 0.0 && m[1].z == 0.0 && m[0].y == 0.0 && m[2].y == 0.0 &&
                             std::abs(glm::dot(m[0], m[2])) <= 1e-12 * sx * sz &&
                             std::abs(sx - sz) <= 1e-12 * sx;
        if (!upright || !std::isfinite(local)) return double(INFINITY);
        const glm::dvec3 o = acc[i].origin;
        return (std::sqrt(o.x * o.x + o.z * o.z) + local * sx) * (1.0 + 1e-6);
    };
    const Aabb everywhere{glm::vec3(-INFINITY), glm::vec3(INFINITY)};
    auto hull = [](Aabb a, const Aabb& b) {
        return Aabb{glm::min(a.min, b.min), glm::max(a.max, b.max)};
    };
    auto overlap = [](Aabb a, const Aabb& b) {
        return Aabb{glm::max(a.min, b.min), glm::min(a.max, b.max)};
    };
    auto clipped = [&](const Aabb& box, const std::vector<HalfSpace>& spaces) {
        return spaces.empty() || box.empty() ? box : overlap(box, clipBox(box, spaces));
    };
    for (size_t i = count; i-- > 0;) {
        const FlatNode& n = nodes_[i];
        const KindInfo& info = kindInfo(n.kind);
        const uint32_t first = n.children.empty() ? 0 : n.children[0];
        Region& r = reach[i];
        if (!isOperation(n.kind)) {
            r.box = solid[i] = n.bounds;
            primitiveSpaces(n, r.spaces);
            radial[i] = frameRadius(i, axisRadius(n.kind, n.params));
        } else if (n.kind == NodeKind::Union) {
            // A smooth union lies where some operand's value is below the blend's growth.
            const float g = smoothGrowth(n);
            radial[i] = 0.0;
            for (uint32_t c : n.children) {
                r.box = hull(r.box, reach[c].box);
                radial[i] = std::max(radial[i], radial[c] + g);
                if (g > 0.0f) {
                    const Region blend = grown(reach[c], g);
                    solid[i] = hull(solid[i], clipped(blend.box, blend.spaces));
                } else {
                    solid[i] = hull(solid[i], solid[c]);
                }
            }
            r.box.min -= g, r.box.max += g;
            if (n.children.size() == 1) addSpaces(r, reach[first].spaces);
        } else if (isTransition(n.kind)) {
            // A morph's surface lies where one of its children's does, or between them, and its
            // value is floored at the distance to the box around both (its bounds).
            r.box = n.bounds;
            radial[i] = 0.0;
            for (uint32_t c : n.children) {
                solid[i] = hull(solid[i], solid[c]);
                radial[i] = std::max(radial[i], radial[c]);
            }
        } else if (n.kind == NodeKind::Intersection) {
            // A smooth maximum is never below the sharp one (every blend profile of sdf.glsl
            // adds to the larger operand, never takes from it), so a smooth intersection lies
            // within the sharp one: its blend grows nothing.
            r.box = solid[i] = everywhere;
            for (uint32_t c : n.children) {
                r.box = overlap(r.box, reach[c].box);
                solid[i] = overlap(solid[i], solid[c]);
                radial[i] = std::min(radial[i], radial[c]);
                addSpaces(r, reach[c].spaces);
            }
        } else if (n.kind == NodeKind::Difference) {
            // Within the first operand (a smooth maximum is never below the sharp one), outside
            // every subtracted plane's half-space: minus its value is its slope times the
            // distance from the other side.
            r.box = reach[first].box;
            solid[i] = solid[first];
            radial[i] = radial[first];
            addSpaces(r, reach[first].spaces);
            for (size_t k = 1; k < n.children.size(); ++k) {
                const uint32_t c = n.children[k];
                if (nodes_[c].kind == NodeKind::Plane) {
                    const HalfSpace h = reach[c].spaces[0];
                    addSpaces(r, {{-h.normal, -h.offset, h.slope}});
                }
                // A box turned by right angles at most fills its bounds: where it spans the
                // first operand's box across two axes, it cuts that box along the third.
                if (nodes_[c].kind != NodeKind::Box || !axisAligned(acc[c].toWorld)) continue;
                const Aabb& cut = nodes_[c].bounds;
                Aabb& box = solid[i];
                for (int a = 0; a < 3; ++a) {
                    const int b = (a + 1) % 3, d = (a + 2) % 3;
                    if (!(cut.min[b] <= box.min[b] && cut.max[b] >= box.max[b] &&
                          cut.min[d] <= box.min[d] && cut.max[d] >= box.max[d]))
                        continue;
                    if (cut.min[a] <= box.min[a]) box.min[a] = std::max(box.min[a], cut.max[a]);
                    if (cut.max[a] >= box.max[a]) box.max[a] = std::min(box.max[a], cut.min[a]);
                }
            }
        } else if (info.role == Role::Value) {
            // An offset's or a shell's value is its child's less a distance; an offset inwards
            // lies within its child.
            const float by = n.params[0];
            const Aabb& child = solid[first];
            if (normalises(n) && child.finite() && !child.empty()) {
                // A normalising offset or shell floors its value at its bounds' distance, as
                // domain operations do, with bounds from the box its child's solid lies in, not
                // from the child's bounds, which the stretching operations below it have grown
                // (pass 2): beyond those, its child's value is the distance to a box, a bound
                // with a gradient of length 1, which the division would take for a distance.
                // Its surface lies near its distance from its child's
                // (tests/unit/test_offsets.cpp), within these bounds.
                const float amount = n.kind == NodeKind::Offset ? std::max(by, 0.0f) : by;
                const float grow = 1.05f * amount + 4.0f * n.params[1];
                nodes_[i].bounds = overlap(n.bounds, Aabb{child.min - grow, child.max + grow});
            }
            if (n.kind == NodeKind::Offset && by <= 0.0f) {
                r = reach[first];
                solid[i] = solid[first];
                radial[i] = radial[first];
            } else {
                r = grown(reach[first], by);
                solid[i] = r.box;
                radial[i] = radial[first] + by;
            }
        } else {
            // A domain operation's value is floored at its bounds' distance; its solid is its
            // child's carried through it.
            r.box = solid[i] = n.bounds;
            const Aabb& child = solid[first];
            if (child.empty()) {
                solid[i] = Aabb{};
            } else if (child.finite()) {
                glm::vec3 lo, hi;
                info.boundsAround(n.params, child.min, child.max, lo, hi);
                // Turning about the y axis keeps the distance from it; a polar repetition moves
                // its child out by its radius first.
                double turned = INFINITY;
                if (n.kind == NodeKind::Twist) turned = radial[first];
                if (n.kind == NodeKind::PolarRepeat)
                    turned = std::abs(double(n.params[1])) + radial[first];
                if (std::isfinite(turned)) {
                    const float t = std::nextafter(float(turned), INFINITY);
                    lo.x = std::max(lo.x, -t), lo.z = std::max(lo.z, -t);
                    hi.x = std::min(hi.x, t), hi.z = std::min(hi.z, t);
                    radial[i] = frameRadius(i, turned);
                }
                solid[i] = toFrame(i, lo, hi);
            }
        }
        r.box = overlap(r.box, n.bounds);
        solid[i] = overlap(solid[i], r.box);
        radial[i] = std::min(radial[i], boxRadius(solid[i]));
        // The half-spaces that an enclosing intersection, difference, one-operand union or
        // inward offset takes on clip there, with the rest of its own.
        const uint32_t up = parent[i];
        const bool carried =
            up != UINT32_MAX &&
            (nodes_[up].kind == NodeKind::Intersection ||
             (nodes_[up].kind == NodeKind::Difference && nodes_[up].children[0] == i) ||
             (nodes_[up].kind == NodeKind::Union && nodes_[up].children.size() == 1) ||
             (nodes_[up].kind == NodeKind::Offset && nodes_[up].params[0] <= 0.0f));
        if (!carried) solid[i] = clipped(solid[i], r.spaces);
        if (solid[i].empty()) solid[i] = Aabb{};
    }
    if (count) solidBounds_ = solid[0];
}

float Evaluator::distance(glm::vec3 p) const {
    return distance(p, 0);
}

Sample Evaluator::sample(glm::vec3 p) const {
    return sample(p, 0);
}

namespace {

// The node itself, or the outermost domain operation it lies in: the subtree that takes world
// points.
uint32_t worldSubtree(const std::vector<FlatNode>& nodes, uint32_t node) {
    while (nodes[node].frame != kWorldFrame)
        node = nodes[node].frame;
    return node;
}

} // namespace

float Evaluator::distance(glm::vec3 p, uint32_t node) const {
    if (node >= nodes_.size()) return INFINITY; // an empty scene is empty space
    return evaluate<float>(nodes_, worldSubtree(nodes_, node), p, skipping_);
}

Sample Evaluator::sample(glm::vec3 p, uint32_t node) const {
    if (node >= nodes_.size()) return {INFINITY, kDefaultColor};
    glm::vec4 v = evaluate<glm::vec4>(nodes_, worldSubtree(nodes_, node), p, skipping_);
    return {v.w, glm::vec3(v)};
}

float Evaluator::prunedDistance(glm::vec3 p) const {
    if (nodes_.empty()) return INFINITY;
    return detail::prunedField(*this).distance(nodes_, p);
}

Sample Evaluator::prunedSample(glm::vec3 p) const {
    if (nodes_.empty()) return {INFINITY, kDefaultColor};
    return detail::prunedField(*this).sample(nodes_, p);
}

const detail::PrunedField& detail::prunedField(const Evaluator& evaluator) {
    Evaluator::Pruned& pruned = *evaluator.pruned_;
    std::call_once(pruned.once, [&] { pruned.field = pruneField(evaluator); });
    return pruned.field;
}

bool provablyEmpty(const Evaluator& evaluator) {
    const Aabb& bounds = evaluator.bounds();
    if (bounds.empty()) return true;
    if (!bounds.finite()) return false;
    std::vector<Aabb> boxes{bounds}; // coarse to fine: boxes[next] is the next to look at
    for (size_t next = 0; next < boxes.size(); ++next) {
        const Aabb box = boxes[next];
        const glm::vec3 centre = 0.5f * (box.min + box.max), half = 0.5f * (box.max - box.min);
        const float d = evaluator.distance(centre);
        if (!(d >= 0.0f) || next == 4096) return false;
        if (d > glm::length(half)) continue;
        for (int i = 0; i < 8; ++i) {
            const glm::vec3 corner(i & 1 ? centre.x : box.min.x, i & 2 ? centre.y : box.min.y,
                                   i & 4 ? centre.z : box.min.z);
            boxes.push_back(Aabb{corner, corner + half});
        }
    }
    return true;
}

namespace {

// Where the eye lies from a box's centre: a three-quarter view of its largest face, that face's
// normal turned some 35 to 40 degrees off towards the right, the top and the front, so that the
// face is seen open and its two neighbours at a slant; a flat part is never seen edge-on. The
// front (xy) is the largest unless another is a quarter larger; the top (xz) before the side.
glm::vec3 threeQuarter(glm::vec3 size) {
    const float front = size.x * size.y, top = size.x * size.z, side = size.y * size.z;
    glm::vec3 w(0.45f, 0.55f, 0.6f);
    if (top > 1.25f * front && top >= side)
        w.y = 1.0f;
    else if (side > 1.25f * front)
        w.x = 1.0f;
    else
        w.z = 1.0f;
    return glm::normalize(w);
}

} // namespace

Camera frameCamera(const Evaluator& evaluator, float aspect, float fov) {
    Camera camera;
    camera.fov = fov;
    const Aabb box = evaluator.nodes().empty() ? Aabb{glm::vec3(-1.0f), glm::vec3(1.0f)}
                                               : evaluator.finiteBounds();
    const glm::vec3 centre = 0.5f * (box.max + box.min), half = 0.5f * (box.max - box.min);
    const glm::vec3 direction = threeQuarter(glm::max(box.max - box.min, glm::vec3(1e-6f)));
    // The camera's axes as makeRayCamera (sdfcsg/camera.h) makes them.
    const glm::vec3 right = glm::normalize(glm::cross(-direction, camera.up));
    const glm::vec3 up = glm::cross(right, -direction);
    // The nearest eye from which every corner lies within the view, a tenth inside its edges: a
    // corner at v from the centre lies at depth D - v.direction, and needs |v.right| and |v.up|
    // within that depth times the half-angles' tangents.
    const float tanV = 0.9f * std::tan(0.5f * glm::radians(fov));
    const float tanH = tanV * std::max(aspect, 1e-3f);
    // At least as far as frames a ball of radius 1e-3: a solid smaller than that is framed as
    // one, not from a hair's breadth.
    const float halfH = std::atan(std::tan(0.5f * glm::radians(fov)) * std::max(aspect, 1e-3f));
    float distance = 1.1e-3f / std::sin(std::min(0.5f * glm::radians(fov), halfH));
    for (int c = 0; c < 8; ++c) {
        const glm::vec3 v((c & 1 ? 1.0f : -1.0f) * half.x, (c & 2 ? 1.0f : -1.0f) * half.y,
                          (c & 4 ? 1.0f : -1.0f) * half.z);
        const float depth = glm::dot(v, direction);
        distance =
            std::max({distance, depth + std::abs(glm::dot(v, right)) / tanH,
                      depth + std::abs(glm::dot(v, up)) / tanV, depth + 1e-3f * glm::length(half)});
    }
    camera.eye = centre + direction * distance;
    camera.target = centre;
    return camera;
}

} // namespace sdfcsg
