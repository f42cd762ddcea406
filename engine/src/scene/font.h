// Glyph outlines from TrueType and OpenType fonts, through FreeType: the text node's shape.
#pragma once

#include "sdfcsg/error.h"
#include "sdfcsg/scene.h"

#include <glm/vec2.hpp>

#include <cstddef>
#include <string>
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
    glm::vec2 min{0.0f}, max{0.0f};     // the glyphs' exact outline extents, as placed; 0 if none
    float advance = 0.0f;               // the pen's advance after the last glyph, kerning applied
};

inline constexpr size_t kMaxTextCharacters = 256;
inline constexpr size_t kMaxTextSegments = 65536;
// How far the quadratics that replace a cubic may stray from it, in ems.
inline constexpr float kCubicTolerance = 1e-3f;

// DejaVu Sans from Debian's fonts-dejavu-core.
std::string_view defaultFontFile();

// A font file and the face in it that a text is set in (a collection holds several).
struct FontFace {
    std::string file;
    long index = 0;
};

// The font that a text node's "font" names, under the scene's rule (scene/files.h): empty, the
// default font; a name with a slash or a font file's extension (.ttf, .otf, ...), a file
// (sceneFile()); anything else, an installed family through fontconfig ("DejaVu Sans", matched
// ignoring case and blanks). Errors: "cannot load font \"NAME\": <why>", with the file it
// resolved to for a trusted scene; the caller says less for an untrusted one.
Result<FontFace> findFont(std::string_view name, const SceneFiles& files);

// The outlines of `utf8` set on one line in `fontFile`, the font's em square `size` units tall,
// with its kerning (the legacy 'kern' table; GPOS is not read). Contours come as the font winds
// them: TrueType's outer contours clockwise, holes counter-clockwise; inside is non-zero winding.
// Spaces advance the pen and add no segments. Each call opens its own FreeType library, so calls
// may run on any threads at once. Errors are messages without a file or path, for the caller to
// place: "cannot load font \"PATH\": <why>", "the font \"PATH\" has no glyph for 'X' (U+0058)",
// "text is one line: it may not hold a line break", bad UTF-8, more than kMaxTextCharacters
// characters or kMaxTextSegments segments.
// `faceIndex` picks the face of a collection.
Result<TextOutline> textOutline(std::string_view utf8, std::string_view fontFile, float size,
                                long faceIndex = 0);

// The cubic Bezier p0, p1, p2, p3 as quadratics appended to `out`, chained from p0 to p3, within
// `tolerance` of it (units of the points; plus float rounding): n equal parameter pieces, n the
// least for which sqrt(3) / 36 * |p3 - 3 p2 + 3 p1 - p0| / n^3 <= tolerance. At most 64 pieces,
// which hold the bound while that third difference is under 5.4 million tolerances (5400 ems
// for textOutline, which passes kCubicTolerance * size; in a font of 1000 units per em, whose
// coordinates are 16-bit, it is at most 524 ems).
void cubicToQuadratics(glm::vec2 p0, glm::vec2 p1, glm::vec2 p2, glm::vec2 p3,
                       std::vector<GlyphSegment>& out, float tolerance = kCubicTolerance);

} // namespace sdfcsg::detail
