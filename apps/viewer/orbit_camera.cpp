#include "orbit_camera.h"

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sdfcsg::viewer {

namespace {

glm::vec3 backward(const OrbitCamera& c) { // from the target towards the eye
    return {std::cos(c.pitch) * std::sin(c.yaw), std::sin(c.pitch),
            std::cos(c.pitch) * std::cos(c.yaw)};
}

} // namespace

OrbitCamera orbitFromCamera(const Camera& camera) {
    OrbitCamera c;
    c.target = camera.target;
    c.fov = camera.fov;
    glm::vec3 offset = camera.eye - camera.target;
    c.distance = std::max(glm::length(offset), kMinDistance);
    glm::vec3 dir = offset / c.distance;
    c.pitch = std::clamp(std::asin(std::clamp(dir.y, -1.0f, 1.0f)), -kMaxPitch, kMaxPitch);
    c.yaw = std::atan2(dir.x, dir.z);
    return c;
}

glm::vec3 eyeOf(const OrbitCamera& camera) {
    return camera.target + camera.distance * backward(camera);
}

Camera toCamera(const OrbitCamera& camera) {
    Camera c;
    c.eye = eyeOf(camera);
    c.target = camera.target;
    c.up = {0.0f, 1.0f, 0.0f};
    c.fov = camera.fov;
    return c;
}

void orbit(OrbitCamera& camera, float dYaw, float dPitch) {
    camera.yaw = std::remainder(camera.yaw + dYaw, 2.0f * std::numbers::pi_v<float>);
    camera.pitch = std::clamp(camera.pitch + dPitch, -kMaxPitch, kMaxPitch);
}

void pan(OrbitCamera& camera, float dx, float dy) {
    glm::vec3 forward = -backward(camera);
    glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0.0f, 1.0f, 0.0f)));
    glm::vec3 up = glm::cross(right, forward);
    float visible = 2.0f * camera.distance * std::tan(glm::radians(camera.fov) * 0.5f);
    camera.target += (-dx * right + dy * up) * visible;
}

void zoom(OrbitCamera& camera, float factor) {
    camera.distance = std::max(camera.distance * factor, kMinDistance);
}

void frameBox(OrbitCamera& camera, const Aabb& box, float aspect) {
    if (box.empty() || !box.finite()) return;
    camera.target = 0.5f * (box.min + box.max);
    float radius = std::max(0.5f * glm::length(box.max - box.min), 1.0e-3f);
    float halfY = glm::radians(camera.fov) * 0.5f;
    float halfX = std::atan(std::tan(halfY) * aspect);
    camera.distance = 1.05f * radius / std::sin(std::min(halfX, halfY));
}

namespace {

// A node's bounds with unbounded primitives (planes) left out: finite bounds as they are, else
// a union of its operands', of the first operand's alone for a difference. (Parsed scenes are
// depth-capped, so the recursion is bounded.)
Aabb finitePart(const Evaluator& evaluator, uint32_t node) {
    const FlatNode& n = evaluator.nodes()[node];
    if (n.bounds.empty() || n.bounds.finite() || n.children.empty()) {
        return n.bounds.finite() ? n.bounds : Aabb{};
    }
    if (n.kind == NodeKind::Difference) return finitePart(evaluator, n.children[0]);
    Aabb box;
    for (uint32_t c : n.children) {
        Aabb part = finitePart(evaluator, c);
        if (part.empty()) continue;
        box.min = glm::min(box.min, part.min), box.max = glm::max(box.max, part.max);
    }
    return box;
}

} // namespace

Aabb framedBounds(const Evaluator& evaluator, int node) {
    if (node >= 0 && node < int(evaluator.nodes().size())) {
        const Aabb& box = evaluator.nodes()[node].bounds;
        if (!box.empty() && box.finite()) return box;
    }
    if (evaluator.nodes().empty()) return evaluator.finiteBounds();
    Aabb box = finitePart(evaluator, 0);
    return box.empty() ? evaluator.finiteBounds() : box;
}

} // namespace sdfcsg::viewer
