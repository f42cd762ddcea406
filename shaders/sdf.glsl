// The SDF function library, one source for both languages: the kernels include it as GLSL and
// engine/src/field/sdf.h includes it as C++ with GLM standing in for GLSL, so the CPU evaluator and the
// GPU evaluate the same formulas. It is written in the dialect the two share: float literals with
// an f suffix, no swizzles (vec2(p.x, p.z), vec3(v)), no out parameters, functions marked SDF_FN.
//
// Exact distance functions after Inigo Quilez (https://iquilezles.org/articles/distfunctions/,
// .../smin/). Every primitive is centred at the origin of its local frame and takes the kernel
// parameters that its table entry's kernel() derives (engine/src/scene/nodes.cpp: half extents, half
// heights), not the JSON values. Adding a primitive: its line in engine/include/sdfcsg/kinds.h,
// its table entry, its formula here and its line in sdPrimitive() below (docs/vocabulary.md).

#ifndef SDF_FN
#define SDF_FN
#endif

// NodeKind's numbers, kKindSphere ... (generated from engine/include/sdfcsg/kinds.h).
#include "kinds.glsl"

// Polygon and text read their outlines from data beside the nodes: in GLSL the node buffer seen
// as vec4s (their records follow the nodes, engine/src/codegen/gpu_nodes.cpp), in C++ the node's own
// array (engine/src/field/sdf.h). SDF_DATA_PARAM is the extra parameter that carries it, SDF_DATA_ARG
// passes it on.
#ifndef SDF_DATA
#define SDF_DATA(i) nodeWords[i]
#define SDF_DATA_PARAM
#define SDF_DATA_ARG
layout(std430, set = 0, binding = SDFCSG_BINDING_NODES) readonly buffer NodeWords {
    vec4 nodeWords[];
};
#endif

SDF_FN float dot2(vec2 v) { return dot(v, v); }
SDF_FN float dot2(vec3 v) { return dot(v, v); }

SDF_FN float sdSphere(vec3 p, float r) { return length(p) - r; }

// b: half extents.
SDF_FN float sdBox(vec3 p, vec3 b) {
    vec3 q = abs(p) - b;
    return length(max(q, 0.0f)) + min(max(q.x, max(q.y, q.z)), 0.0f);
}

// b: half extents including the rounding r (r <= min(b)).
SDF_FN float sdRoundBox(vec3 p, vec3 b, float r) {
    vec3 q = abs(p) - b + r;
    return length(max(q, 0.0f)) + min(max(q.x, max(q.y, q.z)), 0.0f) - r;
}

// n: unit normal; the solid is where dot(p, n) < offset.
SDF_FN float sdPlane(vec3 p, vec3 n, float offset) { return dot(p, n) - offset; }

// Isosceles triangle in xy (base width 2*hw at y = -h/2, apex at y = +h/2) extruded to z in
// [-hl, hl]: IQ's exact sdTriangleIsosceles (apex at t = 0, base at t.y = h) and opExtrusion.
SDF_FN float sdTriangularPrism(vec3 p, float hw, float h, float hl) {
    vec2 q = vec2(hw, h);
    vec2 t = vec2(abs(p.x), 0.5f * h - p.y);
    vec2 a = t - q * clamp(dot(t, q) / dot(q, q), 0.0f, 1.0f);
    vec2 b = t - q * vec2(clamp(t.x / q.x, 0.0f, 1.0f), 1.0f);
    vec2 d = min(vec2(dot(a, a), -(t.x * q.y - t.y * q.x)), vec2(dot(b, b), -(t.y - q.y)));
    float d2 = -sqrt(d.x) * sign(d.y);
    vec2 w = vec2(d2, abs(p.z) - hl);
    return min(max(w.x, w.y), 0.0f) + length(max(w, 0.0f));
}

// Ring around the y axis.
SDF_FN float sdTorus(vec3 p, float major, float minor) {
    vec2 q = vec2(length(vec2(p.x, p.z)) - major, p.y);
    return length(q) - minor;
}

// Capped cylinder along y; hh: half height.
SDF_FN float sdCylinder(vec3 p, float r, float hh) {
    vec2 d = abs(vec2(length(vec2(p.x, p.z)), p.y)) - vec2(r, hh);
    return min(max(d.x, d.y), 0.0f) + length(max(d, 0.0f));
}

// IQ's exact sdCappedCone: radius r1 at y = -hh, r2 at y = +hh.
SDF_FN float sdCone(vec3 p, float r1, float hh, float r2) {
    vec2 q = vec2(length(vec2(p.x, p.z)), p.y);
    vec2 k1 = vec2(r2, hh);
    vec2 k2 = vec2(r2 - r1, 2.0f * hh);
    vec2 ca = vec2(q.x - min(q.x, (q.y < 0.0f) ? r1 : r2), abs(q.y) - hh);
    vec2 cb = q - k1 + k2 * clamp(dot(k1 - q, k2) / dot2(k2), 0.0f, 1.0f);
    float s = (cb.x < 0.0f && ca.y < 0.0f) ? -1.0f : 1.0f;
    return s * sqrt(min(dot2(ca), dot2(cb)));
}

SDF_FN float sdCapsule(vec3 p, vec3 a, vec3 b, float r) {
    vec3 pa = p - a, ba = b - a;
    float h = clamp(dot(pa, ba) / max(dot(ba, ba), 1e-30f), 0.0f, 1.0f);
    return length(pa - ba * h) - r;
}

// Not exact: the unit sphere's distance in the frame scaled by the radii (inv: their inverses),
// times the smallest radius. That is 1-Lipschitz and zero on the surface, so it never exceeds
// the true distance, and it is at least the true distance times min/max of the radii.
SDF_FN float sdEllipsoid(vec3 p, vec3 inv, float smallest) {
    return (length(p * inv) - 1.0f) * smallest;
}

// Regular hexagon in xz (corners on the x axis, apothem ap) extruded along y to [-hh, hh]; IQ's
// sdHexPrism with its axis on y.
SDF_FN float sdHexPrism(vec3 p, float ap, float hh) {
    const vec3 k = vec3(-0.8660254f, 0.5f, 0.57735027f);
    vec2 q = abs(vec2(p.x, p.z));
    q -= 2.0f * min(dot(vec2(k.x, k.y), q), 0.0f) * vec2(k.x, k.y);
    vec2 d = vec2(length(q - vec2(clamp(q.x, -k.z * ap, k.z * ap), ap)) * sign(q.y - ap),
                  abs(p.y) - hh);
    return min(max(d.x, d.y), 0.0f) + length(max(d, 0.0f));
}

// Regular octahedron with its vertices at distance s on the axes (IQ's exact form).
SDF_FN float sdOctahedron(vec3 p, float s) {
    vec3 a = abs(p);
    float m = a.x + a.y + a.z - s;
    vec3 q;
    if (3.0f * a.x < m)
        q = a;
    else if (3.0f * a.y < m)
        q = vec3(a.y, a.z, a.x);
    else if (3.0f * a.z < m)
        q = vec3(a.z, a.x, a.y);
    else
        return m * 0.57735027f;
    float k = clamp(0.5f * (q.z - q.y + s), 0.0f, s);
    return length(vec3(q.x, q.y - s + k, q.z - k));
}

