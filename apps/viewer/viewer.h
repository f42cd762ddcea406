// The window's state and the functions that its files share. The window-free logic (camera,
// picking, edits, undo, files, scripts, workers) lives in the other headers of this folder; these
// files make the window around it:
//   main.cpp        arguments and the main loop
//   viewer.cpp      scene, files, undo, generation, mesh extraction and export, images to render
//   input.cpp       mouse and keyboard
//   panels.cpp      the ImGui panels
//   automation.cpp  the commands of --script
//   presenter.cpp, mesh_view.cpp  the window's Vulkan device (presenter.h)
#pragma once

#include "document.h"
#include "orbit_camera.h"
#include "presenter.h"
#include "script.h"
#include "workers.h"

#include <sdfcsg/error.h>
#include <sdfcsg/eval.h>
#include <sdfcsg/generate.h>
#include <sdfcsg/mesh.h>
#include <sdfcsg/render.h>
#include <sdfcsg/scene.h>

#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

struct GLFWwindow;

namespace sdfcsg::viewer {

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

// Everything the window shows and edits, from the workers to the panels' text fields; main()
// owns the one instance.
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
    std::vector<FieldNote> fieldNotes;    // of `scene`: where its field stops being a distance

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
    MeshReport meshReport;                      // of the mesh shown
    std::shared_ptr<const Mesh> meshPreview;    // drawn while the camera moves, if any
    std::vector<float> meshWalls, previewWalls; // ExtractedMesh's
    bool thinWalls = false;                     // thin regions drawn red
    // The last mesh frame's time (a blit when the view did not change) and the device time of the
    // last drawing of the mesh.
    double meshFrameMs = 0.0, meshDrawMs = -1.0;
    std::string meshScript, exportScript; // "file:line: " while a script's extraction or write runs
    bool meshView = false, wireframe = false;
    int meshResolution = 128;
    int meshMethod = 0;        // 0 dual contouring, 1 marching cubes (MeshMethod's order)
    float meshSimplify = 0.0f; // cells from the surface that simplification may move it; 0: off
    int exportUnit = int(kDefaultLengthUnit); // 3MF: LengthUnit's order
    bool customBounds = false;
    float boundsMin[3] = {-1, -1, -1}, boundsMax[3] = {1, 1, 1};
    std::string meshMessage;
    char exportPath[512] = "mesh.glb";
    std::filesystem::path exporting; // the file the export worker writes

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
    std::filesystem::path recentFile; // recentFilesPath(), from the environment at the start
    std::filesystem::path browseDir = std::filesystem::current_path();
    bool browserOpen = false;
    std::vector<std::filesystem::directory_entry> browseEntries; // the listing of browseListed
    std::filesystem::path browseListed;
    double browseTime = 0;
    std::string status;

    // Automation.
    std::deque<Command> script;
    std::string scriptFile;
    std::filesystem::path pendingShot; // waiting for the current full image, then written
    bool exitAfterShot = false;
    int framesLeft = 0;
    int settledFrames = 0; // frames in a row that showed the current full image
    int exitCode = 0;
    double waitStart = 0;
    double commandWaitStart = 0; // of a command waiting for an image or a reload
    int reloads = 0;             // not yet answered by the script's wait-reload
};

// Seconds on a steady clock.
double now();

// ---- viewer.cpp: scene, files, undo ----------------------------------------------------------

// Back to the scene's own camera, or one that frames it.
void resetCamera(Viewer& v);
// Gives the presenter `mesh` and the preview, their thin walls red where v.thinWalls is set;
// false with `error` where they do not fit.
bool uploadShownMesh(Viewer& v, const Mesh& mesh, std::string& error);
// Frames the selected node, or the scene when none is selected (F).
void frameSelection(Viewer& v);
// Hands the document's scene to the workers when it changed.
void syncScene(Viewer& v);
// Opens a scene file; one that loads becomes where Save writes, and gets its own camera.
void openFile(Viewer& v, const std::filesystem::path& path);
// Where Ctrl+S writes.
std::filesystem::path savePathOf(const Viewer& v);
void save(Viewer& v, const std::filesystem::path& path);
// Applies an edit's outcome: a new undo step, or the error in the status line.
bool commit(Viewer& v, Result<Scene> edited, std::string mergeKey = {});
void undo(Viewer& v);
void redo(Viewer& v);

// ---- viewer.cpp: generation ------------------------------------------------------------------

// Reads the language model's settings from the environment for the Generate panel.
void describeEndpoint(Viewer& v);
// `edit`: the current scene goes with the request, to be changed (as `sdfcsg edit` does).
void startGeneration(Viewer& v, std::string request, bool edit);
// Applies a finished generation: its scene as one undo step, or its problems in the panel while
// the current scene stays. False when a script's generation failed.
bool finishGeneration(Viewer& v);

// ---- viewer.cpp: mesh ------------------------------------------------------------------------

// Starts extracting a mesh with the panel's settings (resolution, method, bounds,
// simplification).
void startMesh(Viewer& v);

// Starts writing the mesh in the background; the problem when it cannot start.
std::optional<std::string> startExport(Viewer& v, const std::filesystem::path& path);
// Takes a finished extraction (the mesh goes to the device once, here) and a finished export.
// False when one that a script started failed.
bool finishMesh(Viewer& v);

// ---- viewer.cpp: images ----------------------------------------------------------------------

// The key of the image the current state calls for, at full or at preview resolution.
ViewKey wantedKey(Viewer& v, bool full);
// The camera or a dragged value changed a moment ago: images are previews meanwhile.
bool moving(const Viewer& v);
// Takes a finished render, and asks the render worker for the image the view needs next.
void updateImage(Viewer& v);
// The full-resolution image of the current state is on screen, from its baked kernel (so a
// screenshot is the same whether or not the live renderer drew the edit first).
bool settled(Viewer& v);

// ---- input.cpp -------------------------------------------------------------------------------

// Selects the primitive under window coordinates (x, y), in the ray-marched or the mesh view.
void pick(Viewer& v, double x, double y);
// The mouse and the keyboard, where ImGui does not take them.
void handleInput(Viewer& v);

// ---- panels.cpp ------------------------------------------------------------------------------

// The panels of this frame, between ImGui::NewFrame() and ImGui::Render().
void panels(Viewer& v);

// ---- automation.cpp --------------------------------------------------------------------------

// Runs commands until one has to wait for an image. False when a command failed.
bool runScript(Viewer& v);

} // namespace sdfcsg::viewer
