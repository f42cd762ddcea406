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

#include "codegen/gpu_nodes.h"
#include "codegen/shader_compile.h"
#include "gpu/vk.h"
#include "mesh/mc_tables.h"
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
    Grid g;
    g.h = h;
    glm::vec3 extent = box.max - box.min;
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

    // Indexed by binding order in kBindings. Buffers that an extraction sizes are freed at its
    // end (placeholders of 4 bytes stay, so the descriptor set is always complete).
    Buffer buffers[kBindingCount];

    explicit Impl(Context::Impl& c) : ctx(c) {}
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
            list[i] = &buffers[i];
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
        uint64_t total = 0;
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
};

Mesher::Mesher(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Mesher::~Mesher() = default;

Result<std::unique_ptr<Mesher>> Mesher::create(Context& context, const Scene& scene,
                                               Evaluation evaluation) {
    if (scene.nodes.empty()) return usage("the scene has no nodes");
    auto impl = std::make_unique<Impl>(detail::contextImpl(context));
    Impl& m = *impl;
    m.evaluator = std::make_unique<Evaluator>(scene);
    // Pruned on the host while the kernels build, as in Renderer::create.
    auto fieldWords = std::async(
        std::launch::async, [&] { return detail::fieldWords(scene, *m.evaluator, evaluation); });

    CodegenOptions codegen;
    codegen.inlineParams = true;
    codegen.evaluation = evaluation;
    codegen.boundsTests = !m.cpuDevice();
    const std::string sceneGlsl = generateSceneGlsl(scene, codegen);
    m.setLayout = detail::createDescriptorSetLayout(m.ctx, kBindings);
    m.pipelineLayout = detail::createPipelineLayout(m.ctx, m.setLayout, sizeof(MeshPush));
    m.pool = detail::createDescriptorPool(m.ctx, kBindings);
    m.set = detail::allocateDescriptorSet(m.ctx, m.pool, m.setLayout);
    std::vector<detail::GpuNode> nodes = detail::packNodes(*m.evaluator);
    std::vector<uint32_t> tables = packTables();
    for (const detail::Binding& b : kBindings) {
        uint64_t bytes = b.binding == SDFCSG_BINDING_MESH_GRID     ? sizeof(MeshGrid)
                         : b.binding == SDFCSG_BINDING_NODES       ? nodes.size() * sizeof nodes[0]
                         : b.binding == SDFCSG_BINDING_MESH_TABLES ? tables.size() * 4
                         : b.binding == SDFCSG_BINDING_MESH_STATUS ? 8
                         : b.binding == SDFCSG_BINDING_FIELD       ? 0 // uploadField() makes it
                                                                   : 4;
        if (b.binding == SDFCSG_BINDING_FIELD) continue;
        auto made = detail::createBuffer(m.ctx, bytes,
                                         b.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER
                                             ? VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT
                                             : VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                         Impl::memoryUse(b.binding));
        if (!made) return made.error();
        m.buffer(b.binding) = *made;
    }
    detail::uploadBuffer(m.ctx, m.buffer(SDFCSG_BINDING_NODES), nodes.data(),
                         nodes.size() * sizeof nodes[0]);
    detail::uploadBuffer(m.ctx, m.buffer(SDFCSG_BINDING_MESH_TABLES), tables.data(),
                         tables.size() * 4);
    if (auto made =
            detail::uploadField(m.ctx, m.buffer(SDFCSG_BINDING_FIELD), detail::emptyField());
        !made)
        return made.error();
    MeshGrid empty = {};
    detail::uploadBuffer(m.ctx, m.buffer(SDFCSG_BINDING_MESH_GRID), &empty, sizeof empty);
    m.writeDescriptors();

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
        auto spirv = detail::compileKernel("mesh_triangles.comp", "", m.ctx.compile, fresh);
        if (!spirv) {
            passesError = spirv.error();
            return;
        }
        const Impl::Spec dual = m.dualSpec();
        if (fresh) {
            const detail::Precompile job{*spirv, dual};
            helperMs = detail::precompileElsewhere(m.ctx, {&job, 1}, kBindings, sizeof(MeshPush));
        }
        m.passes = detail::createShaderModule(m.ctx, *spirv);
        m.dualPass = m.pipeline(m.passes, dual);
    });
    bool fresh = false;
    auto spirv = detail::compileKernel("mesh_field.comp", sceneGlsl, m.ctx.compile, fresh);
    if (spirv) {
        m.field = detail::createShaderModule(m.ctx, *spirv);
        m.cull = m.pipeline(m.field, m.spec(SDFCSG_MESH_PASS_CULL, SDFCSG_MESH_GROUP_X));
        m.classify = m.pipeline(m.field, m.spec(SDFCSG_MESH_PASS_CLASSIFY, SDFCSG_MESH_BRICK));
        m.vertices = m.pipeline(m.field, m.spec(SDFCSG_MESH_PASS_VERTICES, SDFCSG_MESH_GROUP_X));
        // Every pipeline runs once on an empty batch, so drivers that compile at first use
        // (llvmpipe) have done so before the first extraction is timed.
        for (VkPipeline p : {m.cull, m.classify, m.vertices})
            m.warmUp(p);
    }
    other.join();
    if (!spirv) return spirv.error();
    if (passesError) return *passesError;
    const auto start = std::chrono::steady_clock::now();
    m.warmUp(m.dualPass);
    const std::chrono::duration<double, std::milli> dualMs =
        std::chrono::steady_clock::now() - start;
    // Loading the helper's machine code takes a tenth of its compile or less.
    if (helperMs > 0.0 && dualMs.count() > 0.25 * helperMs) detail::compileHelperMissed(m.ctx);

    auto words = fieldWords.get();
    if (!words) return words.error();
    auto made = detail::uploadField(m.ctx, m.buffer(SDFCSG_BINDING_FIELD), *words);
    if (!made) return made.error();
    if (*made) m.writeDescriptors();
    return std::unique_ptr<Mesher>(new Mesher(std::move(impl)));
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

