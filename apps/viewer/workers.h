// Background threads for the slow engine calls, so the window keeps answering: one renders
// (compiling when the structure changes), one extracts meshes, one asks a language model for a
// scene. The first two share the viewer's Context, whose queue submissions take turns
// (context.h).
#pragma once

#include <sdfcsg/context.h>
#include <sdfcsg/generate.h>
#include <sdfcsg/mesh.h>
#include <sdfcsg/render.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace sdfcsg::viewer {

struct RenderJob {
    std::shared_ptr<const Scene> scene;
    uint64_t sceneVersion = 0; // a new version with the same structure is only an upload
    RenderOptions options;     // camera set by the caller
    uint64_t id = 0;
};

struct RenderOutput {
    uint64_t id = 0;
    Image image; // empty when nothing could be rendered
    std::vector<PixelInfo> pixels;
    RenderOptions options;
    std::shared_ptr<const Scene> scene; // the scene the image shows (the last that compiled)
    double renderSeconds = 0.0;
    double compileSeconds = 0.0; // 0 when no compile was needed
    std::optional<Error> error;  // the job's scene failed to compile (or the render failed)
};

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

  private:
    void run();
    RenderOutput process(const RenderJob& job);

    Context& context_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::optional<RenderJob> pending_;
    std::optional<RenderOutput> done_;
    bool busy_ = false, stop_ = false;
    // Used by the worker thread only.
    std::unique_ptr<Renderer> renderer_;
    std::shared_ptr<const Scene> compiled_;
    uint64_t compiledVersion_ = 0;
    std::optional<uint64_t> failedVersion_;
    std::optional<Error> failure_;
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
