// sdfcsg: the command-line tool. A thin layer over the engine library: argument parsing,
// messages and exit codes live here, everything else in sdfcsg::engine.
#include "bench.h"
#include "cli.h"
#include "generate.h"

#include <sdfcsg/sdfcsg.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <sys/resource.h>
#include <unistd.h>

namespace {

using namespace sdfcsg::app;

// A minimal option reader: positional arguments, and options that take a value.
struct Args {
    std::string command;
    std::vector<std::string> positional;
    std::vector<std::pair<std::string, std::string>> options; // name -> value ("" for flags)
    std::string error;

    Args(std::string cmd, int argc, char** argv, std::vector<std::string_view> valued,
         std::vector<std::string_view> flags)
        : command(std::move(cmd)) {
        for (int i = 0; i < argc; ++i) {
            std::string_view a = argv[i];
            if (a.size() > 1 && a[0] == '-' &&
                !(a.size() > 1 && (std::isdigit(a[1]) || a[1] == '.'))) {
                std::string name(a), value;
                if (auto eq = name.find('='); eq != std::string::npos) {
                    value = name.substr(eq + 1);
                    name.resize(eq);
                } else if (std::find(valued.begin(), valued.end(), name) != valued.end()) {
                    if (i + 1 >= argc) {
                        error = "option " + name + " needs a value";
                        return;
                    }
                    value = argv[++i];
                }
                bool known = std::find(valued.begin(), valued.end(), name) != valued.end() ||
                             std::find(flags.begin(), flags.end(), name) != flags.end();
                if (!known) {
                    error = "unknown option " + name;
                    return;
                }
                options.emplace_back(name, value);
            } else {
                positional.emplace_back(a);
            }
        }
    }
    bool has(std::string_view name) const {
        for (auto& [n, v] : options)
            if (n == name) return true;
        return false;
    }
    std::string get(std::string_view name, std::string fallback = {}) const {
        for (auto it = options.rbegin(); it != options.rend(); ++it)
            if (it->first == name) return it->second;
        return fallback;
    }
};

// A path's extension in lower case (".png"), or "" without one.
std::string lowerExtension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

bool parseUint(const std::string& s, uint32_t lo, uint32_t hi, uint32_t& out) {
    char* end = nullptr;
    errno = 0;
    unsigned long v = std::strtoul(s.c_str(), &end, 10);
    if (s.empty() || *end || errno || v < lo || v > hi || s[0] == '-') return false;
    out = uint32_t(v);
    return true;
}

bool parseFloat(const std::string& s, float& out) {
    char* end = nullptr;
    float v = std::strtof(s.c_str(), &end);
    if (s.empty() || *end || !std::isfinite(v)) return false;
    out = v;
    return true;
}

bool parseVec3(const std::string& s, glm::vec3& out) {
    std::vector<std::string> parts;
    size_t start = 0;
    for (size_t i = 0; i <= s.size(); ++i)
        if (i == s.size() || s[i] == ',') {
            parts.push_back(s.substr(start, i - start));
            start = i + 1;
        }
    if (parts.size() != 3) return false;
    for (int i = 0; i < 3; ++i)
        if (!parseFloat(parts[i], out[i])) return false;
    return true;
}

sdfcsg::Result<sdfcsg::Scene> load(const std::string& path) {
    return sdfcsg::loadScene(path);
}

const char* kMainHelp =
    R"(sdfcsg - constructive solid geometry on signed distance fields, with Vulkan

Usage: sdfcsg COMMAND [ARGS...]

Commands:
  render    ray-march a scene to a PNG image
  mesh      extract a triangle mesh (PLY, OBJ, STL, glTF binary or 3MF)
  validate  check scene files and list every problem found
  glsl      print the GLSL a scene compiles to
  convert   convert a scene (e.g. the legacy format) to the current format
  schema    print the JSON Schema of the scene format
  bench     measure frame, compile and meshing times on the bundled scenes
  generate  describe a scene in plain language and have a language model write it
  edit      change a scene by a plain-language instruction, through a language model
  eval-prompts  run a list of prompts through generate and report validity and cost

'sdfcsg COMMAND --help' describes a command. Exit codes: 0 success, 1 invalid scene or a
limit exceeded, 2 bad command line, 3 file read or write failure, 4 Vulkan or shader failure,
5 language model endpoint failure.
)";

