// The window's device (presenter.h): instance, device and swapchain, the engine's image, and
// the frame, which blits that image or the mesh view's (mesh_view.cpp) and draws ImGui over it.
#include "presenter_internal.h"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_vulkan.h>

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <vector>

namespace sdfcsg::viewer {

namespace {

void imguiCheck(VkResult result) {
    if (result != VK_SUCCESS) vk::fail("ImGui Vulkan backend", result, __FILE__, __LINE__);
}

// Host visible and mapped, replaced by a larger one when it is too small.
void ensureBuffer(Presenter& p, vk::Buffer& b, VkDeviceSize size, VkBufferUsageFlags usage) {
    if (b.size >= size) return;
    vk::destroyBuffer(p.device, b);
    VK_CHECK(
        vk::createBuffer(p.device, p.memoryProperties, size, usage, vk::MemoryUse::Staging, b));
}

void createSceneImage(Presenter& p, uint32_t width, uint32_t height) {
    vk::destroyImage(p.device, p.sceneImage);
    // The bytes as the engine wrote them, no conversion.
    p.sceneImage =
        vk::createImage(p.device, p.memoryProperties, {width, height}, VK_FORMAT_R8G8B8A8_UNORM,
                        VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    p.sceneWidth = width;
    p.sceneHeight = height;
}

void destroySwapchainViews(Presenter& p) {
    for (VkFramebuffer f : p.framebuffers)
        vkDestroyFramebuffer(p.device, f, nullptr);
    for (VkImageView v : p.views)
        vkDestroyImageView(p.device, v, nullptr);
    p.framebuffers.clear();
    p.views.clear();
    p.images.clear();
}

bool createSwapchain(Presenter& p) {
    int w = 0, h = 0;
    glfwGetFramebufferSize(p.window, &w, &h);
    if (w <= 0 || h <= 0) return false;
    VK_CHECK(vkDeviceWaitIdle(p.device));
    VkSurfaceCapabilitiesKHR caps;
    VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(p.physical, p.surface, &caps));
    VkExtent2D extent = caps.currentExtent;
    if (extent.width == UINT32_MAX) {
        extent.width =
            std::clamp(uint32_t(w), caps.minImageExtent.width, caps.maxImageExtent.width);
        extent.height =
            std::clamp(uint32_t(h), caps.minImageExtent.height, caps.maxImageExtent.height);
    }
    if (extent.width == 0 || extent.height == 0) return false;
    p.canCapture = caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    VkSwapchainCreateInfoKHR info = {VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    info.surface = p.surface;
    info.minImageCount = std::max(2u, caps.minImageCount);
    if (caps.maxImageCount) info.minImageCount = std::min(info.minImageCount, caps.maxImageCount);
    info.imageFormat = p.format.format;
    info.imageColorSpace = p.format.colorSpace;
    info.imageExtent = extent;
    info.imageArrayLayers = 1;
    info.imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                      (p.canCapture ? VK_IMAGE_USAGE_TRANSFER_SRC_BIT : 0);
    info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.preTransform = caps.currentTransform;
    info.compositeAlpha = (caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR)
                              ? VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
                              : VkCompositeAlphaFlagBitsKHR(caps.supportedCompositeAlpha &
                                                            -caps.supportedCompositeAlpha);
    info.presentMode = VK_PRESENT_MODE_FIFO_KHR; // always available
    info.clipped = VK_TRUE;
    info.oldSwapchain = p.swapchain;
    VkSwapchainKHR swapchain;
    VK_CHECK(vkCreateSwapchainKHR(p.device, &info, nullptr, &swapchain));
    destroySwapchainViews(p);
    if (p.swapchain) vkDestroySwapchainKHR(p.device, p.swapchain, nullptr);
    p.swapchain = swapchain;
    p.extent = extent;
    uint32_t count = 0;
    VK_CHECK(vkGetSwapchainImagesKHR(p.device, swapchain, &count, nullptr));
    p.images.resize(count);
    VK_CHECK(vkGetSwapchainImagesKHR(p.device, swapchain, &count, p.images.data()));
    for (VkImage image : p.images) {
        VkImageViewCreateInfo view = {VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
        view.image = image;
        view.viewType = VK_IMAGE_VIEW_TYPE_2D;
        view.format = p.format.format;
        view.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        VkImageView v;
        VK_CHECK(vkCreateImageView(p.device, &view, nullptr, &v));
        p.views.push_back(v);
        VkFramebufferCreateInfo fb = {VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
        fb.renderPass = p.renderPass;
        fb.attachmentCount = 1;
        fb.pAttachments = &v;
        fb.width = extent.width;
        fb.height = extent.height;
        fb.layers = 1;
        VkFramebuffer f;
        VK_CHECK(vkCreateFramebuffer(p.device, &fb, nullptr, &f));
        p.framebuffers.push_back(f);
    }
    ImGui_ImplVulkan_SetMinImageCount(info.minImageCount);
    p.rebuild = false;
    return true;
}

// createPresenter's steps after the instance and the window's surface (defined below it).
bool pickDevice(Presenter& p, std::string& error);
void createDevice(Presenter& p);
void chooseFormat(Presenter& p);
void createRenderPass(Presenter& p);
void createCommands(Presenter& p);
void initImGui(Presenter& p);

} // namespace

PresenterPtr createPresenter(GLFWwindow* window, bool validationWanted, std::string& error) {
    PresenterPtr p(new Presenter);
    p->window = window;
    uint32_t extensionCount = 0;
    const char** extensions = glfwGetRequiredInstanceExtensions(&extensionCount);
    if (!extensions) {
        error = "GLFW found no Vulkan window-system support";
        return nullptr;
    }
    const bool validation = validationWanted && vk::validationAvailable();
    if (vk::createInstance("sdfcsg-viewer", VK_API_VERSION_1_1, {extensions, extensionCount},
                           validation ? &p->validationMessages : nullptr, p->instance,
                           p->messenger) != VK_SUCCESS) {
        error = "could not create a Vulkan instance with window-system extensions";
        return nullptr;
    }
    if (glfwCreateWindowSurface(p->instance, window, nullptr, &p->surface) != VK_SUCCESS) {
        error = "could not create a Vulkan surface for the window";
        return nullptr;
    }
    if (!pickDevice(*p, error)) return nullptr;
    createDevice(*p);
    chooseFormat(*p);
    createRenderPass(*p);
    VkPhysicalDeviceProperties properties;
    vkGetPhysicalDeviceProperties(p->physical, &properties);
    p->limits = properties.limits;
    createMeshPipeline(*p);
    createCommands(*p);
    initImGui(*p);
    return p;
}

namespace {

// Any device that can draw to the window's surface; a discrete GPU first. False (and the
// error) when none can.
bool pickDevice(Presenter& p, std::string& error) {
    uint32_t count = 0;
    vkEnumeratePhysicalDevices(p.instance, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    vkEnumeratePhysicalDevices(p.instance, &count, devices.data());
    int bestScore = -1;
    for (VkPhysicalDevice d : devices) {
        uint32_t families = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(d, &families, nullptr);
        std::vector<VkQueueFamilyProperties> props(families);
        vkGetPhysicalDeviceQueueFamilyProperties(d, &families, props.data());
        for (uint32_t f = 0; f < families; ++f) {
            VkBool32 present = VK_FALSE;
            vkGetPhysicalDeviceSurfaceSupportKHR(d, f, p.surface, &present);
            if (!(props[f].queueFlags & VK_QUEUE_GRAPHICS_BIT) || !present) continue;
            VkPhysicalDeviceProperties dp;
            vkGetPhysicalDeviceProperties(d, &dp);
            int score = dp.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU     ? 3
                        : dp.deviceType == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU ? 2
                                                                                  : 1;
            if (score > bestScore) {
                bestScore = score;
                p.physical = d;
                p.family = f;
                p.deviceName = dp.deviceName;
            }
            break;
        }
    }
    if (!p.physical) {
        error = "no Vulkan device can present to this window";
        return false;
    }
    return true;
}

void createDevice(Presenter& p) {
    vkGetPhysicalDeviceMemoryProperties(p.physical, &p.memoryProperties);
    float priority = 1.0f;
    VkDeviceQueueCreateInfo queueInfo = {VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queueInfo.queueFamilyIndex = p.family;
    queueInfo.queueCount = 1;
    queueInfo.pQueuePriorities = &priority;
    const char* deviceExtensions[] = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
    VkDeviceCreateInfo deviceInfo = {VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    deviceInfo.queueCreateInfoCount = 1;
    deviceInfo.pQueueCreateInfos = &queueInfo;
    deviceInfo.enabledExtensionCount = 1;
    deviceInfo.ppEnabledExtensionNames = deviceExtensions;
    VK_CHECK(vkCreateDevice(p.physical, &deviceInfo, nullptr, &p.device));
    vkGetDeviceQueue(p.device, p.family, 0, &p.queue);
}

// A UNORM format, so the engine's bytes reach the screen (and screenshots) unchanged.
void chooseFormat(Presenter& p) {
    uint32_t formatCount = 0;
    vkGetPhysicalDeviceSurfaceFormatsKHR(p.physical, p.surface, &formatCount, nullptr);
    std::vector<VkSurfaceFormatKHR> formats(formatCount);
    vkGetPhysicalDeviceSurfaceFormatsKHR(p.physical, p.surface, &formatCount, formats.data());
    p.format = formats.empty()
                   ? VkSurfaceFormatKHR{VK_FORMAT_B8G8R8A8_UNORM, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR}
                   : formats[0];
    for (const VkSurfaceFormatKHR& f : formats)
        if (f.format == VK_FORMAT_B8G8R8A8_UNORM || f.format == VK_FORMAT_R8G8B8A8_UNORM) {
            p.format = f;
            break;
        }
}

// ImGui draws over the blitted image: load, not clear.
void createRenderPass(Presenter& p) {
    VkAttachmentDescription attachment = {};
    attachment.format = p.format.format;
    attachment.samples = VK_SAMPLE_COUNT_1_BIT;
    attachment.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
    attachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    attachment.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    attachment.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    attachment.initialLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    attachment.finalLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
    VkAttachmentReference ref = {0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkSubpassDescription subpass = {};
    subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    subpass.colorAttachmentCount = 1;
    subpass.pColorAttachments = &ref;
    VkSubpassDependency dependency = {};
    dependency.srcSubpass = VK_SUBPASS_EXTERNAL;
    dependency.dstSubpass = 0;
    dependency.srcStageMask =
        VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    dependency.dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    dependency.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    dependency.dstAccessMask =
        VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    VkRenderPassCreateInfo passInfo = {VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    passInfo.attachmentCount = 1;
    passInfo.pAttachments = &attachment;
    passInfo.subpassCount = 1;
    passInfo.pSubpasses = &subpass;
    passInfo.dependencyCount = 1;
    passInfo.pDependencies = &dependency;
    VK_CHECK(vkCreateRenderPass(p.device, &passInfo, nullptr, &p.renderPass));
}

// The descriptor pool for ImGui, and the frame's command buffer, fence and semaphores.
void createCommands(Presenter& p) {
    VkDescriptorPoolSize poolSize = {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 16};
    VkDescriptorPoolCreateInfo poolInfo = {VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    poolInfo.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
    poolInfo.maxSets = 16;
    poolInfo.poolSizeCount = 1;
    poolInfo.pPoolSizes = &poolSize;
    VK_CHECK(vkCreateDescriptorPool(p.device, &poolInfo, nullptr, &p.descriptorPool));

    VkCommandPoolCreateInfo cmdPool = {VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    cmdPool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    cmdPool.queueFamilyIndex = p.family;
    VK_CHECK(vkCreateCommandPool(p.device, &cmdPool, nullptr, &p.commandPool));
    VkCommandBufferAllocateInfo cmdInfo = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cmdInfo.commandPool = p.commandPool;
    cmdInfo.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cmdInfo.commandBufferCount = 1;
    VK_CHECK(vkAllocateCommandBuffers(p.device, &cmdInfo, &p.cmd));
    VkFenceCreateInfo fenceInfo = {VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK_CHECK(vkCreateFence(p.device, &fenceInfo, nullptr, &p.fence));
    VkSemaphoreCreateInfo semInfo = {VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VK_CHECK(vkCreateSemaphore(p.device, &semInfo, nullptr, &p.acquired));
    VK_CHECK(vkCreateSemaphore(p.device, &semInfo, nullptr, &p.rendered));
}

// ImGui's Vulkan backend, and its fonts, uploaded once.
void initImGui(Presenter& p) {
    VkSurfaceCapabilitiesKHR caps;
    VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(p.physical, p.surface, &caps));
    ImGui_ImplVulkan_InitInfo init = {};
    init.Instance = p.instance;
    init.PhysicalDevice = p.physical;
    init.Device = p.device;
    init.QueueFamily = p.family;
    init.Queue = p.queue;
    init.DescriptorPool = p.descriptorPool;
    init.MinImageCount = std::max(2u, caps.minImageCount);
    init.ImageCount = std::max(init.MinImageCount, 3u);
    init.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
    init.CheckVkResultFn = imguiCheck;
    ImGui_ImplVulkan_Init(&init, p.renderPass);

    vk::beginCommands(p.cmd);
    ImGui_ImplVulkan_CreateFontsTexture(p.cmd);
    vk::submitAndWait(p.device, p.queue, p.cmd, p.fence);
    ImGui_ImplVulkan_DestroyFontUploadObjects();
}

} // namespace

void destroyPresenter(Presenter* p) {
    if (!p) return;
    if (p->device) {
        vkDeviceWaitIdle(p->device);
        if (p->renderPass) ImGui_ImplVulkan_Shutdown();
        vk::destroyBuffer(p->device, p->staging);
        vk::destroyBuffer(p->device, p->readback);
        vk::destroyImage(p->device, p->sceneImage);
        for (DeviceMesh& m : p->meshes)
            destroyMesh(*p, m);
        destroyMeshTarget(*p);
        destroySwapchainViews(*p);
        if (p->timestamps) vkDestroyQueryPool(p->device, p->timestamps, nullptr);
        for (VkPipeline pipeline : p->meshPipelines)
            vkDestroyPipeline(p->device, pipeline, nullptr);
        vkDestroyPipeline(p->device, p->gridPipeline, nullptr);
        vkDestroyRenderPass(p->device, p->meshPass, nullptr);
        vkDestroyPipelineLayout(p->device, p->meshLayout, nullptr);
        if (p->swapchain) vkDestroySwapchainKHR(p->device, p->swapchain, nullptr);
        vkDestroySemaphore(p->device, p->acquired, nullptr);
        vkDestroySemaphore(p->device, p->rendered, nullptr);
        vkDestroyFence(p->device, p->fence, nullptr);
        vkDestroyCommandPool(p->device, p->commandPool, nullptr);
        vkDestroyDescriptorPool(p->device, p->descriptorPool, nullptr);
        vkDestroyRenderPass(p->device, p->renderPass, nullptr);
        vkDestroyDevice(p->device, nullptr);
    }
    if (p->surface) vkDestroySurfaceKHR(p->instance, p->surface, nullptr);
    vk::destroyInstance(p->instance, p->messenger);
    delete p;
}

void setImage(Presenter& p, const Image& image) {
    if (image.width == 0 || image.height == 0) return;
    ensureBuffer(p, p.staging, image.rgba.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    // The previous frame has finished (drawFrame waits), so the buffer is free to overwrite.
    vk::uploadBuffer(p.device, p.staging, image.rgba.data(), image.rgba.size());
    if (image.width != p.sceneWidth || image.height != p.sceneHeight)
        createSceneImage(p, image.width, image.height);
    p.sceneDirty = true;
    p.hasScene = true;
}

namespace {

// The engine's new image, from the staging buffer into the scene image.
void recordSceneUpload(Presenter& p) {
    vk::recordImageBarrier(p.cmd, p.sceneImage.image, VK_IMAGE_LAYOUT_UNDEFINED,
                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT,
                           VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
    VkBufferImageCopy region = {};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {p.sceneWidth, p.sceneHeight, 1};
    vkCmdCopyBufferToImage(p.cmd, p.staging.buffer, p.sceneImage.image,
                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    vk::recordImageBarrier(p.cmd, p.sceneImage.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                           VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
                           VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                           VK_PIPELINE_STAGE_TRANSFER_BIT);
    p.sceneDirty = false;
}

// The window's image cleared to the background, and the scene image or the mesh view blitted
// over it.
void recordBackground(Presenter& p, VkImage target, const float background[3], bool drawsMesh) {
    vk::recordImageBarrier(p.cmd, target, VK_IMAGE_LAYOUT_UNDEFINED,
                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT,
                           VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
    VkClearColorValue clear = {{background[0], background[1], background[2], 1.0f}};
    VkImageSubresourceRange range = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdClearColorImage(p.cmd, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &clear, 1, &range);
    if (p.hasScene || drawsMesh) {
        // The engine renders at the window's aspect ratio, at full or reduced size; stretching
        // fills the window either way. Same size (always so for the mesh): a plain copy of
        // every pixel.
        const VkImage source = drawsMesh ? p.meshColor.image : p.sceneImage.image;
        const uint32_t width = drawsMesh ? p.meshExtent.width : p.sceneWidth;
        const uint32_t height = drawsMesh ? p.meshExtent.height : p.sceneHeight;
        vk::recordImageBarrier(p.cmd, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                               VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
                               VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                               VK_PIPELINE_STAGE_TRANSFER_BIT);
        VkImageBlit blit = {};
        blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        blit.srcOffsets[1] = {int32_t(width), int32_t(height), 1};
        blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        blit.dstOffsets[1] = {int32_t(p.extent.width), int32_t(p.extent.height), 1};
        bool same = width == p.extent.width && height == p.extent.height;
        vkCmdBlitImage(p.cmd, source, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target,
                       VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit,
                       same ? VK_FILTER_NEAREST : VK_FILTER_LINEAR);
    }
}

// ImGui over the image, in the window's render pass, which leaves it ready to present.
void recordUi(Presenter& p, VkImage target, uint32_t index, ImDrawData* ui) {
    vk::recordImageBarrier(
        p.cmd, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
        VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
        VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
        VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT);
    VkRenderPassBeginInfo pass = {VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    pass.renderPass = p.renderPass;
    pass.framebuffer = p.framebuffers[index];
    pass.renderArea.extent = p.extent;
    vkCmdBeginRenderPass(p.cmd, &pass, VK_SUBPASS_CONTENTS_INLINE);
    if (ui) ImGui_ImplVulkan_RenderDrawData(ui, p.cmd);
    vkCmdEndRenderPass(p.cmd);
}

// The presented image, copied to the readback buffer for the host.
void recordCapture(Presenter& p, VkImage target) {
    ensureBuffer(p, p.readback, VkDeviceSize(p.extent.width) * p.extent.height * 4,
                 VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    vk::recordImageBarrier(
        p.cmd, target, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
        VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT,
        VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
    VkBufferImageCopy region = {};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {p.extent.width, p.extent.height, 1};
    vkCmdCopyImageToBuffer(p.cmd, target, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, p.readback.buffer,
                           1, &region);
    vk::recordImageBarrier(p.cmd, target, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_ACCESS_TRANSFER_READ_BIT, 0,
                           VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
    vk::recordBufferBarrier(p.cmd, p.readback.buffer, VK_ACCESS_TRANSFER_WRITE_BIT,
                            VK_ACCESS_HOST_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                            VK_PIPELINE_STAGE_HOST_BIT);
}

// Submits the frame and presents it, then waits for it: one frame in flight, as the image takes
// ~ms to draw and the engine's render is the slow part.
void submitAndPresent(Presenter& p, uint32_t index) {
    VkPipelineStageFlags waitStage = VK_PIPELINE_STAGE_TRANSFER_BIT;
    VkSubmitInfo submit = {VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.waitSemaphoreCount = 1;
    submit.pWaitSemaphores = &p.acquired;
    submit.pWaitDstStageMask = &waitStage;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &p.cmd;
    submit.signalSemaphoreCount = 1;
    submit.pSignalSemaphores = &p.rendered;
    VK_CHECK(vkQueueSubmit(p.queue, 1, &submit, p.fence));
    VkPresentInfoKHR present = {VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
    present.waitSemaphoreCount = 1;
    present.pWaitSemaphores = &p.rendered;
    present.swapchainCount = 1;
    present.pSwapchains = &p.swapchain;
    present.pImageIndices = &index;
    VkResult presented = vkQueuePresentKHR(p.queue, &present);
    if (presented == VK_ERROR_OUT_OF_DATE_KHR || presented == VK_SUBOPTIMAL_KHR)
        p.rebuild = true;
    else
        VK_CHECK(presented);
    VK_CHECK(vkWaitForFences(p.device, 1, &p.fence, VK_TRUE, UINT64_MAX));
    VK_CHECK(vkResetFences(p.device, 1, &p.fence));
}

// The mesh's drawing time, from the timestamps around it.
void readMeshTime(Presenter& p) {
    p.meshMs = -1.0;
    if (!p.timestamps) return;
    uint64_t ticks[2];
    VK_CHECK(vkGetQueryPoolResults(p.device, p.timestamps, 0, 2, sizeof ticks, ticks,
                                   sizeof(uint64_t),
                                   VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    p.meshMs =
        double((ticks[1] - ticks[0]) & p.timestampMask) * double(p.limits.timestampPeriod) * 1e-6;
}

// The captured window as RGBA8, from the readback buffer.
void readCapture(const Presenter& p, Image& capture) {
    capture.width = p.extent.width;
    capture.height = p.extent.height;
    capture.rgba.resize(size_t(p.extent.width) * p.extent.height * 4);
    vk::invalidateBuffer(p.device, p.readback);
    std::memcpy(capture.rgba.data(), p.readback.data, capture.rgba.size());
    bool bgra =
        p.format.format == VK_FORMAT_B8G8R8A8_UNORM || p.format.format == VK_FORMAT_B8G8R8A8_SRGB;
    for (size_t i = 0; i < capture.rgba.size(); i += 4) {
        if (bgra) std::swap(capture.rgba[i], capture.rgba[i + 2]);
        capture.rgba[i + 3] = 255;
    }
}

} // namespace

bool drawFrame(Presenter& p, ImDrawData* ui, const float background[3], const MeshView* mesh,
               Image* capture) {
    if (p.rebuild && !createSwapchain(p)) return false;
    uint32_t index = 0;
    VkResult acquired = vkAcquireNextImageKHR(p.device, p.swapchain, UINT64_MAX, p.acquired,
                                              VK_NULL_HANDLE, &index);
    if (acquired == VK_ERROR_OUT_OF_DATE_KHR) {
        p.rebuild = true;
        return false;
    }
    if (acquired != VK_SUBOPTIMAL_KHR) VK_CHECK(acquired);
    VkImage target = p.images[index];

    VK_CHECK(vkResetCommandBuffer(p.cmd, 0));
    vk::beginCommands(p.cmd);
    const bool drawsMesh = mesh && p.meshes[0].indexCount > 0;
    bool meshDrawn = false; // this frame
    if (drawsMesh) {
        ensureMeshTarget(p);
        std::vector<float> key = meshKey(p, *mesh, background);
        if (!p.meshDrawn || key != p.drawnKey) {
            drawMesh(p, *mesh, background);
            p.drawnKey = std::move(key);
            p.meshDrawn = meshDrawn = true;
        }
    }
    if (p.sceneDirty) recordSceneUpload(p);
    recordBackground(p, target, background, drawsMesh);
    recordUi(p, target, index, ui);
    bool capturing = capture && p.canCapture;
    if (capturing) recordCapture(p, target);
    VK_CHECK(vkEndCommandBuffer(p.cmd));
    submitAndPresent(p, index);
    if (meshDrawn) readMeshTime(p);
    if (capturing)
        readCapture(p, *capture);
    else if (capture)
        capture->width = capture->height = 0; // this surface cannot be read back
    return true;
}

uint32_t presenterValidationMessages(const Presenter& p) {
    return p.validationMessages.count.load();
}

std::string presenterDeviceName(const Presenter& p) {
    return p.deviceName;
}

} // namespace sdfcsg::viewer
