#version 450
// Sphere tracing of the generated scene in passes over a band of rows (kPass):
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
// Each pass is its own pipeline (kPass), and the driver compiles only the code its pass reaches:
// the overlays, which the viewer uses, cost the shade kernel nothing.
//
// Rays are generated and clipped exactly as engine/src/camera.h does on the CPU (the tests trace
// the same rays with the reference evaluator). Normals use the four-tap tetrahedral difference
// of the original system; soft shadows are IQ's improved technique
// (https://iquilezles.org/articles/rmshadows/); ambient occlusion samples along the normal.
#extension GL_GOOGLE_include_directive : require

#include "shared.h"
#include "sdf.glsl"
#include "nodes.glsl"
#include "scene.glsl"

layout(local_size_x = SDFCSG_RAYMARCH_GROUP_X, local_size_y = SDFCSG_RAYMARCH_GROUP_Y) in;
layout(constant_id = SDFCSG_SPEC_RAYMARCH_PASS) const uint kPass = SDFCSG_RAYMARCH_PASS_MARCH;

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

// Steps per shadow ray, each a full scene evaluation. A ray that grazes a surface crawls along
// it in short steps; one that runs out of them before passing it ends too lit, and with 16 a
// patch of the snowman's drift showed the edge where that began. 24 cost about 1% of a frame.
const int kShadowSteps = 24;
const float kShadowSharpness = 10.0;

struct Trace {
    float t;     // hit: ray parameter; negative for a miss
    uint steps;  // march iterations
    vec3 n;      // surface normal (normals and shaded modes)
    float ao;    // 1: open, 0: occluded
    vec4 shadow; // per light: 1 lit, 0 shadowed
};

// The march pass: the first hit along the ray, clipped to the boxes that hold surfaces.
Trace march(vec3 ro, vec3 rd) {
    Trace r = Trace(-1.0, 0u, vec3(0.0), 1.0, vec4(1.0));
    vec2 range = clipRay(frame.clipMin.xyz, frame.clipMax.xyz, ro, rd);
    if (frame.surfaceBoxCount.x > 0u) {
        // Start at the first entry into a box that holds surfaces, end at the last exit.
        vec2 parts = vec2(1.0e30, -1.0e30);
        for (uint i = 0u; i < frame.surfaceBoxCount.x; ++i) {
            vec2 b = partInterval(i, ro, rd);
            if (b.x <= b.y) parts = vec2(min(parts.x, b.x), max(parts.y, b.y));
        }
        range = vec2(max(range.x, parts.x), min(range.y, parts.y));
    }
    float tFar = min(range.y, frame.clipMin.w);
    float t = range.x;
    bool marching = t <= tFar;
    while (marching) {
        float d = sceneDistance(ro + rd * t);
        r.steps += 1u;
        if (d < hitEpsilon(t)) {
            r.t = t;
            marching = false;
        } else {
            t += d;
            marching = t <= tFar && r.steps < SDFCSG_MAX_STEPS;
        }
    }
    return r;
}

// The shade pass: normal, occlusion and shadows at the hit r.t. All scene evaluations go
// through one call of sceneDistance in one loop, driven by a small state machine: four normal
// taps, five occlusion taps and one shadow ray per light, each evaluating the scene at
// origin + dir * t. Two reasons, both about lavapipe: its compiler inlines every call site, so
// one site keeps the JIT compile short; and a lane that has finished its occlusion taps
// evaluates its shadow steps in the same instructions as its neighbours' taps instead of
// idling through them.
const uint kNormal = 1u, kOcclusion = 2u, kShadow = 3u, kDone = 4u;

// The tetrahedron k = (1, -1): k.xyy, k.yyx, k.yxy, k.xxx.
vec3 tetraTap(int i) {
    return i == 0 ? vec3(1.0, -1.0, -1.0)
         : i == 1 ? vec3(-1.0, -1.0, 1.0)
         : i == 2 ? vec3(-1.0, 1.0, -1.0)
                  : vec3(1.0);
}

