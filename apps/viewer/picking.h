// Selecting a node by clicking in the ray-marched image or the mesh view, and showing the
// selection in the ray-marched image.
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

// Image pixels [x0, x1) x [y0, y1).
struct PixelRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    bool empty() const { return x0 >= x1 || y0 >= y1; }
};

// The pixels a box can cover in a width x height image seen with `camera`: the rectangle
// around its projected corners, cut to the image. The whole image when the box is unbounded
// or reaches behind the eye; empty when it is empty or lies outside the view.
PixelRect projectedRect(const Camera& camera, uint32_t width, uint32_t height, const Aabb& box);

// The pixels whose visible surface belongs to nodes()[node]: hit points (from the depths of a
// render with `camera`) that lie within a few pixel footprints of that subtree's surface. One
// byte per pixel, 1 for selected; rows top to bottom. Only pixels within two of the node's
// projected bounds (projectedRect) are evaluated, so a small node costs little in a large image.
std::vector<uint8_t> selectionMask(const Evaluator& evaluator, uint32_t node, const Camera& camera,
                                   uint32_t width, uint32_t height,
                                   const std::vector<PixelInfo>& pixels);

// Tints the masked pixels and draws a one-pixel outline around them (an image of the mask's size).
void drawHighlight(Image& image, const std::vector<uint8_t>& mask);

} // namespace sdfcsg::viewer
