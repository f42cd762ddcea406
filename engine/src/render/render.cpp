// The ray march: per band of rows, the clip, march, ends, shade and light passes and, with several
// samples per pixel or overlays, the resolve and overlay passes (shaders/clip.comp, march.comp,
// light.comp, shade.comp and finish.comp, around raymarch.glsl), read back to RGBA8 and
// per-pixel info.
#include "sdfcsg/render.h"

#include "codegen/scene_buffers.h"
#include "codegen/shader_compile.h"
#include "field/bake.h"
#include "field/prune.h"
#include "gpu/vk.h"
#include "render/camera.h"

#include "sdfcsg/compile.h"
#include "sdfcsg/eval.h"

#include "shared.h"

#include <glm/vec4.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

namespace sdfcsg {
namespace {

using detail::Buffer;

struct FrameLight {
    glm::vec4 direction; // towards the light
    glm::vec4 inverse;   // 1 / direction, finite
    glm::vec4 color;
};

// Mirrors the Frame uniform block in shaders/raymarch.glsl (std140: every member is 16 bytes).
struct FrameUniform {
    glm::vec4 eye, right, up, forward;
    glm::vec4 clipMin, clipMax;
    glm::vec4 background, sky;
    glm::vec4 distances; // depth near, depth far, occlusion scale, shadow reach
    FrameLight lights[SDFCSG_MAX_LIGHTS];
    glm::vec4 surfaceBoxes[2 * SDFCSG_MAX_CLIP_BOXES]; // surface parts, as in raymarch.glsl
    glm::vec4 grid;                                    // centre x, z; plane height; spacing
};
static_assert(sizeof(FrameUniform) ==
              10 * 16 + SDFCSG_MAX_LIGHTS * 48 + SDFCSG_MAX_CLIP_BOXES * 32);

// Mirrors the Control buffer in shaders/raymarch.glsl: the values that branches read.
struct FrameControl {
    glm::uvec4 size;   // width, height, mode, flags
    glm::uvec4 counts; // aa, lights, nodes, selected
    glm::uvec4 parts;  // x: surface parts in FrameUniform::surfaceBoxes
};
static_assert(SDFCSG_MAX_LIGHTS == 4, "shade.comp reads the lights into four locals");
static_assert(GroundGrid{}.halfLines == SDFCSG_GRID_HALF_LINES);

constexpr detail::Binding kBindings[] = {
    {SDFCSG_BINDING_FRAME, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
    {SDFCSG_BINDING_NODES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_PIXELS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_INFO, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_SAMPLES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_HITS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_TILES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_CONTROL, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_SURFACES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_RANGES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_FIELD, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
};

// What the renderers of a context share: the layout of the kernels' bindings, and the pipelines
// of the passes that do not evaluate the scene (clip.comp, light.comp, finish.comp), each made
// once per context, at its first use. A new scene compiles only its own kernels.
struct SharedPasses {
    Context::Impl& ctx;
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkShaderModule clip = VK_NULL_HANDLE, light = VK_NULL_HANDLE, finish = VK_NULL_HANDLE;
    // The SPIR-V of clip.comp and light.comp where glslang made it (none was cached): then the
    // driver has most likely not compiled them either, and the compile helper may.
    std::vector<uint32_t> freshClip, freshLight;
    std::mutex mutex; // guards pipelines and warm
    VkPipeline pipelines[SDFCSG_RAYMARCH_PASSES] = {};
    bool warm[SDFCSG_RAYMARCH_PASSES] = {}; // the pipeline has run (Renderer::Impl::warmUp)

    explicit SharedPasses(Context::Impl& c) : ctx(c) {}

    // The pipeline of a pass, created on first use. Under mutex.
    VkPipeline created(uint32_t pass);

    ~SharedPasses() {
        for (VkPipeline p : pipelines)
            if (p) vkDestroyPipeline(ctx.device, p, nullptr);
        for (VkShaderModule m : {clip, light, finish})
            if (m) vkDestroyShaderModule(ctx.device, m, nullptr);
        if (layout) vkDestroyPipelineLayout(ctx.device, layout, nullptr);
        if (setLayout) vkDestroyDescriptorSetLayout(ctx.device, setLayout, nullptr);
    }
};

// Mirrors the Band push constants of shaders/raymarch.glsl.
struct BandConstants {
    uint32_t firstRow;
    uint32_t colorOffset;
};

constexpr uint32_t kGroupSize = SDFCSG_RAYMARCH_GROUP_X * SDFCSG_RAYMARCH_GROUP_Y;
constexpr VkDeviceSize kHitsHeader = 16;   // count, then the shade pass's dispatch
constexpr VkDeviceSize kSurfaceBytes = 64; // per listed hit: four vec4 (raymarch.glsl)
constexpr VkDeviceSize kRangeBytes = 32;   // per sample: two vec4 (raymarch.glsl)

Error usage(std::string text) {
    return Error::message(ErrorKind::Usage, "<render>", std::move(text));
}

// Samples per submission (see Renderer::render).
constexpr uint32_t kBandSamples = 1u << 16;

// Bands of whole workgroup rows, about kBandSamples samples each: a heavy scene or a huge image
// never becomes one long dispatch (GPU drivers reset a device whose work runs for seconds), and
// the caller can follow progress and stop between bands.
struct BandPlan {
    uint64_t pixels = 0;      // of the image
    uint32_t aa = 1;          // samples per pixel along each axis
    uint32_t bandGroups = 0;  // workgroup rows per band
    uint64_t bandSamples = 0; // samples per band
    uint64_t groupsX = 0;     // workgroups along a row of samples
    uint32_t groupsY = 0;     // workgroup rows of pixels in the image
};

// A frame's pipelines, null for the passes it does not run.
struct FramePasses {
    VkPipeline clip = VK_NULL_HANDLE, march = VK_NULL_HANDLE, shade = VK_NULL_HANDLE,
               light = VK_NULL_HANDLE, ends = VK_NULL_HANDLE, resolve = VK_NULL_HANDLE,
               overlay = VK_NULL_HANDLE;
};

// Workgroups whose rays cannot meet a surface are not marched (with `culling`); the band is
// filled with the colour and info of a miss first.
struct MissFill {
    bool culling = false;
    std::vector<detail::ScreenRect> rects; // where rays may meet a surface
    uint32_t color = 0;                    // RGBA8
    uint32_t info = 0;                     // the bits of t = -1
};

Result<std::shared_ptr<SharedPasses>> sharedPasses(Context::Impl& ctx) {
    std::lock_guard lock(ctx.rendererSharedMutex);
    if (ctx.rendererShared) return std::static_pointer_cast<SharedPasses>(ctx.rendererShared);
    auto shared = std::make_shared<SharedPasses>(ctx);
    const char* kernels[] = {"clip.comp", "light.comp", "finish.comp"};
    VkShaderModule* modules[] = {&shared->clip, &shared->light, &shared->finish};
    std::vector<uint32_t>* fresh[] = {&shared->freshClip, &shared->freshLight, nullptr};
    for (int i = 0; i < 3; ++i) {
        bool ranGlslang = false;
        auto spirv = detail::compileKernel(kernels[i], "", ctx.compile, ranGlslang);
        if (!spirv) return spirv.error();
        *modules[i] = detail::createShaderModule(ctx, *spirv);
        if (ranGlslang && fresh[i]) *fresh[i] = std::move(*spirv);
    }
    shared->setLayout = detail::createDescriptorSetLayout(ctx, kBindings);
    shared->layout = detail::createPipelineLayout(ctx, shared->setLayout, sizeof(BandConstants));
    ctx.rendererShared = shared;
    return shared;
}

} // namespace

// Node words (outlines, images) follow the nodes in their buffer: a new size is a new buffer.
static size_t wordCount(const Node& n) {
    return n.words ? n.words->size() : 0;
}

// Whether the code calls node n's colour formula (ownColors).
static bool colored(const Node& n) {
    return ownColors(detail::baked(n) ? NodeKind::Mesh : n.kind, n.words.get());
}

bool sameStructure(const Scene& a, const Scene& b) {
    if (a.nodes.size() != b.nodes.size()) return false;
    for (size_t i = 0; i < a.nodes.size(); ++i)
        if (a.nodes[i].kind != b.nodes[i].kind || a.nodes[i].children != b.nodes[i].children ||
            wordCount(a.nodes[i]) != wordCount(b.nodes[i]) ||
            colored(a.nodes[i]) != colored(b.nodes[i]))
            return false;
    return true;
}

// The options' errors that the caller can fix, if any.
static std::optional<Error> checkRenderOptions(const RenderOptions& options, uint32_t nodeCount) {
    if (options.width == 0 || options.height == 0)
        return usage("the image must be at least 1 x 1 pixels");
    if (options.aa == 0 || options.aa > kMaxAntialiasing)
        return usage("aa must be in 1.." + std::to_string(kMaxAntialiasing));
    if (options.boxes == BoxOverlay::Selected &&
        (options.selectedNode < 0 || uint32_t(options.selectedNode) >= nodeCount))
        return usage("selectedNode " + std::to_string(options.selectedNode) +
                     " is not a node of the scene (it has " + std::to_string(nodeCount) + ")");
    return std::nullopt;
}

struct Renderer::Impl {
    Context::Impl& ctx;
    RendererOptions options;
    Scene scene; // the values last uploaded; structure fixed at creation
    std::unique_ptr<Evaluator> evaluator;
    bool tapes = false; // evaluated from pruned tapes
    bool balls = false; // the tape machine reads spheres as balls (SDFCSG_TAPE_BALLS)
    uint32_t nodeCount = 0;

    std::shared_ptr<SharedPasses> shared;
    VkPipelineLayout pipelineLayout = VK_NULL_HANDLE; // shared->layout
    // The scene's kernels, march.comp and shade.comp, and their pipelines: [pass][bounds
    // skipping]. The generated code differs with skipping (CodegenOptions::boundsTests).
    // buildKernels() makes the default ones, kernels() and pipeline() the others on first use.
    VkShaderModule modules[2][2] = {};
    VkPipeline pipelines[2][2] = {};
    static_assert(SDFCSG_RAYMARCH_PASS_MARCH == 0 && SDFCSG_RAYMARCH_PASS_SHADE == 1);
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VkDescriptorSet set = VK_NULL_HANDLE;

    detail::SceneBuffers sceneBuffers; // the node buffer and the field
    // The image (pixels, info), and per band: the samples' colours (with several per pixel),
    // the workgroups to march and the hits to shade.
    Buffer frame, control, pixels, info, pixelsStaging, infoStaging, samples, hits, tiles, surfaces,
        ranges;
    uint32_t capacity = 0;         // pixels the image buffers hold
    uint32_t sampleCapacity = 0;   // samples the band buffers hold
    uint32_t tileCapacity = 0;     // workgroups the tile list holds
    bool samplesArePixels = false; // what the SAMPLES binding points at
    std::vector<PixelInfo> lastInfo;
    Camera lastCamera;       // of the last render()
    uint32_t lastHeight = 0; // in pixels

    explicit Impl(Context::Impl& c) : ctx(c), sceneBuffers(c) {}
    // No work of this renderer is pending between calls (submitAndWait() waits for it), and the
    // device may be busy with other threads' work: nothing to wait for.
    ~Impl() {
        VkDevice device = ctx.device;
        for (Buffer* b : {&frame, &control, &pixels, &info, &pixelsStaging, &infoStaging, &samples,
                          &hits, &tiles, &surfaces, &ranges})
            detail::destroyBuffer(ctx, *b);
        destroyKernel();
        if (pool) vkDestroyDescriptorPool(device, pool, nullptr);
    }

    // Generates and compiles the scene's kernels, replacing the previous ones, and makes the
    // march and shade pipelines that render() uses by default, ready to run. The two kernels are
    // compiled side by side. On llvmpipe, which makes machine code at a pipeline's first dispatch
    // and one pipeline at a time, a new march kernel is compiled on the context's helper device
    // (precompileElsewhere()) while this device compiles the shade kernel. On failure the
    // previous kernels stay.
    Status buildKernels() {
        const bool skipping = defaultSkipping();
        const std::string glsl = sceneGlsl(skipping);
        // While this device compiles the shade kernel, the other thread makes the march kernel:
        // on llvmpipe, its machine code on the helper device (if it is a new kernel), and this
        // device's pipeline beside that, which at its first dispatch loads the helper's work.
        BuiltKernel march;
        double helperMs = 0.0; // the helper's compile of the march kernel
        std::thread other([&, fresh = freshSharedSpirv()] {
            march = buildMarch(glsl, skipping, fresh, helperMs);
        });
        BuiltKernel shade = buildKernel(compileKernel("shade.comp", glsl, ctx.compile),
                                        SDFCSG_RAYMARCH_PASS_SHADE, skipping);
        if (!shade.error) {
            warmUp(shade.pipeline);
            pipeline(SDFCSG_RAYMARCH_PASS_LIGHT, false); // made once per context
        }
        other.join();
        if (march.error || shade.error) {
            for (BuiltKernel* b : {&march, &shade}) {
                if (b->pipeline) vkDestroyPipeline(ctx.device, b->pipeline, nullptr);
                if (b->module) vkDestroyShaderModule(ctx.device, b->module, nullptr);
            }
            return shade.error ? *shade.error : *march.error;
        }
        destroyKernel();
        modules[SDFCSG_RAYMARCH_PASS_MARCH][skipping ? 1 : 0] = march.module;
        modules[SDFCSG_RAYMARCH_PASS_SHADE][skipping ? 1 : 0] = shade.module;
        pipelines[SDFCSG_RAYMARCH_PASS_MARCH][skipping ? 1 : 0] = march.pipeline;
        pipelines[SDFCSG_RAYMARCH_PASS_SHADE][skipping ? 1 : 0] = shade.pipeline;
        const auto start = std::chrono::steady_clock::now();
        warmUp(march.pipeline);
        const std::chrono::duration<double, std::milli> marchMs =
            std::chrono::steady_clock::now() - start;
        // Loading the helper's machine code takes a few milliseconds, a tenth of its compile or
        // less; compiling it again takes about as long as the helper did.
        if (helperMs > 0.0 && marchMs.count() > 0.25 * helperMs) detail::compileHelperMissed(ctx);
        return Ok{};
    }

    // A kernel's module and its pipeline for a pass, or why it could not be made.
    struct BuiltKernel {
        std::optional<Error> error;
        VkShaderModule module = VK_NULL_HANDLE;
        VkPipeline pipeline = VK_NULL_HANDLE;
    };
    BuiltKernel buildKernel(const Result<std::vector<uint32_t>>& spirv, uint32_t pass,
                            bool skipping) {
        BuiltKernel b;
        if (!spirv) {
            b.error = spirv.error();
            return b;
        }
        b.module = detail::createShaderModule(ctx, *spirv);
        b.pipeline = createPipeline(b.module, pass, skipping);
        return b;
    }

    // In a context's first build the passes that do not depend on the scene are most likely new
    // too: their SPIR-V, where glslang made it and their pipelines are still to make (the clip
    // pass's, then the ends pass's), for the helper to compile after the march kernel.
    std::array<std::vector<uint32_t>, 2> freshSharedSpirv() {
        std::array<std::vector<uint32_t>, 2> fresh;
        std::lock_guard lock(shared->mutex);
        if (!shared->pipelines[SDFCSG_RAYMARCH_PASS_CLIP])
            fresh[0] = std::exchange(shared->freshClip, {});
        if (!shared->pipelines[SDFCSG_RAYMARCH_PASS_ENDS])
            fresh[1] = std::exchange(shared->freshLight, {});
        return fresh;
    }

    // On buildKernels()' other thread: the march kernel, whose machine code (with that of the
    // fresh shared passes) the helper device compiles where it is new (helperMs: how long the
    // march kernel took there), then the shared passes' pipelines. This device compiles the
    // light pass after the shade kernel meanwhile (about as long on either side).
    BuiltKernel buildMarch(const std::string& glsl, bool skipping,
                           const std::array<std::vector<uint32_t>, 2>& fresh, double& helperMs) {
        detail::makeCompileHelper(ctx); // the last build used it up
        bool compiled = false;
        auto spirv = detail::compileKernel("march.comp", glsl, ctx.compile, compiled);
        const auto marchSpec = specConstants(SDFCSG_RAYMARCH_PASS_MARCH, skipping);
        const auto clipSpec = specConstants(SDFCSG_RAYMARCH_PASS_CLIP, false);
        const auto endsSpec = specConstants(SDFCSG_RAYMARCH_PASS_ENDS, false);
        std::vector<detail::Precompile> jobs;
        if (spirv && compiled) jobs.push_back({*spirv, marchSpec});
        if (!fresh[0].empty()) jobs.push_back({fresh[0], clipSpec});
        if (!fresh[1].empty()) jobs.push_back({fresh[1], endsSpec});
        // This device's pipeline translates the kernel (SPIR-V to the driver's IR, a tenth of
        // the compile). Beside the helper's compile of the march kernel alone, which ends
        // before the shade kernel's, that would take the shade kernel's core from it: after
        // it. Beside a first build's longer list, which ends later.
        BuiltKernel march;
        auto translate = [&] { march = buildKernel(spirv, SDFCSG_RAYMARCH_PASS_MARCH, skipping); };
        std::thread beside;
        if (jobs.size() > 1) beside = std::thread(translate);
        const double ms = detail::precompileElsewhere(ctx, jobs, kBindings, sizeof(BandConstants));
        if (spirv && compiled) helperMs = ms;
        if (beside.joinable())
            beside.join();
        else
            translate();
        // The first renderer of a context makes the passes that do not depend on the scene
        // (their machine code, in a first build, from the helper): their translations too,
        // beside the shade kernel's compile. Their warm-ups follow (pipeline()).
        for (uint32_t pass : {SDFCSG_RAYMARCH_PASS_CLIP, SDFCSG_RAYMARCH_PASS_ENDS}) {
            std::lock_guard lock(shared->mutex);
            shared->created(pass);
        }
        return march;
    }

    // The scene's kernels and their pipelines.
    void destroyKernel() {
        for (int pass : {SDFCSG_RAYMARCH_PASS_MARCH, SDFCSG_RAYMARCH_PASS_SHADE})
            for (int skipping : {0, 1}) {
                VkPipeline& p = pipelines[pass][skipping];
                if (p) vkDestroyPipeline(ctx.device, p, nullptr);
                p = VK_NULL_HANDLE;
                VkShaderModule& m = modules[pass][skipping];
                if (m) vkDestroyShaderModule(ctx.device, m, nullptr);
                m = VK_NULL_HANDLE;
            }
    }

    std::string sceneGlsl(bool skipping) const {
        CodegenOptions codegen;
        codegen.inlineParams = options.inlineValues;
        codegen.evaluation = options.evaluation;
        codegen.boundsTests = skipping;
        return generateSceneGlsl(scene, codegen);
    }

    // The scene's kernels for a skipping choice, compiled on first use.
    Status kernels(bool skipping) {
        VkShaderModule* made[] = {&modules[SDFCSG_RAYMARCH_PASS_MARCH][skipping ? 1 : 0],
                                  &modules[SDFCSG_RAYMARCH_PASS_SHADE][skipping ? 1 : 0]};
        if (*made[0] && *made[1]) return Ok{};
        const std::string glsl = sceneGlsl(skipping);
        const char* names[] = {"march.comp", "shade.comp"};
        for (int i = 0; i < 2; ++i) {
            if (*made[i]) continue;
            auto spirv = compileKernel(names[i], glsl, ctx.compile);
            if (!spirv) return spirv.error();
            *made[i] = detail::createShaderModule(ctx, *spirv);
        }
        return Ok{};
    }

    // Whether the tape machine reads the spheres of a scene with these values as balls.
    bool readsBalls(const Evaluator& values) const {
        return tapes && options.inlineValues && detail::allSpheresAreBalls(values.nodes());
    }

    bool defaultSkipping() const {
        return ctx.properties.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU;
    }

    static std::array<detail::SpecConstant, 2> specConstants(uint32_t pass, bool skipping) {
        return {
            {{SDFCSG_SPEC_BOUNDS_SKIPPING, skipping ? 1u : 0u}, {SDFCSG_SPEC_RAYMARCH_PASS, pass}}};
    }

    VkPipeline createPipeline(VkShaderModule module, uint32_t pass, bool skipping) const {
        return detail::createComputePipeline(ctx, module, pipelineLayout,
                                             specConstants(pass, skipping));
    }

    // The pipeline of a pass and skipping choice, created and warmed up on first use.
    VkPipeline pipeline(uint32_t pass, bool skipping) {
        if (pass != SDFCSG_RAYMARCH_PASS_MARCH && pass != SDFCSG_RAYMARCH_PASS_SHADE) {
            std::lock_guard lock(shared->mutex);
            VkPipeline p = shared->created(pass);
            if (!shared->warm[pass]) warmUp(p);
            shared->warm[pass] = true;
            return p;
        }
        VkPipeline& p = pipelines[pass][skipping ? 1 : 0];
        if (!p) {
            p = createPipeline(modules[pass][skipping ? 1 : 0], pass, skipping); // see kernels()
            warmUp(p);
        }
        return p;
    }

    // Some drivers (llvmpipe among them) compile a compute pipeline to machine code only at its
    // first dispatch. An empty dispatch (image size 0 and no hits: every invocation returns at
    // once) moves that cost here, so a created pipeline is ready and the first frame costs what
    // later ones do.
    void warmUp(VkPipeline p) {
        FrameControl empty = {};
        detail::uploadBuffer(ctx, control, &empty, sizeof(empty));
        VkCommandBuffer cmd = detail::beginCommands(ctx);
        vkCmdFillBuffer(cmd, hits.buffer, 0, kHitsHeader, 0);
        detail::recordComputeBarrier(cmd);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p);
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 0, 1, &set, 0,
                                nullptr);
        const BandConstants band = {};
        vkCmdPushConstants(cmd, pipelineLayout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof band, &band);
        vkCmdDispatch(cmd, 1, 1, 1);
        detail::submitAndWait(ctx);
    }

