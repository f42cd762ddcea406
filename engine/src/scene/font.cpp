// FreeType reads TrueType and OpenType outlines exactly (font units, no hinting), handles
// composite glyphs and kerning tables: the design card's choice for text, and far more than a
// hand-written reader would get right.
#include "scene/font.h"

#include "scene/files.h"

#include <fontconfig/fontconfig.h>

#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_OUTLINE_H

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

namespace sdfcsg::detail {

namespace {

constexpr uintmax_t kMaxFontBytes = uintmax_t(64) << 20;

Error problem(std::string text) {
    return Error::message(ErrorKind::Validation, {}, std::move(text));
}

struct LibraryDone {
    void operator()(FT_Library l) const { FT_Done_FreeType(l); }
};
struct FaceDone {
    void operator()(FT_Face f) const { FT_Done_Face(f); }
};

// Declared in this order, the face is released before its library, on every path.
struct Font {
    std::unique_ptr<FT_LibraryRec_, LibraryDone> library;
    std::unique_ptr<FT_FaceRec_, FaceDone> face;
};

// The next code point of UTF-8 text, or -1 where it is not valid UTF-8 (RFC 3629: no overlong
// forms, no surrogates, nothing above U+10FFFF).
long nextCodePoint(std::string_view s, size_t& at) {
    const auto byte = [&](size_t i) { return static_cast<unsigned char>(s[i]); };
    const unsigned char lead = byte(at);
    const int extra = lead < 0x80         ? 0
                      : (lead >> 5) == 6  ? 1
                      : (lead >> 4) == 14 ? 2
                      : (lead >> 3) == 30 ? 3
                                          : -1;
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

// Unicode's mandatory breaks (UAX #14: BK, CR, LF, NL): any of them would start a second line.
bool lineBreak(long code) {
    return (code >= 0x0a && code <= 0x0d) || code == 0x85 || code == 0x2028 || code == 0x2029;
}

Result<std::vector<long>> codePoints(std::string_view utf8) {
    std::vector<long> codes;
    for (size_t at = 0; at < utf8.size();) {
        const size_t start = at;
        const long code = nextCodePoint(utf8, at);
        if (code < 0) {
            char byte[8];
            std::snprintf(byte, sizeof byte, "0x%02X",
                          unsigned(static_cast<unsigned char>(utf8[start])));
            return problem("expected text in UTF-8, got the byte " + std::string(byte) +
                           " at offset " + std::to_string(start));
        }
        if (lineBreak(code)) return problem("text is one line: it may not hold a line break");
        codes.push_back(code);
    }
    if (codes.size() > kMaxTextCharacters)
        return problem("expected at most " + std::to_string(kMaxTextCharacters) +
                       " characters, got " + std::to_string(codes.size()));
    return codes;
}

// Only regular files of a font's size reach FreeType: a pipe or a device would block or never
// end.
Result<Font> openFont(const std::string& file, long faceIndex) {
    const auto fail = [&](const char* why) {
        return problem("cannot load font \"" + file + "\": " + why);
    };
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec))
        return fail(std::filesystem::exists(file, ec) ? "not a regular file" : "no such file");
    if (std::filesystem::file_size(file, ec) > kMaxFontBytes) return fail("larger than 64 MiB");
    FT_Library library = nullptr;
    if (FT_Init_FreeType(&library) != 0) return problem("cannot start FreeType");
    Font font{decltype(Font::library)(library), nullptr};
    FT_Face face = nullptr;
    if (FT_New_Face(library, file.c_str(), faceIndex, &face) != 0)
        return fail("not a font FreeType can read");
    font.face.reset(face);
    if (!FT_IS_SCALABLE(face) || face->units_per_EM == 0) return fail("it has no outlines");
    return font;
}

// A name with a slash or a font file's extension is a file; anything else a family.
bool namesAFile(std::string_view name) {
    if (name.find_first_of("/\\") != std::string_view::npos) return true;
    std::string lower(name.substr(name.size() - std::min<size_t>(name.size(), 6)));
    for (char& c : lower)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    for (std::string_view extension :
         {".ttf", ".otf", ".ttc", ".otc", ".pfa", ".pfb", ".woff", ".woff2"})
        if (lower.ends_with(extension)) return true;
    return false;
}

// A family name as fontconfig compares them: blanks dropped, ASCII letters in lower case.
std::string folded(std::string_view name) {
    std::string out;
    for (char c : name)
        if (c != ' ') out += char(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

struct PatternDone {
    void operator()(FcPattern* p) const { FcPatternDestroy(p); }
};
using Pattern = std::unique_ptr<FcPattern, PatternDone>;

// The installed font whose family is `family` (ignoring case and blanks), its regular face as
// fontconfig picks it; empty where none is. fontconfig's best match for an unknown family is
// some other font, so the match's families are checked.
std::optional<FontFace> fontOfFamily(const std::string& family) {
    // fontconfig's configuration is process-wide; calls take turns.
    static std::mutex mutex;
    std::lock_guard lock(mutex);
    if (!FcInit()) return std::nullopt;
    Pattern pattern(FcPatternCreate());
    if (!pattern) return std::nullopt;
    // Added as a value, not parsed as a fontconfig name: "x:file=/etc/passwd" is a family.
    const auto* name = reinterpret_cast<const FcChar8*>(family.c_str());
    FcPatternAddString(pattern.get(), FC_FAMILY, name);
    FcConfigSubstitute(nullptr, pattern.get(), FcMatchPattern);
    FcDefaultSubstitute(pattern.get());
    FcResult result = FcResultNoMatch;
    Pattern match(FcFontMatch(nullptr, pattern.get(), &result));
    if (!match) return std::nullopt;
    bool named = false;
    FcChar8* value = nullptr;
    for (int i = 0;
         !named && FcPatternGetString(match.get(), FC_FAMILY, i, &value) == FcResultMatch; ++i)
        named = folded(reinterpret_cast<const char*>(value)) == folded(family);
    if (!named || FcPatternGetString(match.get(), FC_FILE, 0, &value) != FcResultMatch)
        return std::nullopt;
    FontFace face{reinterpret_cast<const char*>(value), 0};
    int index = 0;
    if (FcPatternGetInteger(match.get(), FC_INDEX, 0, &index) == FcResultMatch)
        face.index = index & 0xffff; // the high bits pick a variable font's named instance
    return face;
}

std::string missingGlyph(const std::string& file, long code) {
    char name[16];
    std::snprintf(name, sizeof name, "U+%04lX", code);
    const std::string shown =
        code >= 0x20 && code < 0x7f ? "'" + std::string(1, char(code)) + "' " : "";
    return "the font \"" + file + "\" has no glyph for " + shown + "(" + name + ")";
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
    // FreeType closes each contour itself; this is for an outline that would not.
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
    const glm::vec2 b = w.at(to), c = w.at(control);
    if (b != w.last || c != w.last) w.out->push_back({w.last, b, c, true});
    w.last = b;
    return 0;
}

int cubicTo(const FT_Vector* c1, const FT_Vector* c2, const FT_Vector* to, void* user) {
    Walk& w = *static_cast<Walk*>(user);
    const glm::vec2 b = w.at(to);
    cubicToQuadratics(w.last, w.at(c1), w.at(c2), b, *w.out, float(kCubicTolerance * w.em));
    w.last = b;
    return 0;
}

// The glyph's outline in font units, unhinted so that it is the font's own, into segments.
bool walkGlyph(FT_Face face, FT_UInt glyph, Walk& walk) {
    static const FT_Outline_Funcs funcs = {moveTo, lineTo, conicTo, cubicTo, 0, 0};
    const FT_Int32 flags = FT_LOAD_NO_SCALE | FT_LOAD_NO_HINTING | FT_LOAD_NO_BITMAP;
    if (FT_Load_Glyph(face, glyph, flags) != 0 || face->glyph->format != FT_GLYPH_FORMAT_OUTLINE)
        return false;
    const bool ok = FT_Outline_Decompose(&face->glyph->outline, &funcs, &walk) == 0;
    walk.close();
    return ok;
}

// The exact extents of a line or quadratic: its ends, and where the curve turns.
void growExtents(const GlyphSegment& g, glm::vec2& lo, glm::vec2& hi) {
    lo = glm::min(lo, glm::min(g.a, g.b)), hi = glm::max(hi, glm::max(g.a, g.b));
    if (!g.quadratic) return;
    for (int k = 0; k < 2; ++k) {
        const float den = g.a[k] - 2.0f * g.c[k] + g.b[k];
        const float t = den != 0.0f ? (g.a[k] - g.c[k]) / den : -1.0f;
        if (t > 0.0f && t < 1.0f) {
            const float v = (1 - t) * (1 - t) * g.a[k] + 2 * t * (1 - t) * g.c[k] + t * t * g.b[k];
            lo[k] = std::min(lo[k], v), hi[k] = std::max(hi[k], v);
        }
    }
}

} // namespace

Result<FontFace> findFont(std::string_view name, const SceneFiles& files) {
    if (name.empty()) return FontFace{std::string(defaultFontFile()), 0};
    const auto fail = [&](const std::string& shown, const std::string& why) {
        return problem("cannot load font \"" + shown + "\": " + why);
    };
    if (namesAFile(name)) {
        auto file = sceneFile(name, files, kMaxFontBytes);
        if (!file) {
            const std::filesystem::path named(name);
            const bool joined = !named.is_absolute() && !files.folder.empty();
            return fail(joined ? (files.folder / named).string() : std::string(name),
                        file.error().diagnostics[0].message);
        }
        return FontFace{file->string(), 0};
    }
    const std::string family(name);
    if (family.find('\0') == std::string::npos)
        if (auto face = fontOfFamily(family)) return *face;
    return fail(family, "no installed font family has that name (fc-list : family lists them)");
}

std::string_view defaultFontFile() {
    return "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
}

// Each piece [t0, t1] is itself a cubic (a, q1, q2, b) with q1 = a + h B'(t0), q2 = b - h B'(t1),
// h = (t1 - t0) / 3, and its third difference is the whole curve's over n^3. Its quadratic has
// the control (3 (q1 + q2) - a - b) / 4, the mean of where the two end tangents would put it;
// the cubic minus that quadratic (raised to degree 3) is D t (1 - t) (1 - 2 t) / 2 with D the
// piece's third difference, at most sqrt(3) / 36 |D|: the parametric distance, which bounds the
// distance between the curves both ways.
void cubicToQuadratics(glm::vec2 p0f, glm::vec2 p1f, glm::vec2 p2f, glm::vec2 p3f,
                       std::vector<GlyphSegment>& out, float tolerance) {
    const glm::dvec2 p0(p0f), p1(p1f), p2(p2f), p3(p3f);
    const double third = glm::length(p3 - 3.0 * p2 + 3.0 * p1 - p0);
    const double pieces = std::cbrt(std::sqrt(3.0) / 36.0 * third / double(tolerance));
    const int n = pieces < 64.0 ? std::max(1, int(std::ceil(pieces))) : 64; // NaN too
    auto point = [&](double t) {
        const double u = 1.0 - t;
        return u * u * u * p0 + 3.0 * u * u * t * p1 + 3.0 * u * t * t * p2 + t * t * t * p3;
    };
    auto tangent = [&](double t) {
        const double u = 1.0 - t;
        return 3.0 * (u * u * (p1 - p0) + 2.0 * u * t * (p2 - p1) + t * t * (p3 - p2));
    };
    glm::vec2 a = p0f; // each piece starts where the last one ended, bit for bit
    for (int k = 0; k < n; ++k) {
        const double t0 = double(k) / n, t1 = double(k + 1) / n, h = (t1 - t0) / 3.0;
        const glm::dvec2 q1 = point(t0) + h * tangent(t0), q2 = point(t1) - h * tangent(t1);
        const glm::vec2 b = k + 1 == n ? p3f : glm::vec2(point(t1));
        const glm::dvec2 c = (3.0 * (q1 + q2) - point(t0) - point(t1)) / 4.0;
        out.push_back({a, b, glm::vec2(c), true});
        a = b;
    }
}

Result<TextOutline> textOutline(std::string_view utf8, std::string_view fontFile, float size,
                                long faceIndex) {
    auto codes = codePoints(utf8);
    if (!codes) return codes.error();
    const std::string file(fontFile);
    auto font = openFont(file, faceIndex);
    if (!font) return font.error();
    const FT_Face face = font->face.get();

    TextOutline out;
    Walk walk{&out.segments, glm::dvec2(0.0), double(size) / face->units_per_EM, double(size)};
    FT_UInt previous = 0;
    glm::vec2 lo(INFINITY), hi(-INFINITY);
    for (long code : *codes) {
        const FT_UInt glyph = FT_Get_Char_Index(face, FT_ULong(code));
        if (glyph == 0) return problem(missingGlyph(file, code));
        if (previous && FT_HAS_KERNING(face)) {
            FT_Vector kern{};
            FT_Get_Kerning(face, previous, glyph, FT_KERNING_UNSCALED, &kern);
            walk.pen.x += double(kern.x) * walk.scale;
        }
        const size_t before = out.segments.size();
        if (!walkGlyph(face, glyph, walk))
            return problem("cannot load font \"" + file + "\": glyph " + std::to_string(glyph) +
                           " has no outline FreeType can read");
        for (size_t s = before; s < out.segments.size(); ++s)
            growExtents(out.segments[s], lo, hi);
        if (out.segments.size() > kMaxTextSegments)
            return problem("the text's outlines have more than " +
                           std::to_string(kMaxTextSegments) + " segments");
        walk.pen.x += double(face->glyph->advance.x) * walk.scale;
        previous = glyph;
    }
    out.advance = float(walk.pen.x);
    if (!out.segments.empty()) out.min = lo, out.max = hi;
    return out;
}

} // namespace sdfcsg::detail