Result<Mesh> Mesher::Impl::run(const MeshOptions& options, MeshStats& stats, bool cullBricks) {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    skippedSurface = false;
    auto grid = planGrid(*evaluator, options);
    if (!grid) return grid.error();
    const Grid& g = *grid;
    stats.cells = g.cells;
    stats.voxelSize = g.h;
    stats.bounds = Aabb{g.origin, g.origin + g.h * glm::vec3(g.cells)};
    stats.bricks = g.brickCount;
    auto stage = [&](const char* name, Clock::time_point t0) {
        double seconds = secondsSince(t0);
        for (MeshStats::Stage& st : stats.stages)
            if (st.name == name) {
                st.seconds += seconds;
                return;
            }
        stats.stages.push_back({name, seconds});
    };
    size_t peak = 0;
    auto notePeak = [&](uint64_t extra) { peak = std::max<size_t>(peak, heldBytes() + extra); };

    // Known before any work: the brick map, on the device and on the host.
    const uint64_t mapBytes = g.brickCount * 4 * 2;
    if (g.brickCount >= SDFCSG_MESH_NO_BRICK || mapBytes > options.memoryBudget)
        return overBudget(g, "its brick map", mapBytes, options.memoryBudget);

    // Progress: the cull counts one unit, each batch two (classify, vertices) and one for its
    // triangles.
    double progressTotal = 1, progressDone = 0;
    auto progress = [&](double units) {
        progressDone += units;
        return !options.progress || options.progress(float(progressDone / progressTotal));
    };
    const Error cancelled = Error::message(ErrorKind::Cancelled, "<mesh>", "cancelled");

    MeshGrid gridUniform;
    gridUniform.origin = glm::vec4(g.origin, g.h);
    gridUniform.cells = glm::uvec4(g.cells, options.refineSteps);
    gridUniform.bricks = glm::uvec4(g.bricks, 0);
    const float halfDiagonal = 0.5f * std::sqrt(3.0f) * float(kBrick) * g.h;
    const bool dual = options.method == MeshMethod::DualContouring;
    gridUniform.cull =
        glm::vec4(cullBricks ? halfDiagonal * 1.001f : INFINITY, dual ? kDualNormalOffset : 0.0f,
                  dual ? kDualNormalTaps : kNormalTaps, 0);
    detail::uploadBuffer(ctx, buffer(SDFCSG_BINDING_MESH_GRID), &gridUniform, sizeof gridUniform);
    const uint32_t zero[2] = {0, 0};
    detail::uploadBuffer(ctx, buffer(SDFCSG_BINDING_MESH_STATUS), zero, sizeof zero);

    auto t0 = Clock::now();
    if (!dual && !triangles) { // the marching-cubes triangle pass, made at its first use
        triangles = pipeline(passes, spec(SDFCSG_MESH_PASS_TRIANGLES, SDFCSG_MESH_BRICK));
        warmUp(triangles);
        stage("compile", t0);
    }

    // Cull.
    t0 = Clock::now();
    if (auto ok = reserve(SDFCSG_BINDING_MESH_MAP, g.brickCount * 4); !ok) return ok.error();
    {
        VkCommandBuffer cmd = begin(cull);
        const uint64_t chunk = uint64_t(kMaxGroups) * SDFCSG_MESH_GROUP_X;
        for (uint64_t first = 0; first < g.brickCount; first += chunk) {
            MeshPush push;
            push.first = uint32_t(first);
            push.count = uint32_t(std::min(chunk, g.brickCount - first));
            dispatch(cmd, push, detail::groupCount(push.count, SDFCSG_MESH_GROUP_X));
        }
        finish(cmd);
    }
    std::vector<uint32_t> map(g.brickCount), active;
    {
        const uint32_t* flags = mapped<uint32_t>(SDFCSG_BINDING_MESH_MAP);
        for (uint64_t b = 0; b < g.brickCount; ++b) {
            map[b] = flags[b] ? uint32_t(active.size()) : SDFCSG_MESH_NO_BRICK;
            if (flags[b]) active.push_back(uint32_t(b));
        }
    }
    stage("cull", t0);
    stats.activeBricks = active.size();
    const uint32_t activeCount = uint32_t(active.size());
    const uint32_t batches = (activeCount + kBatchBricks - 1) / kBatchBricks;
    const uint32_t batchBricks = std::min(activeCount, kBatchBricks);
    progressTotal += 3.0 * batches;
    if (!progress(1)) return cancelled;

    // Known once the bricks are culled: what the bricks hold for the whole extraction.
    const uint64_t fixedBytes =
        mapBytes + activeCount * kBytesPerActive + batchBricks * kBytesPerBatchBrick;
    if (activeCount > kMaxActive || fixedBytes > options.memoryBudget)
        return overBudget(g, "the " + std::to_string(activeCount) + " bricks that hold surface",
                          fixedBytes, options.memoryBudget);
    detail::uploadBuffer(ctx, buffer(SDFCSG_BINDING_MESH_MAP), map.data(), map.size() * 4);
    for (auto [binding, bytes] :
         {std::pair{SDFCSG_BINDING_MESH_ACTIVE, activeCount * 4ull},
          {SDFCSG_BINDING_MESH_RECORDS, activeCount * uint64_t(SDFCSG_MESH_RECORD) * 4},
          {SDFCSG_BINDING_MESH_COUNTS, activeCount * 16ull},
          {SDFCSG_BINDING_MESH_BASES, activeCount * 16ull},
          {SDFCSG_BINDING_MESH_SAMPLES, batchBricks * uint64_t(SDFCSG_MESH_BRICK_BLOCK) * 4},
          {SDFCSG_BINDING_MESH_EDGES, batchBricks * uint64_t(SDFCSG_MESH_BRICK_EDGES) * 4}})
        if (auto ok = reserve(binding, bytes); !ok) return ok.error();
    if (activeCount)
        detail::uploadBuffer(ctx, buffer(SDFCSG_BINDING_MESH_ACTIVE), active.data(),
                             active.size() * 4);
    notePeak(map.size() * 4);

    // Per active brick: the first edge point, marching-cubes triangle, dual vertex and dual
    // triangle it makes.
    std::vector<glm::uvec4> bases(activeCount);
    glm::u64vec4 totals(0);
    auto batchOf = [&](uint32_t batch) {
        MeshPush push;
        push.first = batch * kBatchBricks;
        push.count = std::min(kBatchBricks, activeCount - push.first);
        return push;
    };
    // The [first, end) range of bases[.][k] over the batch of `push`.
    auto batchRange = [&](const MeshPush& push, int k) {
        const uint64_t end =
            push.first + push.count < activeCount ? bases[push.first + push.count][k] : totals[k];
        return std::pair<uint32_t, uint64_t>(bases[push.first][k], end);
    };
    Mesh mesh;
    for (uint32_t batch = 0; batch < batches; ++batch) {
        MeshPush push = batchOf(batch);
        t0 = Clock::now();
        VkCommandBuffer cmd = begin(classify);
        dispatch(cmd, push, push.count);
        finish(cmd);
        const glm::uvec4* counts = mapped<glm::uvec4>(SDFCSG_BINDING_MESH_COUNTS);
        for (uint32_t i = push.first; i < push.first + push.count; ++i) {
            bases[i] = glm::uvec4(totals);
            totals += glm::u64vec4(counts[i]);
        }
        push.vertexBase = bases[push.first].x;
        stage("classify", t0);
        if (!progress(1)) return cancelled;

        const uint64_t batchVertices = totals.x - push.vertexBase;
        const uint64_t meshBytes = dual ? totals.x * kBytesPerVertex + totals.z * kBytesPerVertex +
                                              totals.w * kBytesPerTriangle
                                        : totals.x * kBytesPerVertex + totals.y * kBytesPerTriangle;
        if (totals.x > UINT32_MAX || totals.z > UINT32_MAX ||
            fixedBytes + meshBytes > options.memoryBudget)
            return overBudget(g, "the mesh", fixedBytes + meshBytes, options.memoryBudget);

        t0 = Clock::now();
        detail::uploadBuffer(ctx, buffer(SDFCSG_BINDING_MESH_BASES), bases.data(),
                             bases.size() * 16);
        // Marching cubes takes the batch's vertices; dual contouring keeps every edge point.
        if (dual) push.vertexBase = 0;
        if (auto ok = dual ? grow(SDFCSG_BINDING_MESH_VERTICES, totals.x * 48)
                           : reserve(SDFCSG_BINDING_MESH_VERTICES, batchVertices * 48);
            !ok)
            return ok.error();
        cmd = begin(vertices);
        dispatch(cmd, push, push.count);
        finish(cmd);
        stage("vertices", t0);

        t0 = Clock::now();
        if (!dual) {
            const float* v = mapped<float>(SDFCSG_BINDING_MESH_VERTICES);
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
        if (!progress(1)) return cancelled;
    }

    const int triangleKind = dual ? 3 : 1;
    std::vector<glm::vec3> smooth; // dual contouring: where foldQuads moves folding vertices
    mesh.indices.resize(totals[triangleKind] * 3);
    if (dual) {
        std::swap(buffer(SDFCSG_BINDING_MESH_VERTICES), buffer(SDFCSG_BINDING_MESH_HERMITE));
        writeDescriptors();
        mesh.positions.resize(totals.z);
        mesh.normals.resize(totals.z);
        mesh.colors.resize(totals.z);
        smooth.resize(totals.z);
    }
    for (uint32_t batch = 0; batch < batches; ++batch) {
        MeshPush push = batchOf(batch);
        auto [first, end] = batchRange(push, triangleKind);
        push.triangleBase = first;
        const uint64_t batchTriangles = end - first;
        auto [firstVertex, endVertex] = batchRange(push, 2);
        push.vertexBase = firstVertex;

        t0 = Clock::now();
        if (auto ok = reserve(SDFCSG_BINDING_MESH_INDICES, batchTriangles * 12); !ok)
            return ok.error();
        if (dual) {
            if (auto ok = reserve(SDFCSG_BINDING_MESH_VERTICES, (endVertex - firstVertex) * 48);
                !ok)
                return ok.error();
        }
        VkCommandBuffer cmd = begin(dual ? dualPass : triangles);
        dispatch(cmd, push, push.count);
        finish(cmd);
        stage(dual ? "dual" : "triangles", t0);

        t0 = Clock::now();
        if (dual) {
            const float* v = mapped<float>(SDFCSG_BINDING_MESH_VERTICES);
            for (uint64_t o = firstVertex; o < endVertex; ++o, v += 12) {
                mesh.positions[o] = glm::vec3(v[0], v[1], v[2]);
                mesh.normals[o] = glm::vec3(v[3], v[4], v[5]);
                mesh.colors[o] = glm::vec3(v[6], v[7], v[8]);
                smooth[o] = glm::vec3(v[9], v[10], v[11]);
            }
        }
        std::memcpy(mesh.indices.data() + uint64_t(first) * 3,
                    mapped<uint32_t>(SDFCSG_BINDING_MESH_INDICES), batchTriangles * 12);
        stage("download", t0);
        notePeak(map.size() * 4 + mesh.positions.capacity() * 36 + smooth.capacity() * 12 +
                 mesh.indices.capacity() * 4);
        if (!progress(1)) return cancelled;
    }

    const uint32_t* status = mapped<uint32_t>(SDFCSG_BINDING_MESH_STATUS);
    skippedSurface = status[1] != 0;
    if (dual && !skippedSurface) {
        t0 = Clock::now();
        // The field where a few triangles need it: on scenes of pruned tapes, the CPU's whole
        // tree is too slow and its own pruned field would be a second prune (forest_10k at 256:
        // 1.6 -> 2.6 s), so there the vertices' normals alone decide.
        detail::Distance distance;
        if (evaluator->nodes().size() < kTapeMinNodes)
            distance = [&](glm::vec3 p) { return evaluator->distance(p); };
        detail::foldQuads(mesh, smooth, distance, g.h);
        stage("quads", t0);
    }
    stats.surfaceCut = status[0] != 0;
    stats.vertices = mesh.vertexCount();
    stats.triangles = mesh.triangleCount();
    stats.peakBytes = peak;
    stats.totalSeconds = secondsSince(start);
    return mesh;
}

Result<Mesh> extractMesh(Context& context, const Scene& scene, const MeshOptions& options,
                         MeshStats* stats) {
    auto mesher = Mesher::create(context, scene);
    if (!mesher) return mesher.error();
    return (*mesher)->extract(options, stats);
}

} // namespace sdfcsg
