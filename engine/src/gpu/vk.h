// Private Vulkan plumbing: the context's internals, and helpers for buffers, compute pipelines,
// descriptors and one-shot submissions on a context. Plain structs and free functions, over the
// helpers on plain handles that the viewer shares (engine/vulkan/vulkan_helpers.h).
//
// Errors the user can cause (no device, out of memory for a requested size) come back as
// Results; every other VkResult that is not VK_SUCCESS is a bug and aborts via VK_CHECK, in
// every build type.
#pragma once

#include "sdfcsg/compile.h"
#include "sdfcsg/context.h"
#include "sdfcsg/error.h"

#include "vulkan_helpers.h"

#include <vulkan/vulkan.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>

namespace sdfcsg {

struct Context::Impl {
    VkInstance instance = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
    VkPhysicalDeviceProperties properties{};
    VkPhysicalDeviceMemoryProperties memoryProperties{};
    VkDevice device = VK_NULL_HANDLE;
    uint32_t queueFamily = 0;
    VkQueue queue = VK_NULL_HANDLE;
    VkCommandPool commandPool = VK_NULL_HANDLE;
    VkCommandBuffer commandBuffer = VK_NULL_HANDLE; // reused by submitAndWait()
    VkFence fence = VK_NULL_HANDLE;
    // Held from beginCommands() to submitAndWait(): the command buffer, its pool, the fence and
    // the queue are shared by every Renderer and Mesher of the context, whatever their thread.
    std::mutex submitMutex;
    bool validation = false;
    vk::MessageCounter validationMessages; // this context's and its compile helper's
    std::thread compilerWarmUp;            // detail::warmUpCompiler(), while the device is set up
    uint32_t deviceIndex = 0;              // in vkEnumeratePhysicalDevices' order
    // How the renderers and meshers of this context compile: ContextOptions::shaderCacheDir, or
    // the environment's, resolved when the context is made.
    CompileOptions compile;

    // llvmpipe only: a second instance and device on the same driver, whose queue compiles a
    // kernel to machine code while this one's compiles another (see precompileElsewhere()).
    // Made with the context, and again after each use (makeCompileHelper()).
    bool helperWanted = false;    // set before the context is shared, then read only
    ContextOptions helperOptions; // this device, this validation setting
    std::mutex helperMutex;       // guards what follows
    std::unique_ptr<Impl> helper;
    bool helperFailed = false; // its setup or a hand-over failed once: not tried again
    std::atomic<uint32_t> helperCompiles{0}; // pipelines it compiled (tests look)

    // What the renderers of this context share (render.cpp), made by the first.
    std::mutex rendererSharedMutex;
    std::shared_ptr<void> rendererShared;