    // The field (SceneBuffers::fieldWords()), and the descriptors when its buffer is new.
    Status uploadField(std::span<const uint32_t> words) {
        auto made = sceneBuffers.uploadField(words);
        if (!made) return made.error();
        if (*made) writeDescriptors();
        return Ok{};
    }

    // Once the image and band buffers exist (create() reserves both).
    void writeDescriptors() {
        if (!pixels.buffer || !samples.buffer) return;
        const Buffer* colors = samplesArePixels ? &pixels : &samples;
        const Buffer* buffers[] = {&frame,
                                   &sceneBuffers.nodes(),
                                   &pixels,
                                   &info,
                                   colors,
                                   &hits,
                                   &tiles,
                                   &control,
                                   &surfaces,
                                   &ranges,
                                   &sceneBuffers.field()};
        detail::writeDescriptorSet(ctx, set, kBindings, buffers);
    }

    // Grows the band buffers to hold `count` samples in `tileCount` workgroups; never shrinks
    // them. On failure the old buffers stay.
    Status reserveSamples(uint32_t count, uint32_t tileCount) {
        if (count <= sampleCapacity && tileCount <= tileCapacity) return Ok{};
        count = std::max(count, sampleCapacity);
        tileCount = std::max(tileCount, tileCapacity);
        constexpr VkBufferUsageFlags kStorage =
            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
        constexpr int kBuffers = 5;
        const VkDeviceSize sizes[kBuffers] = {
            VkDeviceSize(count) * 4, kHitsHeader + VkDeviceSize(count) * 8,
            VkDeviceSize(tileCount) * 4, VkDeviceSize(count) * kSurfaceBytes,
            VkDeviceSize(count) * kRangeBytes};
        const VkBufferUsageFlags usages[kBuffers] = {
            kStorage, kStorage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT,
            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT};
        const detail::MemoryUse uses[kBuffers] = {
            detail::MemoryUse::Device, detail::MemoryUse::Device, detail::MemoryUse::Upload,
            detail::MemoryUse::Device, detail::MemoryUse::Device};
        Buffer made[kBuffers];
        for (int i = 0; i < kBuffers; ++i) {
            auto buffer = detail::createBuffer(ctx, sizes[i], usages[i], uses[i]);
            if (!buffer) {
                for (Buffer& b : made)
                    detail::destroyBuffer(ctx, b);
                return buffer.error();
            }
            made[i] = *buffer;
        }
        Buffer* current[kBuffers] = {&samples, &hits, &tiles, &surfaces, &ranges};
        for (int i = 0; i < kBuffers; ++i) {
            detail::destroyBuffer(ctx, *current[i]);
            *current[i] = made[i];
        }
        sampleCapacity = count;
        tileCapacity = tileCount;
        writeDescriptors();
        return Ok{};
    }