const char* kRenderHelp = R"(Usage: sdfcsg render SCENE -o OUT.png [options]

Ray-marches SCENE with a Vulkan compute pass and writes a PNG (atomically). Notes on the
scene, as validate prints them, go to standard error.

Options:
  -o, --output FILE     output PNG (required); - for standard output. A symbolic link is
                        followed; a FIFO or a device is written into; any other file that is
                        not a regular one is refused
  --width W, --height H image size in pixels (default 800 x 600, at most 16384 each)
  --mode M              shaded (default), normals, depth or steps (iteration heat map)
  --eye X,Y,Z           camera position (default: the scene's camera, else framed)
  --target X,Y,Z        point the camera looks at
  --fov DEG             vertical field of view in degrees (default 45)
  --aa N                N x N samples per pixel (1..8, default 1)
  --no-shadows          disable soft shadows
  --no-ao               disable ambient occlusion
  --boxes all|none      overlay every node's bounding box
  --grid                a ground grid under the solid (lines a power of ten apart)
  --skip, --no-skip     force bounds skipping on or off (default: on for GPUs, off for
                        CPU devices, where it only adds work; the image is the same)
  --evaluation E        auto (default), inlined (every node a line of the kernel; at most
                        512 nodes) or tapes (per-region pruned tapes; the default from 160
                        nodes)
  --device NAME         Vulkan device: index or part of its name (also SDFCSG_DEVICE)
  --validation          enable the Vulkan validation layer
)";

// A one-line bar on a terminal, redrawn when the whole percentage changes.
class ProgressBar {
  public:
    explicit ProgressBar(const char* label) : label_(label) {}
    bool update(float fraction) {
        const int percent = int(std::clamp(fraction, 0.0f, 1.0f) * 100.0f);
        if (percent == shown_) return true;
        shown_ = percent;
        constexpr int kWidth = 40;
        const int filled = percent * kWidth / 100;
        std::fprintf(stderr, "\r%s [%.*s%*s] %3d%%", label_, filled,
                     "########################################", kWidth - filled, "", percent);
        std::fflush(stderr);
        return true;
    }
    ~ProgressBar() {
        if (shown_ >= 0) std::fprintf(stderr, "\r%60s\r", "");
    }

  private:
    const char* label_;
    int shown_ = -1;
};

// --evaluation auto|inlined|tapes (CodegenOptions); false with a message when it is neither.
bool parseEvaluation(const Args& args, const char* command, sdfcsg::Evaluation& out) {
    // kUsage comes from usageError(), which prints the message.
    if (!args.has("--evaluation")) return true;
    const std::string v = args.get("--evaluation");
    if (v == "auto")
        out = sdfcsg::Evaluation::Auto;
    else if (v == "inlined")
        out = sdfcsg::Evaluation::Inlined;
    else if (v == "tapes")
        out = sdfcsg::Evaluation::Tapes;
    else
        return usageError(command, "--evaluation expects auto, inlined or tapes, got '" + v + "'"),
               false;
    return true;
}

// The scene's notes (sdfcsg::fieldNotes), one a line as FILE: JSON.PATH: note: MESSAGE.
void printNotes(const std::string& path, const sdfcsg::Scene& scene, FILE* to) {
    for (const sdfcsg::FieldNote& note : sdfcsg::fieldNotes(scene, sdfcsg::Evaluator(scene)))
        std::fprintf(to, "%s: %s: note: %s\n", path.c_str(), note.path.c_str(),
                     note.message.c_str());
}

