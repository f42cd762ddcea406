#include "presenter.h"

#include "render/camera.h"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_vulkan.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <vector>

namespace sdfcsg::viewer {

namespace {

// SPIR-V of shaders/mesh.vert, mesh.frag, grid.vert and grid.frag, compiled by
// glslangValidator during the build.
#include "grid_frag.h"
#include "grid_vert.h"
#include "mesh_frag.h"
#include "mesh_vert.h"

// As in the engine: a failing Vulkan call here is a bug or a lost device, not a user error.
void check(VkResult result, const char* call, int line) {
    if (result == VK_SUCCESS) return;
    std::fprintf(stderr, "%s:%d: %s failed: VkResult %d\n", __FILE__, line, call, int(result));
    std::abort();
}
#define VK_CHECK(call) check((call), #call, __LINE__)

void imguiCheck(VkResult result) {
    check(result, "ImGui Vulkan backend", __LINE__);
}

struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
    VkDeviceSize size = 0;
};

// An image the mesh is drawn into, with its memory and view.
struct Target {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
};

} // namespace

// In one device-local buffer: the vertices (MeshVertex), the triangles' indices, and for the
// wireframe the triangles' corners (three MeshVertex per triangle). The corners triple the memory
// (about 140 bytes a triangle in all), but lavapipe draws them faster than the welded vertices'
// edges as lines (62 against 300 ms at 717k triangles).
struct DeviceMesh {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize indexOffset = 0, cornerOffset = 0;
    uint32_t indexCount = 0; // 0: no mesh
};

struct Presenter {
    GLFWwindow* window = nullptr;
    VkInstance instance = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    std::atomic<uint32_t> validationMessages{0};
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    VkPhysicalDeviceMemoryProperties memoryProperties{};
    std::string deviceName;
    uint32_t family = 0;
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    VkSurfaceKHR surface = VK_NULL_HANDLE;
    VkSurfaceFormatKHR format{};
    VkRenderPass renderPass = VK_NULL_HANDLE;
    VkDescriptorPool descriptorPool = VK_NULL_HANDLE;
    VkCommandPool commandPool = VK_NULL_HANDLE;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    VkSemaphore acquired = VK_NULL_HANDLE, rendered = VK_NULL_HANDLE;

    VkSwapchainKHR swapchain = VK_NULL_HANDLE;
    VkExtent2D extent{};
    bool canCapture = false; // swapchain images allow TRANSFER_SRC
    std::vector<VkImage> images;
    std::vector<VkImageView> views;
    std::vector<VkFramebuffer> framebuffers;
    bool rebuild = true;

    // The engine's image: host staging buffer, device image it is copied into.
    Buffer staging;
    VkImage sceneImage = VK_NULL_HANDLE;
    VkDeviceMemory sceneMemory = VK_NULL_HANDLE;
    uint32_t sceneWidth = 0, sceneHeight = 0;
    bool sceneDirty = false;
    bool hasScene = false;
    Buffer readback;

    // The mesh view is drawn into an image of the window's size, then blitted as the engine's
    // image is: a frame whose camera, mesh and size are those of the last draw only blits it,
    // so panels stay quick over a mesh that takes long to draw (a CPU device).
    VkFormat depthFormat = VK_FORMAT_UNDEFINED;
    VkRenderPass meshPass = VK_NULL_HANDLE;
    Target meshColor, meshDepth;
    VkExtent2D meshExtent{};
    VkFramebuffer meshFramebuffer = VK_NULL_HANDLE;
    VkPhysicalDeviceLimits limits{};
    VkPipelineLayout meshLayout = VK_NULL_HANDLE;
    VkPipeline meshPipelines[2] = {}; // both sides, back faces culled
    VkPipeline gridPipeline = VK_NULL_HANDLE;
    bool meshDrawn = false; // meshColor holds the drawing described by drawnKey
    std::vector<float> drawnKey;
    DeviceMesh meshes[2];                    // the mesh and its preview (MeshView::preview)
    VkQueryPool timestamps = VK_NULL_HANDLE; // none when the queue cannot time
    uint64_t timestampMask = 0;
    double meshMs = -1.0;
};

// The push constants of shaders/mesh_draw.glsl.
struct MeshConstants {
    float eye[4], right[4], up[4], forward[4], line[4], grid[4];
};

// One vertex of the mesh as the vertex shader's inputs read it: the engine's Mesh keeps the
// three in arrays of their own, but one interleaved record reads a single cache line per
// vertex where three arrays would read three.
struct MeshVertex {
    glm::vec3 position, normal, color;
};
static_assert(sizeof(MeshVertex) == 36, "the vertex input reads tightly packed floats");

