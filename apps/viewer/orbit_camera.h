// The viewer's camera: orbits a target point, pans in the view plane, zooms along the view axis.
#pragma once

#include <sdfcsg/eval.h>
#include <sdfcsg/scene.h>

#include <glm/vec3.hpp>

namespace sdfcsg::viewer {

struct OrbitCamera {
    glm::vec3 target{0.0f};
    float yaw = 0.0f;   // radians about +y; 0 looks from +z towards -z
    float pitch = 0.0f; // radians above the xz plane, within +-kMaxPitch
    float distance = 5.0f;
    float fov = 45.0f; // vertical, degrees
};

// Kept short of the pole so that "up" stays well defined.
inline constexpr float kMaxPitch = 1.55f;
inline constexpr float kMinDistance = 1.0e-3f;

OrbitCamera orbitFromCamera(const Camera& camera);
Camera toCamera(const OrbitCamera& camera);
glm::vec3 eyeOf(const OrbitCamera& camera);

// Turns by the given angles (radians); pitch is clamped.
void orbit(OrbitCamera& camera, float dYaw, float dPitch);
// Moves the target in the view plane by fractions of the viewport height (dx to the right,
// dy downwards, as a mouse moves), so the scene follows the cursor at the target's depth.
void pan(OrbitCamera& camera, float dx, float dy);
// Multiplies the distance to the target (factor < 1 moves closer).
void zoom(OrbitCamera& camera, float factor);
// Keeps the viewing direction and fits the box (finite) in the view: target at its centre and
// its bounding sphere inside both fields of view. aspect = width / height.
void frameBox(OrbitCamera& camera, const Aabb& box, float aspect);

// What F frames: the bounds of nodes()[node] when finite, else the box the solid's finite part
// lies in: a difference within its first operand, whatever it subtracts, and planes left out
// (so a ground plane does not bring in what is cut away elsewhere). node < 0: the solid.
Aabb framedBounds(const Evaluator& evaluator, int node);

} // namespace sdfcsg::viewer
