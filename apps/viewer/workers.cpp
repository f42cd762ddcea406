#include "workers.h"

#include "edit.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace sdfcsg::viewer {

namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

} // namespace

RenderWorker::RenderWorker(Context& context) : context_(context) {
    thread_ = std::thread([this] { run(); });
}

RenderWorker::~RenderWorker() {
    {
        std::lock_guard lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
    if (liveThread_.joinable()) liveThread_.join(); // a compile cannot be interrupted
}

void RenderWorker::submit(RenderJob job) {
    {
        std::lock_guard lock(mutex_);
        pending_ = std::move(job);
    }
    wake_.notify_all();
}

std::optional<RenderOutput> RenderWorker::take() {
    std::lock_guard lock(mutex_);
    auto out = std::move(done_);
    done_.reset();
    return out;
}

bool RenderWorker::idle() const {
    std::lock_guard lock(mutex_);
    return !pending_ && !busy_;
}

void RenderWorker::run() {
    for (;;) {
        RenderJob job;
        {
            std::unique_lock lock(mutex_);
            wake_.wait(lock, [&] { return stop_ || pending_; });
            if (stop_) return;
            job = std::move(*pending_);
            pending_.reset();
            busy_ = true;
        }
        RenderOutput out = process(job);
        std::lock_guard lock(mutex_);
        done_ = std::move(out);
        busy_ = false;
    }
}

bool RenderWorker::liveBuildDone() const {
    return liveDone_;
}

void RenderWorker::startLiveBuild(std::shared_ptr<const Scene> scene) {
    if (!liveDone_ || live_) return;
    if (liveThread_.joinable()) liveThread_.join();
    liveBuildScene_ = scene;
    liveDone_ = false;
    liveThread_ = std::thread([this, scene = std::move(scene)] {
        RendererOptions options;
        options.inlineValues = false;
        auto built = Renderer::create(context_, *scene, options);
        std::lock_guard lock(mutex_);
        liveBuilt_ = std::move(built);
        liveDone_ = true;
    });
}

// Adopts a finished live build when it fits the wanted structure (one built for a structure
// that was edited away meanwhile is dropped).
void RenderWorker::takeLiveBuild(const Scene& wanted) {
    std::optional<Result<std::unique_ptr<Renderer>>> built;
    {
        std::lock_guard lock(mutex_);
        built.swap(liveBuilt_);
    }
    if (!built || !*built || !sameStructure(*liveBuildScene_, wanted)) return;
    live_ = std::move(**built);
    liveScene_ = liveBuildScene_;
    liveVersion_ = ~0ull; // it holds the build's values; its first use uploads the wanted ones
}

RenderOutput RenderWorker::process(const RenderJob& job) {
    RenderOutput out;
    out.id = job.id;
    takeLiveBuild(*job.scene);
    if (live_ && !sameStructure(*liveScene_, *job.scene)) live_.reset();

    Renderer* renderer = nullptr;
    if (baked_ && bakedVersion_ == job.sceneVersion) {
        renderer = baked_.get();
    } else if (job.preview && live_) {
        if (liveVersion_ != job.sceneVersion) {
            if (auto updated = live_->updateValues(*job.scene); updated)
                liveVersion_ = job.sceneVersion;
            else
                failure_ = updated.error();
        }
        if (liveVersion_ == job.sceneVersion) {
            renderer = live_.get();
            out.live = true;
            failure_.reset();
        }
    } else if (failedVersion_ != job.sceneVersion) { // a scene that failed waits for a change
        const bool valueEdit = baked_ && sameStructure(*bakedScene_, *job.scene);
        auto start = std::chrono::steady_clock::now();
        auto created = Renderer::create(context_, *job.scene);
        out.compileSeconds = secondsSince(start);
        if (created) {
            baked_ = std::move(*created);
            bakedScene_ = job.scene;
            bakedVersion_ = job.sceneVersion;
            failedVersion_.reset();
            failure_.reset();
            renderer = baked_.get();
            if (valueEdit && job.preview) startLiveBuild(job.scene); // a value is being dragged
        } else {
            failedVersion_ = job.sceneVersion;
            failure_ = created.error();
        }
    }
    out.error = failure_;
    // A scene that does not compile leaves the last one that did on screen.
    if (!renderer) renderer = baked_.get();
    if (!renderer) return out;
    out.scene = out.live ? job.scene : bakedScene_;
    out.options = job.options;
    if (out.options.selectedNode >= int(out.scene->nodes.size())) out.options.selectedNode = -1;
    auto start = std::chrono::steady_clock::now();
    auto image = renderer->render(out.options);
    out.renderSeconds = secondsSince(start);
    if (!image) {
        out.error = image.error();
        return out;
    }
    out.image = std::move(*image);
    out.pixels = renderer->lastPixelInfo();
    return out;
}

MeshWorker::~MeshWorker() {
    cancel_ = true;
    if (thread_.joinable()) thread_.join();
}

bool MeshWorker::start(std::shared_ptr<const Scene> scene, MeshOptions options) {
    if (running_) return false;
    if (thread_.joinable()) thread_.join();
    running_ = true;
    cancel_ = false;
    progress_ = 0.0f;
    thread_ = std::thread([this, scene = std::move(scene), options = std::move(options)]() mutable {
        options.progress = [this](float done) {
            progress_ = done;
            return !cancel_.load();
        };
        MeshStats stats;
        Result<Mesh> mesh = extractMesh(context_, *scene, options, &stats);
        {
            std::lock_guard lock(mutex_);
            done_ = std::move(mesh);
            stats_ = stats;
        }
        running_ = false;
    });
    return true;
}

std::optional<Result<Mesh>> MeshWorker::take() {
    std::lock_guard lock(mutex_);
    auto out = std::move(done_);
    done_.reset();
    return out;
}

MeshStats MeshWorker::stats() const {
    std::lock_guard lock(mutex_);
    return stats_;
}

ExportWorker::~ExportWorker() {
    if (thread_.joinable()) thread_.join();
}

bool ExportWorker::start(std::shared_ptr<const Mesh> mesh, std::filesystem::path path,
                         MeshFormat format) {
    if (running_) return false;
    if (thread_.joinable()) thread_.join();
    running_ = true;
    thread_ = std::thread([this, mesh = std::move(mesh), path = std::move(path), format] {
        Status written = writeMesh(*mesh, path, format);
        {
            std::lock_guard lock(mutex_);
            done_ = std::move(written);
        }
        running_ = false;
    });
    return true;
}

std::optional<Status> ExportWorker::take() {
    std::lock_guard lock(mutex_);
    auto out = std::move(done_);
    done_.reset();
    return out;
}

GenerateWorker::~GenerateWorker() {
    cancel_ = true;
    if (thread_.joinable()) thread_.join();
}

bool GenerateWorker::start(std::string request, std::string currentScene, GenerateOptions options) {
    if (running_) return false;
    if (thread_.joinable()) thread_.join();
    running_ = true;
    cancel_ = false;
    {
        std::lock_guard lock(mutex_);
        message_.clear();
        start_ = std::chrono::steady_clock::now();
    }
    options.currentScene = std::move(currentScene);
    options.progress = [this](const GenerateProgress& p) {
        if (p.waiting) return; // the seconds are counted in status()
        std::lock_guard lock(mutex_);
        message_ = p.message;
    };
    options.cancelled = [this] { return cancel_.load(); };
    thread_ = std::thread([this, request = std::move(request), options = std::move(options)] {
        GenerateStats stats;
        Result<Generated> generated = generateScene(request, options, &stats);
        {
            std::lock_guard lock(mutex_);
            done_ = std::move(generated);
            stats_ = stats;
        }
        running_ = false;
    });
    return true;
}

GenerateStatus GenerateWorker::status() const {
    std::lock_guard lock(mutex_);
    return {message_, secondsSince(start_)};
}

std::optional<Result<Generated>> GenerateWorker::take() {
    std::lock_guard lock(mutex_);
    auto out = std::move(done_);
    done_.reset();
    return out;
}

GenerateStats GenerateWorker::stats() const {
    std::lock_guard lock(mutex_);
    return stats_;
}

float previewScale(double lastSeconds, uint64_t lastPixels, uint64_t fullPixels, double target) {
    if (lastSeconds <= 0.0 || lastPixels == 0 || fullPixels == 0) return 0.5f;
    double perPixel = lastSeconds / double(lastPixels);
    double pixels = target / perPixel;
    double scale = std::sqrt(pixels / double(fullPixels));
    return float(std::clamp(scale, 0.125, 1.0));
}

} // namespace sdfcsg::viewer
