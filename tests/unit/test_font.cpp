// Glyph outlines (font.h) held to FreeType's own numbers, read here independently: contours
// closed and counted as the font has them, wound the TrueType way, enclosing the area FreeType's
// rasterizer covers, with FreeType's bounding boxes and advances (kerning included); linear in
// the size; the exact error messages; and the cubic-to-quadratic split within its bound (no
// installed font has cubic outlines, so the split is tested on its own).
#include "scene/font.h"

#include <gtest/gtest.h>

#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_BBOX_H
#include FT_OUTLINE_H

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>

namespace sdfcsg {
namespace {

using detail::GlyphSegment;
using detail::TextOutline;
namespace fs = std::filesystem;

const std::string kFont(detail::defaultFontFile());

// The default font, opened with FreeType for the test's own measurements.
class FreeTypeFace {
  public:
    FreeTypeFace() {
        EXPECT_EQ(FT_Init_FreeType(&library_), 0);
        EXPECT_EQ(FT_New_Face(library_, kFont.c_str(), 0, &face_), 0) << kFont;
    }
    ~FreeTypeFace() {
        FT_Done_Face(face_);
        FT_Done_FreeType(library_);
    }
    FreeTypeFace(const FreeTypeFace&) = delete;
    FreeTypeFace& operator=(const FreeTypeFace&) = delete;
    FT_Face operator->() const { return face_; }
    FT_Face get() const { return face_; }

    FT_UInt glyph(char32_t code) const { return FT_Get_Char_Index(face_, code); }
    // The glyph's unscaled, unhinted outline, as loaded into the face's slot.
    const FT_Outline& load(char32_t code) const {
        EXPECT_EQ(FT_Load_Glyph(face_, glyph(code), FT_LOAD_NO_SCALE | FT_LOAD_NO_HINTING), 0);
        return face_->glyph->outline;
    }
    double kerning(char32_t left, char32_t right) const {
        FT_Vector k{};
        FT_Get_Kerning(face_, glyph(left), glyph(right), FT_KERNING_UNSCALED, &k);
        return double(k.x);
    }

