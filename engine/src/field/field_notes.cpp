// Where a scene's field stops being a distance, and which operations depend on it being one
// (sdfcsg/eval.h, fieldNotes); and the mesh nodes whose files needed repair. Offsets, shells and
// smooth blends act on the field's values: over a field whose values lie below the distance by up
// to a factor L, an offset r would land between r and L r from the child's surface and a shell of
// thickness t be t to L t thick, but for their division by the field's gradient (FlatNode::loss),
// which brings them near r and t to first order; a blend of radius k reaches up to L k.
#include "sdfcsg/eval.h"
#include "sdfcsg/nodes.h"

#include "field/bake.h"
#include "field/mesh_field.h"
#include "field/sdf.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace sdfcsg {
namespace {

// Where a subtree's field stops being a distance: the cause with the largest factor.
struct Loss {
    bool any = false;
    float factor = 0.0f; // values down to distance / factor; 0 where unknown (a blend)
    std::string cause;   // "twist at root.children[0] divides its field by up to 1.41"
};

std::string number(float x) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", double(x));
    return text;
}

// The node's "smooth" parameter (Booleans and mirror), or 0.
float smoothOf(const Node& n) {
    for (const ParamInfo& p : kindInfo(n.kind).params)
        if (p.name == "smooth") return n.params[p.slot];
    return 0.0f;
}

// What the node itself does to the distance, besides its children.
Loss ownLoss(const Node& n, const FlatNode& flat) {
    const std::string at = std::string(kindInfo(n.kind).name) + " at " + n.path;
    float factor = 1.0f;
    std::string how;
    if (n.kind == NodeKind::Twist || n.kind == NodeKind::Bend || n.kind == NodeKind::Taper) {
        factor = flat.params[7] > 0.0f ? 1.0f / flat.params[7] : 1.0f;
        how = " divides its field by up to ";
    } else if (n.kind == NodeKind::BendLinear) {
        const auto& k = flat.params;
        factor = sdf::bendLinearStretch({k[0], k[1], k[2], k[3]}, {k[4], k[5], k[6], k[7]});
        how = " divides its field by ";
    } else if (isTransition(n.kind)) {
        factor = flat.params[7] > 0.0f ? 1.0f / flat.params[7] : 1.0f;
        how = " divides its field by ";
    } else if (n.kind == NodeKind::Heightmap) {
        factor = flat.params[7] > 0.0f ? 1.0f / flat.params[7] : 1.0f;
        how = ": a bound (its slopes' Lipschitz bound), below the distance by up to ";
    } else if (n.kind == NodeKind::Ellipsoid) {
        const float lo = std::min({n.params[0], n.params[1], n.params[2]});
        const float hi = std::max({n.params[0], n.params[1], n.params[2]});
        factor = hi / lo;
        how = ": a bound, below the distance by up to ";
    }
    const glm::vec3 s = n.transform.scale;
    const float stretch = std::max({s.x, s.y, s.z}) / std::min({s.x, s.y, s.z});
    if (stretch > factor) {
        factor = stretch;
        how = ", scaled unevenly: its field below the distance by up to ";
    }
    if (factor > 1.001f) return {true, factor, at + how + number(factor)};
    if (smoothOf(n) > 0.0f)
        return {true, 0.0f,
                "smooth blend at " + n.path + ": no distance within " + number(smoothOf(n)) +
                    " of its seam"};
    return {};
}

// From what loss on the renderer's shading shows it (fieldNotes): the knurled knob's twist,
// 1.51, darkens nothing visibly.
constexpr float kShadingNoteLoss = 2.0f;

bool worse(const Loss& a, const Loss& b) { // a weighs more than b
    return a.any && (!b.any || a.factor > b.factor);
}