int cmdRender(int argc, char** argv) {
    Args args("render", argc, argv,
              {"-o", "--output", "--width", "--height", "--mode", "--eye", "--target", "--fov",
               "--aa", "--boxes", "--device", "--evaluation"},
              {"--no-shadows", "--no-ao", "--grid", "--skip", "--no-skip", "--validation", "--help",
               "-h"});
    if (args.has("--help") || args.has("-h")) return std::fputs(kRenderHelp, stdout), kOk;
    if (!args.error.empty()) return usageError("render", args.error);
    if (args.positional.size() != 1) return usageError("render", "expected one SCENE file");
    std::string out = args.get("-o", args.get("--output"));
    if (out.empty()) return usageError("render", "missing -o OUT.png");
    if (const std::string ext = lowerExtension(out); !ext.empty() && ext != ".png")
        return usageError("render", "render writes PNG images; the output must end in .png, got '" +
                                        out + "'");

    sdfcsg::RenderOptions options;
    if (args.has("--width") && !parseUint(args.get("--width"), 1, 16384, options.width))
        return usageError("render", "--width expects an integer in 1..16384");
    if (args.has("--height") && !parseUint(args.get("--height"), 1, 16384, options.height))
        return usageError("render", "--height expects an integer in 1..16384");
    if (args.has("--aa") && !parseUint(args.get("--aa"), 1, sdfcsg::kMaxAntialiasing, options.aa))
        return usageError("render", "--aa expects an integer in 1.." +
                                        std::to_string(sdfcsg::kMaxAntialiasing));
    if (args.has("--mode")) {
        auto mode = sdfcsg::parseRenderMode(args.get("--mode"));
        if (!mode)
            return usageError("render", "--mode expects shaded, normals, depth or steps, got '" +
                                            args.get("--mode") + "'");
        options.mode = *mode;
    }
    if (args.has("--boxes")) {
        std::string b = args.get("--boxes");
        if (b != "all" && b != "none") return usageError("render", "--boxes expects all or none");
        options.boxes = b == "all" ? sdfcsg::BoxOverlay::All : sdfcsg::BoxOverlay::None;
    }
    options.shadows = !args.has("--no-shadows");
    options.ambientOcclusion = !args.has("--no-ao");
    options.grid = args.has("--grid");
    if (args.has("--skip")) options.boundsSkipping = true;
    if (args.has("--no-skip")) options.boundsSkipping = false;
    if (auto writable = sdfcsg::checkOutput(out); !writable) return fail(writable.error());

    auto scene = load(args.positional[0]);
    if (!scene) return fail(scene.error());
    printNotes(args.positional[0], *scene, stderr);

    // Camera: explicit flags override the scene's camera, which overrides automatic framing.
    if (args.has("--eye") || args.has("--target") || args.has("--fov")) {
        sdfcsg::Evaluator evaluator(*scene);
        float aspect = float(options.width) / float(options.height);
        sdfcsg::Camera camera = scene->camera.value_or(sdfcsg::frameCamera(evaluator, aspect));
        if (args.has("--eye") && !parseVec3(args.get("--eye"), camera.eye))
            return usageError("render", "--eye expects X,Y,Z");
        if (args.has("--target") && !parseVec3(args.get("--target"), camera.target))
            return usageError("render", "--target expects X,Y,Z");
        if (args.has("--fov") && (!parseFloat(args.get("--fov"), camera.fov) ||
                                  camera.fov <= 0.0f || camera.fov >= 180.0f))
            return usageError("render", "--fov expects degrees in (0, 180)");
        if (camera.eye == camera.target)
            return usageError("render", "the camera's eye and target must differ");
        options.camera = camera;
    }

    sdfcsg::RendererOptions rendererOptions;
    if (!parseEvaluation(args, "render", rendererOptions.evaluation)) return kUsage;
    if (auto fits = sdfcsg::checkEvaluation(*scene, rendererOptions.evaluation); !fits)
        return fail(fits.error());
    sdfcsg::ContextOptions contextOptions;
    contextOptions.device = args.get("--device");
    if (args.has("--validation")) contextOptions.validation = 1;
    catchInterrupts(); // from here on, an interruption is reported (the watchdog's grace)
    auto context = sdfcsg::Context::create(contextOptions);
    if (!context) return fail(context.error());
    auto renderer = sdfcsg::Renderer::create(**context, *scene, rendererOptions);
    if (!renderer) return fail(renderer.error());
    auto image = [&] {
        ProgressBar bar("rendering"); // erased again when the render ends
        const bool tty = ::isatty(STDERR_FILENO);
        options.progress = [&](float done) { return (!tty || bar.update(done)) && !interrupted(); };
        return (*renderer)->render(options);
    }();
    if (!image) return fail(image.error());
    auto png = sdfcsg::encodePng(*image, out);
    if (!png) return fail(png.error());
    if (auto written = writeOutput(out, *png); !written) return fail(written.error());
    if (auto why = (*renderer)->nothingShown())
        std::fprintf(stderr, "warning: %s shows nothing: %s\n", out.c_str(), why->c_str());
    return kOk;
}

const char* kMeshHelp = R"(Usage: sdfcsg mesh SCENE -o OUT.(ply|obj|stl|glb|3mf) [options]

