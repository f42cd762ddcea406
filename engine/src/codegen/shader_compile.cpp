// GLSL -> SPIR-V at runtime through glslang's C++ API, with a SPIR-V cache keyed by a hash of
// every source that can reach the compiler (the kernel, the embedded library, the generated
// scene) plus a salt naming this code and glslang's version. The cache lives in memory and on
// disk; disk entries carry their key, length and a checksum, so a truncated or foreign file is
// ignored and overwritten, never trusted. The disk cache is kept under a size cap, least recently
// used entries going first: a read renews an entry's modification time, and each write trims the
// folder (trimShaderCache).
#include "codegen/shader_compile.h"

#include "codegen/embedded_shaders.h"
#include "gpu/environment.h"

#include "sdfcsg/compile.h"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>
#include <glslang/build_info.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <unordered_map>

namespace sdfcsg {
namespace {

namespace fs = std::filesystem;

// Bump when anything about how sources become SPIR-V changes (options, target, includer).
constexpr std::string_view kSalt = "sdfcsg-spirv-1 vulkan1.1 spv1.3 no-opt";
// Kept in memory per process; a viewer recompiling on every edit should not grow without end.
constexpr size_t kMemoryEntries = 64;

// FNV-1a, 64-bit: small, and plenty for a cache key.
struct Hash {
    uint64_t h = 0xcbf29ce484222325ull;
    void add(const void* data, size_t size) {
        auto* p = static_cast<const unsigned char*>(data);
        for (size_t i = 0; i < size; ++i)
            h = (h ^ p[i]) * 0x100000001b3ull;
    }
    void add(std::string_view s) {
        uint64_t n = s.size();
        add(&n, sizeof n); // length-prefixed, so that concatenations cannot collide
        add(s.data(), s.size());
    }
};

struct DiskHeader {
    char magic[8]; // "sdfcsgSV"
    uint64_t key;
    uint64_t words;
    uint64_t checksum; // FNV-1a of the SPIR-V words
};
constexpr char kMagic[8] = {'s', 'd', 'f', 'c', 's', 'g', 'S', 'V'};
constexpr uint32_t kSpirvMagic = 0x07230203;

struct Cache {
    std::mutex mutex;
    std::unordered_map<uint64_t, std::vector<uint32_t>> memory;
    detail::ShaderCacheStats stats;
};

void remember(Cache& c, uint64_t key, const std::vector<uint32_t>& spirv) {
    if (c.memory.size() >= kMemoryEntries) c.memory.clear();
    c.memory.emplace(key, spirv);
}

Cache& cache() {
    static Cache c;
    return c;
}

// Only one glslang compile at a time: it keeps process-wide state, and compiles are rare.
std::mutex& compilerMutex() {
    static std::mutex m;
    return m;
}

fs::path cacheFile(const fs::path& dir, uint64_t key) {
    char name[32];
    std::snprintf(name, sizeof name, "%016llx.spv", static_cast<unsigned long long>(key));
    return dir / name;
}

uint64_t checksum(const std::vector<uint32_t>& words) {
    Hash h;
    h.add(words.data(), words.size() * sizeof(uint32_t));
    return h.h;
}

bool readDisk(const fs::path& file, uint64_t key, std::vector<uint32_t>& out) {
    std::ifstream in(file, std::ios::binary);
    DiskHeader header;
    if (!in.read(reinterpret_cast<char*>(&header), sizeof header)) return false;
    if (std::memcmp(header.magic, kMagic, sizeof kMagic) != 0 || header.key != key ||
        header.words < 5 || header.words > (64u << 20))
        return false;
    std::vector<uint32_t> words(header.words);
    if (!in.read(reinterpret_cast<char*>(words.data()), std::streamsize(words.size() * 4)))
        return false;
    if (in.peek() != std::ifstream::traits_type::eof()) return false; // trailing garbage
    if (words[0] != kSpirvMagic || checksum(words) != header.checksum) return false;
    out = std::move(words);
    // Recently used: the last to be trimmed. Best effort (the folder may be read-only), and
    // harmless where another process removed the entry meanwhile.
    std::error_code ec;
    fs::last_write_time(file, fs::file_time_type::clock::now(), ec);
    return true;
}

// Best effort: a cache that cannot be written only costs the next run a compile.
void writeDisk(const fs::path& dir, uint64_t key, const std::vector<uint32_t>& words,
               uint64_t maxBytes) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) return;
    static std::atomic<uint32_t> counter{0};
    fs::path target = cacheFile(dir, key);
    fs::path temp = target;
    temp += ".tmp" + std::to_string(::getpid()) + "." + std::to_string(counter++);
    {
        std::ofstream out(temp, std::ios::binary | std::ios::trunc);
        DiskHeader header{};
        std::memcpy(header.magic, kMagic, sizeof kMagic);
        header.key = key;
        header.words = words.size();
        header.checksum = checksum(words);
        out.write(reinterpret_cast<const char*>(&header), sizeof header);
        out.write(reinterpret_cast<const char*>(words.data()), std::streamsize(words.size() * 4));
        if (!out.flush()) {
            out.close();
            fs::remove(temp, ec);
            return;
        }
    }
    fs::rename(temp, target, ec);
    if (ec) {
        fs::remove(temp, ec);
        return;
    }
    detail::trimShaderCache(dir, maxBytes, target);
}

