// Declarations and helpers of the ray-march kernels, none of which evaluates the scene: the
// scene's march.comp and shade.comp, and finish.comp, which does not depend on it.
//
// Sphere tracing of the generated scene in passes over a band of rows:
//   march:   one invocation per sample (aa x aa per pixel) traces its ray to the first hit and
//            writes the colour of misses and of the depth and steps modes; hits that need
//            shading are appended to a list, which also counts the shade pass's workgroups.
//            It runs only the workgroups whose rays can meet a surface (the host lists them);
//            the host fills the rest of the band with the colour of a miss;
//   shade:   one invocation per listed hit (an indirect dispatch): normal, occlusion, shadows
//            and lighting;
//   overlay: with the ground grid or the box overlay on, one invocation per listed hit draws
//            them over its shaded colour (the march pass draws them over the samples it colours);
//   resolve: with several samples per pixel, one invocation per pixel averages them.
// CPU drivers such as lavapipe run invocations in SIMD lanes and execute every branch that any
// lane takes; split this way, misses never pay for shading and every shading lane has a hit.
// Each pass is its own module and pipeline: a kernel holds only the code its pass reaches, and
// the overlays and the resolve, which do not depend on the scene, are compiled once per renderer.
//
// Rays are generated and clipped exactly as engine/src/camera.h does on the CPU (the tests trace
// the same rays with the reference evaluator). Normals use the four-tap tetrahedral difference
// of the original system; soft shadows are IQ's improved technique
// (https://iquilezles.org/articles/rmshadows/); ambient occlusion samples along the normal.

layout(local_size_x = SDFCSG_RAYMARCH_GROUP_X, local_size_y = SDFCSG_RAYMARCH_GROUP_Y) in;

struct FrameLight {
    vec4 direction; // xyz: unit vector towards the light
    vec4 inverse;   // xyz: 1 / direction, per component (finite), for slab tests
    vec4 color;     // rgb: colour times intensity
};

// Mirrors FrameUniform in engine/src/render.cpp (std140).
layout(std140, set = 0, binding = SDFCSG_BINDING_FRAME) uniform Frame {
    vec4 eye;        // xyz; w: tan(fov / 2)
    vec4 right;      // xyz; w: aspect (width / height)
    vec4 up;         // xyz; w: pixel footprint at unit distance
    vec4 forward;    // xyz; w: minimum hit epsilon
    vec4 clipMin;    // xyz: ray clip box; w: far distance
    vec4 clipMax;    // xyz; w: sample footprint at unit distance (the pixel's / aa)
    vec4 background; // rgb as given (output space)
    vec4 sky;        // rgb: background in linear space, for the ambient term
    vec4 distances;  // x: depth-mode near, y: depth-mode far, z: occlusion scale, w: shadow reach
    uvec4 size;      // width, height, mode, flags
    uvec4 counts;    // aa, light count, node count, selected node
    FrameLight lights[SDFCSG_MAX_LIGHTS];
    uvec4 surfaceBoxCount; // x: regions that hold every surface (0: use the clip box alone)
    // Pairs: a box (min, w = 0; max), or a half-space dot(p, n) < offset (n, w = 1; offset, ...).
    vec4 surfaceBoxes[2 * SDFCSG_MAX_CLIP_BOXES];
    vec4 grid; // ground grid: xy: centre (x, z); z: height of its plane; w: line spacing
} frame;

// The band this dispatch computes (engine/src/render.cpp): its first pixel row, and where its
// first sample's colour goes in Colors.
layout(push_constant) uniform Band {
    uint firstRow;
    uint colorOffset;
} band;

layout(std430, set = 0, binding = SDFCSG_BINDING_PIXELS) writeonly buffer Pixels {
    uint pixels[];
};

// Per pixel, from its first sample: x: ray parameter of the hit (negative: a miss), y: steps.
layout(std430, set = 0, binding = SDFCSG_BINDING_INFO) writeonly buffer Info {
    vec2 info[];
};

// Packed RGBA8 per sample of the band, row-major over the band's sample grid; with one sample
// per pixel this is the Pixels buffer itself (colorOffset: the band's first pixel).
layout(std430, set = 0, binding = SDFCSG_BINDING_SAMPLES) buffer Colors {
    uint colors[];
};

// The workgroups of the band's sample grid that the march pass runs, one per workgroup of the
// dispatch: x | y << 16.
layout(std430, set = 0, binding = SDFCSG_BINDING_TILES) readonly buffer Tiles {
    uint tiles[];
};