    // Grows the image buffers to hold `count` pixels; never shrinks them. On failure the old
    // buffers stay.
    Status reserve(uint32_t count) {
        if (count <= capacity) return Ok{};
        constexpr VkBufferUsageFlags kOutput = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                               VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                               VK_BUFFER_USAGE_TRANSFER_DST_BIT;
        const VkDeviceSize sizes[] = {VkDeviceSize(count) * 4, VkDeviceSize(count) * 8};
        Buffer made[4]; // pixels, info, and their staging copies when those are not mappable
        auto create = [&](int i, VkDeviceSize size, VkBufferUsageFlags usage,
                          detail::MemoryUse use) -> Status {
            auto buffer = detail::createBuffer(ctx, size, usage, use);
            if (!buffer) {
                for (Buffer& b : made)
                    detail::destroyBuffer(ctx, b);
                return buffer.error();
            }
            made[i] = *buffer;
            return Ok{};
        };
        for (int i = 0; i < 2; ++i)
            if (auto ok = create(i, sizes[i], kOutput, detail::MemoryUse::Readback); !ok) return ok;
        if (!made[0].data || !made[1].data)
            for (int i = 0; i < 2; ++i)
                if (auto ok = create(2 + i, sizes[i], VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                     detail::MemoryUse::Staging);
                    !ok)
                    return ok;
        Buffer* current[] = {&pixels, &info, &pixelsStaging, &infoStaging};
        for (int i = 0; i < 4; ++i) {
            detail::destroyBuffer(ctx, *current[i]);
            *current[i] = made[i];
        }
        capacity = count;
        writeDescriptors();
        return Ok{};
    }

