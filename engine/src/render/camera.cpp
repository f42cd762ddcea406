// The ray marcher's rays on the CPU (sdfcsg/camera.h), and the finite bounds that cameras frame.
// shaders/raymarch.glsl and march.comp implement the same formulas; keep the two in step.
#include "render/camera.h"

namespace sdfcsg {

RayCamera makeRayCamera(const Camera& camera, uint32_t width, uint32_t height) {
    RayCamera rc;
    rc.eye = camera.eye;
    rc.forward = glm::normalize(camera.target - camera.eye);
    glm::vec3 up = camera.up;
    if (glm::length(glm::cross(rc.forward, up)) < 1e-6f) // looking straight along up
        up = std::abs(rc.forward.z) < 0.9f ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0);
    rc.right = glm::normalize(glm::cross(rc.forward, up));
    rc.up = glm::cross(rc.right, rc.forward);
    rc.tanHalfFov = std::tan(glm::radians(camera.fov) * 0.5f);
    rc.aspect = float(width) / float(height);
    rc.footprint = 2.0f * rc.tanHalfFov / float(height);
    return rc;
}

glm::vec3 rayDirection(const RayCamera& rc, float x, float y, uint32_t width, uint32_t height) {
    float u = (2.0f * x / float(width) - 1.0f) * rc.tanHalfFov * rc.aspect;
    float v = (1.0f - 2.0f * y / float(height)) * rc.tanHalfFov;
    return glm::normalize(rc.forward + u * rc.right + v * rc.up);
}

// Finer than about half a pixel's footprint is invisible and costs steps.
float hitEpsilon(const RayCamera& rc, float t) {
    return std::max(kMinHitEpsilon, 0.5f * t * rc.footprint);
}

std::optional<float> marchRay(const Evaluator& evaluator, const RayCamera& rc, glm::vec3 dir) {
    const detail::ClipVolume clip = detail::makeClipVolume(evaluator, rc.eye);
    float t, tFar;
    if (!detail::rayInterval(clip, rc.eye, dir, t, tFar)) return std::nullopt;
    // The loop of march() in shaders/march.comp.
    for (uint32_t i = 0; i < SDFCSG_MAX_STEPS && t <= tFar; ++i) {
        float d = evaluator.distance(rc.eye + t * dir);
        if (d < hitEpsilon(rc, t)) return t;
        t += d;
    }
    return std::nullopt;
}

Aabb Evaluator::finiteBounds() const {
    return detail::finiteSceneBounds(*this);
}

} // namespace sdfcsg
