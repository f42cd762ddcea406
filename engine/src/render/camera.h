// Ray clipping shared by the renderer (which uploads these values), marchRay() (camera.cpp) and
// the CPU tests (which trace the same rays). shaders/raymarch.glsl and march.comp implement the
// same formulas; keep the two in step.
#pragma once

#include "sdfcsg/camera.h"
#include "sdfcsg/eval.h"
#include "sdfcsg/scene.h"
#include "shared.h"

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace sdfcsg::detail {

// The camera's formulas are public (sdfcsg/camera.h, defined in camera.cpp); the renderer and
// the tests name them here as before.
using sdfcsg::hitEpsilon;
using sdfcsg::kMinHitEpsilon;
using sdfcsg::makeRayCamera;
using sdfcsg::RayCamera;
using sdfcsg::rayDirection;

// A region that holds surfaces: a box, or the half-space dot(p, normal) < offset of a plane.
struct SurfacePart {
    bool halfSpace = false;
    Aabb box;
    glm::vec3 normal{0.0f};
    float offset = 0.0f;
};

// Regions that together hold every surface of the scene, at most SDFCSG_MAX_CLIP_BOXES: when the
// root is a sharp union, the boxes of its finite operands (neighbours in the file grouped
// together when there are more) and the half-spaces of its planes; else none (the clip volume
// alone). A ray starts at its first entry into any of them and ends at its last exit, so rays
// that pass between the parts, or above a ground plane, cost no steps.
inline std::vector<SurfacePart> surfaceParts(const Evaluator& evaluator) {
    const FlatNode& root = evaluator.nodes()[0];
    if (root.kind != NodeKind::Union || root.smooth > 0.0f) return {};
    std::vector<SurfacePart> planes;
    std::vector<const Aabb*> finite;
    for (uint32_t child : root.children) {
        const FlatNode& node = evaluator.nodes()[child];
        if (node.bounds.finite()) {
            finite.push_back(&node.bounds);
        } else if (node.kind == NodeKind::Plane) {
            // local = toLocal * p + offset and the solid is dot(local, n) < k3.
            glm::vec3 n(node.params[0], node.params[1], node.params[2]);
            SurfacePart part;
            part.halfSpace = true;
            part.normal = glm::transpose(node.toLocal) * n;
            part.offset = node.params[3] - glm::dot(node.offset, n);
            planes.push_back(part);
        } else {
            return {};
        }
    }
    if (planes.size() >= SDFCSG_MAX_CLIP_BOXES || (finite.empty() && planes.empty())) return {};
    const size_t groups = std::min(finite.size(), SDFCSG_MAX_CLIP_BOXES - planes.size());
    std::vector<SurfacePart> parts(groups);
    for (size_t i = 0; i < finite.size(); ++i) {
        Aabb& g = parts[i * groups / finite.size()].box;
        g.min = glm::min(g.min, finite[i]->min);
        g.max = glm::max(g.max, finite[i]->max);
    }
    parts.insert(parts.end(), planes.begin(), planes.end());
    return parts;
}

// The part of space rays are traced in: the scene's bounds, cut to a cube around the eye whose
// half size is the far distance (planes make bounds infinite), and within it the boxes that hold
// the surfaces.
struct ClipVolume {
    Aabb box;
    float far;                      // no ray goes beyond this t
    std::vector<SurfacePart> parts; // surfaceParts(); empty: the box alone
};

// Bounds of the finite primitives: what a camera looks at and what "far" is measured against.
inline Aabb finitePrimitiveBounds(const Evaluator& evaluator) {
    Aabb box;
    for (const FlatNode& node : evaluator.nodes()) {
        // A 2D profile's own box is a prism of the xy plane: the solid is the box of the extrude
        // or revolve that holds it.
        const bool solid = kindInfo(node.kind).operation
                               ? node.kind == NodeKind::Extrude || node.kind == NodeKind::Revolve
                               : !isProfile(node.kind);
        if (!solid || !node.bounds.finite() || node.bounds.empty()) continue;
        box.min = glm::min(box.min, node.bounds.min);
        box.max = glm::max(box.max, node.bounds.max);
    }
    if (box.empty()) box = Aabb{glm::vec3(-1.0f), glm::vec3(1.0f)};
    return box;
}

// Evaluator::finiteBounds() (sdfcsg/eval.h), here for the renderer and the mesher.
inline Aabb finiteSceneBounds(const Evaluator& evaluator) {
    const Aabb root = evaluator.solidBounds();
    const Aabb parts = finitePrimitiveBounds(evaluator);
    Aabb box;
    for (int a = 0; a < 3; ++a) {
        box.min[a] = std::isfinite(root.min[a]) ? root.min[a] : parts.min[a];
        box.max[a] = std::isfinite(root.max[a]) ? root.max[a] : parts.max[a];
        if (!(box.min[a] < box.max[a])) return parts; // an empty solid: frame its parts
    }
    return box;
}

inline ClipVolume makeClipVolume(const Evaluator& evaluator, glm::vec3 eye) {
    Aabb finite = finitePrimitiveBounds(evaluator);
    glm::vec3 centre = 0.5f * (finite.min + finite.max);
    float radius = 0.5f * glm::length(finite.max - finite.min);
    ClipVolume clip;
    clip.far = std::max(4.0f * (glm::length(eye - centre) + radius), 20.0f);
    clip.box = evaluator.bounds();
    clip.box.min = glm::max(clip.box.min, eye - glm::vec3(clip.far));
    clip.box.max = glm::min(clip.box.max, eye + glm::vec3(clip.far));
    clip.parts = surfaceParts(evaluator);
    return clip;
}

// Slab test; returns false when the ray misses. tNear is clamped to 0 (eye inside the box).
inline bool clipRay(const Aabb& box, glm::vec3 origin, glm::vec3 dir, float& tNear, float& tFar) {
    glm::vec3 inv;
    for (int i = 0; i < 3; ++i)
        inv[i] = 1.0f / (std::abs(dir[i]) < 1e-20f ? (dir[i] >= 0.0f ? 1e-20f : -1e-20f) : dir[i]);
    glm::vec3 t0 = (box.min - origin) * inv;
    glm::vec3 t1 = (box.max - origin) * inv;
    glm::vec3 lo = glm::min(t0, t1), hi = glm::max(t0, t1);
    tNear = std::max(std::max(lo.x, lo.y), std::max(lo.z, 0.0f));
    tFar = std::min(std::min(hi.x, hi.y), hi.z);
    return tNear <= tFar;
}

// Entry and exit of a ray in a surface part, as partInterval() in shaders/raymarch.glsl.
inline bool partInterval(const SurfacePart& part, glm::vec3 origin, glm::vec3 dir, float& tIn,
                         float& tOut) {
    if (!part.halfSpace) return clipRay(part.box, origin, dir, tIn, tOut);
    float dn = glm::dot(dir, part.normal), on = glm::dot(origin, part.normal);
    float tPlane = (part.offset - on) / (std::abs(dn) < 1e-20f ? 1e-20f : dn);
    if (on < part.offset) {
        tIn = 0.0f, tOut = dn > 0.0f ? tPlane : 1.0e30f;
    } else {
        tIn = dn < 0.0f ? tPlane : 1.0f, tOut = dn < 0.0f ? 1.0e30f : 0.0f;
    }
    return tIn <= tOut;
}

// The interval of a ray that is traced, as march() in shaders/march.comp computes it: inside
// the clip box, from the first entry into a surface box to the last exit. False when empty.
inline bool rayInterval(const ClipVolume& clip, glm::vec3 origin, glm::vec3 dir, float& tNear,
                        float& tFar) {
    clipRay(clip.box, origin, dir, tNear, tFar);
    if (!clip.parts.empty()) {
        float first = 1.0e30f, last = -1.0e30f;
        for (const SurfacePart& part : clip.parts) {
            float a, b;
            if (partInterval(part, origin, dir, a, b))
                first = std::min(first, a), last = std::max(last, b);
        }
        tNear = std::max(tNear, first);
        tFar = std::min(tFar, last);
    }
    tFar = std::min(tFar, clip.far);
    return tNear <= tFar;
}

// A rectangle of the image, in pixels from the top-left corner (x0 <= x < x1, y0 <= y < y1).
struct ScreenRect {
    float x0, y0, x1, y1;
};

// Rectangles of the image outside which no ray can meet a surface: the projections of the
// surface boxes (or of the clip box when there are none), cut to the clip box, a pixel wider on
// every side. Empty when nothing is in view. False when that cannot be bounded (a half-space,
// or a box reaching behind the eye): then every ray must be traced.
inline bool surfaceRects(const RayCamera& rc, const ClipVolume& clip, uint32_t width,
                         uint32_t height, std::vector<ScreenRect>& rects) {
    rects.clear();
    std::vector<Aabb> boxes;
    if (clip.parts.empty()) boxes.push_back(clip.box);
    for (const SurfacePart& part : clip.parts) {
        if (part.halfSpace) return false;
        Aabb b{glm::max(part.box.min, clip.box.min), glm::min(part.box.max, clip.box.max)};
        if (!b.empty()) boxes.push_back(b);
    }
    const float sx = 0.5f * float(width) / (rc.tanHalfFov * rc.aspect);
    const float sy = 0.5f * float(height) / rc.tanHalfFov;
    for (const Aabb& b : boxes) {
        ScreenRect r{1e30f, 1e30f, -1e30f, -1e30f};
        for (int c = 0; c < 8; ++c) {
            glm::vec3 corner((c & 1) ? b.max.x : b.min.x, (c & 2) ? b.max.y : b.min.y,
                             (c & 4) ? b.max.z : b.min.z);
            glm::vec3 v = corner - rc.eye;
            float z = glm::dot(v, rc.forward);
            if (z < 1e-4f * (1.0f + glm::length(v))) return false; // at or behind the eye
            float x = 0.5f * float(width) + sx * glm::dot(v, rc.right) / z;
            float y = 0.5f * float(height) - sy * glm::dot(v, rc.up) / z;
            r = {std::min(r.x0, x), std::min(r.y0, y), std::max(r.x1, x), std::max(r.y1, y)};
        }
        r = {r.x0 - 1.0f, r.y0 - 1.0f, r.x1 + 1.0f, r.y1 + 1.0f};
        if (r.x1 > 0.0f && r.y1 > 0.0f && r.x0 < float(width) && r.y0 < float(height))
            rects.push_back(r);
    }
    return true;
}

} // namespace sdfcsg::detail
