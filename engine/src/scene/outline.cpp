#include "scene/outline.h"

#include "field/sdf.h"
#include "scene/files.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>

namespace sdfcsg::detail {

namespace {

float cross(glm::vec2 a, glm::vec2 b) {
    return a.x * b.y - a.y * b.x;
}

// A curve whose control point lies on its chord (within a millionth of it) is that chord: the
// exact quadratic distance divides by the curve's second difference, which is then near zero.
bool straight(const GlyphSegment& s) {
    const glm::vec2 chord = s.b - s.a;
    return std::abs(cross(s.c - s.a, chord)) <= 1e-6f * glm::dot(chord, chord);
}

// The curve's turn along `axis` (0: x, 1: y) strictly inside it, or -1.
float turn(const GlyphSegment& s, int axis) {
    const float den = s.a[axis] - 2.0f * s.c[axis] + s.b[axis];
    const float t = den != 0.0f ? (s.a[axis] - s.c[axis]) / den : -1.0f;
    return t > 1e-6f && t < 1.0f - 1e-6f ? t : -1.0f;
}

// The segment split where it turns in y and, with `inX`, in x too.
void appendMonotonic(const GlyphSegment& s, std::vector<GlyphSegment>& out, bool inX,
                     int axis = 1) {
    if (!s.quadratic || straight(s)) {
        if (s.a != s.b) out.push_back({s.a, s.b, 0.5f * (s.a + s.b), false});
        return;
    }
    const float t = turn(s, axis);
    const bool last = axis == 0 || !inX;
    if (t < 0.0f) {
        if (last)
            out.push_back(s);
        else
            appendMonotonic(s, out, inX, 0);
        return;
    }
    const glm::vec2 ac = glm::mix(s.a, s.c, t), cb = glm::mix(s.c, s.b, t);
    const glm::vec2 m = glm::mix(ac, cb, t);
    for (const GlyphSegment& piece :
         {GlyphSegment{s.a, m, ac, true}, GlyphSegment{m, s.b, cb, true}}) {
        if (last)
            out.push_back(piece);
        else
            appendMonotonic(piece, out, inX, 0);
    }
}

bool segmentsCross(glm::vec2 a, glm::vec2 b, glm::vec2 c, glm::vec2 d) {
    const float d1 = cross(b - a, c - a), d2 = cross(b - a, d - a);
    const float d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
    if (((d1 > 0) != (d2 > 0) || d1 == 0 || d2 == 0) &&
        ((d3 > 0) != (d4 > 0) || d3 == 0 || d4 == 0)) {
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

namespace {

struct Box2 {
    glm::vec2 lo, hi;
};

glm::vec2 segmentMin(const GlyphSegment& s) {
    return glm::min(glm::min(s.a, s.b), s.c);
}
glm::vec2 segmentMax(const GlyphSegment& s) {
    return glm::max(glm::max(s.a, s.b), s.c);
}

float boxDistance(const Box2& box, glm::vec2 p) {
    return glm::length(glm::max(glm::max(box.lo - p, p - box.hi), 0.0f));
}

glm::vec2 corner(const Box2& box, int k) {
    return {k & 1 ? box.hi.x : box.lo.x, k & 2 ? box.hi.y : box.lo.y};
}

// Whether the line from a to b meets the box (clipped to it, Liang and Barsky).
bool meets(const Box2& box, glm::vec2 a, glm::vec2 b) {
    float t0 = 0.0f, t1 = 1.0f;
    for (int k = 0; k < 2; ++k) {
        const float d = b[k] - a[k];
        if (d == 0.0f) {
            if (a[k] < box.lo[k] || a[k] > box.hi[k]) return false;
            continue;
        }
        float u = (box.lo[k] - a[k]) / d, v = (box.hi[k] - a[k]) / d;
        if (u > v) std::swap(u, v);
        t0 = std::max(t0, u), t1 = std::min(t1, v);
    }
    return t0 <= t1;
}

// The point of curve s at t.
glm::vec2 at(const GlyphSegment& s, float t) {
    return glm::mix(glm::mix(s.a, s.c, t), glm::mix(s.c, s.b, t), t);
}

constexpr int kCurvePieces = 8;

// The distance between two boxes.
float gap(const Box2& a, const Box2& b) {
    return glm::length(glm::max(glm::max(a.lo - b.hi, b.lo - a.hi), 0.0f));
}

// The distance from the box to the box of segment s's control points: a quick lower bound.
float hullDistance(const GlyphSegment& s, const Box2& box) {
    return gap(box, {segmentMin(s), segmentMax(s)});
}

// The least distance from the box to segment s: exact for a line (apart, the nearest pair has a
// corner of one of them); for a curve, to the boxes of the control points of its eighths.
float lowerDistance(const GlyphSegment& s, const Box2& box) {
    if (s.quadratic) {
        float least = INFINITY;
        for (int k = 0; k < kCurvePieces; ++k) {
            const float t0 = float(k) / kCurvePieces, t1 = float(k + 1) / kCurvePieces;
            // The piece's control point: where the tangents at its ends meet.
            const glm::vec2 a = at(s, t0), b = at(s, t1);
            const glm::vec2 c = glm::mix(glm::mix(s.a, s.c, t0), glm::mix(s.c, s.b, t0), t1);
            least = std::min(least,
                             gap(box, {glm::min(glm::min(a, b), c), glm::max(glm::max(a, b), c)}));
        }
        return least;
    }
    if (meets(box, s.a, s.b)) return 0.0f;
    float least = std::min(boxDistance(box, s.a), boxDistance(box, s.b));
    for (int k = 0; k < 4; ++k)
        least = std::min(least, std::sqrt(sdf::sqSegment2(corner(box, k), s.a, s.b)));
    return least;
}

// The greatest distance from a point of the box to segment s, at most: a distance to a line or
// to a point is convex, so greatest at a corner; a curve is no farther than any of its points.
float upperDistance(const GlyphSegment& s, const Box2& box) {
    float least = INFINITY;
    for (int k = 0; k <= (s.quadratic ? kCurvePieces : 0); ++k) {
        const glm::vec2 point = at(s, float(k) / kCurvePieces);
        float most = 0.0f;
        for (int j = 0; j < 4; ++j)
            most = std::max(most, s.quadratic ? sdf::dot2(corner(box, j) - point)
                                              : sdf::sqSegment2(corner(box, j), s.a, s.b));
        least = std::min(least, most);
    }
    return std::sqrt(least);
}

// The grid of an outline (outline.h): the cells from a recursive split of the grid, each block
// keeping only the segments that can be nearest somewhere in it, so that its parts start from
// those.
class GridBuilder {
  public:
    GridBuilder(const std::vector<GlyphSegment>& segments, glm::vec2 corner, float side,
                uint32_t nx, uint32_t ny, size_t budget)
        : segments_(segments), corner_(corner), side_(side), nx_(nx), ny_(ny), budget_(budget) {
        // Cells grow by more than single precision's rounding of a point's cell, so that a
        // point near a cell's edge finds every segment near it in the cell it is given.
        slack_ = 1e-3f * side;
        for (const GlyphSegment& s : segments)
            slack_ = std::max(slack_, 1e-5f * glm::length(glm::max(glm::abs(s.a), glm::abs(s.b))));
    }

    // The words from 2 on (the cell records, then the lists); empty past the budget.
    std::vector<glm::vec4> build() {
        out_.assign(size_t(nx_) * ny_, glm::vec4(0.0f));
        windings_.assign(size_t(nx_) * ny_, 0.0f);
        for (uint32_t y = 0; y < ny_; ++y)
            rowWindings(y);
        std::vector<uint32_t> all(segments_.size());
        for (uint32_t i = 0; i < all.size(); ++i)
            all[i] = i;
        if (!block(0, nx_, 0, ny_, all)) return {};
        return std::move(out_);
    }

  private:
    // The centre of cell (x, y), computed as sdOutline computes it.
    glm::vec2 centre(uint32_t x, uint32_t y) const {
        return corner_ + (glm::vec2(float(x), float(y)) + 0.5f) * side_;
    }

    // The winding at the centres of row y's cells, by the ray towards +x: what sdf.glsl's
    // crossing tests give, sorted so that a cell counts only the crossings near its centre
    // (where rounding could decide) one by one.
    void rowWindings(uint32_t y) {
        const float cy = centre(0, y).y;
        std::vector<std::pair<float, uint32_t>> crossings; // (x, segment)
        for (uint32_t i = 0; i < segments_.size(); ++i) {
            const GlyphSegment& s = segments_[i];
            if ((s.a.y <= cy) == (s.b.y <= cy)) continue;
            const float x = s.quadratic ? sdf::quadraticAtHeight(cy, s.a, s.c, s.b)
                                        : s.a.x + (cy - s.a.y) * (s.b.x - s.a.x) / (s.b.y - s.a.y);
            crossings.emplace_back(x, i);
        }
        std::sort(crossings.begin(), crossings.end());
        std::vector<float> after(crossings.size() + 1, 0.0f); // the sum from k on
        for (size_t k = crossings.size(); k-- > 0;) {
            const GlyphSegment& s = segments_[crossings[k].second];
            after[k] = after[k + 1] + (s.b.y > s.a.y ? 1.0f : -1.0f);
        }
        auto below = [&](float x) {
            return size_t(std::lower_bound(crossings.begin(), crossings.end(), std::pair(x, 0u)) -
                          crossings.begin());
        };
        for (uint32_t x = 0; x < nx_; ++x) {
            const glm::vec2 c = centre(x, y);
            const size_t from = below(c.x - slack_), to = below(c.x + slack_);
            float winding = after[to];
            for (size_t k = from; k < to; ++k) {
                const GlyphSegment& s = segments_[crossings[k].second];
                winding += s.quadratic ? sdf::quadraticCrossing(c, s.a, s.c, s.b)
                                       : sdf::lineCrossing(c, s.a, s.b);
            }
            windings_[x + nx_ * y] = winding;
        }
    }

    // Cells [x0, x1) x [y0, y1) from the segments that can be nearest somewhere in them: at a
    // point of the block the nearest segment is no farther than any segment's upper bound, so
    // its lower bound is not above the least of those.
    bool block(uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1,
               const std::vector<uint32_t>& candidates) {
        const Box2 box{corner_ + side_ * glm::vec2(float(x0), float(y0)) - slack_,
                       corner_ + side_ * glm::vec2(float(x1), float(y1)) + slack_};
        // A segment's upper bound is above its lower bound: only those nearer than the least so
        // far can lower it.
        float least = INFINITY;
        std::vector<float> hull(candidates.size());
        for (size_t k = 0; k < candidates.size(); ++k) {
            hull[k] = hullDistance(segments_[candidates[k]], box);
            if (hull[k] < least)
                least = std::min(least, upperDistance(segments_[candidates[k]], box));
        }
        std::vector<uint32_t> kept;
        for (size_t k = 0; k < candidates.size(); ++k)
            if (hull[k] <= least + slack_ &&
                lowerDistance(segments_[candidates[k]], box) <= least + slack_)
                kept.push_back(candidates[k]);
        if (x1 - x0 > 1 || y1 - y0 > 1) {
            if (x1 - x0 >= y1 - y0) {
                const uint32_t m = (x0 + x1) / 2;
                return block(x0, m, y0, y1, kept) && block(m, x1, y0, y1, kept);
            }
            const uint32_t m = (y0 + y1) / 2;
            return block(x0, x1, y0, m, kept) && block(x0, x1, m, y1, kept);
        }
        const float winding = windings_[x0 + nx_ * y0];
        const auto quadratics = std::stable_partition(
            kept.begin(), kept.end(), [&](uint32_t i) { return !segments_[i].quadratic; });
        // Neighbouring cells often keep the same segments: a list is written once.
        auto [list, added] = lists_.try_emplace(kept, uint32_t(2 + out_.size()));
        out_[x0 + nx_ * y0] = {float(list->second), float(quadratics - kept.begin()),
                               float(kept.end() - quadratics), winding};
        if (!added) return true;
        for (uint32_t i : kept) {
            const GlyphSegment& s = segments_[i];
            out_.emplace_back(s.a.x, s.a.y, s.b.x, s.b.y);
            if (s.quadratic) out_.emplace_back(s.c.x, s.c.y, 0.0f, 0.0f);
        }
        return out_.size() <= budget_;
    }

    const std::vector<GlyphSegment>& segments_;
    glm::vec2 corner_;
    float side_, slack_;
    uint32_t nx_, ny_;
    size_t budget_;
    std::vector<glm::vec4> out_;
    std::vector<float> windings_;                     // at each cell's centre
    std::map<std::vector<uint32_t>, uint32_t> lists_; // each list's first word
};

// Per contour a box and a range of segments, then the segments, the lines of a contour before
// its quadratics.
std::vector<glm::vec4> packContours(std::vector<std::vector<GlyphSegment>> contours) {
    std::erase_if(contours, [](const auto& c) { return c.empty(); });
    std::vector<glm::vec4> out(2 * contours.size());
    for (size_t k = 0; k < contours.size(); ++k) {
        std::vector<GlyphSegment>& contour = contours[k];
        const auto quadratics = std::stable_partition(
            contour.begin(), contour.end(), [](const GlyphSegment& s) { return !s.quadratic; });
        const uint32_t first = uint32_t(out.size());
        glm::vec2 lo(INFINITY), hi(-INFINITY);
        for (const GlyphSegment& s : contour) {
            lo = glm::min(lo, segmentMin(s)), hi = glm::max(hi, segmentMax(s));
            out.emplace_back(s.a.x, s.a.y, s.b.x, s.b.y);
            if (s.quadratic) out.emplace_back(s.c.x, s.c.y, 0.0f, 0.0f);
        }
        out[2 * k] = glm::vec4(lo, hi);
        out[2 * k + 1] = glm::vec4(float(first), float(quadratics - contour.begin()),
                                   float(contours.size()), float(contour.end() - quadratics));
    }
    return out;
}

// The grid of cells of about equal count to `target` over the outline's box and two cells
// around it, or empty where its lists pass `budget` words.
std::vector<glm::vec4> packGrid(const std::vector<GlyphSegment>& segments, Box2 box, size_t target,
                                size_t budget) {
    const glm::vec2 extent = glm::max(box.hi - box.lo, glm::vec2(1e-6f));
    float side = std::sqrt(extent.x * extent.y / float(target));
    uint32_t nx = 1, ny = 1;
    for (;; side *= 1.05f) {
        nx = uint32_t(std::ceil(extent.x / side)) + 4;
        ny = uint32_t(std::ceil(extent.y / side)) + 4;
        if (size_t(nx) * ny <= target) break;
    }
    auto cells = GridBuilder(segments, box.lo - 2.0f * side, side, nx, ny, budget).build();
    if (cells.empty()) return {};
    cells.insert(cells.begin(), {float(nx), float(ny), side, float(segments.size())});
    return cells;
}

} // namespace

std::vector<glm::vec4> packOutline(std::span<const GlyphSegment> segments, glm::vec2 shift) {
    std::vector<std::vector<GlyphSegment>> contours;
    std::vector<GlyphSegment> all; // split in x as well, for a grid
    Box2 box{glm::vec2(INFINITY), glm::vec2(-INFINITY)};
    for (size_t i = 0; i < segments.size(); ++i) {
        GlyphSegment s = segments[i];
        s.a += shift, s.b += shift, s.c += shift;
        if (i == 0 || segments[i].a != segments[i - 1].b) contours.emplace_back();
        appendMonotonic(s, contours.back(), false);
        appendMonotonic(s, all, true);
    }
    for (const GlyphSegment& s : all)
        box.lo = glm::min(box.lo, segmentMin(s)), box.hi = glm::max(box.hi, segmentMax(s));
    if (all.empty()) return {};
    std::vector<glm::vec4> listed = packContours(std::move(contours));
    if (listed.size() <= kGridOutlineWords) {
        std::vector<glm::vec4> out = {{0.0f, listed[1].z, 0.0f, 0.0f}, {box.lo, box.hi}};
        out.insert(out.end(), listed.begin(), listed.end());
        return out;
    }
    const size_t budget = 256 + kGridWordsPerSegment * all.size();
    for (size_t target = std::min<size_t>(64 * all.size(), kMaxGridCells);; target /= 4) {
        target = std::max<size_t>(target, 25);
        std::vector<glm::vec4> grid = packGrid(all, box, target, target > 25 ? budget : SIZE_MAX);
        if (grid.empty()) continue;
        grid.insert(grid.begin() + 1, glm::vec4(box.lo, box.hi));
        return grid;
    }
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

Result<std::shared_ptr<const std::vector<glm::vec4>>> buildOutline(const Node& node,
                                                                   const SceneFiles& files) {
    std::vector<GlyphSegment> segments;
    glm::vec2 shift(0.0f);
    if (node.kind == NodeKind::Polygon) {
        const auto& p = node.points;
        for (size_t i = 0; i < p.size(); ++i)
            segments.push_back({p[i], p[(i + 1) % p.size()], p[i], false});
    } else {
        const std::string& name = node.strings[1];
        // An untrusted scene's messages name the font as the scene does, and nothing else.
        auto fontProblem = [&](const Error& e) {
            const std::string said =
                files.trusted ? e.diagnostics[0].message
                              : untrustedFileProblem("font", name,
                                                     ": name an installed font family, such as "
                                                     "\"DejaVu Sans\", or leave it out");
            return Error(ErrorKind::Validation, Diagnostic{{}, "font", said});
        };
        auto font = findFont(name, files);
        if (!font) return fontProblem(font.error());
        auto text = textOutline(node.strings[0], font->file, node.params[0], font->index);
        if (!text) {
            std::string message = text.error().diagnostics[0].message;
            if (message.starts_with("cannot load font")) return fontProblem(text.error());
            if (!files.trusted && !name.empty())
                for (size_t at; (at = message.find(font->file)) != std::string::npos;)
                    message.replace(at, font->file.size(), name);
            return Error::message(ErrorKind::Validation, {}, message);
        }
        // "width" or "height" (slots 1 and 2, 0 when absent) scales the text to that ink
        // extent; its outlines are linear in the size.
        const glm::vec2 ink = text->max - text->min;
        const float fit = node.params[1] > 0.0f && ink.x > 0.0f   ? node.params[1] / ink.x
                          : node.params[2] > 0.0f && ink.y > 0.0f ? node.params[2] / ink.y
                                                                  : 1.0f;
        segments = std::move(text->segments);
        if (fit != 1.0f)
            for (GlyphSegment& s : segments)
                s.a *= fit, s.b *= fit, s.c *= fit;
        shift = -0.5f * fit * (text->min + text->max);
    }
    return std::make_shared<const std::vector<glm::vec4>>(packOutline(segments, shift));
}

std::shared_ptr<const std::vector<glm::vec4>> revolvedOutline(std::span<const glm::vec2> points,
                                                              float axis) {
    const size_t n = points.size();
    auto onAxis = [&](size_t i) { return points[i % n].x == axis; };
    auto axisEdge = [&](size_t i) { return onAxis(i) && onAxis(i + 1); };
    size_t first = n; // the first point of the edges off the axis, after one on it
    for (size_t i = 0; i < n; ++i) {
        if (points[i].x < axis) return nullptr;
        if (axisEdge(i + n - 1) && !axisEdge(i)) first = i;
    }
    if (first == n) return nullptr;
    // The chain off the axis runs from `first` to `last`, both on the axis, through points off
    // it; every other edge lies on the axis.
    size_t last = first + 1;
    while (!onAxis(last))
        ++last;
    for (size_t i = last; i < first + n; ++i)
        if (!axisEdge(i)) return nullptr;
    std::vector<GlyphSegment> segments;
    for (size_t i = first; i < last; ++i)
        segments.push_back({points[i % n], points[(i + 1) % n], points[i % n], false});
    auto mirror = [&](glm::vec2 p) { return glm::vec2(2.0f * axis - p.x, p.y); };
    for (size_t i = last; i-- > first;)
        segments.push_back({mirror(points[(i + 1) % n]), mirror(points[i % n]),
                            mirror(points[(i + 1) % n]), false});
    return std::make_shared<const std::vector<glm::vec4>>(packOutline(segments, glm::vec2(0.0f)));
}

} // namespace sdfcsg::detail
