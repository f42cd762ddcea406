// Scene -> GLSL -> SPIR-V without a GPU: the generated code's shape (one line per node, nothing
// pasted twice, linear size), that it compiles in both modes through compileKernel, compile
// errors as values, the SPIR-V cache in memory and on disk, and the settings the library takes from
// the environment.
#include "codegen/shader_compile.h"
#include "gpu/environment.h"
#include "scene_build_util.h"

#include <sdfcsg/compile.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace sdfcsg {
namespace {

using namespace sdfcsg::test;
namespace fs = std::filesystem;

double seconds(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

std::vector<std::string> lines(const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);)
        out.push_back(line);
    return out;
}

// The body of one generated function.
std::string function(const std::string& glsl, const std::string& signature) {
    size_t begin = glsl.find(signature);
    EXPECT_NE(begin, std::string::npos) << signature;
    size_t end = glsl.find("\n}\n", begin);
    return glsl.substr(begin, end - begin);
}

size_t count(const std::string& text, const std::regex& pattern) {
    return size_t(std::distance(std::sregex_iterator(text.begin(), text.end(), pattern),
                                std::sregex_iterator()));
}

std::vector<Scene> testScenes() {
    std::vector<Scene> scenes = {primitiveGallery()};
    for (uint32_t seed = 1; seed <= 3; ++seed)
        scenes.push_back(randomScene(seed, 50, 6, true));
    return scenes;
}

TEST(Codegen, OneCommentedLinePerNode) {
    Scene scene = primitiveGallery();
    scene.nodes[1].name = "red ball";
    std::string glsl = generateSceneGlsl(scene);
    for (const char* signature : {"float sceneDistance(vec3 p)", "vec4 sceneSample(vec3 p)"}) {
        std::string body = function(glsl, signature);
        const char v = body[0] == 'f' ? 'd' : 's';
        for (uint32_t i = 0; i < scene.nodes.size(); ++i) {
            const Node& n = scene.nodes[i];
            std::string label = n.name.empty() ? n.path : n.name;
            std::string comment = "// " + label + " (" + std::string(kindInfo(n.kind).name) + ")";
            // Exactly one line declares the node's value, and it carries the comment.
            std::regex declaration("(float|vec4) " + std::string(1, v) + std::to_string(i) + " = ");
            int found = 0;
            for (const std::string& line : lines(body)) {
                if (!std::regex_search(line, declaration)) continue;
                ++found;
                EXPECT_NE(line.find(comment), std::string::npos) << line;
            }
            EXPECT_EQ(found, 1) << "node " << i;
            // Read exactly once by its parent (never pasted twice); the root is returned.
            if (i > 0 && !kindInfo(n.kind).operation) {
                std::regex use("\\b" + std::string(1, v) + std::to_string(i) + "\\b");
                EXPECT_EQ(count(body, use), 2u) << "node " << i << " defined once, used once";
            }
        }
    }
}

TEST(Codegen, NamesCannotBreakTheCode) {
    // A trailing backslash would splice the next line into the comment; newlines would end it.
    Scene scene =
        makeScene(unite({sphere(1).named("evil\\"), box(1, 1, 1).named("two\nlines */ \xc3\xa9")}));
    std::string glsl = generateSceneGlsl(scene);
    EXPECT_EQ(glsl.find('\\'), std::string::npos);
    EXPECT_NE(glsl.find("// two?lines */ ?? (box)"), std::string::npos) << glsl;
    auto spirv = compileKernel("probe.comp", glsl);
    EXPECT_TRUE(spirv) << spirv.error().str();
}

TEST(Codegen, BoundsTestsCanBeLeftOut) {
    Scene scene =
        makeScene(unite({sphere(1), subtract({box(1, 1, 1), sphere(0.6f)}), box(2, 1, 1)}));
    for (bool inlineParams : {false, true}) {
        CodegenOptions options;
        options.inlineParams = inlineParams;
        const std::string with = generateSceneGlsl(scene, options);
        options.boundsTests = false;
        const std::string without = generateSceneGlsl(scene, options);
        EXPECT_NE(with.find("if (unionNeeds("), std::string::npos) << with;
        EXPECT_NE(with.find("if (differenceNeeds("), std::string::npos) << with;
        EXPECT_EQ(without.find("Needs("), std::string::npos) << without;
        // The same lines otherwise: each guard becomes a plain block.
        std::vector<std::string> a = lines(with), b = lines(without);
        ASSERT_EQ(a.size(), b.size()) << without;
        for (size_t i = 0; i < a.size(); ++i)
            if (a[i].find("Needs(") != std::string::npos)
                EXPECT_EQ(b[i], a[i].substr(0, a[i].find("if (")) + "{");
            else
                EXPECT_EQ(b[i], a[i]);
        auto spirv = compileKernel("march.comp", without);
        EXPECT_TRUE(spirv) << spirv.error().str();
    }
}

