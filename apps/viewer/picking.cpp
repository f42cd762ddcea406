#include "picking.h"

#include <sdfcsg/camera.h> // the renderer's own ray formulas, so picks match the pixels

#include <algorithm>
#include <cmath>
#include <limits>

namespace sdfcsg::viewer {

std::optional<glm::vec3> pickPoint(const Camera& camera, uint32_t width, uint32_t height,
                                   const std::vector<PixelInfo>& pixels, float x, float y) {
    if (x < 0.0f || y < 0.0f || x >= float(width) || y >= float(height) ||
        pixels.size() != size_t(width) * height)
        return std::nullopt;
    uint32_t i = uint32_t(x), j = uint32_t(y);
    float t = pixels[size_t(j) * width + i].depth;
    if (!(t >= 0.0f)) return std::nullopt;
    RayCamera rc = makeRayCamera(camera, width, height);
    // The depth belongs to the ray through the pixel's centre (the first sample).
    glm::vec3 dir = rayDirection(rc, float(i) + 0.5f, float(j) + 0.5f, width, height);
    return rc.eye + t * dir;
}

std::optional<glm::vec3> castRay(const Evaluator& evaluator, const Camera& camera, uint32_t width,
                                 uint32_t height, float x, float y) {
    if (x < 0.0f || y < 0.0f || x >= float(width) || y >= float(height)) return std::nullopt;
    const RayCamera rc = makeRayCamera(camera, width, height);
    const glm::vec3 dir = rayDirection(rc, x, y, width, height);
    const std::optional<float> t = marchRay(evaluator, rc, dir);
    if (!t) return std::nullopt;
    return rc.eye + *t * dir;
}

int nearestPrimitive(const Evaluator& evaluator, glm::vec3 p) {
    int best = -1;
    float bestDistance = std::numeric_limits<float>::infinity();
    const auto& nodes = evaluator.nodes();
    for (uint32_t i = 0; i < nodes.size(); ++i) {
        if (kindInfo(nodes[i].kind).operation) continue;
        float d = std::abs(evaluator.distance(p, i));
        if (d < bestDistance) bestDistance = d, best = int(i);
    }
    return best;
}

PixelRect projectedRect(const Camera& camera, uint32_t width, uint32_t height, const Aabb& box) {
    const PixelRect whole{0, 0, int(width), int(height)};
    if (box.empty()) return {};
    if (!box.finite()) return whole;
    // The inverse of rayDirection(): a point's offsets along right and up over its depth.
    RayCamera rc = makeRayCamera(camera, width, height);
    float x0 = std::numeric_limits<float>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
    for (int corner = 0; corner < 8; ++corner) {
        glm::vec3 p(corner & 1 ? box.max.x : box.min.x, corner & 2 ? box.max.y : box.min.y,
                    corner & 4 ? box.max.z : box.min.z);
        glm::vec3 d = p - rc.eye;
        float z = glm::dot(d, rc.forward);
        if (z <= 1e-6f) return whole; // a corner behind the eye projects nowhere sensible
        float u = glm::dot(d, rc.right) / (z * rc.tanHalfFov * rc.aspect);
        float v = glm::dot(d, rc.up) / (z * rc.tanHalfFov);
        float x = (u + 1.0f) * 0.5f * float(width), y = (1.0f - v) * 0.5f * float(height);
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
    PixelRect r;
    r.x0 = int(std::clamp(std::floor(x0), 0.0f, float(width)));
    r.y0 = int(std::clamp(std::floor(y0), 0.0f, float(height)));
    r.x1 = int(std::clamp(std::ceil(x1), 0.0f, float(width)));
    r.y1 = int(std::clamp(std::ceil(y1), 0.0f, float(height)));
    return r.empty() ? PixelRect{} : r;
}

std::vector<uint8_t> selectionMask(const Evaluator& evaluator, uint32_t node, const Camera& camera,
                                   uint32_t width, uint32_t height,
                                   const std::vector<PixelInfo>& pixels) {
    std::vector<uint8_t> mask(size_t(width) * height, 0);
    if (node >= evaluator.nodes().size() || pixels.size() != mask.size()) return mask;
    // Points within the tolerance below of the bounds project within two pixels of them.
    PixelRect r = projectedRect(camera, width, height, evaluator.nodes()[node].bounds);
    if (r.empty()) return mask;
    r.x0 = std::max(r.x0 - 2, 0), r.y0 = std::max(r.y0 - 2, 0);
    r.x1 = std::min(r.x1 + 2, int(width)), r.y1 = std::min(r.y1 + 2, int(height));
    RayCamera rc = makeRayCamera(camera, width, height);
    for (int j = r.y0; j < r.y1; ++j)
        for (int i = r.x0; i < r.x1; ++i) {
            const size_t k = size_t(j) * width + size_t(i);
            const float t = pixels[k].depth;
            if (!(t >= 0.0f)) continue;
            glm::vec3 dir = rayDirection(rc, float(i) + 0.5f, float(j) + 0.5f, width, height);
            // The march stops within half a footprint of the scene's surface; the node's own
            // surface is that one where it shows, and farther where another node's shows, except
            // within a pixel or two of where the two meet.
            const float tolerance = std::max(2.0f * t * rc.footprint, 4.0f * kMinHitEpsilon);
            if (std::abs(evaluator.distance(rc.eye + t * dir, node)) <= tolerance) mask[k] = 1;
        }
    return mask;
}

void drawHighlight(Image& image, const std::vector<uint8_t>& mask) {
    const int w = int(image.width), h = int(image.height);
    if (mask.size() != size_t(w) * size_t(h) || image.rgba.size() != mask.size() * 4) return;
    const uint8_t colour[3] = {255, 170, 40};
    auto at = [&](int x, int y) {
        return x >= 0 && y >= 0 && x < w && y < h && mask[size_t(y) * w + x];
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            // The outline is drawn just outside the mask, so the tinted surface keeps its shading.
            const bool inside = at(x, y);
            const bool edge =
                !inside && (at(x - 1, y) || at(x + 1, y) || at(x, y - 1) || at(x, y + 1));
            if (!inside && !edge) continue;
            uint8_t* p = &image.rgba[(size_t(y) * w + x) * 4];
            for (int c = 0; c < 3; ++c)
                p[c] = edge ? colour[c] : uint8_t((int(p[c]) * 3 + int(colour[c]) * 2) / 5);
        }
}

} // namespace sdfcsg::viewer
