// The headless compute context: instance, optional validation messenger, device selection that
// accepts CPU devices (lavapipe), one compute queue, a command pool and a fence.
#include "gpu/vk.h"

#include "codegen/shader_compile.h"
#include "gpu/environment.h"

#include <algorithm>
#include <cctype>
#include <string_view>
#include <vector>

namespace sdfcsg {
namespace {

Error vulkanError(std::string text, VkResult result = VK_SUCCESS) {
    if (result != VK_SUCCESS) text += std::string(" (") + vk::resultName(result) + ")";
    return Error::message(ErrorKind::Vulkan, "<vulkan>", std::move(text));
}

// 1: required, 0: off, -1: on if installed. SDFCSG_VALIDATION=1 asks for it explicitly, so a
// missing layer is an error then; debug builds merely use it when present.
int wantedValidation(int requested) {
    if (requested >= 0) return requested;
    if (detail::environment().validation >= 0) return detail::environment().validation;
#ifndef NDEBUG
    return -1;
#else
    return 0;
#endif
}

int typeRank(VkPhysicalDeviceType type) {
    switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
        return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
        return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
        return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
        return 3;
    default:
        return 4;
    }
}

std::string lower(std::string_view s) {
    std::string out(s);
    for (char& c : out)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

// The kernels use subgroupBroadcastFirst (shade.comp says why): optional in Vulkan 1.1, though
// lavapipe and the desktop GPU drivers offer it.
bool ballotInCompute(VkPhysicalDevice device) {
    VkPhysicalDeviceSubgroupProperties subgroup = {
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
    VkPhysicalDeviceProperties2 props = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    props.pNext = &subgroup;
    vkGetPhysicalDeviceProperties2(device, &props);
    return (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) &&
           (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_BALLOT_BIT);
}

// A compute-capable queue family, preferring one without graphics (a dedicated compute queue).
int computeFamily(VkPhysicalDevice device) {
    uint32_t count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
    std::vector<VkQueueFamilyProperties> families(count);
    vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
    int best = -1;
    for (uint32_t i = 0; i < count; ++i) {
        if (!(families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) || families[i].queueCount == 0)
            continue;
        if (best < 0) best = int(i);
        if (!(families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT)) return int(i);
    }
    return best;
}

// llvmpipe makes machine code at a pipeline's first dispatch, not when it is created.
bool compilesAtDispatch(const Context::Impl& impl) {
    if (impl.properties.apiVersion < VK_API_VERSION_1_2) return false;
    VkPhysicalDeviceDriverProperties driver = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 props = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    props.pNext = &driver;
    vkGetPhysicalDeviceProperties2(impl.physicalDevice, &props);
    return driver.driverID == VK_DRIVER_ID_MESA_LLVMPIPE;
}

} // namespace

Context::Impl::~Impl() {
    rendererShared.reset(); // holds objects of the device
    helper.reset();
    if (compilerWarmUp.joinable()) compilerWarmUp.join();
    if (device) {
        vkDeviceWaitIdle(device);
        if (fence) vkDestroyFence(device, fence, nullptr);
        if (commandPool) vkDestroyCommandPool(device, commandPool, nullptr);
        vkDestroyDevice(device, nullptr);
    }
    vk::destroyInstance(instance, messenger);
}

Context::Context(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Context::~Context() = default;

std::string Context::deviceName() const {
    return impl_->properties.deviceName;
}
bool Context::cpuDevice() const {
    return impl_->properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
}
bool Context::validationEnabled() const {
    return impl_->validation;
}
uint32_t Context::validationMessageCount() const {
    return impl_->validationMessages.count.load(std::memory_order_relaxed);
}

Status detail::setUpContext(Context::Impl& impl, const ContextOptions& options,
                            Context::Impl& report) {
    uint32_t loaderVersion = VK_API_VERSION_1_0;
    auto enumerateVersion = reinterpret_cast<PFN_vkEnumerateInstanceVersion>(
        vkGetInstanceProcAddr(nullptr, "vkEnumerateInstanceVersion"));
    if (enumerateVersion) VK_CHECK(enumerateVersion(&loaderVersion));
    if (loaderVersion < VK_API_VERSION_1_1)
        return vulkanError("the Vulkan loader supports only Vulkan 1.0; 1.1 or newer is needed");

    // Validation: 1 = required, -1 = if available, 0 = off.
    int validation = wantedValidation(options.validation);
    if (validation != 0) {
        bool available = vk::validationAvailable();
        if (!available && validation == 1)
            return vulkanError(
                std::string(vk::kValidationLayer) +
                " was requested but is not installed (Debian: vulkan-validationlayers)");
        impl.validation = available;
    }

    VkResult result = vk::createInstance(
        "sdfcsg", std::min<uint32_t>(loaderVersion, VK_API_VERSION_1_3), {},
        impl.validation ? &report.validationMessages : nullptr, impl.instance, impl.messenger);
    if (result == VK_ERROR_INCOMPATIBLE_DRIVER)
        return vulkanError("no Vulkan driver is installed (Debian: mesa-vulkan-drivers)", result);
    if (result != VK_SUCCESS) return vulkanError("cannot create a Vulkan instance", result);

    // Device selection.
    uint32_t count = 0;
    VK_CHECK(vkEnumeratePhysicalDevices(impl.instance, &count, nullptr));
    std::vector<VkPhysicalDevice> devices(count);
    VK_CHECK(vkEnumeratePhysicalDevices(impl.instance, &count, devices.data()));
    if (devices.empty())
        return vulkanError("no Vulkan device found (install mesa-vulkan-drivers for the CPU "
                           "driver lavapipe)");

    const std::string wanted =
        options.device.empty() ? detail::environment().device : options.device;

    std::string list;
    int chosen = -1, chosenFamily = -1;
    for (uint32_t i = 0; i < count; ++i) {
        VkPhysicalDeviceProperties props;
        vkGetPhysicalDeviceProperties(devices[i], &props);
        int family = computeFamily(devices[i]);
        const bool usable = props.apiVersion >= VK_API_VERSION_1_1 && ballotInCompute(devices[i]);
        list += "\n  " + std::to_string(i) + ": " + props.deviceName +
                (family < 0 ? " (no compute queue)" : "") +
                (family >= 0 && !usable ? " (no Vulkan 1.1 subgroup ballot in compute)" : "");
        if (family < 0 || !usable) continue;
        bool match;
        if (!wanted.empty()) {
            bool numeric = std::all_of(wanted.begin(), wanted.end(),
                                       [](char c) { return std::isdigit((unsigned char)c); });
            match = numeric ? std::to_string(i) == wanted
                            : lower(props.deviceName).find(lower(wanted)) != std::string::npos;
        } else {
            match = true;
        }
        if (!match) continue;
        if (chosen < 0) {
            chosen = int(i), chosenFamily = family;
            continue;
        }
        VkPhysicalDeviceProperties best;
        vkGetPhysicalDeviceProperties(devices[chosen], &best);
        if (typeRank(props.deviceType) < typeRank(best.deviceType))
            chosen = int(i), chosenFamily = family;
    }
    if (chosen < 0) {
        if (!wanted.empty())
            return vulkanError(
                "no Vulkan 1.1 device with a compute queue and subgroup ballot matches "
                "SDFCSG_DEVICE=\"" +
                wanted + "\"; devices:" + list);
        return vulkanError(
            "no Vulkan 1.1 device with a compute queue and subgroup ballot; devices:" + list);
    }
    impl.physicalDevice = devices[chosen];
    impl.deviceIndex = uint32_t(chosen);
    impl.queueFamily = uint32_t(chosenFamily);
    vkGetPhysicalDeviceProperties(impl.physicalDevice, &impl.properties);
    vkGetPhysicalDeviceMemoryProperties(impl.physicalDevice, &impl.memoryProperties);

    float priority = 1.0f;
    VkDeviceQueueCreateInfo queueInfo = {VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queueInfo.queueFamilyIndex = impl.queueFamily;
    queueInfo.queueCount = 1;
    queueInfo.pQueuePriorities = &priority;
    VkDeviceCreateInfo deviceInfo = {VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    deviceInfo.queueCreateInfoCount = 1;
    deviceInfo.pQueueCreateInfos = &queueInfo;
    result = vkCreateDevice(impl.physicalDevice, &deviceInfo, nullptr, &impl.device);
    if (result != VK_SUCCESS)
        return vulkanError(std::string("cannot create a device on ") + impl.properties.deviceName,
                           result);
    vkGetDeviceQueue(impl.device, impl.queueFamily, 0, &impl.queue);

    VkCommandPoolCreateInfo poolInfo = {VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    poolInfo.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
    poolInfo.queueFamilyIndex = impl.queueFamily;
    VK_CHECK(vkCreateCommandPool(impl.device, &poolInfo, nullptr, &impl.commandPool));

    VkCommandBufferAllocateInfo allocInfo = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    allocInfo.commandPool = impl.commandPool;
    allocInfo.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    allocInfo.commandBufferCount = 1;
    VK_CHECK(vkAllocateCommandBuffers(impl.device, &allocInfo, &impl.commandBuffer));

    VkFenceCreateInfo fenceInfo = {VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK_CHECK(vkCreateFence(impl.device, &fenceInfo, nullptr, &impl.fence));

    return Ok{};
}

Result<std::unique_ptr<Context>> Context::create(const ContextOptions& options) {
    auto impl = std::make_unique<Impl>();
    // Read before the context's threads start (gpu/environment.h).
    impl->compile.cacheDir =
        options.shaderCacheDir ? *options.shaderCacheDir : detail::environment().shaderCacheDir;
    const bool mesaCacheDisabled = detail::mesaDiskCacheDisabled();
    impl->compilerWarmUp = std::thread(detail::warmUpCompiler);
    if (auto ok = detail::setUpContext(*impl, options, *impl); !ok) return ok.error();
    // Mesa's disk cache of machine code, which the compile helper hands its work over with, is on
    // unless the environment turns it off.
    if (options.compileHelper && compilesAtDispatch(*impl) && !mesaCacheDisabled) {
        impl->helperOptions = options;
        impl->helperOptions.device = std::to_string(impl->deviceIndex);
        impl->helperOptions.validation = impl->validation ? 1 : 0;
        impl->helperWanted = true;
        detail::makeCompileHelper(*impl);
    }
    return std::unique_ptr<Context>(new Context(std::move(impl)));
}

} // namespace sdfcsg