void surface(vec3 ro, vec3 rd, inout Trace r) {
    uint mode = frame.size.z;
    uint flags = frame.size.w;
    uint lightCount = (flags & SDFCSG_FLAG_SHADOWS) != 0u ? frame.counts.y : 0u;
    float aoScale = frame.distances.z;
    float shadowReach = frame.distances.w;

    vec3 light0 = frame.lights[0].direction.xyz, inverse0 = frame.lights[0].inverse.xyz;
    vec3 light1 = frame.lights[1].direction.xyz, inverse1 = frame.lights[1].inverse.xyz;
    vec3 light2 = frame.lights[2].direction.xyz, inverse2 = frame.lights[2].inverse.xyz;
    vec3 light3 = frame.lights[3].direction.xyz, inverse3 = frame.lights[3].inverse.xyz;

    float eps = hitEpsilon(r.t);
    vec3 p = ro + rd * r.t; // the hit, then the hit lifted off the surface

    // Where each shadow ray can end, worked out here rather than in the loop (whose every
    // iteration would run it): occluders lie inside the clip box and the boxes that hold
    // surfaces, so a ray ends where it leaves them. From the hit; the ray starts from the
    // hit lifted by 2 eps, hence the margin.
    vec4 ends = vec4(0.0);
    for (uint i = 0u; i < lightCount; ++i) {
        vec3 l = i == 0u ? light0 : i == 1u ? light1 : i == 2u ? light2 : light3;
        vec3 inv = i == 0u ? inverse0 : i == 1u ? inverse1 : i == 2u ? inverse2 : inverse3;
        vec3 t0 = (frame.clipMin.xyz - p) * inv, t1 = (frame.clipMax.xyz - p) * inv;
        vec3 far = max(t0, t1);
        float end = min(min(far.x, far.y), min(far.z, shadowReach));
        if (frame.surfaceBoxCount.x > 0u) {
            float lastExit = 0.0;
            for (uint b = 0u; b < frame.surfaceBoxCount.x; ++b) {
                vec2 range = partInterval(b, p, l);
                if (range.x <= range.y) lastExit = max(lastExit, range.y);
            }
            end = min(end, lastExit);
        }
        ends = mix(ends, vec4(end), equal(uvec4(0u, 1u, 2u, 3u), uvec4(i)));
    }
    uint phase = kNormal;
    vec3 origin = p, dir = tetraTap(0);
    float t = eps;
    int tap = 0;
    float weight = 1.0;
    uint light = 0u;
    float res = 1.0, ph = 1.0e20, shadowEnd = 0.0; // shadow ray (IQ's improved soft shadow)

    while (phase != kDone) {
        float d = sceneDistance(origin + dir * t);
        bool nextLight = false;

        if (phase == kNormal) {
            r.n += dir * d;
            tap += 1;
            dir = tetraTap(tap);
            if (tap == 4) {
                r.n = normalize(r.n);
                // Lift off the surface so occlusion and shadow rays do not re-hit it at once.
                p += r.n * (2.0 * eps);
                origin = p;
                if (mode != SDFCSG_MODE_SHADED) {
                    phase = kDone;
                } else if ((flags & SDFCSG_FLAG_AO) != 0u) {
                    phase = kOcclusion;
                    tap = 0;
                    r.ao = 0.0; // accumulates occlusion until the last tap
                    dir = r.n;
                    t = aoScale * 0.01;
                } else {
                    nextLight = true;
                }
            }
        } else if (phase == kOcclusion) {
            r.ao += (t - d) * weight;
            weight *= 0.95;
            tap += 1;
            t += aoScale * 0.03;
            if (tap == 5) {
                r.ao = clamp(1.0 - 3.0 * r.ao / aoScale, 0.0, 1.0);
                nextLight = true;
            }
        } else { // kShadow
            if (d < eps * 0.5) {
                res = 0.0;
            } else {
                float y = d * d / (2.0 * ph);
                float w = sqrt(max(d * d - y * y, 0.0));
                res = min(res, kShadowSharpness * w / max(0.0, t - y));
                ph = d;
                t += max(d, eps);
            }
            tap += 1;
            if (res < 0.02 || t >= shadowEnd || tap >= kShadowSteps) {
                r.shadow = mix(r.shadow, vec4(res < 0.02 ? 0.0 : res),
                               equal(uvec4(0u, 1u, 2u, 3u), uvec4(light)));
                light += 1u;
                nextLight = true;
            }
        }

        if (nextLight) {
            // Light directions come from locals with selects: indexing the uniform array by a
            // per-lane index would gather in every iteration of this loop on CPU drivers.
            dir = light == 0u ? light0 : light == 1u ? light1 : light == 2u ? light2 : light3;
            shadowEnd = light == 0u ? ends.x : light == 1u ? ends.y : light == 2u ? ends.z : ends.w;
            phase = light < lightCount ? kShadow : kDone;
            t = 2.0 * eps;
            // A light behind the surface needs no shadow (Lambert is zero): end it at once.
            tap = dot(r.n, dir) > 0.0 ? 0 : kShadowSteps;
            res = 1.0;
            ph = 1.0e20;
        }
    }
}

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