Extracts a triangle mesh of SCENE in Vulkan compute passes, by dual contouring (sharp edges
and corners of the solid stay sharp) or marching cubes, and writes it
(atomically) in the format that OUT's extension names: binary PLY with normals and colours,
OBJ with normals and colours ("v x y z r g b"), binary STL for printing, glTF 2.0 binary, or
3MF with colours for slicers (z up: the scene's y axis becomes the build direction).
The mesh is indexed, and closed and manifold wherever the surface lies inside the bounds;
where the bounds cut the surface it is open, and a note says so. Its triangles and vertices
are ordered for the GPU's vertex cache and fetch. Notes on the scene, as validate prints
them, go to standard error.

--simplify and --target-triangles merge triangles where the surface allows (meshoptimizer's
edge collapses): vertices stay where they were, with their normals and colours, the outline
of each colour and of an open mesh stays in place, and the mesh stays closed and manifold
with its topology. With --simplify no point of it lies farther than ERROR from the surface
(sampled over every triangle by the CPU evaluator), or where the unsimplified mesh already
did, no farther than that. With both, the simplification stops at whichever limit it
reaches first.

Options:
  -o, --output FILE      output mesh (required): .ply, .obj, .stl, .glb or .3mf; - for
                         standard output. A symbolic link is followed; a FIFO or a device
                         is written into; any other file that is not a regular one is refused
  --format F             ply, obj, stl, glb or 3mf, instead of OUT's extension
  --unit U               3MF only: what one scene unit is, mm, cm (default), m or inch
  --method M             dc (dual contouring, the default) or mc (marching cubes)
  --color-regions on|off cut the mesh where the scene's colour jumps (a hard union or
                         difference of differently coloured parts) and give each triangle
                         one colour: on (default) for .glb and .3mf, which write a colour
                         per triangle; off (default for the others) keeps vertex colours,
                         which blend across a border
  --resolution N         cells along the longest axis of the bounds (default 128)
  --voxel-size H         cell edge length in scene units, instead of --resolution
  --bounds X0,Y0,Z0,X1,Y1,Z1
                         region to mesh (default: the scene's finite bounds plus a margin
                         of a few cells)
  --simplify ERROR       simplify, moving the surface at most ERROR (scene units, > 0)
  --target-triangles N   simplify to at most N triangles (where the topology and the held
                         outlines allow)
  --stats                print the grid, brick and mesh sizes, the time per stage and the
                         peak memory (and the triangles before and after simplifying)
  --report               check the written mesh and print the report: closed, manifold,
                         oriented, self-intersections, shells, genus, volume, area, bounds
                         (on standard error where the mesh goes to standard output)
  --report-json FILE     write the same report as JSON to FILE
  --min-wall W           with --report or --report-json, also measure the walls from the
                         field and report the area thinner than W (scene units; default
                         0.8 mm in the unit of --unit, so 0.08 with one unit a centimetre),
                         and the overhangs past 45 degrees with the scene's +y up
  --evaluation E         auto (default), inlined or tapes, as for render
  --device NAME          Vulkan device: index or part of its name (also SDFCSG_DEVICE)
  --validation           enable the Vulkan validation layer
)";

bool parseBounds(const std::string& s, sdfcsg::Aabb& out) {
    std::vector<float> values;
    size_t start = 0;
    for (size_t i = 0; i <= s.size(); ++i)
        if (i == s.size() || s[i] == ',') {
            float v = 0;
            if (!parseFloat(s.substr(start, i - start), v)) return false;
            values.push_back(v);
            start = i + 1;
        }
    if (values.size() != 6) return false;
    out.min = {values[0], values[1], values[2]};
    out.max = {values[3], values[4], values[5]};
    return out.min.x < out.max.x && out.min.y < out.max.y && out.min.z < out.max.z;
}

std::string mebibytes(double bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f MiB", bytes / (1024.0 * 1024.0));
    return text;
}

