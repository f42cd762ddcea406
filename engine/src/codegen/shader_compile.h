// Internals of compileKernel (sdfcsg/compile.h) that tests and the benchmark look at.
#pragma once

#include "sdfcsg/compile.h"
#include "sdfcsg/error.h"

#include <cstdint>
#include <filesystem>
#include <string_view>
#include <vector>

namespace sdfcsg::detail {

struct ShaderCacheStats {
    uint64_t memoryHits = 0; // served from this process's memory
    uint64_t diskHits = 0;   // read back from the on-disk cache
    uint64_t compiles = 0;   // glslang runs (successful or not)
    uint64_t evictions = 0;  // disk entries removed to keep the cache under its cap
};

ShaderCacheStats shaderCacheStats();

// compileKernel() (sdfcsg/compile.h), telling whether glslang ran: the SPIR-V was in neither
// cache, so the kernel is new to this machine and the driver has most likely not cached its
// machine code either.
Result<std::vector<uint32_t>> compileKernel(std::string_view kernel, std::string_view sceneGlsl,
                                            const CompileOptions& options, bool& ranGlslang);

// Keeps the SPIR-V disk cache in `dir` within `maxBytes`: removes its least recently used
// entries (oldest modification time first) until the rest fit, never `keep` (the entry just
// written), and temporaries left for an hour by a writer that died. Files that vanish while it
// works (other processes trim the same folder) are skipped; files that are not the cache's are
// left alone. compileKernel() calls it after each entry it writes.
void trimShaderCache(const std::filesystem::path& dir, uint64_t maxBytes,
                     const std::filesystem::path& keep = {});

// Sets glslang up for compute shaders, once per process: its first parse builds the tables of
// built-in symbols (about 0.1 s on lavapipe's machines). Context::create starts it on a thread
// of its own, so that it overlaps the device's setup; compiles wait for it.
void warmUpCompiler();

} // namespace sdfcsg::detail
