#include "vulkan_helpers.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <vector>

namespace sdfcsg::vk {

const char* resultName(VkResult result) {
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
        SDFCSG_RESULT(VK_SUBOPTIMAL_KHR)
        SDFCSG_RESULT(VK_ERROR_OUT_OF_DATE_KHR)
        SDFCSG_RESULT(VK_ERROR_SURFACE_LOST_KHR)
#undef SDFCSG_RESULT
    default:
        return "VkResult(unknown)";
    }
}

void fail(const char* call, VkResult result, const char* file, int line) {
    std::fprintf(stderr, "%s:%d: Vulkan call failed with %s (%d): %s\n", file, line,
                 resultName(result), int(result), call);
    std::fflush(stderr);
    std::abort();
}

// ---- Instance and validation -------------------------------------------------------------------

namespace {

bool layerAvailable(const char* name) {
    uint32_t count = 0;
    VK_CHECK(vkEnumerateInstanceLayerProperties(&count, nullptr));
    std::vector<VkLayerProperties> layers(count);
    VK_CHECK(vkEnumerateInstanceLayerProperties(&count, layers.data()));
    return std::any_of(layers.begin(), layers.end(), [&](const VkLayerProperties& l) {
        return std::string_view(l.layerName) == name;
    });
}

bool extensionAvailable(const char* layer, const char* name) {
    uint32_t count = 0;
    VK_CHECK(vkEnumerateInstanceExtensionProperties(layer, &count, nullptr));
    std::vector<VkExtensionProperties> list(count);
    VK_CHECK(vkEnumerateInstanceExtensionProperties(layer, &count, list.data()));
    return std::any_of(list.begin(), list.end(), [&](const VkExtensionProperties& e) {
        return std::string_view(e.extensionName) == name;
    });
}

VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                             VkDebugUtilsMessageTypeFlagsEXT,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data,
                                             void* user) {
    auto* messages = static_cast<MessageCounter*>(user);
    messages->count.fetch_add(1, std::memory_order_relaxed);
    const char* level =
        (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning";
    std::fprintf(stderr, "vulkan validation %s%s: %s\n", messages->label, level,
                 data && data->pMessage ? data->pMessage : "(no message)");
    return VK_FALSE;
}

} // namespace

