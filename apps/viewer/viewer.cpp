// What the viewer does besides input and panels: the scene handed to the workers, files and undo,
// generation, mesh extraction and export, and the images asked of the render worker.
#include "viewer.h"

#include <sdfcsg/export.h>
#include <sdfcsg/generate.h>

#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <utility>

namespace fs = std::filesystem;

namespace sdfcsg::viewer {

namespace {

float aspectOf(const Viewer& v) {
    int w = 1, h = 1;
    glfwGetFramebufferSize(v.window, &w, &h);
    return h > 0 ? float(w) / float(h) : 1.0f;
}

void addRecent(Viewer& v, const fs::path& path) {
    std::string p = path.string();
    v.recent.erase(std::remove(v.recent.begin(), v.recent.end(), p), v.recent.end());
    v.recent.insert(v.recent.begin(), p);
    if (v.recent.size() > 10) v.recent.resize(10);
    saveRecent(v.recentFile, v.recent);
}

} // namespace

double now() {
    using namespace std::chrono;
    return duration<double>(steady_clock::now().time_since_epoch()).count();
}

namespace {

// `mesh` with the vertices whose wall is thinner than `minWall` red (in vertex colours, so
// without its colour per triangle).
Mesh thinWallsRed(const Mesh& mesh, const std::vector<float>& walls, float minWall) {
    Mesh red = mesh;
    red.triangleColors.clear();
    for (size_t i = 0; i < red.colors.size() && i < walls.size(); ++i)
        if (walls[i] < minWall) red.colors[i] = glm::vec3(0.9f, 0.1f, 0.05f);
    return red;
}

} // namespace

bool uploadShownMesh(Viewer& v, const Mesh& mesh, std::string& error) {
    const Mesh* preview = v.meshPreview.get();
    if (!v.thinWalls) return setMesh(*v.presenter, mesh, preview, error);
    const float least = defaultMinWall();
    const Mesh red = thinWallsRed(mesh, v.meshWalls, least);
    std::optional<Mesh> redPreview;
    if (preview) redPreview = thinWallsRed(*preview, v.previewWalls, least);
    return setMesh(*v.presenter, red, redPreview ? &*redPreview : nullptr, error);
}

void resetCamera(Viewer& v) {
    if (!v.evaluator) return;
    Camera c = v.scene->camera ? *v.scene->camera : frameCamera(*v.evaluator, aspectOf(v));
    // A solid beyond single precision frames no camera: the default one shows why nothing shows.
    auto finite = [](glm::vec3 p) { return std::isfinite(p.x + p.y + p.z); };
    if (!finite(c.eye) || !finite(c.target)) c = Camera{};
    v.camera = orbitFromCamera(c);
}

void frameSelection(Viewer& v) {
    if (!v.evaluator) return;
    frameBox(v.camera, framedBounds(*v.evaluator, v.selected), aspectOf(v));
    v.lastInteraction = now();
}

void syncScene(Viewer& v) {
    if (!v.doc.loaded() || v.sceneVersion == v.doc.version()) return;
    bool first = !v.scene;
    v.scene = std::make_shared<const Scene>(v.doc.scene());
    v.sceneVersion = v.doc.version();
    v.evaluator = std::make_unique<Evaluator>(*v.scene);
    v.fieldNotes = fieldNotes(*v.scene, *v.evaluator);
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

fs::path savePathOf(const Viewer& v) {
    return v.savePath[0] ? fs::path(v.savePath) : v.doc.path();
}

void save(Viewer& v, const fs::path& path) {
    auto saved = v.doc.save(path);
    v.status = saved ? "saved " + path.string() : saved.error().str();
    if (saved) addRecent(v, path);
}

bool commit(Viewer& v, Result<Scene> edited, std::string mergeKey) {
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
    v.endpoint = endpoint ? endpoint->model + " at " + endpoint->shownUrl +
                                (v.llm.apiKey.empty() ? " (no API key)" : "")
                          : endpoint.error().str();
}

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

// ---- Mesh ------------------------------------------------------------------------------------

void startMesh(Viewer& v) {
    MeshOptions o;
    o.resolution = uint32_t(v.meshResolution);
    o.method = v.meshMethod == 1 ? MeshMethod::MarchingCubes : MeshMethod::DualContouring;
    o.colorRegions = true; // the mesh may be exported to 3MF or glTF, which carry its regions
    if (v.customBounds)
        o.bounds = Aabb{glm::vec3(v.boundsMin[0], v.boundsMin[1], v.boundsMin[2]),
                        glm::vec3(v.boundsMax[0], v.boundsMax[1], v.boundsMax[2])};
    v.mesher->start(v.scene, o, v.meshSimplify);
    v.meshMessage = "extracting...";
}

std::optional<std::string> startExport(Viewer& v, const fs::path& path) {
    auto format = meshFormatFromPath(path);
    if (!format)
        return path.string() +
               ": the extension names no mesh format (.ply, .obj, .stl, .glb, .3mf)";
    constexpr LengthUnit kUnits[] = {LengthUnit::Millimeter, LengthUnit::Centimeter,
                                     LengthUnit::Meter, LengthUnit::Inch};
    if (!v.exporter->start(v.mesh, path, *format, kUnits[v.exportUnit]))
        return "a mesh is being written";
    v.exporting = path;
    v.meshMessage = "writing " + path.string() + "...";
    return std::nullopt;
}

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
            v.meshReport = std::move((*done)->report);
            v.meshWalls = std::move((*done)->walls);
            v.previewWalls = std::move((*done)->previewWalls);
            v.meshPreview.reset();
            if ((*done)->preview)
                v.meshPreview = std::make_shared<const Mesh>(std::move(*(*done)->preview));
            v.thinWalls = v.thinWalls && !v.meshWalls.empty();
            std::string error;
            if (uploadShownMesh(v, *mesh, error)) {
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

bool settled(Viewer& v) {
    if (!v.scene) return !v.doc.loaded() && !v.generating; // nothing to draw, none coming
    return v.haveShown && v.shown == wantedKey(v, true) && v.renderer->idle() &&
           !(v.last.live && v.renderer->refinementPending(v.sceneVersion));
}

} // namespace sdfcsg::viewer