// Hits of the band that need shading: x: sample index in the band, y: ray parameter (bits).
// count and groups are cleared before the march pass; groups, 1, 1 are the shade pass's
// indirect dispatch.
layout(std430, set = 0, binding = SDFCSG_BINDING_HITS) buffer Hits {
    uint count;
    uint groups;
    uint groupsY;
    uint groupsZ;
    uvec2 hits[];
};

float hitEpsilon(float t) {
    return max(frame.forward.w, 0.5 * t * frame.clipMax.w);
}

vec3 rayDirection(vec2 xy) {
    vec2 size = vec2(frame.size.xy);
    float u = (2.0 * xy.x / size.x - 1.0) * frame.eye.w * frame.right.w;
    float v = (1.0 - 2.0 * xy.y / size.y) * frame.eye.w;
    return normalize(frame.forward.xyz + u * frame.right.xyz + v * frame.up.xyz);
}

vec3 safeInverse(vec3 d) {
    vec3 s = mix(vec3(-1.0e-20), vec3(1.0e-20), greaterThanEqual(d, vec3(0.0)));
    return 1.0 / mix(d, s, lessThan(abs(d), vec3(1.0e-20)));
}

// Slab test against a box; x: entry (clamped to 0), y: exit. Misses when x > y.
vec2 clipRay(vec3 bmin, vec3 bmax, vec3 ro, vec3 rd) {
    vec3 inv = safeInverse(rd);
    vec3 t0 = (bmin - ro) * inv;
    vec3 t1 = (bmax - ro) * inv;
    vec3 lo = min(t0, t1), hi = max(t0, t1);
    return vec2(max(max(lo.x, lo.y), max(lo.z, 0.0)), min(min(hi.x, hi.y), hi.z));
}

// Entry and exit of a ray in surface part i (see Frame); misses when x > y.
vec2 partInterval(uint i, vec3 ro, vec3 rd) {
    vec4 a = frame.surfaceBoxes[2u * i], b = frame.surfaceBoxes[2u * i + 1u];
    if (a.w == 0.0) return clipRay(a.xyz, b.xyz, ro, rd);
    float dn = dot(rd, a.xyz), on = dot(ro, a.xyz);
    float tPlane = (b.x - on) / (abs(dn) < 1.0e-20 ? 1.0e-20 : dn);
    if (on < b.x) return vec2(0.0, dn > 0.0 ? tPlane : 1.0e30);
    return dn < 0.0 ? vec2(tPlane, 1.0e30) : vec2(1.0, 0.0);
}

struct Trace {
    float t;     // hit: ray parameter; negative for a miss
    uint steps;  // march iterations
    vec3 n;      // surface normal (normals and shaded modes)
    float ao;    // 1: open, 0: occluded
    vec4 shadow; // per light: 1 lit, 0 shadowed
};

vec3 heat(float x) {
    x = clamp(x, 0.0, 1.0);
    // Blue -> cyan -> green -> yellow -> red.
    return clamp(vec3(1.5 - abs(4.0 * x - 3.0), 1.5 - abs(4.0 * x - 2.0), 1.5 - abs(4.0 * x - 1.0)),
                 0.0, 1.0);
}

float pow48(float x) {
    float x2 = x * x, x4 = x2 * x2, x8 = x4 * x4, x16 = x8 * x8;
    return x16 * x16 * x16;
}

// Whether a sample's colour needs the shade pass: hits in the shaded and normals modes.
bool needsShading(Trace r) {
    uint mode = frame.size.z;
    return r.t >= 0.0 && (mode == SDFCSG_MODE_SHADED || mode == SDFCSG_MODE_NORMALS);
}

// The colour of a sample that needs no shading (see needsShading).
vec3 plainColor(Trace r) {
    uint mode = frame.size.z;
    // Steps on a log scale: a handful already shows, and 256 is red.
    if (mode == SDFCSG_MODE_STEPS) return heat(log2(1.0 + float(r.steps)) / log2(1.0 + float(SDFCSG_MAX_STEPS)));
    if (r.t < 0.0) return mode == SDFCSG_MODE_SHADED ? frame.background.rgb : vec3(0.0);
    float x = (r.t - frame.distances.x) / max(frame.distances.y - frame.distances.x, 1e-6);
    return vec3(1.0 - 0.85 * clamp(x, 0.0, 1.0)); // depth
}

