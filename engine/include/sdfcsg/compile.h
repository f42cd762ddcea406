// sdfcsg: scene -> GLSL -> SPIR-V.
//
// Each scene becomes one generated GLSL file holding `float sceneDistance(vec3 p)` and
// `vec4 sceneSample(vec3 p)` (rgb colour, distance in w). Every node is evaluated once into a
// local, one line per node, commented with its name or JSON path, so compile time is linear in
// the scene size. Static GLSL (the SDF library in shaders/sdf.glsl and the kernels) is embedded
// in the library; the generated file is what a kernel's `#include "scene.glsl"` resolves to.
#pragma once

#include "sdfcsg/error.h"
#include "sdfcsg/eval.h"
#include "sdfcsg/scene.h"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace sdfcsg {

// How the generated scene code evaluates the tree. Inlined: every node becomes a line of code
// (fastest for small scenes, and what a user reads in `sdfcsg glsl`). Tapes: the code is the
// same for every scene, a stack machine (shaders/tape.glsl) that runs, per cell of an octree
// around the solid, the nodes that can change the field there (engine/src/field/prune.h), read from
// buffers; its size and build time do not grow with the scene. Auto: tapes above
// kTapeMinNodes nodes.
enum class Evaluation : uint8_t { Auto, Inlined, Tapes };
inline constexpr size_t kTapeMinNodes = 160;
// The most nodes that Inlined takes: the driver's compile time and memory grow faster than the
// code (on lavapipe, 500 distinct spheres build in about 4 s and 330 MB, 1000 in two minutes).
inline constexpr size_t kInlinedMaxNodes = 512;
bool usesTapes(const Scene& scene, Evaluation evaluation);
// A Limit error, before any work, for a scene larger than `evaluation` takes (Inlined past
// kInlinedMaxNodes); Renderer::create and Mesher::create check it.
Status checkEvaluation(const Scene& scene, Evaluation evaluation);

struct CodegenOptions {
    Evaluation evaluation = Evaluation::Auto;
    // false: numeric parameters, transforms and bounds are read from the node buffer, so
    // changing a value needs no recompile (the viewer). true: they are baked in as literals,
    // which the driver's compiler folds (fastest for one-off headless renders). Scenes evaluated
    // from tapes read every value from buffers
    // either way; true lets their kernel read spheres as balls (centre and radius) where every
    // sphere's scale is the same on every axis, so that an edit changing that recompiles.
    bool inlineParams = false;
    // Whether each operand of a union or difference is guarded by a test of its bounds, which
    // the kernels turn on or off with a specialisation constant (kBoundsSkipping in
    // shaders/nodes.glsl). false leaves the tests out, for kernels that would turn them off:
    // the same values, and less code for the driver to compile (for the house's kernels on
    // lavapipe, about a sixth less time).
    bool boundsTests = true;
};

std::string generateSceneGlsl(const Scene& scene, const CodegenOptions& options = {});

// Source of an embedded shader file (e.g. "sdf.glsl", "march.comp"); empty if unknown.
std::string_view shaderSource(std::string_view name);

struct CompileOptions {
    // The folder of the SPIR-V disk cache, made where missing; an empty path: no disk cache.
    // Unset: the environment's, SDFCSG_CACHE_DIR ("off": none), else $XDG_CACHE_HOME/sdfcsg, else
    // ~/.cache/sdfcsg, as the library read it once (sdfcsg/context.h).
    std::optional<std::filesystem::path> cacheDir;
    // The disk cache's size cap in bytes. After each entry it writes, compileKernel removes the
    // least recently used entries (by modification time, which reading an entry renews) until
    // the folder fits; the entry just written always stays. Processes that share the folder may
    // read, write and trim it at once. Unset: SDFCSG_CACHE_SIZE (MiB), else 64 MiB.
    std::optional<uint64_t> cacheMaxBytes;
};

// Compiles an embedded kernel with `scene.glsl` resolving to `sceneGlsl`. SPIR-V is cached by a
// hash of everything that reaches the compiler, in this process's memory and in the disk cache
// of `options`. Errors carry the compiler log. Thread-safe.
Result<std::vector<uint32_t>> compileKernel(std::string_view kernel, std::string_view sceneGlsl,
                                            const CompileOptions& options = {});

// Forgets the SPIR-V kept in this process's memory (the disk caches stay), so that the next
// compile of each kernel reads a disk cache or runs the compiler: for measuring build times.
void clearShaderMemoryCache();

} // namespace sdfcsg