    // The image's bands (see BandPlan), or an error where the device cannot hold them.
    Result<BandPlan> planBands(const RenderOptions& render) const {
        const VkPhysicalDeviceLimits& limits = ctx.properties.limits;
        BandPlan b;
        b.pixels = uint64_t(render.width) * render.height;
        b.aa = render.aa;
        const uint64_t rowGroupSamples =
            uint64_t(render.width) * b.aa * b.aa * SDFCSG_RAYMARCH_GROUP_Y;
        b.bandGroups = uint32_t(std::max<uint64_t>(1, kBandSamples / rowGroupSamples));
        b.bandSamples = rowGroupSamples * b.bandGroups;
        const uint64_t sampleColumns = uint64_t(render.width) * b.aa;
        b.groupsY = detail::groupCount(render.height, SDFCSG_RAYMARCH_GROUP_Y);
        b.groupsX = (sampleColumns + SDFCSG_RAYMARCH_GROUP_X - 1) / SDFCSG_RAYMARCH_GROUP_X;
        if (b.pixels * 8 > limits.maxStorageBufferRange ||
            kHitsHeader + b.bandSamples * 8 > limits.maxStorageBufferRange ||
            b.groupsX > limits.maxComputeWorkGroupCount[0] || b.groupsX > 0xffff ||
            uint64_t(b.bandGroups) * b.aa > 0xffff || // the tile list packs x | y << 16
            uint64_t(b.bandGroups) * b.aa > limits.maxComputeWorkGroupCount[1] ||
            b.bandSamples / kGroupSize > limits.maxComputeWorkGroupCount[0])
            return Error::message(
                ErrorKind::Limit, "<render>",
                "an image of " + std::to_string(render.width) + " x " +
                    std::to_string(render.height) + " pixels" +
                    (b.aa > 1 ? " at aa " + std::to_string(b.aa) : std::string()) +
                    " is too large for " + ctx.properties.deviceName);
        return b;
    }

