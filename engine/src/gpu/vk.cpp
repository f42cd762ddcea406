#include "gpu/vk.h"

#include <cstdio>
#include <vector>

namespace sdfcsg::detail {

namespace {

Error outOfMemory(VkDeviceSize size, VkResult result) {
    char text[160];
    std::snprintf(text, sizeof(text), "cannot allocate a %.1f MiB buffer (%s)",
                  double(size) / (1024.0 * 1024.0), vk::resultName(result));
    return Error::message(ErrorKind::Limit, "<vulkan>", text);
}

} // namespace

Result<Buffer> createBuffer(Context::Impl& ctx, VkDeviceSize size, VkBufferUsageFlags usage,
                            MemoryUse use) {
    Buffer buffer;
    VkResult result = vk::createBuffer(ctx.device, ctx.memoryProperties, size, usage, use, buffer);
    if (result != VK_SUCCESS) return outOfMemory(size, result);
    return buffer;
}

VkDescriptorSetLayout createDescriptorSetLayout(Context::Impl& ctx,
                                                std::span<const Binding> bindings) {
    std::vector<VkDescriptorSetLayoutBinding> list(bindings.size());
    for (uint32_t i = 0; i < list.size(); ++i) {
        list[i].binding = bindings[i].binding;
        list[i].descriptorType = bindings[i].type;
        list[i].descriptorCount = 1;
        list[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    VkDescriptorSetLayoutCreateInfo info = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    info.bindingCount = uint32_t(list.size());
    info.pBindings = list.data();
    VkDescriptorSetLayout layout = VK_NULL_HANDLE;
    VK_CHECK(vkCreateDescriptorSetLayout(ctx.device, &info, nullptr, &layout));
    return layout;
}

VkPipelineLayout createPipelineLayout(Context::Impl& ctx, VkDescriptorSetLayout setLayout,
                                      uint32_t pushConstantBytes) {
    VkPushConstantRange range = {VK_SHADER_STAGE_COMPUTE_BIT, 0, pushConstantBytes};
    VkPipelineLayoutCreateInfo info = {VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    info.setLayoutCount = 1;
    info.pSetLayouts = &setLayout;
    info.pushConstantRangeCount = pushConstantBytes ? 1 : 0;
    info.pPushConstantRanges = &range;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VK_CHECK(vkCreatePipelineLayout(ctx.device, &info, nullptr, &layout));
    return layout;
}

VkPipeline createComputePipeline(Context::Impl& ctx, VkShaderModule module, VkPipelineLayout layout,
                                 std::span<const SpecConstant> spec) {
    std::vector<VkSpecializationMapEntry> entries(spec.size());
    for (uint32_t i = 0; i < entries.size(); ++i)
        entries[i] = {spec[i].id,
                      uint32_t(i * sizeof(SpecConstant) + offsetof(SpecConstant, value)),
                      sizeof(uint32_t)};
    VkSpecializationInfo specialization = {};
    specialization.mapEntryCount = uint32_t(entries.size());
    specialization.pMapEntries = entries.data();
    specialization.dataSize = spec.size_bytes();
    specialization.pData = spec.data();

    VkComputePipelineCreateInfo info = {VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = module;
    info.stage.pName = "main";
    info.stage.pSpecializationInfo = spec.empty() ? nullptr : &specialization;
    info.layout = layout;
    VkPipeline pipeline = VK_NULL_HANDLE;
    VK_CHECK(vkCreateComputePipelines(ctx.device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline));
    return pipeline;
}

VkDescriptorPool createDescriptorPool(Context::Impl& ctx, std::span<const Binding> bindings) {
    std::vector<VkDescriptorPoolSize> sizes;
    for (const Binding& b : bindings) {
        bool found = false;
        for (VkDescriptorPoolSize& s : sizes)
            if (s.type == b.type) ++s.descriptorCount, found = true;
        if (!found) sizes.push_back({b.type, 1});
    }
    VkDescriptorPoolCreateInfo info = {VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    info.maxSets = 1;
    info.poolSizeCount = uint32_t(sizes.size());
    info.pPoolSizes = sizes.data();
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VK_CHECK(vkCreateDescriptorPool(ctx.device, &info, nullptr, &pool));
    return pool;
}

VkDescriptorSet allocateDescriptorSet(Context::Impl& ctx, VkDescriptorPool pool,
                                      VkDescriptorSetLayout layout) {
    VkDescriptorSetAllocateInfo info = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    info.descriptorPool = pool;
    info.descriptorSetCount = 1;
    info.pSetLayouts = &layout;
    VkDescriptorSet set = VK_NULL_HANDLE;
    VK_CHECK(vkAllocateDescriptorSets(ctx.device, &info, &set));
    return set;
}

void writeDescriptorSet(Context::Impl& ctx, VkDescriptorSet set, std::span<const Binding> bindings,
                        std::span<const Buffer* const> buffers) {
    std::vector<VkDescriptorBufferInfo> infos(bindings.size());
    std::vector<VkWriteDescriptorSet> writes(bindings.size());
    for (uint32_t i = 0; i < bindings.size(); ++i) {
        infos[i] = {buffers[i]->buffer, 0, VK_WHOLE_SIZE};
        writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        writes[i].dstSet = set;
        writes[i].dstBinding = bindings[i].binding;
        writes[i].descriptorCount = 1;
        writes[i].descriptorType = bindings[i].type;
        writes[i].pBufferInfo = &infos[i];
    }
    vkUpdateDescriptorSets(ctx.device, uint32_t(writes.size()), writes.data(), 0, nullptr);
}

VkCommandBuffer beginCommands(Context::Impl& ctx) {
    ctx.submitMutex.lock(); // until submitAndWait(), in this thread
    VK_CHECK(vkResetCommandPool(ctx.device, ctx.commandPool, 0));
    vk::beginCommands(ctx.commandBuffer);
    return ctx.commandBuffer;
}

void submitAndWait(Context::Impl& ctx) {
    vk::submitAndWait(ctx.device, ctx.queue, ctx.commandBuffer, ctx.fence);
    ctx.submitMutex.unlock();
}

void recordComputeBarrier(VkCommandBuffer cmd) {
    VkMemoryBarrier barrier = {VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                            VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
                         0, 1, &barrier, 0, nullptr, 0, nullptr);
}

void recordReadback(VkCommandBuffer cmd, const Buffer& buffer, const Buffer* staging) {
    // Written by shaders or by fills (vkCmdFillBuffer).
    constexpr VkPipelineStageFlags kWriters =
        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
    VkMemoryBarrier barrier = {VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    if (buffer.data) {
        barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
        vkCmdPipelineBarrier(cmd, kWriters, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0, nullptr,
                             0, nullptr);
        return;
    }
    barrier.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    vkCmdPipelineBarrier(cmd, kWriters, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &barrier, 0, nullptr,
                         0, nullptr);
    VkBufferCopy region = {0, 0, buffer.size};
    vkCmdCopyBuffer(cmd, buffer.buffer, staging->buffer, 1, &region);
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                         &barrier, 0, nullptr, 0, nullptr);
}

const void* readback(Context::Impl& ctx, const Buffer& buffer, const Buffer* staging) {
    const Buffer& source = buffer.data ? buffer : *staging;
    invalidateBuffer(ctx, source);
    return source.data;
}

} // namespace sdfcsg::detail
