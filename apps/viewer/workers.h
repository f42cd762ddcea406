// Background threads for the slow engine calls, so the window keeps answering: one renders
// (compiling when the scene changes), one extracts meshes, one writes them to files, one asks a
// language model for a scene. The first two share the viewer's Context, whose queue submissions take turns
// (context.h).
#pragma once

#include <sdfcsg/context.h>
#include <sdfcsg/export.h>
#include <sdfcsg/generate.h>
#include <sdfcsg/mesh.h>
#include <sdfcsg/render.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
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
};

struct RenderOutput {
    uint64_t id = 0;
    Image image; // empty when nothing could be rendered
    std::vector<PixelInfo> pixels;
    RenderOptions options;
    std::shared_ptr<const Scene> scene; // the scene the image shows (the last that compiled)
    double renderSeconds = 0.0;
    double compileSeconds = 0.0; // 0 when no compile was needed
    bool live = false; // drawn by the live renderer: new values uploaded, not compiled
    std::optional<Error> error;  // the job's scene failed to compile (or the render failed)
};

// Frames come from a renderer with the values inlined ("baked"): on CPU drivers its kernel
// compiles many times faster and runs several times faster than one that reads them from the
// node buffer. A new version of the values is baked again, except for previews once the "live"
// renderer is there: it reads the values from the node buffer, so a value edit is an upload, not
// a recompile. It is built on a thread of its own after the first value edit of a structure,
// since its compile takes seconds on lavapipe; until then previews of edits bake too.
class RenderWorker {
  public:
    explicit RenderWorker(Context& context);
    ~RenderWorker();
    RenderWorker(const RenderWorker&) = delete;
    RenderWorker& operator=(const RenderWorker&) = delete;

    // Replaces any job that has not started: only the newest request matters.
    void submit(RenderJob job);
    // The result of the latest finished job, once.
    std::optional<RenderOutput> take();
    // No job waiting or running.
    bool idle() const;
    // The live renderer's build, started by a value edit, has finished (or none is running).
    bool liveBuildDone() const;

  private:
    void run();
    RenderOutput process(const RenderJob& job);
    void startLiveBuild(std::shared_ptr<const Scene> scene);
    void takeLiveBuild(const Scene& wanted);

    Context& context_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::optional<RenderJob> pending_;
    std::optional<RenderOutput> done_;
    bool busy_ = false, stop_ = false;
    // Used by the worker thread only.
    std::unique_ptr<Renderer> baked_;
    std::shared_ptr<const Scene> bakedScene_;
    uint64_t bakedVersion_ = 0;
    std::unique_ptr<Renderer> live_;
    std::shared_ptr<const Scene> liveScene_; // the structure it was built for
    uint64_t liveVersion_ = 0;               // the values it holds
    std::optional<uint64_t> failedVersion_;
    std::optional<Error> failure_;
    // The live renderer's build: the worker starts and takes it; liveDone_ tells the others.
    std::thread liveThread_;
    std::shared_ptr<const Scene> liveBuildScene_;
    std::optional<Result<std::unique_ptr<Renderer>>> liveBuilt_; // under mutex_
    std::atomic<bool> liveDone_{true};
    std::thread thread_;
};

class MeshWorker {
  public:
    explicit MeshWorker(Context& context) : context_(context) {}
    ~MeshWorker();

    // Starts an extraction unless one is running (false then).
    bool start(std::shared_ptr<const Scene> scene, MeshOptions options);
    void cancel() { cancel_ = true; }
    bool running() const { return running_; }
    float progress() const { return progress_; }
    // The finished extraction, once (an Error when it failed or was cancelled).
    std::optional<Result<Mesh>> take();
    MeshStats stats() const;

  private:
    Context& context_;
    std::thread thread_;
    std::atomic<bool> running_{false}, cancel_{false};
    std::atomic<float> progress_{0.0f};
    mutable std::mutex mutex_;
    std::optional<Result<Mesh>> done_;
    MeshStats stats_;
};

// writeMesh() on a thread: encoding and writing a fine mesh takes a second or more (an OBJ of
// 2.3 million triangles about 1.2 s). The file is written atomically, as writeMesh() does.
class ExportWorker {
  public:
    ExportWorker() = default;
    ~ExportWorker(); // waits for a write in progress
    ExportWorker(const ExportWorker&) = delete;
    ExportWorker& operator=(const ExportWorker&) = delete;

    // Starts writing unless a write is running (false then). The mesh is shared, not copied: it
    // stays alive while the write needs it, even when the caller replaces its own.
    bool start(std::shared_ptr<const Mesh> mesh, std::filesystem::path path, MeshFormat format);
    bool running() const { return running_; }
    // The finished write's outcome, once.
    std::optional<Status> take();

  private:
    std::thread thread_;
    std::atomic<bool> running_{false};
    mutable std::mutex mutex_;
    std::optional<Status> done_;
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
    GenerateWorker() = default;
    ~GenerateWorker(); // cancels a running generation and waits for it (about a second)
    GenerateWorker(const GenerateWorker&) = delete;
    GenerateWorker& operator=(const GenerateWorker&) = delete;

    // Starts generating unless a generation is running (false then). A non-empty currentScene
    // (a scene's JSON) asks for that scene changed as `request` says. The worker sets
    // options.progress and options.cancelled itself.
    bool start(std::string request, std::string currentScene, GenerateOptions options);
    // The generation stops within about a second; take() then gives ErrorKind::Cancelled.
    void cancel() { cancel_ = true; }
    bool running() const { return running_; }
    GenerateStatus status() const;
    // The finished generation, once (an Error when it failed or was cancelled).
    std::optional<Result<Generated>> take();
    GenerateStats stats() const; // of the last finished generation

  private:
    std::thread thread_;
    std::atomic<bool> running_{false}, cancel_{false};
    mutable std::mutex mutex_;
    std::string message_;
    std::chrono::steady_clock::time_point start_;
    std::optional<Result<Generated>> done_;
    GenerateStats stats_;
};

// Internal resolution while the camera moves: the fraction of the full size along each axis
// that brings the frame time near `target` seconds, given how long `lastPixels` pixels took.
// Between 1/8 and 1.
float previewScale(double lastSeconds, uint64_t lastPixels, uint64_t fullPixels, double target);

} // namespace sdfcsg::viewer
