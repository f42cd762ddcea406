// sdfcsg bench: median frame times with and without bounds skipping, and the time from scene
// JSON to a ready pipeline, for every scene in a folder; with --mesh, median mesh extraction
// times per stage at several resolutions instead.
#include "bench.h"
#include "cli.h"

#include <sdfcsg/sdfcsg.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

namespace sdfcsg::app {
namespace {

namespace fs = std::filesystem;

// Points Mesa's disk cache of machine code at a folder for a scope, then restores the variable.
// Mesa reads MESA_SHADER_CACHE_DIR whenever a device is made (a context's, and its compile
// helper's after each use) and offers no other way in. The benchmark does one thing at a time, so
// no thread of the library reads the environment while it changes.
class DriverCacheDir {
  public:
    explicit DriverCacheDir(const fs::path& dir) {
        if (const char* old = std::getenv(kName)) old_ = old;
        ::setenv(kName, dir.c_str(), 1);
    }
    ~DriverCacheDir() {
        if (old_)
            ::setenv(kName, old_->c_str(), 1);
        else
            ::unsetenv(kName);
    }
    DriverCacheDir(const DriverCacheDir&) = delete;
    DriverCacheDir& operator=(const DriverCacheDir&) = delete;

  private:
    static constexpr const char* kName = "MESA_SHADER_CACHE_DIR";
    std::optional<std::string> old_;
};

// The scenes (*.json) in `dir`, sorted; empty, with a message, when there are none.
std::vector<fs::path> findScenes(const fs::path& dir) {
    std::vector<fs::path> scenes;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(dir, ec))
        if (entry.path().extension() == ".json") scenes.push_back(entry.path());
    if (ec || scenes.empty()) {
        std::fprintf(stderr, "sdfcsg bench: no scenes (*.json) in %s\n", dir.string().c_str());
        return {};
    }
    std::sort(scenes.begin(), scenes.end());
    return scenes;
}

const char* kHelp =
    R"(Usage: sdfcsg bench [--scenes DIR] [--width W] [--height H] [--frames N] [--buffer]
                   [--evaluation E]
       sdfcsg bench --mesh [--scenes DIR] [--resolutions 128,256,512] [--runs N]
                   [--method dc|mc] [--simplify E] [--error] [--report]
       sdfcsg bench --mesh-node FILE... [--resolution N] [--runs N]

For every scene (*.json) in DIR (default assets/scenes), prints the median milliseconds per
frame in shaded mode with and without bounding-box skipping (after two warm-up frames; a frame
includes the read-back), and the median milliseconds from JSON text to a ready pipeline (parse,
code generation, GLSL compilation, pipeline creation including the driver's compile):
  cold        a new scene, none of its kernels cached (SPIR-V and driver disk caches in folders
              of their own), in a context that has built one other scene, and so has made the
              passes that do not depend on the scene: as in the viewer;
  one device  the same without the compile helper (see ContextOptions::compileHelper);
  new process the same in a new context, whose disk caches hold what the other scene's build
              in an earlier context left there: a new process on a machine that has run
              sdfcsg before;
  first       the first build of a new context with nothing cached at all;
  warm        with the SPIR-V and driver disk caches filled but the in-process cache cleared.
Then the repetition lines, per frame: a repeat of 64 copies and a polar_repeat of 24 against
one copy alone (framed on itself, so that it fills the picture as the copies do) and against
the union of the same copies as nodes of their own (the same picture).

Options:
  --scenes DIR   folder of scenes (default assets/scenes)
  --width W      image width (default 1280)
  --height H     image height (default 720)
  --frames N     timed frames per measurement (default 5)
  --evaluation E auto (default), inlined or tapes, as for render
  --buffer       also time a renderer that reads the values from the node buffer, as the
                 viewer's value edits do (so no recompile): its frame and its build from a
                 parsed scene, with nothing cached (slow to compile on lavapipe)

With --mesh, prints for every scene and resolution the median seconds of each stage of mesh
extraction and of the whole (from a compiled scene to an indexed mesh in host memory), over
--runs extractions (default 3) after one warm-up per scene. The resolution is the number of
cells along the longest axis of the bounds: the scene's finite bounds plus a margin, except
for the reference scenes mesh_a and mesh_b, which are meshed in the bounds their benchmark
defines. --method picks dual contouring (default) or marching cubes. --simplify E then
simplifies every mesh with a largest error of E cells (as sdfcsg mesh --simplify does, its
time in the total), and the triangle counts before and after are shown. --error adds the
distance from the surface of points spread over every triangle (not only its vertices),
by the CPU evaluator, in cells: the largest and the 99th percentile. --report adds the median
seconds of the mesh report on each mesh (as sdfcsg mesh --report computes it, walls from the
field included), beside the extraction and not in its total.

With --mesh-node, prints for every mesh file the median seconds from the file to a mesh node's
ready field ('sdfcsg bench --mesh-node --help' says more).
)";

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    size_t n = v.size();
    return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

bool parseCount(const char* s, uint32_t lo, uint32_t hi, uint32_t& out) {
    char* end = nullptr;
    unsigned long v = std::strtoul(s, &end, 10);
    if (!*s || *end || *s == '-' || v < lo || v > hi) return false;
    out = uint32_t(v);
    return true;
}

// A scene's JSON, the files it names relative to its file's folder, as loadScene() reads them.
Result<Scene> parseAt(const std::string& json, const std::string& file) {
    ParseOptions options;
    options.files.folder = std::filesystem::path(file).parent_path();
    return parseScene(json, file, options);
}

// JSON text to a renderer with its pipeline built.
Result<std::unique_ptr<Renderer>> buildFromJson(Context& context, const std::string& json,
                                                const std::string& file,
                                                Evaluation evaluation = Evaluation::Auto) {
    auto scene = parseAt(json, file);
    if (!scene) return scene.error();
    RendererOptions options;
    options.evaluation = evaluation;
    return Renderer::create(context, *scene, options);
}

Result<double> medianFrameMs(Renderer& renderer, const RenderOptions& options, uint32_t frames) {
    std::vector<double> times;
    for (uint32_t i = 0; i < frames + 2; ++i) {
        auto start = Clock::now();
        auto image = renderer.render(options);
        if (!image) return image.error();
        if (i >= 2) times.push_back(msSince(start));
    }
    return median(times);
}

// A value edit as the viewer makes one on a scene of pruned tapes: the last primitive moved back
// and forth by a hundredth of the scene's size, then a frame (updateValues() prunes the field
// again and uploads it; no compile).
Result<double> medianEditMs(Renderer& renderer, const Scene& scene, const RenderOptions& options,
                            uint32_t frames) {
    size_t moved = scene.nodes.size();
    while (moved > 0 && kindInfo(scene.nodes[moved - 1].kind).operation)
        --moved;
    if (moved == 0) return 0.0;
    const Aabb box = Evaluator(scene).bounds();
    const float step = box.finite() ? 0.01f * glm::length(box.max - box.min) : 0.01f;
    std::vector<double> times;
    Scene edited = scene;
    for (uint32_t i = 0; i < frames; ++i) {
        edited.nodes[moved - 1].transform.translate.x += i % 2 == 0 ? step : -step;
        auto start = Clock::now();
        if (auto ok = renderer.updateValues(edited); !ok) return ok.error();
        auto image = renderer.render(options);
        if (!image) return image.error();
        times.push_back(msSince(start));
    }
    if (auto ok = renderer.updateValues(scene); !ok) return ok.error();
    return median(times);
}

// Repetitions against the copies written out: per frame, one copy alone framed on itself (so
// that it fills the picture about as the N copies do), a repeat or polar_repeat of N copies,
// and the union of the same N copies as nodes of their own with the same camera.
struct RepeatCase {
    const char* name;
    int copies;
    std::string repeated, unionOf; // root nodes
};

const char* const kCopy = R"({"type": "round_box", "size": [0.3, 0.3, 0.3], "radius": 0.05)";

std::string sceneJson(const std::string& root) {
    return R"({"version": 1, "root": )" + root + "}";
}

std::vector<RepeatCase> repeatCases() {
    RepeatCase grid{"repeat 8x8", 64, {}, {}};
    grid.repeated = R"({"type": "repeat", "count": [8, 1, 8], "spacing": [0.5, 1, 0.5], )"
                    R"("children": [)" +
                    std::string(kCopy) + "}]}";
    RepeatCase ring{"polar_repeat 24", 24, {}, {}};
    ring.repeated = R"({"type": "polar_repeat", "count": 24, "radius": 1.5, "children": [)" +
                    std::string(kCopy) + "}]}";
    for (RepeatCase* c : {&grid, &ring}) {
        c->unionOf = R"({"type": "union", "children": [)";
        for (int i = 0; i < c->copies; ++i) {
            c->unionOf += i ? ", " : "";
            if (c == &grid)
                c->unionOf += kCopy + std::string(R"(, "translate": [)") +
                              std::to_string(0.5 * (i % 8 - 3.5)) + ", 0, " +
                              std::to_string(0.5 * (i / 8 - 3.5)) + "]}";
            else
                c->unionOf += R"({"type": "union", "rotate": [0, )" + std::to_string(15 * i) +
                              R"(, 0], "children": [)" + kCopy + R"(, "translate": [1.5, 0, 0]}]})";
        }
        c->unionOf += "]}";
    }
    return {grid, ring};
}

// Prints the repetition lines; false after printing an error.
bool runRepeatBench(Context& context, uint32_t width, uint32_t height, uint32_t frames) {
    std::printf("\n%-16s %6s %8s %10s %9s %11s\n", "repetition", "copies", "one ms", "repeat ms",
                "union ms", "repeat/one");
    for (const RepeatCase& c : repeatCases()) {
        auto framing = parseScene(sceneJson(c.repeated), c.name);
        if (!framing) return std::fprintf(stderr, "%s\n", framing.error().str().c_str()), false;
        RenderOptions options;
        options.width = width, options.height = height;
        double ms[3] = {};
        const std::string roots[3] = {kCopy + std::string("}"), c.repeated, c.unionOf};
        for (int k = 0; k < 3; ++k) {
            if (k == 0)
                options.camera.reset(); // one copy fills the picture as the N do
            else
                options.camera = frameCamera(Evaluator(*framing), float(width) / float(height));
            auto renderer = buildFromJson(context, sceneJson(roots[k]), c.name);
            auto frame = renderer ? medianFrameMs(**renderer, options, frames)
                                  : Result<double>(renderer.error());
            if (!frame) return std::fprintf(stderr, "%s\n", frame.error().str().c_str()), false;
            ms[k] = *frame;
        }
        std::printf("%-16s %6d %8.1f %10.1f %9.1f %10.2fx\n", c.name, c.copies, ms[0], ms[1], ms[2],
                    ms[1] / std::max(ms[0], 1e-9));
    }
    return true;
}

struct Row {
    std::string name;
    size_t nodes = 0;
    double skip = 0, noSkip = 0, cold = 0, coldOneDevice = 0, newProcess = 0, first = 0, warm = 0;
    double edit = NAN;                  // scenes of pruned tapes
    double buffer = 0, bufferBuild = 0; // with --buffer

