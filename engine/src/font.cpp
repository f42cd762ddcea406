// FreeType reads TrueType and OpenType outlines exactly (font units, no hinting), handles
// composite glyphs and kerning tables: the design card's choice for text, and far more than a
// hand-written reader would get right.
#include "font.h"

#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_OUTLINE_H

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

namespace sdfcsg::detail {

namespace {

Error problem(std::string text) {
    return Error::message(ErrorKind::Validation, {}, std::move(text));
}

struct LibraryDone {
    void operator()(FT_Library l) const { FT_Done_FreeType(l); }
};
struct FaceDone {
    void operator()(FT_Face f) const { FT_Done_Face(f); }
};

// The next code point of UTF-8 text, or -1 where it is not valid UTF-8.
long nextCodePoint(std::string_view s, size_t& at) {
    const auto byte = [&](size_t i) { return static_cast<unsigned char>(s[i]); };
    const unsigned char lead = byte(at);
    const int extra = lead < 0x80 ? 0 : (lead >> 5) == 6 ? 1 : (lead >> 4) == 14 ? 2
                                     : (lead >> 3) == 30 ? 3 : -1;
    if (extra < 0 || at + size_t(extra) >= s.size()) return -1;
    long code = extra == 0 ? lead : lead & (0x3f >> extra);
    for (int k = 1; k <= extra; ++k) {
        if ((byte(at + k) & 0xc0) != 0x80) return -1;
        code = code << 6 | (byte(at + k) & 0x3f);
    }
    static constexpr long kLeast[] = {0, 0x80, 0x800, 0x10000};
    if (code < kLeast[extra] || code > 0x10ffff || (code >= 0xd800 && code <= 0xdfff)) return -1;
    at += size_t(extra) + 1;
    return code;
}

// Decomposition state: the pen's offset and the scale, in font units to text units.
struct Walk {
    std::vector<GlyphSegment>* out;
    glm::dvec2 pen;
    double scale, em;
    glm::vec2 last{0.0f}, start{0.0f};
    bool open = false;

