// Glyph outlines from TrueType and OpenType fonts, through FreeType: the text node's shape.
#pragma once

#include "sdfcsg/error.h"

#include <glm/vec2.hpp>

#include <string_view>
#include <vector>

namespace sdfcsg::detail {

// One piece of a glyph contour, in the text's units: a line from a to b, or a quadratic Bezier
// from a through control c to b.
struct GlyphSegment {
    glm::vec2 a, b, c;
    bool quadratic;
};

struct TextOutline {
    std::vector<GlyphSegment> segments; // closed contours, y up, baseline at y = 0, pen from x = 0
    glm::vec2 min{0.0f}, max{0.0f};     // the glyphs' outline extents, as placed
    float advance = 0.0f;               // the pen's advance after the last glyph
};

inline constexpr size_t kMaxTextCharacters = 256;
inline constexpr size_t kMaxTextSegments = 65536;

// DejaVu Sans from Debian's fonts-dejavu-core.
std::string_view defaultFontFile();

// The outlines of `utf8` set on one line in `fontFile`, the font's em square `size` units tall,
// with its kerning. Cubic curves (OpenType CFF outlines) become quadratics within 1e-3 em.
// Errors are messages without a file or path, for the caller to place.
Result<TextOutline> textOutline(std::string_view utf8, std::string_view fontFile, float size);

} // namespace sdfcsg::detail