TEST(Codegen, IndentationFollowsDepth) {
    Scene scene = makeScene(unite({sphere(1), subtract({box(1, 1, 1), sphere(0.6f)})}));
    std::string body = function(generateSceneGlsl(scene), "float sceneDistance");
    auto indentOf = [&](const std::string& what) {
        for (const std::string& line : lines(body))
            if (line.find(what) != std::string::npos) return line.find_first_not_of(' ');
        return std::string::npos;
    };
    size_t root = indentOf("// root (union)");
    size_t op = indentOf("// root.children[1] (difference)");
    size_t leaf = indentOf("// root.children[1].children[1] (sphere)");
    EXPECT_LT(root, op);
    EXPECT_LT(op, leaf);
}

TEST(Codegen, GeneratedCodeCompilesInBothModes) {
    for (const Scene& scene : testScenes()) {
        SCOPED_TRACE(scene.file);
        for (bool inlineParams : {false, true}) {
            CodegenOptions options;
            options.inlineParams = inlineParams;
            std::string glsl = generateSceneGlsl(scene, options);
            auto spirv = compileKernel("probe.comp", glsl);
            ASSERT_TRUE(spirv) << spirv.error().str() << "\n" << glsl;
            EXPECT_EQ((*spirv)[0], 0x07230203u);
            // Values stay out of buffer-mode code, and inline code reads no node buffer.
            EXPECT_EQ(glsl.find("nodes[") == std::string::npos, inlineParams);
        }
    }
}

TEST(Codegen, BundledScenesCompile) {
    std::vector<fs::path> paths = bundledScenePaths();
    ASSERT_GE(paths.size(), 6u);
    const CompileOptions noDiskCache{fs::path()};
    for (const fs::path& path : paths) {
        auto scene = loadScene(path);
        ASSERT_TRUE(scene) << scene.error().str();
        for (bool inlineParams : {false, true}) {
            CodegenOptions options;
            options.inlineParams = inlineParams;
            std::string glsl = generateSceneGlsl(*scene, options);
            for (const char* kernel : {"probe.comp", "march.comp", "shade.comp"}) {
                clearShaderMemoryCache();
                auto start = std::chrono::steady_clock::now();
                auto spirv = compileKernel(kernel, glsl, noDiskCache);
                ASSERT_TRUE(spirv) << path << " " << kernel << ": " << spirv.error().str();
                std::printf(
                    "%-18s %3zu nodes %-6s %-14s %6zu B GLSL -> %6zu B SPIR-V in %5.1f ms\n",
                    path.stem().c_str(), scene->nodes.size(), inlineParams ? "inline" : "buffer",
                    kernel, glsl.size(), spirv->size() * 4, seconds(start) * 1000);
            }
        }
    }
}

TEST(Codegen, EveryKernelCompilesAgainstGeneratedCode) {
    std::string glsl = generateSceneGlsl(primitiveGallery());
    for (const char* kernel : {"probe.comp", "march.comp", "shade.comp"}) {
        if (shaderSource(kernel).empty()) continue; // not written yet
        auto spirv = compileKernel(kernel, glsl);
        EXPECT_TRUE(spirv) << kernel << ": " << (spirv ? "" : spirv.error().str());
    }
}

TEST(Codegen, ChangingValuesKeepsTheBufferModeCode) {
    Scene a = randomScene(8, 40);
    Scene b = a;
    for (Node& n : b.nodes) {
        n.transform.translate += glm::vec3(0.5f);
        n.params[0] *= 1.5f;
        if (kindInfo(n.kind).role == Role::Boolean) n.params[1] = 2.0f; // chamfer
        n.color = glm::vec3(0.1f, 0.2f, 0.3f);
    }
    EXPECT_EQ(generateSceneGlsl(a), generateSceneGlsl(b));
    CodegenOptions inl;
    inl.inlineParams = true;
    EXPECT_NE(generateSceneGlsl(a, inl), generateSceneGlsl(b, inl));
}

