// The outlines of polygon and text nodes, as shaders/sdf.glsl's sdOutline reads them: per
// closed contour a box and a range of segments, then the segments, the lines of a contour
// before its quadratics (split where they turn in y, so that each crosses a horizontal line at
// most once).
#pragma once

#include "font.h"
#include "sdfcsg/error.h"
#include "sdfcsg/scene.h"

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include <span>
#include <string>
#include <vector>

namespace sdfcsg::detail {

// Segments of closed contours one after another (a contour ends where the next segment does not
// start at its end), moved by `shift`.
std::vector<glm::vec4> packOutline(std::span<const GlyphSegment> segments, glm::vec2 shift);

// Why the polygon is not simple (two edges that cross or touch, a repeated point), or "".
std::string polygonProblem(std::span<const glm::vec2> points);

// The node's outline: a polygon's edges, or a text's glyphs centred on the origin. Errors are
// the font's (font.h), for the caller to place at the node.
Result<std::shared_ptr<const std::vector<glm::vec4>>> buildOutline(const Node& node);

} // namespace sdfcsg::detail
