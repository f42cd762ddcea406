// sdfcsg bench --mesh-node: the time from a mesh file to a mesh node's ready field (the file
// read, its triangles welded, its distance field baked), per file.
#include "bench.h"
#include "cli.h"

#include <sdfcsg/sdfcsg.h>

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace sdfcsg::app {
namespace {

namespace fs = std::filesystem;

const char* kHelp =
    R"(Usage: sdfcsg bench --mesh-node FILE... [--resolution N] [--runs N]

For every mesh file (STL, OBJ, PLY, glTF binary or 3MF), prints the median seconds from the
file to a mesh node's ready field over --runs parses (default 3) of a scene of one mesh node
that names it at --resolution cells (default 128, the node's default): the file read, its
triangles welded, the field's bricks baked and its words made. Then the field's size and the
process's peak resident memory so far (after every file before it too: for one file's figure,
name one file).
)";

// The scene JSON of one mesh node reading `file` at `resolution` cells.
std::string meshScene(const fs::path& file, unsigned resolution) {
    std::string name;
    for (char c : file.filename().string()) { // a file name of the benchmark's own choosing
        if (c == '"' || c == '\\') name += '\\';
        name += c;
    }
    return R"({"version": 1, "root": {"type": "mesh", "file": ")" + name + R"(", "resolution": )" +
           std::to_string(resolution) + "}}";
}

bool parseNumber(const char* s, unsigned lo, unsigned hi, unsigned& out) {
    char* end = nullptr;
    const unsigned long v = std::strtoul(s, &end, 10);
    if (!*s || *end || *s == '-' || v < lo || v > hi) return false;
    out = unsigned(v);
    return true;
}

} // namespace

int runMeshNodeBench(int argc, char** argv) {
    std::vector<fs::path> files;
    unsigned resolution = 128, runs = 3;
    for (int i = 0; i < argc; ++i) {
        const std::string_view a = argv[i];
        bool ok = true;
        if (a == "--help" || a == "-h")
            return std::fputs(kHelp, stdout), 0;
        else if (a == "--mesh-node")
            continue;
        else if (i + 1 < argc && a == "--resolution")
            ok = parseNumber(argv[++i], 8, 1024, resolution);
        else if (i + 1 < argc && a == "--runs")
            ok = parseNumber(argv[++i], 1, 1000, runs);
        else if (!a.empty() && a[0] != '-')
            files.emplace_back(a);
        else
            ok = false;
        if (!ok) return usageError("bench", "bad argument '" + std::string(argv[i]) + "'");
    }
    if (files.empty()) {
        std::fprintf(stderr, "sdfcsg bench: --mesh-node needs mesh files\n");
        return 2;
    }
    using Clock = std::chrono::steady_clock;
    std::printf("%-24s %9s %5s %10s %9s %9s\n", "file", "file MiB", "res", "seconds", "field MiB",
                "peak MiB");
    for (const fs::path& file : files) {
        ParseOptions options;
        options.files.folder = file.parent_path();
        const std::string json = meshScene(file, resolution);
        std::vector<double> seconds;
        size_t fieldBytes = 0;
        for (unsigned run = 0; run < runs; ++run) {
            const auto start = Clock::now();
            auto scene = parseScene(json, file.string(), options);
            seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
            if (!scene) {
                std::fprintf(stderr, "%s\n", scene.error().str().c_str());
                return 1;
            }
            for (const Node& node : scene->nodes)
                if (node.words) fieldBytes = node.words->size() * sizeof(glm::vec4);
        }
        std::sort(seconds.begin(), seconds.end());
        std::error_code ec;
        const double fileMiB = double(fs::file_size(file, ec)) / double(1 << 20);
        rusage usage{};
        ::getrusage(RUSAGE_SELF, &usage); // ru_maxrss in KiB on Linux
        std::printf("%-24s %9.1f %5u %10.3f %9.1f %9.1f\n", file.filename().string().c_str(),
                    fileMiB, resolution, seconds[seconds.size() / 2],
                    double(fieldBytes) / double(1 << 20), double(usage.ru_maxrss) / 1024.0);
    }
    std::printf("\nSeconds: median from the mesh file to its node's ready field.\n");
    return 0;
}

} // namespace sdfcsg::app