Scene smoothChain(int spheres) {
    std::vector<Tree> children;
    for (int i = 0; i < spheres; ++i)
        children.push_back(sphere(0.3f).at(0.2f * float(i), std::sin(float(i)), 0));
    return makeScene(unite(std::move(children), 0.25f), "<chain " + std::to_string(spheres) + ">");
}

// A smooth minimum reads both operands twice; pasting expressions would double the code per
// operand. Size must grow linearly, and 2000 smoothly united spheres compile quickly.
TEST(Codegen, SizeAndCompileTimeAreLinear) {
    std::string small = generateSceneGlsl(smoothChain(1000));
    std::string large = generateSceneGlsl(smoothChain(2000));
    EXPECT_LT(double(large.size()) / double(small.size()), 2.1);

    // Also nested 64 deep (the parser's limit), each level smoothly blended.
    Tree deep = sphere(0.5f);
    for (int i = 0; i < 63; ++i)
        deep = unite({sphere(0.5f).at(0.1f * float(i), 0, 0), deep}, 0.1f);
    std::string nested = generateSceneGlsl(makeScene(deep));
    size_t text = 0; // without indentation, which grows with depth (at most 64 levels)
    for (const std::string& line : lines(nested))
        text += line.size() - std::min(line.size(), line.find_first_not_of(' '));
    EXPECT_LT(text, 2u * 127 * 300);

    clearShaderMemoryCache();
    auto start = std::chrono::steady_clock::now();
    auto spirv = compileKernel("probe.comp", large, CompileOptions{fs::path()}); // no disk cache
    double elapsed = seconds(start);
    ASSERT_TRUE(spirv) << spirv.error().str();
    std::printf("2000 smoothly united spheres: %zu bytes of GLSL, compiled in %.0f ms\n",
                large.size(), elapsed * 1000);
    EXPECT_LT(elapsed, 3.0);
    EXPECT_TRUE(compileKernel("probe.comp", nested));
}

// With literal values, an operation whose blend radius is 0 takes the sharp form (one
// comparison, same bits); a smooth one keeps the blend. Buffer-mode code reads every radius.
TEST(Codegen, LiteralSharpOperationsTakeTheShortForm) {
    Scene scene =
        makeScene(subtract({unite({sphere(1), sphere(0.5f).at(1, 0, 0)}, 0.25f), sphere(0.3f)}));
    CodegenOptions inl;
    inl.inlineParams = true;
    const std::string literal = generateSceneGlsl(scene, inl);
    EXPECT_NE(literal.find("d0 = sharpDifference(d0, d4);"), std::string::npos) << literal;
    EXPECT_NE(literal.find("s0 = sharpDifference(s0, s4);"), std::string::npos) << literal;
    EXPECT_NE(literal.find("d1 = opUnion(d1, d3, 0.25);"), std::string::npos) << literal;
    const std::string buffer = generateSceneGlsl(scene);
    EXPECT_EQ(buffer.find("sharp"), std::string::npos) << buffer;
    EXPECT_NE(buffer.find("d0 = opDifference(d0, d4, nodeSmooth(0u), nodeBlend(0u));"),
              std::string::npos)
        << buffer;
}

// Inlined evaluation inlines every value it is asked to, and takes at most kInlinedMaxNodes
// nodes: a larger scene is refused, naming the limit and the modes that take it.
TEST(Codegen, InlinedEvaluationIsBounded) {
    CodegenOptions inl;
    inl.inlineParams = true;
    inl.evaluation = Evaluation::Inlined; // by default, such scenes run pruned tapes
    const Scene atLimit = smoothChain(int(kInlinedMaxNodes) - 1); // the union and its spheres
    ASSERT_EQ(atLimit.nodes.size(), kInlinedMaxNodes);
    EXPECT_EQ(generateSceneGlsl(atLimit, inl).find("nodes["), std::string::npos);
    EXPECT_TRUE(checkEvaluation(atLimit, Evaluation::Inlined));
    Scene past = smoothChain(int(kInlinedMaxNodes));
    past.file = "big.json";
    auto refused = checkEvaluation(past, Evaluation::Inlined);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().kind, ErrorKind::Limit);
    EXPECT_EQ(refused.error().str(),
              "big.json: root: inlined evaluation takes at most 512 nodes and this scene has 513; "
              "evaluate it from tapes (--evaluation tapes or auto)");
    EXPECT_TRUE(checkEvaluation(past, Evaluation::Auto));
    EXPECT_TRUE(checkEvaluation(past, Evaluation::Tapes));
}

