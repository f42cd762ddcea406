// The SDF function library: exact distance functions after Inigo Quilez
// (https://iquilezles.org/articles/distfunctions/, .../distfunctions2d/, .../smin/) and the CSG
// operators. engine/src/sdf.h implements the same formulas line by line in C++; tests hold the
// two together. Every primitive is centred at the origin of its local frame and takes the
// kernel parameters that packNodes() derives (half extents, half heights), not the JSON values.

float dot2(vec2 v) { return dot(v, v); }
float dot2(vec3 v) { return dot(v, v); }

float sdSphere(vec3 p, float r) { return length(p) - r; }

// b: half extents.
float sdBox(vec3 p, vec3 b) {
    vec3 q = abs(p) - b;
    return length(max(q, 0.0)) + min(max(q.x, max(q.y, q.z)), 0.0);
}

// b: half extents including the rounding r (r <= min(b)).
float sdRoundBox(vec3 p, vec3 b, float r) {
    vec3 q = abs(p) - b + r;
    return length(max(q, 0.0)) + min(max(q.x, max(q.y, q.z)), 0.0) - r;
}

// n: unit normal; the solid is where dot(p, n) < offset.
float sdPlane(vec3 p, vec3 n, float offset) { return dot(p, n) - offset; }

// Isosceles triangle in xy (base width 2*hw at y = -h/2, apex at y = +h/2) extruded to z in
// [-hl, hl]: IQ's exact sdTriangleIsosceles (apex at t = 0, base at t.y = h) and opExtrusion.
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

// Ring around the y axis.
float sdTorus(vec3 p, float major, float minor) {
    vec2 q = vec2(length(p.xz) - major, p.y);
    return length(q) - minor;
}

// Capped cylinder along y; hh: half height.
float sdCylinder(vec3 p, float r, float hh) {
    vec2 d = abs(vec2(length(p.xz), p.y)) - vec2(r, hh);
    return min(max(d.x, d.y), 0.0) + length(max(d, 0.0));
}

// IQ's exact sdCappedCone: radius r1 at y = -hh, r2 at y = +hh.
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

// CSG operators: IQ's polynomial smooth minimum with blend radius k, and smooth max(a, b) =
// -smin(-a, -b). Once the operands differ by k or more the blend factor is exactly 0 or 1, so
// those cases return an operand unchanged: this makes bounds skipping exact in floating point
// (the skipped operand could not have changed a single bit) and gives k = 0 the sharp operator
// (ties go to the first operand). Selects rather than branches: both sides are a few
// instructions, and every branch costs CPU drivers (lavapipe) compile time. The vec4 forms carry
// colour in rgb and the distance in w; colour blends by the same factor.
// Difference(a, b) = max(a, -b).
float opUnion(float a, float b, float k) {
    float h = clamp(0.5 + 0.5 * (b - a) / max(k, 1e-30), 0.0, 1.0);
    float blend = mix(b, a, h) - k * h * (1.0 - h);
    float r = (a - b >= k) ? b : blend;
    return (b - a >= k) ? a : r;
}

float opIntersection(float a, float b, float k) {
    float h = clamp(0.5 - 0.5 * (b - a) / max(k, 1e-30), 0.0, 1.0);
    float blend = mix(b, a, h) + k * h * (1.0 - h);
    float r = (b - a >= k) ? b : blend;
    return (a - b >= k) ? a : r;
}

float opDifference(float a, float b, float k) { return opIntersection(a, -b, k); }

vec4 opUnion(vec4 a, vec4 b, float k) {
    float h = clamp(0.5 + 0.5 * (b.w - a.w) / max(k, 1e-30), 0.0, 1.0);
    vec4 blend = vec4(mix(b.rgb, a.rgb, h), mix(b.w, a.w, h) - k * h * (1.0 - h));
    vec4 r = (a.w - b.w >= k) ? b : blend;
    return (b.w - a.w >= k) ? a : r;
}

vec4 opIntersection(vec4 a, vec4 b, float k) {
    float h = clamp(0.5 - 0.5 * (b.w - a.w) / max(k, 1e-30), 0.0, 1.0);
    vec4 blend = vec4(mix(b.rgb, a.rgb, h), mix(b.w, a.w, h) + k * h * (1.0 - h));
    vec4 r = (b.w - a.w >= k) ? b : blend;
    return (a.w - b.w >= k) ? a : r;
}

vec4 opDifference(vec4 a, vec4 b, float k) { return opIntersection(a, vec4(b.rgb, -b.w), k); }

// The operators at k = 0, for code that knows k is 0: the same bits as opUnion(a, b, 0.0) and
// the others (the blend is never chosen), in one comparison. The full forms cost lavapipe's
// compiler and every evaluation their unused blend: for the house scene, a sixth of the
// ray-march kernels' compile time.
float sharpUnion(float a, float b) { return a <= b ? a : b; }
float sharpIntersection(float a, float b) { return a >= b ? a : b; }
float sharpDifference(float a, float b) { return a >= -b ? a : -b; }
vec4 sharpUnion(vec4 a, vec4 b) { return a.w <= b.w ? a : b; }
vec4 sharpIntersection(vec4 a, vec4 b) { return a.w >= b.w ? a : b; }
vec4 sharpDifference(vec4 a, vec4 b) { return a.w >= -b.w ? a : vec4(b.rgb, -b.w); }

// Tap i (0..3) of the four-tap tetrahedral difference, the tetrahedron k = (1, -1): k.xyy,
// k.yyx, k.yxy, k.xxx. The normal at p is normalize(sum of tap(i) * f(p + tap(i) * e)).
vec3 tetraTap(int i) {
    return i == 0 ? vec3(1.0, -1.0, -1.0)
         : i == 1 ? vec3(-1.0, -1.0, 1.0)
         : i == 2 ? vec3(-1.0, 1.0, -1.0)
                  : vec3(1.0);
}