// The note of a dependent node over a child field with `loss`.
std::string noteOf(const Node& n, const Loss& loss) {
    const std::string kind =
        (smoothOf(n) > 0.0f ? "smooth " : "") + std::string(kindInfo(n.kind).name);
    const float factor = loss.factor;
    std::string effect;
    // Offsets and shells divide by the field's gradient (FlatNode::loss) where their child's
    // distance could not be baked (field/bake.h): a first-order distance, which strays where the
    // stretch changes within their reach.
    const std::string divides =
        n.params[detail::kAccuracySlot] != detail::kAccuracyExact
            ? "divided by the field's gradient, to first order; \"accuracy\": \"exact\" bakes "
              "the child's distance; "
            : "divided by the field's gradient, to first order, not baked: at a quarter of the "
              "distance its field would exceed " +
                  std::to_string(detail::kMaxBakeBytes >> 20) +
                  " MiB, or its child is unbounded or of more than " +
                  std::to_string(detail::kMaxBakedNodes) + " nodes; ";
    if (n.kind == NodeKind::Offset) {
        const float r = std::abs(n.params[0]);
        effect = "the surface lies about " + number(r) + " from the child's (" + divides +
                 (factor > 0.0f ? number(r) + " to " + number(r * factor) + " without)"
                                : "not " + number(r) + " within the blend)");
    } else if (n.kind == NodeKind::Shell) {
        const float t = n.params[0];
        effect = "the skin is about " + number(t) + " thick (" + divides +
                 (factor > 0.0f ? number(t) + " to " + number(t * factor) + " without)"
                                : "not " + number(t) + " within the blend)");
    } else {
        const float k = smoothOf(n);
        effect = factor > 0.0f
                     ? "the blend reaches up to " + number(k * factor) + " instead of " + number(k)
                     : "the blend there does not reach " + number(k);
    }
    return kind + " over a field that is not a distance (" + loss.cause + "): " + effect;
}

// "3 open edges" and the like, the nouns in the singular and the plural.
std::string counted(size_t n, const std::string& one, const std::string& many,
                    const std::string& rest) {
    return std::to_string(n) + " " + (n == 1 ? one : many) + rest;
}

// A mesh node whose file is not a closed, consistently oriented surface (detail::MeshDefects):
// what was found, and where its inside comes from instead. Empty for a clean mesh.
std::string meshNote(const Node& n) {
    if (!n.words) return {};
    const detail::MeshDefects d = detail::storedDefects(*n.words);
    std::vector<std::string> found;
    if (d.openEdges) found.push_back(counted(d.openEdges, "open edge", "open edges", ""));
    if (d.crowdedEdges)
        found.push_back(counted(d.crowdedEdges, "edge", "edges", " of three or more triangles"));
    if (d.flippedEdges)
        found.push_back(counted(d.flippedEdges, "edge", "edges",
                                " between triangles wound opposite ways (flipped triangles)"));
    if (d.degenerate)
        found.push_back(counted(d.degenerate, "triangle", "triangles", " of no area"));
    if (found.empty()) return {};
    std::string list;
    for (size_t i = 0; i < found.size(); ++i)
        list += (i == 0 ? "" : ", ") + found[i];
    return "mesh \"" + n.strings[0] + "\" is not closed and consistently oriented: " + list +
           "; its inside comes from the generalised winding number, which fills holes and "
           "outvotes flipped triangles";
}

} // namespace

std::vector<FieldNote> fieldNotes(const Scene& scene, const Evaluator& evaluator) {
    const size_t count = std::min(scene.nodes.size(), evaluator.nodes().size());
    std::vector<Loss> losses(count); // each subtree's, children first
    std::vector<FieldNote> notes;
    for (size_t i = count; i-- > 0;) {
        const Node& n = scene.nodes[i];
        Loss loss;
        for (uint32_t c : n.children)
            if (c < count && worse(losses[c], loss)) loss = losses[c];
        const bool dependent =
            n.kind == NodeKind::Offset || n.kind == NodeKind::Shell || smoothOf(n) > 0.0f;
        // A baked offset or shell reads its child's distance (field/bake.h): nothing to note.
        if (dependent && loss.any && !detail::baked(n)) notes.push_back({n.path, noteOf(n, loss)});
        // A mesh in a definition used more than once: one note for its one path.
        if (n.kind == NodeKind::Mesh)
            if (std::string note = meshNote(n);
                !note.empty() && std::none_of(notes.begin(), notes.end(), [&](const FieldNote& f) {
                    return f.path == n.path && f.message == note;
                }))
                notes.push_back({n.path, note});
        const Loss own = ownLoss(n, evaluator.nodes()[i]);
        if (worse(own, loss) || (own.any && !loss.any)) loss = own;
        if (detail::baked(n)) loss = own; // a distance again, but for its own scale
        losses[i] = loss;
    }
    std::reverse(notes.begin(), notes.end()); // in the file's order
    // Ambient occlusion and soft shadows compare the field's values along rays with the
    // distances travelled (shaders/shade.comp): values below the distance read as nearby
    // surfaces. A blend's seam is too narrow to show; a factor from kShadingNoteLoss on does.
    if (count > 0 && losses[0].factor >= kShadingNoteLoss)
        notes.push_back(
            {scene.nodes[0].path,
             "ambient occlusion and soft shadows over a field that is not a distance (" +
                 losses[0].cause +
                 "): the shading can be darker where its values lie "
                 "below the distance (down to 1/" +
                 number(losses[0].factor) + " of it); --no-ao and --no-shadows leave them out"});
    return notes;
}

} // namespace sdfcsg