TEST(Codegen, CompileErrorsComeBackWithTheLog) {
    auto broken =
        compileKernel("probe.comp", "float sceneDistance(vec3 p) { return undefinedThing; }\n");
    ASSERT_FALSE(broken);
    EXPECT_EQ(broken.error().kind, ErrorKind::Shader);
    std::string log = broken.error().str();
    EXPECT_NE(log.find("undefinedThing"), std::string::npos) << log;
    EXPECT_NE(log.find("probe.comp"), std::string::npos) << log;

    auto missing = compileKernel("no_such_kernel.comp", "");
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().kind, ErrorKind::Shader);

    auto syntax = compileKernel("probe.comp", "float sceneDistance(vec3 p) { return 1.0 }\n");
    ASSERT_FALSE(syntax);
    EXPECT_NE(syntax.error().str().find("scene.glsl"), std::string::npos) << syntax.error().str();
}

TEST(Codegen, SpirvIsCachedInMemoryAndOnDisk) {
    fs::path dir = fs::path(SDFCSG_TEST_OUTPUT_DIR) / "codegen-cache";
    fs::remove_all(dir);
    const CompileOptions cache{dir};
    // A scene no other test (or earlier run) compiles.
    std::string glsl = generateSceneGlsl(randomScene(99, 30));
    glsl +=
        "// " + std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()) + "\n";

    auto before = detail::shaderCacheStats();
    auto first = compileKernel("probe.comp", glsl, cache);
    ASSERT_TRUE(first) << first.error().str();
    auto afterFirst = detail::shaderCacheStats();
    EXPECT_EQ(afterFirst.compiles, before.compiles + 1);

    auto second = compileKernel("probe.comp", glsl, cache);
    ASSERT_TRUE(second);
    EXPECT_EQ(*second, *first);
    EXPECT_EQ(detail::shaderCacheStats().memoryHits, afterFirst.memoryHits + 1);
    EXPECT_EQ(detail::shaderCacheStats().compiles, afterFirst.compiles);

    // A new process would find it on disk.
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(dir))
        files.push_back(entry.path());
    ASSERT_EQ(files.size(), 1u) << "one entry, no temporary files left behind";
    EXPECT_EQ(files[0].extension(), ".spv");
    clearShaderMemoryCache();
    auto diskHits = detail::shaderCacheStats().diskHits;
    auto third = compileKernel("probe.comp", glsl, cache);
    ASSERT_TRUE(third);
    EXPECT_EQ(*third, *first);
    EXPECT_EQ(detail::shaderCacheStats().diskHits, diskHits + 1);

    // A damaged entry is ignored, recompiled and replaced.
    for (int damage = 0; damage < 2; ++damage) {
        if (damage == 0)
            fs::resize_file(files[0], fs::file_size(files[0]) / 2);
        else {
            std::fstream f(files[0], std::ios::in | std::ios::out | std::ios::binary);
            f.seekg(100);
            char byte = char(f.get());
            f.seekp(100);
            f.put(char(byte ^ 0x5a));
        }
        clearShaderMemoryCache();
        auto compiles = detail::shaderCacheStats().compiles;
        auto again = compileKernel("probe.comp", glsl, cache);
        ASSERT_TRUE(again);
        EXPECT_EQ(*again, *first);
        EXPECT_EQ(detail::shaderCacheStats().compiles, compiles + 1);
        clearShaderMemoryCache();
        diskHits = detail::shaderCacheStats().diskHits;
        EXPECT_TRUE(compileKernel("probe.comp", glsl, cache));
        EXPECT_EQ(detail::shaderCacheStats().diskHits, diskHits + 1) << "rewritten";
    }

    // An empty path disables the disk cache.
    fs::remove_all(dir);
    clearShaderMemoryCache();
    EXPECT_TRUE(compileKernel("probe.comp", glsl, CompileOptions{fs::path()}));
    EXPECT_FALSE(fs::exists(dir));
}