bool validationAvailable() {
    return layerAvailable(kValidationLayer) &&
           extensionAvailable(nullptr, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
}

VkResult createInstance(const char* application, uint32_t apiVersion,
                        std::span<const char* const> extensions, MessageCounter* messages,
                        VkInstance& instance, VkDebugUtilsMessengerEXT& messenger) {
    VkApplicationInfo app = {VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = application;
    app.pEngineName = "sdfcsg";
    app.apiVersion = apiVersion;

    std::vector<const char*> enabled(extensions.begin(), extensions.end());
    VkDebugUtilsMessengerCreateInfoEXT messengerInfo = {
        VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    messengerInfo.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                                    VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messengerInfo.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                                VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                                VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    messengerInfo.pfnUserCallback = debugCallback;
    messengerInfo.pUserData = messages;

    VkInstanceCreateInfo info = {VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    info.pApplicationInfo = &app;
    if (messages) {
        enabled.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        info.enabledLayerCount = 1;
        info.ppEnabledLayerNames = &kValidationLayer;
        info.pNext = &messengerInfo; // also reports problems in vkCreate/DestroyInstance
    }
    info.enabledExtensionCount = uint32_t(enabled.size());
    info.ppEnabledExtensionNames = enabled.data();
    instance = VK_NULL_HANDLE;
    messenger = VK_NULL_HANDLE;
    VkResult result = vkCreateInstance(&info, nullptr, &instance);
    if (result != VK_SUCCESS) {
        instance = VK_NULL_HANDLE;
        return result;
    }
    if (messages) {
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
        VK_CHECK(create(instance, &messengerInfo, nullptr, &messenger));
    }
    return VK_SUCCESS;
}

void destroyInstance(VkInstance instance, VkDebugUtilsMessengerEXT messenger) {
    if (!instance) return;
    if (messenger) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroy) destroy(instance, messenger, nullptr);
    }
    vkDestroyInstance(instance, nullptr);
}

// ---- Buffers -----------------------------------------------------------------------------------

uint32_t findMemoryType(const VkPhysicalDeviceMemoryProperties& properties, uint32_t typeBits,
                        VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) {
    uint32_t fallback = UINT32_MAX;
    for (uint32_t i = 0; i < properties.memoryTypeCount; ++i) {
        VkMemoryPropertyFlags flags = properties.memoryTypes[i].propertyFlags;
        if (!(typeBits & (1u << i)) || (flags & required) != required) continue;
        if ((flags & preferred) == preferred) return i;
        if (fallback == UINT32_MAX) fallback = i;
    }
    return fallback;
}

namespace {

uint32_t memoryTypeFor(const VkPhysicalDeviceMemoryProperties& props, uint32_t bits,
                       MemoryUse use) {
    constexpr VkMemoryPropertyFlags kHost =
        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    uint32_t type = UINT32_MAX;
    switch (use) {
    case MemoryUse::Upload:
        type = findMemoryType(props, bits, kHost, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        break;
    case MemoryUse::Readback:
        // Device-local first; on CPU drivers and resizable-BAR GPUs it is also mappable, and the
        // caller only adds a staging copy when it is not.
        type = findMemoryType(props, bits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT,
                              VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
        if (type == UINT32_MAX)
            type = findMemoryType(props, bits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                                  VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
        break;
    case MemoryUse::Device:
        type = findMemoryType(props, bits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0);
        if (type == UINT32_MAX) type = findMemoryType(props, bits, 0, 0);
        break;
    case MemoryUse::Staging:
        type = findMemoryType(props, bits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                              VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
        break;
    }
    return type;
}

bool outOfMemory(VkResult result) {
    return result == VK_ERROR_OUT_OF_HOST_MEMORY || result == VK_ERROR_OUT_OF_DEVICE_MEMORY;
}

} // namespace

VkResult createBuffer(VkDevice device, const VkPhysicalDeviceMemoryProperties& properties,
                      VkDeviceSize size, VkBufferUsageFlags usage, MemoryUse use, Buffer& buffer) {
    buffer = Buffer{};
    buffer.size = size < 4 ? 4 : size;

    VkBufferCreateInfo info = {VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = buffer.size;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VkResult result = vkCreateBuffer(device, &info, nullptr, &buffer.buffer);
    if (outOfMemory(result)) {
        buffer = Buffer{};
        return result;
    }
    VK_CHECK(result);

    VkMemoryRequirements requirements;
    vkGetBufferMemoryRequirements(device, buffer.buffer, &requirements);
    const uint32_t type = memoryTypeFor(properties, requirements.memoryTypeBits, use);
    if (type == UINT32_MAX) {
        std::fprintf(stderr, "%s:%d: no memory type for buffer usage %#x\n", __FILE__, __LINE__,
                     unsigned(usage));
        std::abort();
    }

    VkMemoryAllocateInfo allocate = {VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    allocate.allocationSize = requirements.size;
    allocate.memoryTypeIndex = type;
    result = vkAllocateMemory(device, &allocate, nullptr, &buffer.memory);
    if (outOfMemory(result)) {
        vkDestroyBuffer(device, buffer.buffer, nullptr);
        buffer = Buffer{};
        return result;
    }
    VK_CHECK(result);
    VK_CHECK(vkBindBufferMemory(device, buffer.buffer, buffer.memory, 0));

    VkMemoryPropertyFlags flags = properties.memoryTypes[type].propertyFlags;
    buffer.coherent = flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    if (flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)
        VK_CHECK(vkMapMemory(device, buffer.memory, 0, VK_WHOLE_SIZE, 0, &buffer.data));
    return VK_SUCCESS;
}

void destroyBuffer(VkDevice device, Buffer& buffer) {
    if (buffer.buffer) vkDestroyBuffer(device, buffer.buffer, nullptr);
    if (buffer.memory) vkFreeMemory(device, buffer.memory, nullptr); // unmaps implicitly
    buffer = Buffer{};
}

void uploadBuffer(VkDevice device, const Buffer& buffer, const void* data, size_t size) {
    if (!buffer.data || size > buffer.size) {
        std::fprintf(stderr, "%s:%d: upload of %zu bytes to a buffer of %llu (mapped: %d)\n",
                     __FILE__, __LINE__, size, (unsigned long long)buffer.size,
                     buffer.data != nullptr);
        std::abort();
    }
    std::memcpy(buffer.data, data, size);
    flushBuffer(device, buffer);
}

void flushBuffer(VkDevice device, const Buffer& buffer) {
    if (buffer.coherent) return;
    VkMappedMemoryRange range = {VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
    range.memory = buffer.memory;
    range.size = VK_WHOLE_SIZE;
    VK_CHECK(vkFlushMappedMemoryRanges(device, 1, &range));
}

void invalidateBuffer(VkDevice device, const Buffer& buffer) {
    if (buffer.coherent) return;
    VkMappedMemoryRange range = {VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
    range.memory = buffer.memory;
    range.size = VK_WHOLE_SIZE;
    VK_CHECK(vkInvalidateMappedMemoryRanges(device, 1, &range));
}

// ---- Images ------------------------------------------------------------------------------------

Image createImage(VkDevice device, const VkPhysicalDeviceMemoryProperties& properties,
                  VkExtent2D extent, VkFormat format, VkImageUsageFlags usage,
                  VkImageAspectFlags viewAspect) {
    Image image;
    VkImageCreateInfo info = {VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {extent.width, extent.height, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    VK_CHECK(vkCreateImage(device, &info, nullptr, &image.image));

    VkMemoryRequirements requirements;
    vkGetImageMemoryRequirements(device, image.image, &requirements);
    const uint32_t type = memoryTypeFor(properties, requirements.memoryTypeBits, MemoryUse::Device);
    if (type == UINT32_MAX) {
        std::fprintf(stderr, "%s:%d: no memory type for image usage %#x\n", __FILE__, __LINE__,
                     unsigned(usage));
        std::abort();
    }
    VkMemoryAllocateInfo allocate = {VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    allocate.allocationSize = requirements.size;
    allocate.memoryTypeIndex = type;
    VK_CHECK(vkAllocateMemory(device, &allocate, nullptr, &image.memory));
    VK_CHECK(vkBindImageMemory(device, image.image, image.memory, 0));

    if (viewAspect) {
        VkImageViewCreateInfo view = {VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
        view.image = image.image;
        view.viewType = VK_IMAGE_VIEW_TYPE_2D;
        view.format = format;
        view.subresourceRange = {viewAspect, 0, 1, 0, 1};
        VK_CHECK(vkCreateImageView(device, &view, nullptr, &image.view));
    }
    return image;
}

void destroyImage(VkDevice device, Image& image) {
    if (image.view) vkDestroyImageView(device, image.view, nullptr);
    if (image.image) vkDestroyImage(device, image.image, nullptr);
    if (image.memory) vkFreeMemory(device, image.memory, nullptr);
    image = Image{};
}

// ---- Shaders, commands and barriers ------------------------------------------------------------

VkShaderModule createShaderModule(VkDevice device, std::span<const uint32_t> spirv) {
    VkShaderModuleCreateInfo info = {VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    info.codeSize = spirv.size_bytes();
    info.pCode = spirv.data();
    VkShaderModule module = VK_NULL_HANDLE;
    VK_CHECK(vkCreateShaderModule(device, &info, nullptr, &module));
    return module;
}

void beginCommands(VkCommandBuffer cmd) {
    VkCommandBufferBeginInfo info = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(cmd, &info));
}

void submitAndWait(VkDevice device, VkQueue queue, VkCommandBuffer cmd, VkFence fence) {
    VK_CHECK(vkEndCommandBuffer(cmd));
    VkSubmitInfo submit = {VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd;
    VK_CHECK(vkQueueSubmit(queue, 1, &submit, fence));
    VK_CHECK(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX));
    VK_CHECK(vkResetFences(device, 1, &fence));
}

void recordImageBarrier(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to,
                        VkAccessFlags srcAccess, VkAccessFlags dstAccess,
                        VkPipelineStageFlags srcStage, VkPipelineStageFlags dstStage) {
    VkImageMemoryBarrier barrier = {VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    barrier.srcAccessMask = srcAccess;
    barrier.dstAccessMask = dstAccess;
    barrier.oldLayout = from;
    barrier.newLayout = to;
    barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = image;
    barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd, srcStage, dstStage, 0, 0, nullptr, 0, nullptr, 1, &barrier);
}

void recordBufferBarrier(VkCommandBuffer cmd, VkBuffer buffer, VkAccessFlags srcAccess,
                         VkAccessFlags dstAccess, VkPipelineStageFlags srcStage,
                         VkPipelineStageFlags dstStage) {
    VkBufferMemoryBarrier barrier = {VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
    barrier.srcAccessMask = srcAccess;
    barrier.dstAccessMask = dstAccess;
    barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.buffer = buffer;
    barrier.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(cmd, srcStage, dstStage, 0, 0, nullptr, 1, &barrier, 0, nullptr);
}

} // namespace sdfcsg::vk
