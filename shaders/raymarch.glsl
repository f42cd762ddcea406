// Declarations and helpers of the ray-march kernels, none of which evaluates the scene: the
// scene's march.comp and shade.comp, and clip.comp, light.comp and finish.comp, which do not
// depend on it.
//
// Sphere tracing of the generated scene in passes over a band of rows:
//   clip:    one invocation per sample (aa x aa per pixel) finds the part of its ray to march:
//            inside the clip box, from the first entry into a region that holds surfaces to
//            the last exit;
//   march:   one invocation per sample traces that part of its ray to the first hit and
//            writes the colour of misses and of the depth and steps modes; hits that need
//            shading are appended to a list, which also counts the shade pass's workgroups.
//            Both run only the workgroups whose rays can meet a surface (the host lists them);
//            the host fills the rest of the band with the colour of a miss;
//   ends:    one invocation per listed hit (an indirect dispatch): where the shadow ray towards
//            each light can end, leaving the clip box and the boxes that hold surfaces;
//   shade:   one invocation per listed hit: colour, normal, occlusion and shadows;
//   light:   one invocation per listed hit: lighting, from what the shade pass found;
//   resolve: with several samples per pixel, one invocation per pixel averages them;
//   overlay: with the ground grid or the box overlay on, one invocation per pixel draws them
//            over its colour, in front of its first sample's hit.
// CPU drivers such as lavapipe run invocations in SIMD lanes and execute every branch that any
// lane takes; split this way, misses never pay for shading and every shading lane has a hit.
// Each pass is its own pipeline: a kernel holds only the code its pass reaches, and the passes
// that do not depend on the scene (clip.comp, light.comp, finish.comp) are compiled once per
// context.
// Whatever a scene kernel holds, each new scene pays for in its compile (drawing the overlays in
// the march pass took a third of its compile for a one-sphere scene, clipping the rays a fifth of
// the house's; the shadow-ray ends and the lighting a quarter of the shade kernel's), so the
// scene kernels hold nothing that can live elsewhere.
//
// Rays are generated and clipped exactly as engine/src/render/camera.h does on the CPU (the tests trace
// the same rays with the reference evaluator). Normals use the four-tap tetrahedral difference
// of the original system; soft shadows are IQ's improved technique
// (https://iquilezles.org/articles/rmshadows/); ambient occlusion samples along the normal.

layout(local_size_x = SDFCSG_RAYMARCH_GROUP_X, local_size_y = SDFCSG_RAYMARCH_GROUP_Y) in;

struct FrameLight {
    vec4 direction; // xyz: unit vector towards the light
    vec4 inverse;   // xyz: 1 / direction, per component (finite), for slab tests
    vec4 color;     // rgb: colour times intensity
};

// Mirrors FrameUniform in engine/src/render/render.cpp (std140): the frame's values. No branch or loop
// may depend on these alone (see Control).
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
    FrameLight lights[SDFCSG_MAX_LIGHTS];
    // The parts that hold every surface (control.parts.x of them), pairs: a box (min, w = 0;
    // max), or a half-space dot(p, n) < offset (n, w = 1; offset, ...).
    vec4 surfaceBoxes[2 * SDFCSG_MAX_CLIP_BOXES];
    vec4 grid; // ground grid: xy: centre (x, z); z: height of its plane; w: line spacing
} frame;

// Mirrors FrameControl in engine/src/render/render.cpp: the frame's values that branches and loops
// read. A storage buffer, not a uniform block: lavapipe (Mesa 22.3) may specialise a kernel on
// the uniform-block values that decide its branches, and then compiles it again whenever the
// block or the push constants change, which they do at every band's dispatch. Whether it does
// depends on its heuristics and on the code, the scene's included: with these values in Frame,
// the march kernel did for smooth_blend, a third of its frame in depth mode.
// Render.OtherValuesCompileNothing checks that no kernel recompiles. Only these few values
// are in a storage buffer, whose every load costs CPU drivers a bounds check.
layout(std430, set = 0, binding = SDFCSG_BINDING_CONTROL) readonly buffer Control {
    uvec4 size;   // width, height, mode, flags
    uvec4 counts; // aa, light count, node count, selected node
    uvec4 parts;  // x: surface parts in Frame.surfaceBoxes (0: the clip box alone)
} control;