// A tiny cap: each write trims the folder to it, the least recently used entries first, and
// reading an entry makes it the most recently used.
TEST(Codegen, DiskCacheStaysUnderItsCapLeastRecentlyUsedFirst) {
    const fs::path dir = fs::path(SDFCSG_TEST_OUTPUT_DIR) / "codegen-cache-cap";
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::ofstream(dir / "notes.txt") << "not the cache's";
    const std::string stamp =
        std::to_string(std::chrono::steady_clock::now().time_since_epoch().count());
    // Four scenes no other test compiles, each a file of the same size (within a few bytes).
    std::vector<std::string> glsl;
    for (int i = 0; i < 4; ++i)
        glsl.push_back(generateSceneGlsl(randomScene(7, 3)) + "// " + stamp + " " +
                       std::to_string(i) + "\n");
    CompileOptions uncapped{dir};
    std::vector<fs::path> files;
    const auto now = fs::file_time_type::clock::now();
    for (int i = 0; i < 3; ++i) {
        std::set<fs::path> before;
        for (const auto& entry : fs::directory_iterator(dir))
            before.insert(entry.path());
        ASSERT_TRUE(compileKernel("probe.comp", glsl[i], uncapped));
        for (const auto& entry : fs::directory_iterator(dir))
            if (!before.count(entry.path())) files.push_back(entry.path());
        ASSERT_EQ(files.size(), size_t(i) + 1);
        // Entry 0 the oldest, then 1, then 2.
        fs::last_write_time(files[i], now - std::chrono::minutes(30 - 10 * i));
    }
    const uint64_t entryBytes = fs::file_size(files[0]);

    // Reading entry 0 back from disk makes it the most recently used.
    clearShaderMemoryCache();
    const auto diskHits = detail::shaderCacheStats().diskHits;
    ASSERT_TRUE(compileKernel("probe.comp", glsl[0], uncapped));
    ASSERT_EQ(detail::shaderCacheStats().diskHits, diskHits + 1);
    EXPECT_GT(fs::last_write_time(files[0]), now - std::chrono::minutes(1));

    // Room for two entries: writing a fourth removes 1 and 2, the least recently used.
    CompileOptions capped{dir, 2 * entryBytes + entryBytes / 2};
    const auto evictions = detail::shaderCacheStats().evictions;
    ASSERT_TRUE(compileKernel("probe.comp", glsl[3], capped));
    EXPECT_EQ(detail::shaderCacheStats().evictions, evictions + 2);
    EXPECT_TRUE(fs::exists(files[0]));
    EXPECT_FALSE(fs::exists(files[1]));
    EXPECT_FALSE(fs::exists(files[2]));
    EXPECT_TRUE(fs::exists(dir / "notes.txt"));
    uint64_t total = 0;
    size_t entries = 0;
    for (const auto& entry : fs::directory_iterator(dir))
        if (entry.path().extension() == ".spv") total += entry.file_size(), ++entries;
    EXPECT_EQ(entries, 2u);
    EXPECT_LE(total, *capped.cacheMaxBytes);

    // A cap below one entry keeps the entry just written, and nothing else.
    CompileOptions tiny{dir, 1};
    clearShaderMemoryCache();
    ASSERT_TRUE(compileKernel("probe.comp", glsl[1], tiny));
    entries = 0;
    for (const auto& entry : fs::directory_iterator(dir))
        entries += entry.path().extension() == ".spv";
    EXPECT_EQ(entries, 1u);
    clearShaderMemoryCache();
    const auto hits = detail::shaderCacheStats().diskHits;
    ASSERT_TRUE(compileKernel("probe.comp", glsl[1], tiny));
    EXPECT_EQ(detail::shaderCacheStats().diskHits, hits + 1);
}