// Thin edges of node boxes in front of the hit: where the ray enters or leaves a box close to
// one of its edges (the second-smallest distance to a face plane is within a pixel or so).
vec4 boxOverlay(vec3 ro, vec3 rd, float tHit) {
    uint flags = frame.size.w;
    uint first = 0u, last = frame.counts.z;
    if ((flags & SDFCSG_FLAG_BOXES_SELECTED) != 0u) {
        first = frame.counts.w;
        last = min(first + 1u, frame.counts.z);
    }
    float tLimit = tHit < 0.0 ? frame.clipMin.w : tHit;
    vec4 result = vec4(0.0);
    for (uint i = first; i < last; ++i) {
        vec3 bmin = nodes[i].bmin.xyz, bmax = nodes[i].bmax.xyz;
        if (any(greaterThan(bmax - bmin, vec3(1.0e29))) || any(greaterThan(bmin, bmax))) continue;
        vec2 range = clipRay(bmin, bmax, ro, rd);
        if (range.x > range.y) continue;
        for (int e = 0; e < 2; ++e) {
            float t = e == 0 ? range.x : range.y;
            if (t <= 0.0 || t > tLimit) continue;
            vec3 p = ro + rd * t;
            vec3 d = min(abs(p - bmin), abs(p - bmax));
            // Second smallest component: distance to the nearest edge on this face.
            float edge = max(min(d.x, d.y), min(max(d.x, d.y), d.z));
            float width = 1.2 * t * frame.up.w;
            if (edge < width) {
                float a = 1.0 - edge / width;
                result = max(result, vec4(1.0, 0.85, 0.2, 0.9 * a));
            }
        }
    }
    return result;
}

// How much of the sample the ground grid covers where the ray meets the grid's plane in front
// of the hit (tHit < 0: a miss): lines frame.grid.w apart, 2 SDFCSG_GRID_HALF_LINES + 1 each
// way, about a pixel wide, fading out where a pixel spans so much of the spacing that they
// would alias.
float gridCoverage(vec3 ro, vec3 rd, float tHit) {
    float spacing = frame.grid.w;
    float tPlane = (frame.grid.z - ro.y) / (abs(rd.y) < 1.0e-20 ? 1.0e-20 : rd.y);
    if (tPlane <= 0.0 || (tHit >= 0.0 && tPlane > tHit) || tPlane > frame.clipMin.w) return 0.0;
    vec2 q = (ro.xz + rd.xz * tPlane - frame.grid.xy) / spacing; // in spacings from the centre
    if (any(greaterThan(abs(q), vec2(float(SDFCSG_GRID_HALF_LINES) + 0.5)))) return 0.0;
    vec2 toLine = abs(q - round(q));
    float width = tPlane * frame.up.w / spacing; // a pixel, in spacings, across the ray
    float along = width / max(abs(rd.y), 0.05);  // ... and along it, where the plane tilts away
    float line = 1.0 - smoothstep(0.5 * width, 1.5 * width, min(toLine.x, toLine.y));
    bool axis = (abs(round(q.x)) < 0.5 && toLine.x <= toLine.y) ||
                (abs(round(q.y)) < 0.5 && toLine.y <= toLine.x);
    return line * (axis ? 0.7 : 0.4) * (1.0 - smoothstep(0.1, 0.3, along));
}

uint packColor(vec3 c) {
    uvec3 u = uvec3(clamp(c, 0.0, 1.0) * 255.0 + 0.5);
    return u.r | (u.g << 8) | (u.b << 16) | (255u << 24);
}

vec3 unpackColor(uint c) {
    return vec3(uvec3(c, c >> 8, c >> 16) & 255u) / 255.0;
}

// The sample's final colour: the ground grid and the box edges drawn over it.
uint finish(vec3 c, vec3 ro, vec3 rd, float t) {
    if ((frame.size.w & SDFCSG_FLAG_GRID) != 0u) c = mix(c, vec3(0.12), gridCoverage(ro, rd, t));
    if ((frame.size.w & (SDFCSG_FLAG_BOXES_ALL | SDFCSG_FLAG_BOXES_SELECTED)) != 0u) {
        vec4 o = boxOverlay(ro, rd, t);
        c = mix(c, o.rgb, o.a);
    }
    return packColor(c);
}

// Sample `sampleIndex` of the band (row-major over its width * aa columns): its pixel and its ray.
void sampleRay(uint sampleIndex, out uvec2 pixel, out vec3 rd) {
    uint aa = max(frame.counts.x, 1u);
    uvec2 s = uvec2(sampleIndex % (frame.size.x * aa), sampleIndex / (frame.size.x * aa));
    pixel = s / aa + uvec2(0u, band.firstRow);
    vec2 offset = (vec2(s % aa) + 0.5) / float(aa);
    rd = rayDirection(vec2(pixel) + offset);
}

