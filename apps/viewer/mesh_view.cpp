// The mesh view: an extracted mesh drawn by the window's device with a graphics pipeline, into an
// image of the window's size that drawFrame() (presenter.cpp) blits as it does the engine's.
#include "presenter_internal.h"

#include <sdfcsg/camera.h> // the ray marcher's camera, so the mesh lines up with its images

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <string>
#include <vector>

namespace sdfcsg::viewer {

namespace {

// SPIR-V of shaders/mesh.vert, mesh.frag, grid.vert and grid.frag, compiled by
// glslangValidator during the build.
#include "grid_frag.h"
#include "grid_vert.h"
#include "mesh_frag.h"
#include "mesh_vert.h"

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

// Runs one command buffer's worth of work now and waits for it (uploads between frames).
template <typename Record> void submitNow(Presenter& p, Record record) {
    VK_CHECK(vkResetCommandBuffer(p.cmd, 0));
    vk::beginCommands(p.cmd);
    record(p.cmd);
    vk::submitAndWait(p.device, p.queue, p.cmd, p.fence);
}

// Colour cleared to the background and left ready for the blit; depth cleared, never kept.
void createMeshPass(Presenter& p) {
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
}

// The state of the mesh pipelines, which the grid's changes (grid()): they point at each
// other, so it stays where it was made.
struct PipelineState {
    VkPipelineShaderStageCreateInfo stages[2] = {};
    VkVertexInputBindingDescription binding = {0, sizeof(MeshVertex), VK_VERTEX_INPUT_RATE_VERTEX};
    VkVertexInputAttributeDescription attributes[3] = {
        {0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(MeshVertex, position)},
        {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(MeshVertex, normal)},
        {2, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(MeshVertex, color)}};
    VkPipelineVertexInputStateCreateInfo vertexInput = {
        VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    VkPipelineVertexInputStateCreateInfo noInput = {
        VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    VkPipelineInputAssemblyStateCreateInfo assembly = {
        VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    VkPipelineViewportStateCreateInfo viewport = {
        VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    VkPipelineRasterizationStateCreateInfo raster = {
        VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    VkPipelineMultisampleStateCreateInfo multisample = {
        VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    VkPipelineDepthStencilStateCreateInfo depth = {
        VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    VkPipelineColorBlendAttachmentState blendAttachment = {};
    VkPipelineColorBlendStateCreateInfo blend = {
        VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    VkDynamicState dynamicStates[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic = {
        VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    VkGraphicsPipelineCreateInfo info = {VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};

    PipelineState(const Presenter& p, VkShaderModule vert, VkShaderModule frag);
    PipelineState(const PipelineState&) = delete;
    PipelineState& operator=(const PipelineState&) = delete;
    // The grid: lines blended over the mesh, hidden behind it, writing no depth.
    void grid(VkShaderModule vert, VkShaderModule frag);
};

PipelineState::PipelineState(const Presenter& p, VkShaderModule vert, VkShaderModule frag) {
    for (int i = 0; i < 2; ++i) {
        stages[i] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
        stages[i].stage = i == 0 ? VK_SHADER_STAGE_VERTEX_BIT : VK_SHADER_STAGE_FRAGMENT_BIT;
        stages[i].module = i == 0 ? vert : frag;
        stages[i].pName = "main";
    }
    vertexInput.vertexBindingDescriptionCount = 1;
    vertexInput.pVertexBindingDescriptions = &binding;
    vertexInput.vertexAttributeDescriptionCount = 3;
    vertexInput.pVertexAttributeDescriptions = attributes;
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE; // seen from outside, as y points down
    raster.lineWidth = 1.0f;
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    depth.depthTestEnable = VK_TRUE;
    depth.depthWriteEnable = VK_TRUE;
    depth.depthCompareOp = VK_COMPARE_OP_GREATER; // reversed depth: nearer is larger
    blendAttachment.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                                     VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    blend.attachmentCount = 1;
    blend.pAttachments = &blendAttachment;
    dynamic.dynamicStateCount = 2;
    dynamic.pDynamicStates = dynamicStates;
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
}

void PipelineState::grid(VkShaderModule vert, VkShaderModule frag) {
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
    info.pVertexInputState = &noInput;
    stages[0].module = vert;
    stages[1].module = frag;
}

// Timestamps around the mesh's draw, where the queue has them (meshDrawMilliseconds()).
void createTimestamps(Presenter& p) {
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

} // namespace

void createMeshPipeline(Presenter& p) {
    VkPushConstantRange push = {VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                                sizeof(MeshConstants)};
    VkPipelineLayoutCreateInfo layoutInfo = {VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layoutInfo.pushConstantRangeCount = 1;
    layoutInfo.pPushConstantRanges = &push;
    VK_CHECK(vkCreatePipelineLayout(p.device, &layoutInfo, nullptr, &p.meshLayout));
    createMeshPass(p);

    VkShaderModule vert = vk::createShaderModule(p.device, kMeshVert);
    VkShaderModule frag = vk::createShaderModule(p.device, kMeshFrag);
    VkShaderModule gridVert = vk::createShaderModule(p.device, kGridVert);
    VkShaderModule gridFrag = vk::createShaderModule(p.device, kGridFrag);
    PipelineState state(p, vert, frag);
    // Culling back faces halves the triangles a CPU device sets up; only a closed mesh may,
    // since where bounds cut the surface open its inside shows.
    for (int cull = 0; cull < 2; ++cull) {
        state.raster.cullMode = cull ? VK_CULL_MODE_BACK_BIT : VK_CULL_MODE_NONE;
        VK_CHECK(vkCreateGraphicsPipelines(p.device, VK_NULL_HANDLE, 1, &state.info, nullptr,
                                           &p.meshPipelines[cull]));
    }
    state.grid(gridVert, gridFrag);
    VK_CHECK(vkCreateGraphicsPipelines(p.device, VK_NULL_HANDLE, 1, &state.info, nullptr,
                                       &p.gridPipeline));
    for (VkShaderModule m : {vert, frag, gridVert, gridFrag})
        vkDestroyShaderModule(p.device, m, nullptr);
    createTimestamps(p);
}

void destroyMeshTarget(Presenter& p) {
    if (p.meshFramebuffer) vkDestroyFramebuffer(p.device, p.meshFramebuffer, nullptr);
    p.meshFramebuffer = VK_NULL_HANDLE;
    vk::destroyImage(p.device, p.meshColor);
    vk::destroyImage(p.device, p.meshDepth);
    p.meshExtent = {};
    p.meshDrawn = false;
}

void ensureMeshTarget(Presenter& p) {
    if (p.meshFramebuffer && p.meshExtent.width == p.extent.width &&
        p.meshExtent.height == p.extent.height)
        return;
    destroyMeshTarget(p);
    p.meshColor =
        vk::createImage(p.device, p.memoryProperties, p.extent, VK_FORMAT_R8G8B8A8_UNORM,
                        VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                        VK_IMAGE_ASPECT_COLOR_BIT);
    p.meshDepth =
        vk::createImage(p.device, p.memoryProperties, p.extent, p.depthFormat,
                        VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_IMAGE_ASPECT_DEPTH_BIT);
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
    vk::destroyBuffer(p.device, m.buffer);
    m = DeviceMesh{};
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
    vk::Buffer staging;
    auto allocate = [&](VkBufferUsageFlags usage, vk::MemoryUse use, vk::Buffer& buffer) {
        // A fine mesh can exhaust the memory: the user's choice of resolution, not a bug.
        if (vk::createBuffer(p.device, p.memoryProperties, total, usage, use, buffer) == VK_SUCCESS)
            return true;
        error = "not enough memory to draw the mesh (" + std::to_string(total >> 20) + " MiB)";
        return false;
    };
    bool ok = allocate(VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUse::Staging, staging) &&
              allocate(VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_INDEX_BUFFER_BIT |
                           VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                       vk::MemoryUse::Device, m.buffer);
    if (ok) {
        auto* bytes = static_cast<unsigned char*>(staging.data);
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
        const bool flat = mesh.triangleColors.size() == mesh.triangleCount();
        for (size_t i = 0; i < mesh.indices.size(); ++i) {
            corners[i] = vertex(mesh.indices[i]);
            if (flat) corners[i].color = mesh.triangleColors[i / 3];
        }
        m.triangleColours = flat;
        vk::flushBuffer(p.device, staging);
        submitNow(p, [&](VkCommandBuffer cmd) {
            VkBufferCopy region = {0, 0, total};
            vkCmdCopyBuffer(cmd, staging.buffer, m.buffer.buffer, 1, &region);
            vk::recordBufferBarrier(cmd, m.buffer.buffer, VK_ACCESS_TRANSFER_WRITE_BIT,
                                    VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT | VK_ACCESS_INDEX_READ_BIT,
                                    VK_PIPELINE_STAGE_TRANSFER_BIT,
                                    VK_PIPELINE_STAGE_VERTEX_INPUT_BIT);
        });
    }
    vk::destroyBuffer(p.device, staging);
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

} // namespace

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
    const RayCamera rc = makeRayCamera(view.camera, p.extent.width, p.extent.height);
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
    if (view.wireframe || m.triangleColours) {
        vkCmdBindVertexBuffers(p.cmd, 0, 1, &m.buffer.buffer, &m.cornerOffset);
        vkCmdDraw(p.cmd, m.indexCount, 1, 0, 0);
    } else {
        const VkDeviceSize start = 0;
        vkCmdBindVertexBuffers(p.cmd, 0, 1, &m.buffer.buffer, &start);
        vkCmdBindIndexBuffer(p.cmd, m.buffer.buffer, m.indexOffset, VK_INDEX_TYPE_UINT32);
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

uint32_t previewMeshTriangles(const Presenter& p) {
    return p.meshes[1].indexCount / 3;
}

double meshDrawMilliseconds(const Presenter& p) {
    return p.meshMs;
}

} // namespace sdfcsg::viewer