void printMeshStats(const sdfcsg::MeshStats& stats, double compileSeconds, double writeSeconds) {
    const auto& b = stats.bounds;
    std::printf("grid:      %u x %u x %u cells of %g, over [%g, %g, %g] .. [%g, %g, %g]\n",
                stats.cells.x, stats.cells.y, stats.cells.z, stats.voxelSize, b.min.x, b.min.y,
                b.min.z, b.max.x, b.max.y, b.max.z);
    std::printf("bricks:    %llu active of %llu (%.1f%%)\n",
                static_cast<unsigned long long>(stats.activeBricks),
                static_cast<unsigned long long>(stats.bricks),
                stats.bricks ? 100.0 * double(stats.activeBricks) / double(stats.bricks) : 0.0);
    std::printf("mesh:      %llu vertices, %llu triangles\n",
                static_cast<unsigned long long>(stats.vertices),
                static_cast<unsigned long long>(stats.triangles));
    if (stats.unsimplifiedTriangles) {
        std::printf("simplify:  %llu -> %llu triangles in %u tries",
                    static_cast<unsigned long long>(stats.unsimplifiedTriangles),
                    static_cast<unsigned long long>(stats.triangles), stats.simplifyAttempts);
        if (!std::isnan(stats.simplifiedError))
            std::printf(", at most %g from the surface (sampled)", stats.simplifiedError);
        std::printf("\n");
    }
    std::printf("surface:   %s\n", stats.surfaceCut ? "cut by the bounds (the mesh is open there)"
                                                    : "inside the bounds (the mesh is closed)");
    std::printf("time:      %-13s %8.3f s\n", "compile", compileSeconds);
    for (const auto& stage : stats.stages)
        std::printf("           %-13s %8.3f s\n", stage.name.c_str(), stage.seconds);
    std::printf("           %-13s %8.3f s (compiled scene to mesh in memory)\n", "extraction",
                stats.totalSeconds);
    std::printf("           %-13s %8.3f s\n", "write", writeSeconds);
    // ru_maxrss is in KiB on Linux.
    rusage usage{};
    ::getrusage(RUSAGE_SELF, &usage);
    std::printf("memory:    %s peak working set (buffers and mesh), %s peak process RSS\n",
                mebibytes(double(stats.peakBytes)).c_str(),
                mebibytes(double(usage.ru_maxrss) * 1024.0).c_str());
}

