#include "gpu/vk.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace sdfcsg::detail {

const char* vkResultName(VkResult result) {
    switch (result) {
#define SDFCSG_RESULT(name)                                                                        \
    case name:                                                                                     \
        return #name;
        SDFCSG_RESULT(VK_SUCCESS)
        SDFCSG_RESULT(VK_NOT_READY)
        SDFCSG_RESULT(VK_TIMEOUT)
        SDFCSG_RESULT(VK_INCOMPLETE)
        SDFCSG_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
        SDFCSG_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        SDFCSG_RESULT(VK_ERROR_INITIALIZATION_FAILED)
        SDFCSG_RESULT(VK_ERROR_DEVICE_LOST)
        SDFCSG_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
        SDFCSG_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
        SDFCSG_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
        SDFCSG_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
        SDFCSG_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
        SDFCSG_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
        SDFCSG_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
        SDFCSG_RESULT(VK_ERROR_FRAGMENTED_POOL)
        SDFCSG_RESULT(VK_ERROR_OUT_OF_POOL_MEMORY)
        SDFCSG_RESULT(VK_ERROR_UNKNOWN)
#undef SDFCSG_RESULT
    default:
        return "VkResult(unknown)";
    }
}

void vkFail(const char* call, VkResult result, const char* file, int line) {
    std::fprintf(stderr, "%s:%d: Vulkan call failed with %s (%d): %s\n", file, line,
                 vkResultName(result), int(result), call);
    std::fflush(stderr);
    std::abort();
}

namespace {

uint32_t findMemoryType(const VkPhysicalDeviceMemoryProperties& props, uint32_t typeBits,
                        VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) {
    uint32_t fallback = UINT32_MAX;
    for (uint32_t i = 0; i < props.memoryTypeCount; ++i) {
        VkMemoryPropertyFlags flags = props.memoryTypes[i].propertyFlags;
        if (!(typeBits & (1u << i)) || (flags & required) != required) continue;
        if ((flags & preferred) == preferred) return i;
        if (fallback == UINT32_MAX) fallback = i;
    }
    return fallback;
}

Error outOfMemory(VkDeviceSize size, VkResult result) {
    char text[160];
    std::snprintf(text, sizeof(text), "cannot allocate a %.1f MiB buffer (%s)",
                  double(size) / (1024.0 * 1024.0), vkResultName(result));
    return Error::message(ErrorKind::Limit, "<vulkan>", text);
}

} // namespace