    // The image and band buffers for `plan`, and where the samples go: with one per pixel, the
    // passes write the image directly and no resolve runs.
    Status reserveFor(const BandPlan& plan) {
        if (auto reserved = reserve(uint32_t(plan.pixels)); !reserved) return reserved;
        if (auto reserved = reserveSamples(uint32_t(plan.bandSamples),
                                           uint32_t(plan.groupsX) * plan.bandGroups * plan.aa);
            !reserved)
            return reserved;
        if (samplesArePixels != (plan.aa == 1)) {
            samplesArePixels = plan.aa == 1;
            writeDescriptors();
        }
        return Ok{};
    }

    // The pipelines of the passes that the render ask for, compiling the scene's kernels for
    // their skipping choice on first use.
    Result<FramePasses> framePasses(const RenderOptions& render) {
        const bool skipping = render.boundsSkipping.value_or(defaultSkipping());
        if (auto made = kernels(skipping); !made) return made.error();
        const bool shading =
            render.mode == RenderMode::Shaded || render.mode == RenderMode::Normals;
        const bool overlays = render.grid || render.boxes != BoxOverlay::None;
        FramePasses p;
        p.clip = pipeline(SDFCSG_RAYMARCH_PASS_CLIP, false);
        p.march = pipeline(SDFCSG_RAYMARCH_PASS_MARCH, skipping);
        if (shading) p.shade = pipeline(SDFCSG_RAYMARCH_PASS_SHADE, skipping);
        if (shading) p.light = pipeline(SDFCSG_RAYMARCH_PASS_LIGHT, false);
        if (shading && render.mode == RenderMode::Shaded && render.shadows)
            p.ends = pipeline(SDFCSG_RAYMARCH_PASS_ENDS, false);
        if (render.aa > 1) p.resolve = pipeline(SDFCSG_RAYMARCH_PASS_RESOLVE, false);
        if (overlays) p.overlay = pipeline(SDFCSG_RAYMARCH_PASS_OVERLAY, false);
        return p;
    }

    // The steps mode colours misses by their steps, so it traces every ray: no culling there.
    MissFill missFill(const RenderOptions& render, const detail::RayCamera& rc,
                      const detail::ClipVolume& clip) const {
        MissFill miss;
        miss.culling = render.mode != RenderMode::Steps &&
                       detail::surfaceRects(rc, clip, render.width, render.height, miss.rects);
        const glm::vec3 c = render.mode == RenderMode::Shaded ? scene.background : glm::vec3(0.0f);
        const glm::uvec3 u(glm::clamp(c, 0.0f, 1.0f) * 255.0f + 0.5f);
        miss.color = u.r | (u.g << 8) | (u.b << 16) | (255u << 24);
        const float missInfo = -1.0f; // the steps word too, read back as 0
        std::memcpy(&miss.info, &missInfo, sizeof miss.info);
        return miss;
    }

