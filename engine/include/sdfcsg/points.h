// sdfcsg: a scene's field at many points at once, evaluated on the device.
#pragma once

#include "sdfcsg/compile.h"
#include "sdfcsg/context.h"
#include "sdfcsg/error.h"
#include "sdfcsg/scene.h"

#include <glm/vec3.hpp>

#include <cstddef>
#include <memory>
#include <span>

namespace sdfcsg {

// Evaluates the scene's field (distance and colour, as Evaluator::sample does on the CPU, to
// single-precision rounding) at batches of points in a compute pass (shaders/probe.comp). Worth
// it for many points: a batch costs a submission and a copy each way. `context` must outlive the
// sampler; use it from one thread at a time (see context.h).
class PointSampler {
  public:
    // Points per submission; longer spans go in several.
    static constexpr size_t kBatch = size_t(1) << 20;

    static Result<std::unique_ptr<PointSampler>> create(Context& context, const Scene& scene,
                                                        Evaluation evaluation = Evaluation::Auto);
    ~PointSampler();

    // Writes the distance at points[i] to distances[i] and, where `colors` is not empty, the
    // colour to colors[i]; the spans are as long as `points`.
    Status sample(std::span<const glm::vec3> points, std::span<float> distances,
                  std::span<glm::vec3> colors = {});

    struct Impl;

  private:
    explicit PointSampler(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

} // namespace sdfcsg