    ~Impl();
};

namespace detail {

// The internals of a context, for the library and its tests; the public header names Impl only.
struct ContextAccess {
    static Context::Impl& impl(Context& context) { return *context.impl_; }
};
inline Context::Impl& contextImpl(Context& context) {
    return ContextAccess::impl(context);
}

// The instance (its validation messages counted in `report`), the chosen device, its queue,
// command pool and fence: Context::create, and the compile helper.
Status setUpContext(Context::Impl& impl, const ContextOptions& options, Context::Impl& report);

using vk::Buffer;
using vk::MemoryUse;

// Out of device or host memory is an ErrorKind::Limit error naming the size; anything else
// aborts. Sizes of 0 are rounded up to 4 bytes.
Result<Buffer> createBuffer(Context::Impl& ctx, VkDeviceSize size, VkBufferUsageFlags usage,
                            MemoryUse use);
inline void destroyBuffer(Context::Impl& ctx, Buffer& buffer) {
    vk::destroyBuffer(ctx.device, buffer);
}
// Copies to a mapped buffer and flushes it when not coherent.
inline void uploadBuffer(Context::Impl& ctx, const Buffer& buffer, const void* data, size_t size) {
    vk::uploadBuffer(ctx.device, buffer, data, size);
}
// Makes device writes visible to the host (after the fence): invalidates when not coherent.
inline void invalidateBuffer(Context::Impl& ctx, const Buffer& buffer) {
    vk::invalidateBuffer(ctx.device, buffer);
}

struct SpecConstant {
    uint32_t id;
    uint32_t value; // 32-bit scalars only (bool is 0/1)
};

struct Binding {
    uint32_t binding;
    VkDescriptorType type;
};

inline VkShaderModule createShaderModule(Context::Impl& ctx, std::span<const uint32_t> spirv) {
    return vk::createShaderModule(ctx.device, spirv);
}
// Every binding is visible to the compute stage.
VkDescriptorSetLayout createDescriptorSetLayout(Context::Impl& ctx,
                                                std::span<const Binding> bindings);
VkPipelineLayout createPipelineLayout(Context::Impl& ctx, VkDescriptorSetLayout setLayout,
                                      uint32_t pushConstantBytes);
VkPipeline createComputePipeline(Context::Impl& ctx, VkShaderModule module, VkPipelineLayout layout,
                                 std::span<const SpecConstant> spec);
// A pool sized for exactly one set of the given bindings.
VkDescriptorPool createDescriptorPool(Context::Impl& ctx, std::span<const Binding> bindings);
VkDescriptorSet allocateDescriptorSet(Context::Impl& ctx, VkDescriptorPool pool,
                                      VkDescriptorSetLayout layout);
// Points bindings[i] at buffers[i] (the whole buffer).
void writeDescriptorSet(Context::Impl& ctx, VkDescriptorSet set, std::span<const Binding> bindings,
                        std::span<const Buffer* const> buffers);

// Begins the context's command buffer for a one-shot submission, taking the context's submit
// lock: record, then call submitAndWait() from the same thread with no early return between.
VkCommandBuffer beginCommands(Context::Impl& ctx);
// Ends, submits, waits on the fence and releases the submit lock.
void submitAndWait(Context::Impl& ctx);

// Compute shader writes -> reads by later compute dispatches and their indirect arguments.
void recordComputeBarrier(VkCommandBuffer cmd);

// Shader writes -> host reads: records the barrier and, when `buffer` is not mappable, a copy
// into `staging` (which must then exist). Call before submitAndWait(), then readback().
void recordReadback(VkCommandBuffer cmd, const Buffer& buffer, const Buffer* staging);
// The mapped bytes of whichever buffer holds the result, invalidated.
const void* readback(Context::Impl& ctx, const Buffer& buffer, const Buffer* staging);

// llvmpipe makes a compute pipeline's machine code at its first dispatch, on the thread of the
// device's one queue, so the kernels of one renderer would compile one after the other. A second
// instance and device on the same driver compile on a queue thread of their own, and Mesa's disk
// cache of machine code hands the result over: a pipeline made from the same SPIR-V, layout and
// constants on this context loads it at its first dispatch instead of compiling.
//
// A pipeline for precompileElsewhere(): its SPIR-V and specialisation constants.
struct Precompile {
    std::span<const uint32_t> spirv;
    std::span<const SpecConstant> spec;
};
// Compiles such pipelines, one after the other, on the helper device, all with the same layout,
// and returns once their machine code is in the disk cache (destroying the helper's instance
// waits for the cache's writes; the next call makes a new one), with the milliseconds the first
// one's compile took. Returns 0, having done nothing, where there is no helper (other drivers,
// Mesa's disk cache turned off, ContextOptions::compileHelper false) or it is busy.
double precompileElsewhere(Context::Impl& ctx, std::span<const Precompile> pipelines,
                           std::span<const Binding> bindings, uint32_t pushConstantBytes);
// Says that this device compiled a kernel that the helper had compiled (its first dispatch took
// about as long as the helper's compile): Mesa's disk cache did not hand it over, though the
// environment did not turn it off (an unwritable folder, say). Turns the helper off.
void compileHelperMissed(Context::Impl& ctx);
// Makes the helper device where there is none (at first, and after each use), so that
// precompileElsewhere() need not wait for it. Does nothing where the helper does not apply or is
// busy.
void makeCompileHelper(Context::Impl& ctx);

// Dispatch with group counts derived from a local size.
inline uint32_t groupCount(uint32_t threads, uint32_t localSize) {
    return (threads + localSize - 1) / localSize;
}

} // namespace detail
} // namespace sdfcsg