int cmdMesh(int argc, char** argv) {
    using Clock = std::chrono::steady_clock;
    auto secondsSince = [](Clock::time_point t0) {
        return std::chrono::duration<double>(Clock::now() - t0).count();
    };
    Args args("mesh", argc, argv,
              {"-o", "--output", "--resolution", "--voxel-size", "--bounds", "--device",
               "--evaluation", "--unit", "--method", "--simplify", "--target-triangles", "--format",
               "--report-json", "--min-wall", "--color-regions"},
              {"--stats", "--report", "--validation", "--help", "-h"});
    if (args.has("--help") || args.has("-h")) return std::fputs(kMeshHelp, stdout), kOk;
    if (!args.error.empty()) return usageError("mesh", args.error);
    if (args.positional.size() != 1) return usageError("mesh", "expected one SCENE file");
    std::string out = args.get("-o", args.get("--output"));
    if (out.empty()) return usageError("mesh", "missing -o OUT.(ply|obj|stl|glb|3mf)");
    auto format = sdfcsg::meshFormatFromPath(out);
    if (args.has("--format")) {
        format = sdfcsg::meshFormatFromPath("mesh." + args.get("--format"));
        if (!format) return usageError("mesh", "--format expects ply, obj, stl, glb or 3mf");
    }
    if (!format)
        return usageError("mesh", "the output must end in .ply, .obj, .stl, .glb or .3mf (or give "
                                  "--format), got '" +
                                      out + "'");
    sdfcsg::LengthUnit unit = sdfcsg::kDefaultLengthUnit;
    if (args.has("--unit")) {
        auto named = sdfcsg::lengthUnitFromName(args.get("--unit"));
        if (!named) return usageError("mesh", "--unit expects mm, cm, m or inch");
        if (*format != sdfcsg::MeshFormat::ThreeMf)
            return usageError("mesh", "--unit applies to .3mf output only");
        unit = *named;
    }

    sdfcsg::MeshOptions options;
    options.colorRegions = sdfcsg::formatHasTriangleColors(*format);
    if (args.has("--color-regions")) {
        const std::string regions = args.get("--color-regions");
        if (regions != "on" && regions != "off")
            return usageError("mesh", "--color-regions expects on or off, got '" + regions + "'");
        options.colorRegions = regions == "on";
    }
    if (args.has("--method")) {
        const std::string method = args.get("--method");
        if (method != "dc" && method != "mc")
            return usageError("mesh", "--method expects dc or mc, got '" + method + "'");
        options.method =
            method == "mc" ? sdfcsg::MeshMethod::MarchingCubes : sdfcsg::MeshMethod::DualContouring;
    }
    if (args.has("--resolution") && args.has("--voxel-size"))
        return usageError("mesh", "give --resolution or --voxel-size, not both");
    if (args.has("--resolution") &&
        !parseUint(args.get("--resolution"), 1, 1u << 24, options.resolution))
        return usageError("mesh", "--resolution expects an integer in 1..16777216");
    if (args.has("--voxel-size")) {
        float h = 0;
        if (!parseFloat(args.get("--voxel-size"), h) || h <= 0.0f)
            return usageError("mesh", "--voxel-size expects a positive number");
        options.voxelSize = h;
    }
    if (args.has("--bounds")) {
        sdfcsg::Aabb bounds;
        if (!parseBounds(args.get("--bounds"), bounds))
            return usageError("mesh", "--bounds expects X0,Y0,Z0,X1,Y1,Z1 with X0 < X1, Y0 < Y1 "
                                      "and Z0 < Z1");
        options.bounds = bounds;
    }

    sdfcsg::SimplifyOptions simplify;
    if (args.has("--simplify")) {
        const std::string value = args.get("--simplify");
        float error = 0;
        if (!parseFloat(value, error) || error <= 0.0f)
            return usageError("mesh",
                              "--simplify expects a distance greater than 0, got '" + value + "'");
        simplify.maxError = error;
    }
    if (args.has("--target-triangles")) {
        const std::string value = args.get("--target-triangles");
        char* end = nullptr;
        errno = 0;
        const unsigned long long n = std::strtoull(value.c_str(), &end, 10);
        if (value.empty() || !std::isdigit(static_cast<unsigned char>(value[0])) || *end || errno ||
            n == 0)
            return usageError("mesh",
                              "--target-triangles expects a positive integer, got '" + value + "'");
        simplify.targetTriangles = size_t(n);
    }
    if (auto writable = sdfcsg::checkOutput(out); !writable) return fail(writable.error());
    const std::string reportFile = args.get("--report-json");
    float minWall = sdfcsg::defaultMinWall(unit);
    if (args.has("--min-wall")) {
        const std::string value = args.get("--min-wall");
        if (!parseFloat(value, minWall) || !(minWall > 0.0f) || !std::isfinite(minWall))
            return usageError("mesh",
                              "--min-wall expects a length greater than 0, got '" + value + "'");
    }
    if (args.has("--report-json"))
        if (auto writable = sdfcsg::checkOutput(reportFile); !writable)
            return fail(writable.error());

    sdfcsg::Evaluation evaluation = sdfcsg::Evaluation::Auto;
    if (!parseEvaluation(args, "mesh", evaluation)) return kUsage;
    catchInterrupts(); // from here on, an interruption is reported (the watchdog's grace)
    auto scene = load(args.positional[0]);
    if (!scene) return fail(scene.error());
    printNotes(args.positional[0], *scene, stderr);
    if (auto fits = sdfcsg::checkEvaluation(*scene, evaluation); !fits) return fail(fits.error());
    sdfcsg::ContextOptions contextOptions;
    contextOptions.device = args.get("--device");
    if (args.has("--validation")) contextOptions.validation = 1;
    auto context = sdfcsg::Context::create(contextOptions);
    if (!context) return fail(context.error());
    auto t0 = Clock::now();
    auto mesher = sdfcsg::Mesher::create(**context, *scene, evaluation);
    if (!mesher) return fail(mesher.error());
    const double compileSeconds = secondsSince(t0);

    sdfcsg::MeshStats stats;
    auto mesh = [&] {
        ProgressBar bar("meshing"); // erased again when the extraction ends
        const bool tty = ::isatty(STDERR_FILENO);
        options.progress = [&](float done) { return (!tty || bar.update(done)) && !interrupted(); };
        return (*mesher)->extract(options, &stats);
    }();
    if (!mesh) return fail(mesh.error());
    if (simplify.maxError || simplify.targetTriangles) {
        ProgressBar bar("simplifying");
        const bool tty = ::isatty(STDERR_FILENO);
        simplify.progress = [&](float done) {
            return (!tty || bar.update(done)) && !interrupted();
        };
        mesh = sdfcsg::simplifyMesh(*mesh, (*mesher)->evaluator(), simplify, &stats);
        if (!mesh) return fail(mesh.error());
    } else {
        t0 = Clock::now();
        sdfcsg::optimizeMeshOrder(*mesh, true); // a tenth of the extraction's time
        const double seconds = secondsSince(t0);
        stats.stages.push_back({"order", seconds});
        stats.totalSeconds += seconds;
    }
    t0 = Clock::now();
    auto bytes = sdfcsg::encodeMeshFile(*mesh, out, *format, unit);
    if (!bytes) return fail(bytes.error());
    if (auto written = writeOutput(out, *bytes); !written) return fail(written.error());
    const double writeSeconds = secondsSince(t0);

    if (args.has("--stats")) printMeshStats(stats, compileSeconds, writeSeconds);
    if (args.has("--report") || args.has("--report-json")) {
        const sdfcsg::MeshReport report =
            sdfcsg::reportMesh(*mesh, (*mesher)->evaluator(), minWall);
        if (args.has("--report"))
            std::fputs(sdfcsg::reportText(report).c_str(), out == "-" ? stderr : stdout);
        if (args.has("--report-json"))
            if (auto written = writeOutput(reportFile, sdfcsg::reportJson(report)); !written)
                return fail(written.error());
    }
    if (mesh->triangleCount() == 0) {
        options.progress = [](float) { return !interrupted(); };
        const auto why = (*mesher)->whyEmpty(options);
        if (interrupted())
            return fail(sdfcsg::Error::message(sdfcsg::ErrorKind::Cancelled, {}, {}));
        std::fprintf(stderr, "warning: %s holds an empty mesh: %s\n", out.c_str(),
                     why ? why->c_str() : "no surface lies inside the bounds");
    } else if (stats.surfaceCut && !args.has("--stats"))
        std::fprintf(stderr, "note: the bounds cut the surface, so the mesh is open there\n");
    return kOk;
}

