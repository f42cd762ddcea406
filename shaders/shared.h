// Constants shared by the C++ engine and the GLSL kernels. Plain #defines only: this file is
// included by both languages.
#ifndef SDFCSG_SHARED_H
#define SDFCSG_SHARED_H

// Ray-march workgroup: 8 x 8 invocations. lavapipe runs 8-wide SIMD lanes and spreads
// workgroups over its threads, so square tiles of 64 keep every core and lane busy.
#define SDFCSG_RAYMARCH_GROUP_X 8
#define SDFCSG_RAYMARCH_GROUP_Y 8

// Descriptor bindings (set 0).
#define SDFCSG_BINDING_FRAME 0 // uniform Frame: camera, lights, mode, flags
#define SDFCSG_BINDING_NODES                                                                       \
    1 // readonly buffer of Node (see nodes.glsl), index-aligned with the scene
#define SDFCSG_BINDING_PIXELS 2  // buffer of packed RGBA8, row-major, top row first
#define SDFCSG_BINDING_INFO 3    // buffer of vec2 per pixel: (hit depth or -1, step count)
#define SDFCSG_BINDING_SAMPLES 6 // raymarch.glsl: packed RGBA8 per sample of a band
#define SDFCSG_BINDING_HITS 7    // raymarch.glsl: hits to shade, after an indirect dispatch
#define SDFCSG_BINDING_TILES                                                                       \
    8 // raymarch.glsl: workgroups of a band that the clip and march passes run
#define SDFCSG_BINDING_CONTROL 9   // raymarch.glsl: buffer Control: the values that branches read
#define SDFCSG_BINDING_SURFACES 10 // raymarch.glsl: per listed hit, what the shade pass hands over
#define SDFCSG_BINDING_RANGES 11   // raymarch.glsl: per sample, the part of its ray to march
#define SDFCSG_BINDING_FIELD 15    // tape.glsl: per-region pruned tapes (engine/src/field/prune.h)
#define SDFCSG_BINDING_PROBE_IN 4  // probe.comp: readonly buffer of vec4 points (xyz used)
#define SDFCSG_BINDING_PROBE_OUT 5 // probe.comp: buffer of vec4 sceneSample() results

#define SDFCSG_PROBE_GROUP_X 64

// A tape instruction (engine/src/field/prune.h, shaders/tape.glsl): the node's index in the low
// bits and its kind (NodeKind) above them. In the packed tapes, a primitive whose operation follows
// at once also carries that operation (its kind less NodeKind::Union, plus 1) and its
// blend profile, and the next word holds the blend radius.
#define SDFCSG_TAPE_NODE_BITS 20
#define SDFCSG_TAPE_KIND_SHIFT 20  // 6 bits
#define SDFCSG_TAPE_FOLD_SHIFT 26  // 2 bits
#define SDFCSG_TAPE_BLEND_SHIFT 28 // 2 bits
#define SDFCSG_TAPE_DOMAIN_END 63  // the kind of the instruction that ends a domain's child

// Mesh extraction (engine/src/mesh/mesh.cpp, shaders/mesh_*.comp). The grid's samples are split
// into bricks of SDFCSG_MESH_BRICK^3; a brick also reads the samples one step past its far faces,
// so it holds SDFCSG_MESH_BRICK_SAMPLES^3 values and owns the cells and edges that start at its own
// samples.
#define SDFCSG_MESH_BRICK 8
#define SDFCSG_MESH_BRICK_SAMPLES 9
#define SDFCSG_MESH_BRICK_BLOCK 729      // SDFCSG_MESH_BRICK_SAMPLES^3
#define SDFCSG_MESH_BRICK_EDGES 1536     // 3 edges per owned sample
#define SDFCSG_MESH_GROUP_X 64           // cull and vertex passes
#define SDFCSG_MESH_CLASSIFY_X 32        // classify pass: at most 3 rows of 9 samples each
#define SDFCSG_MESH_RECORD 401           // 3 * 8 * 8 + 9 * 9 + 2 * 8 * 8
#define SDFCSG_MESH_NO_BRICK 0xffffffffu // brick map entry of a skipped brick