    // The build columns' medians: cold, one device, new process and first, then warm.
    void builds(const std::vector<double> (&coldRuns)[4], const std::vector<double>& warmRuns) {
        cold = median(coldRuns[0]);
        coldOneDevice = median(coldRuns[1]);
        newProcess = median(coldRuns[2]);
        first = median(coldRuns[3]);
        warm = median(warmRuns);
    }
};

// The reference scenes of the mesh benchmark come with bounds of their own; every other scene
// is meshed in its default bounds. (The scene format has no field for meshing bounds.)
struct ReferenceBounds {
    const char* scene; // file stem
    Aabb bounds;
};
const ReferenceBounds kReferenceBounds[] = {
    {"mesh_a", {glm::vec3(-1.1f), glm::vec3(1.1f)}},
    {"mesh_b", {glm::vec3(-1.0f), glm::vec3(1.0f)}},
};

bool parseList(const char* s, std::vector<uint32_t>& out) {
    out.clear();
    std::string text = s;
    size_t start = 0;
    for (size_t i = 0; i <= text.size(); ++i)
        if (i == text.size() || text[i] == ',') {
            uint32_t v = 0;
            if (!parseCount(text.substr(start, i - start).c_str(), 1, 1u << 16, v)) return false;
            out.push_back(v);
            start = i + 1;
        }
    return !out.empty();
}

struct MeshRow {
    std::string scene;
    uint32_t resolution = 0;
    glm::uvec3 cells{0};
    uint64_t triangles = 0, unsimplified = 0;
    float maxError = NAN, p99Error = NAN; // cells
    std::vector<double> stages;           // median seconds, in the order of the stage names
    double total = 0, report = NAN;       // median seconds; report: beside the total
};

// The distance from the surface, in cells of edge h, of the points kTriangleSamples of
// every triangle.
std::pair<float, float> surfaceError(const Mesh& mesh, const Evaluator& evaluator, float h) {
    std::vector<float> errors;
    errors.reserve(mesh.indices.size() / 3 * 7);
    for (size_t t = 0; t + 3 <= mesh.indices.size(); t += 3) {
        const glm::vec3 a = mesh.positions[mesh.indices[t]],
                        b = mesh.positions[mesh.indices[t + 1]],
                        c = mesh.positions[mesh.indices[t + 2]];
        for (const glm::vec3& w : kTriangleSamples)
            errors.push_back(std::abs(evaluator.distance(w.x * a + w.y * b + w.z * c)) / h);
    }
    if (errors.empty()) return {0.0f, 0.0f};
    const size_t p99 = errors.size() * 99 / 100;
    std::nth_element(errors.begin(), errors.begin() + p99, errors.end());
    return {*std::max_element(errors.begin(), errors.end()), errors[p99]};
}

// The arguments of the mesh benchmark.
struct MeshArgs {
    fs::path dir = "assets/scenes";
    std::vector<uint32_t> resolutions = {128, 256, 512};
    uint32_t runs = 3;
    MeshMethod method = MeshMethod::DualContouring;
    bool measureError = false, report = false;
    float simplifyCells = 0; // 0: no simplification
};

// Reads the arguments; an exit code where the run ends here (a bad argument).
std::optional<int> parseMeshArgs(int argc, char** argv, MeshArgs& args) {
    for (int i = 0; i < argc; ++i) {
        std::string_view a = argv[i];
        bool ok = true;
        if (a == "--mesh")
            continue;
        else if (a == "--error")
            args.measureError = true;
        else if (a == "--report")
            args.report = true;
        else if (i + 1 < argc && a == "--method" && std::string_view(argv[i + 1]) == "dc")
            args.method = MeshMethod::DualContouring, ++i;
        else if (i + 1 < argc && a == "--method" && std::string_view(argv[i + 1]) == "mc")
            args.method = MeshMethod::MarchingCubes, ++i;
        else if (i + 1 < argc && a == "--simplify") {
            char* end = nullptr;
            args.simplifyCells = std::strtof(argv[++i], &end);
            ok = *argv[i] && !*end && std::isfinite(args.simplifyCells) && args.simplifyCells > 0;
        } else if (i + 1 < argc && a == "--scenes")
            args.dir = argv[++i];
        else if (i + 1 < argc && a == "--resolutions")
            ok = parseList(argv[++i], args.resolutions);
        else if (i + 1 < argc && a == "--runs")
            ok = parseCount(argv[++i], 1, 1000, args.runs);
        else
            ok = false;
        if (!ok) return usageError("bench", "bad argument '" + std::string(argv[i]) + "'");
    }
    return std::nullopt;
}

// A row: the median of args.runs extractions at options.resolution (simplified with
// --simplify), per stage in the order of stageNames, which takes the stages it has not seen.
Status measureMeshRow(Mesher& mesher, const Evaluator& evaluator, const MeshOptions& options,
                      const MeshArgs& args, std::vector<std::string>& stageNames, MeshRow& row) {
    std::vector<std::vector<double>> stageTimes;
    std::vector<double> totals, reports;
    for (uint32_t run = 0; run < args.runs; ++run) {
        MeshStats stats;
        auto mesh = mesher.extract(options, &stats);
        if (mesh && args.simplifyCells > 0) {
            SimplifyOptions simplify;
            simplify.maxError = args.simplifyCells * stats.voxelSize;
            mesh = simplifyMesh(*mesh, evaluator, simplify, &stats);
            row.unsimplified = stats.unsimplifiedTriangles;
        }
        if (!mesh) return mesh.error();
        if (args.measureError && run == 0)
            std::tie(row.maxError, row.p99Error) = surfaceError(*mesh, evaluator, stats.voxelSize);
        if (args.report) {
            const auto start = Clock::now();
            reportMesh(*mesh, evaluator, defaultMinWall());
            reports.push_back(msSince(start) / 1000.0);
        }
        row.cells = stats.cells;
        row.triangles = stats.triangles;
        totals.push_back(stats.totalSeconds);
        for (const MeshStats::Stage& stage : stats.stages) {
            auto it = std::find(stageNames.begin(), stageNames.end(), stage.name);
            const size_t k = size_t(it - stageNames.begin());
            if (it == stageNames.end()) stageNames.push_back(stage.name);
            if (stageTimes.size() <= k) stageTimes.resize(k + 1);
            stageTimes[k].push_back(stage.seconds);
        }
    }
    for (const auto& times : stageTimes) // NaN: the stage did not run for this scene
        row.stages.push_back(times.empty() ? std::nan("") : median(times));
    row.total = median(totals);
    if (args.report) row.report = median(reports);
    return Ok{};
}

// A scene's rows, one per resolution, after a warm-up extraction at the first.
Status measureMeshScene(Context& context, const fs::path& path, const MeshArgs& args,
                        std::vector<std::string>& stageNames, std::vector<MeshRow>& rows) {
    const std::string name = path.stem().string();
    auto scene = loadScene(path);
    if (!scene) return scene.error();
    auto mesher = Mesher::create(context, *scene);
    if (!mesher) return mesher.error();
    const Evaluator& evaluator = (*mesher)->evaluator();
    MeshOptions options;
    options.method = args.method;
    for (const ReferenceBounds& r : kReferenceBounds)
        if (name == r.scene) options.bounds = r.bounds;
    options.resolution = args.resolutions.front();
    if (auto warm = (*mesher)->extract(options); !warm) return warm.error();
    for (uint32_t resolution : args.resolutions) {
        options.resolution = resolution;
        MeshRow row;
        row.scene = name;
        row.resolution = resolution;
        if (auto ok = measureMeshRow(**mesher, evaluator, options, args, stageNames, row); !ok)
            return ok;
        std::fprintf(stderr, "  %s at %u done\n", name.c_str(), resolution);
        rows.push_back(row);
    }
    return Ok{};
}

void printMeshRows(const std::vector<MeshRow>& rows, const std::vector<std::string>& stageNames,
                   const MeshArgs& args) {
    std::printf("\n%-16s %5s %16s %10s", "scene", "res", "cells", "triangles");
    if (args.simplifyCells > 0) std::printf(" %10s", "before");
    for (const std::string& stage : stageNames)
        std::printf(" %*s", int(std::max<size_t>(stage.size(), 8)), stage.c_str());
    std::printf(" %8s", "total s");
    if (args.measureError) std::printf(" %9s %9s", "max err", "p99 err");
    if (args.report) std::printf(" %8s", "report s");
    std::printf("\n");
    for (const MeshRow& r : rows) {
        const std::string cells = std::to_string(r.cells.x) + "x" + std::to_string(r.cells.y) +
                                  "x" + std::to_string(r.cells.z);
        std::printf("%-16s %5u %16s %10llu", r.scene.c_str(), r.resolution, cells.c_str(),
                    static_cast<unsigned long long>(r.triangles));
        if (args.simplifyCells > 0)
            std::printf(" %10llu", static_cast<unsigned long long>(r.unsimplified));
        for (size_t k = 0; k < stageNames.size(); ++k) {
            const int width = int(std::max<size_t>(stageNames[k].size(), 8));
            if (k < r.stages.size() && !std::isnan(r.stages[k]))
                std::printf(" %*.3f", width, r.stages[k]);
            else
                std::printf(" %*s", width, "-");
        }
        std::printf(" %8.3f", r.total);
        if (args.measureError) std::printf(" %9.3f %9.3f", r.maxError, r.p99Error);
        if (args.report) std::printf(" %8.3f", r.report);
        std::printf("\n");
    }
    std::printf(
        "\nSeconds, median per stage and in total, from a compiled scene to an indexed mesh "
        "in host memory. res: cells along the longest axis of the bounds.\n");
}

int runMeshBench(int argc, char** argv) {
    MeshArgs args;
    if (auto exit = parseMeshArgs(argc, argv, args)) return *exit;
    std::vector<fs::path> scenes = findScenes(args.dir);
    if (scenes.empty()) return 3;
    auto context = Context::create();
    if (!context) {
        std::fprintf(stderr, "%s\n", context.error().str().c_str());
        return 4;
    }
    std::printf("device: %s, median of %u extraction%s (1 warm-up per scene)\n",
                (*context)->deviceName().c_str(), args.runs, args.runs == 1 ? "" : "s");
    std::vector<std::string> stageNames; // in the order the mesher reports them
    std::vector<MeshRow> rows;
    int status = 0;
    for (const fs::path& path : scenes)
        if (auto ok = measureMeshScene(**context, path, args, stageNames, rows); !ok) {
            const Error& e = ok.error();
            std::fprintf(stderr, "%s: %s\n", path.string().c_str(), e.str().c_str());
            status = exitCode(e);
            break;
        }
    printMeshRows(rows, stageNames, args);
    return status;
}

// The arguments of the render benchmark.
struct RenderArgs {
    fs::path dir = "assets/scenes";
    uint32_t width = 1280, height = 720, frames = 5;
    bool buffer = false;
    Evaluation evaluation = Evaluation::Auto;
};

// Reads the arguments; an exit code where the run ends here (help, or a bad argument).
std::optional<int> parseRenderArgs(int argc, char** argv, RenderArgs& args) {
    for (int i = 0; i < argc; ++i) {
        std::string_view a = argv[i];
        if (a == "--help" || a == "-h") {
            std::fputs(kHelp, stdout);
            return 0;
        }
        if (a == "--buffer") {
            args.buffer = true;
            continue;
        }
        bool ok = i + 1 < argc;
        if (ok && a == "--scenes")
            args.dir = argv[++i];
        else if (ok && a == "--width")
            ok = parseCount(argv[++i], 1, 16384, args.width);
        else if (ok && a == "--height")
            ok = parseCount(argv[++i], 1, 16384, args.height);
        else if (ok && a == "--frames")
            ok = parseCount(argv[++i], 1, 1000, args.frames);
        else if (ok && a == "--evaluation") {
            const std::string_view v = argv[++i];
            ok = v == "auto" || v == "inlined" || v == "tapes";
            args.evaluation = v == "inlined" ? Evaluation::Inlined
                              : v == "tapes" ? Evaluation::Tapes
                                             : Evaluation::Auto;
        } else
            ok = false;
        if (!ok) return usageError("bench", "bad argument '" + std::string(argv[i]) + "'");
    }
    return std::nullopt;
}

// The frame columns: with and without bounds skipping, and for scenes of pruned tapes a value
// edit's frame.
Status measureFrames(Renderer& renderer, const std::string& json, const std::string& file,
                     const RenderArgs& args, RenderOptions options, Row& row) {
    options.boundsSkipping = true;
    auto skip = medianFrameMs(renderer, options, args.frames);
    if (!skip) return skip.error();
    options.boundsSkipping = false;
    auto noSkip = medianFrameMs(renderer, options, args.frames);
    if (!noSkip) return noSkip.error();
    row.skip = *skip;
    row.noSkip = *noSkip;
    if (auto scene = parseAt(json, file); scene && usesTapes(*scene, args.evaluation)) {
        options.boundsSkipping.reset();
        auto edit = medianEditMs(renderer, *scene, options, args.frames);
        if (!edit) return edit.error();
        row.edit = *edit;
    }
    return Ok{};
}

// The buffer columns (--buffer): a renderer that reads the values from the node buffer, built on
// `coldContext`, and its frame.
Status measureBuffer(Context& coldContext, const std::string& json, const std::string& file,
                     const RenderArgs& args, RenderOptions options, Row& row) {
    auto scene = parseAt(json, file);
    if (!scene) return scene.error();
    RendererOptions values;
    values.inlineValues = false;
    values.evaluation = args.evaluation;
    auto start = Clock::now();
    auto built = Renderer::create(coldContext, *scene, values);
    if (!built) return built.error();
    row.bufferBuild = msSince(start);
    options.boundsSkipping.reset();
    auto frame = medianFrameMs(**built, options, args.frames);
    if (!frame) return frame.error();
    row.buffer = *frame;
    return Ok{};
}

void printRenderRows(const std::vector<Row>& rows, bool buffer) {
    std::printf("\n%-13s %5s %8s %10s %7s %15s %10s %11s %6s %5s", "scene", "nodes", "skip ms",
                "no-skip ms", "speedup", "json->pipe cold", "one device", "new process", "first",
                "warm");
    std::printf(" %7s", "edit ms");
    if (buffer) std::printf(" %10s %16s", "buffer ms", "buffer build ms");
    std::printf("\n");
    for (const Row& r : rows) {
        std::printf("%-13s %5zu %8.1f %10.1f %6.2fx %15.1f %10.1f %11.1f %6.1f %5.1f",
                    r.name.c_str(), r.nodes, r.skip, r.noSkip, r.noSkip / std::max(r.skip, 1e-9),
                    r.cold, r.coldOneDevice, r.newProcess, r.first, r.warm);
        if (std::isnan(r.edit))
            std::printf(" %7s", "-");
        else
            std::printf(" %7.1f", r.edit);
        if (buffer) std::printf(" %10.1f %16.1f", r.buffer, r.bufferBuild);
        std::printf("\n");
    }
    std::printf(
        "\njson->pipe ms: parse + codegen + GLSL compile + pipelines ready to run. cold: a new "
        "scene, its kernels cached nowhere, in a context that has built another; one device: "
        "the same without the compile helper; new process: the same in a new context (the disk "
        "caches hold the other scene's build); first: a new context, nothing cached at all; "
        "warm: SPIR-V and driver disk caches filled, in-process cache cleared. edit ms (scenes "
        "of pruned tapes): a value edit as the viewer makes one, the field pruned again and "
        "uploaded, and the frame after it.\n"
        "Renders use bounds skipping by default on GPUs and not on CPU devices (lavapipe runs both "
        "sides of every branch, so there the bounds tests only add work).\n");
}

// A new folder under the temporary one; empty, with a message, when it cannot be made.
fs::path temporaryFolder() {
    std::string name = (fs::temp_directory_path() / "sdfcsg-bench-XXXXXX").string();
    if (!::mkdtemp(name.data())) {
        std::fprintf(stderr, "sdfcsg bench: cannot create a temporary cache folder\n");
        return {};
    }
    return name;
}

std::string readText(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

} // namespace

int runBench(int argc, char** argv) {
    if (std::find(argv, argv + argc, std::string_view("--mesh-node")) != argv + argc)
        return runMeshNodeBench(argc, argv);
    if (std::find(argv, argv + argc, std::string_view("--mesh")) != argv + argc) {
        for (int j = 0; j < argc; ++j)
            if (std::string_view(argv[j]) == "--help" || std::string_view(argv[j]) == "-h")
                return std::fputs(kHelp, stdout), 0;
        return runMeshBench(argc, argv);
    }
    RenderArgs args;
    if (auto exit = parseRenderArgs(argc, argv, args)) return *exit;
    const fs::path& dir = args.dir;
    const uint32_t width = args.width, height = args.height, frames = args.frames;
    const bool buffer = args.buffer;
    const Evaluation evaluation = args.evaluation;

    std::error_code ec;
    std::vector<fs::path> scenes = findScenes(dir);
    if (scenes.empty()) return 3;

    // A private disk cache, so "warm" means exactly this run's compiles; below it, an empty
    // folder for Mesa's disk cache for every cold build.
    const fs::path cacheDir = temporaryFolder();
    if (cacheDir.empty()) return 3;
    ContextOptions warmOptions;
    warmOptions.shaderCacheDir = cacheDir;
    auto context = Context::create(warmOptions);
    if (!context) {
        std::fprintf(stderr, "%s\n", context.error().str().c_str());
        fs::remove_all(cacheDir, ec);
        return 4;
    }
    constexpr int kPipelineRuns = 3;
    int coldRuns = 0;
    // The other scene of the cold column's contexts.
    const std::string kOtherScene = R"({"version": 1, "root": {"type": "sphere", "radius": 1}})";
    // Runs `work` on a new context whose SPIR-V and driver disk caches are folders of their own:
    // empty (Seed::None); or holding what building the other scene left there, in an earlier
    // context (Seed::Earlier: as a new process finds them on a machine that has run sdfcsg
    // before) or in this one (Seed::Same: as the viewer has them when it opens another scene).
    // Mesa reads its folder when a device is made (the compile helper's too, after each use), so
    // its variable stays set throughout.
    enum class Seed { None, Earlier, Same };
    auto withColdContext = [&](bool helper, Seed seed, auto&& work) -> Status {
        const fs::path runDir = cacheDir / ("cold-" + std::to_string(coldRuns++));
        std::error_code made;
        fs::create_directories(runDir, made); // Mesa makes only the last folder of its path
        const DriverCacheDir driverCache(runDir / "mesa");
        ContextOptions contextOptions;
        contextOptions.compileHelper = helper;
        contextOptions.shaderCacheDir = runDir / "spirv";
        auto buildOther = [&](Context& c) -> Status {
            clearShaderMemoryCache();
            auto other = buildFromJson(c, kOtherScene, "<other scene>");
            if (!other) return other.error();
            clearShaderMemoryCache();
            return Ok{};
        };
        if (seed == Seed::Earlier) {
            auto seeding = Context::create(contextOptions);
            if (!seeding) return seeding.error();
            if (auto ok = buildOther(**seeding); !ok) return ok;
        } // the context's end finishes the driver cache's writes
        auto coldContext = Context::create(contextOptions);
        if (!coldContext) return coldContext.error();
        if (seed == Seed::Same)
            if (auto ok = buildOther(**coldContext); !ok) return ok;
        clearShaderMemoryCache();
        return work(**coldContext);
    };

    std::printf("device: %s, %u x %u shaded, median of %u frames (2 warm-up)\n",
                (*context)->deviceName().c_str(), width, height, frames);
    std::vector<Row> rows;
    int status = 0;
    for (const fs::path& path : scenes) {
        const std::string json = readText(path), file = path.string();
        Row row;
        row.name = path.stem().string();

        auto fail = [&](const Error& e) {
            std::fprintf(stderr, "%s: %s\n", file.c_str(), e.str().c_str());
            status = exitCode(e);
        };
        // Alternated: cold, one device, new process, first.
        constexpr int kColdColumns = 4;
        const Seed seeds[kColdColumns] = {Seed::Same, Seed::Same, Seed::Earlier, Seed::None};
        std::vector<double> cold[kColdColumns], warm;
        std::unique_ptr<Renderer> renderer;
        for (int i = 0; i < kColdColumns * kPipelineRuns && status == 0; ++i) {
            const int column = i % kColdColumns;
            auto build = [&](Context& coldContext) -> Status {
                auto start = Clock::now();
                auto built = buildFromJson(coldContext, json, file, evaluation);
                if (!built) return built.error();
                cold[column].push_back(msSince(start));
                return Ok{};
            };
            auto ok = withColdContext(column != 1, seeds[column], build);
            if (!ok) fail(ok.error());
        }
        for (int i = 0; i <= kPipelineRuns && status == 0; ++i) { // on cacheDir's SPIR-V
            clearShaderMemoryCache();
            auto start = Clock::now();
            auto built = buildFromJson(**context, json, file, evaluation);
            if (!built)
                fail(built.error());
            else if (i > 0)
                warm.push_back(msSince(start)); // run 0 fills the disk cache
            if (built) renderer = std::move(*built);
        }
        if (status != 0) break;
        row.builds(cold, warm);
        if (auto scene = parseAt(json, file)) row.nodes = scene->nodes.size();

        RenderOptions options;
        options.width = width;
        options.height = height;
        if (auto ok = measureFrames(*renderer, json, file, args, options, row); !ok) {
            fail(ok.error());
            break;
        }
        if (buffer) {
            auto ok = withColdContext(true, Seed::None, [&](Context& coldContext) {
                return measureBuffer(coldContext, json, file, args, options, row);
            });
            if (!ok) {
                fail(ok.error());
                break;
            }
        }
        std::fprintf(stderr, "  %s done\n", row.name.c_str());
        rows.push_back(row);
    }
    fs::remove_all(cacheDir, ec);

    printRenderRows(rows, buffer);
    if (status == 0 && !runRepeatBench(**context, width, height, frames)) status = 4;
    return status;
}

} // namespace sdfcsg::app