const char* kValidateHelp = R"(Usage: sdfcsg validate SCENE...

Parses and validates each scene (current or legacy format) and prints every problem found,
one per line as FILE: JSON.PATH: MESSAGE (or FILE:LINE:COLUMN: MESSAGE for syntax errors).
For a valid scene, notes where an offset, a shell or a smooth blend acts on a field that is
not a distance (under a twist, bend or taper, a scale that differs between axes, an
ellipsoid, or within another smooth blend), and by how much it lands off; and mesh nodes
whose files are not closed and consistently oriented (open edges, flipped triangles...),
whose inside comes from the winding number; as FILE: JSON.PATH: note: MESSAGE.
Exits with 0 if all scenes are valid, 1 if any is not, 3 if a file cannot be read.
)";

int cmdValidate(int argc, char** argv) {
    Args args("validate", argc, argv, {}, {"--help", "-h"});
    if (args.has("--help") || args.has("-h")) return std::fputs(kValidateHelp, stdout), kOk;
    if (!args.error.empty()) return usageError("validate", args.error);
    if (args.positional.empty()) return usageError("validate", "expected at least one SCENE file");
    int worst = kOk;
    for (const std::string& path : args.positional) {
        auto scene = load(path);
        if (!scene) {
            int code = fail(scene.error());
            worst = std::max(worst, int(code == kIo ? kIo : kInvalidScene));
            continue;
        }
        std::printf("%s: ok (%zu node%s)\n", path.c_str(), scene->nodes.size(),
                    scene->nodes.size() == 1 ? "" : "s");
        printNotes(path, *scene, stdout);
    }
    return worst;
}

// Writes text to -o FILE atomically, or to standard output.
int emit(const std::string& text, const std::string& out) {
    if (out.empty()) {
        std::fwrite(text.data(), 1, text.size(), stdout);
        return kOk;
    }
    if (auto written = sdfcsg::writeFileAtomic(out, text); !written) return fail(written.error());
    return kOk;
}

const char* kGlslHelp = R"(Usage: sdfcsg glsl SCENE [-o FILE] [--inline] [--no-bounds-tests]

Prints the GLSL that SCENE compiles to: sceneDistance() and sceneSample(), one line per node.
  -o, --output FILE  write to FILE (atomically) instead of standard output
  --inline           bake parameters in as literals instead of reading the node buffer
  --no-bounds-tests  leave out the tests that skip operands by their bounds, as the renderer
                     does where it does not skip (by default on CPU devices such as lavapipe)
)";