// Square pyramid of base side w at y = -hh and apex at y = +hh, in the frame scaled by 1 / w
// (unit base at y = 0, apex height h = 2 hh / w): IQ's sdPyramid for the sloped faces, and the
// base square where it is nearer (below the base plane, and inside when the base is the nearer
// face), which his form leaves out.
SDF_FN float sdPyramid(vec3 p, float w, float h, float hh) {
    vec3 u = vec3(p.x, p.y + hh, p.z) / w;
    vec2 xz = abs(vec2(u.x, u.z));
    if (u.y < 0.0f) return length(vec3(max(xz - 0.5f, 0.0f), u.y)) * w;
    float m2 = h * h + 0.25f;
    xz = (xz.y > xz.x) ? vec2(xz.y, xz.x) : xz;
    xz -= 0.5f;
    vec3 q = vec3(xz.y, h * u.y - 0.5f * xz.x, h * xz.x + 0.5f * u.y);
    float s = max(-q.x, 0.0f);
    float t = clamp((q.y - 0.5f * xz.y) / (m2 + 0.25f), 0.0f, 1.0f);
    float a = m2 * (q.x + s) * (q.x + s) + q.y * q.y;
    float b = m2 * (q.x + 0.5f * t) * (q.x + 0.5f * t) + (q.y - m2 * t) * (q.y - m2 * t);
    float d2 = min(q.y, -q.x * m2 - q.y * 0.5f) > 0.0f ? 0.0f : min(a, b);
    float d = sqrt((d2 + q.z * q.z) / m2) * sign(q.z);
    return (d < 0.0f ? max(d, -u.y) : d) * w;
}

// Cylinder along y (radius r, half height hh) whose rim is rounded by rr: the cylinder of
// radius r - rr and half height hh - rr grown by rr.
SDF_FN float sdRoundedCylinder(vec3 p, float r, float hh, float rr) {
    vec2 d = vec2(length(vec2(p.x, p.z)) - r, abs(p.y) - hh);
    return min(max(d.x, d.y), 0.0f) + length(max(d, 0.0f)) - rr;
}

// The hull of a sphere of radius r1 at y = -h/2 and one of r2 at y = +h/2 (IQ's sdRoundCone);
// b = (r1 - r2) / h and a = sqrt(1 - b b), |r1 - r2| < h.
SDF_FN float sdRoundCone(vec3 p, float r1, float r2, float h, float b, float a) {
    vec2 q = vec2(length(vec2(p.x, p.z)), p.y + 0.5f * h);
    float k = dot(q, vec2(-b, a));
    if (k < 0.0f) return length(q) - r1;
    if (k > a * h) return length(q - vec2(0.0f, h)) - r2;
    return dot(q, vec2(a, b)) - r1;
}

// Chain link in the xy plane: a stadium of straight half length le along y and end radius r1,
// swept by a circle of radius r2 (IQ's sdLink).
SDF_FN float sdLink(vec3 p, float le, float r1, float r2) {
    vec3 q = vec3(p.x, max(abs(p.y) - le, 0.0f), p.z);
    return length(vec2(length(vec2(q.x, q.y)) - r1, q.z)) - r2;
}

// Arc of a ring around the y axis, symmetric about +z, reaching the angle whose sine and cosine
// are sn and cs either side of it (IQ's sdCappedTorus with its axis on y).
SDF_FN float sdCappedTorus(vec3 p, float ra, float rb, float sn, float cs) {
    vec2 q = vec2(abs(p.x), p.z);
    float k = (cs * q.x > sn * q.y) ? dot(q, vec2(sn, cs)) : length(q);
    return sqrt(max(dot(p, p) + ra * ra - 2.0f * ra * k, 0.0f)) - rb;
}

// ---- 2D profiles: distances in the xy plane, so prisms along z as fields of space ----

SDF_FN float sdCircle(vec3 p, float r) { return length(vec2(p.x, p.y)) - r; }

// Half width and height bx, by (rounding included), corner radius r.
SDF_FN float sdRectangle(vec3 p, float bx, float by, float r) {
    vec2 q = abs(vec2(p.x, p.y)) - vec2(bx, by) + r;
    return length(max(q, 0.0f)) + min(max(q.x, q.y), 0.0f) - r;
}

// IQ's regular polygon: circumradius r, half the sector an, cs and sn its cosine and sine.
// Folded into the sector of the edge on top, the edge is the segment x = r cs, |y| <= r sn.
SDF_FN float sdRegularPolygon(vec3 p, float r, float an, float cs, float sn) {
    float bn = mod(atan(p.x, p.y) + an, 2.0f * an) - an;
    vec2 q = length(vec2(p.x, p.y)) * vec2(cos(bn), abs(sin(bn))) - r * vec2(cs, sn);
    q.y += clamp(-q.y, 0.0f, r * sn);
    return length(q) * sign(q.x);
}

// The squared distance from p to the segment ab.
SDF_FN float sqSegment2(vec2 p, vec2 a, vec2 b) {
    vec2 pa = p - a, ba = b - a;
    return dot2(pa - ba * clamp(dot(pa, ba) / dot(ba, ba), 0.0f, 1.0f));
}

SDF_FN float cubeRoot(float x) { return sign(x) * pow(abs(x), 1.0f / 3.0f); }

// The squared exact distance to the quadratic Bezier from a through control c to b (IQ's
// sdBezier: the nearest point's parameter is a root of a cubic). The loader makes nearly
// straight curves lines, so b - 2c + a is never near zero.
SDF_FN float sqQuadratic2(vec2 p, vec2 a, vec2 c, vec2 b) {
    vec2 ea = c - a, eb = a - 2.0f * c + b, ec = ea * 2.0f, ed = a - p;
    float kk = 1.0f / dot(eb, eb);
    float kx = kk * dot(ea, eb);
    float ky = kk * (2.0f * dot(ea, ea) + dot(ed, eb)) / 3.0f;
    float kz = kk * dot(ed, ea);
    float pp = ky - kx * kx, q = kx * (2.0f * kx * kx - 3.0f * ky) + kz;
    float h = q * q + 4.0f * pp * pp * pp;
    float res;
    if (h >= 0.0f) {
        h = sqrt(h);
        float t = clamp(cubeRoot(0.5f * (h - q)) + cubeRoot(0.5f * (-h - q)) - kx, 0.0f, 1.0f);
        res = dot2(ed + (ec + eb * t) * t);
    } else {
        float z = sqrt(-pp);
        float v = acos(clamp(q / (pp * z * 2.0f), -1.0f, 1.0f)) / 3.0f;
        float m = cos(v), n = sin(v) * 1.732050808f;
        float t0 = clamp((m + m) * z - kx, 0.0f, 1.0f), t1 = clamp((-n - m) * z - kx, 0.0f, 1.0f);
        res = min(dot2(ed + (ec + eb * t0) * t0), dot2(ed + (ec + eb * t1) * t1));
    }
    return min(res, min(dot2(ed), dot2(b - p)));
}

