// sdfcsg: polygon meshes of a scene, extracted in Vulkan compute passes by dual contouring
// (the default) or marching cubes.
//
// The field is sampled on a grid of cubic cells covering the bounds. A grid edge whose end
// samples differ in sign (inside is d < 0) is crossed by the surface; it gets a point on the
// surface and the field's normal there.
// - Marching cubes makes those points the vertices, and the triangles of each cell come from the
//   marching-cubes table. Sharp edges of the solid come out bevelled, up to half a cell wide.
// - Dual contouring makes one vertex per piece of surface in a cell (the pieces of its
//   marching-cubes case; a cell where two sheets pass gets two), placed where the planes through
//   the piece's edge points meet best (a quadratic error function, solved by eigenvectors and
//   kept in the cell), and one quad per crossed edge, joining the vertices of its four cells.
//   Flat faces stay flat, and the sharp edges and corners of the solid stay sharp. Where a
//   sharp edge runs close along a grid line or plane, vertices of cells on both sides can land
//   on it and cross over; a quad that then faces against its vertices' normals has its vertices
//   moved to the mean of their edge points instead (smooth there, as surface nets are). Where
//   triangles still cross, as in cells of several pieces of surface (parts smaller than a
//   cell), the quads around those cells are split into triangles that each lie inside one
//   cell, through the edge points and points on the cells' faces, so that none crosses another.
// Either way the mesh is indexed and welded by construction and, wherever the surface lies
// inside the bounds, closed and manifold, with triangles wound counter-clockwise seen from
// outside.
//
// Colours: each vertex takes the scene's colour where it lies. Where parts of different colours
// meet in a hard union or difference, the colour jumps along the curve where their surfaces meet;
// with MeshOptions::colorRegions, in a scene of more than one colour, each edge that crosses such a
// border gets a vertex on it (found by bisection on the surface, in the CPU evaluator's field), and
// the triangles are cut there, so every triangle lies in one colour (Mesh::triangleColors). Smooth
// blends have no border and keep blended vertex colours (engine/src/mesh/mesh_colors.h).
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
// vertex; indices has three per triangle, and triangleColors none or one per triangle.
struct Mesh {
    std::vector<glm::vec3> positions; // scene units
    std::vector<glm::vec3> normals;   // unit length, pointing out of the solid
    std::vector<glm::vec3> colors;    // the scene's colours (0..1, as written in the scene)
    std::vector<uint32_t> indices;    // counter-clockwise seen from outside
    // Empty, or each triangle's colour: the scene's colour at its centre (moved onto the
    // surface). Set by Mesher::extract with MeshOptions::colorRegions for scenes of more than
    // one colour, whose meshes have an edge wherever the colour jumps, so that each triangle lies
    // in one colour; the exporters then write 3MF and glTF in regions of one colour. A vertex on
    // such a border keeps one of the colours that meet there in `colors`.
    std::vector<glm::vec3> triangleColors;

    size_t vertexCount() const { return positions.size(); }
    size_t triangleCount() const { return indices.size() / 3; }
};

enum class MeshMethod {
    DualContouring, // sharp edges and corners kept (see above)
    MarchingCubes,
};

struct MeshOptions {
    MeshMethod method = MeshMethod::DualContouring;
    // The region to mesh. Unset: the scene's finite bounds plus a margin of a few voxels (the
    // finite part only, for scenes with planes).
    std::optional<Aabb> bounds;
    // Cells along the longest axis of the bounds; the others get as many cells of the same
    // size as they need. Ignored when voxelSize is set.
    uint32_t resolution = 128;
    std::optional<float> voxelSize; // edge length of a cell, in scene units
    // Root-finding steps that move each edge point from the linear estimate onto the surface.
    uint32_t refineSteps = 3;
    // Host memory the extraction may use for its working buffers, in bytes; a request that
    // needs more fails with ErrorKind::Limit before the heavy work starts.
    size_t memoryBudget = size_t(4) << 30;
    // Cut the mesh along the borders where the colour jumps and set Mesh::triangleColors (see
    // Colours above), for outputs that carry a colour per triangle (formatHasTriangleColors in
    // sdfcsg/export.h). A host pass that follows each border in the field: on mesh_a, two
    // colours at 256 cells, about half as long again as the extraction. Off, each vertex keeps
    // the colour where it lies and triangles across a border blend the two.
    bool colorRegions = false;
    // Dual contouring's last host step: the vertices of triangles that still face against the
    // field's gradient (at features thinner than a cell) move to points of their cells that
    // unfold them (docs/robustness.md). Off, the mesh is the one a reference mesher that lacks
    // the step makes; the field is then asked far less on the host.
    bool unfold = true;
    // Called from the calling thread with the fraction done (0..1), at least once per batch of
    // bricks; returning false cancels the extraction (ErrorKind::Cancelled).
    std::function<bool(float)> progress;
};