Result<Buffer> createBuffer(Context::Impl& ctx, VkDeviceSize size, VkBufferUsageFlags usage,
                            MemoryUse use) {
    Buffer buffer;
    buffer.size = size < 4 ? 4 : size;

    VkBufferCreateInfo info = {VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = buffer.size;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VkResult result = vkCreateBuffer(ctx.device, &info, nullptr, &buffer.buffer);
    if (result == VK_ERROR_OUT_OF_HOST_MEMORY || result == VK_ERROR_OUT_OF_DEVICE_MEMORY)
        return outOfMemory(size, result);
    VK_CHECK(result);

    VkMemoryRequirements requirements;
    vkGetBufferMemoryRequirements(ctx.device, buffer.buffer, &requirements);

    constexpr VkMemoryPropertyFlags kHost =
        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    uint32_t type = UINT32_MAX;
    const auto& props = ctx.memoryProperties;
    switch (use) {
    case MemoryUse::Upload:
        type = findMemoryType(props, requirements.memoryTypeBits, kHost,
                              VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        break;
    case MemoryUse::Readback:
        // Device-local first; on CPU drivers and resizable-BAR GPUs it is also mappable, and the
        // caller only adds a staging copy when it is not.
        type =
            findMemoryType(props, requirements.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT,
                           VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
        if (type == UINT32_MAX)
            type = findMemoryType(props, requirements.memoryTypeBits,
                                  VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                                  VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
        break;
    case MemoryUse::Device:
        type = findMemoryType(props, requirements.memoryTypeBits,
                              VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0);
        if (type == UINT32_MAX) type = findMemoryType(props, requirements.memoryTypeBits, 0, 0);
        break;
    case MemoryUse::Staging:
        type =
            findMemoryType(props, requirements.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                           VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
        break;
    }
    if (type == UINT32_MAX) {
        std::fprintf(stderr, "%s:%d: no memory type for buffer usage %#x\n", __FILE__, __LINE__,
                     unsigned(usage));
        std::abort();
    }

    VkMemoryAllocateInfo allocate = {VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    allocate.allocationSize = requirements.size;
    allocate.memoryTypeIndex = type;
    result = vkAllocateMemory(ctx.device, &allocate, nullptr, &buffer.memory);
    if (result == VK_ERROR_OUT_OF_HOST_MEMORY || result == VK_ERROR_OUT_OF_DEVICE_MEMORY) {
        vkDestroyBuffer(ctx.device, buffer.buffer, nullptr);
        return outOfMemory(size, result);
    }
    VK_CHECK(result);
    VK_CHECK(vkBindBufferMemory(ctx.device, buffer.buffer, buffer.memory, 0));

    VkMemoryPropertyFlags flags = props.memoryTypes[type].propertyFlags;
    buffer.coherent = flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    if (flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)
        VK_CHECK(vkMapMemory(ctx.device, buffer.memory, 0, VK_WHOLE_SIZE, 0, &buffer.data));
    return buffer;
}

void destroyBuffer(Context::Impl& ctx, Buffer& buffer) {
    if (buffer.buffer) vkDestroyBuffer(ctx.device, buffer.buffer, nullptr);
    if (buffer.memory) vkFreeMemory(ctx.device, buffer.memory, nullptr); // unmaps implicitly
    buffer = Buffer{};
}

void uploadBuffer(Context::Impl& ctx, const Buffer& buffer, const void* data, size_t size) {
    if (!buffer.data || size > buffer.size) {
        std::fprintf(stderr, "%s:%d: upload of %zu bytes to a buffer of %llu (mapped: %d)\n",
                     __FILE__, __LINE__, size, (unsigned long long)buffer.size,
                     buffer.data != nullptr);
        std::abort();
    }
    std::memcpy(buffer.data, data, size);
    if (!buffer.coherent) {
        VkMappedMemoryRange range = {VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
        range.memory = buffer.memory;
        range.size = VK_WHOLE_SIZE;
        VK_CHECK(vkFlushMappedMemoryRanges(ctx.device, 1, &range));
    }
}

void invalidateBuffer(Context::Impl& ctx, const Buffer& buffer) {
    if (buffer.coherent) return;
    VkMappedMemoryRange range = {VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
    range.memory = buffer.memory;
    range.size = VK_WHOLE_SIZE;
    VK_CHECK(vkInvalidateMappedMemoryRanges(ctx.device, 1, &range));
}

VkShaderModule createShaderModule(Context::Impl& ctx, std::span<const uint32_t> spirv) {
    VkShaderModuleCreateInfo info = {VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    info.codeSize = spirv.size_bytes();
    info.pCode = spirv.data();
    VkShaderModule module = VK_NULL_HANDLE;
    VK_CHECK(vkCreateShaderModule(ctx.device, &info, nullptr, &module));
    return module;
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
    VkCommandBufferBeginInfo info = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(ctx.commandBuffer, &info));
    return ctx.commandBuffer;
}

void submitAndWait(Context::Impl& ctx) {
    VK_CHECK(vkEndCommandBuffer(ctx.commandBuffer));
    VkSubmitInfo submit = {VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &ctx.commandBuffer;
    VK_CHECK(vkResetFences(ctx.device, 1, &ctx.fence));
    VK_CHECK(vkQueueSubmit(ctx.queue, 1, &submit, ctx.fence));
    VK_CHECK(vkWaitForFences(ctx.device, 1, &ctx.fence, VK_TRUE, UINT64_MAX));
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