namespace {

VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                             VkDebugUtilsMessageTypeFlagsEXT,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data,
                                             void* user) {
    static_cast<Presenter*>(user)->validationMessages.fetch_add(1);
    const char* level =
        (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning";
    std::fprintf(stderr, "vulkan validation (window) %s: %s\n", level,
                 data && data->pMessage ? data->pMessage : "(no message)");
    return VK_FALSE;
}

// As for the engine's context: SDFCSG_VALIDATION (set by the tests) turns the validation layer
// on, here for the window's device, when the layer is installed.
bool wantValidation() {
    const char* env = std::getenv("SDFCSG_VALIDATION");
    if (!env || !*env || std::string_view(env) == "0") return false;
    uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> layers(count);
    vkEnumerateInstanceLayerProperties(&count, layers.data());
    for (const VkLayerProperties& l : layers)
        if (std::string_view(l.layerName) == "VK_LAYER_KHRONOS_validation") return true;
    return false;
}

uint32_t memoryType(const Presenter& p, uint32_t bits, VkMemoryPropertyFlags flags) {
    for (uint32_t i = 0; i < p.memoryProperties.memoryTypeCount; ++i)
        if ((bits & (1u << i)) &&
            (p.memoryProperties.memoryTypes[i].propertyFlags & flags) == flags)
            return i;
    std::fprintf(stderr, "presenter: no suitable memory type\n");
    std::abort();
}

void destroyBuffer(Presenter& p, Buffer& b) {
    if (b.buffer) vkDestroyBuffer(p.device, b.buffer, nullptr);
    if (b.memory) vkFreeMemory(p.device, b.memory, nullptr);
    b = {};
}

// Host-visible, coherent, persistently mapped.
void ensureBuffer(Presenter& p, Buffer& b, VkDeviceSize size, VkBufferUsageFlags usage) {
    if (b.size >= size) return;
    destroyBuffer(p, b);
    VkBufferCreateInfo info = {VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = size;
    info.usage = usage;
    VK_CHECK(vkCreateBuffer(p.device, &info, nullptr, &b.buffer));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(p.device, b.buffer, &req);
    VkMemoryAllocateInfo alloc = {VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex =
        memoryType(p, req.memoryTypeBits,
                   VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    VK_CHECK(vkAllocateMemory(p.device, &alloc, nullptr, &b.memory));
    VK_CHECK(vkBindBufferMemory(p.device, b.buffer, b.memory, 0));
    VK_CHECK(vkMapMemory(p.device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped));
    b.size = size;
}

void destroySceneImage(Presenter& p) {
    if (p.sceneImage) vkDestroyImage(p.device, p.sceneImage, nullptr);
    if (p.sceneMemory) vkFreeMemory(p.device, p.sceneMemory, nullptr);
    p.sceneImage = VK_NULL_HANDLE;
    p.sceneMemory = VK_NULL_HANDLE;
}

// A 2D image in device-local memory, in the undefined layout.
void createImage(Presenter& p, VkExtent2D extent, VkFormat format, VkImageUsageFlags usage,
                 VkImage& image, VkDeviceMemory& memory) {
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
    VK_CHECK(vkCreateImage(p.device, &info, nullptr, &image));
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(p.device, image, &req);
    VkMemoryAllocateInfo alloc = {VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = memoryType(p, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VK_CHECK(vkAllocateMemory(p.device, &alloc, nullptr, &memory));
    VK_CHECK(vkBindImageMemory(p.device, image, memory, 0));
}

void createSceneImage(Presenter& p, uint32_t width, uint32_t height) {
    destroySceneImage(p);
    // The bytes as the engine wrote them, no conversion.
    createImage(p, {width, height}, VK_FORMAT_R8G8B8A8_UNORM,
                VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, p.sceneImage,
                p.sceneMemory);
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

void destroyTarget(Presenter& p, Target& t) {
    if (t.view) vkDestroyImageView(p.device, t.view, nullptr);
    if (t.image) vkDestroyImage(p.device, t.image, nullptr);
    if (t.memory) vkFreeMemory(p.device, t.memory, nullptr);
    t = {};
}

Target createTarget(Presenter& p, VkExtent2D extent, VkFormat format, VkImageUsageFlags usage,
                    VkImageAspectFlags aspect) {
    Target t;
    createImage(p, extent, format, usage, t.image, t.memory);
    VkImageViewCreateInfo view = {VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view.image = t.image;
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = format;
    view.subresourceRange = {aspect, 0, 1, 0, 1};
    VK_CHECK(vkCreateImageView(p.device, &view, nullptr, &t.view));
    return t;
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

void barrier(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to,
             VkAccessFlags srcAccess, VkAccessFlags dstAccess, VkPipelineStageFlags srcStage,
             VkPipelineStageFlags dstStage) {
    VkImageMemoryBarrier b = {VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = srcAccess;
    b.dstAccessMask = dstAccess;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd, srcStage, dstStage, 0, 0, nullptr, 0, nullptr, 1, &b);
}

// The first depth-only format the device can render to (D16 always can); float depth first,
// since the mesh view's depth is reversed and precise only in floating point.
VkFormat chooseDepthFormat(VkPhysicalDevice physical) {
    for (VkFormat f : {VK_FORMAT_D32_SFLOAT, VK_FORMAT_X8_D24_UNORM_PACK32}) {
        VkFormatProperties props;
        vkGetPhysicalDeviceFormatProperties(physical, f, &props);
        if (props.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT) return f;
    }
    return VK_FORMAT_D16_UNORM;
}

VkShaderModule createShader(VkDevice device, const uint32_t* code, size_t bytes) {
    VkShaderModuleCreateInfo info = {VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    info.codeSize = bytes;
    info.pCode = code;
    VkShaderModule module;
    VK_CHECK(vkCreateShaderModule(device, &info, nullptr, &module));
    return module;
}

// The mesh view's render pass, pipelines and timestamp queries. The mesh comes in through
// fixed-function vertex input, one pipeline (per culling choice) for the shaded view and the
// wireframe; the ground grid is a line list that its vertex shader makes from the vertex index.
void createMeshPipeline(Presenter& p) {
    VkPushConstantRange push = {VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                                sizeof(MeshConstants)};
    VkPipelineLayoutCreateInfo layoutInfo = {VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layoutInfo.pushConstantRangeCount = 1;
    layoutInfo.pPushConstantRanges = &push;
    VK_CHECK(vkCreatePipelineLayout(p.device, &layoutInfo, nullptr, &p.meshLayout));

    // Colour cleared to the background and left ready for the blit; depth cleared, never kept.
    p.depthFormat = chooseDepthFormat(p.physical);
    VkAttachmentDescription attachments[2] = {};
    attachments[0].format = VK_FORMAT_R8G8B8A8_UNORM; // as the engine's image
    attachments[0].samples = VK_SAMPLE_COUNT_1_BIT;
    attachments[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    attachments[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    attachments[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    attachments[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    attachments[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    attachments[0].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    attachments[1] = attachments[0];
    attachments[1].format = p.depthFormat;
    attachments[1].storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    attachments[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    VkAttachmentReference colorRef = {0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkAttachmentReference depthRef = {1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    VkSubpassDescription subpass = {};
    subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    subpass.colorAttachmentCount = 1;
    subpass.pColorAttachments = &colorRef;
    subpass.pDepthStencilAttachment = &depthRef;
    VkSubpassDependency dependencies[2] = {};
    // Before: the last blit that read the colour image, the last draw's depth writes.
    dependencies[0].srcSubpass = VK_SUBPASS_EXTERNAL;
    dependencies[0].dstSubpass = 0;
    dependencies[0].srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT |
                                   VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                                   VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
    dependencies[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
                                   VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                                   VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
    dependencies[0].srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    dependencies[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT |
                                    VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                                    VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    // After: the blit into the window's image.
    dependencies[1].srcSubpass = 0;
    dependencies[1].dstSubpass = VK_SUBPASS_EXTERNAL;
    dependencies[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    dependencies[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
    dependencies[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    dependencies[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    VkRenderPassCreateInfo passInfo = {VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    passInfo.attachmentCount = 2;
    passInfo.pAttachments = attachments;
    passInfo.subpassCount = 1;
    passInfo.pSubpasses = &subpass;
    passInfo.dependencyCount = 2;
    passInfo.pDependencies = dependencies;
    VK_CHECK(vkCreateRenderPass(p.device, &passInfo, nullptr, &p.meshPass));

    VkShaderModule vert = createShader(p.device, kMeshVert, sizeof kMeshVert);
    VkShaderModule frag = createShader(p.device, kMeshFrag, sizeof kMeshFrag);
    VkShaderModule gridVert = createShader(p.device, kGridVert, sizeof kGridVert);
    VkShaderModule gridFrag = createShader(p.device, kGridFrag, sizeof kGridFrag);
    VkPipelineShaderStageCreateInfo stages[2] = {};
    stages[0] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = vert;
    stages[0].pName = "main";
    stages[1] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = frag;
    stages[1].pName = "main";
    VkVertexInputBindingDescription binding = {0, sizeof(MeshVertex), VK_VERTEX_INPUT_RATE_VERTEX};
    VkVertexInputAttributeDescription attributes[3] = {
        {0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(MeshVertex, position)},
        {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(MeshVertex, normal)},
        {2, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(MeshVertex, color)}};
    VkPipelineVertexInputStateCreateInfo vertexInput = {
        VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    vertexInput.vertexBindingDescriptionCount = 1;
    vertexInput.pVertexBindingDescriptions = &binding;
    vertexInput.vertexAttributeDescriptionCount = 3;
    vertexInput.pVertexAttributeDescriptions = attributes;
    VkPipelineInputAssemblyStateCreateInfo assembly = {
        VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo viewport = {
        VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo raster = {
        VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE; // seen from outside, as y points down
    raster.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo multisample = {
        VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    VkPipelineDepthStencilStateCreateInfo depth = {
        VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    depth.depthTestEnable = VK_TRUE;
    depth.depthWriteEnable = VK_TRUE;
    depth.depthCompareOp = VK_COMPARE_OP_GREATER; // reversed depth: nearer is larger
    VkPipelineColorBlendAttachmentState blendAttachment = {};
    blendAttachment.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                                     VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    VkPipelineColorBlendStateCreateInfo blend = {
        VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    blend.attachmentCount = 1;
    blend.pAttachments = &blendAttachment;
    VkDynamicState dynamicStates[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic = {
        VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamic.dynamicStateCount = 2;
    dynamic.pDynamicStates = dynamicStates;
    VkGraphicsPipelineCreateInfo info = {VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    info.stageCount = 2;
    info.pStages = stages;
    info.pVertexInputState = &vertexInput;
    info.pInputAssemblyState = &assembly;
    info.pViewportState = &viewport;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pDepthStencilState = &depth;
    info.pColorBlendState = &blend;
    info.pDynamicState = &dynamic;
    info.layout = p.meshLayout;
    info.renderPass = p.meshPass;
    // Culling back faces halves the triangles a CPU device sets up; only a closed mesh may,
    // since where bounds cut the surface open its inside shows.
    for (int cull = 0; cull < 2; ++cull) {
        raster.cullMode = cull ? VK_CULL_MODE_BACK_BIT : VK_CULL_MODE_NONE;
        VK_CHECK(vkCreateGraphicsPipelines(p.device, VK_NULL_HANDLE, 1, &info, nullptr,
                                           &p.meshPipelines[cull]));
    }
    // The grid: blended over the mesh, hidden behind it, writing no depth.
    raster.cullMode = VK_CULL_MODE_NONE;
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_LINE_LIST;
    depth.depthWriteEnable = VK_FALSE;
    blendAttachment.blendEnable = VK_TRUE;
    blendAttachment.srcColorBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA;
    blendAttachment.dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
    blendAttachment.colorBlendOp = VK_BLEND_OP_ADD;
    blendAttachment.srcAlphaBlendFactor = VK_BLEND_FACTOR_ZERO;
    blendAttachment.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    blendAttachment.alphaBlendOp = VK_BLEND_OP_ADD;
    VkPipelineVertexInputStateCreateInfo noInput = {
        VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    info.pVertexInputState = &noInput;
    stages[0].module = gridVert;
    stages[1].module = gridFrag;
    VK_CHECK(
        vkCreateGraphicsPipelines(p.device, VK_NULL_HANDLE, 1, &info, nullptr, &p.gridPipeline));
    for (VkShaderModule m : {vert, frag, gridVert, gridFrag})
        vkDestroyShaderModule(p.device, m, nullptr);

    uint32_t familyCount = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(p.physical, &familyCount, nullptr);
    std::vector<VkQueueFamilyProperties> families(familyCount);
    vkGetPhysicalDeviceQueueFamilyProperties(p.physical, &familyCount, families.data());
    uint32_t bits = families[p.family].timestampValidBits;
    if (bits > 0) {
        p.timestampMask = bits >= 64 ? ~0ull : (1ull << bits) - 1;
        VkQueryPoolCreateInfo query = {VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
        query.queryType = VK_QUERY_TYPE_TIMESTAMP;
        query.queryCount = 2;
        VK_CHECK(vkCreateQueryPool(p.device, &query, nullptr, &p.timestamps));
    }
}

void destroyMeshTarget(Presenter& p) {
    if (p.meshFramebuffer) vkDestroyFramebuffer(p.device, p.meshFramebuffer, nullptr);
    p.meshFramebuffer = VK_NULL_HANDLE;
    destroyTarget(p, p.meshColor);
    destroyTarget(p, p.meshDepth);
    p.meshExtent = {};
    p.meshDrawn = false;
}

// Called between frames (the previous frame has finished), so the old images are free.
void ensureMeshTarget(Presenter& p) {
    if (p.meshFramebuffer && p.meshExtent.width == p.extent.width &&
        p.meshExtent.height == p.extent.height)
        return;
    destroyMeshTarget(p);
    p.meshColor =
        createTarget(p, p.extent, VK_FORMAT_R8G8B8A8_UNORM,
                     VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                     VK_IMAGE_ASPECT_COLOR_BIT);
    p.meshDepth =
        createTarget(p, p.extent, p.depthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                     VK_IMAGE_ASPECT_DEPTH_BIT);
    VkImageView views[] = {p.meshColor.view, p.meshDepth.view};
    VkFramebufferCreateInfo fb = {VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fb.renderPass = p.meshPass;
    fb.attachmentCount = 2;
    fb.pAttachments = views;
    fb.width = p.extent.width;
    fb.height = p.extent.height;
    fb.layers = 1;
    VK_CHECK(vkCreateFramebuffer(p.device, &fb, nullptr, &p.meshFramebuffer));
    p.meshExtent = p.extent;
}

void destroyMesh(Presenter& p, DeviceMesh& m) {
    if (m.buffer) vkDestroyBuffer(p.device, m.buffer, nullptr);
    if (m.memory) vkFreeMemory(p.device, m.memory, nullptr);
    m = DeviceMesh{};
}

// Runs one command buffer's worth of work now and waits for it (uploads between frames).
template <typename Record> void submitNow(Presenter& p, Record record) {
    VK_CHECK(vkResetCommandBuffer(p.cmd, 0));
    VkCommandBufferBeginInfo begin = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(p.cmd, &begin));
    record(p.cmd);
    VK_CHECK(vkEndCommandBuffer(p.cmd));
    VkSubmitInfo submit = {VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &p.cmd;
    VK_CHECK(vkQueueSubmit(p.queue, 1, &submit, p.fence));
    VK_CHECK(vkWaitForFences(p.device, 1, &p.fence, VK_TRUE, UINT64_MAX));
    VK_CHECK(vkResetFences(p.device, 1, &p.fence));
}

} // namespace

PresenterPtr createPresenter(GLFWwindow* window, std::string& error) {
    PresenterPtr p(new Presenter);
    p->window = window;
    uint32_t extensionCount = 0;
    const char** extensions = glfwGetRequiredInstanceExtensions(&extensionCount);
    if (!extensions) {
        error = "GLFW found no Vulkan window-system support";
        return nullptr;
    }
    VkApplicationInfo app = {VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "sdfcsg-viewer";
    app.apiVersion = VK_API_VERSION_1_1;
    std::vector<const char*> instanceExtensions(extensions, extensions + extensionCount);
    const bool validation = wantValidation();
    const char* layer = "VK_LAYER_KHRONOS_validation";
    VkDebugUtilsMessengerCreateInfoEXT messengerInfo = {
        VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    messengerInfo.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                                    VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messengerInfo.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                                VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                                VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    messengerInfo.pfnUserCallback = debugCallback;
    messengerInfo.pUserData = p.get();
    VkInstanceCreateInfo instanceInfo = {VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    instanceInfo.pApplicationInfo = &app;
    if (validation) {
        instanceExtensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        instanceInfo.enabledLayerCount = 1;
        instanceInfo.ppEnabledLayerNames = &layer;
        instanceInfo.pNext = &messengerInfo;
    }
    instanceInfo.enabledExtensionCount = uint32_t(instanceExtensions.size());
    instanceInfo.ppEnabledExtensionNames = instanceExtensions.data();
    if (vkCreateInstance(&instanceInfo, nullptr, &p->instance) != VK_SUCCESS) {
        error = "could not create a Vulkan instance with window-system extensions";
        return nullptr;
    }
    if (validation) {
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(p->instance, "vkCreateDebugUtilsMessengerEXT"));
        VK_CHECK(create(p->instance, &messengerInfo, nullptr, &p->messenger));
    }
    if (glfwCreateWindowSurface(p->instance, window, nullptr, &p->surface) != VK_SUCCESS) {
        error = "could not create a Vulkan surface for the window";
        return nullptr;
    }
    // Any device that can draw to this window; a discrete GPU first.
    uint32_t count = 0;
    vkEnumeratePhysicalDevices(p->instance, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    vkEnumeratePhysicalDevices(p->instance, &count, devices.data());
    int bestScore = -1;
    for (VkPhysicalDevice d : devices) {
        uint32_t families = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(d, &families, nullptr);
        std::vector<VkQueueFamilyProperties> props(families);
        vkGetPhysicalDeviceQueueFamilyProperties(d, &families, props.data());
        for (uint32_t f = 0; f < families; ++f) {
            VkBool32 present = VK_FALSE;
            vkGetPhysicalDeviceSurfaceSupportKHR(d, f, p->surface, &present);
            if (!(props[f].queueFlags & VK_QUEUE_GRAPHICS_BIT) || !present) continue;
            VkPhysicalDeviceProperties dp;
            vkGetPhysicalDeviceProperties(d, &dp);
            int score = dp.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU     ? 3
                        : dp.deviceType == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU ? 2
                                                                                  : 1;
            if (score > bestScore) {
                bestScore = score;
                p->physical = d;
                p->family = f;
                p->deviceName = dp.deviceName;
            }
            break;
        }
    }
    if (!p->physical) {
        error = "no Vulkan device can present to this window";
        return nullptr;
    }
    vkGetPhysicalDeviceMemoryProperties(p->physical, &p->memoryProperties);
    float priority = 1.0f;
    VkDeviceQueueCreateInfo queueInfo = {VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queueInfo.queueFamilyIndex = p->family;
    queueInfo.queueCount = 1;
    queueInfo.pQueuePriorities = &priority;
    const char* deviceExtensions[] = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
    VkDeviceCreateInfo deviceInfo = {VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    deviceInfo.queueCreateInfoCount = 1;
    deviceInfo.pQueueCreateInfos = &queueInfo;
    deviceInfo.enabledExtensionCount = 1;
    deviceInfo.ppEnabledExtensionNames = deviceExtensions;
    VK_CHECK(vkCreateDevice(p->physical, &deviceInfo, nullptr, &p->device));
    vkGetDeviceQueue(p->device, p->family, 0, &p->queue);

    // A UNORM format, so the engine's bytes reach the screen (and screenshots) unchanged.
    uint32_t formatCount = 0;
    vkGetPhysicalDeviceSurfaceFormatsKHR(p->physical, p->surface, &formatCount, nullptr);
    std::vector<VkSurfaceFormatKHR> formats(formatCount);
    vkGetPhysicalDeviceSurfaceFormatsKHR(p->physical, p->surface, &formatCount, formats.data());
    p->format = formats.empty() ? VkSurfaceFormatKHR{VK_FORMAT_B8G8R8A8_UNORM,
                                                     VK_COLOR_SPACE_SRGB_NONLINEAR_KHR}
                                : formats[0];
    for (const VkSurfaceFormatKHR& f : formats)
        if (f.format == VK_FORMAT_B8G8R8A8_UNORM || f.format == VK_FORMAT_R8G8B8A8_UNORM) {
            p->format = f;
            break;
        }

    // ImGui draws over the blitted image: load, not clear.
    VkAttachmentDescription attachment = {};
    attachment.format = p->format.format;
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
    VK_CHECK(vkCreateRenderPass(p->device, &passInfo, nullptr, &p->renderPass));
    VkPhysicalDeviceProperties properties;
    vkGetPhysicalDeviceProperties(p->physical, &properties);
    p->limits = properties.limits;
    createMeshPipeline(*p);

    VkDescriptorPoolSize poolSize = {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 16};
    VkDescriptorPoolCreateInfo poolInfo = {VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    poolInfo.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
    poolInfo.maxSets = 16;
    poolInfo.poolSizeCount = 1;
    poolInfo.pPoolSizes = &poolSize;
    VK_CHECK(vkCreateDescriptorPool(p->device, &poolInfo, nullptr, &p->descriptorPool));

    VkCommandPoolCreateInfo cmdPool = {VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    cmdPool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    cmdPool.queueFamilyIndex = p->family;
    VK_CHECK(vkCreateCommandPool(p->device, &cmdPool, nullptr, &p->commandPool));
    VkCommandBufferAllocateInfo cmdInfo = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cmdInfo.commandPool = p->commandPool;
    cmdInfo.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cmdInfo.commandBufferCount = 1;
    VK_CHECK(vkAllocateCommandBuffers(p->device, &cmdInfo, &p->cmd));
    VkFenceCreateInfo fenceInfo = {VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK_CHECK(vkCreateFence(p->device, &fenceInfo, nullptr, &p->fence));
    VkSemaphoreCreateInfo semInfo = {VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VK_CHECK(vkCreateSemaphore(p->device, &semInfo, nullptr, &p->acquired));
    VK_CHECK(vkCreateSemaphore(p->device, &semInfo, nullptr, &p->rendered));

    VkSurfaceCapabilitiesKHR caps;
    VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(p->physical, p->surface, &caps));
    ImGui_ImplVulkan_InitInfo init = {};
    init.Instance = p->instance;
    init.PhysicalDevice = p->physical;
    init.Device = p->device;
    init.QueueFamily = p->family;
    init.Queue = p->queue;
    init.DescriptorPool = p->descriptorPool;
    init.MinImageCount = std::max(2u, caps.minImageCount);
    init.ImageCount = std::max(init.MinImageCount, 3u);
    init.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
    init.CheckVkResultFn = imguiCheck;
    ImGui_ImplVulkan_Init(&init, p->renderPass);

    // Fonts, once.
    VkCommandBufferBeginInfo begin = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(p->cmd, &begin));
    ImGui_ImplVulkan_CreateFontsTexture(p->cmd);
    VK_CHECK(vkEndCommandBuffer(p->cmd));
    VkSubmitInfo submit = {VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &p->cmd;
    VK_CHECK(vkQueueSubmit(p->queue, 1, &submit, VK_NULL_HANDLE));
    VK_CHECK(vkDeviceWaitIdle(p->device));
    ImGui_ImplVulkan_DestroyFontUploadObjects();
    return p;
}

void destroyPresenter(Presenter* p) {
    if (!p) return;
    if (p->device) {
        vkDeviceWaitIdle(p->device);
        if (p->renderPass) ImGui_ImplVulkan_Shutdown();
        destroyBuffer(*p, p->staging);
        destroyBuffer(*p, p->readback);
        destroySceneImage(*p);
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
    if (p->messenger) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(p->instance, "vkDestroyDebugUtilsMessengerEXT"));
        destroy(p->instance, p->messenger, nullptr);
    }
    if (p->instance) vkDestroyInstance(p->instance, nullptr);
    delete p;
}

void setImage(Presenter& p, const Image& image) {
    if (image.width == 0 || image.height == 0) return;
    ensureBuffer(p, p.staging, image.rgba.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    // The previous frame has finished (drawFrame waits), so the buffer is free to overwrite.
    std::memcpy(p.staging.mapped, image.rgba.data(), image.rgba.size());
    if (image.width != p.sceneWidth || image.height != p.sceneHeight)
        createSceneImage(p, image.width, image.height);
    p.sceneDirty = true;
    p.hasScene = true;
}

namespace {

bool uploadMesh(Presenter& p, DeviceMesh& m, const Mesh& mesh, std::string& error) {
    if (mesh.indices.empty() || mesh.positions.empty()) return true;
    if (mesh.vertexCount() - 1 > p.limits.maxDrawIndexedIndexValue) {
        error = "the mesh has too many vertices to draw on " + p.deviceName + " (" +
                std::to_string(mesh.vertexCount()) + ")";
        return false;
    }
    const VkDeviceSize vertexBytes = VkDeviceSize(mesh.vertexCount()) * sizeof(MeshVertex);
    const VkDeviceSize indexBytes = VkDeviceSize(mesh.indices.size()) * sizeof(uint32_t);
    const VkDeviceSize cornerBytes = VkDeviceSize(mesh.indices.size()) * sizeof(MeshVertex);
    const VkDeviceSize total = vertexBytes + indexBytes + cornerBytes; // multiples of 4
    // Through a staging buffer into device-local memory: the mesh is read every frame, and on a
    // discrete GPU host-visible memory would be read across the bus each time.
    auto allocate = [&](VkBufferUsageFlags usage, VkMemoryPropertyFlags flags, VkBuffer& buffer,
                        VkDeviceMemory& memory) {
        VkBufferCreateInfo info = {VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
        info.size = total;
        info.usage = usage;
        VK_CHECK(vkCreateBuffer(p.device, &info, nullptr, &buffer));
        VkMemoryRequirements req;
        vkGetBufferMemoryRequirements(p.device, buffer, &req);
        VkMemoryAllocateInfo alloc = {VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        alloc.allocationSize = req.size;
        alloc.memoryTypeIndex = memoryType(p, req.memoryTypeBits, flags);
        // A fine mesh can exhaust the memory: the user's choice of resolution, not a bug.
        VkResult result = vkAllocateMemory(p.device, &alloc, nullptr, &memory);
        if (result == VK_ERROR_OUT_OF_DEVICE_MEMORY || result == VK_ERROR_OUT_OF_HOST_MEMORY) {
            error = "not enough memory to draw the mesh (" + std::to_string(total >> 20) + " MiB)";
            return false;
        }
        VK_CHECK(result);
        VK_CHECK(vkBindBufferMemory(p.device, buffer, memory, 0));
        return true;
    };
    VkBuffer staging = VK_NULL_HANDLE;
    VkDeviceMemory stagingMemory = VK_NULL_HANDLE;
    bool ok = allocate(VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                       VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                       staging, stagingMemory) &&
              allocate(VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_INDEX_BUFFER_BIT |
                           VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                       VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, m.buffer, m.memory);
    if (ok) {
        void* mapped = nullptr;
        VK_CHECK(vkMapMemory(p.device, stagingMemory, 0, VK_WHOLE_SIZE, 0, &mapped));
        auto* bytes = static_cast<unsigned char*>(mapped);
        // Written from the mesh, never read back: mapped memory may be uncached.
        const bool coloured = mesh.colors.size() == mesh.positions.size();
        auto vertex = [&](size_t i) { // a mesh without colours is light grey
            return MeshVertex{mesh.positions[i], mesh.normals[i],
                              coloured ? mesh.colors[i] : glm::vec3(0.8f)};
        };
        auto* vertices = reinterpret_cast<MeshVertex*>(bytes);
        for (size_t i = 0; i < mesh.vertexCount(); ++i)
            vertices[i] = vertex(i);
        std::memcpy(bytes + vertexBytes, mesh.indices.data(), indexBytes);
        auto* corners = reinterpret_cast<MeshVertex*>(bytes + vertexBytes + indexBytes);
        for (size_t i = 0; i < mesh.indices.size(); ++i)
            corners[i] = vertex(mesh.indices[i]);
        vkUnmapMemory(p.device, stagingMemory);
        submitNow(p, [&](VkCommandBuffer cmd) {
            VkBufferCopy region = {0, 0, total};
            vkCmdCopyBuffer(cmd, staging, m.buffer, 1, &region);
            VkBufferMemoryBarrier b = {VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
            b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
            b.dstAccessMask = VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT | VK_ACCESS_INDEX_READ_BIT;
            b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
            b.buffer = m.buffer;
            b.size = VK_WHOLE_SIZE;
            vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT,
                                 VK_PIPELINE_STAGE_VERTEX_INPUT_BIT, 0, 0, nullptr, 1, &b, 0,
                                 nullptr);
        });
    }
    if (staging) vkDestroyBuffer(p.device, staging, nullptr);
    if (stagingMemory) vkFreeMemory(p.device, stagingMemory, nullptr);
    if (!ok) {
        destroyMesh(p, m);
        return false;
    }
    m.indexOffset = vertexBytes;
    m.indexCount = uint32_t(mesh.indices.size());
    m.cornerOffset = vertexBytes + indexBytes;
    return true;
}

} // namespace

bool setMesh(Presenter& p, const Mesh& mesh, const Mesh* preview, std::string& error) {
    VK_CHECK(vkDeviceWaitIdle(p.device)); // the last frame may still read the old buffers
    for (DeviceMesh& m : p.meshes)
        destroyMesh(p, m);
    p.meshDrawn = false;
    if (!uploadMesh(p, p.meshes[0], mesh, error)) return false;
    // The preview only speeds up moving views: one that does not fit leaves the mesh drawn
    // while the camera moves too, which is no error.
    std::string ignored;
    if (preview && !uploadMesh(p, p.meshes[1], *preview, ignored)) destroyMesh(p, p.meshes[1]);
    return true;
}

namespace {

// Which of the meshes a view draws: the preview while the camera moves, when there is one.
const DeviceMesh& shownMesh(const Presenter& p, const MeshView& view) {
    return view.preview && p.meshes[1].indexCount > 0 ? p.meshes[1] : p.meshes[0];
}

// What a drawing of the mesh depends on besides the meshes and the size.
std::vector<float> meshKey(const Presenter& p, const MeshView& view, const float background[3]) {
    const Camera& c = view.camera;
    const GroundGrid g = view.grid.value_or(GroundGrid{});
    return {c.eye.x,
            c.eye.y,
            c.eye.z,
            c.target.x,
            c.target.y,
            c.target.z,
            c.up.x,
            c.up.y,
            c.up.z,
            c.fov,
            background[0],
            background[1],
            background[2],
            float(view.wireframe),
            float(view.closed),
            float(view.grid.has_value()),
            g.centreX,
            g.centreZ,
            g.height,
            g.spacing,
            float(g.halfLines),
            float(&shownMesh(p, view) == &p.meshes[1])};
}

// The mesh pass into meshColor, timed when the queue can.
void drawMesh(Presenter& p, const MeshView& view, const float background[3]) {
    if (p.timestamps) vkCmdResetQueryPool(p.cmd, p.timestamps, 0, 2);
    VkRenderPassBeginInfo pass = {VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    pass.renderPass = p.meshPass;
    pass.framebuffer = p.meshFramebuffer;
    pass.renderArea.extent = p.extent;
    VkClearValue clears[2] = {};
    clears[0].color = {{background[0], background[1], background[2], 1.0f}};
    clears[1].depthStencil = {0.0f, 0}; // reversed depth: 0 is infinitely far
    pass.clearValueCount = 2;
    pass.pClearValues = clears;
    if (p.timestamps)
        vkCmdWriteTimestamp(p.cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, p.timestamps, 0);
    vkCmdBeginRenderPass(p.cmd, &pass, VK_SUBPASS_CONTENTS_INLINE);
    VkViewport viewport = {0, 0, float(p.extent.width), float(p.extent.height), 0, 1};
    VkRect2D scissor = {{0, 0}, p.extent};
    vkCmdSetViewport(p.cmd, 0, 1, &viewport);
    vkCmdSetScissor(p.cmd, 0, 1, &scissor);
    detail::RayCamera rc = detail::makeRayCamera(view.camera, p.extent.width, p.extent.height);
    glm::vec3 right = rc.right / (rc.tanHalfFov * rc.aspect), up = rc.up / rc.tanHalfFov;
    // Reversed float depth is precise at any distance, so the near plane can sit very close.
    float nearPlane = std::max(1e-6f, 1e-4f * glm::length(view.camera.target - view.camera.eye));
    const GroundGrid g = view.grid.value_or(GroundGrid{});
    MeshConstants c = {{rc.eye.x, rc.eye.y, rc.eye.z, nearPlane},
                       {right.x, right.y, right.z, rc.footprint},
                       {up.x, up.y, up.z, float(g.halfLines)},
                       {rc.forward.x, rc.forward.y, rc.forward.z, view.wireframe ? 1.0f : 0.0f},
                       {0.05f, 0.05f, 0.05f, 1.0f},
                       {g.centreX, g.centreZ, g.height, g.spacing}};
    const VkShaderStageFlags stages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
    vkCmdPushConstants(p.cmd, p.meshLayout, stages, 0, sizeof c, &c);
    vkCmdBindPipeline(p.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p.meshPipelines[view.closed]);
    const DeviceMesh& m = shownMesh(p, view);
    if (view.wireframe) {
        vkCmdBindVertexBuffers(p.cmd, 0, 1, &m.buffer, &m.cornerOffset);
        vkCmdDraw(p.cmd, m.indexCount, 1, 0, 0);
    } else {
        const VkDeviceSize start = 0;
        vkCmdBindVertexBuffers(p.cmd, 0, 1, &m.buffer, &start);
        vkCmdBindIndexBuffer(p.cmd, m.buffer, m.indexOffset, VK_INDEX_TYPE_UINT32);
        vkCmdDrawIndexed(p.cmd, m.indexCount, 1, 0, 0, 0);
    }
    if (view.grid) { // two lines of two vertices each per step along each axis
        vkCmdBindPipeline(p.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p.gridPipeline);
        vkCmdDraw(p.cmd, 4 * uint32_t(2 * g.halfLines + 1), 1, 0, 0);
    }
    vkCmdEndRenderPass(p.cmd);
    if (p.timestamps)
        vkCmdWriteTimestamp(p.cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, p.timestamps, 1);
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
    VkCommandBufferBeginInfo begin = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(p.cmd, &begin));
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
    if (p.sceneDirty) {
        barrier(p.cmd, p.sceneImage, VK_IMAGE_LAYOUT_UNDEFINED,
                VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT,
                VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
        VkBufferImageCopy region = {};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = {p.sceneWidth, p.sceneHeight, 1};
        vkCmdCopyBufferToImage(p.cmd, p.staging.buffer, p.sceneImage,
                               VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        barrier(p.cmd, p.sceneImage, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
                VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                VK_PIPELINE_STAGE_TRANSFER_BIT);
        p.sceneDirty = false;
    }
    barrier(p.cmd, target, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
            VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
            VK_PIPELINE_STAGE_TRANSFER_BIT);
    VkClearColorValue clear = {{background[0], background[1], background[2], 1.0f}};
    VkImageSubresourceRange range = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdClearColorImage(p.cmd, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &clear, 1, &range);
    if (p.hasScene || drawsMesh) {
        // The engine renders at the window's aspect ratio, at full or reduced size; stretching
        // fills the window either way. Same size (always so for the mesh): a plain copy of
        // every pixel.
        const VkImage source = drawsMesh ? p.meshColor.image : p.sceneImage;
        const uint32_t width = drawsMesh ? p.meshExtent.width : p.sceneWidth;
        const uint32_t height = drawsMesh ? p.meshExtent.height : p.sceneHeight;
        barrier(p.cmd, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
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
    barrier(p.cmd, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
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
    bool capturing = capture && p.canCapture;
    if (capturing) {
        ensureBuffer(p, p.readback, VkDeviceSize(p.extent.width) * p.extent.height * 4,
                     VK_BUFFER_USAGE_TRANSFER_DST_BIT);
        barrier(p.cmd, target, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
                VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                VK_PIPELINE_STAGE_TRANSFER_BIT);
        VkBufferImageCopy region = {};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = {p.extent.width, p.extent.height, 1};
        vkCmdCopyImageToBuffer(p.cmd, target, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                               p.readback.buffer, 1, &region);
        barrier(p.cmd, target, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_ACCESS_TRANSFER_READ_BIT, 0,
                VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
        VkBufferMemoryBarrier host = {VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
        host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
        host.srcQueueFamilyIndex = host.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        host.buffer = p.readback.buffer;
        host.size = VK_WHOLE_SIZE;
        vkCmdPipelineBarrier(p.cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0,
                             0, nullptr, 1, &host, 0, nullptr);
    }
    VK_CHECK(vkEndCommandBuffer(p.cmd));

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
    // One frame in flight: the image takes ~ms to draw, the engine's render is the slow part.
    VK_CHECK(vkWaitForFences(p.device, 1, &p.fence, VK_TRUE, UINT64_MAX));
    VK_CHECK(vkResetFences(p.device, 1, &p.fence));
    if (meshDrawn) p.meshMs = -1.0;
    if (meshDrawn && p.timestamps) {
        uint64_t ticks[2];
        VK_CHECK(vkGetQueryPoolResults(p.device, p.timestamps, 0, 2, sizeof ticks, ticks,
                                       sizeof(uint64_t),
                                       VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
        p.meshMs = double((ticks[1] - ticks[0]) & p.timestampMask) *
                   double(p.limits.timestampPeriod) * 1e-6;
    }

    if (capturing) {
        capture->width = p.extent.width;
        capture->height = p.extent.height;
        capture->rgba.resize(size_t(p.extent.width) * p.extent.height * 4);
        std::memcpy(capture->rgba.data(), p.readback.mapped, capture->rgba.size());
        bool bgra = p.format.format == VK_FORMAT_B8G8R8A8_UNORM ||
                    p.format.format == VK_FORMAT_B8G8R8A8_SRGB;
        for (size_t i = 0; i < capture->rgba.size(); i += 4) {
            if (bgra) std::swap(capture->rgba[i], capture->rgba[i + 2]);
            capture->rgba[i + 3] = 255;
        }
    } else if (capture) {
        capture->width = capture->height = 0; // this surface cannot be read back
    }
    return true;
}

uint32_t previewMeshTriangles(const Presenter& p) {
    return p.meshes[1].indexCount / 3;
}

double meshDrawMilliseconds(const Presenter& p) {
    return p.meshMs;
}

uint32_t presenterValidationMessages(const Presenter& p) {
    return p.validationMessages.load();
}

std::string presenterDeviceName(const Presenter& p) {
    return p.deviceName;
}

} // namespace sdfcsg::viewer
