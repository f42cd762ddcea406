#include "picking.h"

#include "camera.h" // the renderer's own ray formulas, so picks match the pixels

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
    detail::RayCamera rc = detail::makeRayCamera(camera, width, height);
    // The depth belongs to the ray through the pixel's centre (the first sample).
    glm::vec3 dir = detail::rayDirection(rc, float(i) + 0.5f, float(j) + 0.5f, width, height);
    return rc.eye + t * dir;
}

std::optional<glm::vec3> castRay(const Evaluator& evaluator, const Camera& camera, uint32_t width,
                                 uint32_t height, float x, float y) {
    if (x < 0.0f || y < 0.0f || x >= float(width) || y >= float(height)) return std::nullopt;
    detail::RayCamera rc = detail::makeRayCamera(camera, width, height);
    glm::vec3 dir = detail::rayDirection(rc, x, y, width, height);
    const detail::ClipVolume clip = detail::makeClipVolume(evaluator, rc.eye);
    float t, tFar;
    if (!detail::rayInterval(clip, rc.eye, dir, t, tFar)) return std::nullopt;
    // The loop of march() in shaders/raymarch.comp.
    for (uint32_t i = 0; i < SDFCSG_MAX_STEPS && t <= tFar; ++i) {
        float d = evaluator.distance(rc.eye + t * dir);
        if (d < detail::hitEpsilon(rc, t)) return rc.eye + t * dir;
        t += d;
    }
    return std::nullopt;
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

} // namespace sdfcsg::viewer