// Scene colours are treated as gamma 2 (sRGB, close enough): squared to shade, square-rooted
// back; pow() is slow on CPU drivers. Lambert and Blinn-Phong per light, an ambient term from the
// background, occlusion and shadows from surface().
vec3 shade(vec3 ro, vec3 rd, Trace r) {
    uint mode = frame.size.z;
    vec3 n = r.n;
    if (mode == SDFCSG_MODE_NORMALS) return n * 0.5 + 0.5;

    vec3 albedo = sceneSample(ro + rd * r.t).rgb;
    albedo *= albedo;
    vec3 col = albedo * (0.10 + 0.15 * frame.sky.rgb * (0.5 + 0.5 * n.y)) * r.ao;
    // Unrolled with constant indices: a per-lane index into r.shadow would keep it in memory.
    for (int i = 0; i < SDFCSG_MAX_LIGHTS; ++i) {
        vec3 l = frame.lights[i].direction.xyz;
        float lambert = max(dot(n, l), 0.0);
        float spec = pow48(max(dot(n, normalize(l - rd)), 0.0)) * 0.25;
        float lit = uint(i) < frame.counts.y ? r.shadow[i] * lambert : 0.0;
        col += frame.lights[i].color.rgb * lit * (albedo + spec);
    }
    col = sqrt(col);
    // Fade into the background towards the far limit so a ground plane has no hard edge.
    float fog = smoothstep(0.6, 1.0, r.t / frame.clipMin.w);
    return mix(col, frame.background.rgb, fog);
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


void marchPass() {
    uint aa = max(frame.counts.x, 1u);
    uint tile = tiles[gl_WorkGroupID.x];
    uvec2 s = uvec2(tile & 0xffffu, tile >> 16) * gl_WorkGroupSize.xy + gl_LocalInvocationID.xy;
    if (s.x >= frame.size.x * aa || s.y / aa + band.firstRow >= frame.size.y) return;
    uint sampleIndex = s.y * frame.size.x * aa + s.x;
    uvec2 pixel;
    vec3 rd;
    sampleRay(sampleIndex, pixel, rd);
    vec3 ro = frame.eye.xyz;
    Trace r = march(ro, rd);
    if (all(equal(s % aa, uvec2(0u)))) info[pixel.y * frame.size.x + pixel.x] = vec2(r.t, float(r.steps));
    if (needsShading(r)) {
        uint slot = atomicAdd(count, 1u);
        if (slot % (SDFCSG_RAYMARCH_GROUP_X * SDFCSG_RAYMARCH_GROUP_Y) == 0u) atomicAdd(groups, 1u);
        hits[slot] = uvec2(sampleIndex, floatBitsToUint(r.t));
    } else {
        colors[band.colorOffset + sampleIndex] = finish(plainColor(r), ro, rd, r.t);
    }
}

void shadePass() {
    uint slot = gl_WorkGroupID.x * (SDFCSG_RAYMARCH_GROUP_X * SDFCSG_RAYMARCH_GROUP_Y) +
                gl_LocalInvocationIndex;
    if (slot >= count) return;
    uvec2 hit = hits[slot];
    uvec2 pixel;
    vec3 rd;
    sampleRay(hit.x, pixel, rd);
    vec3 ro = frame.eye.xyz;
    Trace r = Trace(uintBitsToFloat(hit.y), 0u, vec3(0.0), 1.0, vec4(1.0));
    surface(ro, rd, r);
    colors[band.colorOffset + hit.x] = packColor(shade(ro, rd, r));
}

void resolvePass() {
    uvec2 pixel = gl_GlobalInvocationID.xy + uvec2(0u, band.firstRow);
    if (any(greaterThanEqual(pixel, frame.size.xy))) return;
    uint aa = max(frame.counts.x, 1u);
    uint row = frame.size.x * aa;
    uint first = gl_GlobalInvocationID.y * aa * row + gl_GlobalInvocationID.x * aa;
    vec3 sum = vec3(0.0);
    for (uint sy = 0u; sy < aa; ++sy)
        for (uint sx = 0u; sx < aa; ++sx)
            sum += unpackColor(colors[first + sy * row + sx]);
    pixels[pixel.y * frame.size.x + pixel.x] = packColor(sum / float(aa * aa));
}

void overlayPass() {
    uint slot = gl_WorkGroupID.x * (SDFCSG_RAYMARCH_GROUP_X * SDFCSG_RAYMARCH_GROUP_Y) +
                gl_LocalInvocationIndex;
    if (slot >= count) return;
    uvec2 hit = hits[slot];
    uvec2 pixel;
    vec3 rd;
    sampleRay(hit.x, pixel, rd);
    uint i = band.colorOffset + hit.x;
    colors[i] = finish(unpackColor(colors[i]), frame.eye.xyz, rd, uintBitsToFloat(hit.y));
}

void main() {
    if (kPass == SDFCSG_RAYMARCH_PASS_MARCH) marchPass();
    else if (kPass == SDFCSG_RAYMARCH_PASS_SHADE) shadePass();
    else if (kPass == SDFCSG_RAYMARCH_PASS_RESOLVE) resolvePass();
    else overlayPass();
}