// Resolves "scene.glsl" to the generated scene and every other name to an embedded file.
class Includer : public glslang::TShader::Includer {
  public:
    explicit Includer(std::string_view scene) : scene_(scene) {}

    IncludeResult* includeLocal(const char* name, const char*, size_t) override {
        return resolve(name);
    }
    IncludeResult* includeSystem(const char* name, const char*, size_t) override {
        return resolve(name);
    }
    void releaseInclude(IncludeResult* result) override { delete result; }

  private:
    IncludeResult* resolve(std::string_view name) {
        std::string_view text = name == "scene.glsl" ? scene_ : shaderSource(name);
        if (text.empty() && name != "scene.glsl") return nullptr; // glslang reports it
        if (text.empty()) text = "\n";
        return new IncludeResult(std::string(name), text.data(), text.size(), nullptr);
    }
    std::string_view scene_;
};

constexpr auto kMessages = EShMessages(EShMsgSpvRules | EShMsgVulkanRules);

// Every compile's settings, so that all share the built-in symbol tables of the first.
void setEnvironment(glslang::TShader& shader) {
    shader.setEnvInput(glslang::EShSourceGlsl, EShLangCompute, glslang::EShClientVulkan, 100);
    shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_1);
    shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_3);
}

std::once_flag compilerReady;

Result<std::vector<uint32_t>> runGlslang(std::string_view kernel, std::string_view source,
                                         std::string_view scene) {
    detail::warmUpCompiler();
    std::lock_guard lock(compilerMutex());

    const std::string name(kernel);
    const char* text = source.data();
    const int length = int(source.size());
    const char* names = name.c_str();
    glslang::TShader shader(EShLangCompute);
    shader.setStringsWithLengthsAndNames(&text, &length, &names, 1);
    setEnvironment(shader);
    const auto messages = kMessages;
    Includer includer(scene);
    auto failure = [&](const char* what, const char* log) {
        std::string message = std::string(what) + "\n" + log;
        while (!message.empty() && message.back() == '\n')
            message.pop_back();
        return Error::message(ErrorKind::Shader, name, std::move(message));
    };
    if (!shader.parse(GetDefaultResources(), 450, ENoProfile, false, false, messages, includer))
        return failure("GLSL compilation failed:", shader.getInfoLog());

    glslang::TProgram program;
    program.addShader(&shader);
    if (!program.link(messages)) return failure("GLSL link failed:", program.getInfoLog());

    // No spirv-opt: the driver optimises anyway, and skipping it keeps compiles fast.
    glslang::SpvOptions options;
    options.disableOptimizer = true;
    options.generateDebugInfo = false;
    options.validate = false;
    std::vector<uint32_t> spirv;
    spv::SpvBuildLogger logger;
    glslang::GlslangToSpv(*program.getIntermediate(EShLangCompute), spirv, &logger, &options);
    if (spirv.empty()) return failure("SPIR-V generation failed:", logger.getAllMessages().c_str());
    return spirv;
}

} // namespace

std::string_view shaderSource(std::string_view name) {
    for (const detail::EmbeddedFile& f : detail::embeddedShaders())
        if (f.name == name) return f.text;
    return {};
}

Result<std::vector<uint32_t>> compileKernel(std::string_view kernel, std::string_view sceneGlsl,
                                            const CompileOptions& options) {
    bool compiled;
    return detail::compileKernel(kernel, sceneGlsl, options, compiled);
}

