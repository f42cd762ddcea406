// sdfcsg-viewer: an interactive window over the engine. The engine renders on a background
// thread (RenderWorker) into host images; this file handles input, the ImGui panels, and hands
// the images to the Presenter. Everything that can be tested without a window lives in the
// other files of this folder.
#include "document.h"
#include "edit.h"
#include "orbit_camera.h"
#include "picking.h"
#include "presenter.h"
#include "script.h"
#include "workers.h"

#include <sdfcsg/export.h>
#include <sdfcsg/generate.h>
#include <sdfcsg/io.h>

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_vulkan.h>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

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

double now() {
    using namespace std::chrono;
    return duration<double>(steady_clock::now().time_since_epoch()).count();
}

// Everything a rendered image depends on; an image is current when its key equals the wanted one.
struct ViewKey {
    uint64_t sceneVersion = 0;
    Camera camera;
    RenderMode mode = RenderMode::Shaded;
    bool shadows = true, ao = true, grid = false;
    BoxOverlay boxes = BoxOverlay::None;
    int selected = -1;
    uint32_t width = 0, height = 0;
    bool mesh = false, wireframe = false;
    bool meshPreview = false; // the mesh's coarse preview, while the camera moves
    bool operator==(const ViewKey& o) const {
        return sceneVersion == o.sceneVersion && camera.eye == o.camera.eye &&
               camera.target == o.camera.target && camera.fov == o.camera.fov && mode == o.mode &&
               shadows == o.shadows && ao == o.ao && grid == o.grid && boxes == o.boxes &&
               selected == o.selected && width == o.width && height == o.height && mesh == o.mesh &&
               wireframe == o.wireframe && meshPreview == o.meshPreview;
    }
};

struct Viewer {
    GLFWwindow* window = nullptr;
    PresenterPtr presenter;
    std::unique_ptr<Context> context;
    std::unique_ptr<Context> liveContext; // the live renderer's own device (RenderWorker)
    std::unique_ptr<RenderWorker> renderer;
    std::unique_ptr<MeshWorker> mesher;
    std::unique_ptr<ExportWorker> exporter;
    Document doc;
    std::shared_ptr<const Scene> scene; // doc.scene() as handed to the workers
    uint64_t sceneVersion = ~0ull;
    std::unique_ptr<Evaluator> evaluator; // of `scene`, for picking and framing

    OrbitCamera camera;
    RenderMode mode = RenderMode::Shaded;
    bool shadows = true, ao = true, grid = false, showUi = true;
    BoxOverlay boxes = BoxOverlay::Selected;
    int selected = -1;

    // Images.
    uint64_t nextJob = 1;
    ViewKey submitted, shown; // what the worker was last asked for / what is on screen
    bool haveSubmitted = false, haveShown = false;
    std::vector<std::pair<uint64_t, ViewKey>> jobs; // id -> key of jobs in flight
    RenderOutput last;                              // the image on screen, with its depths
    double lastInteraction = -1.0;
    float scale = 0.5f;    // preview resolution while the camera moves
    bool refining = false; // a job redraws the live image with its baked kernel
    double renderMs = 0.0, compileMs = 0.0;
    std::optional<Error> renderError;

    // Mouse.
    bool pressed[3] = {false, false, false};
    double pressX = 0, pressY = 0, lastX = 0, lastY = 0;
    bool dragged = false;

    // Mesh mode. The mesh is shared with the export thread; the presenter holds its own copy on
    // the device.
    std::shared_ptr<const Mesh> mesh;
    MeshStats meshStats;
    // The last mesh frame's time (a blit when the view did not change) and the device time of the
    // last drawing of the mesh.
    double meshFrameMs = 0.0, meshDrawMs = -1.0;
    std::string meshScript, exportScript; // "file:line: " while a script's extraction or write runs
    bool meshView = false, wireframe = false;
    int meshResolution = 128;
    bool customBounds = false;
    float boundsMin[3] = {-1, -1, -1}, boundsMax[3] = {1, 1, 1};
    std::string meshMessage;
    char exportPath[512] = "mesh.glb";
    fs::path exporting; // the file the export worker writes

    // Generation.
    std::unique_ptr<GenerateWorker> generator;
    LlmConfig llm;        // from the environment
    std::string endpoint; // "model at URL", or why there is none; never the key
    bool endpointOk = false;
    bool startedEmpty = false; // no scene given on the command line
    char prompt[4096] = "";
    bool generating = false; // started, and the result not yet applied
    bool generatingEdit = false;
    std::string generationScript; // "file:line: " when a script started it
    std::string generateSummary;
    std::vector<Diagnostic> generateWarnings;
    std::optional<Error> generateError;

    // Files.
    char openPath[512] = "";
    char savePath[512] = "";
    char shotPath[512] = "viewer.png";
    std::vector<std::string> recent;
    fs::path browseDir = fs::current_path();
    bool browserOpen = false;
    std::vector<fs::directory_entry> browseEntries; // the listing of browseListed
    fs::path browseListed;
    double browseTime = 0;
    std::string status;

    // Automation.
    std::deque<Command> script;
    std::string scriptFile;
    fs::path pendingShot; // waiting for the current full image, then written
    bool exitAfterShot = false;
    int framesLeft = 0;
    int settledFrames = 0; // frames in a row that showed the current full image
    int exitCode = 0;
    double waitStart = 0;
    double commandWaitStart = 0; // of a command waiting for an image or a reload
    int reloads = 0;             // not yet answered by the script's wait-reload
};

float aspectOf(const Viewer& v) {
    int w = 1, h = 1;
    glfwGetFramebufferSize(v.window, &w, &h);
    return h > 0 ? float(w) / float(h) : 1.0f;
}

void resetCamera(Viewer& v) {
    if (!v.evaluator) return;
    Camera c = v.scene->camera ? *v.scene->camera : frameCamera(*v.evaluator, aspectOf(v));
    v.camera = orbitFromCamera(c);
}

void frameSelection(Viewer& v) {
    if (!v.evaluator) return;
    frameBox(v.camera, framedBounds(*v.evaluator, v.selected), aspectOf(v));
    v.lastInteraction = now();
}

void addRecent(Viewer& v, const fs::path& path) {
    std::string p = path.string();
    v.recent.erase(std::remove(v.recent.begin(), v.recent.end(), p), v.recent.end());
    v.recent.insert(v.recent.begin(), p);
    if (v.recent.size() > 10) v.recent.resize(10);
    saveRecent(recentFilesPath(), v.recent);
}

// Hands the document's scene to the workers when it changed.
void syncScene(Viewer& v) {
    if (!v.doc.loaded() || v.sceneVersion == v.doc.version()) return;
    bool first = !v.scene;
    v.scene = std::make_shared<const Scene>(v.doc.scene());
    v.sceneVersion = v.doc.version();
    v.evaluator = std::make_unique<Evaluator>(*v.scene);
    if (v.selected >= int(v.scene->nodes.size())) v.selected = -1;
    if (first) resetCamera(v);
}

