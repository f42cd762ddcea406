// The Presenter's state, shared by presenter.cpp (the instance and device, the swapchain, the
// engine's image and the frame) and mesh_view.cpp (the mesh view's pipelines, target, meshes and
// drawing). Only those two files include it; the rest of the viewer goes through presenter.h.
#pragma once

#include "presenter.h"

#include "vulkan_helpers.h" // the engine's helpers on plain handles, and VK_CHECK

#include <cstdint>
#include <string>
#include <vector>

namespace sdfcsg::viewer {

// In one device-local buffer: the vertices (MeshVertex), the triangles' indices, and for the
// wireframe the triangles' corners (three MeshVertex per triangle). The corners triple the memory
// (about 140 bytes a triangle in all), but lavapipe draws them faster than the welded vertices'
// edges as lines (62 against 300 ms at 717k triangles).
struct DeviceMesh {
    vk::Buffer buffer;
    VkDeviceSize indexOffset = 0, cornerOffset = 0;
    uint32_t indexCount = 0; // 0: no mesh
    // A colour per triangle (Mesh::triangleColors): drawn from the corners, which carry it.
    bool triangleColours = false;
};

struct Presenter {
    GLFWwindow* window = nullptr;
    VkInstance instance = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    vk::MessageCounter validationMessages{"(window) "};
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
    vk::Buffer staging;
    vk::Image sceneImage;
    uint32_t sceneWidth = 0, sceneHeight = 0;
    bool sceneDirty = false;
    bool hasScene = false;
    vk::Buffer readback;

    // The mesh view is drawn into an image of the window's size, then blitted as the engine's
    // image is: a frame whose camera, mesh and size are those of the last draw only blits it,
    // so panels stay quick over a mesh that takes long to draw (a CPU device).
    VkFormat depthFormat = VK_FORMAT_UNDEFINED;
    VkRenderPass meshPass = VK_NULL_HANDLE;
    vk::Image meshColor, meshDepth; // with their views
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

// ---- mesh_view.cpp ---------------------------------------------------------------------------

// The mesh view's render pass, pipelines and timestamp queries. The mesh comes in through
// fixed-function vertex input, one pipeline (per culling choice) for the shaded view and the
// wireframe; the ground grid is a line list that its vertex shader makes from the vertex index.
void createMeshPipeline(Presenter& p);
void destroyMeshTarget(Presenter& p);
// Called between frames (the previous frame has finished), so the old images are free.
void ensureMeshTarget(Presenter& p);
void destroyMesh(Presenter& p, DeviceMesh& m);
// What a drawing of the mesh depends on besides the meshes and the size.
std::vector<float> meshKey(const Presenter& p, const MeshView& view, const float background[3]);
// The mesh pass into meshColor, timed when the queue can.
void drawMesh(Presenter& p, const MeshView& view, const float background[3]);

} // namespace sdfcsg::viewer
