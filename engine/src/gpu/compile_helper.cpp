// The compile helper of lavapipe contexts: see precompileElsewhere() in vk.h.
#include "gpu/vk.h"

#include <algorithm>
#include <chrono>
#include <vector>

namespace sdfcsg::detail {
namespace {

// Uniform blocks are at most this large on every device (Vulkan's minimum limit).
constexpr VkDeviceSize kBindingBytes = 16384;

// Under ctx.helperMutex.
bool haveHelper(Context::Impl& ctx) {
    if (!ctx.helper && !ctx.helperFailed) {
        auto helper = std::make_unique<Context::Impl>();
        if (setUpContext(*helper, ctx.helperOptions, ctx))
            ctx.helper = std::move(helper);
        else
            ctx.helperFailed = true;
    }
    return ctx.helper != nullptr;
}

} // namespace

void makeCompileHelper(Context::Impl& ctx) {
    if (!ctx.helperWanted) return;
    std::unique_lock lock(ctx.helperMutex, std::try_to_lock);
    if (lock) haveHelper(ctx);
}

double precompileElsewhere(Context::Impl& ctx, std::span<const Precompile> pipelines,
                           std::span<const Binding> bindings, uint32_t pushConstantBytes) {
    if (!ctx.helperWanted || pipelines.empty()) return 0.0;
    std::unique_lock lock(ctx.helperMutex, std::try_to_lock);
    if (!lock || !haveHelper(ctx)) return 0.0;
    Context::Impl& h = *ctx.helper;
    // Every binding of the set must point at a buffer, though a dispatch of no workgroups, which
    // makes llvmpipe compile, runs no invocation to read one. Its zeros are what the pipelines'
    // warm-ups on the context's device bind: at a pipeline's first dispatch, lavapipe may inline
    // the values of its uniform blocks into the code, and keeps doing so if that shrank it
    // enough, so the two devices compile the same code only for the same values.
    auto buffer =
        createBuffer(h, kBindingBytes,
                     VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                         VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                     MemoryUse::Device);
    if (!buffer) return 0.0;
    VkCommandBuffer fill = beginCommands(h);
    vkCmdFillBuffer(fill, buffer->buffer, 0, VK_WHOLE_SIZE, 0);
    recordComputeBarrier(fill);
    submitAndWait(h);
    VkDescriptorSetLayout setLayout = createDescriptorSetLayout(h, bindings);
    VkPipelineLayout layout = createPipelineLayout(h, setLayout, pushConstantBytes);
    VkDescriptorPool pool = createDescriptorPool(h, bindings);
    VkDescriptorSet set = allocateDescriptorSet(h, pool, setLayout);
    const std::vector<const Buffer*> buffers(bindings.size(), &*buffer);
    writeDescriptorSet(h, set, bindings, buffers);
    const std::vector<uint8_t> zeros(pushConstantBytes);

    double firstMs = 0.0;
    for (const Precompile& p : pipelines) {
        VkShaderModule module = createShaderModule(h, p.spirv);
        VkPipeline pipeline = createComputePipeline(h, module, layout, p.spec);
        VkCommandBuffer cmd = beginCommands(h);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &set, 0,
                                nullptr);
        if (pushConstantBytes)
            vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, pushConstantBytes,
                               zeros.data());
        vkCmdDispatch(cmd, 0, 0, 0);
        const auto start = std::chrono::steady_clock::now();
        submitAndWait(h);
        const std::chrono::duration<double, std::milli> took =
            std::chrono::steady_clock::now() - start;
        if (&p == pipelines.data()) firstMs = took.count();
        vkDestroyPipeline(h.device, pipeline, nullptr);
        vkDestroyShaderModule(h.device, module, nullptr);
    }

    vkDestroyDescriptorPool(h.device, pool, nullptr);
    vkDestroyPipelineLayout(h.device, layout, nullptr);
    vkDestroyDescriptorSetLayout(h.device, setLayout, nullptr);
    destroyBuffer(h, *buffer);
    ctx.helper.reset(); // the instance's end waits for the disk cache's writes
    ctx.helperCompiles.fetch_add(uint32_t(pipelines.size()), std::memory_order_relaxed);
    return std::max(firstMs, 1e-3);
}

void compileHelperMissed(Context::Impl& ctx) {
    std::lock_guard lock(ctx.helperMutex);
    ctx.helperFailed = true;
    ctx.helper.reset();
}

} // namespace sdfcsg::detail
