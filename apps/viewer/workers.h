// Background threads for the slow engine calls, so the window keeps answering: one renders
// (compiling when the scene changes), two build renderers beside it, one extracts meshes, one
// writes them to files, one asks a language model for a scene. All but the live renderer share
// the viewer's Context, whose queue submissions take turns (context.h).
#pragma once

#include <sdfcsg/context.h>
#include <sdfcsg/eval.h>
#include <sdfcsg/export.h>
#include <sdfcsg/generate.h>
#include <sdfcsg/mesh.h>
#include <sdfcsg/mesh_report.h>
#include <sdfcsg/render.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace sdfcsg::viewer {

struct RenderJob {
    std::shared_ptr<const Scene> scene;
    uint64_t sceneVersion = 0; // a new version with the same structure is only new values
    RenderOptions options;     // camera set by the caller
    uint64_t id = 0;
    bool preview = false; // a frame while the camera or a value moves: speed over exactness
    int highlight = -1;   // a node whose visible surface full-resolution frames tint and outline
};

struct RenderOutput {
    uint64_t id = 0;
    Image image; // empty when nothing could be rendered
    std::vector<PixelInfo> pixels;
    RenderOptions options;
    std::shared_ptr<const Scene> scene; // the scene the image shows (the last that compiled)
    double renderSeconds = 0.0;
    double compileSeconds = 0.0; // 0 when no compile was needed
    bool live = false;           // drawn by the live renderer: new values uploaded, not compiled
    std::optional<Error> error;  // the job's scene failed to compile (or the render failed)
};

// Builds renderers on a thread of its own, one at a time, for the newest scene asked for: a
// request made while a build runs waits for it, replacing any older waiting request.
// How the workers build renderers: Renderer::create, or in tests one that fails as a shader
// compile can.
using RendererFactory = std::function<Result<std::unique_ptr<Renderer>>(Context&, const Scene&,
                                                                        const RendererOptions&)>;
Result<std::unique_ptr<Renderer>> createRenderer(Context& context, const Scene& scene,
                                                 const RendererOptions& options);

class RendererBuilder {
  public:
    struct Built {
        std::shared_ptr<const Scene> scene;
        uint64_t version = 0;
        Result<std::unique_ptr<Renderer>> renderer;
    };
    // `context` must outlive the builder.
    RendererBuilder(Context& context, RendererOptions options,
                    RendererFactory create = createRenderer);
    ~RendererBuilder(); // waits for a running build: a compile cannot be interrupted
    RendererBuilder(const RendererBuilder&) = delete;
    RendererBuilder& operator=(const RendererBuilder&) = delete;

    void request(std::shared_ptr<const Scene> scene, uint64_t version);
    // The latest finished build, once.
    std::optional<Built> take();
    // The newest request is for `version` and has not been taken: waiting, running, or built
    // (successfully, for ready()).
    bool pending(uint64_t version) const;
    bool ready(uint64_t version) const;
    // The newest request is for this structure (any version) and has not been taken.
    bool pendingStructure(const Scene& scene) const;
    bool busy() const;     // a request waits or is being built
    bool building() const; // a compile is running

  private:
    void run();

    Context& context_;
    RendererOptions options_;
    RendererFactory create_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::shared_ptr<const Scene> wanted_; // the newest request, until taken
    uint64_t wantedVersion_ = 0;
    bool waiting_ = false, running_ = false, stop_ = false;
    std::optional<Built> done_;
    std::thread thread_;
};

// Frames come from a renderer with the values inlined ("baked"): on CPU drivers its kernel
// compiles many times faster and runs several times faster than one that reads them from the
// node buffer. Beside it, once a structure is on screen, the "live" renderer is built in the
// background: it reads the values from the node buffer, so a value edit is an upload, not a
// recompile. Its compile takes seconds on lavapipe, so it runs on a Context of its own (another
// device and queue), where it stalls no baked frame; the live renderer draws there too.
//
// Once it exists, a value edit is drawn by it at once (previews, and still frames unless a
// recompile has been measured to show them sooner), and a still frame drawn live has its values
// baked again by a second builder in the background: a refinement (faster to draw, and the
// same pixels as `sdfcsg render`) that the caller asks for once refinementReady(), never a wait
// before the edit shows.
//
// A scene evaluated from pruned tapes reads its values from buffers, so the baked renderer takes
// its value edits, but where its kernel reads every sphere as a ball (Renderer::followsValues):
// then a live renderer, which reads spheres through their transforms, is built beside it and
// draws the edit that scales a sphere differently per axis, or no longer.
class RenderWorker {
  public:
    // The live renderer is built and draws on `liveContext` (null: on `context`). Both must
    // outlive the worker.
    explicit RenderWorker(Context& context, Context* liveContext = nullptr,
                          RendererFactory create = createRenderer);
    ~RenderWorker(); // waits for running compiles (see compiling())
    RenderWorker(const RenderWorker&) = delete;
    RenderWorker& operator=(const RenderWorker&) = delete;