void openFile(Viewer& v, const fs::path& path) {
    auto opened = v.doc.open(path);
    if (opened) {
        // Only a file that loaded becomes where Save writes: the scene on screen is its scene.
        std::snprintf(v.savePath, sizeof v.savePath, "%s", path.string().c_str());
        addRecent(v, path);
        v.selected = -1;
        v.scene.reset(); // the camera is reset for a new file
        v.mesh.reset();
        v.status = "opened " + path.string();
    } else {
        v.status = "could not open " + path.string();
    }
}

// Applies an edit's outcome: a new undo step, or the error in the status line.
bool commit(Viewer& v, Result<Scene> edited, std::string mergeKey = {}) {
    if (!edited) {
        v.status = edited.error().str();
        return false;
    }
    v.doc.history().push(std::move(*edited), std::move(mergeKey));
    v.doc.touch();
    return true;
}

void undo(Viewer& v) {
    if (v.doc.history().undo()) v.doc.touch();
}
void redo(Viewer& v) {
    if (v.doc.history().redo()) v.doc.touch();
}

// ---- Generation ------------------------------------------------------------------------------

void describeEndpoint(Viewer& v) {
    v.llm = llmConfigFromEnvironment();
    auto endpoint = llmEndpoint(v.llm);
    v.endpointOk = bool(endpoint);
    v.endpoint = endpoint ? endpoint->model + " at " + endpoint->url +
                                (v.llm.apiKey.empty() ? " (no API key)" : "")
                          : endpoint.error().str();
}

// `edit`: the current scene goes with the request, to be changed (as `sdfcsg edit` does).
void startGeneration(Viewer& v, std::string request, bool edit) {
    GenerateOptions options;
    options.llm = v.llm;
    std::string current = edit && v.doc.loaded() ? toJson(v.doc.scene()) : std::string();
    if (!v.generator->start(std::move(request), std::move(current), std::move(options))) return;
    v.generating = true;
    v.generatingEdit = edit;
    v.generateSummary.clear();
    v.generateWarnings.clear();
    v.generateError.reset();
}

// Applies a finished generation: its scene as one undo step, or its problems in the panel while
// the current scene stays. False when a script's generation failed.
bool finishGeneration(Viewer& v) {
    if (!v.generating) return true;
    auto done = v.generator->take();
    if (!done) return true;
    v.generating = false;
    const std::string where = std::exchange(v.generationScript, {});
    if (!*done) {
        v.generateError = done->error();
        if (where.empty()) return true;
        std::fprintf(stderr, "%s%s\n", where.c_str(), done->error().str().c_str());
        v.exitCode = 1;
        return false;
    }
    Generated& g = **done;
    v.generateSummary = generationSummary(g, v.generator->stats());
    v.generateWarnings = std::move(g.warnings);
    if (!where.empty()) {
        std::fprintf(stderr, "%s%s\n", where.c_str(), v.generateSummary.c_str());
        for (const Diagnostic& w : v.generateWarnings)
            std::fprintf(stderr, "%swarning: %s: %s\n", where.c_str(), w.path.c_str(),
                         w.message.c_str());
    }
    v.doc.replace(std::move(g.scene));
    v.selected = -1; // the node numbers changed
    v.mesh.reset();
    v.meshView = false;
    if (!v.generatingEdit) v.scene.reset(); // a new scene gets its own camera (syncScene)
    v.status = v.generatingEdit ? "edited by the model (undo: Ctrl+Z)"
                                : "generated a new scene (undo: Ctrl+Z)";
    return true;
}

// Where Ctrl+S writes.
fs::path savePathOf(const Viewer& v) {
    return v.savePath[0] ? fs::path(v.savePath) : v.doc.path();
}

void save(Viewer& v, const fs::path& path) {
    auto saved = v.doc.save(path);
    v.status = saved ? "saved " + path.string() : saved.error().str();
    if (saved) addRecent(v, path);
}

// ---- Rendering -------------------------------------------------------------------------------

ViewKey wantedKey(Viewer& v, bool full) {
    ViewKey k;
    k.sceneVersion = v.sceneVersion;
    k.camera = toCamera(v.camera);
    k.mode = v.mode;
    k.shadows = v.shadows;
    k.ao = v.ao;
    k.grid = v.grid;
    k.boxes = v.boxes;
    k.selected = v.selected; // its box, and its highlight in full-resolution frames
    int w = 1, h = 1;
    glfwGetFramebufferSize(v.window, &w, &h);
    float s = full ? 1.0f : v.scale;
    k.width = std::max(1u, uint32_t(std::lround(float(w) * s)));
    k.height = std::max(1u, uint32_t(std::lround(float(h) * s)));
    k.mesh = v.meshView && v.mesh;
    k.wireframe = k.mesh && v.wireframe;
    // As the ray marcher lowers the resolution, the mesh view lowers the triangles: their number,
    // not the pixels, sets its frame time.
    k.meshPreview = k.mesh && !full && previewMeshTriangles(*v.presenter) > 0;
    return k;
}

bool moving(const Viewer& v) {
    return now() - v.lastInteraction < 0.3;
}

void updateImage(Viewer& v) {
    if (auto out = v.renderer->take()) {
        auto job =
            std::find_if(v.jobs.begin(), v.jobs.end(), [&](auto& j) { return j.first == out->id; });
        ViewKey key = job != v.jobs.end() ? job->second : ViewKey{};
        v.jobs.erase(v.jobs.begin(), job == v.jobs.end() ? job : job + 1);
        v.renderError = out->error;
        v.refining = false;
        if (out->compileSeconds > 0) v.compileMs = out->compileSeconds * 1000.0;
        if (!out->image.rgba.empty()) {
            v.renderMs = out->renderSeconds * 1000.0;
            bool full = key.width == wantedKey(v, true).width;
            if (!full) // aim previews at about 80 ms
                v.scale = previewScale(
                    out->renderSeconds, uint64_t(key.width) * key.height,
                    uint64_t(wantedKey(v, true).width) * wantedKey(v, true).height, 0.08);
            setImage(*v.presenter, out->image);
            v.last = std::move(*out);
            // A failed compile shows the last good scene: its image is not the wanted one.
            v.shown = key;
            if (v.last.scene && v.last.error) v.shown.sceneVersion = ~0ull;
            v.haveShown = true;
        }
    }
    if (!v.scene) return;
    ViewKey want = wantedKey(v, !moving(v));
    if (want.mesh) { // the presenter draws the mesh itself, every frame
        v.shown = want;
        v.haveShown = true;
        v.haveSubmitted = false;
        return;
    }
    // A value edit drawn by the live renderer is drawn again once its baked kernel is built:
    // the same image as `sdfcsg render` gives, and faster to redraw.
    const bool refine = v.haveShown && v.shown == want && v.last.live && !v.refining &&
                        v.renderer->refinementReady(v.sceneVersion);
    if (!refine) {
        if (v.haveSubmitted && v.submitted == want) return;
        if (v.haveShown && v.shown == want) return;
    }
    // While a render runs, wait: a newer job replaces the queued one anyway.
    if (!v.renderer->idle() && v.haveSubmitted) return;
    v.refining = refine;
    RenderJob job;
    job.scene = v.scene;
    job.sceneVersion = v.sceneVersion;
    job.id = v.nextJob++;
    job.preview = moving(v);
    job.options.width = want.width;
    job.options.height = want.height;
    job.options.camera = want.camera;
    job.options.mode = want.mode;
    job.options.shadows = want.shadows;
    job.options.ambientOcclusion = want.ao;
    job.options.grid = want.grid;
    job.options.boxes =
        want.selected < 0 && want.boxes == BoxOverlay::Selected ? BoxOverlay::None : want.boxes;
    job.options.selectedNode = want.selected;
    job.highlight = want.selected;
    v.jobs.emplace_back(job.id, want);
    v.renderer->submit(std::move(job));
    v.submitted = want;
    v.haveSubmitted = true;
}