int cmdGlsl(int argc, char** argv) {
    Args args("glsl", argc, argv, {"-o", "--output"},
              {"--inline", "--no-bounds-tests", "--help", "-h"});
    if (args.has("--help") || args.has("-h")) return std::fputs(kGlslHelp, stdout), kOk;
    if (!args.error.empty()) return usageError("glsl", args.error);
    if (args.positional.size() != 1) return usageError("glsl", "expected one SCENE file");
    auto scene = load(args.positional[0]);
    if (!scene) return fail(scene.error());
    sdfcsg::CodegenOptions options;
    options.inlineParams = args.has("--inline");
    options.boundsTests = !args.has("--no-bounds-tests");
    return emit(sdfcsg::generateSceneGlsl(*scene, options), args.get("-o", args.get("--output")));
}

const char* kConvertHelp = R"(Usage: sdfcsg convert IN -o OUT.json|OUT.py

Reads a scene in any supported format (the legacy SDFBooleanEngine node list is detected
automatically), validates it and writes it in the current format (atomically). To a .py file,
it writes a Python program that builds the scene with the sdfcsg module (docs/python.md) and
saves its JSON, by default beside it (OUT.json).
)";

int cmdConvert(int argc, char** argv) {
    Args args("convert", argc, argv, {"-o", "--output"}, {"--help", "-h"});
    if (args.has("--help") || args.has("-h")) return std::fputs(kConvertHelp, stdout), kOk;
    if (!args.error.empty()) return usageError("convert", args.error);
    if (args.positional.size() != 1) return usageError("convert", "expected one input file");
    std::string out = args.get("-o", args.get("--output"));
    if (out.empty()) return usageError("convert", "missing -o OUT.json");
    auto scene = load(args.positional[0]);
    if (!scene) return fail(scene.error());
    const std::filesystem::path path(out);
    if (path.extension() == ".py")
        return emit(
            sdfcsg::model::toPython(*scene, path.filename().replace_extension(".json").string()),
            out);
    return emit(sdfcsg::toJson(*scene), out);
}

const char* kSchemaHelp = R"(Usage: sdfcsg schema [-o FILE] [--markdown]

Prints the JSON Schema (draft 2020-12) of the scene format, generated from the node table.
  --markdown  print the field reference in Markdown instead (as in docs/scene-format.md)
)";

int cmdSchema(int argc, char** argv) {
    Args args("schema", argc, argv, {"-o", "--output"}, {"--markdown", "--help", "-h"});
    if (args.has("--help") || args.has("-h")) return std::fputs(kSchemaHelp, stdout), kOk;
    if (!args.error.empty()) return usageError("schema", args.error);
    if (!args.positional.empty()) return usageError("schema", "takes no arguments");
    std::string text =
        args.has("--markdown") ? sdfcsg::sceneFormatReference() : sdfcsg::sceneJsonSchema();
    return emit(text, args.get("-o", args.get("--output")));
}

} // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fputs(kMainHelp, stderr);
        return kUsage;
    }
    std::string_view command = argv[1];
    if (command == "--help" || command == "-h" || command == "help") {
        std::fputs(kMainHelp, stdout);
        return kOk;
    }
    if (command == "--version") {
        std::printf("sdfcsg %d.%d.%d\n", SDFCSG_VERSION_MAJOR, SDFCSG_VERSION_MINOR,
                    SDFCSG_VERSION_PATCH);
        return kOk;
    }
    const std::pair<std::string_view, std::function<int(int, char**)>> commands[] = {
        {"render", cmdRender},
        {"mesh", cmdMesh},
        {"validate", cmdValidate},
        {"glsl", cmdGlsl},
        {"convert", cmdConvert},
        {"schema", cmdSchema},
        {"bench", sdfcsg::app::runBench},
        {"generate", sdfcsg::app::runGenerate},
        {"edit", sdfcsg::app::runEdit},
        {"eval-prompts", sdfcsg::app::runEvalPrompts},
    };
    for (auto& [name, run] : commands)
        if (command == name) return run(argc - 2, argv + 2);
    std::fprintf(stderr, "sdfcsg: unknown command '%s'\n\n%s", argv[1], kMainHelp);
    return kUsage;
}
