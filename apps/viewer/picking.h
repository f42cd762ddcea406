// Selecting a node by clicking in the ray-marched image or the mesh view.
#pragma once

#include <sdfcsg/eval.h>
#include <sdfcsg/render.h>

#include <glm/vec3.hpp>

#include <cstdint>
#include <optional>
#include <vector>

namespace sdfcsg::viewer {

// The surface point seen through image point (x, y) (pixels from the top-left corner of a
// width x height image rendered with `camera`), from the depths of that render; nullopt where
// the ray missed or (x, y) lies outside the image.
std::optional<glm::vec3> pickPoint(const Camera& camera, uint32_t width, uint32_t height,
                                   const std::vector<PixelInfo>& pixels, float x, float y);

// The surface point seen through image point (x, y) of a width x height view with `camera`,
// found by tracing the ray on the CPU as the ray marcher traces it: for views without depths
// from the engine (the mesh view, which shares the ray marcher's camera). nullopt where the ray
// misses or (x, y) lies outside the image.
std::optional<glm::vec3> castRay(const Evaluator& evaluator, const Camera& camera, uint32_t width,
                                 uint32_t height, float x, float y);

// The primitive whose own surface lies nearest to p (smallest |distance|), or -1 when the scene
// has none. A point on a carved face picks the primitive that carved it.
int nearestPrimitive(const Evaluator& evaluator, glm::vec3 p);

} // namespace sdfcsg::viewer
