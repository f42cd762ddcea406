// Vulkan helpers on plain handles, shared by the engine's headless context (engine/src/gpu/vk.h
// builds its context's helpers on them) and the viewer's window device (apps/viewer/presenter.cpp):
// the instance with the validation layer and its messenger, buffers and their memory types,
// images, shader modules, one-shot submissions and barriers. Plain structs and free functions.
// Internal to the build: the engine compiles them in, and they are not installed.
//
// Every VkResult that is not VK_SUCCESS is a bug and aborts via VK_CHECK with file:line, in every
// build type, except the few that a user can cause (no driver, out of memory for a size they
// chose), which come back for the caller to turn into a message.
#pragma once

#include <vulkan/vulkan.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>

namespace sdfcsg::vk {

[[noreturn]] void fail(const char* call, VkResult result, const char* file, int line);
// "VK_ERROR_OUT_OF_DEVICE_MEMORY" and the like.
const char* resultName(VkResult result);

} // namespace sdfcsg::vk

#define VK_CHECK(call)                                                                             \
    do {                                                                                           \
        VkResult vkCheckResult_ = (call);                                                          \
        if (vkCheckResult_ != VK_SUCCESS)                                                          \
            ::sdfcsg::vk::fail(#call, vkCheckResult_, __FILE__, __LINE__);                         \
    } while (0)

namespace sdfcsg::vk {

// ---- Instance and validation -------------------------------------------------------------------

inline constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

// Whether the validation layer and the debug-utils extension that its messages come through are
// installed.
bool validationAvailable();

// Where an instance's validation messages go: each warning and error is printed to stderr as
// "vulkan validation <label>error: ..." and counted. Must outlive the instance.
struct MessageCounter {
    const char* label = ""; // "(window) ", say, to tell two instances apart
    std::atomic<uint32_t> count{0};
};

// An instance with `extensions`, and where `messages` is set, the validation layer, the
// debug-utils extension and a messenger that reports to `messages` (vkCreateInstance's and
// vkDestroyInstance's problems included). Returns vkCreateInstance's result; `instance` and
// `messenger` are set where it is VK_SUCCESS.
VkResult createInstance(const char* application, uint32_t apiVersion,
                        std::span<const char* const> extensions, MessageCounter* messages,
                        VkInstance& instance, VkDebugUtilsMessengerEXT& messenger);
// The messenger and the instance, either of which may be null; after the instance's devices and
// surfaces.
void destroyInstance(VkInstance instance, VkDebugUtilsMessengerEXT messenger);

// ---- Buffers -----------------------------------------------------------------------------------

enum class MemoryUse {
    Upload,   // written by the host every frame, read by shaders (uniforms, node data)
    Readback, // written by shaders, read by the host; device-local where that is also mappable
    Staging,  // host visible, cached where it can be: the source or target of transfers (a large
              // upload, a Readback buffer that turned out not to be mappable), or storage that
              // shaders write and the host reads in place
    Device,   // used by the device alone; device-local where there is such memory
};

struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize size = 0;
    void* data = nullptr;  // persistently mapped, or null when the memory is not host visible
    bool coherent = false; // no flush/invalidate needed
};

// The first of the memory types in `typeBits` that has every flag of `required`, preferring one
// that also has those of `preferred`; UINT32_MAX when none has `required`.
uint32_t findMemoryType(const VkPhysicalDeviceMemoryProperties& properties, uint32_t typeBits,
                        VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred);

// A buffer of `size` bytes (0 is rounded up to 4) in the memory that `use` asks for, mapped where
// that is host visible. Out of device or host memory returns that result and leaves `buffer`
// empty; any other failure aborts.
VkResult createBuffer(VkDevice device, const VkPhysicalDeviceMemoryProperties& properties,
                      VkDeviceSize size, VkBufferUsageFlags usage, MemoryUse use, Buffer& buffer);
// Frees the buffer and its memory (null handles are skipped) and empties `buffer`.
void destroyBuffer(VkDevice device, Buffer& buffer);
// Copies `size` bytes to a mapped buffer and flushes them when it is not coherent; aborts when
// the buffer is not mapped or too small.
void uploadBuffer(VkDevice device, const Buffer& buffer, const void* data, size_t size);
// Makes host writes to a mapped buffer visible to the device: flushes when not coherent.
void flushBuffer(VkDevice device, const Buffer& buffer);
// Makes device writes visible to the host (after the fence): invalidates when not coherent.
void invalidateBuffer(VkDevice device, const Buffer& buffer);

// ---- Images ------------------------------------------------------------------------------------

struct Image {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
};

// A 2D image of one level and one layer, optimally tiled in device-local memory, in the undefined
// layout; with a `viewAspect`, a view of it too (an image used for transfers alone may have none).
Image createImage(VkDevice device, const VkPhysicalDeviceMemoryProperties& properties,
                  VkExtent2D extent, VkFormat format, VkImageUsageFlags usage,
                  VkImageAspectFlags viewAspect = 0);
// The view, the image and its memory (null handles are skipped); empties `image`.
void destroyImage(VkDevice device, Image& image);

// ---- Shaders, commands and barriers ------------------------------------------------------------

VkShaderModule createShaderModule(VkDevice device, std::span<const uint32_t> spirv);

// Begins a command buffer for one submission.
void beginCommands(VkCommandBuffer cmd);
// Ends `cmd`, submits it to `queue` and waits for it on `fence`, which must be unsignalled and is
// left so.
void submitAndWait(VkDevice device, VkQueue queue, VkCommandBuffer cmd, VkFence fence);

// A layout transition of an image's one colour level and layer, with the accesses and stages it
// orders.
void recordImageBarrier(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to,
                        VkAccessFlags srcAccess, VkAccessFlags dstAccess,
                        VkPipelineStageFlags srcStage, VkPipelineStageFlags dstStage);
// The accesses and stages a whole buffer's writes are ordered with.
void recordBufferBarrier(VkCommandBuffer cmd, VkBuffer buffer, VkAccessFlags srcAccess,
                         VkAccessFlags dstAccess, VkPipelineStageFlags srcStage,
                         VkPipelineStageFlags dstStage);

} // namespace sdfcsg::vk