// The full-resolution image of the current state is on screen, from its baked kernel (so a
// screenshot is the same whether or not the live renderer drew the edit first).
bool settled(Viewer& v) {
    return v.scene && v.haveShown && v.shown == wantedKey(v, true) && v.renderer->idle() &&
           !(v.last.live && v.renderer->refinementPending(v.sceneVersion));
}

// ---- Input -----------------------------------------------------------------------------------

void pick(Viewer& v, double x, double y) {
    int w = 1, h = 1;
    glfwGetFramebufferSize(v.window, &w, &h);
    int ww = 1, wh = 1;
    glfwGetWindowSize(v.window, &ww, &wh);
    if (v.meshView && v.mesh && v.evaluator) {
        // The mesh view has no depths from the engine, but it shares the ray marcher's camera:
        // the ray through the pixel meets the scene's surface where the mesh shows it.
        auto p = castRay(*v.evaluator, toCamera(v.camera), uint32_t(w), uint32_t(h),
                         float(x) * float(w) / float(ww), float(y) * float(h) / float(wh));
        v.selected = p ? nearestPrimitive(*v.evaluator, *p) : -1;
        return;
    }
    if (!v.last.scene || v.last.image.rgba.empty() || !v.evaluator) return;
    // Window coordinates -> image pixels (the image fills the window).
    float ix = float(x) * float(w) / float(ww) * float(v.last.image.width) / float(w);
    float iy = float(y) * float(h) / float(wh) * float(v.last.image.height) / float(h);
    auto p = pickPoint(*v.last.options.camera, v.last.image.width, v.last.image.height,
                       v.last.pixels, ix, iy);
    if (!p) {
        v.selected = -1;
        return;
    }
    Evaluator shown(*v.last.scene);
    v.selected = nearestPrimitive(shown, *p);
    if (v.selected >= int(v.scene->nodes.size())) v.selected = -1;
}

void handleInput(Viewer& v) {
    ImGuiIO& io = ImGui::GetIO();
    double x, y;
    glfwGetCursorPos(v.window, &x, &y);
    int ww = 1, wh = 1;
    glfwGetWindowSize(v.window, &ww, &wh);
    for (int b = 0; b < 3; ++b) {
        bool down = glfwGetMouseButton(v.window, b) == GLFW_PRESS;
        if (down && !v.pressed[b] && !io.WantCaptureMouse) {
            v.pressed[b] = true;
            v.pressX = v.lastX = x, v.pressY = v.lastY = y;
            v.dragged = false;
        } else if (!down && v.pressed[b]) {
            v.pressed[b] = false;
            if (b == 0 && !v.dragged) pick(v, x, y);
        }
    }
    double dx = x - v.lastX, dy = y - v.lastY;
    if (std::hypot(x - v.pressX, y - v.pressY) > 3.0) v.dragged = true;
    bool shift = glfwGetKey(v.window, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                 glfwGetKey(v.window, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
    if ((dx != 0 || dy != 0) && v.dragged) {
        if (v.pressed[0] && !shift) {
            orbit(v.camera, -float(dx) * 0.008f, float(dy) * 0.008f);
            v.lastInteraction = now();
        } else if (v.pressed[1] || v.pressed[2] || (v.pressed[0] && shift)) {
            pan(v.camera, float(dx) / float(wh), float(dy) / float(wh));
            v.lastInteraction = now();
        }
    }
    v.lastX = x, v.lastY = y;
    if (!io.WantCaptureMouse && io.MouseWheel != 0.0f) {
        zoom(v.camera, std::pow(0.9f, io.MouseWheel));
        v.lastInteraction = now();
    }
    if (io.WantCaptureKeyboard) return;
    bool ctrl = io.KeyCtrl;
    auto pressedKey = [&](int key) {
        return ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey(key)));
    };
    (void)pressedKey;
    auto held = [&](int key) { return glfwGetKey(v.window, key) == GLFW_PRESS; };
    float step = float(io.DeltaTime) * 1.5f;
    if (held(GLFW_KEY_LEFT) || held(GLFW_KEY_RIGHT) || held(GLFW_KEY_UP) || held(GLFW_KEY_DOWN)) {
        float h = (held(GLFW_KEY_LEFT) ? 1.0f : 0.0f) - (held(GLFW_KEY_RIGHT) ? 1.0f : 0.0f);
        float vv = (held(GLFW_KEY_UP) ? 1.0f : 0.0f) - (held(GLFW_KEY_DOWN) ? 1.0f : 0.0f);
        if (shift)
            pan(v.camera, -h * step * 0.3f, vv * step * 0.3f);
        else
            orbit(v.camera, h * step, -vv * step);
        v.lastInteraction = now();
    }
    if (held(GLFW_KEY_EQUAL) || held(GLFW_KEY_KP_ADD) || held(GLFW_KEY_PAGE_UP)) {
        zoom(v.camera, 1.0f - step * 0.5f);
        v.lastInteraction = now();
    }
    if (held(GLFW_KEY_MINUS) || held(GLFW_KEY_KP_SUBTRACT) || held(GLFW_KEY_PAGE_DOWN)) {
        zoom(v.camera, 1.0f + step * 0.5f);
        v.lastInteraction = now();
    }
    auto hit = [&](int key) { return ImGui::IsKeyPressed(key, false); };
    if (ctrl && hit(GLFW_KEY_Z)) shift ? redo(v) : undo(v);
    if (ctrl && hit(GLFW_KEY_Y)) redo(v);
    if (ctrl && hit(GLFW_KEY_S)) save(v, savePathOf(v));
    if (ctrl) return;
    if (hit(GLFW_KEY_F)) frameSelection(v);
    if (hit(GLFW_KEY_R)) resetCamera(v), v.lastInteraction = now();
    if (hit(GLFW_KEY_1)) v.mode = RenderMode::Shaded;
    if (hit(GLFW_KEY_2)) v.mode = RenderMode::Normals;
    if (hit(GLFW_KEY_3)) v.mode = RenderMode::Depth;
    if (hit(GLFW_KEY_4)) v.mode = RenderMode::Steps;
    if (hit(GLFW_KEY_H)) v.showUi = !v.showUi;
    if (hit(GLFW_KEY_G)) v.grid = !v.grid;
    if (hit(GLFW_KEY_M) && v.mesh) v.meshView = !v.meshView;
    if (hit(GLFW_KEY_B)) v.boxes = BoxOverlay((uint32_t(v.boxes) + 1) % 3);
    if (hit(GLFW_KEY_ESCAPE)) v.selected = -1;
}