#define SDFCSG_BINDING_MESH_GRID 0   // uniform MeshGrid: origin, cell size, counts
#define SDFCSG_BINDING_MESH_TABLES 2 // readonly uint[]: marching-cubes tables
#define SDFCSG_BINDING_MESH_ACTIVE 3 // uint[]: linear index of each active brick (its slot)
#define SDFCSG_BINDING_MESH_MAP                                                                    \
    4                                 // uint[]: per grid brick, 1 when active (cull pass writes),
                                      // then its slot or SDFCSG_MESH_NO_BRICK (host writes)
#define SDFCSG_BINDING_MESH_SAMPLES 5 // float[]: the block of each brick of the batch
#define SDFCSG_BINDING_MESH_RECORDS                                                                \
    6 // uint[]: per active brick, SDFCSG_MESH_RECORD words:
      // per owned row, first edge vertex and crossed edges;
      // per owned row, first dual vertex; then the signs of
      // the block, a word per row; then per owned row, each
      // cell's dual vertices before it in the row, a byte each
#define SDFCSG_BINDING_MESH_COUNTS                                                                 \
    7                               // uvec4[]: per active brick, edge vertices, triangles
                                    // of marching cubes, dual vertices, dual triangles
#define SDFCSG_BINDING_MESH_BASES 8 // uvec4[]: per active brick, the first of each
#define SDFCSG_BINDING_MESH_EDGES 9 // uint[]: crossed edges of each brick of the batch
#define SDFCSG_BINDING_MESH_VERTICES                                                               \
    10                                 // float[]: per vertex: position, normal, colour, and
                                       // a second normal (vertices pass) or the mean of its
                                       // edge points (dual pass): 12 floats
#define SDFCSG_BINDING_MESH_INDICES 11 // uint[]: 3 per triangle
#define SDFCSG_BINDING_MESH_STATUS 12  // uint[2]: surface cut, brick skipped wrongly
#define SDFCSG_BINDING_MESH_HERMITE 13 // float[]: dual contouring: every edge vertex, 12 each

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
#define SDFCSG_FLAG_GRID 16
#define SDFCSG_GRID_HALF_LINES 10 // ground grid lines on each side of the middle ones

// Bounds that are infinite (planes) are stored as +-SDFCSG_HUGE to keep arithmetic finite.
#define SDFCSG_HUGE 1.0e30

// Specialization constant ids.
#define SDFCSG_SPEC_BOUNDS_SKIPPING 0
#define SDFCSG_SPEC_MESH_PASS 1     // mesh_field.comp: which pass (SDFCSG_MESH_PASS_*)
#define SDFCSG_SPEC_MESH_GROUP 2    // mesh_field.comp: workgroup size of that pass
#define SDFCSG_SPEC_RAYMARCH_PASS 3 // finish.comp, light.comp: which pass (SDFCSG_RAYMARCH_PASS_*)

#define SDFCSG_RAYMARCH_PASS_MARCH 0
#define SDFCSG_RAYMARCH_PASS_SHADE 1
#define SDFCSG_RAYMARCH_PASS_RESOLVE 2
#define SDFCSG_RAYMARCH_PASS_OVERLAY 3
#define SDFCSG_RAYMARCH_PASS_ENDS 4
#define SDFCSG_RAYMARCH_PASS_LIGHT 5
#define SDFCSG_RAYMARCH_PASS_CLIP 6
#define SDFCSG_RAYMARCH_PASSES 7

#define SDFCSG_MESH_PASS_CULL 0
#define SDFCSG_MESH_PASS_CLASSIFY 1
#define SDFCSG_MESH_PASS_VERTICES 2
// mesh_triangles.comp
#define SDFCSG_MESH_PASS_TRIANGLES 0
#define SDFCSG_MESH_PASS_DUAL 1

#endif
