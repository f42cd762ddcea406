// sdfcsg: ray-marched images of a scene, computed in a Vulkan compute pass.
#pragma once

#include "sdfcsg/compile.h"
#include "sdfcsg/context.h"
#include "sdfcsg/error.h"
#include "sdfcsg/scene.h"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace sdfcsg {

enum class RenderMode : uint32_t { Shaded, Normals, Depth, Steps };
std::optional<RenderMode> parseRenderMode(std::string_view name);

enum class BoxOverlay : uint32_t { None, All, Selected };

class Evaluator;

// The ground grid that RenderOptions::grid draws, on the plane under the solid's finite bounds.
struct GroundGrid {
    float centreX = 0.0f, centreZ = 0.0f; // where the middle lines cross
    float height = 0.0f;                  // y of the plane: the bottom of the bounds
    float spacing = 1.0f; // a power of ten, from a twentieth to a half of the bounds' width
    int halfLines = 10;   // lines on each side of the middle ones
};
GroundGrid groundGrid(const Evaluator& evaluator);

// The most samples per pixel along each axis (RenderOptions::aa).
inline constexpr uint32_t kMaxAntialiasing = 8;

struct RenderOptions {
    uint32_t width = 800, height = 600;
    RenderMode mode = RenderMode::Shaded;
    std::optional<Camera> camera; // unset: the scene's camera, else framed from its bounds
    uint32_t aa = 1;              // N x N samples per pixel, 1..kMaxAntialiasing
    bool shadows = true;
    bool ambientOcclusion = true;
    // Skip operands whose bounds cannot change the result (the image is the same either way).
    // Unset: on for GPUs, off for CPU devices such as lavapipe, which execute both sides of
    // every branch in their SIMD lanes, so the bounds tests only add work there.
    std::optional<bool> boundsSkipping;
    BoxOverlay boxes = BoxOverlay::None;
    int selectedNode = -1; // for BoxOverlay::Selected
    bool grid = false;     // ground grid (groundGrid()), hidden behind surfaces
    // The image is computed in bands of rows, one submission each, so no single dispatch runs
    // for long. Called after each band with the fraction done; returning false stops the
    // render (ErrorKind::Cancelled).
    std::function<bool(float)> progress;
};

// Tightly packed 8-bit RGBA, rows top to bottom.
struct Image {
    uint32_t width = 0, height = 0;
    std::vector<uint8_t> rgba;
};

// Per-pixel data of the last render, for tests and picking: hit mask, ray distance and
// iteration count (first sample of each pixel).
struct PixelInfo {
    float depth; // ray parameter t of the hit, or a negative value for a miss
    uint32_t steps;
};

// Why an image whose pixels (Renderer::lastPixelInfo) `camera` saw on a grid `height` pixels high
// shows no surface, as a clause for a warning: the solid too large for single precision (whatever
// the pixels), the camera inside it, the solid empty, smaller than a pixel, or out of view.
// Nothing where some pixel shows the solid.
std::optional<std::string> whyNothingShows(const Evaluator& evaluator, const Camera& camera,
                                           uint32_t height, const std::vector<PixelInfo>& pixels);

// Same node kinds and children, node for node: what updateValues() needs to keep the kernel.
bool sameStructure(const Scene& a, const Scene& b);

struct RendererOptions {
    // true: numeric values are baked into the kernel as literals. CPU drivers (lavapipe) run
    // that several times faster, but updateValues() must then regenerate and recompile.
    // false: values are read from a buffer, so updateValues() only uploads them (the viewer).
    // Scenes evaluated from pruned tapes read their values from buffers either way; true lets
    // the tape machine read spheres as balls where every sphere's scale is the same on every
    // axis (faster), so that updateValues() recompiles where an edit changes that.
    bool inlineValues = true;
    Evaluation evaluation = Evaluation::Auto; // inlined or pruned tapes (CodegenOptions)
};

class Renderer {
  public:
    // Generates, compiles and builds the pipeline for this scene; the pipeline is ready to run
    // (drivers that compile on first use have done so) when this returns. `context` must
    // outlive the renderer.
    static Result<std::unique_ptr<Renderer>> create(Context& context, const Scene& scene,
                                                    const RendererOptions& options = {});
    ~Renderer();

    // Replaces numeric values (sizes, transforms, colours, smooth radii, lights, background,
    // camera). With inlineValues == false this is an upload, without recompiling; otherwise
    // the kernel is regenerated. Fails with ErrorKind::Usage if the structure (kinds, children)
    // differs from the compiled one.
    Status updateValues(const Scene& scene);
    // Whether updateValues(scene) would only upload: the structure is the same, and the kernel
    // holds none of the values that differ (see followsValues()).
    bool uploads(const Scene& scene) const;
    // Whether the kernel holds some of the scene's values, so that some edits of values rebuild
    // it: values inlined, or on tapes spheres read as balls (see inlineValues).
    bool followsValues() const;

    Result<Image> render(const RenderOptions& options);
    // Per-pixel hit depth and step count of the last render().
    const std::vector<PixelInfo>& lastPixelInfo() const;
    // whyNothingShows() for the last render().
    std::optional<std::string> nothingShown() const;

    struct Impl;

  private:
    explicit Renderer(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

// The PNG file of an image; errors name `path`.
Result<std::string> encodePng(const Image& image, const std::filesystem::path& path);

// Writes a PNG as writeFileAtomic() does (sdfcsg/io.h).
Status writePng(const Image& image, const std::filesystem::path& path);

} // namespace sdfcsg
