// sdfcsg: polygon meshes of a scene, extracted by marching cubes in Vulkan compute passes.
//
// The field is sampled on a grid of cubic cells covering the bounds. One vertex is made per grid
// edge whose end samples differ in sign (inside is d < 0), so the mesh is indexed and welded by
// construction; triangles come from the standard marching-cubes table. Wherever the surface lies
// inside the bounds the mesh is closed and manifold, with triangles wound counter-clockwise seen
// from outside.
//
// The grid is processed in bricks of SDFCSG_MESH_BRICK^3 cells (shaders/shared.h). A brick whose
// centre lies farther from the surface than its half-diagonal cannot contain surface (the field
// is 1-Lipschitz) and is skipped, so the cost follows the surface area, not the volume.
#pragma once

#include "sdfcsg/compile.h"
#include "sdfcsg/context.h"
#include "sdfcsg/error.h"
#include "sdfcsg/eval.h"
#include "sdfcsg/scene.h"

#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace sdfcsg {

// An indexed triangle mesh in host memory. positions, normals and colors have one entry per
// vertex; indices has three per triangle.
struct Mesh {
    std::vector<glm::vec3> positions; // scene units
    std::vector<glm::vec3> normals;   // unit length, pointing out of the solid
    std::vector<glm::vec3> colors;    // the scene's colours (0..1, as written in the scene)
    std::vector<uint32_t> indices;    // counter-clockwise seen from outside

    size_t vertexCount() const { return positions.size(); }
    size_t triangleCount() const { return indices.size() / 3; }
};

struct MeshOptions {
    // The region to mesh. Unset: the scene's finite bounds plus a margin of a few voxels (the
    // finite part only, for scenes with planes).
    std::optional<Aabb> bounds;
    // Cells along the longest axis of the bounds; the others get as many cells of the same
    // size as they need. Ignored when voxelSize is set.
    uint32_t resolution = 128;
    std::optional<float> voxelSize; // edge length of a cell, in scene units
    // Root-finding steps that move each vertex from the linear estimate onto the surface.
    uint32_t refineSteps = 2;
    // Host memory the extraction may use for its working buffers, in bytes; a request that
    // needs more fails with ErrorKind::Limit before the heavy work starts.
    size_t memoryBudget = size_t(4) << 30;
    // Called from the calling thread with the fraction done (0..1), at least once per batch of
    // bricks; returning false cancels the extraction (ErrorKind::Cancelled).
    std::function<bool(float)> progress;
};

struct MeshStats {
    glm::uvec3 cells{0};    // grid size in cells
    float voxelSize = 0;    // cell edge length
    Aabb bounds;            // the region the grid covers (at least the requested bounds)
    uint64_t bricks = 0;    // bricks in the grid
    uint64_t activeBricks = 0; // bricks that may contain surface
    uint64_t vertices = 0, triangles = 0;
    // True when the solid reaches the boundary of the bounds: the mesh is open there.
    bool surfaceCut = false;
    struct Stage {
        std::string name;
        double seconds;
    };
    std::vector<Stage> stages; // wall time per stage, in order
    double totalSeconds = 0;
    size_t peakBytes = 0;      // largest working memory held at once (buffers and mesh)
};

// Extracts meshes of one scene. Compiles the scene's kernels once; extract() may then be called
// any number of times with different options. `context` must outlive the mesher; use it from
// one thread at a time (see context.h).
class Mesher {
  public:
    // `evaluation`: inlined scene code or pruned tapes (CodegenOptions).
    static Result<std::unique_ptr<Mesher>> create(Context& context, const Scene& scene,
                                                  Evaluation evaluation = Evaluation::Auto);
    ~Mesher();

    // Fails with ErrorKind::Usage for bad options (empty or non-finite bounds, resolution 0)
    // and ErrorKind::Limit when the grid needs more memory than options.memoryBudget.
    Result<Mesh> extract(const MeshOptions& options, MeshStats* stats = nullptr);

    struct Impl;

  private:
    explicit Mesher(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

// One-shot convenience: Mesher::create + extract.
Result<Mesh> extractMesh(Context& context, const Scene& scene, const MeshOptions& options = {},
                         MeshStats* stats = nullptr);

} // namespace sdfcsg
