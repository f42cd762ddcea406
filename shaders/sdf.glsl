// The SDF function library: exact distance functions after Inigo Quilez
// (https://iquilezles.org/articles/distfunctions/, .../distfunctions2d/) and the CSG
// operators. engine/src/sdf.h implements the same formulas in C++; tests hold them together.
// Every primitive is centred at the origin in its local frame; sizes are half extents here.

float dot2(vec2 v) { return dot(v, v); }
float dot2(vec3 v) { return dot(v, v); }

float sdSphere(vec3 p, float r) { return length(p) - r; }

float sdBox(vec3 p, vec3 b) {
    vec3 q = abs(p) - b;
    return length(max(q, 0.0)) + min(max(q.x, max(q.y, q.z)), 0.0);
}

// b: half extents including the rounding r.
float sdRoundBox(vec3 p, vec3 b, float r) {
    vec3 q = abs(p) - b + r;
    return length(max(q, 0.0)) + min(max(q.x, max(q.y, q.z)), 0.0) - r;
}

// n: unit normal; the solid is where dot(p, n) < offset.
float sdPlane(vec3 p, vec3 n, float offset) { return dot(p, n) - offset; }

// Isosceles triangle prism: base width 2*hw, height h (apex up), bounding box centred; half
// length hl along z. IQ's exact sdTriangleIsosceles, extruded exactly.
float sdTriangularPrism(vec3 p, float hw, float h, float hl) {
    vec2 q = vec2(hw, h);
    vec2 t = vec2(abs(p.x), 0.5 * h - p.y);
    vec2 a = t - q * clamp(dot(t, q) / dot(q, q), 0.0, 1.0);
    vec2 b = t - q * vec2(clamp(t.x / q.x, 0.0, 1.0), 1.0);
    vec2 d = min(vec2(dot(a, a), -(t.x * q.y - t.y * q.x)), vec2(dot(b, b), -(t.y - q.y)));
    float d2 = -sqrt(d.x) * sign(d.y);
    vec2 w = vec2(d2, abs(p.z) - hl);
    return min(max(w.x, w.y), 0.0) + length(max(w, 0.0));
}

float sdTorus(vec3 p, float major, float minor) {
    vec2 q = vec2(length(p.xz) - major, p.y);
    return length(q) - minor;
}

// hh: half height.
float sdCylinder(vec3 p, float r, float hh) {
    vec2 d = abs(vec2(length(p.xz), p.y)) - vec2(r, hh);
    return min(max(d.x, d.y), 0.0) + length(max(d, 0.0));
}

// Capped cone: radius r1 at y = -hh, r2 at y = +hh.
float sdCone(vec3 p, float r1, float hh, float r2) {
    vec2 q = vec2(length(p.xz), p.y);
    vec2 k1 = vec2(r2, hh);
    vec2 k2 = vec2(r2 - r1, 2.0 * hh);
    vec2 ca = vec2(q.x - min(q.x, (q.y < 0.0) ? r1 : r2), abs(q.y) - hh);
    vec2 cb = q - k1 + k2 * clamp(dot(k1 - q, k2) / dot2(k2), 0.0, 1.0);
    float s = (cb.x < 0.0 && ca.y < 0.0) ? -1.0 : 1.0;
    return s * sqrt(min(dot2(ca), dot2(cb)));
}

float sdCapsule(vec3 p, vec3 a, vec3 b, float r) {
    vec3 pa = p - a, ba = b - a;
    float h = clamp(dot(pa, ba) / max(dot(ba, ba), 1e-30), 0.0, 1.0);
    return length(pa - ba * h) - r;
}

// CSG operators. k is the blend radius (IQ's polynomial smooth minimum); k <= 0 is the sharp
// operator, and ties go to the first operand. The vec4 forms carry colour in rgb and the
// distance in w, blending colour by the same factor as the distance.
float opUnion(float a, float b, float k) {
    if (k <= 0.0) return min(a, b);
    float h = clamp(0.5 + 0.5 * (b - a) / k, 0.0, 1.0);
    return mix(b, a, h) - k * h * (1.0 - h);
}

float opIntersection(float a, float b, float k) {
    if (k <= 0.0) return max(a, b);
    float h = clamp(0.5 - 0.5 * (b - a) / k, 0.0, 1.0);
    return mix(b, a, h) + k * h * (1.0 - h);
}

float opDifference(float a, float b, float k) { return opIntersection(a, -b, k); }

vec4 opUnion(vec4 a, vec4 b, float k) {
    if (k <= 0.0) return (b.w < a.w) ? b : a;
    float h = clamp(0.5 + 0.5 * (b.w - a.w) / k, 0.0, 1.0);
    return vec4(mix(b.rgb, a.rgb, h), mix(b.w, a.w, h) - k * h * (1.0 - h));
}

vec4 opIntersection(vec4 a, vec4 b, float k) {
    if (k <= 0.0) return (b.w > a.w) ? b : a;
    float h = clamp(0.5 - 0.5 * (b.w - a.w) / k, 0.0, 1.0);
    return vec4(mix(b.rgb, a.rgb, h), mix(b.w, a.w, h) + k * h * (1.0 - h));
}

vec4 opDifference(vec4 a, vec4 b, float k) { return opIntersection(a, vec4(b.rgb, -b.w), k); }
