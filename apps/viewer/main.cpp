// sdfcsg-viewer: an interactive window over the engine. The engine renders on a background
// thread (RenderWorker) into host images; this file reads the arguments and runs the main loop,
// which polls input, draws the panels and hands the images to the Presenter (viewer.h lists the
// files that do each). Everything that can be tested without a window lives in the other files
// of this folder.
#include "edit.h"
#include "viewer.h"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_vulkan.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using namespace sdfcsg;
using namespace sdfcsg::viewer;

namespace {

constexpr const char* kUsage =
    "usage: sdfcsg-viewer [SCENE] [--size WxH] [--screenshot OUT.png --frames N]\n"
    "                     [--script FILE] [--no-ui]\n"
    "  --size WxH         window size in pixels (default 1280x720)\n"
    "  --screenshot OUT   after N frames and the full-resolution image, write the window to\n"
    "                     OUT (PNG) and exit\n"
    "  --frames N         frames to draw before the screenshot (default 1)\n"
    "  --script FILE      run viewer commands from FILE (see apps/viewer/script.h), then exit\n"
    "  --no-ui            hide the panels (H toggles them)\n"
    "The Generate panel and the script's generate command reach a language model set up as for\n"
    "'sdfcsg generate': SDFCSG_LLM_BASE_URL, SDFCSG_LLM_MODEL, SDFCSG_LLM_API_KEY, ...\n";

struct Args {
    fs::path scene;
    fs::path screenshot;
    int frames = 1;
    int width = 1280, height = 720;
    fs::path script;
    bool noUi = false;
};

bool parseArgs(int argc, char** argv, Args& args, std::string& error) {
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        auto value = [&](std::string& out) {
            if (i + 1 >= argc) {
                error = a + ": expected a value";
                return false;
            }
            out = argv[++i];
            return true;
        };
        std::string v;
        if (a == "--help" || a == "-h") {
            std::fputs(kUsage, stdout);
            std::exit(0);
        } else if (a == "--size") {
            if (!value(v)) return false;
            if (std::sscanf(v.c_str(), "%dx%d", &args.width, &args.height) != 2 ||
                args.width < 16 || args.height < 16 || args.width > 8192 || args.height > 8192) {
                error = "--size: expected WxH between 16x16 and 8192x8192, got \"" + v + "\"";
                return false;
            }
        } else if (a == "--screenshot") {
            if (!value(v)) return false;
            args.screenshot = v;
        } else if (a == "--frames") {
            if (!value(v)) return false;
            args.frames = std::atoi(v.c_str());
            if (args.frames < 1) {
                error = "--frames: expected a positive number, got \"" + v + "\"";
                return false;
            }
        } else if (a == "--script") {
            if (!value(v)) return false;
            args.script = v;
        } else if (a == "--no-ui") {
            args.noUi = true;
        } else if (!a.empty() && a[0] == '-') {
            error = "unknown option " + a;
            return false;
        } else if (args.scene.empty()) {
            args.scene = a;
        } else {
            error = "more than one scene given";
            return false;
        }
    }
    return true;
}

// --script: the commands, parsed and checked before anything starts. 0, or the exit code.
int loadScript(const Args& args, Viewer& v) {
    if (args.script.empty()) return 0;
    std::ifstream in(args.script, std::ios::binary);
    if (!in) {
        std::fprintf(stderr, "%s: cannot read the file\n", args.script.string().c_str());
        return 3;
    }
    std::stringstream text;
    text << in.rdbuf();
    auto parsed = parseScript(text.str(), args.script.string());
    if (!parsed) {
        std::fprintf(stderr, "%s\n", parsed.error().str().c_str());
        return 2;
    }
    v.script.assign(parsed->begin(), parsed->end());
    v.scriptFile = args.script.string();
    return 0;
}

// The engine's contexts and the background workers. 0, or the exit code.
int startWorkers(Viewer& v) {
    auto context = Context::create();
    if (!context) {
        std::fprintf(stderr, "%s\n", context.error().str().c_str());
        return 4;
    }
    v.context = std::move(*context);
    // Without a second device the live renderer shares the first, and its compile then
    // delays frames once.
    if (auto live = Context::create()) v.liveContext = std::move(*live);
    v.renderer = std::make_unique<RenderWorker>(*v.context, v.liveContext.get());
    v.mesher = std::make_unique<MeshWorker>(*v.context);
    v.exporter = std::make_unique<ExportWorker>();
    v.generator = std::make_unique<GenerateWorker>();
    describeEndpoint(v);
    return 0;
}