// ---- Panels ----------------------------------------------------------------------------------

// A dragged tree node's payload: its index in v.scene.
constexpr const char* kNodePayload = "sdfcsg-node";

// Draws the tree below `node`. A node dropped on another is only recorded in *drop (dragged,
// target), to apply once the tree is drawn: the edit renumbers the nodes being drawn.
void nodeTree(Viewer& v, uint32_t node, std::optional<std::pair<uint32_t, uint32_t>>* drop) {
    const Scene& s = *v.scene;
    const Node& n = s.nodes[node];
    bool operation = kindInfo(n.kind).operation;
    ImGuiTreeNodeFlags flags = ImGuiTreeNodeFlags_OpenOnArrow | ImGuiTreeNodeFlags_DefaultOpen |
                               ImGuiTreeNodeFlags_SpanAvailWidth;
    if (!operation) flags |= ImGuiTreeNodeFlags_Leaf | ImGuiTreeNodeFlags_NoTreePushOnOpen;
    if (int(node) == v.selected) flags |= ImGuiTreeNodeFlags_Selected;
    std::string label = nodeLabel(s, node);
    if (operation && s.nodes[node].params[0] > 0.0f)
        label += " smooth " + std::to_string(s.nodes[node].params[0]).substr(0, 5);
    bool open = ImGui::TreeNodeEx((void*)(uintptr_t)node, flags, "%s", label.c_str());
    if (ImGui::IsItemClicked() && !ImGui::IsItemToggledOpen()) v.selected = int(node);
    if (node != 0 && ImGui::BeginDragDropSource()) { // the root has nowhere to go
        ImGui::SetDragDropPayload(kNodePayload, &node, sizeof node);
        ImGui::TextUnformatted(nodeLabel(s, node).c_str());
        ImGui::EndDragDropSource();
    }
    if (ImGui::BeginDragDropTarget()) {
        if (const ImGuiPayload* payload = ImGui::AcceptDragDropPayload(kNodePayload)) {
            uint32_t dragged = 0;
            std::memcpy(&dragged, payload->Data, sizeof dragged);
            if (dragged != node) *drop = std::pair(dragged, node);
        }
        ImGui::EndDragDropTarget();
    }
    if (operation && open) {
        for (uint32_t c : n.children)
            nodeTree(v, c, drop);
        ImGui::TreePop();
    }
}

void valueEditor(Viewer& v) {
    if (v.selected < 0 || v.selected >= int(v.scene->nodes.size())) {
        ImGui::TextDisabled("Click a node in the tree or the image to select it.");
        return;
    }
    uint32_t id = uint32_t(v.selected);
    const Node n = v.scene->nodes[id]; // a copy: edits replace the scene
    const KindInfo& info = kindInfo(n.kind);
    ImGui::Text("%s", nodeLabel(*v.scene, id).c_str());
    ImGui::TextDisabled("%s", n.path.c_str());
    auto edited = [&](const char* key, std::vector<float> values) {
        commit(v, setValue(*v.scene, id, key, values), std::to_string(id) + key);
        v.lastInteraction = now(); // previews while a value is dragged, as while the camera moves
    };
    for (const ParamInfo& p : info.params) {
        std::string name(p.name);
        float min = p.check == Check::Positive      ? 1e-3f
                    : p.check == Check::NonNegative ? 0.0f
                                                    : -1e6f;
        if (p.type == ValueType::Choice) {
            const size_t chosen = std::min(size_t(n.params[p.slot]), p.choices.size() - 1);
            if (ImGui::BeginCombo(name.c_str(), std::string(p.choices[chosen]).c_str())) {
                for (size_t c = 0; c < p.choices.size(); ++c)
                    if (ImGui::Selectable(std::string(p.choices[c]).c_str(), c == chosen) &&
                        c != chosen)
                        edited(name.c_str(), {float(c)});
                ImGui::EndCombo();
            }
            continue;
        }
        if (p.type == ValueType::Text) {
            char text[1024];
            std::snprintf(text, sizeof text, "%s", n.strings[p.slot].c_str());
            if (ImGui::InputText(name.c_str(), text, sizeof text,
                                 ImGuiInputTextFlags_EnterReturnsTrue))
                commit(v, setText(*v.scene, id, p.name, text), std::to_string(id) + name);
            continue;
        }
        if (p.type == ValueType::Points) {
            std::vector<float> flat;
            for (glm::vec2 q : n.points)
                flat.insert(flat.end(), {q.x, q.y});
            bool moved = false;
            for (size_t i = 0; i < n.points.size(); ++i)
                moved |= ImGui::DragFloat2(("point " + std::to_string(i)).c_str(), &flat[2 * i],
                                           0.01f, -1e6f, 1e6f, "%.3f");
            if (moved) edited(name.c_str(), flat);
            if (ImGui::IsItemDeactivatedAfterEdit()) v.doc.history().endMerge();
            continue;
        }
        if (p.type == ValueType::Number) {
            float value = n.params[p.slot];
            if (ImGui::DragFloat(name.c_str(), &value, 0.01f, min, std::min(p.maximum, 1e6f),
                                 "%.3f"))
                edited(name.c_str(), {std::clamp(value, min, p.maximum)});
        } else {
            float value[3] = {n.params[p.slot], n.params[p.slot + 1], n.params[p.slot + 2]};
            if (ImGui::DragFloat3(name.c_str(), value, 0.01f, min, 1e6f, "%.3f"))
                edited(name.c_str(),
                       {std::max(value[0], min), std::max(value[1], min), std::max(value[2], min)});
        }
        if (ImGui::IsItemDeactivatedAfterEdit()) v.doc.history().endMerge();
    }
    glm::vec3 t = n.transform.translate, r = n.transform.rotate;
    glm::vec3 s = n.transform.scale;
    if (ImGui::DragFloat3("translate", &t.x, 0.01f)) edited("translate", {t.x, t.y, t.z});
    if (ImGui::IsItemDeactivatedAfterEdit()) v.doc.history().endMerge();
    if (ImGui::DragFloat3("rotate", &r.x, 0.5f)) edited("rotate", {r.x, r.y, r.z});
    if (ImGui::IsItemDeactivatedAfterEdit()) v.doc.history().endMerge();
    if (ImGui::DragFloat3("scale", &s.x, 0.005f, 1e-3f, 1e3f))
        edited("scale", {std::max(s.x, 1e-3f), std::max(s.y, 1e-3f), std::max(s.z, 1e-3f)});
    if (ImGui::IsItemDeactivatedAfterEdit()) v.doc.history().endMerge();
    bool own = n.color.has_value();
    if (ImGui::Checkbox("own colour", &own))
        own ? edited("color", {0.8f, 0.8f, 0.8f}) : edited("color", {});
    if (own) {
        glm::vec3 c = *n.color;
        if (ImGui::ColorEdit3("color", &c.x)) edited("color", {c.x, c.y, c.z});
        if (ImGui::IsItemDeactivatedAfterEdit()) v.doc.history().endMerge();
    }

    ImGui::Separator();
    // Structural edits: the renderer recompiles on the worker thread.
    if (ImGui::BeginCombo("kind", std::string(info.name).c_str())) {
        for (const KindInfo& k : nodeKinds())
            if (k.operation == info.operation &&
                ImGui::Selectable(std::string(k.name).c_str(), k.kind == n.kind) &&
                k.kind != n.kind)
                commit(v, changeKind(*v.scene, id, k.kind));
        ImGui::EndCombo();
    }
    if (info.operation) {
        if (ImGui::BeginCombo("add child", "choose a kind")) {
            for (const KindInfo& k : nodeKinds())
                if (ImGui::Selectable(std::string(k.name).c_str())) {
                    uint32_t added = 0;
                    if (commit(v, addChild(*v.scene, id, k.kind, &added))) v.selected = int(added);
                }
            ImGui::EndCombo();
        }
    }
    if (ImGui::Button("move up")) {
        uint32_t moved = id;
        if (commit(v, moveNode(*v.scene, id, -1, &moved))) v.selected = int(moved);
    }
    ImGui::SameLine();
    if (ImGui::Button("move down")) {
        uint32_t moved = id;
        if (commit(v, moveNode(*v.scene, id, 1, &moved))) v.selected = int(moved);
    }
    ImGui::SameLine();
    if (ImGui::Button("remove") && commit(v, removeNode(*v.scene, id))) v.selected = -1;
}