struct MeshStats {
    glm::uvec3 cells{0};       // grid size in cells
    float voxelSize = 0;       // cell edge length
    Aabb bounds;               // the region the grid covers (at least the requested bounds)
    uint64_t bricks = 0;       // bricks in the grid
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
    size_t peakBytes = 0; // largest working memory held at once (buffers and mesh)
    // Set by simplifyMesh, which also updates the counts above and appends its stages (their
    // time counted in totalSeconds): the triangles it was given, how many simplifications it
    // ran and checked, and the largest sampled distance of the result from the surface (NaN
    // without SimplifyOptions::maxError, which is when it does not sample).
    uint64_t unsimplifiedTriangles = 0;
    uint32_t simplifyAttempts = 0;
    float simplifiedError = 0;
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
    // Why extract(options) found no surface, as a clause for a note: the solid is empty, or the
    // grid too coarse, with the smallest resolution that finds the surface (by extracting
    // coarse grids again, each cancelled as options.progress says). Nothing where the reason
    // is not known (options.bounds may just miss the solid) or an extraction failed.
    std::optional<std::string> whyEmpty(const MeshOptions& options);
    // The scene's CPU evaluator the extraction steps use: simplifyMesh and reportMesh given this
    // one share its pruning and its baked fields instead of making them again.
    const Evaluator& evaluator() const;

    struct Impl;

  private:
    explicit Mesher(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

// One-shot convenience: Mesher::create + extract.
Result<Mesh> extractMesh(Context& context, const Scene& scene, const MeshOptions& options = {},
                         MeshStats* stats = nullptr);

// Simplification (engine/src/mesh/mesh_simplify.cpp, by meshoptimizer's edge collapses ranked by
// quadric error). A collapse moves one vertex onto a neighbour, so every vertex of the result is
// a vertex of the input with its position, normal and colour. A vertex with a neighbour of
// another colour never moves: each patch of one colour keeps its outline, and the colour of every
// point of the surface stays what it was. The outline of an open mesh (bounds that cut the
// surface) never moves either.
struct SimplifyOptions {
    // How far from the scene's surface any point of the result may lie, in scene units (a finite
    // number > 0); where the input already lay farther than that, no farther than it did there.
    // Unset: no bound, targetTriangles alone decides.
    std::optional<float> maxError;
    // At most this many triangles, where the topology and the vertices that must stay allow it.
    // Unset: as few as maxError allows. With both, the simplification stops at whichever limit
    // it reaches first.
    std::optional<size_t> targetTriangles;
    // Called now and then on the calling thread with the fraction done (0 to 1, never falling);
    // returning false stops the simplification, which then fails with ErrorKind::Cancelled.
    std::function<bool(float)> progress;
};

// Where simplifyMesh holds a triangle (a, b, c) to the field, as barycentric weights (the point
// is w.x * a + w.y * b + w.z * c): its centre, the middles of its sides and the points halfway
// from the centre to each corner. Unlike its corners, these see a triangle that cuts across a
// sharp edge or corner of the solid. `sdfcsg bench --mesh --error` samples the same points.
inline const glm::vec3 kTriangleSamples[7] = {glm::vec3(1.0f / 3),
                                              glm::vec3(0.5f, 0.5f, 0.0f),
                                              glm::vec3(0.0f, 0.5f, 0.5f),
                                              glm::vec3(0.5f, 0.0f, 0.5f),
                                              glm::vec3(2, 0.5f, 0.5f) / 3.0f,
                                              glm::vec3(0.5f, 2, 0.5f) / 3.0f,
                                              glm::vec3(0.5f, 0.5f, 2) / 3.0f};

// The simplified mesh, closed and manifold with the same Euler characteristic wherever the input
// was, ordered as optimizeMeshOrder orders it. `evaluator` is the scene that `mesh` was extracted
// from (for scenes of kTapeMinNodes nodes or more its prunedDistance is used). Each
// simplification is checked: the field is sampled over every triangle (at the points that
// `sdfcsg bench --mesh --error` samples, and on triangles longer than two of the input's mean
// edges on a lattice about one such edge apart), and the edges, vertex fans and parts are held
// to the input's. A result that strays too far or whose topology changed is simplified again
// with the input's vertices around the faults held in place; the target error grows over a few
// passes, each from the last result that passed, and where the whole mesh cannot be mended it
// is simplified in blocks of space, each on its own. At worst the input comes back (ordered).
// Runs on up to two threads. Fails with ErrorKind::Usage when neither limit is set, maxError is
// not a finite number > 0 or targetTriangles is 0, and with ErrorKind::Cancelled when
// options.progress returns false.
Result<Mesh> simplifyMesh(const Mesh& mesh, const Evaluator& evaluator,
                          const SimplifyOptions& options, MeshStats* stats = nullptr);

// Reorders the triangles for the GPU's post-transform vertex cache and then the vertices in the
// order the triangles first use them (for fetch locality), dropping vertices that no triangle
// uses. The surface, its winding and every vertex's attributes are unchanged. `fast` plans for a
// FIFO cache instead: for a mesh from Mesher::extract, 0.85 vertex transforms per triangle
// instead of 0.83 (with a 32-entry cache; 0.94 as extracted) in a third of the time (0.05 s
// instead of 0.18 s for 880,000 triangles on one core).
void optimizeMeshOrder(Mesh& mesh, bool fast = false);

} // namespace sdfcsg
