// PointSampler: shaders/probe.comp over batches of points, with the scene's values inlined as
// the one-off renders take them.
#include "sdfcsg/points.h"

#include "codegen/scene_buffers.h"
#include "gpu/vk.h"
#include "shared.h"

#include <glm/vec4.hpp>

#include <algorithm>

namespace sdfcsg {

struct PointSampler::Impl {
    Context::Impl& ctx;
    detail::SceneBuffers scene;
    detail::Buffer in, out, staging;
    VkShaderModule module = VK_NULL_HANDLE;
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VkDescriptorSet set = VK_NULL_HANDLE;

    explicit Impl(Context::Impl& c) : ctx(c), scene(c) {}
    ~Impl() {
        for (detail::Buffer* b : {&in, &out, &staging})
            detail::destroyBuffer(ctx, *b);
        vkDestroyPipeline(ctx.device, pipeline, nullptr);
        vkDestroyDescriptorPool(ctx.device, pool, nullptr);
        vkDestroyPipelineLayout(ctx.device, layout, nullptr);
        vkDestroyDescriptorSetLayout(ctx.device, setLayout, nullptr);
        vkDestroyShaderModule(ctx.device, module, nullptr);
    }
};

namespace {

constexpr detail::Binding kBindings[] = {
    {SDFCSG_BINDING_NODES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_PROBE_IN, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_PROBE_OUT, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_FIELD, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
};

} // namespace

PointSampler::PointSampler(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
PointSampler::~PointSampler() = default;

Result<std::unique_ptr<PointSampler>> PointSampler::create(Context& context, const Scene& scene,
                                                           Evaluation evaluation) {
    if (auto ok = checkEvaluation(scene, evaluation); !ok) return ok.error();
    Context::Impl& ctx = detail::contextImpl(context);
    auto impl = std::make_unique<Impl>(ctx);
    CodegenOptions codegen;
    codegen.evaluation = usesTapes(scene, evaluation) ? Evaluation::Tapes : Evaluation::Inlined;
    codegen.inlineParams = true;
    // Bounds skipping on, whatever the device: without it the values away from the surface are
    // other bounds than the CPU evaluator's (the same surface, not the same numbers).
    codegen.boundsTests = true;
    auto spirv = compileKernel("probe.comp", generateSceneGlsl(scene, codegen));
    if (!spirv) return spirv.error();

    const Evaluator evaluator(scene);
    if (auto ok = impl->scene.create(evaluator); !ok) return ok.error();
    auto words = detail::SceneBuffers::fieldWords(scene, evaluator, codegen.evaluation);
    if (!words) return words.error();
    if (auto ok = impl->scene.uploadField(*words); !ok) return ok.error();

    const VkDeviceSize bytes = kBatch * sizeof(glm::vec4);
    auto in = detail::createBuffer(ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                   detail::MemoryUse::Upload);
    if (!in) return in.error();
    impl->in = *in;
    auto out = detail::createBuffer(
        ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
        detail::MemoryUse::Readback);
    if (!out) return out.error();
    impl->out = *out;
    if (!impl->out.data) {
        auto staging = detail::createBuffer(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                            detail::MemoryUse::Staging);
        if (!staging) return staging.error();
        impl->staging = *staging;
    }

    impl->module = detail::createShaderModule(ctx, *spirv);
    impl->setLayout = detail::createDescriptorSetLayout(ctx, kBindings);
    impl->layout = detail::createPipelineLayout(ctx, impl->setLayout, sizeof(uint32_t));
    const detail::SpecConstant spec[] = {{SDFCSG_SPEC_BOUNDS_SKIPPING, 1u}};
    impl->pipeline = detail::createComputePipeline(ctx, impl->module, impl->layout, spec);
    impl->pool = detail::createDescriptorPool(ctx, kBindings);
    impl->set = detail::allocateDescriptorSet(ctx, impl->pool, impl->setLayout);
    const detail::Buffer* buffers[] = {&impl->scene.nodes(), &impl->in, &impl->out,
                                       &impl->scene.field()};
    detail::writeDescriptorSet(ctx, impl->set, kBindings, buffers);
    return std::unique_ptr<PointSampler>(new PointSampler(std::move(impl)));
}

Status PointSampler::sample(std::span<const glm::vec3> points, std::span<float> distances,
                            std::span<glm::vec3> colors) {
    if (distances.size() != points.size() || (!colors.empty() && colors.size() != points.size()))
        return Error::message(ErrorKind::Usage, "<points>",
                              "the distances and colours must be as many as the points");
    Impl& s = *impl_;
    std::vector<glm::vec4> batch;
    for (size_t first = 0; first < points.size(); first += kBatch) {
        const size_t n = std::min(kBatch, points.size() - first);
        batch.resize(n);
        for (size_t i = 0; i < n; ++i)
            batch[i] = glm::vec4(points[first + i], 1.0f);
        detail::uploadBuffer(s.ctx, s.in, batch.data(), n * sizeof(glm::vec4));
        const uint32_t count = uint32_t(n);
        VkCommandBuffer cmd = detail::beginCommands(s.ctx);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, s.pipeline);
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, s.layout, 0, 1, &s.set, 0,
                                nullptr);
        vkCmdPushConstants(cmd, s.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(count), &count);
        vkCmdDispatch(cmd, detail::groupCount(count, SDFCSG_PROBE_GROUP_X), 1, 1);
        detail::recordReadback(cmd, s.out, s.staging.buffer ? &s.staging : nullptr);
        detail::submitAndWait(s.ctx);
        const auto* result = static_cast<const glm::vec4*>(
            detail::readback(s.ctx, s.out, s.staging.buffer ? &s.staging : nullptr));
        for (size_t i = 0; i < n; ++i) {
            distances[first + i] = result[i].w;
            if (!colors.empty()) colors[first + i] = glm::vec3(result[i]);
        }
    }
    return Ok{};
}

} // namespace sdfcsg
