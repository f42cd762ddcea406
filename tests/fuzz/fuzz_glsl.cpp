// Fuzz target: bytes -> parseScene -> generated GLSL -> glslang, checking that every scene that
// validates compiles, in each way the library compiles scenes: values read from the node buffer
// or inlined as literals (the renderer), and inlined with primitive lists (the mesher). The
// input's hash picks one of the three, so a crash reproduces from its file alone. The kernels are
// the library's own; probe.comp includes exactly what march.comp and shade.comp give the scene to
// build on (shared.h, sdf.glsl, nodes.glsl) and is much quicker to compile.
//
// Almost every random change to a scene breaks it, and fuzz_parse covers broken input, so the
// mutator retries until the scene still loads: most executions then compile a scene. The SPIR-V
// cache stays in memory only (the same GLSL text twice is compiled once); the counts printed at
// exit say how many scenes glslang compiled.
#include "codegen/shader_compile.h"

#include <sdfcsg/compile.h>
#include <sdfcsg/scene.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>

extern "C" size_t LLVMFuzzerMutate(uint8_t* data, size_t size, size_t maxSize);

namespace {

uint64_t invalid = 0; // executions whose input did not load

bool loads(const uint8_t* data, size_t size) {
    return bool(sdfcsg::parseScene(std::string_view(reinterpret_cast<const char*>(data), size)));
}

void report() {
    const auto stats = sdfcsg::detail::shaderCacheStats();
    std::fprintf(stderr,
                 "fuzz_glsl: %llu scenes compiled by glslang, %llu served from memory, %llu "
                 "inputs did not load\n",
                 static_cast<unsigned long long>(stats.compiles),
                 static_cast<unsigned long long>(stats.memoryHits),
                 static_cast<unsigned long long>(invalid));
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    std::atexit(report);
    return 0;
}

extern "C" size_t LLVMFuzzerCustomMutator(uint8_t* data, size_t size, size_t maxSize,
                                          unsigned int) {
    std::string original(reinterpret_cast<const char*>(data), size);
    for (int attempt = 0; attempt < 16; ++attempt) {
        const size_t mutated = LLVMFuzzerMutate(data, size, maxSize);
        if (loads(data, mutated)) return mutated;
        std::memcpy(data, original.data(), original.size());
    }
    return size;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    auto scene = sdfcsg::parseScene(text, "fuzz.json");
    if (!scene) {
        ++invalid;
        return 0;
    }

    uint64_t hash = 0xcbf29ce484222325ull; // FNV-1a
    for (size_t i = 0; i < size; ++i)
        hash = (hash ^ data[i]) * 0x100000001b3ull;
    sdfcsg::CodegenOptions options;
    std::string_view kernel = "probe.comp";
    switch (hash % 3) {
    case 0:
        break;
    case 1:
        options.inlineParams = true;
        break;
    default:
        options.inlineParams = true;
        kernel = "mesh_field.comp";
    }
    const std::string glsl = sdfcsg::generateSceneGlsl(*scene, options);
    const sdfcsg::CompileOptions memoryOnly{std::filesystem::path()}; // no disk cache
    auto spirv = sdfcsg::compileKernel(kernel, glsl, memoryOnly);
    if (!spirv) {
        std::fprintf(stderr, "fuzz_glsl: a valid scene's GLSL does not compile (%.*s)\n%s\n%s\n",
                     int(kernel.size()), kernel.data(), spirv.error().str().c_str(), glsl.c_str());
        std::abort();
    }
    return 0;
}