    glm::vec2 at(const FT_Vector* v) const {
        return glm::vec2(pen + glm::dvec2(double(v->x), double(v->y)) * scale);
    }
    void close() {
        if (open && last != start) out->push_back({last, start, 0.5f * (last + start), false});
        open = false;
    }
};

int moveTo(const FT_Vector* to, void* user) {
    Walk& w = *static_cast<Walk*>(user);
    w.close();
    w.last = w.start = w.at(to);
    w.open = true;
    return 0;
}

int lineTo(const FT_Vector* to, void* user) {
    Walk& w = *static_cast<Walk*>(user);
    const glm::vec2 b = w.at(to);
    if (b != w.last) w.out->push_back({w.last, b, 0.5f * (w.last + b), false});
    w.last = b;
    return 0;
}

int conicTo(const FT_Vector* control, const FT_Vector* to, void* user) {
    Walk& w = *static_cast<Walk*>(user);
    const glm::vec2 b = w.at(to);
    w.out->push_back({w.last, b, w.at(control), true});
    w.last = b;
    return 0;
}

// A cubic as quadratics: each of n equal parameter pieces by the quadratic through its ends
// whose control is where the end tangents meet in the mean (3 (c1 + c2) - p0 - p3) / 4. Its
// distance to the piece is at most sqrt(3) / 36 times the piece's third difference
// |p3 - 3 c2 + 3 c1 - p0| / n^3; n is chosen for 1e-3 em.
int cubicTo(const FT_Vector* c1, const FT_Vector* c2, const FT_Vector* to, void* user) {
    Walk& w = *static_cast<Walk*>(user);
    const glm::dvec2 p0(w.last), p1(w.at(c1)), p2(w.at(c2)), p3(w.at(to));
    const double third = glm::length(p3 - 3.0 * p2 + 3.0 * p1 - p0);
    const double tolerance = 1e-3 * w.em;
    const int n = std::clamp(int(std::ceil(std::cbrt(0.0481 * third / tolerance))), 1, 64);
    auto point = [&](double t) {
        const double u = 1.0 - t;
        return u * u * u * p0 + 3.0 * u * u * t * p1 + 3.0 * u * t * t * p2 + t * t * t * p3;
    };
    auto tangent = [&](double t) {
        const double u = 1.0 - t;
        return 3.0 * (u * u * (p1 - p0) + 2.0 * u * t * (p2 - p1) + t * t * (p3 - p2));
    };
    for (int k = 0; k < n; ++k) {
        const double t0 = double(k) / n, t1 = double(k + 1) / n, h = (t1 - t0) / 3.0;
        const glm::dvec2 a = point(t0), b = point(t1);
        const glm::dvec2 q1 = a + h * tangent(t0), q2 = b - h * tangent(t1);
        const glm::dvec2 c = (3.0 * (q1 + q2) - a - b) / 4.0;
        w.out->push_back({glm::vec2(a), glm::vec2(b), glm::vec2(c), true});
    }
    w.last = glm::vec2(p3);
    return 0;
}

} // namespace

std::string_view defaultFontFile() {
    return "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
}

Result<TextOutline> textOutline(std::string_view utf8, std::string_view fontFile, float size) {
    std::vector<long> codes;
    for (size_t at = 0; at < utf8.size();) {
        const long code = nextCodePoint(utf8, at);
        if (code < 0) return problem("expected text in UTF-8, got bytes that are not");
        if (code == '\n' || code == '\r')
            return problem("text is one line: it may not hold a line break");
        codes.push_back(code);
        if (codes.size() > kMaxTextCharacters)
            return problem("expected at most " + std::to_string(kMaxTextCharacters) +
                           " characters");
    }
    FT_Library rawLibrary = nullptr;
    if (FT_Init_FreeType(&rawLibrary) != 0) return problem("cannot start FreeType");
    std::unique_ptr<FT_LibraryRec_, LibraryDone> library(rawLibrary);
    const std::string file(fontFile);
    // Only regular files of a font's size: a pipe or a device would block or never end.
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec))
        return problem("cannot load font \"" + file + "\": " +
                       (std::filesystem::exists(file, ec) ? "not a regular file" : "no such file"));
    if (std::filesystem::file_size(file, ec) > 64u << 20)
        return problem("cannot load font \"" + file + "\": larger than 64 MiB");
    FT_Face rawFace = nullptr;
    if (FT_New_Face(library.get(), file.c_str(), 0, &rawFace) != 0)
        return problem("cannot load font \"" + file + "\": not a font FreeType can read");
    std::unique_ptr<FT_FaceRec_, FaceDone> face(rawFace);
    if (!FT_IS_SCALABLE(face.get()) || face->units_per_EM == 0)
        return problem("cannot load font \"" + file + "\": it has no outlines");

    TextOutline out;
    Walk walk{&out.segments, glm::dvec2(0.0), double(size) / face->units_per_EM, double(size)};
    const FT_Outline_Funcs funcs = {moveTo, lineTo, conicTo, cubicTo, 0, 0};
    FT_UInt previous = 0;
    bool any = false;
    glm::vec2 lo(INFINITY), hi(-INFINITY);
    for (long code : codes) {
        const FT_UInt glyph = FT_Get_Char_Index(face.get(), FT_ULong(code));
        if (glyph == 0) {
            char name[16];
            std::snprintf(name, sizeof name, "U+%04lX", code);
            std::string shown = code >= 0x20 && code < 0x7f ? "'" + std::string(1, char(code)) + "' "
                                                            : "";
            return problem("the font \"" + file + "\" has no glyph for " + shown + "(" + name +
                           ")");
        }
        if (previous && FT_HAS_KERNING(face.get())) {
            FT_Vector kern{};
            FT_Get_Kerning(face.get(), previous, glyph, FT_KERNING_UNSCALED, &kern);
            walk.pen.x += double(kern.x) * walk.scale;
        }
        if (FT_Load_Glyph(face.get(), glyph, FT_LOAD_NO_SCALE | FT_LOAD_NO_HINTING |
                                                 FT_LOAD_NO_BITMAP) != 0 ||
            face->glyph->format != FT_GLYPH_FORMAT_OUTLINE)
            return problem("cannot load font \"" + file + "\": glyph " + std::to_string(glyph) +
                           " has no outline");
        const size_t before = out.segments.size();
        FT_Outline_Decompose(&face->glyph->outline, &funcs, &walk);
        walk.close();
        for (size_t s = before; s < out.segments.size(); ++s) {
            const GlyphSegment& g = out.segments[s];
            lo = glm::min(lo, glm::min(g.a, g.b)), hi = glm::max(hi, glm::max(g.a, g.b));
            if (g.quadratic) { // the curve's extremes: where its derivative is zero
                for (int k = 0; k < 2; ++k) {
                    const float den = g.a[k] - 2.0f * g.c[k] + g.b[k];
                    const float t = den != 0.0f ? (g.a[k] - g.c[k]) / den : -1.0f;
                    if (t > 0.0f && t < 1.0f) {
                        const float v = (1 - t) * (1 - t) * g.a[k] + 2 * t * (1 - t) * g.c[k] +
                                        t * t * g.b[k];
                        lo[k] = std::min(lo[k], v), hi[k] = std::max(hi[k], v);
                    }
                }
            }
            any = true;
        }
        if (out.segments.size() > kMaxTextSegments)
            return problem("the text's outlines have more than " +
                           std::to_string(kMaxTextSegments) + " segments");
        walk.pen.x += double(face->glyph->advance.x) * walk.scale;
        previous = glyph;
    }
    out.advance = float(walk.pen.x);
    if (any) out.min = lo, out.max = hi;
    return out;
}

} // namespace sdfcsg::detail
