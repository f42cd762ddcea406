// The generated GLSL against the CPU reference evaluator: shaders/probe.comp evaluates
// sceneSample at points, and expectGpuMatchesCpu() holds the results to the Evaluator's within
// single-precision tolerances, for each way the kernels may be built (test_gpu_eval.cpp,
// test_definitions.cpp).
#pragma once

#include "codegen/scene_buffers.h"
#include "field/prune.h"
#include "gpu/vk.h"
#include "gpu_test.h"
#include "shared.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

#include <random>
#include <string>
#include <vector>

namespace sdfcsg::test {

// How probeGpu() compiles and runs the scene.
struct Probe {
    const char* name;
    bool boundsTests; // CodegenOptions::boundsTests
    bool skipping;    // kBoundsSkipping
    // The result is read back through a staging copy, as on GPUs whose storage memory is not
    // mappable (lavapipe's always is), so that path runs under validation too.
    bool viaStaging;
    // Pruned tapes (shaders/tape.glsl), held to the CPU's pruned field
    // (engine/src/field/prune.cpp).
    bool tapes = false;
    // Values written into the code as literals (CodegenOptions::inlineParams).
    bool inlineParams = false;
};

inline constexpr Probe kProbes[] = {
    {"bounds skipping on", true, true, false},
    {"bounds skipping off, staging read-back", true, false, true},
    {"bounds tests left out", false, false, false},
    {"pruned tapes", true, true, false, true},
};

// Runs probe.comp over `points`; returns (rgb colour, distance) per point.
inline std::vector<glm::vec4> probeGpu(Context& context, const Scene& scene,
                                       const std::vector<glm::vec4>& points, const Probe& probe) {
    Context::Impl& ctx = detail::contextImpl(context);
    CodegenOptions codegen;
    codegen.boundsTests = probe.boundsTests;
    codegen.evaluation = probe.tapes ? Evaluation::Tapes : Evaluation::Inlined;
    codegen.inlineParams = probe.inlineParams;
    const std::string glsl = generateSceneGlsl(scene, codegen);
    if (!probe.boundsTests) {
        EXPECT_EQ(glsl.find("Needs("), std::string::npos) << glsl;
    }
    auto spirv = compileKernel("probe.comp", glsl);
    if (!spirv) {
        ADD_FAILURE() << spirv.error().str();
        return {};
    }
    const detail::Binding bindings[] = {
        {SDFCSG_BINDING_NODES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
        {SDFCSG_BINDING_PROBE_IN, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
        {SDFCSG_BINDING_PROBE_OUT, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
        {SDFCSG_BINDING_FIELD, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
    };
    VkShaderModule module = detail::createShaderModule(ctx, *spirv);
    VkDescriptorSetLayout setLayout = detail::createDescriptorSetLayout(ctx, bindings);
    VkPipelineLayout layout = detail::createPipelineLayout(ctx, setLayout, sizeof(uint32_t));
    detail::SpecConstant spec[] = {{SDFCSG_SPEC_BOUNDS_SKIPPING, probe.skipping ? 1u : 0u}};
    VkPipeline pipeline = detail::createComputePipeline(ctx, module, layout, spec);
    VkDescriptorPool pool = detail::createDescriptorPool(ctx, bindings);
    VkDescriptorSet set = detail::allocateDescriptorSet(ctx, pool, setLayout);

    Evaluator evaluator(scene);
    detail::SceneBuffers sceneBuffers(ctx);
    EXPECT_TRUE(sceneBuffers.create(evaluator));
    const VkDeviceSize bytes = points.size() * sizeof(glm::vec4);
    detail::Buffer in = *detail::createBuffer(ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                              detail::MemoryUse::Upload);
    detail::Buffer out = *detail::createBuffer(
        ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
        detail::MemoryUse::Readback);
    detail::Buffer staging;
    detail::Buffer source = out; // what recordReadback() sees
    if (probe.viaStaging) source.data = nullptr;
    if (!source.data)
        staging = *detail::createBuffer(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                        detail::MemoryUse::Staging);
    detail::uploadBuffer(ctx, in, points.data(), bytes);
    auto words = detail::SceneBuffers::fieldWords(scene, evaluator, codegen.evaluation);
    EXPECT_TRUE(words) << words.error().str();
    if (words) {
        EXPECT_TRUE(sceneBuffers.uploadField(*words));
    }
    const detail::Buffer* buffers[] = {&sceneBuffers.nodes(), &in, &out, &sceneBuffers.field()};
    detail::writeDescriptorSet(ctx, set, bindings, buffers);

    uint32_t count = uint32_t(points.size());
    VkCommandBuffer cmd = detail::beginCommands(ctx);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(count), &count);
    vkCmdDispatch(cmd, detail::groupCount(count, SDFCSG_PROBE_GROUP_X), 1, 1);
    detail::recordReadback(cmd, source, &staging);
    detail::submitAndWait(ctx);
    const auto* result = static_cast<const glm::vec4*>(detail::readback(ctx, source, &staging));
    std::vector<glm::vec4> samples(result, result + points.size());

    for (detail::Buffer* b : {&in, &out, &staging})
        detail::destroyBuffer(ctx, *b);
    vkDestroyPipeline(ctx.device, pipeline, nullptr);
    vkDestroyDescriptorPool(ctx.device, pool, nullptr);
    vkDestroyPipelineLayout(ctx.device, layout, nullptr);
    vkDestroyDescriptorSetLayout(ctx.device, setLayout, nullptr);
    vkDestroyShaderModule(ctx.device, module, nullptr);
    return samples;
}

// Uniform points in the scene's bounds grown by a margin (a cube around the finite part where
// planes make them infinite), plus as many pulled onto the surface by a Newton step, where
// the colour blends and sign changes are.
inline std::vector<glm::vec4> samplePoints(const Evaluator& ev, size_t count, uint32_t seed) {
    Aabb box = ev.bounds();
    if (!box.finite()) {
        Aabb finite;
        for (const FlatNode& n : ev.nodes())
            if (n.bounds.finite() && !n.bounds.empty()) {
                finite.min = glm::min(finite.min, n.bounds.min);
                finite.max = glm::max(finite.max, n.bounds.max);
            }
        if (finite.empty()) finite = Aabb{glm::vec3(-2.0f), glm::vec3(2.0f)};
        box.min = glm::max(box.min, finite.min - 2.0f);
        box.max = glm::min(box.max, finite.max + 2.0f);
    }
    float margin = 0.25f * glm::length(box.max - box.min) + 0.1f;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<glm::vec4> points;
    for (size_t i = 0; i < count; ++i) {
        glm::vec3 t(u(rng), u(rng), u(rng));
        glm::vec3 p = glm::mix(box.min - margin, box.max + margin, t);
        points.emplace_back(p, 0.0f);
        const float h = 1e-3f;
        float d = ev.distance(p);
        glm::vec3 g(ev.distance(p + glm::vec3(h, 0, 0)) - ev.distance(p - glm::vec3(h, 0, 0)),
                    ev.distance(p + glm::vec3(0, h, 0)) - ev.distance(p - glm::vec3(0, h, 0)),
                    ev.distance(p + glm::vec3(0, 0, h)) - ev.distance(p - glm::vec3(0, 0, h)));
        if (glm::length(g) > 1e-6f) points.emplace_back(p - d * glm::normalize(g), 0.0f);
    }
    return points;
}

inline void expectGpuMatchesCpu(Context& context, const Scene& scene, size_t count = 2048) {
    Evaluator ev(scene);
    const detail::PrunedField pruned = detail::pruneField(ev);
    std::vector<glm::vec4> points = samplePoints(ev, count, 12345);
    for (const Probe& probe : kProbes) {
        SCOPED_TRACE(probe.name);
        std::vector<glm::vec4> gpu = probeGpu(context, scene, points, probe);
        ASSERT_EQ(gpu.size(), points.size());
        size_t badDistance = 0, badColour = 0;
        std::string first;
        for (size_t i = 0; i < points.size(); ++i) {
            glm::vec3 p(points[i]);
            // Scenes with value and domain operations run on tapes whatever is asked.
            const bool tapes = probe.tapes || usesTapes(scene, Evaluation::Inlined);
            Sample cpu = tapes ? pruned.sample(ev.nodes(), p) : ev.sample(p);
            // Single precision throughout; the two sides round transforms differently.
            float tolerance = 2e-5f * (1.0f + glm::length(p)) + 1e-5f * std::abs(cpu.distance);
            if (!(std::abs(gpu[i].w - cpu.distance) <= tolerance)) {
                if (badDistance++ == 0)
                    first = "at (" + std::to_string(p.x) + ", " + std::to_string(p.y) + ", " +
                            std::to_string(p.z) + "): gpu " + std::to_string(gpu[i].w) + ", cpu " +
                            std::to_string(cpu.distance);
            }
            glm::vec3 dc = glm::abs(glm::vec3(gpu[i]) - cpu.color);
            badColour += std::max(dc.x, std::max(dc.y, dc.z)) > 1e-3f;
        }
        EXPECT_EQ(badDistance, 0u)
            << badDistance << " of " << points.size() << " distances differ; first " << first;
        // A sharp operation's colour switches where two operands tie; rounding may pick either.
        EXPECT_LE(badColour, points.size() / 500)
            << badColour << " of " << points.size() << " colours differ";
    }
}

} // namespace sdfcsg::test
