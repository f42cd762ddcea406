// sdfcsg: the headless Vulkan compute context.
//
// No window and no surface extensions. Any device with a compute queue is acceptable,
// CPU devices (Mesa lavapipe) included; a discrete GPU is preferred, then integrated, virtual,
// CPU. SDFCSG_DEVICE=<index or part of the name> overrides the choice.
//
// Threads: a Context may be shared. Renderers and Meshers made from one Context can be used
// from different threads at the same time (say, meshing in the background while a viewer
// renders); their GPU submissions take turns on the context's queue. Each Renderer or Mesher
// is used by one thread at a time. Scene loading, code generation, compileKernel() and the
// Evaluator's const methods are safe to call from any thread.
#pragma once

#include "sdfcsg/error.h"

#include <cstdint>
#include <memory>
#include <string>

namespace sdfcsg {

struct ContextOptions {
    // Enable VK_LAYER_KHRONOS_validation and count its messages. Defaults to on in debug builds
    // and when SDFCSG_VALIDATION=1; SDFCSG_VALIDATION=0 forces it off.
    int validation = -1; // -1: default, 0: off, 1: on (an error if the layer is missing)
    std::string device;  // overrides SDFCSG_DEVICE when not empty
    // On lavapipe, which compiles kernels to machine code one after the other on its one queue,
    // compile a renderer's new kernels side by side on a second device of the same driver, which
    // hands the machine code over through Mesa's shader cache on disk (so only while that cache
    // is on, as it is by default). Other drivers compile in parallel threads anyway.
    bool compileHelper = true;
};

class Context {
  public:
    static Result<std::unique_ptr<Context>> create(const ContextOptions& options = {});
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    std::string deviceName() const;
    // The device is a CPU implementation (lavapipe): invocations run in SIMD lanes through both
    // sides of every branch, so kernels with values baked in run several times faster there.
    bool cpuDevice() const;
    bool validationEnabled() const;
    // Messages the validation layer has reported so far (warnings and errors). Each is also
    // printed to stderr.
    uint32_t validationMessageCount() const;

    struct Impl;
    Impl& impl() { return *impl_; }

  private:
    explicit Context(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

} // namespace sdfcsg