void fileBrowser(Viewer& v) {
    if (!v.browserOpen) return;
    ImGui::SetNextWindowSize(ImVec2(420, 360), ImGuiCond_FirstUseEver);
    if (ImGui::Begin("Open scene", &v.browserOpen)) {
        ImGui::TextWrapped("%s", v.browseDir.string().c_str());
        if (ImGui::Selectable("..")) v.browseDir = v.browseDir.parent_path();
        // Listed again on navigation and every second, not every frame: a large or network
        // folder would slow the window down.
        std::error_code ec;
        if (v.browseListed != v.browseDir || now() - v.browseTime > 1.0) {
            v.browseEntries.clear();
            for (const auto& e : fs::directory_iterator(v.browseDir, ec))
                if (e.is_directory(ec) || e.path().extension() == ".json")
                    v.browseEntries.push_back(e);
            std::sort(v.browseEntries.begin(), v.browseEntries.end(), [](auto& a, auto& b) {
                return std::pair(!a.is_directory(), a.path()) <
                       std::pair(!b.is_directory(), b.path());
            });
            v.browseListed = v.browseDir;
            v.browseTime = now();
        }
        const std::vector<fs::directory_entry> entries = v.browseEntries; // may change below
        for (const auto& e : entries) {
            std::string name = e.path().filename().string() + (e.is_directory(ec) ? "/" : "");
            if (ImGui::Selectable(name.c_str())) {
                if (e.is_directory(ec)) {
                    v.browseDir = e.path();
                } else {
                    openFile(v, e.path());
                    v.browserOpen = false;
                }
            }
        }
    }
    ImGui::End();
}

// Starts writing the mesh in the background; the problem when it cannot start.
std::optional<std::string> startExport(Viewer& v, const fs::path& path) {
    auto format = meshFormatFromPath(path);
    if (!format)
        return path.string() + ": the extension names no mesh format (.ply, .obj, .stl, .glb, .3mf)";
    if (!v.exporter->start(v.mesh, path, *format)) return "a mesh is being written";
    v.exporting = path;
    v.meshMessage = "writing " + path.string() + "...";
    return std::nullopt;
}

// Takes a finished extraction (the mesh goes to the device once, here) and a finished export.
// False when one that a script started failed.
bool finishMesh(Viewer& v) {
    bool ok = true;
    auto report = [&](std::string& where, const std::string& message, bool failed) {
        if (!where.empty() && failed) {
            std::fprintf(stderr, "%s%s\n", where.c_str(), message.c_str());
            v.exitCode = 1;
            ok = false;
        }
        where.clear();
    };
    if (auto done = v.mesher->take()) {
        if (*done) {
            auto mesh = std::make_shared<const Mesh>(std::move((*done)->mesh));
            v.meshStats = v.mesher->stats();
            std::string error;
            const Mesh* preview = (*done)->preview ? &*(*done)->preview : nullptr;
            if (setMesh(*v.presenter, *mesh, preview, error)) {
                v.mesh = std::move(mesh);
                char text[160];
                std::snprintf(text, sizeof text, "%zu vertices, %zu triangles, %.2f s%s",
                              v.mesh->vertexCount(), v.mesh->triangleCount(),
                              v.meshStats.totalSeconds,
                              v.meshStats.surfaceCut ? " (cut by bounds)" : "");
                v.meshMessage = text;
                v.meshView = true;
            } else {
                v.mesh.reset();
                v.meshView = false;
                v.meshMessage = error;
            }
        } else {
            v.meshMessage = done->error().str();
        }
        report(v.meshScript, v.meshMessage, !v.mesh || !*done);
    }
    if (auto written = v.exporter->take()) {
        v.meshMessage = *written ? "wrote " + v.exporting.string() : written->error().str();
        report(v.exportScript, v.meshMessage, !*written);
    }
    return ok;
}

void meshPanel(Viewer& v) {
    ImGui::SliderInt("resolution", &v.meshResolution, 16, 512);
    ImGui::Checkbox("custom bounds", &v.customBounds);
    if (v.customBounds) {
        ImGui::DragFloat3("min", v.boundsMin, 0.01f);
        ImGui::DragFloat3("max", v.boundsMax, 0.01f);
    }
    if (v.mesher->running()) {
        ImGui::ProgressBar(v.mesher->progress());
        if (ImGui::Button("cancel")) v.mesher->cancel();
    } else if (ImGui::Button("extract mesh") && v.scene) {
        MeshOptions o;
        o.resolution = uint32_t(v.meshResolution);
        if (v.customBounds)
            o.bounds = Aabb{glm::vec3(v.boundsMin[0], v.boundsMin[1], v.boundsMin[2]),
                            glm::vec3(v.boundsMax[0], v.boundsMax[1], v.boundsMax[2])};
        v.mesher->start(v.scene, o);
        v.meshMessage = "extracting...";
    }
    if (!v.meshMessage.empty()) ImGui::TextWrapped("%s", v.meshMessage.c_str());
    if (!v.mesh) return;
    ImGui::Checkbox("show mesh (M)", &v.meshView);
    ImGui::SameLine();
    ImGui::Checkbox("wireframe", &v.wireframe);
    if (v.meshView) {
        if (v.shown.meshPreview)
            ImGui::Text("preview mesh: %u triangles", previewMeshTriangles(*v.presenter));
        else
            ImGui::Text("full mesh: %zu triangles", v.mesh->triangleCount());
        ImGui::Text("mesh frame %.1f ms, last drawn in %.1f ms", v.meshFrameMs, v.meshDrawMs);
    }
    ImGui::InputText("file", v.exportPath, sizeof v.exportPath);
    ImGui::SameLine();
    if (v.exporter->running()) {
        ImGui::TextDisabled("writing...");
    } else if (ImGui::Button("export")) {
        if (auto problem = startExport(v, v.exportPath)) v.meshMessage = *problem;
    }
}