    // Replaces any job that has not started: only the newest request matters.
    void submit(RenderJob job);
    // The result of the latest finished job, once.
    std::optional<RenderOutput> take();
    // No job waiting or running.
    bool idle() const;
    // The live renderer for the newest job's structure is built (or its build failed): no
    // build of it is waiting or running.
    bool liveBuildDone() const;
    // A baked renderer for values `version`, drawn live so far, is being built / is built and
    // waits for a job of that version to use it.
    bool refinementPending(uint64_t version) const;
    bool refinementReady(uint64_t version) const;
    // A compile is running on some thread, so destroying the worker would wait for it.
    bool compiling() const;

  private:
    void run();
    // process()'s steps, in order.
    RenderOutput process(const RenderJob& job);
    void adoptBuilds(const RenderJob& job);
    void updateBaked(const RenderJob& job, RenderOutput& out);
    bool bakeSooner(const RenderJob& job, bool tapes) const;
    Renderer* updateLive(const RenderJob& job, RenderOutput& out);
    Renderer* compileBaked(const RenderJob& job, RenderOutput& out);
    void draw(const RenderJob& job, Renderer& renderer, RenderOutput& out);
    void highlight(RenderOutput& out, int node);

    Context& context_;
    RendererFactory create_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::optional<RenderJob> pending_;
    std::optional<RenderOutput> done_;
    bool busy_ = false, stop_ = false;
    std::atomic<bool> compilingHere_{false};
    // Used by the worker thread only.
    std::unique_ptr<Renderer> baked_;
    std::shared_ptr<const Scene> bakedScene_;
    uint64_t bakedVersion_ = 0;
    std::unique_ptr<Renderer> live_;
    uint64_t liveVersion_ = 0; // the values it holds
    std::optional<uint64_t> failedVersion_;
    std::optional<Error> failure_;
    // Measured: seconds per pixel of the last live and baked frames, and of the last compile.
    double liveRate_ = 0, bakedRate_ = 0, bakeSeconds_ = 0;
    // The last frame before its highlight, so a new selection only redraws the highlight.
    struct Drawn {
        const Renderer* renderer = nullptr;
        uint64_t version = 0;
        RenderOptions options;
        Image image;
        std::vector<PixelInfo> pixels;
    };
    std::optional<Drawn> drawn_;
    std::shared_ptr<const Scene> evaluatorScene_;
    std::unique_ptr<Evaluator> evaluator_; // of evaluatorScene_, for highlights
    // Declared last, so they stop before the renderers above are destroyed.
    std::unique_ptr<RendererBuilder> liveBuilder_, bakeBuilder_;
    std::thread thread_;
};

// One job at a time on a thread of its own, its result handed over once: what the mesh, export
// and generation workers share. A worker holds one as its last member, so that the job, which may
// use the worker's other members, has stopped before they are destroyed.
template <class T> class BackgroundJob {
  public:
    BackgroundJob() = default;
    ~BackgroundJob() { // cancels a running job and waits for it
        cancel_ = true;
        if (thread_.joinable()) thread_.join();
    }
    BackgroundJob(const BackgroundJob&) = delete;
    BackgroundJob& operator=(const BackgroundJob&) = delete;

    // Starts job() on the thread unless a job is running (false then); what it returns is kept
    // for take().
    template <class Job> bool start(Job job) {
        if (running_) return false;
        if (thread_.joinable()) thread_.join();
        running_ = true;
        cancel_ = false;
        thread_ = std::thread([this, job = std::move(job)]() mutable {
            T result = job();
            {
                std::lock_guard lock(mutex_);
                done_ = std::move(result);
            }
            running_ = false;
        });
        return true;
    }
    // Asks the job to stop; a job that polls cancelled() does so soon, others finish.
    void cancel() { cancel_ = true; }
    bool cancelled() const { return cancel_; }
    bool running() const { return running_; }
    // The finished job's result, once.
    std::optional<T> take() {
        std::lock_guard lock(mutex_);
        std::optional<T> out = std::move(done_);
        done_.reset();
        return out;
    }

  private:
    std::thread thread_;
    std::atomic<bool> running_{false}, cancel_{false};
    std::mutex mutex_;
    std::optional<T> done_;
};

