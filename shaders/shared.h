// Constants shared by the C++ engine and the GLSL kernels. Plain #defines only: this file is
// included by both languages.
#ifndef SDFCSG_SHARED_H
#define SDFCSG_SHARED_H

// Ray-march workgroup: 8 x 8 invocations. lavapipe runs 8-wide SIMD lanes and spreads
// workgroups over its threads, so square tiles of 64 keep every core and lane busy.
#define SDFCSG_RAYMARCH_GROUP_X 8
#define SDFCSG_RAYMARCH_GROUP_Y 8

// Descriptor bindings (set 0).
#define SDFCSG_BINDING_FRAME 0  // uniform Frame: camera, lights, mode, flags
#define SDFCSG_BINDING_NODES 1  // readonly buffer of Node (see nodes.glsl), index-aligned with the scene
#define SDFCSG_BINDING_PIXELS 2 // buffer of packed RGBA8, row-major, top row first
#define SDFCSG_BINDING_INFO 3   // buffer of vec2 per pixel: (hit depth or -1, step count)
#define SDFCSG_BINDING_PROBE_IN 4  // probe.comp: readonly buffer of vec4 points (xyz used)
#define SDFCSG_BINDING_PROBE_OUT 5 // probe.comp: buffer of vec4 sceneSample() results

#define SDFCSG_PROBE_GROUP_X 64

#define SDFCSG_MAX_LIGHTS 4
#define SDFCSG_MAX_CLIP_BOXES 8 // boxes that hold every surface; rays skip the space outside them
#define SDFCSG_MAX_STEPS 256

#define SDFCSG_MODE_SHADED 0
#define SDFCSG_MODE_NORMALS 1
#define SDFCSG_MODE_DEPTH 2
#define SDFCSG_MODE_STEPS 3

#define SDFCSG_FLAG_SHADOWS 1
#define SDFCSG_FLAG_AO 2
#define SDFCSG_FLAG_BOXES_ALL 4
#define SDFCSG_FLAG_BOXES_SELECTED 8

// Bounds that are infinite (planes) are stored as +-SDFCSG_HUGE to keep arithmetic finite.
#define SDFCSG_HUGE 1.0e30

// Specialization constant ids.
#define SDFCSG_SPEC_BOUNDS_SKIPPING 0

#endif
