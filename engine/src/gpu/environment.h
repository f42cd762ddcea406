// The environment variables that the library reads of its own accord, and when (sdfcsg/context.h
// lists them for users). The others are read only when a program asks: llmConfigFromEnvironment()
// (sdfcsg/generate.h), and libcurl's proxy variables where LlmConfig::proxy is unset.
//
// The library's own variables are read once per process, by the first call of environment(), and
// changes made later are not seen: a program that wants other settings (a test, the benchmark)
// passes them in ContextOptions and CompileOptions rather than changing the environment while the
// library's threads may be reading it. Context::create and compileKernel() make that first call
// on their caller's thread; the only other reads are of Mesa's variables, below.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

namespace sdfcsg::detail {

inline constexpr uint64_t kDefaultShaderCacheBytes = uint64_t(64) << 20;

struct Environment {
    // SDFCSG_VALIDATION: 0 for "0", 1 for any other value, -1 where unset or empty.
    int validation = -1;
    // SDFCSG_DEVICE: a device index or part of a device name; empty where unset.
    std::string device;
    // The SPIR-V disk cache: SDFCSG_CACHE_DIR (empty for "off"), else $XDG_CACHE_HOME/sdfcsg,
    // else $HOME/.cache/sdfcsg; empty (no disk cache) where none of them is set.
    std::filesystem::path shaderCacheDir;
    // Its size cap: SDFCSG_CACHE_SIZE in MiB (a number above 0; anything else is ignored), else
    // 64 MiB. Past it, the least recently used entries go (shader_compile.cpp).
    uint64_t shaderCacheMaxBytes = kDefaultShaderCacheBytes;
};

// The environment as it was at the first call.
const Environment& environment();
// The settings of the environment that `lookup` gives (a variable's value, or null where it is
// unset): environment() passes std::getenv, the tests other environments.
Environment readEnvironment(const std::function<const char*(const char* name)>& lookup);

// Whether MESA_SHADER_CACHE_DISABLE or MESA_GLSL_CACHE_DISABLE turns Mesa's disk cache of machine
// code off, as Mesa parses them. They are Mesa's, and Mesa reads them whenever a device is made,
// so Context::create reads them each time too, before it makes its device, to know whether the
// compile helper can hand machine code over through that cache.
bool mesaDiskCacheDisabled();

} // namespace sdfcsg::detail