void generatePanel(Viewer& v) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped("%s", v.endpoint.c_str());
    ImGui::PopStyleColor();
    ImGui::InputTextMultiline("##prompt", v.prompt, sizeof v.prompt,
                              ImVec2(-1, ImGui::GetTextLineHeight() * 4));
    if (v.generating) {
        const GenerateStatus s = v.generator->status();
        ImGui::Text("%c %.0f s", "|/-\\"[int(s.seconds * 8) % 4], s.seconds);
        ImGui::SameLine();
        if (ImGui::Button("Cancel")) v.generator->cancel();
        ImGui::TextWrapped("%s", s.message.c_str());
    } else {
        ImGui::BeginDisabled(!v.prompt[0] || !v.endpointOk);
        if (ImGui::Button("Generate new scene")) startGeneration(v, v.prompt, false);
        ImGui::SameLine();
        ImGui::BeginDisabled(!v.doc.loaded());
        if (ImGui::Button("Edit this scene")) startGeneration(v, v.prompt, true);
        ImGui::EndDisabled();
        ImGui::EndDisabled();
    }
    if (!v.generateSummary.empty()) ImGui::TextWrapped("%s", v.generateSummary.c_str());
    ImGui::PushStyleColor(ImGuiCol_Text, IM_COL32(255, 200, 90, 255));
    for (const Diagnostic& w : v.generateWarnings)
        ImGui::TextWrapped("warning: %s: %s", w.path.c_str(), w.message.c_str());
    ImGui::PopStyleColor();
    if (v.generateError) {
        ImGui::PushStyleColor(ImGuiCol_Text, IM_COL32(255, 110, 110, 255));
        ImGui::TextWrapped("%s", v.generateError->str().c_str());
        ImGui::PopStyleColor();
        ImGui::TextDisabled("the scene was not changed");
    }
}

void panels(Viewer& v) {
    ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(340, 0), ImGuiCond_FirstUseEver);
    ImGui::Begin("sdfcsg");
    if (ImGui::CollapsingHeader("File", ImGuiTreeNodeFlags_DefaultOpen)) {
        ImGui::InputText("##open", v.openPath, sizeof v.openPath);
        ImGui::SameLine();
        if (ImGui::Button("open") && v.openPath[0]) openFile(v, v.openPath);
        ImGui::SameLine();
        if (ImGui::Button("browse")) v.browserOpen = true;
        if (!v.recent.empty() && ImGui::BeginCombo("recent", v.recent[0].c_str())) {
            for (const std::string& r : std::vector<std::string>(v.recent))
                if (ImGui::Selectable(r.c_str())) openFile(v, r);
            ImGui::EndCombo();
        }
        ImGui::InputText("##save", v.savePath, sizeof v.savePath);
        ImGui::SameLine();
        if (ImGui::Button("save") && v.savePath[0]) save(v, v.savePath);
        ImGui::BeginDisabled(!v.doc.history().canUndo());
        if (ImGui::Button("undo")) undo(v);
        ImGui::EndDisabled();
        ImGui::SameLine();
        ImGui::BeginDisabled(!v.doc.history().canRedo());
        if (ImGui::Button("redo")) redo(v);
        ImGui::EndDisabled();
    }
    // Load errors (the file) and compile errors (the edited scene) both keep the last good
    // scene on screen.
    const std::optional<Error>* errors[] = {&v.doc.error(), &v.renderError};
    for (const std::optional<Error>* e : errors) {
        if (!*e) continue;
        ImGui::PushStyleColor(ImGuiCol_Text, IM_COL32(255, 110, 110, 255));
        ImGui::TextWrapped("%s", (*e)->str().c_str());
        ImGui::PopStyleColor();
        if (v.scene) ImGui::TextDisabled("showing the last scene that worked");
    }
    if (!v.status.empty()) ImGui::TextWrapped("%s", v.status.c_str());
    if (ImGui::CollapsingHeader("View", ImGuiTreeNodeFlags_DefaultOpen)) {
        int mode = int(v.mode);
        ImGui::RadioButton("shaded", &mode, 0);
        ImGui::SameLine();
        ImGui::RadioButton("normals", &mode, 1);
        ImGui::SameLine();
        ImGui::RadioButton("depth", &mode, 2);
        ImGui::SameLine();
        ImGui::RadioButton("steps", &mode, 3);
        v.mode = RenderMode(mode);
        ImGui::Checkbox("shadows", &v.shadows);
        ImGui::SameLine();
        ImGui::Checkbox("AO", &v.ao);
        ImGui::SameLine();
        ImGui::Checkbox("grid", &v.grid);
        int boxes = int(v.boxes);
        ImGui::Combo("boxes", &boxes, "none\0all\0selected\0");
        v.boxes = BoxOverlay(boxes);
        if (ImGui::Button("frame (F)")) frameSelection(v);
        ImGui::SameLine();
        if (ImGui::Button("reset (R)")) resetCamera(v), v.lastInteraction = now();
        ImGui::InputText("##shot", v.shotPath, sizeof v.shotPath);
        ImGui::SameLine();
        if (ImGui::Button("screenshot")) v.pendingShot = v.shotPath;
        ImGui::Text("render %.0f ms at %u x %u%s", v.renderMs, v.last.image.width,
                    v.last.image.height,
                    v.haveShown && v.shown.width < wantedKey(v, true).width ? " (preview)" : "");
        if (v.compileMs > 0) ImGui::Text("last compile %.0f ms", v.compileMs);
        ImGui::Text("UI %.1f ms/frame", 1000.0f / std::max(ImGui::GetIO().Framerate, 1.0f));
        ImGui::TextDisabled("%s", v.context->deviceName().c_str());
    }
    if (v.scene && ImGui::CollapsingHeader("Scene", ImGuiTreeNodeFlags_DefaultOpen)) {
        ImGui::BeginChild("tree", ImVec2(0, 220), true);
        std::optional<std::pair<uint32_t, uint32_t>> drop;
        nodeTree(v, 0, &drop);
        ImGui::EndChild();
        uint32_t moved = 0;
        if (drop && commit(v, dropNode(*v.scene, drop->first, drop->second, &moved)))
            v.selected = int(moved);
    }
    if (v.scene && ImGui::CollapsingHeader("Node", ImGuiTreeNodeFlags_DefaultOpen)) valueEditor(v);
    if (v.scene && ImGui::CollapsingHeader("Mesh")) meshPanel(v);
    // Open at first when started without a scene: describing one is a way to start.
    if (ImGui::CollapsingHeader("Generate", v.startedEmpty ? ImGuiTreeNodeFlags_DefaultOpen : 0))
        generatePanel(v);
    ImGui::End();
    fileBrowser(v);
}