// The window, ImGui and the presenter that draws into the window. 0, or the exit code.
int openWindow(Viewer& v, const Args& args) {
    glfwSetErrorCallback([](int code, const char* text) {
        std::fprintf(stderr, "GLFW error %d: %s\n", code, text);
    });
    if (!glfwInit()) {
        std::fprintf(stderr, "sdfcsg-viewer: cannot open a window (no display?)\n");
        return 4;
    }
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    std::string title = "sdfcsg-viewer" + (args.scene.empty() ? "" : " - " + args.scene.string());
    v.window = glfwCreateWindow(args.width, args.height, title.c_str(), nullptr, nullptr);
    if (!v.window || !glfwVulkanSupported()) {
        std::fprintf(stderr, "sdfcsg-viewer: cannot create a Vulkan window\n");
        return 4;
    }
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr; // the same layout every run, no file beside the scene
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForVulkan(v.window, true);
    std::string error;
    v.presenter = createPresenter(v.window, v.context->validationEnabled(), error);
    if (!v.presenter) {
        std::fprintf(stderr, "sdfcsg-viewer: %s\n", error.c_str());
        return 4;
    }
    return 0;
}

// Live reload: the scene's file changed on disk.
void pollReload(Viewer& v) {
    const std::shared_ptr<const Scene> before = v.scene;
    if (!v.doc.pollReload()) return;
    v.status = v.doc.error() ? "reload failed" : "reloaded " + v.doc.path().string();
    // Node numbers change with the file: the selection follows its node.
    if (!v.doc.error() && before && v.selected >= 0) {
        auto same = sameNode(*before, uint32_t(v.selected), v.doc.scene());
        v.selected = same ? int(*same) : -1;
    }
    ++v.reloads;
}

// Input and the panels, then the image they ask for.
void updateUi(Viewer& v) {
    ImGui_ImplVulkan_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    handleInput(v);
    syncScene(v);
    if (v.showUi) panels(v);
    ImGui::Render();
    syncScene(v);
    updateImage(v);
}

MeshView meshViewOf(const Viewer& v) {
    MeshView meshView;
    meshView.camera = toCamera(v.camera);
    meshView.wireframe = v.wireframe;
    meshView.closed = !v.meshStats.surfaceCut;
    // As updateImage() chose: screenshots wait for a settled view, which draws the full mesh.
    meshView.preview = v.shown.meshPreview;
    if (v.grid && v.evaluator) meshView.grid = groundGrid(*v.evaluator);
    return meshView;
}

// Writes the pending screenshot; false when that fails (v.exitCode says so).
bool writeShot(Viewer& v, Image& capture, bool drawsMesh) {
    if (capture.rgba.empty()) {
        // This surface cannot be read back: the scene image alone is the next best.
        capture = v.last.image;
    }
    auto written = writePng(capture, v.pendingShot);
    if (!written) {
        std::fprintf(stderr, "%s\n", written.error().str().c_str());
        v.exitCode = 3;
        return false;
    }
    const std::string shot = v.pendingShot.string();
    if (!v.scene) {
        std::fprintf(stderr, "note: %s shows no scene: none is open\n", shot.c_str());
    } else if (!drawsMesh && v.evaluator) {
        const Camera camera = v.last.options.camera.value_or(toCamera(v.camera));
        if (auto why = whyNothingShows(*v.evaluator, camera, v.last.options.height, v.last.pixels))
            std::fprintf(stderr, "note: %s shows nothing: %s\n", shot.c_str(), why->c_str());
    }
    // With the mesh's device time, so scripts can time the mesh view.
    if (drawsMesh && v.meshDrawMs >= 0.0)
        std::printf("wrote %s (%u x %u), mesh drawn in %.1f ms\n", v.pendingShot.string().c_str(),
                    capture.width, capture.height, v.meshDrawMs);
    else
        std::printf("wrote %s (%u x %u)\n", v.pendingShot.string().c_str(), capture.width,
                    capture.height);
    v.pendingShot.clear();
    return true;
}

// Draws the window, and writes the pending screenshot once the view has settled. False when the
// run ends here: the screenshot failed, or it was the one that ends the run.
bool drawWindow(Viewer& v) {
    Image capture;
    // One settled frame more, so the panels show the numbers of the image they sit on.
    v.settledFrames = settled(v) ? v.settledFrames + 1 : 0;
    bool shoot = !v.pendingShot.empty() && v.settledFrames >= 2 && v.framesLeft <= 1;
    float bg[3] = {0.1f, 0.1f, 0.1f};
    if (v.scene)
        bg[0] = v.scene->background.r, bg[1] = v.scene->background.g, bg[2] = v.scene->background.b;
    MeshView meshView = meshViewOf(v);
    const bool drawsMesh = v.meshView && v.mesh;
    const double frameStart = now();
    bool drawn = drawFrame(*v.presenter, ImGui::GetDrawData(), bg, drawsMesh ? &meshView : nullptr,
                           shoot ? &capture : nullptr);
    if (drawn && drawsMesh) {
        v.meshFrameMs = (now() - frameStart) * 1000.0;
        v.meshDrawMs = meshDrawMilliseconds(*v.presenter);
    }
    if (drawn && v.framesLeft > 0) --v.framesLeft;
    if (!shoot || !drawn) return true;
    return writeShot(v, capture, drawsMesh) && !v.exitAfterShot;
}