// Processes share the folder: a reader keeps an entry that another trims away, files that
// vanish while a trim lists them are skipped, and a dead writer's old temporaries go.
TEST(Codegen, TrimmingToleratesVanishingFilesAndOpenReaders) {
    const fs::path dir = fs::path(SDFCSG_TEST_OUTPUT_DIR) / "codegen-cache-trim";
    fs::remove_all(dir);
    fs::create_directories(dir);
    auto name = [](int i) {
        char text[32];
        std::snprintf(text, sizeof text, "%016x.spv", i);
        return std::string(text);
    };
    const std::string bytes(1000, 'x');
    for (int i = 0; i < 400; ++i)
        std::ofstream(dir / name(i)) << bytes;
    std::ifstream reader(dir / name(0), std::ios::binary);
    ASSERT_TRUE(reader);
    std::thread remover([&] {
        for (int i = 399; i > 0; --i) {
            std::error_code ec;
            fs::remove(dir / name(i), ec);
        }
    });
    for (int round = 0; round < 20; ++round)
        detail::trimShaderCache(dir, 0);
    remover.join();
    EXPECT_TRUE(fs::is_empty(dir));
    std::string read((std::istreambuf_iterator<char>(reader)), std::istreambuf_iterator<char>());
    EXPECT_EQ(read, bytes) << "an open entry stays readable after it is trimmed away";

    const fs::path fresh = dir / (name(1) + ".tmp123.0"), stale = dir / (name(2) + ".tmp456.0");
    std::ofstream(fresh) << bytes;
    std::ofstream(stale) << bytes;
    fs::last_write_time(stale, fs::file_time_type::clock::now() - std::chrono::hours(2));
    detail::trimShaderCache(dir, 0);
    EXPECT_TRUE(fs::exists(fresh)) << "a temporary being written stays";
    EXPECT_FALSE(fs::exists(stale));
}

// The variables of sdfcsg/context.h, as the library reads them once (gpu/environment.h).
TEST(Codegen, SettingsFromTheEnvironment) {
    std::map<std::string, std::string> environment;
    auto read = [&] {
        return detail::readEnvironment([&](const char* name) -> const char* {
            auto it = environment.find(name);
            return it == environment.end() ? nullptr : it->second.c_str();
        });
    };
    detail::Environment e = read();
    EXPECT_EQ(e.validation, -1);
    EXPECT_EQ(e.device, "");
    EXPECT_EQ(e.shaderCacheDir, fs::path()) << "no disk cache without a home";

    environment = {{"HOME", "/home/someone"}, {"SDFCSG_VALIDATION", "0"}};
    e = read();
    EXPECT_EQ(e.validation, 0);
    EXPECT_EQ(e.shaderCacheDir, fs::path("/home/someone/.cache/sdfcsg"));

    environment["XDG_CACHE_HOME"] = "/cache";
    environment["SDFCSG_VALIDATION"] = "1";
    environment["SDFCSG_DEVICE"] = "llvmpipe";
    e = read();
    EXPECT_EQ(e.validation, 1);
    EXPECT_EQ(e.device, "llvmpipe");
    EXPECT_EQ(e.shaderCacheDir, fs::path("/cache/sdfcsg"));

    environment["SDFCSG_CACHE_DIR"] = "/spirv";
    EXPECT_EQ(read().shaderCacheDir, fs::path("/spirv"));
    environment["SDFCSG_CACHE_DIR"] = "off";
    EXPECT_EQ(read().shaderCacheDir, fs::path());
    environment["SDFCSG_CACHE_DIR"] = ""; // empty is unset
    environment["SDFCSG_VALIDATION"] = "";
    e = read();
    EXPECT_EQ(e.shaderCacheDir, fs::path("/cache/sdfcsg"));
    EXPECT_EQ(e.validation, -1);

    EXPECT_EQ(e.shaderCacheMaxBytes, uint64_t(64) << 20);
    environment["SDFCSG_CACHE_SIZE"] = "16";
    EXPECT_EQ(read().shaderCacheMaxBytes, uint64_t(16) << 20);
    environment["SDFCSG_CACHE_SIZE"] = "0.5";
    EXPECT_EQ(read().shaderCacheMaxBytes, uint64_t(1) << 19);
    for (const char* ignored : {"0", "-3", "lots", "12MB", ""}) {
        environment["SDFCSG_CACHE_SIZE"] = ignored;
        EXPECT_EQ(read().shaderCacheMaxBytes, uint64_t(64) << 20) << ignored;
    }
}

} // namespace
} // namespace sdfcsg