// How a segment winds around p: +-1 where the ray from p towards +x crosses it, counted
// half-open in y so a ray through a shared end point counts once. A line crosses it where p
// lies on the left of the line going up (or the right going down), a test without division.
SDF_FN float lineCrossing(vec2 p, vec2 a, vec2 b) {
    if ((a.y <= p.y) == (b.y <= p.y)) return 0.0f;
    float side = (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
    return b.y > a.y ? (side > 0.0f ? 1.0f : 0.0f) : (side < 0.0f ? -1.0f : 0.0f);
}

// Where a quadratic through control point c that spans height y in its half-open way (the
// loader makes them monotonic in y) crosses it: its x there.
SDF_FN float quadraticAtHeight(float y, vec2 a, vec2 c, vec2 b) {
    // y(t) = A t^2 + B t + C = y has one root in [0, 1]; the stable pair of formulas.
    float qa = a.y - 2.0f * c.y + b.y, qb = 2.0f * (c.y - a.y), qc = a.y - y;
    float root = sqrt(max(qb * qb - 4.0f * qa * qc, 0.0f));
    float qq = -0.5f * (qb + (qb >= 0.0f ? root : -root));
    float t0 = qq / (qa != 0.0f ? qa : 1e-30f), t1 = qc / (qq != 0.0f ? qq : 1e-30f);
    float t = clamp(abs(t0 - 0.5f) < abs(t1 - 0.5f) ? t0 : t1, 0.0f, 1.0f);
    return mix(mix(a.x, c.x, t), mix(c.x, b.x, t), t);
}

// The crossings of the ray towards +x from (x0, y) less those of the ray from (x1, y).
SDF_FN float quadraticCrossings(float y, float x0, float x1, vec2 a, vec2 c, vec2 b) {
    if ((a.y <= y) == (b.y <= y)) return 0.0f;
    float x = quadraticAtHeight(y, a, c, b);
    return (b.y > a.y ? 1.0f : -1.0f) * ((x > x0 ? 1.0f : 0.0f) - (x > x1 ? 1.0f : 0.0f));
}

SDF_FN float quadraticCrossing(vec2 p, vec2 a, vec2 c, vec2 b) {
    return quadraticCrossings(p.y, p.x, 1e30f, a, c, b);
}

// The same for rays towards +y, signed so that they count the same winding: -1 where a segment
// crossing one goes towards +x. (A grid's segments are monotonic in x as well.)
SDF_FN float lineCrossingUp(vec2 p, vec2 a, vec2 b) {
    return -lineCrossing(vec2(p.y, p.x), vec2(a.y, a.x), vec2(b.y, b.x));
}
SDF_FN float quadraticCrossingsUp(float x, float y0, float y1, vec2 a, vec2 c, vec2 b) {
    return -quadraticCrossings(x, y0, y1, vec2(a.y, a.x), vec2(c.y, c.x), vec2(b.y, b.x));
}

// A small polygon or text outline (engine/src/scene/outline.h), listed by contour from `first`: the
// exact distance to its line and quadratic segments, negative where they wind around p
// (non-zero rule). The distance starts from an upper bound, the nearest of the contours' first
// points; then a contour runs only where its box is nearer than the nearest segment so far (for
// the distance) or holds p (a contour whose box does not hold p cannot wind around it). The
// tests set a contour's loop counts rather than skip it, and lines and quadratics have loops of
// their own rather than a select per segment: a CPU device (lavapipe) runs both sides of every
// branch, but a loop only as long as one of its lanes needs it.
SDF_FN float sdContours(vec2 p, uint first, uint contours SDF_DATA_PARAM) {
    float best = 1e30f, winding = 0.0f; // best: the least squared distance
    for (uint g = 0u; g < contours; ++g) {
        vec4 start = SDF_DATA(first + uint(SDF_DATA(first + 2u * g + 1u).x));
        best = min(best, dot2(vec2(start.x, start.y) - p));
    }
    for (uint g = 0u; g < contours; ++g) {
        vec4 box = SDF_DATA(first + 2u * g), range = SDF_DATA(first + 2u * g + 1u);
        vec2 e = max(vec2(box.x - p.x, box.y - p.y), vec2(p.x - box.z, p.y - box.w));
        bool holds = max(e.x, e.y) <= 0.0f;
        bool runs = holds || dot2(max(e, 0.0f)) < best;
        uint at = first + uint(range.x), lines = runs ? uint(range.y) : 0u;
        uint quadratics = runs ? uint(range.w) : 0u;
        for (uint s = 0u; s < lines; ++s) {
            vec4 ab = SDF_DATA(at + s);
            vec2 a = vec2(ab.x, ab.y), b = vec2(ab.z, ab.w);
            if (holds) winding += lineCrossing(p, a, b);
            best = min(best, sqSegment2(p, a, b));
        }
        at += uint(range.y);
        for (uint s = 0u; s < quadratics; ++s) {
            vec4 ab = SDF_DATA(at + 2u * s), cq = SDF_DATA(at + 2u * s + 1u);
            vec2 a = vec2(ab.x, ab.y), b = vec2(ab.z, ab.w), c = vec2(cq.x, cq.y);
            if (holds) winding += quadraticCrossing(p, a, c, b);
            vec2 f = max(min(min(a, b), c) - p, p - max(max(a, b), c));
            if (dot2(max(f, 0.0f)) < best) best = min(best, sqQuadratic2(p, a, c, b));
        }
    }
    return winding != 0.0f ? -sqrt(best) : sqrt(best);
}

// Polygon and text: the exact distance to an outline (engine/src/scene/outline.h, from `first`, with
// its box lo, hi) of line and quadratic segments, negative where they wind around p (non-zero
// rule). A small one is listed by contour (nx = 0). A larger one has a grid of nx by ny cells
// of `side`, two cells beyond its box: at q, the nearest point of the grid to p, the nearest of
// the segments that q's cell lists, and the winding at the cell's centre c carried to q along
// the path from c across to h = (q.x, c.y) and up to q (a segment that crosses it meets the
// cell, so the cell lists it): the crossings of the ray towards +x from h less those from c,
// then of the ray towards +y from q less those from h. Beyond the grid, sqrt(|p - q|^2 + d(q)^2)
// is a lower bound (every segment lies in the grid, on the far side of q from p), 1-Lipschitz
// and equal to the distance on the grid's edge; and never below the distance to the box. A
// point's work is its cell's few segments: loads from a buffer in a loop are what costs a CPU
// device (lavapipe) most.
SDF_FN float sdOutline(vec3 p3, float firstAt, float nx, vec2 lo, vec2 hi, float ny, float side
                       SDF_DATA_PARAM) {
    vec2 p = vec2(p3.x, p3.y);
    uint first = uint(firstAt);
    if (nx == 0.0f) return sdContours(p, first + 2u, uint(ny) SDF_DATA_ARG);
    vec2 corner = lo - 2.0f * side, cells = vec2(nx, ny);
    vec2 q = clamp(p, corner, corner + cells * side);
    vec2 g = min(floor((q - corner) / side), cells - 1.0f);
    vec4 cell = SDF_DATA(first + 2u + uint(g.x + nx * g.y));
    vec2 c = corner + (g + 0.5f) * side, h = vec2(q.x, c.y);
    uint at = first + uint(cell.x), lines = uint(cell.y), quadratics = uint(cell.z);
    float best = 1e30f, winding = cell.w; // best: the least squared distance
    for (uint s = 0u; s < lines; ++s) {
        vec4 ab = SDF_DATA(at + s);
        vec2 a = vec2(ab.x, ab.y), b = vec2(ab.z, ab.w);
        best = min(best, sqSegment2(q, a, b));
        winding += lineCrossing(h, a, b) - lineCrossing(c, a, b) + lineCrossingUp(q, a, b) -
                   lineCrossingUp(h, a, b);
    }
    at += lines;
    for (uint s = 0u; s < quadratics; ++s) {
        vec4 ab = SDF_DATA(at + 2u * s), kq = SDF_DATA(at + 2u * s + 1u);
        vec2 a = vec2(ab.x, ab.y), b = vec2(ab.z, ab.w), k = vec2(kq.x, kq.y);
        best = min(best, sqQuadratic2(q, a, k, b));
        winding += quadraticCrossings(c.y, h.x, c.x, a, k, b) +
                   quadraticCrossingsUp(q.x, q.y, h.y, a, k, b);
    }
    float d = sqrt(dot2(p - q) + best);
    vec2 e = max(lo - p, p - hi);
    float boxDistance = length(max(e, 0.0f)) + min(max(e.x, e.y), 0.0f);
    return max(winding != 0.0f ? -d : d, boxDistance);
}

// The image profile's sample at grid point g of a grid of nx per row (engine/src/scene/image.h:
// four samples to a word, from word 2).
SDF_FN float imageSample(uint first, float nx, vec2 g SDF_DATA_PARAM) {
    uint k = uint(g.x + nx * g.y);
    return SDF_DATA(first + 2u + k / 4u)[int(k % 4u)];
}

// Image: the signed distance to a mask's edges (engine/src/scene/image.h, from `first`), sampled
// at the centres of the pixels of the image (lo to hi) and of a ring of outside pixels around
// it, nx by ny samples `side` apart, and interpolated bilinearly: exact at the samples, and
// within a small part of a pixel of the distance between them (bilinear interpolation of a
// distance has a slope of up to sqrt(2) within a pixel or two of a corner of the mask). Beyond
// the samples, at q the nearest point of their rectangle, sqrt(|p - q|^2 + d(q)^2): the edges
// lie inside the image, on the far side of q from p, so this is a lower bound, 1-Lipschitz and
// the interpolation itself on the rectangle. Never below the distance to the image's box.
SDF_FN float sdImage(vec3 p3, float firstAt, float nx, vec2 lo, vec2 hi, float ny, float side
                     SDF_DATA_PARAM) {
    vec2 p = vec2(p3.x, p3.y);
    uint first = uint(firstAt);
    vec2 corner = lo - 0.5f * side, last = vec2(nx, ny) - 1.0f;
    vec2 q = clamp(p, corner, corner + last * side);
    vec2 t = (q - corner) / side;
    vec2 g = clamp(floor(t), vec2(0.0f), last - 1.0f);
    vec2 f = t - g;
    float d00 = imageSample(first, nx, g SDF_DATA_ARG);
    float d10 = imageSample(first, nx, g + vec2(1.0f, 0.0f) SDF_DATA_ARG);
    float d01 = imageSample(first, nx, g + vec2(0.0f, 1.0f) SDF_DATA_ARG);
    float d11 = imageSample(first, nx, g + vec2(1.0f) SDF_DATA_ARG);
    float d = mix(mix(d00, d10, f.x), mix(d01, d11, f.x), f.y);
    float v = d < 0.0f ? d : sqrt(dot2(p - q) + d * d);
    vec2 e = max(lo - p, p - hi);
    return max(v, length(max(e, 0.0f)) + min(max(e.x, e.y), 0.0f));
}

// Heightmap: the solid under heights over x in [-hx, hx], z in [-hz, hz] (engine/src/scene/image.h,
// from `first`: nx by ny heights at the centres of the image's pixels, interpolated bilinearly
// and held at the border's beyond them), within the box up to `height`. y - height(x, z) changes
// by at most sqrt(1 + sx^2 + sz^2) per unit, sx and sz the steepest slopes of the interpolation,
// so times its inverse `invL` it is a bound, and so is its maximum with the box's distance.
SDF_FN float sdHeightmap(vec3 p, float firstAt, float nx, float hx, float hz, float height,
                         float ny, float invL SDF_DATA_PARAM) {
    uint first = uint(firstAt);
    vec2 n = vec2(nx, ny), extent = vec2(hx, hz);
    vec2 t = clamp((vec2(p.x, p.z) + extent) * n / (2.0f * extent) - 0.5f, vec2(0.0f), n - 1.0f);
    vec2 g = min(floor(t), max(n - 2.0f, 0.0f)), g1 = min(g + 1.0f, n - 1.0f);
    vec2 f = t - g;
    float h00 = imageSample(first, nx, g SDF_DATA_ARG);
    float h10 = imageSample(first, nx, vec2(g1.x, g.y) SDF_DATA_ARG);
    float h01 = imageSample(first, nx, vec2(g.x, g1.y) SDF_DATA_ARG);
    float h11 = imageSample(first, nx, g1 SDF_DATA_ARG);
    float h = mix(mix(h00, h10, f.x), mix(h01, h11, f.x), f.y);
    float box = sdBox(p - vec3(0.0f, 0.5f * height, 0.0f), vec3(hx, 0.5f * height, hz));
    return max((p.y - h) * invL, box);
}

// Mesh: the field of a triangle mesh (engine/src/field/mesh_field.h, from `first`): word 0 holds
// the grid's bricks along x, y, z and the band, word 1 its corner and cell, word 2 where its
// colours begin (0: it has none); from word 3 a slot per brick (its samples' first index over
// 729, or -1 outside, -2 inside), four to a word, then the bricks' 9^3 samples each, four to a
// word, then as many colours. Trilinear within a brick with samples; the band, a bound of the
// right sign, in one without; beyond the grid, the distance to it plus the band.
SDF_FN float meshWord(uint at, uint k SDF_DATA_PARAM) {
    return SDF_DATA(at + k / 4u)[int(k % 4u)];
}
SDF_FN float sdMesh(vec3 p, float firstAt, float bx, float ox, float oy, float oz, float cell,
                    float by, float bz SDF_DATA_PARAM) {
    uint first = uint(firstAt);
    vec3 origin = vec3(ox, oy, oz);
    float band = SDF_DATA(first).w;
    vec3 bricks = vec3(bx, by, bz);
    vec3 g = (p - origin) / cell;
    vec3 outside = max(max(-g, g - 8.0f * bricks), vec3(0.0f));
    if (outside.x + outside.y + outside.z > 0.0f) return length(outside) * cell + band;
    vec3 b = min(floor(g / 8.0f), bricks - 1.0f);
    float slot = meshWord(first + 3u, uint(b.x + bx * (b.y + by * b.z)) SDF_DATA_ARG);
    if (slot < 0.0f) return slot < -1.5f ? -band : band;
    uint samples = first + 3u + (uint(bx * by * bz) + 3u) / 4u;
    vec3 local = min(g - 8.0f * b, vec3(8.0f));
    vec3 i = min(floor(local), vec3(7.0f));
    vec3 t = local - i;
    uint k = uint(slot) * 729u + uint(i.x + 9.0f * (i.y + 9.0f * i.z));
    float c000 = meshWord(samples, k SDF_DATA_ARG), c100 = meshWord(samples, k + 1u SDF_DATA_ARG);
    float c010 = meshWord(samples, k + 9u SDF_DATA_ARG);
    float c110 = meshWord(samples, k + 10u SDF_DATA_ARG);
    float c001 = meshWord(samples, k + 81u SDF_DATA_ARG);
    float c101 = meshWord(samples, k + 82u SDF_DATA_ARG);
    float c011 = meshWord(samples, k + 90u SDF_DATA_ARG);
    float c111 = meshWord(samples, k + 91u SDF_DATA_ARG);
    // Samples reach a cell beyond the band, the bricks without them stop at it: clamped to the
    // band, the field meets theirs without a step (and stays a bound).
    return clamp(mix(mix(mix(c000, c100, t.x), mix(c010, c110, t.x), t.y),
                     mix(mix(c001, c101, t.x), mix(c011, c111, t.x), t.y), t.z),
                 -band, band);
}

// The mesh's colour at p (MeshField::color): the colour of the sample nearest to p, stored as
// r 65536 + g 256 + b (exact in a float; -1 for none), or the node's `color` where there is none.
SDF_FN vec3 colorMesh(vec3 p, float firstAt, float bx, float ox, float oy, float oz, float cell,
                      float by, float bz, vec3 color SDF_DATA_PARAM) {
    uint first = uint(firstAt);
    float colorsAt = SDF_DATA(first + 2u).x;
    vec3 bricks = vec3(bx, by, bz);
    vec3 g = (p - vec3(ox, oy, oz)) / cell;
    if (colorsAt == 0.0f || min(g.x, min(g.y, g.z)) < 0.0f ||
        max(g.x - 8.0f * bx, max(g.y - 8.0f * by, g.z - 8.0f * bz)) > 0.0f)
        return color;
    vec3 b = min(floor(g / 8.0f), bricks - 1.0f);
    float slot = meshWord(first + 3u, uint(b.x + bx * (b.y + by * b.z)) SDF_DATA_ARG);
    if (slot < 0.0f) return color;
    vec3 i = clamp(floor(g - 8.0f * b + 0.5f), vec3(0.0f), vec3(8.0f));
    float c = meshWord(first + uint(colorsAt),
                       uint(slot) * 729u + uint(i.x + 9.0f * (i.y + 9.0f * i.z)) SDF_DATA_ARG);
    if (c < 0.0f) return color;
    float r = floor(c / 65536.0f), gb = c - 65536.0f * r, g8 = floor(gb / 256.0f);
    return vec3(r, g8, gb - 256.0f * g8) * (1.0f / 255.0f);
}

// CSG operators: IQ's polynomial smooth minimum with blend radius k, and smooth max(a, b) =
// -smin(-a, -b). Once the operands differ by k or more the blend factor is exactly 0 or 1, so
// those cases return an operand unchanged: this makes bounds skipping and pruning exact in
// floating point (the dropped operand could not have changed a single bit) and gives k = 0 the
// sharp operator (ties go to the first operand). Selects rather than branches: both sides are a
// few instructions, and every branch costs CPU drivers (lavapipe) compile time. The vec4 forms
// carry colour in rgb and the distance in w; colour blends by the same factor.
// Difference(a, b) = max(a, -b).
SDF_FN float opUnion(float a, float b, float k) {
    float h = clamp(0.5f + 0.5f * (b - a) / max(k, 1e-30f), 0.0f, 1.0f);
    float blend = mix(b, a, h) - k * h * (1.0f - h);
    float r = (a - b >= k) ? b : blend;
    return (b - a >= k) ? a : r;
}

SDF_FN float opIntersection(float a, float b, float k) {
    float h = clamp(0.5f - 0.5f * (b - a) / max(k, 1e-30f), 0.0f, 1.0f);
    float blend = mix(b, a, h) + k * h * (1.0f - h);
    float r = (b - a >= k) ? b : blend;
    return (a - b >= k) ? a : r;
}

SDF_FN float opDifference(float a, float b, float k) { return opIntersection(a, -b, k); }

SDF_FN vec4 opUnion(vec4 a, vec4 b, float k) {
    float h = clamp(0.5f + 0.5f * (b.w - a.w) / max(k, 1e-30f), 0.0f, 1.0f);
    vec4 blend = vec4(mix(vec3(b), vec3(a), h), mix(b.w, a.w, h) - k * h * (1.0f - h));
    vec4 r = (a.w - b.w >= k) ? b : blend;
    return (b.w - a.w >= k) ? a : r;
}

SDF_FN vec4 opIntersection(vec4 a, vec4 b, float k) {
    float h = clamp(0.5f - 0.5f * (b.w - a.w) / max(k, 1e-30f), 0.0f, 1.0f);
    vec4 blend = vec4(mix(vec3(b), vec3(a), h), mix(b.w, a.w, h) + k * h * (1.0f - h));
    vec4 r = (b.w - a.w >= k) ? b : blend;
    return (a.w - b.w >= k) ? a : r;
}

SDF_FN vec4 opDifference(vec4 a, vec4 b, float k) {
    return opIntersection(a, vec4(vec3(b), -b.w), k);
}

// The operators at k = 0, for code that knows k is 0: the same bits as opUnion(a, b, 0.0f) and
// the others (the blend is never chosen), in one comparison. The full forms cost lavapipe's
// compiler and every evaluation their unused blend.
SDF_FN float sharpUnion(float a, float b) { return a <= b ? a : b; }
SDF_FN float sharpIntersection(float a, float b) { return a >= b ? a : b; }
SDF_FN float sharpDifference(float a, float b) { return a >= -b ? a : -b; }
SDF_FN vec4 sharpUnion(vec4 a, vec4 b) { return a.w <= b.w ? a : b; }
SDF_FN vec4 sharpIntersection(vec4 a, vec4 b) { return a.w >= b.w ? a : b; }
SDF_FN vec4 sharpDifference(vec4 a, vec4 b) { return a.w >= -b.w ? a : vec4(vec3(b), -b.w); }

// Blend profiles (the "blend" field; 0, the polynomial, is opUnion above). Each union is
// min(a, b) - k w(h) with h = max(k - |a - b|, 0) / k: round (1) is the circular fillet, of
// radius k where the surfaces meet at a right angle; chamfer (2) cuts the corner along
// a + b = k, as hg_sdf's does, with half its slope so that the field stays 1-Lipschitz. Both
// pass at most half of a change in either operand on, are exact once |a - b| >= k and never
// dip more than k below min(a, b), which pruning and the bounds rely on (engine/src/field/prune.cpp).
SDF_FN float blendDip(float h, uint style) {
    return style == 2u ? 0.5f * h : 0.5f * (1.0f + h - sqrt(max(1.0f + 2.0f * h - h * h, 0.0f)));
}

SDF_FN float opUnion(float a, float b, float k, uint style) {
    if (style == 0u) return opUnion(a, b, k);
    float h = max(k - abs(a - b), 0.0f) / max(k, 1e-30f);
    float blend = min(a, b) - k * blendDip(h, style);
    float r = (a - b >= k) ? b : blend;
    return (b - a >= k) ? a : r;
}

SDF_FN float opIntersection(float a, float b, float k, uint style) {
    return style == 0u ? opIntersection(a, b, k) : -opUnion(-a, -b, k, style);
}

SDF_FN float opDifference(float a, float b, float k, uint style) {
    return opIntersection(a, -b, k, style);
}

SDF_FN vec4 opUnion(vec4 a, vec4 b, float k, uint style) {
    if (style == 0u) return opUnion(a, b, k);
    float h = clamp(0.5f + 0.5f * (b.w - a.w) / max(k, 1e-30f), 0.0f, 1.0f);
    return vec4(mix(vec3(b), vec3(a), h), opUnion(a.w, b.w, k, style));
}

SDF_FN vec4 opIntersection(vec4 a, vec4 b, float k, uint style) {
    if (style == 0u) return opIntersection(a, b, k);
    float h = clamp(0.5f - 0.5f * (b.w - a.w) / max(k, 1e-30f), 0.0f, 1.0f);
    return vec4(mix(vec3(b), vec3(a), h), opIntersection(a.w, b.w, k, style));
}

SDF_FN vec4 opDifference(vec4 a, vec4 b, float k, uint style) {
    return opIntersection(a, vec4(vec3(b), -b.w), k, style);
}

// Tap i (0..3) of the four-tap tetrahedral difference, the tetrahedron k = (1, -1): k.xyy,
// k.yyx, k.yxy, k.xxx. The normal at p is normalize(sum of tap(i) * f(p + tap(i) * e)).
SDF_FN vec3 tetraTap(int i) {
    return i == 0 ? vec3(1.0f, -1.0f, -1.0f)
         : i == 1 ? vec3(-1.0f, -1.0f, 1.0f)
         : i == 2 ? vec3(-1.0f, 1.0f, -1.0f)
                  : vec3(1.0f);
}

// A primitive's local distance by its kind (NodeKind's numbering) and kernel parameters (a:
// slots 0-3, b: slots 4-7). `kinds` has bit k set for each kind the caller may pass; a constant,
// it leaves a kernel the formulas of its scene's kinds alone.
#define SDF_IS(n) (kind == n && ((kinds >> n) & 1u) != 0u)
SDF_FN float sdPrimitive(uint kind, vec3 q, vec4 a, vec4 b, uint kinds SDF_DATA_PARAM) {
    if (SDF_IS(kKindSphere)) return sdSphere(q, a.x);
    if (SDF_IS(kKindBox)) return sdBox(q, vec3(a));
    if (SDF_IS(kKindRoundBox)) return sdRoundBox(q, vec3(a), a.w);
    if (SDF_IS(kKindPlane)) return sdPlane(q, vec3(a), a.w);
    if (SDF_IS(kKindTriangularPrism)) return sdTriangularPrism(q, a.x, a.y, a.z);
    if (SDF_IS(kKindTorus)) return sdTorus(q, a.x, a.y);
    if (SDF_IS(kKindCylinder)) return sdCylinder(q, a.x, a.y);
    if (SDF_IS(kKindCone)) return sdCone(q, a.x, a.y, a.z);
    if (SDF_IS(kKindCapsule)) return sdCapsule(q, vec3(a), vec3(b), a.w);
    if (SDF_IS(kKindEllipsoid)) return sdEllipsoid(q, vec3(a), a.w);
    if (SDF_IS(kKindHexPrism)) return sdHexPrism(q, a.x, a.y);
    if (SDF_IS(kKindOctahedron)) return sdOctahedron(q, a.x);
    if (SDF_IS(kKindPyramid)) return sdPyramid(q, a.x, a.y, a.z);
    if (SDF_IS(kKindRoundedCylinder)) return sdRoundedCylinder(q, a.x, a.y, a.z);
    if (SDF_IS(kKindRoundCone)) return sdRoundCone(q, a.x, a.y, a.z, a.w, b.x);
    if (SDF_IS(kKindLink)) return sdLink(q, a.x, a.y, a.z);
    if (SDF_IS(kKindCappedTorus)) return sdCappedTorus(q, a.x, a.y, a.z, a.w);
    if (SDF_IS(kKindHeightmap))
        return sdHeightmap(q, a.x, a.y, a.z, a.w, b.x, b.z, b.w SDF_DATA_ARG);
    if (SDF_IS(kKindMesh))
        return sdMesh(q, a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w SDF_DATA_ARG);
    if (SDF_IS(kKindCircle)) return sdCircle(q, a.x);
    if (SDF_IS(kKindRectangle)) return sdRectangle(q, a.x, a.y, a.z);
    if (SDF_IS(kKindRegularPolygon)) return sdRegularPolygon(q, a.x, a.y, a.z, a.w);
    if (SDF_IS(kKindPolygon) || SDF_IS(kKindText))
        return sdOutline(q, a.x, a.y, vec2(a.z, a.w), vec2(b.x, b.y), b.z, b.w SDF_DATA_ARG);
    if (SDF_IS(kKindImage))
        return sdImage(q, a.x, a.y, vec2(a.z, a.w), vec2(b.x, b.y), b.z, b.w SDF_DATA_ARG);
    return 1e30f;
}

// A primitive's own colour at q, by the formula its table entry names (KindInfo::colorFunction),
// from the point and parameters sdPrimitive takes and the node's `color`, which the kinds without
// one keep; `kinds` as sdPrimitive's.
SDF_FN vec3 sdPrimitiveColor(uint kind, vec3 q, vec4 a, vec4 b, vec3 color,
                             uint kinds SDF_DATA_PARAM) {
    if (SDF_IS(kKindMesh))
        return colorMesh(q, a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w, color SDF_DATA_ARG);
    return color;
}
#undef SDF_IS

// ---- Value and domain operations (kernel parameters from their table entries' kernelAround) ----

// Shell: a skin of half thickness a.x about the surface; offset: moved out by a.x.
SDF_FN float valueOp(uint kind, float d, vec4 a) {
    return kind == kKindShell ? abs(d) - a.x : d - a.x;
}

// Over a child whose field is not a distance (FlatNode::loss), an offset or shell measures from
// the child's value divided by its gradient's length, which is a distance to first order near
// the surface (a.y: the tap step h, a.z: the least length the gradient is given, 1/loss, so that
// the value grows by at most the loss; eval.cpp, normalisedStep). The child runs at four taps
// around p, the corners of a tetrahedron (p + h k_c, k_c = (1,-1,-1), (-1,-1,1), (-1,1,-1),
// (1,1,1)); since the k_c sum to zero and k_c k_c^T to 4 I, sum(k_c f_c) / 4h is the gradient
// and sum(f_c) / 4 the value at p, both to second order.
SDF_FN vec3 valueTap(vec3 p, float h, uint c) {
    return p + h * vec3(c == 0u || c == 3u ? 1.0f : -1.0f, c >= 2u ? 1.0f : -1.0f,
                        c == 1u || c == 3u ? 1.0f : -1.0f);
}
// The running sum of the taps: xyz sum(k_c f_c), w sum(f_c).
SDF_FN vec4 valueTapSum(vec4 sum, float d, uint c) {
    return sum + d * vec4(c == 0u || c == 3u ? 1.0f : -1.0f, c >= 2u ? 1.0f : -1.0f,
                          c == 1u || c == 3u ? 1.0f : -1.0f, 1.0f);
}
// The child's value at p over its gradient's length, from the taps' sum; with a.y 0 (a child
// whose field is a distance, at one tap where the code does not know which), the value.
SDF_FN float valueNormalised(vec4 sum, vec4 a) {
    if (a.y <= 0.0f) return sum.w;
    float gradient = length(vec3(sum.x, sum.y, sum.z)) / (4.0f * a.y);
    return 0.25f * sum.w / clamp(gradient, a.z, 1.0f);
}
// The offset's or shell's value from the taps: valueOp of the normalised value, kept within
// |a.x| (1 - a.z) of valueOp of the plain one, which is as far as the division moves the value
// where the surface lies (there the child's value is a.x times the gradient's length, at least
// a.z): the surface is the same, and the value never exceeds the plain one, a bound, by more.
SDF_FN float valueOpNormalised(uint kind, vec4 sum, vec4 a) {
    if (a.y <= 0.0f) return valueOp(kind, sum.w, a);
    float plain = valueOp(kind, 0.25f * sum.w, a);
    float reach = abs(a.x) * (1.0f - a.z) + 2.0f * a.y;
    return plain + clamp(valueOp(kind, valueNormalised(sum, a), a) - plain, -reach, reach);
}

// Domain operations evaluate their child at one or more points of the child's space (the
// candidates) and combine the values: the least of them, for the copies of a repetition. A point
// p here is in the node's local space. Repeat: a: spacing, G; b: count, M packed a byte per
// axis. Along each axis the candidates are the nearest copy, then in turn M more either side,
// then one more towards p, or every copy when that is as many: the nearest copy to any point of
// a child that reaches M copies either side is among them (engine/src/scene/nodes.cpp, repeatKernel).
SDF_FN uint repeatAxisCount(float n, float m) {
    return n <= 1.0f ? 1u : (2.0f * m + 2.0f >= n ? uint(n) : uint(2.0f * m + 2.0f));
}

SDF_FN float repeatAxisM(float packed, uint axis) {
    return float((uint(packed) >> (8u * axis)) & 255u);
}

// Copy index along one axis for candidate c of that axis, -1 when there is none.
SDF_FN float repeatAxisIndex(float x, float s, float n, float m, uint c) {
    float nearest = clamp(floor(x / s + 0.5f * (n - 1.0f) + 0.5f), 0.0f, n - 1.0f);
    float toward = x - (nearest - 0.5f * (n - 1.0f)) * s >= 0.0f ? 1.0f : -1.0f;
    float i;
    if (2.0f * m + 2.0f >= n) {
        i = mod(nearest + float(c), n);
    } else {
        float j = float((c + 1u) / 2u);
        i = c == 0u ? nearest
            : c == uint(2.0f * m + 1.0f) ? nearest + (m + 1.0f) * toward
            : (c % 2u == 1u ? nearest + j * toward : nearest - j * toward);
    }
    return (i < 0.0f || i > n - 1.0f) ? -1.0f : i;
}

// The eases of bend_linear (and its "ease" choices, in order): each rises from 0 at t = 0 to 1
// at t = 1, linearly, as smoothstep (3 t^2 - 2 t^3) or as smootherstep (6 t^5 - 15 t^4 + 10 t^3,
// flat to the second derivative at both ends). easeSlope is the steepest slope of each.
SDF_FN float ease(float t, float style) {
    if (style == 1.0f) return t * t * (3.0f - 2.0f * t);
    if (style == 2.0f) return t * t * t * (t * (6.0f * t - 15.0f) + 10.0f);
    return t;
}
SDF_FN float easeSlope(float style) {
    return style == 1.0f ? 1.5f : (style == 2.0f ? 1.875f : 1.0f);
}

// Bend_linear moves its child by the offset b.xyz times ease(t), t the clamped position of p
// along the axis (a.xyz: p1 - p0 over its squared length, a.w: p0's position along it). The
// map's Jacobian is the identity less offset * ease'(t) * a.xyz, whose norm is at most this.
SDF_FN float bendLinearStretch(vec4 a, vec4 b) {
    return 1.0f + length(vec3(b)) * length(vec3(a)) * easeSlope(b.w);
}

// Transition_linear and transition_radial, at the node's local point p: the weight of the second
// child, the ease (b.y) of t clamped to 0..1, t the position of p along the axis (a.xyz: p1 - p0
// over its squared length, a.w: p0's position along it) or, radial, its distance from the centre
// a.xyz less r0 (a.w), times b.x = 1 / (r1 - r0). transitionSlope is the weight's steepest slope.
SDF_FN float transitionWeight(uint kind, vec3 p, vec4 a, vec4 b) {
    float t = kind == kKindTransitionRadial ? (length(p - vec3(a)) - a.w) * b.x
                                            : dot(p, vec3(a)) - a.w;
    return ease(clamp(t, 0.0f, 1.0f), b.y);
}
SDF_FN float transitionSlope(uint kind, vec4 a, vec4 b) {
    return easeSlope(b.y) * (kind == kKindTransitionRadial ? abs(b.x) : length(vec3(a)));
}

// The morph of values da and db by the weight w: their mix, with db - da clamped to +-b.z (twice
// the diagonal of the children's bounds, which no difference reaches within them) and divided by
// the mix's Lipschitz bound 1 + b.z W (its reciprocal in b.w; W: transitionSlope in the frame's
// units). Colours mix by the same weight.
SDF_FN float opTransition(float da, float db, float w, vec4 b) {
    return (da + w * clamp(db - da, -b.z, b.z)) * b.w;
}
SDF_FN vec4 opTransition(vec4 a, vec4 b, float w, vec4 k) {
    return vec4(mix(vec3(a), vec3(b), w), opTransition(a.w, b.w, w, k));
}

SDF_FN uint polarCount(vec4 a, vec4 b) {
    return a.x <= 1.0f ? 1u : (b.x >= a.x ? uint(a.x) : uint(2.0f * b.x + 2.0f));
}

SDF_FN uint domainCount(uint kind, vec4 a, vec4 b) {
    if (kind == kKindRepeat)
        return repeatAxisCount(b.x, repeatAxisM(b.w, 0u)) *
               repeatAxisCount(b.y, repeatAxisM(b.w, 1u)) *
               repeatAxisCount(b.z, repeatAxisM(b.w, 2u));
    if (kind == kKindPolarRepeat) return polarCount(a, b);
    return 1u;
}

// Candidate c's point in the child's space; w is 1 where the candidate is no copy (beyond the
// ends of a repetition), else 0.
SDF_FN vec4 domainPoint(uint kind, vec3 p, vec4 a, vec4 b, uint c) {
    if (kind == kKindRepeat) {
        float mx = repeatAxisM(b.w, 0u), my = repeatAxisM(b.w, 1u), mz = repeatAxisM(b.w, 2u);
        uint kx = repeatAxisCount(b.x, mx), ky = repeatAxisCount(b.y, my);
        float ix = repeatAxisIndex(p.x, a.x, b.x, mx, c % kx);
        float iy = repeatAxisIndex(p.y, a.y, b.y, my, (c / kx) % ky);
        float iz = repeatAxisIndex(p.z, a.z, b.z, mz, c / (kx * ky));
        vec3 i = vec3(ix, iy, iz);
        vec3 o = (i - 0.5f * (vec3(b) - 1.0f)) * vec3(a);
        return vec4(p - o, (ix < 0.0f || iy < 0.0f || iz < 0.0f) ? 1.0f : 0.0f);
    }
    if (kind == kKindPolarRepeat) {
        // Copy i is the child turned about y by i times the sector a.z, at angle i a.z from +x
        // towards -z.
        float n = a.x, m = b.x;
        float nearest = floor(atan(-p.z, p.x) / a.z + 0.5f);
        float toward = atan(-p.z, p.x) - nearest * a.z >= 0.0f ? 1.0f : -1.0f;
        float j = float((c + 1u) / 2u);
        float i = m >= n ? nearest + float(c)
                  : c == 0u ? nearest
                  : c == uint(2.0f * m + 1.0f) ? nearest + (m + 1.0f) * toward
                  : (c % 2u == 1u ? nearest + j * toward : nearest - j * toward);
        float angle = mod(i, n) * a.z;
        float cs = cos(angle), sn = sin(angle);
        return vec4(p.x * cs - p.z * sn - a.y, p.y, p.x * sn + p.z * cs, 0.0f);
    }
    if (kind == kKindMirror) {
        float k = a.w;
        vec3 m = abs(p);
        if (k > 0.0f) m = sqrt(p * p + k * k);
        return vec4(a.x != 0.0f ? m.x : p.x, a.y != 0.0f ? m.y : p.y, a.z != 0.0f ? m.z : p.z, 0.0f);
    }
    if (kind == kKindElongate) return vec4(p - clamp(p, -vec3(a), vec3(a)), 0.0f);
    if (kind == kKindTwist) {
        float cs = cos(a.x * p.y), sn = sin(a.x * p.y);
        return vec4(cs * p.x + sn * p.z, p.y, -sn * p.x + cs * p.z, 0.0f);
    }
    if (kind == kKindBend) {
        float cs = cos(a.x * p.x), sn = sin(a.x * p.x);
        return vec4(cs * p.x + sn * p.y, -sn * p.x + cs * p.y, p.z, 0.0f);
    }
    if (kind == kKindBendLinear) {
        float t = clamp(dot(p, vec3(a)) - a.w, 0.0f, 1.0f);
        return vec4(p - vec3(b) * ease(t, b.w), 0.0f);
    }
    if (kind == kKindTaper) {
        float s = 1.0f + (a.y - 1.0f) * clamp((p.y + a.x) / (2.0f * a.x), 0.0f, 1.0f);
        return vec4(p.x / s, p.y, p.z / s, 0.0f);
    }
    // Extrude and revolve cut their child at z = 0: revolve at the distance from the y axis
    // less the offset a.x (a 1-Lipschitz map, so the value stays a distance bound).
    if (kind == kKindExtrude) return vec4(p.x, p.y, 0.0f, 0.0f);
    return vec4(length(vec2(p.x, p.z)) - a.x, p.y, 0.0f, 0.0f);
}

// Twist, bend and taper stretch space: their child sees points clamped into the node's bounds,
// and its value is divided by the Lipschitz bound over them (b.w holds its inverse).
SDF_FN bool domainClamps(uint kind) { return kind >= kKindTwist && kind <= kKindTaper; }

// The node's value in its local units from the least of its candidates' values.
SDF_FN float domainFinish(uint kind, vec3 p, float best, vec4 a, vec4 b) {
    if (kind == kKindRepeat) return min(best, a.w);
    if (kind == kKindPolarRepeat) {
        // The copies left out lie at least the angle gamma away from p about the axis, at least
        // b.y from the axis, and between heights b.z and b.w: they are no nearer than that
        // region, whose distance from p depends on p's radius and height alone (a.w: cos gamma;
        // above 1 when every copy that can reach p was a candidate).
        if (a.w > 1.0f) return best;
        float r = length(vec2(p.x, p.z)), rho = max(r * a.w, b.y);
        float across = sqrt(max(r * r + rho * rho - 2.0f * r * rho * a.w, 0.0f));
        float along = max(max(b.z - p.y, p.y - b.w), 0.0f);
        return min(best, length(vec2(across, along)));
    }
    if (kind == kKindExtrude) {
        // The profile's value and |z| against the half height a.x, with edges of radius a.y
        // (IQ's opExtrusion around the profile shrunk by the rounding).
        vec2 w = vec2(best + a.y, abs(p.z) - a.x + a.y);
        return min(max(w.x, w.y), 0.0f) + length(max(w, 0.0f)) - a.y;
    }
    // Bend_linear's stretch is the same everywhere: no clamping, a division.
    if (kind == kKindBendLinear) return best / bendLinearStretch(a, b);
    return domainClamps(kind) ? best * b.w : best;
}