// Until the window closes, the script has run, or a screenshot ends the run.
void runLoop(Viewer& v, const Args& args) {
    bool automated = !args.screenshot.empty() || !args.script.empty();
    double lastPoll = 0;
    while (!glfwWindowShouldClose(v.window)) {
        // Automated runs never sleep; interactive ones wait for input while nothing is pending.
        if (automated || !v.renderer->idle() || v.mesher->running() || v.exporter->running() ||
            moving(v))
            glfwPollEvents();
        else
            glfwWaitEventsTimeout(0.1);
        if (now() - lastPoll > 0.25) {
            lastPoll = now();
            pollReload(v);
        }
        syncScene(v);
        if (!finishGeneration(v) || !finishMesh(v) || !runScript(v)) break;
        updateUi(v);
        if (!drawWindow(v)) break;
        if (!v.pendingShot.empty() && automated && now() - v.waitStart > 300.0) {
            std::fprintf(stderr, "sdfcsg-viewer: no image after 300 s\n");
            v.exitCode = 1;
            break;
        }
        if (!args.script.empty() && v.script.empty() && v.pendingShot.empty() && !v.generating &&
            v.meshScript.empty() && v.exportScript.empty() && !v.exitAfterShot)
            break;
    }
}

// An automated run fails on a render error or, under the tests' validation layer, on any
// message: the window's device, the renderer's and the live renderer's own.
void checkAutomatedRun(Viewer& v) {
    if (v.renderError && v.exitCode == 0) {
        std::fprintf(stderr, "%s\n", v.renderError->str().c_str());
        v.exitCode = 1;
    }
    if (v.exitCode == 0 &&
        (presenterValidationMessages(*v.presenter) || v.context->validationMessageCount() ||
         (v.liveContext && v.liveContext->validationMessageCount()))) {
        std::fprintf(stderr, "sdfcsg-viewer: the validation layer reported problems\n");
        v.exitCode = 1;
    }
}

int shutDown(Viewer& v) {
    glfwHideWindow(v.window);
    v.exporter.reset();  // waits for a file being written
    v.generator.reset(); // cancels a generation in flight
    v.mesher.reset();    // cancels an extraction
    if (v.renderer->compiling()) {
        // A compile cannot be interrupted and may take seconds more. Everything the user asked
        // for is written already (saves and screenshots are synchronous and atomic), so leave
        // without the destructors, which would wait for it.
        std::fflush(stdout);
        std::fflush(stderr);
        std::_Exit(v.exitCode);
    }
    v.renderer.reset();
    v.presenter.reset();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    glfwDestroyWindow(v.window);
    glfwTerminate();
    return v.exitCode;
}

} // namespace

int main(int argc, char** argv) {
    Args args;
    std::string error;
    if (!parseArgs(argc, argv, args, error)) {
        std::fprintf(stderr, "sdfcsg-viewer: %s\n%s", error.c_str(), kUsage);
        return 2;
    }
    Viewer v;
    if (int code = loadScript(args, v)) return code;
    v.showUi = !args.noUi;
    v.recentFile = recentFilesPath(std::getenv("XDG_CONFIG_HOME"), std::getenv("HOME"));
    v.recent = loadRecent(v.recentFile);
    if (int code = startWorkers(v)) return code;
    v.startedEmpty = args.scene.empty();
    if (!args.scene.empty()) {
        openFile(v, args.scene);
        if (!v.doc.loaded() && (!args.screenshot.empty() || !args.script.empty())) {
            std::fprintf(stderr, "%s\n", v.doc.error()->str().c_str());
            return 1;
        }
    }
    if (int code = openWindow(v, args)) return code;
    v.framesLeft = args.frames;
    if (!args.screenshot.empty()) {
        v.pendingShot = args.screenshot;
        v.exitAfterShot = true;
        v.waitStart = now();
    }
    runLoop(v, args);
    if (!args.screenshot.empty() || !args.script.empty()) checkAutomatedRun(v);
    return shutDown(v);
}
