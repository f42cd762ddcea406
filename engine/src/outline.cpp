#include "outline.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace sdfcsg::detail {

namespace {

float cross(glm::vec2 a, glm::vec2 b) { return a.x * b.y - a.y * b.x; }

// A curve whose control point lies on its chord (within a millionth of it) is that chord: the
// exact quadratic distance divides by the curve's second difference, which is then near zero.
bool straight(const GlyphSegment& s) {
    const glm::vec2 chord = s.b - s.a;
    return std::abs(cross(s.c - s.a, chord)) <= 1e-6f * glm::dot(chord, chord);
}

// The segment split at its turn in y, if it has one inside.
void appendMonotonic(const GlyphSegment& s, std::vector<GlyphSegment>& out) {
    if (!s.quadratic || straight(s)) {
        if (s.a != s.b) out.push_back({s.a, s.b, 0.5f * (s.a + s.b), false});
        return;
    }
    const float den = s.a.y - 2.0f * s.c.y + s.b.y;
    const float t = den != 0.0f ? (s.a.y - s.c.y) / den : -1.0f;
    if (!(t > 1e-6f && t < 1.0f - 1e-6f)) {
        out.push_back(s);
        return;
    }
    const glm::vec2 ac = glm::mix(s.a, s.c, t), cb = glm::mix(s.c, s.b, t);
    const glm::vec2 m = glm::mix(ac, cb, t);
    out.push_back({s.a, m, ac, true});
    out.push_back({m, s.b, cb, true});
}

bool segmentsCross(glm::vec2 a, glm::vec2 b, glm::vec2 c, glm::vec2 d) {
    const float d1 = cross(b - a, c - a), d2 = cross(b - a, d - a);
    const float d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
    if (((d1 > 0) != (d2 > 0) || d1 == 0 || d2 == 0) && ((d3 > 0) != (d4 > 0) || d3 == 0 || d4 == 0)) {
        // Collinear pairs cross only where they overlap.
        if (d1 == 0 && d2 == 0) {
            const glm::vec2 lo = glm::min(a, b), hi = glm::max(a, b);
            const glm::vec2 lo2 = glm::min(c, d), hi2 = glm::max(c, d);
            return lo.x <= hi2.x && lo2.x <= hi.x && lo.y <= hi2.y && lo2.y <= hi.y;
        }
        return true;
    }
    return false;
}

} // namespace

std::vector<glm::vec4> packOutline(std::span<const GlyphSegment> segments, glm::vec2 shift) {
    // Contours, monotonic in y.
    std::vector<std::vector<GlyphSegment>> contours;
    for (size_t i = 0; i < segments.size(); ++i) {
        GlyphSegment s = segments[i];
        s.a += shift, s.b += shift, s.c += shift;
        if (i == 0 || segments[i].a != segments[i - 1].b) contours.emplace_back();
        appendMonotonic(s, contours.back());
    }
    std::erase_if(contours, [](const auto& c) { return c.empty(); });
    std::vector<glm::vec4> out(2 * contours.size());
    for (size_t k = 0; k < contours.size(); ++k) {
        std::vector<GlyphSegment>& contour = contours[k];
        const auto quadratics = std::stable_partition(
            contour.begin(), contour.end(), [](const GlyphSegment& s) { return !s.quadratic; });
        const uint32_t first = uint32_t(out.size());
        glm::vec2 lo(INFINITY), hi(-INFINITY);
        for (const GlyphSegment& s : contour) {
            lo = glm::min(lo, glm::min(glm::min(s.a, s.b), s.c));
            hi = glm::max(hi, glm::max(glm::max(s.a, s.b), s.c));
            out.emplace_back(s.a.x, s.a.y, s.b.x, s.b.y);
            if (s.quadratic) out.emplace_back(s.c.x, s.c.y, 0.0f, 0.0f);
        }
        out[2 * k] = glm::vec4(lo, hi);
        // The first record's z holds the number of contours (Evaluator, outlineParams).
        out[2 * k + 1] = glm::vec4(float(first), float(quadratics - contour.begin()),
                                   k == 0 ? float(contours.size()) : 0.0f,
                                   float(contour.end() - quadratics));
    }
    return out;
}

std::string polygonProblem(std::span<const glm::vec2> points) {
    const size_t n = points.size();
    for (size_t i = 0; i < n; ++i)
        if (points[i] == points[(i + 1) % n])
            return "points " + std::to_string(i) + " and " + std::to_string((i + 1) % n) +
                   " are the same; expected a simple polygon";
    for (size_t i = 0; i < n; ++i)
        for (size_t j = i + 2; j < n; ++j) {
            if (i == 0 && j == n - 1) continue; // neighbours through the closing edge
            if (segmentsCross(points[i], points[(i + 1) % n], points[j], points[(j + 1) % n]))
                return "edges " + std::to_string(i) + " and " + std::to_string(j) +
                       " cross (an edge joins a point to the next); expected a simple polygon";
        }
    return {};
}

Result<std::shared_ptr<const std::vector<glm::vec4>>> buildOutline(const Node& node) {
    std::vector<GlyphSegment> segments;
    glm::vec2 shift(0.0f);
    if (node.kind == NodeKind::Polygon) {
        const auto& p = node.points;
        for (size_t i = 0; i < p.size(); ++i)
            segments.push_back({p[i], p[(i + 1) % p.size()], p[i], false});
    } else {
        const std::string& font = node.strings[1];
        auto text = textOutline(node.strings[0], font.empty() ? defaultFontFile() : font,
                                node.params[0]);
        if (!text) return text.error();
        segments = std::move(text->segments);
        shift = -0.5f * (text->min + text->max);
    }
    return std::make_shared<const std::vector<glm::vec4>>(packOutline(segments, shift));
}

} // namespace sdfcsg::detail
