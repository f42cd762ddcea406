// sdfcsg: the ray marcher's rays, made and traced on the CPU, for hosts that work in step with
// its images: a click on a pixel, a view drawn with the same camera, a test that traces what the
// GPU traced.
//
// Renderer::render makes its rays with exactly these formulas (shaders/raymarch.glsl and
// shaders/march.comp hold the GPU's copies), so a point found here lies under the pixel that
// shows it. Pixel coordinates run from the top-left corner of a width x height image; the centre
// of pixel (i, j) is (i + 0.5, j + 0.5).
#pragma once

#include "sdfcsg/scene.h"

#include <glm/vec3.hpp>

#include <cstdint>
#include <optional>

namespace sdfcsg {

class Evaluator;

// The smallest distance at which a ray counts as having hit the surface, in scene units;
// farther from the eye it grows with the pixel footprint (hitEpsilon()).
inline constexpr float kMinHitEpsilon = 1.0e-4f;

// A Camera set up for an image of a given size.
struct RayCamera {
    glm::vec3 eye;
    glm::vec3 right, up, forward; // orthonormal, right-handed: forward = -z of the view
    float tanHalfFov;             // tangent of half the vertical field of view
    float aspect;                 // width / height
    float footprint;              // width of one pixel at unit distance (2 tanHalfFov / height)
};

// `camera` for a width x height image. Where camera.up is parallel to the view direction, another
// up is chosen (z, or x when looking along z).
RayCamera makeRayCamera(const Camera& camera, uint32_t width, uint32_t height);

// The unit direction of the ray through image point (x, y), in pixels.
glm::vec3 rayDirection(const RayCamera& rc, float x, float y, uint32_t width, uint32_t height);

// How close to the surface a ray must come at ray parameter t to hit it: about half a pixel's
// footprint there, and at least kMinHitEpsilon. (With RenderOptions::aa, the renderer divides
// the footprint by aa.)
float hitEpsilon(const RayCamera& rc, float t);

// Traces the ray from rc.eye along `dir` (a unit vector, say from rayDirection()) through the
// field of `evaluator` as the ray marcher traces it with one sample per pixel: over the same
// part of the ray (the scene's bounds cut to a distance from the eye, and within them the boxes
// that hold surfaces), in steps of the distance, until it comes within hitEpsilon() of the
// surface or has taken the kernel's step limit (256 steps). Returns the ray parameter t of the
// hit (the point is rc.eye + t * dir), or nullopt where the ray misses. Costs one
// evaluator.distance() call per step.
std::optional<float> marchRay(const Evaluator& evaluator, const RayCamera& rc, glm::vec3 dir);

} // namespace sdfcsg
