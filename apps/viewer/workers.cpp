#include "workers.h"

#include "edit.h"
#include "picking.h"

#include <sdfcsg/compile.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace sdfcsg::viewer {

namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

} // namespace

Result<std::unique_ptr<Renderer>> createRenderer(Context& context, const Scene& scene,
                                                 const RendererOptions& options) {
    return Renderer::create(context, scene, options);
}

RendererBuilder::RendererBuilder(Context& context, RendererOptions options, RendererFactory create)
    : context_(context), options_(options), create_(std::move(create)) {
    thread_ = std::thread([this] { run(); });
}

RendererBuilder::~RendererBuilder() {
    {
        std::lock_guard lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
}

void RendererBuilder::request(std::shared_ptr<const Scene> scene, uint64_t version) {
    {
        std::lock_guard lock(mutex_);
        if (wanted_ && wantedVersion_ == version) return; // asked for already
        wanted_ = std::move(scene);
        wantedVersion_ = version;
        waiting_ = true;
    }
    wake_.notify_all();
}

std::optional<RendererBuilder::Built> RendererBuilder::take() {
    std::lock_guard lock(mutex_);
    std::optional<Built> out = std::move(done_);
    done_.reset();
    // The newest request is answered once its build is taken; an older build leaves it waiting.
    if (out && !waiting_ && !running_ && out->version == wantedVersion_) wanted_.reset();
    return out;
}

bool RendererBuilder::pending(uint64_t version) const {
    std::lock_guard lock(mutex_);
    if (!wanted_ || wantedVersion_ != version) return false;
    // A build that failed is nothing to wait for.
    return !(done_ && done_->version == version && !done_->renderer && !waiting_);
}

bool RendererBuilder::ready(uint64_t version) const {
    std::lock_guard lock(mutex_);
    return done_ && done_->version == version && bool(done_->renderer);
}

bool RendererBuilder::pendingStructure(const Scene& scene) const {
    std::lock_guard lock(mutex_);
    return wanted_ && sameStructure(*wanted_, scene);
}

bool RendererBuilder::busy() const {
    std::lock_guard lock(mutex_);
    return waiting_ || running_;
}

bool RendererBuilder::building() const {
    std::lock_guard lock(mutex_);
    return running_;
}

void RendererBuilder::run() {
    for (;;) {
        std::shared_ptr<const Scene> scene;
        uint64_t version = 0;
        {
            std::unique_lock lock(mutex_);
            wake_.wait(lock, [&] { return stop_ || waiting_; });
            if (stop_) return;
            scene = wanted_;
            version = wantedVersion_;
            waiting_ = false;
            running_ = true;
        }
        auto built = create_(context_, *scene, options_);
        std::lock_guard lock(mutex_);
        done_.emplace(Built{std::move(scene), version, std::move(built)});
        running_ = false;
    }
}

namespace {

bool sameView(const RenderOptions& a, const RenderOptions& b) {
    const Camera ca = a.camera.value_or(Camera{}), cb = b.camera.value_or(Camera{});
    return a.width == b.width && a.height == b.height && a.mode == b.mode &&
           a.camera.has_value() == b.camera.has_value() && ca.eye == cb.eye &&
           ca.target == cb.target && ca.up == cb.up && ca.fov == cb.fov && a.aa == b.aa &&
           a.shadows == b.shadows && a.ambientOcclusion == b.ambientOcclusion &&
           a.boundsSkipping == b.boundsSkipping && a.boxes == b.boxes &&
           (a.boxes != BoxOverlay::Selected || a.selectedNode == b.selectedNode);
}

} // namespace

RenderWorker::RenderWorker(Context& context, Context* liveContext, RendererFactory create)
    : context_(context), create_(create) {
    RendererOptions live;
    live.inlineValues = false;
    liveBuilder_ =
        std::make_unique<RendererBuilder>(liveContext ? *liveContext : context, live, create);
    bakeBuilder_ = std::make_unique<RendererBuilder>(context, RendererOptions{}, create);
    thread_ = std::thread([this] { run(); });
}

RenderWorker::~RenderWorker() {
    {
        std::lock_guard lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
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
    return !liveBuilder_->busy();
}

bool RenderWorker::refinementPending(uint64_t version) const {
    return bakeBuilder_->pending(version);
}

bool RenderWorker::refinementReady(uint64_t version) const {
    return bakeBuilder_->ready(version);
}

bool RenderWorker::compiling() const {
    return compilingHere_ || liveBuilder_->building() || bakeBuilder_->building();
}

// Takes finished builds that fit the job: a live renderer that takes its values as an upload
// (one built for a structure edited away meanwhile is dropped), a baked one for its values.
void RenderWorker::adoptBuilds(const RenderJob& job) {
    if (auto built = liveBuilder_->take();
        built && built->renderer && (*built->renderer)->uploads(*job.scene)) {
        // The frame on hand stays where the baked renderer drew it: a live one arriving between
        // two jobs of the same scene does not redraw it.
        if (drawn_ && drawn_->renderer == live_.get()) drawn_.reset();
        live_ = std::move(*built->renderer);
        liveVersion_ = built->version; // it holds that version's values
    }
    if (auto built = bakeBuilder_->take();
        built && built->renderer && built->version == job.sceneVersion) {
        baked_ = std::move(*built->renderer);
        bakedScene_ = built->scene;
        bakedVersion_ = built->version;
        drawn_.reset();
    }
}

RenderOutput RenderWorker::process(const RenderJob& job) {
    RenderOutput out;
    out.id = job.id;
    adoptBuilds(job);
    if (live_ && !live_->uploads(*job.scene)) live_.reset(), drawn_.reset();
    const bool tapes = usesTapes(*job.scene, Evaluation::Auto);
    if (tapes) updateBaked(job, out);
    Renderer* renderer = nullptr;
    if (baked_ && bakedVersion_ == job.sceneVersion)
        renderer = baked_.get();
    else if (live_ && !bakeSooner(job, tapes))
        renderer = updateLive(job, out);
    else if (failedVersion_ != job.sceneVersion) // a scene that failed waits for a change
        renderer = compileBaked(job, out);
    out.error = failure_;
    // A scene that does not compile leaves the last one that did on screen.
    if (!renderer) renderer = baked_.get();
    if (renderer) draw(job, *renderer, out);
    return out;
}

// A still frame is drawn live unless recompiling and drawing baked is expected to be sooner: on
// lavapipe a small scene's inlined kernel compiles in a fraction of a second and draws several
// times faster, so at full resolution the live frame can come later. Until the live renderer
// has drawn, its speed is guessed from the baked one's (on lavapipe the house's live frame took
// 6 times as long; a scene evaluated from pruned tapes reads its values from buffers either
// way).
bool RenderWorker::bakeSooner(const RenderJob& job, bool tapes) const {
    const double pixels = double(job.options.width) * double(job.options.height);
    const double guess = context_.cpuDevice() ? (tapes ? 1.5 : 6.0) : 1.0;
    const double liveRate = liveRate_ > 0 ? liveRate_ : bakedRate_ * guess;
    return !job.preview && bakedRate_ > 0 && bakeSeconds_ + bakedRate_ * pixels < liveRate * pixels;
}

// A scene evaluated from pruned tapes reads every value from buffers, so its baked renderer
// takes value edits itself, previews and still frames alike, but for one that its kernel follows
// (a sphere scaled differently per axis, or no longer, where it reads spheres as balls): the live
// renderer draws that one, once built, and the bake follows as a refinement.
void RenderWorker::updateBaked(const RenderJob& job, RenderOutput& out) {
    if (!baked_ || bakedVersion_ == job.sceneVersion) return;
    const bool uploads = baked_->uploads(*job.scene);
    if (!sameStructure(*bakedScene_, *job.scene) || !(uploads || !live_)) return;
    auto start = std::chrono::steady_clock::now();
    compilingHere_ = !uploads;
    auto updated = baked_->updateValues(*job.scene);
    compilingHere_ = false;
    if (!uploads) out.compileSeconds = secondsSince(start);
    if (updated) {
        bakedScene_ = job.scene;
        bakedVersion_ = job.sceneVersion;
        drawn_.reset();
        failure_.reset();
    } else {
        failure_ = updated.error();
    }
}

// The live renderer with the job's values, or null where they do not upload.
Renderer* RenderWorker::updateLive(const RenderJob& job, RenderOutput& out) {
    if (liveVersion_ != job.sceneVersion) {
        drawn_.reset();
        if (auto updated = live_->updateValues(*job.scene); updated)
            liveVersion_ = job.sceneVersion;
        else
            failure_ = updated.error();
    }
    if (liveVersion_ != job.sceneVersion) return nullptr;
    out.live = true;
    failure_.reset();
    // The edit shows now; its baked kernel follows, for the caller to swap in.
    if (!job.preview) bakeBuilder_->request(job.scene, job.sceneVersion);
    return live_.get();
}

// A new baked renderer for the job's scene, compiled here; null where it fails.
Renderer* RenderWorker::compileBaked(const RenderJob& job, RenderOutput& out) {
    auto start = std::chrono::steady_clock::now();
    compilingHere_ = true;
    auto created = create_(context_, *job.scene, RendererOptions{});
    compilingHere_ = false;
    out.compileSeconds = secondsSince(start);
    if (!created) {
        failedVersion_ = job.sceneVersion;
        failure_ = created.error();
        return nullptr;
    }
    bakeSeconds_ = out.compileSeconds;
    baked_ = std::move(*created);
    bakedScene_ = job.scene;
    bakedVersion_ = job.sceneVersion;
    drawn_.reset();
    failedVersion_.reset();
    failure_.reset();
    // A structure on screen: its live renderer is built now, so that the first value edit is
    // already an upload.
    if (baked_->followsValues() && !live_ && !liveBuilder_->pendingStructure(*job.scene))
        liveBuilder_->request(job.scene, job.sceneVersion);
    return baked_.get();
}

// The frame, drawn by `renderer` unless only its highlight changed, then the highlight.
void RenderWorker::draw(const RenderJob& job, Renderer& renderer, RenderOutput& out) {
    out.scene = out.live ? job.scene : bakedScene_;
    out.options = job.options;
    if (out.options.selectedNode >= int(out.scene->nodes.size())) out.options.selectedNode = -1;
    const uint64_t version = out.live ? liveVersion_ : bakedVersion_;
    if (drawn_ && drawn_->renderer == &renderer && drawn_->version == version &&
        sameView(drawn_->options, out.options)) {
        out.image = drawn_->image; // only the highlight changed
        out.pixels = drawn_->pixels;
    } else {
        const double pixels = double(job.options.width) * double(job.options.height);
        auto start = std::chrono::steady_clock::now();
        auto image = renderer.render(out.options);
        out.renderSeconds = secondsSince(start);
        (out.live ? liveRate_ : bakedRate_) = out.renderSeconds / pixels;
        if (!image) {
            out.error = image.error();
            drawn_.reset();
            return;
        }
        out.image = std::move(*image);
        out.pixels = renderer.lastPixelInfo();
        drawn_ = Drawn{&renderer, version, out.options, out.image, out.pixels};
    }
    if (!job.preview) highlight(out, job.highlight);
}

void RenderWorker::highlight(RenderOutput& out, int node) {
    if (node < 0 || node >= int(out.scene->nodes.size()) || !out.options.camera) return;
    if (evaluatorScene_ != out.scene) {
        evaluator_ = std::make_unique<Evaluator>(*out.scene);
        evaluatorScene_ = out.scene;
    }
    auto mask = selectionMask(*evaluator_, uint32_t(node), *out.options.camera, out.image.width,
                              out.image.height, out.pixels);
    drawHighlight(out.image, mask);
}

bool MeshWorker::start(std::shared_ptr<const Scene> scene, MeshOptions options, float simplify) {
    if (job_.running()) return false;
    progress_ = 0.0f;
    return job_.start([this, scene = std::move(scene), options = std::move(options), simplify] {
        Result<ExtractedMesh> out = extract(*scene, options, simplify);
        if (job_.cancelled() && out)
            out = Error::message(ErrorKind::Cancelled, "<mesh>", "cancelled");
        return out;
    });
}

// On the job's thread.
Result<ExtractedMesh> MeshWorker::extract(const Scene& scene, MeshOptions options, float simplify) {
    auto going = [this](float) { return !job_.cancelled(); };
    options.progress = [this](float done) {
        progress_ = done;
        return !job_.cancelled();
    };
    MeshStats stats;
    Result<ExtractedMesh> out = [&]() -> Result<ExtractedMesh> {
        auto mesher = Mesher::create(context_, scene);
        if (!mesher) return mesher.error();
        auto mesh = (*mesher)->extract(options, &stats);
        if (!mesh) return mesh.error();
        ExtractedMesh extracted{std::move(*mesh), std::nullopt};
        const Evaluator& evaluator = (*mesher)->evaluator();
        if (simplify > 0.0f && !job_.cancelled()) {
            SimplifyOptions fewer;
            fewer.maxError = simplify * stats.voxelSize;
            fewer.progress = going;
            auto simplified = simplifyMesh(extracted.mesh, evaluator, fewer, &stats);
            if (!simplified) return simplified.error();
            extracted.mesh = std::move(*simplified);
        }
        extracted.report = reportMesh(extracted.mesh, evaluator, defaultMinWall());
        if (extracted.mesh.vertexCount() <= kWallColouredVertices && !job_.cancelled())
            extracted.walls = wallThickness(extracted.mesh, evaluator);
        if (extracted.mesh.triangleCount() <= previewThreshold_ || job_.cancelled())
            return extracted;
        SimplifyOptions preview;
        preview.targetTriangles = previewThreshold_;
        preview.progress = going;
        if (auto copy = simplifyMesh(extracted.mesh, evaluator, preview); copy) {
            extracted.preview = std::move(*copy);
            if (!extracted.walls.empty())
                extracted.previewWalls = wallThickness(*extracted.preview, evaluator);
        }
        return extracted;
    }();
    // Before the result is handed over, so that its taker reads these stats.
    std::lock_guard lock(mutex_);
    stats_ = stats;
    return out;
}

MeshStats MeshWorker::stats() const {
    std::lock_guard lock(mutex_);
    return stats_;
}

bool ExportWorker::start(std::shared_ptr<const Mesh> mesh, std::filesystem::path path,
                         MeshFormat format, LengthUnit unit) {
    return job_.start([mesh = std::move(mesh), path = std::move(path), format, unit] {
        return writeMesh(*mesh, path, format, unit);
    });
}

bool GenerateWorker::start(std::string request, std::string currentScene, GenerateOptions options) {
    if (job_.running()) return false;
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
    options.cancelled = [this] { return job_.cancelled(); };
    return job_.start([this, request = std::move(request), options = std::move(options)] {
        GenerateStats stats;
        Result<Generated> generated = generateScene(request, options, &stats);
        std::lock_guard lock(mutex_); // before the result is handed over, as in MeshWorker
        stats_ = stats;
        return generated;
    });
}

GenerateStatus GenerateWorker::status() const {
    std::lock_guard lock(mutex_);
    return {message_, secondsSince(start_)};
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
