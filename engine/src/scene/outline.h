// The outlines of polygon and text nodes, as shaders/sdf.glsl's sdOutline reads them. Segments
// are lines and quadratics, split where they turn in y (and, in a grid, in x too), so that each
// crosses a horizontal (and a vertical) line at most once. Word 0 tells the layout, word 1 holds
// the outline's box (lo xy, hi xy); the two give the node's kernel parameters (eval.cpp).
//
// A small outline (at most kGridOutlineWords) is listed by contour, for a loop over all of it or,
// at most kInlinedOutlineWords, for code that writes it out (codegen.cpp): word 0 is (0, contours,
// 0, 0); from word 2, per contour its box and (first segment from word 2, lines, -, quadratics),
// then its lines, a word each (a, b), then its quadratics, two each ((a, b), (c, -)).
//
// A larger one is listed per cell of a grid over its box and two cells around it, each cell with
// the segments that can be the nearest anywhere in it (a point's work is its cell's few
// segments) and the winding at its centre: word 0 is (cells per row, rows, cell side,
// segments); from word 2 a record per cell, row by row: (first word of its list, lines,
// quadratics, winding at its centre); then the lists, lines and quadratics as above.
#pragma once

#include "scene/font.h"
#include "sdfcsg/error.h"
#include "sdfcsg/scene.h"

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include <span>
#include <string>
#include <vector>

namespace sdfcsg::detail {

// Outlines of more words than this get a grid; the most cells of a grid, and the most words of
// its lists per segment (past them, a coarser grid).
inline constexpr size_t kGridOutlineWords = 256;
// Outlines of at most this many words (header included) are written into inlined kernels as
// code (codegen.cpp); larger ones are read from the node buffer in every mode.
inline constexpr size_t kInlinedOutlineWords = 128;
inline constexpr size_t kMaxGridCells = size_t(1) << 16;
inline constexpr size_t kGridWordsPerSegment = 256;

// Segments of closed contours one after another (a contour ends where the next segment does not
// start at its end), moved by `shift`.
std::vector<glm::vec4> packOutline(std::span<const GlyphSegment> segments, glm::vec2 shift);

// Why the polygon is not simple (two edges that cross or touch, a repeated point), or "".
std::string polygonProblem(std::span<const glm::vec2> points);

// The node's outline: a polygon's edges, or a text's glyphs centred on the origin, its font found
// under `files` (findFont()). Errors are the font's (font.h), for the caller to place at the
// node: at its "font" where the diagnostic's path is "font", else at its "text". An untrusted
// scene's font problems say "unknown font" and nothing of the file system, and its glyph
// problems name the font as the scene does.
Result<std::shared_ptr<const std::vector<glm::vec4>>> buildOutline(const Node& node,
                                                                   const SceneFiles& files);

// A revolve's polygon profile that lies at x >= axis and meets the axis x = axis along one run of
// edges: the outline of the polygon joined with its mirror image across the axis, those edges
// gone. Turned about the axis, the axis lies inside the solid, and this outline's field is the
// distance there; the polygon's own would be 0 along the whole axis. nullptr for any other
// polygon.
std::shared_ptr<const std::vector<glm::vec4>> revolvedOutline(std::span<const glm::vec2> points,
                                                              float axis);

} // namespace sdfcsg::detail