// The band this dispatch computes (engine/src/render/render.cpp): its first pixel row, and where its
// first sample's colour goes in Colors.
layout(push_constant) uniform Band {
    uint firstRow;
    uint colorOffset;
} band;

layout(std430, set = 0, binding = SDFCSG_BINDING_PIXELS) buffer Pixels {
    uint pixels[];
};

// Per pixel, from its first sample: x: ray parameter of the hit (negative: a miss), y: steps.
layout(std430, set = 0, binding = SDFCSG_BINDING_INFO) buffer Info {
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
// count and groups are cleared before the march pass; groups, 1, 1 are the indirect dispatch of
// the ends, shade and light passes.
layout(std430, set = 0, binding = SDFCSG_BINDING_HITS) buffer Hits {
    uint count;
    uint groups;
    uint groupsY;
    uint groupsZ;
    uvec2 hits[];
};

// Per listed hit (the index into hits), four vec4s: 0: where each light's shadow ray can end
// (ends pass); 1: the ray (direction, ray parameter of the hit) from the march pass, which the
// shade pass reads and replaces with normal and occlusion; from the shade pass, 2: shadow per
// light, 3: albedo. The shade kernel takes its ray from here: working it out from the sample
// index (hitRay) took a fifth of its compile on lavapipe.
layout(std430, set = 0, binding = SDFCSG_BINDING_SURFACES) buffer Surfaces {
    vec4 surfaces[];
};

// Per sample of the band (row-major), two vec4s from the clip pass: its ray and the part of it
// to march. 0: the direction, and where the march begins; 1: x: where it ends (nothing where it
// begins later). The march kernel takes its ray from here: working it out from the sample
// (sampleRay) took about a third of its compile on lavapipe.
layout(std430, set = 0, binding = SDFCSG_BINDING_RANGES) buffer Ranges {
    vec4 ranges[];
};

// The index into hits of this invocation of the ends, shade and light passes.
uint hitSlot() {
    return gl_WorkGroupID.x * (SDFCSG_RAYMARCH_GROUP_X * SDFCSG_RAYMARCH_GROUP_Y) +
           gl_LocalInvocationIndex;
}

float hitEpsilon(float t) {
    return max(frame.forward.w, 0.5 * t * frame.clipMax.w);
}

vec3 rayDirection(vec2 xy) {
    vec2 size = vec2(control.size.xy);
    float u = (2.0 * xy.x / size.x - 1.0) * frame.eye.w * frame.right.w;
    float v = (1.0 - 2.0 * xy.y / size.y) * frame.eye.w;
    return normalize(frame.forward.xyz + u * frame.right.xyz + v * frame.up.xyz);
}

vec3 safeInverse(vec3 d) {
    vec3 s = mix(vec3(-1.0e-20), vec3(1.0e-20), greaterThanEqual(d, vec3(0.0)));
    return 1.0 / mix(d, s, lessThan(abs(d), vec3(1.0e-20)));
}

// Slab test against a box, given inv = safeInverse(rd); x: entry (clamped to 0), y: exit.
// Misses when x > y.
vec2 clipRayInverse(vec3 bmin, vec3 bmax, vec3 ro, vec3 inv) {
    vec3 t0 = (bmin - ro) * inv;
    vec3 t1 = (bmax - ro) * inv;
    vec3 lo = min(t0, t1), hi = max(t0, t1);
    return vec2(max(max(lo.x, lo.y), max(lo.z, 0.0)), min(min(hi.x, hi.y), hi.z));
}

vec2 clipRay(vec3 bmin, vec3 bmax, vec3 ro, vec3 rd) {
    return clipRayInverse(bmin, bmax, ro, safeInverse(rd));
}

// Entry and exit of a ray in surface part i (see Frame), given inv = safeInverse(rd), which
// the caller works out once for all parts (three divisions); misses when x > y.
vec2 partInterval(uint i, vec3 ro, vec3 rd, vec3 inv) {
    vec4 a = frame.surfaceBoxes[2u * i], b = frame.surfaceBoxes[2u * i + 1u];
    if (a.w == 0.0) return clipRayInverse(a.xyz, b.xyz, ro, inv);
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
    uint mode = control.size.z;
    return r.t >= 0.0 && (mode == SDFCSG_MODE_SHADED || mode == SDFCSG_MODE_NORMALS);
}

// The colour of a sample that needs no shading (see needsShading).
vec3 plainColor(Trace r) {
    uint mode = control.size.z;
    // Steps on a log scale: a handful already shows, and 256 is red.
    if (mode == SDFCSG_MODE_STEPS) return heat(log2(1.0 + float(r.steps)) / log2(1.0 + float(SDFCSG_MAX_STEPS)));
    if (r.t < 0.0) return mode == SDFCSG_MODE_SHADED ? frame.background.rgb : vec3(0.0);
    float x = (r.t - frame.distances.x) / max(frame.distances.y - frame.distances.x, 1e-6);
    return vec3(1.0 - 0.85 * clamp(x, 0.0, 1.0)); // depth
}

uint packColor(vec3 c) {
    uvec3 u = uvec3(clamp(c, 0.0, 1.0) * 255.0 + 0.5);
    return u.r | (u.g << 8) | (u.b << 16) | (255u << 24);
}

vec3 unpackColor(uint c) {
    return vec3(uvec3(c, c >> 8, c >> 16) & 255u) / 255.0;
}

// The pixel and the ray of sample s of the band (column, row in its width * aa x rows * aa grid).
void sampleRay(uvec2 s, out uvec2 pixel, out vec3 rd) {
    uint aa = max(control.counts.x, 1u);
    // s / aa through floats, exact here (s < 2^24, aa <= 8): integer division by a value the
    // compiler cannot see is a loop of scalar divisions on CPU drivers.
    uvec2 p = uvec2((vec2(s) + 0.5) / float(aa));
    pixel = p + uvec2(0u, band.firstRow);
    rd = rayDirection(vec2(pixel) + (vec2(s - p * aa) + 0.5) / float(aa));
}

// Sample index i of the band (row-major) as column and row: i / n through floats, corrected
// by one where rounding missed (n = width * aa; i / n stays below 2^16, so the float quotient
// is within one of it).
uvec2 sampleCoords(uint i) {
    uint n = control.size.x * max(control.counts.x, 1u);
    int row = int(float(i) / float(n));
    int column = int(i) - row * int(n);
    row += column < 0 ? -1 : column >= int(n) ? 1 : 0;
    return uvec2(uint(int(i) - row * int(n)), uint(row));
}

// A listed hit's ray direction and ray parameter (the ends, shade and light passes).
void hitRay(uvec2 hit, out vec3 rd, out float t) {
    uvec2 pixel;
    sampleRay(sampleCoords(hit.x), pixel, rd);
    t = uintBitsToFloat(hit.y);
}

// The sample of this invocation of the clip and march passes (column and row in the band's
// sample grid) and its index; false outside the image.
bool tileSample(out uvec2 s, out uint sampleIndex) {
    uint aa = max(control.counts.x, 1u);
    uint tile = tiles[gl_WorkGroupID.x];
    s = uvec2(tile & 0xffffu, tile >> 16) * gl_WorkGroupSize.xy + gl_LocalInvocationID.xy;
    sampleIndex = s.y * control.size.x * aa + s.x;
    return s.x < control.size.x * aa && s.y < (control.size.y - band.firstRow) * aa;
}
