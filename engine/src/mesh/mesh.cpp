// Mesh extraction: marching cubes or dual contouring over the scene's generated field, in Vulkan
// compute passes.
//
// Per extraction:
//   cull       one value per brick of the grid (shaders/mesh_field.comp); the host compacts the
//              bricks that may hold surface into a list of slots and a map from brick to slot.
//   classify   per batch of active bricks, the brick's block of field values, its crossed
//              edges and brick-local vertex numbers, and its counts; the host turns the counts
//              into each brick's first vertex and triangle;
//   vertices   one point per crossed edge, on the surface, with normal and colour: marching
//              cubes' vertices, dual contouring's edge data;
//   triangles  after every batch is classified (a cell's edges may belong to a later brick),
//              marching cubes' index triples, from its table. Dual contouring instead places
//              its vertices, one per piece of surface in a cell, from the edge data of every
//              batch, and joins them by a quad per crossed edge, in one pass
//              (mesh_triangles.comp); the host turns each quad into the two triangles that fold
//              it least.
// Vertices and triangles come out in brick order, so the mesh is the same on every run.
#include "sdfcsg/mesh.h"

#include "codegen/scene_buffers.h"
#include "codegen/shader_compile.h"
#include "gpu/vk.h"
#include "mesh/mc_tables.h"
#include "mesh/mesh_colors.h"
#include "mesh/mesh_dual.h"
#include "render/camera.h"

#include "sdfcsg/compile.h"

#include "shared.h"

#include <glm/vec4.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <future>
#include <thread>
#include <vector>