Result<std::vector<uint32_t>> detail::compileKernel(std::string_view kernel,
                                                    std::string_view sceneGlsl,
                                                    const CompileOptions& options,
                                                    bool& ranGlslang) {
    ranGlslang = false;
    std::string_view source = shaderSource(kernel);
    if (source.empty())
        return Error::message(ErrorKind::Shader, std::string(kernel),
                              "no embedded shader of this name");

    Hash hash;
    hash.add(kSalt);
    const int version[] = {GLSLANG_VERSION_MAJOR, GLSLANG_VERSION_MINOR, GLSLANG_VERSION_PATCH};
    hash.add(version, sizeof version);
    hash.add(kernel);
    for (const detail::EmbeddedFile& f : detail::embeddedShaders()) {
        hash.add(f.name);
        hash.add(f.text);
    }
    hash.add(sceneGlsl);
    const uint64_t key = hash.h;

    Cache& c = cache();
    {
        std::lock_guard lock(c.mutex);
        if (auto it = c.memory.find(key); it != c.memory.end()) {
            ++c.stats.memoryHits;
            return it->second;
        }
    }
    const fs::path dir = options.cacheDir ? *options.cacheDir : environment().shaderCacheDir;
    std::vector<uint32_t> spirv;
    if (!dir.empty() && readDisk(cacheFile(dir, key), key, spirv)) {
        std::lock_guard lock(c.mutex);
        ++c.stats.diskHits;
        remember(c, key, spirv);
        return spirv;
    }

    auto compiled = runGlslang(kernel, source, sceneGlsl);
    ranGlslang = true;
    {
        std::lock_guard lock(c.mutex);
        ++c.stats.compiles;
        if (compiled) remember(c, key, *compiled);
    }
    if (compiled && !dir.empty())
        writeDisk(dir, key, *compiled,
                  options.cacheMaxBytes ? *options.cacheMaxBytes
                                        : environment().shaderCacheMaxBytes);
    return compiled;
}

namespace detail {

void trimShaderCache(const fs::path& dir, uint64_t maxBytes, const fs::path& keep) {
    struct Entry {
        fs::file_time_type used;
        uint64_t bytes;
        fs::path path;
    };
    std::vector<Entry> entries;
    uint64_t total = 0;
    const auto now = fs::file_time_type::clock::now();
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const fs::path& path = it->path();
        const std::string name = path.filename().string();
        // Entries are "<16 hex digits>.spv"; their temporaries add ".tmp<pid>.<n>". Anything
        // else in the folder is not the cache's to remove.
        const bool entry = name.size() == 20 && name.ends_with(".spv");
        const bool temporary = name.size() > 24 && name.find(".spv.tmp") == 16;
        if (!entry && !temporary) continue;
        std::error_code fileEc;
        const uint64_t bytes = it->file_size(fileEc);
        const fs::file_time_type used = it->last_write_time(fileEc);
        if (fileEc) continue; // gone meanwhile: another process trimmed it, or renamed it in
        // A temporary an hour old belongs to a process that died while writing it.
        if (temporary) {
            if (now - used > std::chrono::hours(1)) fs::remove(path, fileEc);
            continue;
        }
        total += bytes;
        if (path != keep) entries.push_back({used, bytes, path});
    }
    if (total <= maxBytes) return;
    std::sort(entries.begin(), entries.end(),
              [](const Entry& a, const Entry& b) { return a.used < b.used; });
    for (const Entry& e : entries) {
        if (total <= maxBytes) break;
        // Another process may have removed it first; either way it no longer counts. A process
        // reading it keeps its open file (POSIX), and one about to open it recompiles.
        fs::remove(e.path, ec);
        total -= e.bytes;
        std::lock_guard lock(cache().mutex);
        ++cache().stats.evictions;
    }
}

ShaderCacheStats shaderCacheStats() {
    std::lock_guard lock(cache().mutex);
    return cache().stats;
}

void warmUpCompiler() {
    std::call_once(compilerReady, [] {
        glslang::InitializeProcess();
        std::lock_guard lock(compilerMutex());
        const char* text = "#version 450\nlayout(local_size_x = 1) in;\nvoid main() {}\n";
        glslang::TShader shader(EShLangCompute);
        shader.setStrings(&text, 1);
        setEnvironment(shader);
        shader.parse(GetDefaultResources(), 450, ENoProfile, false, false, kMessages);
    });
}

} // namespace detail

void clearShaderMemoryCache() {
    std::lock_guard lock(cache().mutex);
    cache().memory.clear();
}

} // namespace sdfcsg
