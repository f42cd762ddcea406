// Internals of compileKernel (sdfcsg/compile.h) that tests and the benchmark look at.
#pragma once

#include <cstdint>

namespace sdfcsg::detail {

struct ShaderCacheStats {
    uint64_t memoryHits = 0; // served from this process's memory
    uint64_t diskHits = 0;   // read back from the on-disk cache
    uint64_t compiles = 0;   // glslang runs (successful or not)
};

ShaderCacheStats shaderCacheStats();

// Forgets the in-memory cache (the disk cache stays), so the next compile reads the disk.
void clearShaderMemoryCache();

} // namespace sdfcsg::detail