namespace sdfcsg {
namespace {

using detail::Buffer;
using detail::MemoryUse;

constexpr uint32_t kBrick = SDFCSG_MESH_BRICK;
constexpr uint32_t kBatchBricks = 4096;   // bricks sampled and classified per submission
constexpr uint32_t kMaxGroups = 65535;    // the minimum maxComputeWorkGroupCount[0]
constexpr uint64_t kMaxActive = 1u << 22; // slots * SDFCSG_MESH_RECORD fits a uint32_t index
// Bytes each active brick holds for the whole extraction: slot, record, counts, bases.
constexpr uint64_t kBytesPerActive = 4 + SDFCSG_MESH_RECORD * 4 + 16 + 16;
// Bytes of the per-batch working buffers: samples and crossed edges.
constexpr uint64_t kBytesPerBatchBrick = 4 * (SDFCSG_MESH_BRICK_BLOCK + SDFCSG_MESH_BRICK_EDGES);
constexpr uint64_t kBytesPerVertex = 12 * 4 * 2; // GPU output and host mesh (or edge data)
constexpr uint64_t kBytesPerTriangle = 3 * 4 * 2;
// Dual contouring: seven words per quad of two triangles on the GPU, and six plus the number of
// its edge point on the host.
constexpr uint64_t kBytesPerDualTriangle = 14 + 14;
// The normal at an edge point, from four taps this many cells from its centre; for dual
// contouring also around centres kDualNormalOffset cells off the point either way (see
// placeVertices() in shaders/mesh_field.comp), whose taps must keep clear of the planes that
// the offset's direction avoids by 0.15 of it.
constexpr float kNormalTaps = 0.05f, kDualNormalTaps = 0.02f, kDualNormalOffset = 0.25f;

// Mirrors MeshGrid in shaders/mesh_common.glsl (std140).
struct MeshGrid {
    glm::vec4 origin;
    glm::uvec4 cells;
    glm::uvec4 bricks;
    glm::vec4 cull;
};

// Mirrors MeshPush in shaders/mesh_common.glsl.
struct MeshPush {
    uint32_t first = 0, count = 0, vertexBase = 0, triangleBase = 0;
};

constexpr detail::Binding kBindings[] = {
    {SDFCSG_BINDING_MESH_GRID, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
    {SDFCSG_BINDING_NODES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_MESH_TABLES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_MESH_ACTIVE, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_MESH_MAP, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_MESH_SAMPLES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_MESH_RECORDS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_MESH_COUNTS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_MESH_BASES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_MESH_EDGES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_MESH_VERTICES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_MESH_INDICES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_MESH_STATUS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_FIELD, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    {SDFCSG_BINDING_MESH_HERMITE, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
};
constexpr size_t kBindingCount = std::size(kBindings);

// The layout that shaders/mesh_tables.glsl reads. The kernels number a cell's corners
// canonically (bit ox + 2 oy + 4 oz for the corner at offset (ox, oy, oz)), so the cases are
// renumbered from the table's corner order.
std::vector<uint32_t> packTables() {
    auto bits = [](const int* o) { return uint32_t(o[0] | o[1] << 1 | o[2] << 2); };
    uint32_t cornerAt[8]; // table corner at each canonical position
    for (uint32_t c = 0; c < 8; ++c)
        cornerAt[bits(detail::kCornerOffset[c])] = c;
    std::vector<uint32_t> t(2596, 0);
    for (uint32_t canonical = 0; canonical < 256; ++canonical) {
        uint32_t c = 0;
        for (uint32_t k = 0; k < 8; ++k)
            if (canonical & (1u << k)) c |= 1u << cornerAt[k];
        t[canonical] = detail::kTriCount[c];
        for (int k = 0; k < 3 * detail::kTriCount[c]; ++k)
            t[256 + canonical * 4 + k / 4] |= uint32_t(uint8_t(detail::kTriTable[c][k]))
                                              << (8 * (k % 4));
    }
    for (int e = 0; e < 12; ++e)
        t[1280 + e] = bits(detail::kCornerOffset[detail::kEdgeCorners[e][0]]) | detail::kEdgeAxis[e]
                                                                                    << 3;
    for (uint32_t canonical = 0; canonical < 256; ++canonical) {
        uint32_t c = 0;
        for (uint32_t k = 0; k < 8; ++k)
            if (canonical & (1u << k)) c |= 1u << cornerAt[k];
        const detail::CellPatches pieces = detail::cellPatches(c);
        t[1292 + canonical] = uint32_t(pieces.count);
        for (int e = 0; e < 12; ++e)
            if (pieces.patch[e] >= 0) {
                t[1292 + canonical] |= uint32_t(pieces.patch[e]) << (3 + 2 * e);
                t[1572 + 4 * canonical + uint32_t(pieces.patch[e])] |= 1u << e;
            }
    }
    for (int e = 0; e < 12; ++e)
        t[1548 + 8 * detail::kEdgeAxis[e] +
          bits(detail::kCornerOffset[detail::kEdgeCorners[e][0]])] = uint32_t(e);
    return t;
}

struct Grid {
    glm::vec3 origin;
    float h;
    glm::uvec3 cells;
    glm::uvec3 bricks;
    uint64_t brickCount;
};

Error usage(std::string text) {
    return Error::message(ErrorKind::Usage, "<mesh>", std::move(text));
}

std::string mib(uint64_t bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f MiB", double(bytes) / (1024.0 * 1024.0));
    return text;
}

Error overBudget(const Grid& g, const std::string& what, uint64_t bytes, size_t budget) {
    return Error::message(ErrorKind::Limit, "<mesh>",
                          "a grid of " + std::to_string(g.cells.x) + " x " +
                              std::to_string(g.cells.y) + " x " + std::to_string(g.cells.z) +
                              " cells needs " + mib(bytes) + " for " + what +
                              ", more than the memory budget of " + mib(budget) +
                              "; lower the resolution or narrow the bounds");
}

Result<Grid> planGrid(const Evaluator& evaluator, const MeshOptions& options) {
    if (options.voxelSize && !(std::isfinite(*options.voxelSize) && *options.voxelSize > 0.0f))
        return usage("the voxel size must be a positive number");
    if (!options.voxelSize && options.resolution == 0)
        return usage("the resolution must be at least 1");
    Aabb box;
    float h = 0.0f;
    if (options.bounds) {
        box = *options.bounds;
        for (int a = 0; a < 3; ++a)
            if (!std::isfinite(box.min[a]) || !std::isfinite(box.max[a]) ||
                !(box.min[a] < box.max[a]))
                return usage("the bounds must be finite with min < max on every axis");
        glm::vec3 e = box.max - box.min;
        h = options.voxelSize ? *options.voxelSize
                              : std::max(e.x, std::max(e.y, e.z)) / float(options.resolution);
    } else {
        // The finite part of the scene, with a margin of a few cells so that the surface lies
        // strictly inside the grid.
        box = detail::finiteSceneBounds(evaluator);
        glm::vec3 e = box.max - box.min;
        float longest = std::max(std::max(e.x, e.y), std::max(e.z, 1e-6f));
        uint32_t margin = 3;
        if (options.voxelSize) {
            h = *options.voxelSize;
        } else {
            uint32_t n = options.resolution;
            margin = n >= 8 ? std::clamp(n / 32, 1u, 3u) : 0;
            h = longest / float(n - 2 * margin);
        }
        box.min -= glm::vec3(float(margin) * h);
        box.max += glm::vec3(float(margin) * h);
    }
    glm::vec3 extent = box.max - box.min;
    if (!std::isfinite(extent.x + extent.y + extent.z + h)) {
        const Aabb solid = detail::finiteSceneBounds(evaluator);
        const glm::vec3 reach = glm::max(glm::abs(solid.min), glm::abs(solid.max));
        char text[120];
        std::snprintf(text, sizeof text,
                      "the solid is too large for single precision: its bounds reach %.3g",
                      double(std::max({reach.x, reach.y, reach.z})));
        return Error::message(ErrorKind::Limit, "<mesh>", text);
    }
    Grid g;
    g.h = h;
    for (int a = 0; a < 3; ++a) {
        double n = std::ceil(double(extent[a]) / double(h) - 1e-3);
        if (!(n < double(1u << 24)))
            return Error::message(ErrorKind::Limit, "<mesh>",
                                  "the grid would have more than 16777216 cells along an axis; "
                                  "lower the resolution or narrow the bounds");
        g.cells[a] = std::max(1u, uint32_t(n));
        g.bricks[a] = g.cells[a] / kBrick + 1; // bricks cover samples 0..cells
    }
    g.origin = 0.5f * (box.min + box.max) - 0.5f * h * glm::vec3(g.cells);
    g.brickCount = uint64_t(g.bricks.x) * g.bricks.y * g.bricks.z;
    return g;
}

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

} // namespace

struct Mesher::Impl {
    Context::Impl& ctx;
    std::unique_ptr<Evaluator> evaluator;

    VkShaderModule field = VK_NULL_HANDLE;  // cull, classify and vertices passes
    VkShaderModule passes = VK_NULL_HANDLE; // triangle and dual passes
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    VkPipelineLayout pipelineLayout = VK_NULL_HANDLE;
    VkPipeline cull = VK_NULL_HANDLE, classify = VK_NULL_HANDLE, vertices = VK_NULL_HANDLE,
               triangles = VK_NULL_HANDLE, dualPass = VK_NULL_HANDLE;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VkDescriptorSet set = VK_NULL_HANDLE;

    detail::SceneBuffers sceneBuffers; // the node buffer and the field
    // Indexed by binding order in kBindings; those of the node buffer and the field stay empty
    // (sceneBuffers holds them). Buffers that an extraction sizes are freed at its end
    // (placeholders of 4 bytes stay, so the descriptor set is always complete).
    Buffer buffers[kBindingCount];

    explicit Impl(Context::Impl& c) : ctx(c), sceneBuffers(c) {}
    // No work of this mesher is pending between calls (submitAndWait() waits for it), and the
    // device may be busy with other threads' work: nothing to wait for.
    ~Impl() {
        for (Buffer& b : buffers)
            detail::destroyBuffer(ctx, b);
        for (VkPipeline p : {cull, classify, vertices, triangles, dualPass})
            if (p) vkDestroyPipeline(ctx.device, p, nullptr);
        for (VkShaderModule m : {field, passes})
            if (m) vkDestroyShaderModule(ctx.device, m, nullptr);
        if (pool) vkDestroyDescriptorPool(ctx.device, pool, nullptr);
        if (pipelineLayout) vkDestroyPipelineLayout(ctx.device, pipelineLayout, nullptr);
        if (setLayout) vkDestroyDescriptorSetLayout(ctx.device, setLayout, nullptr);
    }

    // Bounds tests pay off only where branches are real (see RenderOptions::boundsSkipping).
    bool cpuDevice() const { return ctx.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU; }

    // The specialisation of a pass: its kind and workgroup size, and for the field passes whether
    // the scene code tests bounds. The helper's compile of a pass must use the same.
    using Spec = std::array<detail::SpecConstant, 3>;
    Spec spec(uint32_t pass, uint32_t group) const {
        return Spec{{{SDFCSG_SPEC_MESH_PASS, pass},
                     {SDFCSG_SPEC_MESH_GROUP, group},
                     {SDFCSG_SPEC_BOUNDS_SKIPPING, cpuDevice() ? 0u : 1u}}};
    }
    // The dual pass's invocations share its lists of vertices and quads. A CPU driver runs a
    // workgroup as rows of SIMD lanes one after another, switching between them at each barrier:
    // one row of a brick's planes does the same work without the switches (mesh_a at 256: the
    // pass takes about 0.6 of the time with 64). A GPU wants its wider groups.
    Spec dualSpec() const {
        return spec(SDFCSG_MESH_PASS_DUAL, cpuDevice() ? SDFCSG_MESH_BRICK : SDFCSG_MESH_GROUP_X);
    }
    VkPipeline pipeline(VkShaderModule module, const Spec& s) {
        return detail::createComputePipeline(ctx, module, pipelineLayout, s);
    }

    Buffer& buffer(uint32_t binding) {
        for (size_t i = 0; i < kBindingCount; ++i)
            if (kBindings[i].binding == binding) return buffers[i];
        std::abort();
    }

    static MemoryUse memoryUse(uint32_t binding) {
        switch (binding) {
        case SDFCSG_BINDING_MESH_GRID:
        case SDFCSG_BINDING_NODES:
        case SDFCSG_BINDING_MESH_TABLES:
        case SDFCSG_BINDING_MESH_ACTIVE:
        case SDFCSG_BINDING_MESH_BASES:
        case SDFCSG_BINDING_MESH_HERMITE:
        case SDFCSG_BINDING_FIELD:
            return MemoryUse::Upload;
        case SDFCSG_BINDING_MESH_MAP: // written by the cull pass, read and rewritten by the host
        case SDFCSG_BINDING_MESH_COUNTS:
        case SDFCSG_BINDING_MESH_VERTICES:
        case SDFCSG_BINDING_MESH_INDICES:
        case SDFCSG_BINDING_MESH_STATUS:
            return MemoryUse::Staging;
        default:
            return MemoryUse::Device;
        }
    }

    // Makes the buffer of `binding` hold at least `bytes`; contents are not kept.
    Status reserve(uint32_t binding, uint64_t bytes) {
        Buffer& b = buffer(binding);
        if (b.buffer && b.size >= bytes) return Ok{};
        VkBufferUsageFlags usage = binding == SDFCSG_BINDING_MESH_GRID
                                       ? VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT
                                       : VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
        auto made = detail::createBuffer(ctx, bytes, usage, memoryUse(binding));
        if (!made) return made.error();
        detail::destroyBuffer(ctx, b);
        b = *made;
        writeDescriptors();
        return Ok{};
    }

    // Makes the host-visible buffer of `binding` hold at least `bytes`, keeping its contents.
    Status grow(uint32_t binding, uint64_t bytes) {
        Buffer& b = buffer(binding);
        if (b.buffer && b.size >= bytes) return Ok{};
        auto made = detail::createBuffer(ctx, std::max<uint64_t>(bytes, b.size + b.size / 2),
                                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, memoryUse(binding));
        if (!made) return made.error();
        detail::invalidateBuffer(ctx, b);
        if (b.size > 4) std::memcpy(made->data, b.data, b.size);
        detail::destroyBuffer(ctx, b);
        b = *made;
        writeDescriptors();
        return Ok{};
    }

    void writeDescriptors() {
        const Buffer* list[kBindingCount];
        for (size_t i = 0; i < kBindingCount; ++i)
            list[i] = kBindings[i].binding == SDFCSG_BINDING_NODES   ? &sceneBuffers.nodes()
                      : kBindings[i].binding == SDFCSG_BINDING_FIELD ? &sceneBuffers.field()
                                                                     : &buffers[i];
        detail::writeDescriptorSet(ctx, set, kBindings, list);
    }

    // Frees what an extraction sized, keeping the scene's buffers.
    void release() {
        for (size_t i = 0; i < kBindingCount; ++i) {
            uint32_t binding = kBindings[i].binding;
            if (binding == SDFCSG_BINDING_MESH_GRID || binding == SDFCSG_BINDING_NODES ||
                binding == SDFCSG_BINDING_MESH_TABLES || binding == SDFCSG_BINDING_MESH_STATUS ||
                binding == SDFCSG_BINDING_FIELD || buffers[i].size <= 4)
                continue;
            detail::destroyBuffer(ctx, buffers[i]);
            auto placeholder = detail::createBuffer(ctx, 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                                    memoryUse(binding));
            if (!placeholder) std::abort(); // 4 bytes
            buffers[i] = *placeholder;
        }
        writeDescriptors();
    }

    uint64_t heldBytes() const {
        uint64_t total = sceneBuffers.heldBytes();
        for (const Buffer& b : buffers)
            total += b.size;
        return total;
    }

    VkCommandBuffer begin(VkPipeline pipeline) {
        VkCommandBuffer cmd = detail::beginCommands(ctx);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 0, 1, &set, 0,
                                nullptr);
        return cmd;
    }

    void dispatch(VkCommandBuffer cmd, const MeshPush& push, uint32_t groups) {
        vkCmdPushConstants(cmd, pipelineLayout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
        vkCmdDispatch(cmd, groups, 1, 1);
    }

    // Shader writes -> host reads of the mapped output buffers.
    void finish(VkCommandBuffer cmd) {
        VkMemoryBarrier barrier = {VK_STRUCTURE_TYPE_MEMORY_BARRIER};
        barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
        barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                             0, 1, &barrier, 0, nullptr, 0, nullptr);
        detail::submitAndWait(ctx);
    }

    template <class T> const T* mapped(uint32_t binding) {
        const Buffer& b = buffer(binding);
        detail::invalidateBuffer(ctx, b);
        return static_cast<const T*>(b.data);
    }

    // Runs a pipeline on an empty batch: drivers that compile at first use (llvmpipe) do so here.
    void warmUp(VkPipeline p) {
        VkCommandBuffer cmd = begin(p);
        dispatch(cmd, MeshPush{}, 1);
        detail::submitAndWait(ctx);
    }

    // Set by run() when a triangle needed a vertex of a skipped brick: the field falls faster
    // than distance somewhere, and its result is wrong.
    bool skippedSurface = false;
    Result<Mesh> run(const MeshOptions& options, MeshStats& stats, bool cullBricks);

    // Mesher::create's steps: every binding's buffer, and the passes' pipelines.
    Status createBuffers();
    Status buildPasses(const std::string& sceneGlsl);
};

Mesher::Mesher(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Mesher::~Mesher() = default;
const Evaluator& Mesher::evaluator() const {
    return *impl_->evaluator;
}

Result<std::unique_ptr<Mesher>> Mesher::create(Context& context, const Scene& scene,
                                               Evaluation evaluation) {
    if (scene.nodes.empty()) return usage("the scene has no nodes");
    if (auto fits = checkEvaluation(scene, evaluation); !fits) return fits.error();
    auto impl = std::make_unique<Impl>(detail::contextImpl(context));
    Impl& m = *impl;
    m.evaluator = std::make_unique<Evaluator>(scene);
    // Pruned on the host while the kernels build, as in Renderer::create.
    auto fieldWords = std::async(std::launch::async, [&] {
        return detail::SceneBuffers::fieldWords(scene, *m.evaluator, evaluation, true);
    });

    CodegenOptions codegen;
    codegen.inlineParams = true;
    codegen.evaluation = evaluation;
    codegen.boundsTests = !m.cpuDevice();
    const std::string sceneGlsl = generateSceneGlsl(scene, codegen);
    m.setLayout = detail::createDescriptorSetLayout(m.ctx, kBindings);
    m.pipelineLayout = detail::createPipelineLayout(m.ctx, m.setLayout, sizeof(MeshPush));
    m.pool = detail::createDescriptorPool(m.ctx, kBindings);
    m.set = detail::allocateDescriptorSet(m.ctx, m.pool, m.setLayout);
    if (auto made = m.createBuffers(); !made) return made.error();
    if (auto built = m.buildPasses(sceneGlsl); !built) return built.error();

    auto words = fieldWords.get();
    if (!words) return words.error();
    auto made = m.sceneBuffers.uploadField(*words);
    if (!made) return made.error();
    if (*made) m.writeDescriptors();
    return std::unique_ptr<Mesher>(new Mesher(std::move(impl)));
}

Status Mesher::Impl::createBuffers() {
    const std::vector<uint32_t> tables = packTables();
    for (const detail::Binding& b : kBindings) {
        if (b.binding == SDFCSG_BINDING_NODES || b.binding == SDFCSG_BINDING_FIELD) continue;
        const uint64_t bytes = b.binding == SDFCSG_BINDING_MESH_GRID     ? sizeof(MeshGrid)
                               : b.binding == SDFCSG_BINDING_MESH_TABLES ? tables.size() * 4
                               : b.binding == SDFCSG_BINDING_MESH_STATUS ? 8
                                                                         : 4;
        auto made = detail::createBuffer(ctx, bytes,
                                         b.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER
                                             ? VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT
                                             : VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                         memoryUse(b.binding));
        if (!made) return made.error();
        buffer(b.binding) = *made;
    }
    if (auto made = sceneBuffers.create(*evaluator); !made) return made;
    detail::uploadBuffer(ctx, buffer(SDFCSG_BINDING_MESH_TABLES), tables.data(), tables.size() * 4);
    MeshGrid empty = {};
    detail::uploadBuffer(ctx, buffer(SDFCSG_BINDING_MESH_GRID), &empty, sizeof empty);
    writeDescriptors();
    return Ok{};
}

Status Mesher::Impl::buildPasses(const std::string& sceneGlsl) {
    // The kernels build on two threads. On llvmpipe, which makes a pipeline's machine code at its
    // first dispatch, on the one queue's thread, the other thread has the compile helper make the
    // dual pass (the longest compile, about as long as the three field passes together) while
    // this device compiles the field passes; this device's dual pass then loads the helper's
    // machine code. The marching-cubes triangle pass is made at the first extraction that
    // asks for it (run()).
    std::optional<Error> passesError;
    double helperMs = 0.0; // the helper's compile of the dual pass
    std::thread other([&] {
        bool fresh = false; // glslang made the SPIR-V: the driver has most likely not compiled it
        auto spirv = detail::compileKernel("mesh_triangles.comp", "", ctx.compile, fresh);
        if (!spirv) {
            passesError = spirv.error();
            return;
        }
        const Spec dual = dualSpec();
        if (fresh) {
            const detail::Precompile job{*spirv, dual};
            helperMs = detail::precompileElsewhere(ctx, {&job, 1}, kBindings, sizeof(MeshPush));
        }
        passes = detail::createShaderModule(ctx, *spirv);
        dualPass = pipeline(passes, dual);
    });
    bool fresh = false;
    auto spirv = detail::compileKernel("mesh_field.comp", sceneGlsl, ctx.compile, fresh);
    if (spirv) {
        field = detail::createShaderModule(ctx, *spirv);
        cull = pipeline(field, spec(SDFCSG_MESH_PASS_CULL, SDFCSG_MESH_GROUP_X));
        classify = pipeline(field, spec(SDFCSG_MESH_PASS_CLASSIFY, SDFCSG_MESH_CLASSIFY_X));
        vertices = pipeline(field, spec(SDFCSG_MESH_PASS_VERTICES, SDFCSG_MESH_GROUP_X));
        // Every pipeline runs once on an empty batch, so drivers that compile at first use
        // (llvmpipe) have done so before the first extraction is timed.
        for (VkPipeline p : {cull, classify, vertices})
            warmUp(p);
    }
    other.join();
    if (!spirv) return spirv.error();
    if (passesError) return *passesError;
    const auto start = std::chrono::steady_clock::now();
    warmUp(dualPass);
    const std::chrono::duration<double, std::milli> dualMs =
        std::chrono::steady_clock::now() - start;
    // Loading the helper's machine code takes a tenth of its compile or less.
    if (helperMs > 0.0 && dualMs.count() > 0.25 * helperMs) detail::compileHelperMissed(ctx);
    return Ok{};
}

std::optional<std::string> Mesher::whyEmpty(const MeshOptions& options) {
    if (provablyEmpty(*impl_->evaluator))
        return "the solid is empty: no point of its bounds lies inside it";
    if (options.bounds) return std::nullopt;
    // The smallest resolution that finds the surface: doubling from the one asked for, then
    // halving the gap. Coarse grids extract in a fraction of the first one's time.
    MeshOptions finer = options;
    finer.voxelSize.reset();
    auto finds = [&](uint32_t resolution) -> std::optional<bool> {
        finer.resolution = resolution;
        auto mesh = extract(finer);
        if (!mesh) return std::nullopt;
        return mesh->triangleCount() > 0;
    };
    constexpr uint32_t kFinest = 1024;
    uint32_t coarse = options.voxelSize ? 0 : options.resolution; // finds nothing
    uint32_t fine = coarse;
    for (;;) {
        if (fine >= kFinest)
            return "no grid of up to " + std::to_string(fine) +
                   " cells along the longest axis finds the surface";
        fine = std::min(std::max(2 * fine, 2u), kFinest);
        auto hit = finds(fine);
        if (!hit) return std::nullopt;
        if (*hit) break;
        coarse = fine;
    }
    while (fine - coarse > 1) {
        const uint32_t middle = coarse + (fine - coarse) / 2;
        auto found = finds(middle);
        if (!found) return std::nullopt;
        (*found ? fine : coarse) = middle;
    }
    return "the grid is too coarse to find the surface; resolution " + std::to_string(fine) +
           " is the smallest that does";
}

Result<Mesh> Mesher::extract(const MeshOptions& options, MeshStats* stats) {
    MeshStats local;
    MeshStats& s = stats ? *stats : local;
    Result<Mesh> mesh = impl_->run(options, s, true);
    if (impl_->skippedSurface) {
        // The field fell faster than distance somewhere, so a skipped brick held surface: mesh
        // every brick instead.
        s = MeshStats{};
        mesh = impl_->run(options, s, false);
    }
    impl_->release();
    return mesh;
}

namespace {

Error cancelled() {
    return Error::message(ErrorKind::Cancelled, "<mesh>", "cancelled");
}

// One run of the passes over one grid (Mesher::Impl::run), and what its steps share.
struct Extraction {
    using Clock = std::chrono::steady_clock;

    Mesher::Impl& m;
    const MeshOptions& options;
    MeshStats& stats;
    const Grid g;
    const bool dual = options.method == MeshMethod::DualContouring;
    // Marching cubes' index triples are the totals' y, dual contouring's their w.
    const int triangleKind = dual ? 3 : 1;
    size_t peak = 0; // bytes held at most
    // Progress: the cull counts one unit, each batch two (classify, vertices) and one for its
    // triangles.
    double progressTotal = 1, progressDone = 0;
    // Brick to slot (SDFCSG_MESH_NO_BRICK where it holds no surface), and slot to brick.
    std::vector<uint32_t> map, active;
    uint32_t activeCount = 0, batches = 0;
    uint64_t fixedBytes = 0; // what the bricks hold for the whole extraction
    // Per active brick: the first edge point, marching-cubes triangle, dual vertex and dual
    // triangle it makes.
    std::vector<glm::uvec4> bases;
    glm::u64vec4 totals{0};
    Mesh mesh;
    std::vector<glm::vec3> smooth;   // dual contouring: where foldQuads moves folding vertices
    std::vector<uint32_t> quadEdges; // dual contouring: each quad's edge point in the edge data

    void stage(const char* name, Clock::time_point t0) {
        const double seconds = secondsSince(t0);
        for (MeshStats::Stage& st : stats.stages)
            if (st.name == name) {
                st.seconds += seconds;
                return;
            }
        stats.stages.push_back({name, seconds});
    }
    void notePeak(uint64_t extra) { peak = std::max<size_t>(peak, m.heldBytes() + extra); }
    bool progress(double units) {
        progressDone += units;
        return !options.progress || options.progress(float(progressDone / progressTotal));
    }
    MeshPush batchOf(uint32_t batch) const {
        MeshPush push;
        push.first = batch * kBatchBricks;
        push.count = std::min(kBatchBricks, activeCount - push.first);
        return push;
    }
    // The [first, end) range of bases[.][k] over the batch of `push`.
    std::pair<uint32_t, uint64_t> batchRange(const MeshPush& push, int k) const {
        const uint64_t end =
            push.first + push.count < activeCount ? bases[push.first + push.count][k] : totals[k];
        return {bases[push.first][k], end};
    }

    Status begin(bool cullBricks);
    Status cull();
    Status reserveBricks();
    Status classify(MeshPush& push);
    Status vertices(MeshPush push);
    void beginTriangles();
    Status triangles(uint32_t batch);
    void finish();
};

// The grid's numbers: in the stats, checked against the budget (the brick map is known before
// any work), and uploaded; the marching-cubes triangle pass, made at its first use.
Status Extraction::begin(bool cullBricks) {
    stats.cells = g.cells;
    stats.voxelSize = g.h;
    stats.bounds = Aabb{g.origin, g.origin + g.h * glm::vec3(g.cells)};
    stats.bricks = g.brickCount;
    const uint64_t mapBytes = g.brickCount * 4 * 2; // on the device and on the host
    if (g.brickCount >= SDFCSG_MESH_NO_BRICK || mapBytes > options.memoryBudget)
        return overBudget(g, "its brick map", mapBytes, options.memoryBudget);

    MeshGrid gridUniform;
    gridUniform.origin = glm::vec4(g.origin, g.h);
    gridUniform.cells = glm::uvec4(g.cells, options.refineSteps);
    gridUniform.bricks = glm::uvec4(g.bricks, 0);
    const float halfDiagonal = 0.5f * std::sqrt(3.0f) * float(kBrick) * g.h;
    gridUniform.cull =
        glm::vec4(cullBricks ? halfDiagonal * 1.001f : INFINITY, dual ? kDualNormalOffset : 0.0f,
                  dual ? kDualNormalTaps : kNormalTaps, 0);
    detail::uploadBuffer(m.ctx, m.buffer(SDFCSG_BINDING_MESH_GRID), &gridUniform,
                         sizeof gridUniform);
    const uint32_t zero[2] = {0, 0};
    detail::uploadBuffer(m.ctx, m.buffer(SDFCSG_BINDING_MESH_STATUS), zero, sizeof zero);

    const auto t0 = Clock::now();
    if (!dual && !m.triangles) {
        m.triangles = m.pipeline(m.passes, m.spec(SDFCSG_MESH_PASS_TRIANGLES, SDFCSG_MESH_BRICK));
        m.warmUp(m.triangles);
        stage("compile", t0);
    }
    return Ok{};
}

// The cull pass, and the list of bricks that may hold surface that the host makes of it.
Status Extraction::cull() {
    const auto t0 = Clock::now();
    if (auto ok = m.reserve(SDFCSG_BINDING_MESH_MAP, g.brickCount * 4); !ok) return ok;
    VkCommandBuffer cmd = m.begin(m.cull);
    const uint64_t chunk = uint64_t(kMaxGroups) * SDFCSG_MESH_GROUP_X;
    for (uint64_t first = 0; first < g.brickCount; first += chunk) {
        MeshPush push;
        push.first = uint32_t(first);
        push.count = uint32_t(std::min(chunk, g.brickCount - first));
        m.dispatch(cmd, push, detail::groupCount(push.count, SDFCSG_MESH_GROUP_X));
    }
    m.finish(cmd);
    map.resize(g.brickCount);
    const uint32_t* flags = m.mapped<uint32_t>(SDFCSG_BINDING_MESH_MAP);
    for (uint64_t b = 0; b < g.brickCount; ++b) {
        map[b] = flags[b] ? uint32_t(active.size()) : SDFCSG_MESH_NO_BRICK;
        if (flags[b]) active.push_back(uint32_t(b));
    }
    stage("cull", t0);
    stats.activeBricks = active.size();
    activeCount = uint32_t(active.size());
    batches = (activeCount + kBatchBricks - 1) / kBatchBricks;
    progressTotal += 3.0 * batches;
    if (!progress(1)) return cancelled();
    return Ok{};
}

// Known once the bricks are culled: what the bricks hold for the whole extraction.
Status Extraction::reserveBricks() {
    const uint32_t batchBricks = std::min(activeCount, kBatchBricks);
    const uint64_t mapBytes = g.brickCount * 4 * 2;
    fixedBytes = mapBytes + activeCount * kBytesPerActive + batchBricks * kBytesPerBatchBrick;
    if (activeCount > kMaxActive || fixedBytes > options.memoryBudget)
        return overBudget(g, "the " + std::to_string(activeCount) + " bricks that hold surface",
                          fixedBytes, options.memoryBudget);
    detail::uploadBuffer(m.ctx, m.buffer(SDFCSG_BINDING_MESH_MAP), map.data(), map.size() * 4);
    for (auto [binding, bytes] :
         {std::pair{SDFCSG_BINDING_MESH_ACTIVE, activeCount * 4ull},
          {SDFCSG_BINDING_MESH_RECORDS, activeCount * uint64_t(SDFCSG_MESH_RECORD) * 4},
          {SDFCSG_BINDING_MESH_COUNTS, activeCount * 16ull},
          {SDFCSG_BINDING_MESH_BASES, activeCount * 16ull},
          {SDFCSG_BINDING_MESH_SAMPLES, batchBricks * uint64_t(SDFCSG_MESH_BRICK_BLOCK) * 4},
          {SDFCSG_BINDING_MESH_EDGES, batchBricks * uint64_t(SDFCSG_MESH_BRICK_EDGES) * 4}})
        if (auto ok = m.reserve(binding, bytes); !ok) return ok;
    if (activeCount)
        detail::uploadBuffer(m.ctx, m.buffer(SDFCSG_BINDING_MESH_ACTIVE), active.data(),
                             active.size() * 4);
    notePeak(map.size() * 4);
    bases.resize(activeCount);
    return Ok{};
}

// The classify pass over a batch, and its bricks' bases from their counts; sets the batch's
// first vertex.
Status Extraction::classify(MeshPush& push) {
    const auto t0 = Clock::now();
    VkCommandBuffer cmd = m.begin(m.classify);
    m.dispatch(cmd, push, push.count);
    m.finish(cmd);
    const glm::uvec4* counts = m.mapped<glm::uvec4>(SDFCSG_BINDING_MESH_COUNTS);
    for (uint32_t i = push.first; i < push.first + push.count; ++i) {
        bases[i] = glm::uvec4(totals);
        totals += glm::u64vec4(counts[i]);
    }
    push.vertexBase = bases[push.first].x;
    stage("classify", t0);
    if (!progress(1)) return cancelled();

    const uint64_t meshBytes = dual ? totals.x * kBytesPerVertex + totals.z * kBytesPerVertex +
                                          totals.w * kBytesPerDualTriangle
                                    : totals.x * kBytesPerVertex + totals.y * kBytesPerTriangle;
    if (totals.x > UINT32_MAX || totals.z > UINT32_MAX ||
        fixedBytes + meshBytes > options.memoryBudget)
        return overBudget(g, "the mesh", fixedBytes + meshBytes, options.memoryBudget);
    return Ok{};
}

// The vertices pass over a classified batch. Marching cubes takes the batch's vertices; dual
// contouring keeps every edge point for its dual pass.
Status Extraction::vertices(MeshPush push) {
    const uint64_t batchVertices = totals.x - push.vertexBase;
    auto t0 = Clock::now();
    detail::uploadBuffer(m.ctx, m.buffer(SDFCSG_BINDING_MESH_BASES), bases.data(),
                         bases.size() * 16);
    if (dual) push.vertexBase = 0;
    if (auto ok = dual ? m.grow(SDFCSG_BINDING_MESH_VERTICES, totals.x * 48)
                       : m.reserve(SDFCSG_BINDING_MESH_VERTICES, batchVertices * 48);
        !ok)
        return ok;
    VkCommandBuffer cmd = m.begin(m.vertices);
    m.dispatch(cmd, push,
               detail::groupCount(uint32_t(totals.x - bases[push.first].x), SDFCSG_MESH_GROUP_X));
    m.finish(cmd);
    stage("vertices", t0);

    t0 = Clock::now();
    if (!dual) {
        const float* v = m.mapped<float>(SDFCSG_BINDING_MESH_VERTICES);
        mesh.positions.resize(totals.x);
        mesh.normals.resize(totals.x);
        mesh.colors.resize(totals.x);
        for (uint64_t i = 0; i < batchVertices; ++i, v += 12) { // as in mesh_field.comp
            uint64_t o = push.vertexBase + i;
            mesh.positions[o] = glm::vec3(v[0], v[1], v[2]);
            mesh.normals[o] = glm::vec3(v[4], v[5], v[6]);
            mesh.colors[o] = glm::vec3(v[3], v[7], v[11]);
        }
    }
    stage("download", t0);
    notePeak(map.size() * 4 + mesh.positions.capacity() * 36);
    if (!progress(1)) return cancelled();
    return Ok{};
}

// After every batch is classified: the mesh's index triples, and for dual contouring its
// vertices, which the dual pass writes where the vertices pass wrote the edge data it reads.
void Extraction::beginTriangles() {
    mesh.indices.resize(totals[triangleKind] * 3);
    if (!dual) return;
    std::swap(m.buffer(SDFCSG_BINDING_MESH_VERTICES), m.buffer(SDFCSG_BINDING_MESH_HERMITE));
    m.writeDescriptors();
    mesh.positions.resize(totals.z);
    mesh.normals.resize(totals.z);
    mesh.colors.resize(totals.z);
    smooth.resize(totals.z);
    quadEdges.resize(totals.w / 2);
}

// The triangles (marching cubes) or dual (dual contouring) pass over a batch.
Status Extraction::triangles(uint32_t batch) {
    MeshPush push = batchOf(batch);
    auto [first, end] = batchRange(push, triangleKind);
    push.triangleBase = first;
    const uint64_t batchTriangles = end - first;
    auto [firstVertex, endVertex] = batchRange(push, 2);
    push.vertexBase = firstVertex;

    auto t0 = Clock::now();
    // Dual contouring writes seven words per quad of two triangles (see emitQuads in
    // shaders/mesh_triangles.comp).
    if (auto ok = m.reserve(SDFCSG_BINDING_MESH_INDICES, batchTriangles * (dual ? 14 : 12)); !ok)
        return ok;
    if (dual) {
        if (auto ok = m.reserve(SDFCSG_BINDING_MESH_VERTICES, (endVertex - firstVertex) * 48); !ok)
            return ok;
    }
    VkCommandBuffer cmd = m.begin(dual ? m.dualPass : m.triangles);
    m.dispatch(cmd, push, push.count);
    m.finish(cmd);
    stage(dual ? "dual" : "triangles", t0);

    t0 = Clock::now();
    if (dual) {
        const float* v = m.mapped<float>(SDFCSG_BINDING_MESH_VERTICES);
        for (uint64_t o = firstVertex; o < endVertex; ++o, v += 12) {
            mesh.positions[o] = glm::vec3(v[0], v[1], v[2]);
            mesh.normals[o] = glm::vec3(v[3], v[4], v[5]);
            mesh.colors[o] = glm::vec3(v[6], v[7], v[8]);
            smooth[o] = glm::vec3(v[9], v[10], v[11]);
        }
    }
    if (dual) {
        // Each quad's triangles, and the number of its edge point in the edge data.
        const uint32_t* words = m.mapped<uint32_t>(SDFCSG_BINDING_MESH_INDICES);
        for (uint64_t q = first / 2; q < end / 2; ++q, words += 7) {
            std::memcpy(mesh.indices.data() + 6 * q, words, 24);
            quadEdges[q] = words[6];
        }
    } else if (batchTriangles > 0) {
        // An empty vector's data() may be null, which memcpy must not get.
        std::memcpy(mesh.indices.data() + uint64_t(first) * 3,
                    m.mapped<uint32_t>(SDFCSG_BINDING_MESH_INDICES), batchTriangles * 12);
    }
    stage("download", t0);
    notePeak(map.size() * 4 + mesh.positions.capacity() * 36 + smooth.capacity() * 12 +
             mesh.indices.capacity() * 4 + quadEdges.capacity() * 4);
    if (!progress(1)) return cancelled();
    return Ok{};
}

// What the passes reported, and dual contouring's host step on quads that fold.
void Extraction::finish() {
    const uint32_t* status = m.mapped<uint32_t>(SDFCSG_BINDING_MESH_STATUS);
    m.skippedSurface = status[1] != 0;
    if (dual && !m.skippedSurface) {
        const auto t0 = Clock::now();
        // The field where the vertices need it: on scenes of pruned tapes, the CPU's whole tree
        // is too slow, and the tapes the kernels run answer instead (pruned once for both).
        const Evaluator& evaluator = *m.evaluator;
        detail::Distance distance = [&](glm::vec3 p) { return evaluator.distance(p); };
        if (evaluator.nodes().size() >= kTapeMinNodes)
            distance = [&](glm::vec3 p) { return evaluator.prunedDistance(p); };
        // The edge data, which the vertices pass wrote, lies where the dual pass read it.
        const auto* edges = m.mapped<detail::EdgePoint>(SDFCSG_BINDING_MESH_HERMITE);
        for (std::vector<glm::vec3>* positions : {&mesh.positions, &smooth})
            detail::pullToSurface(*positions, mesh.indices, quadEdges, edges, g.origin, g.h,
                                  distance, positions != &smooth);
        detail::foldQuads(mesh, smooth, distance, g.h);
        stage("quads", t0);
        const auto t1 = Clock::now();
        const size_t copiesFrom = mesh.vertexCount();
        detail::splitTouchingSheets(mesh);
        stage("sheets", t1);
        const auto t2 = Clock::now();
        detail::separateCrossings(mesh, copiesFrom, quadEdges, edges, g.origin, g.h, distance);
        if (options.unfold) detail::unfoldVertices(mesh, g.origin, g.h, distance);
        stage("crossings", t2);
    }
    // Colour borders, where asked for and where there can be any.
    const Evaluator& evaluator = *m.evaluator;
    if (options.colorRegions && detail::hasSeveralColours(evaluator)) {
        const auto t0 = Clock::now();
        detail::splitColourBorders(mesh, evaluator, g.h);
        stage("colours", t0);
    }
    stats.surfaceCut = status[0] != 0;
    stats.vertices = mesh.vertexCount();
    stats.triangles = mesh.triangleCount();
    stats.peakBytes = peak;
}

} // namespace

Result<Mesh> Mesher::Impl::run(const MeshOptions& options, MeshStats& stats, bool cullBricks) {
    const auto start = std::chrono::steady_clock::now();
    skippedSurface = false;
    auto grid = planGrid(*evaluator, options);
    if (!grid) return grid.error();
    Extraction x{*this, options, stats, *grid};
    if (auto ok = x.begin(cullBricks); !ok) return ok.error();
    if (auto ok = x.cull(); !ok) return ok.error();
    if (auto ok = x.reserveBricks(); !ok) return ok.error();
    for (uint32_t batch = 0; batch < x.batches; ++batch) {
        MeshPush push = x.batchOf(batch);
        if (auto ok = x.classify(push); !ok) return ok.error();
        if (auto ok = x.vertices(push); !ok) return ok.error();
    }
    x.beginTriangles();
    for (uint32_t batch = 0; batch < x.batches; ++batch)
        if (auto ok = x.triangles(batch); !ok) return ok.error();
    x.finish();
    stats.totalSeconds = secondsSince(start);
    return std::move(x.mesh);
}

Result<Mesh> extractMesh(Context& context, const Scene& scene, const MeshOptions& options,
                         MeshStats* stats) {
    auto mesher = Mesher::create(context, scene);
    if (!mesher) return mesher.error();
    return (*mesher)->extract(options, stats);
}

} // namespace sdfcsg