    // One submission per band, reporting progress after each; stops when the caller cancels.
    Status renderBands(const RenderOptions& render, const BandPlan& plan, const FramePasses& passes,
                       const MissFill& miss) {
        std::vector<uint32_t> tileList;
        for (uint32_t firstGroup = 0; firstGroup < plan.groupsY; firstGroup += plan.bandGroups) {
            const uint32_t groups = std::min(plan.bandGroups, plan.groupsY - firstGroup);
            listTiles(plan, firstGroup, groups, miss, tileList);
            if (!tileList.empty())
                detail::uploadBuffer(ctx, tiles, tileList.data(),
                                     tileList.size() * sizeof(uint32_t));
            const bool last = firstGroup + groups == plan.groupsY;
            VkCommandBuffer cmd = detail::beginCommands(ctx);
            recordBand(cmd, render, passes, miss, firstGroup, groups, uint32_t(tileList.size()));
            if (last) {
                detail::recordReadback(cmd, pixels, &pixelsStaging);
                detail::recordReadback(cmd, info, &infoStaging);
            }
            detail::submitAndWait(ctx);
            const float done = float(firstGroup + groups) / float(plan.groupsY);
            if (render.progress && !render.progress(done) && !last)
                return Error::message(ErrorKind::Cancelled, "<render>", "cancelled");
        }
        return Ok{};
    }

    // The workgroups of a band (`groups` workgroup rows from `firstGroup`) whose samples may
    // meet a surface, as x | y << 16: all of them without culling.
    void listTiles(const BandPlan& plan, uint32_t firstGroup, uint32_t groups, const MissFill& miss,
                   std::vector<uint32_t>& out) const {
        const uint32_t firstRow = firstGroup * SDFCSG_RAYMARCH_GROUP_Y;
        const uint32_t aa = plan.aa;
        out.clear();
        for (uint32_t ty = 0; ty < groups * aa; ++ty) {
            const float y0 = float(firstRow) + float(ty * SDFCSG_RAYMARCH_GROUP_Y) / float(aa);
            const float y1 = y0 + float(SDFCSG_RAYMARCH_GROUP_Y) / float(aa);
            for (uint32_t tx = 0; tx < plan.groupsX; ++tx) {
                const float x0 = float(tx * SDFCSG_RAYMARCH_GROUP_X) / float(aa);
                const float x1 = x0 + float(SDFCSG_RAYMARCH_GROUP_X) / float(aa);
                bool visible = !miss.culling;
                for (const detail::ScreenRect& q : miss.rects)
                    visible = visible || (x0 < q.x1 && x1 > q.x0 && y0 < q.y1 && y1 > q.y0);
                if (visible) out.push_back(tx | ty << 16);
            }
        }
    }

    // A band's passes: the miss fill, then per listed workgroup the clip and march passes, per
    // listed hit the ends, shade and light passes, and per pixel the resolve and overlay passes.
    void recordBand(VkCommandBuffer cmd, const RenderOptions& render, const FramePasses& passes,
                    const MissFill& miss, uint32_t firstGroup, uint32_t groups,
                    uint32_t tileCount) {
        const uint32_t aa = render.aa;
        const uint32_t firstRow = firstGroup * SDFCSG_RAYMARCH_GROUP_Y;
        const BandConstants band = {firstRow, aa == 1 ? firstRow * render.width : 0u};
        const uint32_t rows = std::min(groups * SDFCSG_RAYMARCH_GROUP_Y, render.height - firstRow);
        if (miss.culling) {
            const VkDeviceSize first = VkDeviceSize(firstRow) * render.width;
            const VkDeviceSize pixelsInBand = VkDeviceSize(rows) * render.width;
            if (aa == 1)
                vkCmdFillBuffer(cmd, pixels.buffer, first * 4, pixelsInBand * 4, miss.color);
            else
                vkCmdFillBuffer(cmd, samples.buffer, 0, pixelsInBand * aa * aa * 4, miss.color);
            vkCmdFillBuffer(cmd, info.buffer, first * 8, pixelsInBand * 8, miss.info);
        }
        vkCmdFillBuffer(cmd, hits.buffer, 0, 8, 0); // count, and the shade dispatch's x
        vkCmdFillBuffer(cmd, hits.buffer, 8, 8, 1); // its y and z
        detail::recordComputeBarrier(cmd);
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 0, 1, &set, 0,
                                nullptr);
        vkCmdPushConstants(cmd, pipelineLayout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof band, &band);
        if (tileCount > 0) { // the listed workgroups' samples
            vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, passes.clip);
            vkCmdDispatch(cmd, tileCount, 1, 1);
            detail::recordComputeBarrier(cmd);
            vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, passes.march);
            vkCmdDispatch(cmd, tileCount, 1, 1);
        }
        for (VkPipeline perHit : {passes.ends, passes.shade, passes.light}) {
            if (!perHit) continue;
            detail::recordComputeBarrier(cmd);
            vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, perHit);
            vkCmdDispatchIndirect(cmd, hits.buffer, 4);
        }
        for (VkPipeline perPixel : {passes.resolve, passes.overlay}) {
            if (!perPixel) continue;
            detail::recordComputeBarrier(cmd);
            vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, perPixel);
            vkCmdDispatch(cmd, detail::groupCount(render.width, SDFCSG_RAYMARCH_GROUP_X), groups,
                          1);
        }
    }

    // The read-back image, and its per-pixel info for lastPixelInfo().
    Image readImage(uint32_t width, uint32_t height) {
        const uint64_t count = uint64_t(width) * height;
        Image image;
        image.width = width;
        image.height = height;
        image.rgba.resize(count * 4);
        std::memcpy(image.rgba.data(), detail::readback(ctx, pixels, &pixelsStaging), count * 4);
        const auto* words = static_cast<const float*>(detail::readback(ctx, info, &infoStaging));
        lastInfo.resize(count);
        for (uint64_t i = 0; i < count; ++i)
            lastInfo[i] =
                PixelInfo{words[2 * i], words[2 * i + 1] > 0.0f ? uint32_t(words[2 * i + 1]) : 0u};
        return image;
    }

    // The frame's values (f) and those that its branches read (fc).
    void frameValues(const RenderOptions& render, const detail::RayCamera& rc,
                     const detail::ClipVolume& clip, FrameUniform& f, FrameControl& fc) const {
        Aabb finite = detail::finitePrimitiveBounds(*evaluator);

        f = {};
        fc = {};
        f.eye = glm::vec4(rc.eye, rc.tanHalfFov);
        f.right = glm::vec4(rc.right, rc.aspect);
        f.up = glm::vec4(rc.up, rc.footprint);
        f.forward = glm::vec4(rc.forward, detail::kMinHitEpsilon);
        f.clipMin = glm::vec4(clip.box.min, clip.far);
        // Supersampling resolves detail finer than a pixel: the hit epsilon follows the sample.
        f.clipMax = glm::vec4(clip.box.max, rc.footprint / float(std::max(render.aa, 1u)));
        fc.parts.x = uint32_t(clip.parts.size());
        for (size_t i = 0; i < clip.parts.size(); ++i) {
            const detail::SurfacePart& part = clip.parts[i];
            f.surfaceBoxes[2 * i] =
                part.halfSpace ? glm::vec4(part.normal, 1.0f) : glm::vec4(part.box.min, 0.0f);
            f.surfaceBoxes[2 * i + 1] = part.halfSpace ? glm::vec4(part.offset, 0.0f, 0.0f, 0.0f)
                                                       : glm::vec4(part.box.max, 0.0f);
        }
        f.background = glm::vec4(scene.background, 0.0f);
        f.sky = glm::vec4(scene.background * scene.background, 0.0f); // gamma 2, as the kernel
        const float size = std::max(glm::length(finite.max - finite.min), 1e-3f);
        float nearest = finite.distance(rc.eye), farthest = 0.0f;
        for (int c = 0; c < 8; ++c) {
            glm::vec3 corner((c & 1) ? finite.max.x : finite.min.x,
                             (c & 2) ? finite.max.y : finite.min.y,
                             (c & 4) ? finite.max.z : finite.min.z);
            farthest = std::max(farthest, glm::length(corner - rc.eye));
        }
        f.distances = glm::vec4(nearest, farthest, 0.2f * size, size);

        uint32_t flags = 0;
        if (render.shadows) flags |= SDFCSG_FLAG_SHADOWS;
        if (render.ambientOcclusion) flags |= SDFCSG_FLAG_AO;
        if (render.boxes == BoxOverlay::All) flags |= SDFCSG_FLAG_BOXES_ALL;
        if (render.boxes == BoxOverlay::Selected) flags |= SDFCSG_FLAG_BOXES_SELECTED;
        if (render.grid) {
            flags |= SDFCSG_FLAG_GRID;
            const GroundGrid g = groundGrid(*evaluator);
            f.grid = glm::vec4(g.centreX, g.centreZ, g.height, g.spacing);
        }
        fc.size = glm::uvec4(render.width, render.height, uint32_t(render.mode), flags);

        std::vector<Light> lights = scene.lights.empty() ? defaultLights() : scene.lights;
        uint32_t lightCount = uint32_t(std::min<size_t>(lights.size(), SDFCSG_MAX_LIGHTS));
        for (uint32_t i = 0; i < lightCount; ++i) {
            glm::vec3 l = -glm::normalize(lights[i].direction);
            f.lights[i].direction = glm::vec4(l, 0.0f);
            for (int c = 0; c < 3; ++c) // as safeInverse() in the kernel
                f.lights[i].inverse[c] =
                    1.0f / (std::abs(l[c]) < 1e-20f ? (l[c] >= 0.0f ? 1e-20f : -1e-20f) : l[c]);
            f.lights[i].color = glm::vec4(lights[i].color * lights[i].intensity, 0.0f);
        }
        uint32_t selected = render.selectedNode >= 0 ? uint32_t(render.selectedNode) : nodeCount;
        fc.counts = glm::uvec4(render.aa, lightCount, nodeCount, selected);
    }
};