  private:
    FT_Library library_ = nullptr;
    FT_Face face_ = nullptr;
};

TextOutline outlineOf(std::string_view text, float size = 1.0f) {
    auto outline = detail::textOutline(text, kFont, size);
    if (!outline) {
        ADD_FAILURE() << text << ": " << outline.error().str();
        return {};
    }
    return *outline;
}

std::string errorOf(std::string_view text, const std::string& font = kFont) {
    auto outline = detail::textOutline(text, font, 1.0f);
    if (outline) return "accepted";
    EXPECT_EQ(outline.error().kind, ErrorKind::Validation);
    EXPECT_EQ(outline.error().diagnostics.size(), 1u);
    EXPECT_TRUE(outline.error().diagnostics[0].file.empty());
    EXPECT_TRUE(outline.error().diagnostics[0].path.empty());
    return outline.error().diagnostics[0].message;
}

glm::vec2 pointOn(const GlyphSegment& s, float t) {
    if (!s.quadratic) return glm::mix(s.a, s.b, t);
    return (1 - t) * (1 - t) * s.a + 2 * t * (1 - t) * s.c + t * t * s.b;
}

// Contours: runs of segments each starting where the last ended (within 1e-5).
std::vector<std::vector<GlyphSegment>> contoursOf(const std::vector<GlyphSegment>& segments) {
    std::vector<std::vector<GlyphSegment>> contours;
    for (size_t i = 0; i < segments.size(); ++i) {
        if (i == 0 || glm::distance(segments[i].a, segments[i - 1].b) > 1e-5f)
            contours.emplace_back();
        contours.back().push_back(segments[i]);
    }
    return contours;
}

// The exact signed area (counter-clockwise positive): the chord's shoelace term, and for a
// quadratic 2/3 of its control triangle's signed area.
double signedArea(const std::vector<GlyphSegment>& contour) {
    double area = 0.0;
    for (const GlyphSegment& s : contour) {
        const glm::dvec2 a(s.a), b(s.b), c(s.c);
        area += 0.5 * (a.x * b.y - b.x * a.y);
        if (s.quadratic)
            area += (2.0 / 3.0) * 0.5 * ((c.x - a.x) * (b.y - a.y) - (b.x - a.x) * (c.y - a.y));
    }
    return area;
}

// The glyph's ink area in em^2, from FreeType's anti-aliased rasterizer at 1024 pixels per em.
double rasterArea(const FreeTypeFace& face, char32_t code) {
    constexpr int kPixelsPerEm = 1024;
    EXPECT_EQ(FT_Set_Pixel_Sizes(face.get(), 0, kPixelsPerEm), 0);
    EXPECT_EQ(FT_Load_Glyph(face.get(), face.glyph(code), FT_LOAD_NO_HINTING | FT_LOAD_RENDER), 0);
    const FT_Bitmap& bitmap = face->glyph->bitmap;
    double coverage = 0.0;
    for (unsigned row = 0; row < bitmap.rows; ++row)
        for (unsigned col = 0; col < bitmap.width; ++col)
            coverage += bitmap.buffer[row * bitmap.pitch + col] / 255.0;
    return coverage / (double(kPixelsPerEm) * kPixelsPerEm);
}

TEST(Font, BoIsFiveClosedContoursWoundTheTrueTypeWay) {
    const TextOutline text = outlineOf("Bo");
    const auto contours = contoursOf(text.segments);
    FreeTypeFace face;
    const int inB = face.load('B').n_contours;
    EXPECT_EQ(FT_Outline_Get_Orientation(&face->glyph->outline), FT_ORIENTATION_TRUETYPE);
    const int inO = face.load('o').n_contours;
    EXPECT_EQ(inB, 3); // the outline and the two counters
    EXPECT_EQ(inO, 2);
    ASSERT_EQ(contours.size(), size_t(inB + inO));
    for (const auto& contour : contours) {
        EXPECT_LT(glm::distance(contour.back().b, contour.front().a), 1e-5f) << "closed";
        for (const GlyphSegment& s : contour)
            EXPECT_TRUE(s.a != s.b || s.quadratic) << "no zero-length lines";
    }
    // Clockwise outer contours (negative in y-up), counter-clockwise holes; each glyph's sum is
    // minus its ink, which FreeType's rasterizer measures within a percent.
    for (int glyph = 0; glyph < 2; ++glyph) {
        const size_t first = glyph == 0 ? 0 : size_t(inB);
        const size_t end = glyph == 0 ? size_t(inB) : contours.size();
        std::vector<double> areas;
        for (size_t k = first; k < end; ++k)
            areas.push_back(signedArea(contours[k]));
        // The outer contour is the largest, whatever the font's order.
        const size_t outer =
            size_t(std::max_element(areas.begin(), areas.end(),
                                    [](double x, double y) { return std::abs(x) < std::abs(y); }) -
                   areas.begin());
        double sum = 0.0;
        for (size_t k = 0; k < areas.size(); ++k) {
            EXPECT_EQ(areas[k] < 0.0, k == outer) << "contour " << k << " area " << areas[k];
            sum += areas[k];
        }
        const double ink = rasterArea(face, glyph == 0 ? 'B' : 'o');
        EXPECT_LT(sum, 0.0);
        EXPECT_NEAR(-sum, ink, 0.01 * ink) << (glyph == 0 ? "B" : "o");
        if (glyph == 1) { // an "o" about half an em across, its stroke about a tenth of an em
            EXPECT_GT(-sum, 0.08);
            EXPECT_LT(-sum, 0.2);
        }
    }
}

// FreeType's exact bounding box of each glyph, placed at the pen (its advances and kerning),
// in ems: the outline is scaled by 1024 first, so that the box's integer rounding is 1/1024 of a
// font unit.
struct Placement {
    glm::dvec2 min{INFINITY}, max{-INFINITY};
    double advance = 0.0;
};
Placement placeWithFreeType(const FreeTypeFace& face, std::u32string_view text) {
    Placement p;
    const double em = face->units_per_EM;
    for (size_t i = 0; i < text.size(); ++i) {
        if (i > 0) p.advance += face.kerning(text[i - 1], text[i]);
        FT_Outline outline = face.load(text[i]);
        if (outline.n_contours > 0) {
            const FT_Matrix times1024 = {1024 << 16, 0, 0, 1024 << 16};
            FT_Outline_Transform(&outline, &times1024);
            FT_BBox box;
            EXPECT_EQ(FT_Outline_Get_BBox(&outline, &box), 0);
            p.min = glm::min(p.min, glm::dvec2(p.advance + box.xMin / 1024.0, box.yMin / 1024.0));
            p.max = glm::max(p.max, glm::dvec2(p.advance + box.xMax / 1024.0, box.yMax / 1024.0));
        }
        p.advance += double(face->glyph->advance.x);
    }
    p.min /= em, p.max /= em, p.advance /= em;
    return p;
}

TEST(Font, ExtentsAndAdvanceAreFreeTypesOwn) {
    FreeTypeFace face;
    ASSERT_TRUE(FT_HAS_KERNING(face.get())) << "DejaVu Sans has a 'kern' table";
    for (auto [utf8, text] : {std::pair<const char*, std::u32string_view>{"Bo", U"Bo"},
                              {"AVATAR Wy", U"AVATAR Wy"},
                              {"g\xc3\xa9om\xc3\xa9trie", U"g\u00e9om\u00e9trie"}}) {
        const TextOutline outline = outlineOf(utf8);
        const Placement expected = placeWithFreeType(face, text);
        for (int k = 0; k < 2; ++k) {
            EXPECT_NEAR(outline.min[k], expected.min[k], 1e-5) << utf8;
            EXPECT_NEAR(outline.max[k], expected.max[k], 1e-5) << utf8;
        }
        EXPECT_NEAR(outline.advance, expected.advance, 1e-6 * expected.advance) << utf8;
        // Every point of every segment lies in the extents, and some reach each side.
        glm::vec2 lo(INFINITY), hi(-INFINITY);
        for (const GlyphSegment& s : outline.segments)
            for (int i = 0; i <= 1024; ++i) {
                const glm::vec2 q = pointOn(s, i / 1024.0f);
                lo = glm::min(lo, q), hi = glm::max(hi, q);
            }
        for (int k = 0; k < 2; ++k) {
            EXPECT_GE(lo[k], outline.min[k] - 1e-6f) << utf8;
            EXPECT_LE(hi[k], outline.max[k] + 1e-6f) << utf8;
            EXPECT_NEAR(lo[k], outline.min[k], 1e-4f) << utf8;
            EXPECT_NEAR(hi[k], outline.max[k], 1e-4f) << utf8;
        }
    }
    // DejaVu kerns "AV" together.
    EXPECT_LT(face.kerning('A', 'V'), 0.0);
    EXPECT_LT(outlineOf("AV").advance, outlineOf("A").advance + outlineOf("V").advance - 0.01f);
}

TEST(Font, SpacesAdvanceThePenAndDrawNothing) {
    const TextOutline spaces = outlineOf("   ");
    EXPECT_TRUE(spaces.segments.empty());
    EXPECT_EQ(spaces.min, glm::vec2(0.0f));
    EXPECT_EQ(spaces.max, glm::vec2(0.0f));
    FreeTypeFace face;
    face.load(' ');
    EXPECT_NEAR(spaces.advance, 3.0 * face->glyph->advance.x / face->units_per_EM, 1e-6);
    const TextOutline empty = outlineOf("");
    EXPECT_TRUE(empty.segments.empty());
    EXPECT_EQ(empty.advance, 0.0f);
    // "o o" is "oo" with its second glyph moved by a space and the kerning around it.
    const TextOutline apart = outlineOf("o o"), together = outlineOf("oo");
    ASSERT_EQ(apart.segments.size(), together.segments.size());
    const double kerning = face.kerning('o', ' ') + face.kerning(' ', 'o') - face.kerning('o', 'o');
    const float shift = float(spaces.advance / 3.0 + kerning / face->units_per_EM);
    const size_t half = together.segments.size() / 2;
    for (size_t i = half; i < together.segments.size(); ++i)
        EXPECT_NEAR(apart.segments[i].b.x, together.segments[i].b.x + shift, 1e-5f);
}

TEST(Font, TwiceTheSizeIsTwiceEveryCoordinate) {
    const TextOutline one = outlineOf("Bo AV", 1.0f), two = outlineOf("Bo AV", 2.0f);
    ASSERT_EQ(one.segments.size(), two.segments.size());
    const auto near = [](glm::vec2 big, glm::vec2 small) {
        return glm::distance(big, 2.0f * small) <= 1e-5f * std::max(1.0f, glm::length(big));
    };
    for (size_t i = 0; i < one.segments.size(); ++i) {
        const GlyphSegment &s = one.segments[i], &t = two.segments[i];
        EXPECT_EQ(s.quadratic, t.quadratic);
        EXPECT_TRUE(near(t.a, s.a) && near(t.b, s.b) && near(t.c, s.c)) << "segment " << i;
    }
    EXPECT_TRUE(near(two.min, one.min) && near(two.max, one.max));
    EXPECT_NEAR(two.advance, 2.0f * one.advance, 1e-5f * two.advance);
}

TEST(Font, ErrorsSayWhatIsWrong) {
    EXPECT_EQ(errorOf("a", "/nonexistent/font.ttf"),
              "cannot load font \"/nonexistent/font.ttf\": no such file");
    const fs::path dir = fs::path(SDFCSG_TEST_OUTPUT_DIR) / "font";
    fs::create_directories(dir);
    const fs::path notFont = dir / "not-a-font.ttf";
    std::ofstream(notFont) << "This is a text file, not a font.\n";
    EXPECT_EQ(errorOf("a", notFont.string()),
              "cannot load font \"" + notFont.string() + "\": not a font FreeType can read");
    EXPECT_EQ(errorOf("a", dir.string()),
              "cannot load font \"" + dir.string() + "\": not a regular file");
    EXPECT_EQ(errorOf("a", "/dev/zero"), "cannot load font \"/dev/zero\": not a regular file");

    EXPECT_EQ(errorOf("\xff"), "expected text in UTF-8, got the byte 0xFF at offset 0");
    EXPECT_EQ(errorOf("ab\xc3"), "expected text in UTF-8, got the byte 0xC3 at offset 2");
    EXPECT_EQ(errorOf("a\xc0\x80"), "expected text in UTF-8, got the byte 0xC0 at offset 1");
    EXPECT_EQ(errorOf("\xed\xa0\x80"), "expected text in UTF-8, got the byte 0xED at offset 0");

    FreeTypeFace face;
    ASSERT_EQ(face.glyph(0xE000), 0u);
    ASSERT_EQ(face.glyph(0x4E00), 0u); // CJK: DejaVu has none (it has U+1F600)
    EXPECT_EQ(errorOf("a\xee\x80\x80"), "the font \"" + kFont + "\" has no glyph for (U+E000)");
    EXPECT_EQ(errorOf("\xe4\xb8\x80"), "the font \"" + kFont + "\" has no glyph for (U+4E00)");

    EXPECT_EQ(outlineOf(std::string(256, 'a')).segments.size(),
              256 * outlineOf("a").segments.size());
    EXPECT_EQ(errorOf(std::string(257, 'a')), "expected at most 256 characters, got 257");
    // Characters, not bytes: 256 two-byte ones are fine.
    std::string accents;
    for (int i = 0; i < 256; ++i)
        accents += "\xc3\xa9";
    EXPECT_EQ(errorOf(accents), "accepted");

    // DejaVu's snowman (U+2603) is its most detailed glyph: 256 of them are too many segments.
    const std::string snowman = "\xe2\x98\x83";
    const size_t perSnowman = outlineOf(snowman).segments.size();
    ASSERT_GT(256 * perSnowman, detail::kMaxTextSegments);
    std::string snowmen;
    for (int i = 0; i < 256; ++i)
        snowmen += snowman;
    EXPECT_EQ(errorOf(snowmen), "the text's outlines have more than 65536 segments");

    for (const char* broken : {"a\nb", "a\rb", "\r\n",
                               "a\xe2\x80\xa8"
                               "b",
                               "a\xc2\x85"})
        EXPECT_EQ(errorOf(broken), "text is one line: it may not hold a line break") << broken;
}

// Calls on many threads at once (each opens its own FreeType library) give one answer.
TEST(Font, ThreadsGetTheSameOutlines) {
    const TextOutline alone = outlineOf("Threads");
    std::vector<size_t> mismatches(4, 0);
    std::vector<std::thread> threads;
    for (size_t t = 0; t < mismatches.size(); ++t)
        threads.emplace_back([&, t] {
            for (int run = 0; run < 20; ++run) {
                auto o = detail::textOutline("Threads", kFont, 1.0f);
                const bool same = o && o->segments.size() == alone.segments.size() &&
                                  o->advance == alone.advance &&
                                  std::equal(o->segments.begin(), o->segments.end(),
                                             alone.segments.begin(), [](auto& x, auto& y) {
                                                 return x.a == y.a && x.b == y.b && x.c == y.c;
                                             });
                mismatches[t] += !same;
            }
        });
    for (auto& thread : threads)
        thread.join();
    for (size_t m : mismatches)
        EXPECT_EQ(m, 0u);
}

// The cubic-to-quadratic split: pieces chain from p0 to p3 exactly; at each parameter the
// cubic is within the tolerance of its piece (the documented bound, which bounds the distance
// between the curves); and the pieces are as few as the bound allows (with one fewer the
// largest error, which the bound gives exactly, would exceed the tolerance).
glm::dvec2 cubicAt(const glm::dvec2 p[4], double t) {
    const double u = 1.0 - t;
    return u * u * u * p[0] + 3.0 * u * u * t * p[1] + 3.0 * u * t * t * p[2] + t * t * t * p[3];
}

void checkSplit(glm::vec2 p0, glm::vec2 p1, glm::vec2 p2, glm::vec2 p3, float tolerance) {
    std::vector<GlyphSegment> out(1); // appended to, after what is there
    detail::cubicToQuadratics(p0, p1, p2, p3, out, tolerance);
    ASSERT_GE(out.size(), 2u);
    out.erase(out.begin());
    ASSERT_LE(out.size(), 64u);
    EXPECT_EQ(out.front().a, p0);
    EXPECT_EQ(out.back().b, p3);
    for (size_t k = 1; k < out.size(); ++k)
        EXPECT_EQ(out[k].a, out[k - 1].b) << "piece " << k;
    const glm::dvec2 p[4] = {p0, p1, p2, p3};
    const double n = double(out.size());
    double worst = 0.0;
    for (size_t k = 0; k < out.size(); ++k) {
        const GlyphSegment& q = out[k];
        EXPECT_TRUE(q.quadratic);
        for (int i = 0; i <= 200; ++i) {
            const double s = i / 200.0;
            const glm::dvec2 quad = (1 - s) * (1 - s) * glm::dvec2(q.a) +
                                    2 * s * (1 - s) * glm::dvec2(q.c) + s * s * glm::dvec2(q.b);
            worst = std::max(worst, glm::distance(quad, cubicAt(p, (double(k) + s) / n)));
        }
    }
    const double scale =
        std::max({glm::length(p0), glm::length(p1), glm::length(p2), glm::length(p3)});
    const double rounding = 4e-7 * scale; // the points' float rounding
    EXPECT_LE(worst, tolerance + rounding) << out.size() << " pieces";
    const double third = glm::length(p[3] - 3.0 * p[2] + 3.0 * p[1] - p[0]);
    const double bound = std::sqrt(3.0) / 36.0 * third;
    if (out.size() > 1) {
        EXPECT_GT(bound / std::pow(n - 1.0, 3.0), tolerance) << "one piece fewer would do";
        EXPECT_NEAR(worst, bound / (n * n * n), 1e-3 * bound / (n * n * n) + rounding);
    }
}

TEST(Font, CubicsBecomeQuadraticsWithinTheBound) {
    checkSplit({0, 0}, {0, 1}, {1, 1}, {1, 0}, 1e-3f);        // an arch
    checkSplit({0, 0}, {1, 1}, {0, 1}, {1, 0}, 1e-3f);        // a loop
    checkSplit({0, 0}, {0.3f, 1}, {0.7f, -1}, {1, 0}, 1e-3f); // an S
    checkSplit({0, 0}, {0, 1}, {1, 1}, {1, 0}, 1e-6f);
    checkSplit({10, 5}, {10, 6}, {11, 6}, {11, 5}, 1e-3f); // away from the origin
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> coordinate(-1.0f, 1.0f);
    for (int i = 0; i < 200; ++i) {
        glm::vec2 p[4];
        for (auto& q : p)
            q = {coordinate(rng), coordinate(rng)};
        checkSplit(p[0], p[1], p[2], p[3], 1e-3f);
    }
    // A cubic that is a quadratic (third difference zero) is one piece, that quadratic.
    std::vector<GlyphSegment> out;
    const glm::vec2 a(0, 0), c(1, 2), b(2, 0);
    detail::cubicToQuadratics(a, a + 2.0f / 3.0f * (c - a), b + 2.0f / 3.0f * (c - b), b, out);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_LT(glm::distance(out[0].c, c), 1e-6f);
    // The piece count stops at 64, and a tolerance of zero does not divide by it.
    out.clear();
    detail::cubicToQuadratics({0, 0}, {0, 1}, {1, 1}, {1, 0}, out, 0.0f);
    EXPECT_EQ(out.size(), 64u);
}

} // namespace
} // namespace sdfcsg