// ---- Automation ------------------------------------------------------------------------------

// Runs commands until one has to wait for an image. False when a command failed.
bool runScript(Viewer& v) {
    // A script's extraction or write is waited for until finishMesh() has taken its result.
    while (!v.script.empty() && v.pendingShot.empty() && !v.generating && v.meshScript.empty() &&
           v.exportScript.empty()) {
        Command c = v.script.front();
        v.script.pop_front();
        std::string where = v.scriptFile + ":" + std::to_string(c.line) + ": ";
        auto fail = [&](const std::string& message) {
            std::fprintf(stderr, "%s%s\n", where.c_str(), message.c_str());
            v.exitCode = 1;
            return false;
        };
        syncScene(v);
        if (!v.scene && c.verb != "generate" && c.verb != "open") return fail("no scene loaded");
        const std::string arg = c.args.empty() ? "" : c.args[0];
        // Commands that look at the image wait for the full-resolution one of the current state.
        const bool needsImage =
            c.verb == "pick" || c.verb == "print-bounds" || c.verb == "expect-error";
        if ((needsImage && !settled(v)) || (c.verb == "wait-reload" && v.reloads == 0)) {
            if (v.commandWaitStart == 0) v.commandWaitStart = now();
            if (now() - v.commandWaitStart > 300.0)
                return fail(c.verb + ": still waiting after 300 s");
            v.script.push_front(c);
            return true;
        }
        v.commandWaitStart = 0;
        auto selectedNode = [&]() -> std::optional<uint32_t> {
            if (v.selected < 0 || v.selected >= int(v.scene->nodes.size())) return std::nullopt;
            return uint32_t(v.selected);
        };
        auto kindNamed = [](const std::string& name) {
            for (const KindInfo& k : nodeKinds())
                if (k.name == name) return k.kind;
            return NodeKind::Sphere; // parseScript admits known names only
        };
        if (c.verb == "select") {
            if (arg == "none") {
                v.selected = -1;
            } else if (auto n = findNode(*v.scene, arg)) {
                v.selected = int(*n);
            } else {
                return fail("no node named \"" + arg + "\"");
            }
        } else if (c.verb == "set") {
            if (v.selected < 0) return fail("set: no node selected");
            auto edited = setValue(*v.scene, uint32_t(v.selected), arg, c.numbers);
            if (!edited) return fail(edited.error().str());
            commit(v, std::move(edited));
        } else if (c.verb == "mode") {
            v.mode = *parseRenderMode(arg);
        } else if (c.verb == "shadows") {
            v.shadows = arg == "on";
        } else if (c.verb == "ao") {
            v.ao = arg == "on";
        } else if (c.verb == "grid") {
            v.grid = arg == "on";
        } else if (c.verb == "boxes") {
            v.boxes = arg == "none"  ? BoxOverlay::None
                      : arg == "all" ? BoxOverlay::All
                                     : BoxOverlay::Selected;
        } else if (c.verb == "orbit" || c.verb == "drag") {
            orbit(v.camera, glm::radians(c.numbers[0]), glm::radians(c.numbers[1]));
            if (c.verb == "drag") v.lastInteraction = now();
        } else if (c.verb == "zoom") {
            zoom(v.camera, c.numbers[0]);
        } else if (c.verb == "frame") {
            frameSelection(v);
            v.lastInteraction = -1.0;
        } else if (c.verb == "reset") {
            resetCamera(v);
        } else if (c.verb == "undo") {
            undo(v);
        } else if (c.verb == "redo") {
            redo(v);
        } else if (c.verb == "save") {
            fs::path path = !arg.empty() ? fs::path(arg) : savePathOf(v);
            auto saved = v.doc.save(path);
            if (!saved) return fail(saved.error().str());
        } else if (c.verb == "add" || c.verb == "remove" || c.verb == "kind" || c.verb == "op" ||
                   c.verb == "move" || c.verb == "parent") {
            auto node = selectedNode();
            if (!node) return fail(c.verb + ": no node selected");
            uint32_t moved = *node;
            std::optional<uint32_t> parent;
            if (c.verb == "parent" && !(parent = findNode(*v.scene, arg)))
                return fail("no node named \"" + arg + "\"");
            Result<Scene> edited =
                c.verb == "add" ? addChild(*v.scene, *node, kindNamed(arg), &moved)
                : c.verb == "parent"
                    ? reparentNode(*v.scene, *node, *parent,
                                   c.numbers.empty() ? kLastChild : uint32_t(c.numbers[0]), &moved)
                : c.verb == "remove" ? removeNode(*v.scene, *node)
                : c.verb == "move"   ? moveNode(*v.scene, *node, arg == "up" ? -1 : 1, &moved)
                                     : changeKind(*v.scene, *node, kindNamed(arg));
            if (!edited) return fail(edited.error().str());
            commit(v, std::move(edited));
            // As the Node panel's buttons leave the selection.
            if (c.verb == "remove")
                v.selected = -1;
            else
                v.selected = int(moved);
        } else if (c.verb == "open") {
            openFile(v, arg); // a failure shows in the panel, as in the file browser
        } else if (c.verb == "wait-reload") {
            --v.reloads;
        } else if (c.verb == "pick") {
            pick(v, c.numbers[0], c.numbers[1]);
        } else if (c.verb == "ui") {
            v.showUi = arg == "on";
        } else if (c.verb == "print-bounds") {
            auto n = findNode(*v.scene, arg);
            if (!n) return fail("no node named \"" + arg + "\"");
            Evaluator shown(*v.last.scene);
            if (*n >= shown.nodes().size()) return fail("print-bounds: the image shows no " + arg);
            PixelRect r = projectedRect(*v.last.options.camera, v.last.image.width,
                                        v.last.image.height, shown.nodes()[*n].bounds);
            std::printf("bounds %s %d %d %d %d\n", arg.c_str(), r.x0, r.y0, r.x1, r.y1);
            std::fflush(stdout);
        } else if (c.verb == "expect-error") {
            std::string shown = v.doc.error() ? v.doc.error()->str() : "";
            if (v.renderError) shown += (shown.empty() ? "" : "\n") + v.renderError->str();
            if (c.text == "none" ? !shown.empty() : shown.find(c.text) == std::string::npos)
                return fail("expected the error \"" + c.text + "\", shown: \"" + shown + "\"");
        } else if (c.verb == "expect-selected") {
            std::optional<uint32_t> want;
            if (arg != "none") {
                want = findNode(*v.scene, arg);
                if (!want) return fail("no node named \"" + arg + "\"");
            }
            if (selectedNode() != want)
                return fail("expected " + (want ? nodeLabel(*v.scene, *want) : "no node") +
                            " selected, got " +
                            (selectedNode() ? nodeLabel(*v.scene, *selectedNode()) : "none"));
        } else if (c.verb == "screenshot") {
            v.pendingShot = arg;
            v.waitStart = now();
        } else if (c.verb == "mesh" && arg == "extract") {
            MeshOptions o;
            o.resolution = uint32_t(c.numbers[0]);
            v.meshResolution = int(o.resolution); // as if set in the panel
            v.mesher->start(v.scene, o);
            v.meshScript = where;
        } else if (c.verb == "mesh") { // export
            if (!v.mesh) return fail("mesh export: no mesh extracted");
            if (auto problem = startExport(v, c.args[1])) return fail(*problem);
            v.exportScript = where;
        } else if (c.verb == "view") {
            if (arg == "mesh" && !v.mesh) return fail("view mesh: no mesh extracted");
            v.meshView = arg == "mesh";
        } else if (c.verb == "wireframe") {
            v.wireframe = arg == "on";
        } else if (c.verb == "generate" || c.verb == "edit-scene") {
            std::snprintf(v.prompt, sizeof v.prompt, "%s", c.text.c_str()); // as if typed
            startGeneration(v, c.text, c.verb == "edit-scene");
            v.generationScript = where;
        }
        syncScene(v);
    }
    return true;
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
    if (!args.script.empty()) {
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
    }
    v.showUi = !args.noUi;
    v.recent = loadRecent(recentFilesPath());

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
    v.startedEmpty = args.scene.empty();

    if (!args.scene.empty()) {
        openFile(v, args.scene);
        if (!v.doc.loaded() && (!args.screenshot.empty() || !args.script.empty())) {
            std::fprintf(stderr, "%s\n", v.doc.error()->str().c_str());
            return 1;
        }
    }

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
    v.presenter = createPresenter(v.window, error);
    if (!v.presenter) {
        std::fprintf(stderr, "sdfcsg-viewer: %s\n", error.c_str());
        return 4;
    }

    v.framesLeft = args.frames;
    if (!args.screenshot.empty()) {
        v.pendingShot = args.screenshot;
        v.exitAfterShot = true;
        v.waitStart = now();
    }
    bool automated = !args.screenshot.empty() || !args.script.empty();
    double lastPoll = 0;
    while (!glfwWindowShouldClose(v.window)) {
        // Automated runs never sleep; interactive ones wait for input while nothing is pending.
        if (automated || !v.renderer->idle() || v.mesher->running() || v.exporter->running() ||
            moving(v))
            glfwPollEvents();
        else
            glfwWaitEventsTimeout(0.1);
        if (now() - lastPoll > 0.25) { // live reload
            lastPoll = now();
            const std::shared_ptr<const Scene> before = v.scene;
            if (v.doc.pollReload()) {
                v.status = v.doc.error() ? "reload failed" : "reloaded " + v.doc.path().string();
                // Node numbers change with the file: the selection follows its node.
                if (!v.doc.error() && before && v.selected >= 0) {
                    auto same = sameNode(*before, uint32_t(v.selected), v.doc.scene());
                    v.selected = same ? int(*same) : -1;
                }
                ++v.reloads;
            }
        }
        syncScene(v);
        if (!finishGeneration(v) || !finishMesh(v) || !runScript(v)) break;

        ImGui_ImplVulkan_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        handleInput(v);
        syncScene(v);
        if (v.showUi) panels(v);
        ImGui::Render();
        syncScene(v);
        updateImage(v);

        Image capture;
        // One settled frame more, so the panels show the numbers of the image they sit on.
        v.settledFrames = settled(v) ? v.settledFrames + 1 : 0;
        bool shoot = !v.pendingShot.empty() && v.settledFrames >= 2 && v.framesLeft <= 1;
        float bg[3] = {0.1f, 0.1f, 0.1f};
        if (v.scene)
            bg[0] = v.scene->background.r, bg[1] = v.scene->background.g,
            bg[2] = v.scene->background.b;
        MeshView meshView;
        meshView.camera = toCamera(v.camera);
        meshView.wireframe = v.wireframe;
        meshView.closed = !v.meshStats.surfaceCut;
        // As updateImage() chose: screenshots wait for a settled view, which draws the full mesh.
        meshView.preview = v.shown.meshPreview;
        if (v.grid && v.evaluator) meshView.grid = groundGrid(*v.evaluator);
        const bool drawsMesh = v.meshView && v.mesh;
        const double frameStart = now();
        bool drawn = drawFrame(*v.presenter, ImGui::GetDrawData(), bg,
                               drawsMesh ? &meshView : nullptr, shoot ? &capture : nullptr);
        if (drawn && drawsMesh) {
            v.meshFrameMs = (now() - frameStart) * 1000.0;
            v.meshDrawMs = meshDrawMilliseconds(*v.presenter);
        }
        if (drawn && v.framesLeft > 0) --v.framesLeft;
        if (shoot && drawn) {
            if (capture.rgba.empty()) {
                // This surface cannot be read back: the scene image alone is the next best.
                capture = v.last.image;
            }
            auto written = writePng(capture, v.pendingShot);
            if (!written) {
                std::fprintf(stderr, "%s\n", written.error().str().c_str());
                v.exitCode = 3;
                break;
            }
            // With the mesh's device time, so scripts can time the mesh view.
            if (drawsMesh && v.meshDrawMs >= 0.0)
                std::printf("wrote %s (%u x %u), mesh drawn in %.1f ms\n",
                            v.pendingShot.string().c_str(), capture.width, capture.height,
                            v.meshDrawMs);
            else
                std::printf("wrote %s (%u x %u)\n", v.pendingShot.string().c_str(), capture.width,
                            capture.height);
            v.pendingShot.clear();
            if (v.exitAfterShot) break;
        }
        if (!v.pendingShot.empty() && automated && now() - v.waitStart > 300.0) {
            std::fprintf(stderr, "sdfcsg-viewer: no image after 300 s\n");
            v.exitCode = 1;
            break;
        }
        if (!args.script.empty() && v.script.empty() && v.pendingShot.empty() && !v.generating &&
            v.meshScript.empty() && v.exportScript.empty() && !v.exitAfterShot)
            break;
    }
    if (automated && v.renderError && v.exitCode == 0) {
        std::fprintf(stderr, "%s\n", v.renderError->str().c_str());
        v.exitCode = 1;
    }
    // Under the tests' validation layer, any message fails an automated run: the window's
    // device, the renderer's and the live renderer's own.
    if (automated && v.exitCode == 0 &&
        (presenterValidationMessages(*v.presenter) || v.context->validationMessageCount() ||
         (v.liveContext && v.liveContext->validationMessageCount()))) {
        std::fprintf(stderr, "sdfcsg-viewer: the validation layer reported problems\n");
        v.exitCode = 1;
    }
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