GroundGrid groundGrid(const Evaluator& evaluator) {
    const Aabb box = detail::finiteSceneBounds(evaluator);
    const float width = std::max(box.max.x - box.min.x, box.max.z - box.min.z);
    GroundGrid g;
    g.spacing = std::pow(10.0f, std::floor(std::log10(std::max(width, 1e-3f) / 2.0f)));
    g.centreX = std::round(0.5f * (box.min.x + box.max.x) / g.spacing) * g.spacing;
    g.centreZ = std::round(0.5f * (box.min.z + box.max.z) / g.spacing) * g.spacing;
    g.height = box.min.y;
    return g;
}

std::optional<RenderMode> parseRenderMode(std::string_view name) {
    if (name == "shaded") return RenderMode::Shaded;
    if (name == "normals") return RenderMode::Normals;
    if (name == "depth") return RenderMode::Depth;
    if (name == "steps") return RenderMode::Steps;
    return std::nullopt;
}

Renderer::Renderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Renderer::~Renderer() = default;

VkPipeline SharedPasses::created(uint32_t pass) {
    VkPipeline& p = pipelines[pass];
    if (p) return p;
    const bool perHit = pass == SDFCSG_RAYMARCH_PASS_ENDS || pass == SDFCSG_RAYMARCH_PASS_LIGHT;
    VkShaderModule module = pass == SDFCSG_RAYMARCH_PASS_CLIP ? clip : perHit ? light : finish;
    p = detail::createComputePipeline(ctx, module, layout,
                                      Renderer::Impl::specConstants(pass, false));
    return p;
}