// An extraction as the mesh view shows it: the mesh asked for (simplified, when asked) and, when
// that one is too large to redraw at interactive rates, a simplified copy to draw while the
// camera moves.
struct ExtractedMesh {
    Mesh mesh;
    std::optional<Mesh> preview;
    // Of the mesh, with its printability at the default least wall (0.8 mm, one scene unit a
    // centimetre); the self-intersection search takes about 2 s per million triangles.
    MeshReport report;
    // The wall under each vertex of the mesh and of the preview (wallThickness), for meshes of
    // up to kWallColouredVertices vertices; empty for larger ones.
    std::vector<float> walls, previewWalls;
};
inline constexpr size_t kWallColouredVertices = 300000;

// Meshes with more triangles than this get a preview of at most this many: lavapipe redraws
// about 15 million triangles a second (2.9 million in 200 ms), so a larger mesh takes over
// 20 ms a frame.
inline constexpr size_t kPreviewMeshTriangles = 300000;

class MeshWorker {
  public:
    // Meshes of more than `previewThreshold` triangles get a preview.
    explicit MeshWorker(Context& context, size_t previewThreshold = kPreviewMeshTriangles)
        : context_(context), previewThreshold_(previewThreshold) {}

    // Starts an extraction unless one is running (false then). With `simplify` > 0 the mesh is
    // simplified to within that many cells of the surface (simplifyMesh). A large mesh is then
    // followed by its preview, a copy simplified to kPreviewMeshTriangles (or the threshold
    // given), before the result is handed over: no second extraction, and the preview keeps the
    // mesh's outline and colours.
    bool start(std::shared_ptr<const Scene> scene, MeshOptions options, float simplify = 0.0f);
    void cancel() { job_.cancel(); }
    bool running() const { return job_.running(); }
    float progress() const { return progress_; }
    // The finished extraction, once (an Error when it failed or was cancelled; a preview that
    // fails or is cancelled is only left out).
    std::optional<Result<ExtractedMesh>> take() { return job_.take(); }
    MeshStats stats() const; // of the mesh (and its simplification), not of its preview

  private:
    Result<ExtractedMesh> extract(const Scene& scene, MeshOptions options, float simplify);

    Context& context_;
    size_t previewThreshold_;
    std::atomic<float> progress_{0.0f};
    mutable std::mutex mutex_; // guards stats_
    MeshStats stats_;
    BackgroundJob<Result<ExtractedMesh>> job_; // last: see BackgroundJob
};

// writeMesh() on a thread: encoding and writing a fine mesh takes a second or more (an OBJ of
// 2.3 million triangles about 1.2 s). The file is written atomically, as writeMesh() does.
class ExportWorker {
  public:
    // Starts writing unless a write is running (false then). The mesh is shared, not copied: it
    // stays alive while the write needs it, even when the caller replaces its own.
    bool start(std::shared_ptr<const Mesh> mesh, std::filesystem::path path, MeshFormat format,
               LengthUnit unit = LengthUnit::Millimeter);
    bool running() const { return job_.running(); }
    // The finished write's outcome, once.
    std::optional<Status> take() { return job_.take(); }

  private:
    BackgroundJob<Status> job_; // its destructor waits for a write in progress
};

// What a running generation is doing, for the panel.
struct GenerateStatus {
    std::string message; // the latest GenerateProgress message
    double seconds = 0;  // since start()
};

// generateScene() on a thread, so the window never waits for the network. The result is only
// handed over: applying it to the document is the caller's choice.
class GenerateWorker {
  public:
    // Starts generating unless a generation is running (false then). A non-empty currentScene
    // (a scene's JSON) asks for that scene changed as `request` says. The worker sets
    // options.progress and options.cancelled itself.
    bool start(std::string request, std::string currentScene, GenerateOptions options);
    // The generation stops within about a second; take() then gives ErrorKind::Cancelled.
    void cancel() { job_.cancel(); }
    bool running() const { return job_.running(); }
    GenerateStatus status() const;
    // The finished generation, once (an Error when it failed or was cancelled).
    std::optional<Result<Generated>> take() { return job_.take(); }
    GenerateStats stats() const; // of the last finished generation

  private:
    mutable std::mutex mutex_; // guards the three below
    std::string message_;
    std::chrono::steady_clock::time_point start_;
    GenerateStats stats_;
    // Last: destroying the worker cancels a running generation and waits for it (about a
    // second).
    BackgroundJob<Result<Generated>> job_;
};

// Internal resolution while the camera moves: the fraction of the full size along each axis
// that brings the frame time near `target` seconds, given how long `lastPixels` pixels took.
// Between 1/8 and 1.
float previewScale(double lastSeconds, uint64_t lastPixels, uint64_t fullPixels, double target);

} // namespace sdfcsg::viewer