Result<std::unique_ptr<Renderer>> Renderer::create(Context& context, const Scene& scene,
                                                   const RendererOptions& options) {
    if (scene.nodes.empty()) return usage("the scene has no nodes");
    if (auto fits = checkEvaluation(scene, options.evaluation); !fits) return fits.error();
    auto impl = std::make_unique<Impl>(detail::contextImpl(context));
    Impl& r = *impl;
    r.options = options;
    r.scene = scene;
    r.evaluator = std::make_unique<Evaluator>(scene);
    r.tapes = usesTapes(scene, options.evaluation);
    r.balls = r.readsBalls(*r.evaluator);
    r.nodeCount = uint32_t(scene.nodes.size());
    // Pruned on the host while the kernels build (with tapes, they are the same for every
    // scene): on the forest benchmark scene, most of the prune's time.
    auto fieldWords = std::async(std::launch::async, [&] {
        return detail::SceneBuffers::fieldWords(scene, *r.evaluator, options.evaluation);
    });

    auto shared = sharedPasses(r.ctx);
    if (!shared) return shared.error();
    r.shared = *shared;
    r.pipelineLayout = r.shared->layout;
    r.pool = detail::createDescriptorPool(r.ctx, kBindings);
    r.set = detail::allocateDescriptorSet(r.ctx, r.pool, r.shared->setLayout);

    auto frame = detail::createBuffer(
        r.ctx, sizeof(FrameUniform), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, detail::MemoryUse::Upload);
    if (!frame) return frame.error();
    r.frame = *frame;
    auto control = detail::createBuffer(
        r.ctx, sizeof(FrameControl), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, detail::MemoryUse::Upload);
    if (!control) return control.error();
    r.control = *control;
    if (auto made = r.sceneBuffers.create(*r.evaluator); !made) return made.error();
    if (auto reserved = r.reserve(64 * 64); !reserved) return reserved.error();
    if (auto reserved = r.reserveSamples(64 * 64, 64); !reserved) return reserved.error();
    if (auto built = r.buildKernels(); !built) return built.error();
    // The passes around the march and shade passes run in every shaded frame (the first
    // renderer of the context makes them; buildKernels() has made the light pass, and on
    // lavapipe compiled the others on the helper).
    r.pipeline(SDFCSG_RAYMARCH_PASS_CLIP, false);
    r.pipeline(SDFCSG_RAYMARCH_PASS_ENDS, false);
    r.pipeline(SDFCSG_RAYMARCH_PASS_LIGHT, false);
    auto words = fieldWords.get();
    if (!words) return words.error();
    if (auto uploaded = r.uploadField(*words); !uploaded) return uploaded.error();
    return std::unique_ptr<Renderer>(new Renderer(std::move(impl)));
}

Status Renderer::updateValues(const Scene& scene) {
    if (!sameStructure(impl_->scene, scene))
        return usage("updateValues: the scene's structure (node kinds or children) differs from "
                     "the compiled one; create a new Renderer instead");
    Impl& r = *impl_;
    auto evaluator = std::make_unique<Evaluator>(scene);
    auto words = detail::SceneBuffers::fieldWords(scene, *evaluator, r.options.evaluation);
    if (!words) return words.error();
    const bool balls = r.readsBalls(*evaluator);
    Scene previous = std::move(r.scene);
    r.scene = scene;
    if (r.options.inlineValues && (!r.tapes || balls != r.balls)) {
        if (auto built = r.buildKernels(); !built) {
            r.scene = std::move(previous);
            return built.error();
        }
        r.balls = balls;
    }
    r.evaluator = std::move(evaluator);
    // No render is in flight: render() waits for its fence.
    r.sceneBuffers.uploadNodes(*r.evaluator);
    return r.uploadField(*words);
}

bool Renderer::uploads(const Scene& scene) const {
    const Impl& r = *impl_;
    if (!sameStructure(r.scene, scene)) return false;
    if (!r.options.inlineValues) return true;
    return r.tapes && r.readsBalls(Evaluator(scene)) == r.balls;
}

bool Renderer::followsValues() const {
    return impl_->options.inlineValues && (!impl_->tapes || impl_->balls);
}

Result<Image> Renderer::render(const RenderOptions& options) {
    Impl& r = *impl_;
    if (auto bad = checkRenderOptions(options, r.nodeCount)) return *bad;
    auto plan = r.planBands(options);
    if (!plan) return plan.error();
    if (auto reserved = r.reserveFor(*plan); !reserved) return reserved.error();
    const float aspect = float(options.width) / float(options.height);
    const Camera camera = options.camera   ? *options.camera
                          : r.scene.camera ? *r.scene.camera
                                           : frameCamera(*r.evaluator, aspect);
    r.lastCamera = camera, r.lastHeight = options.height;
    auto passes = r.framePasses(options);
    if (!passes) return passes.error();
    const detail::RayCamera rc = detail::makeRayCamera(camera, options.width, options.height);
    const detail::ClipVolume clip = detail::makeClipVolume(*r.evaluator, rc.eye);
    FrameUniform f;
    FrameControl control;
    r.frameValues(options, rc, clip, f, control);
    detail::uploadBuffer(r.ctx, r.frame, &f, sizeof(f));
    detail::uploadBuffer(r.ctx, r.control, &control, sizeof(control));
    const MissFill miss = r.missFill(options, rc, clip);
    if (auto marched = r.renderBands(options, *plan, *passes, miss); !marched)
        return marched.error();
    return r.readImage(options.width, options.height);
}

const std::vector<PixelInfo>& Renderer::lastPixelInfo() const {
    return impl_->lastInfo;
}

std::optional<std::string> Renderer::nothingShown() const {
    const Impl& r = *impl_;
    return whyNothingShows(*r.evaluator, r.lastCamera, r.lastHeight, r.lastInfo);
}

std::optional<std::string> whyNothingShows(const Evaluator& evaluator, const Camera& camera,
                                           uint32_t height, const std::vector<PixelInfo>& pixels) {
    const Aabb box = evaluator.finiteBounds();
    auto largest = [](glm::vec3 v) {
        return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    };
    const float reach = std::max(largest(box.min), largest(box.max));
    char text[160];
    // Past this, squared distances overflow single precision.
    constexpr float kLargest = 1e18f;
    if (!(reach < kLargest) || !(largest(camera.eye) < kLargest)) {
        std::snprintf(text, sizeof text,
                      "the solid is too large for single precision: its bounds reach %.3g", reach);
        return text;
    }
    auto all = [&](auto&& holds) { return std::all_of(pixels.begin(), pixels.end(), holds); };
    if (pixels.empty()) return std::nullopt;
    if (all([](PixelInfo i) { return i.depth == 0.0f; })) return "the camera is inside the solid";
    if (!all([](PixelInfo i) { return i.depth < 0.0f; })) return std::nullopt;
    if (provablyEmpty(evaluator))
        return "the solid is empty: no point of its bounds lies inside it";
    const float size = glm::length(box.max - box.min);
    const float away = glm::length(0.5f * (box.min + box.max) - camera.eye);
    const float pixel = 2.0f * away * std::tan(0.5f * glm::radians(camera.fov)) / float(height);
    if (size < pixel || size < 2.0f * kMinHitEpsilon) {
        std::snprintf(text, sizeof text,
                      "the solid is smaller than a pixel: at most %.3g units across, seen from "
                      "%.3g units away",
                      size, away);
        return text;
    }
    return "the solid lies outside the view";
}

} // namespace sdfcsg
