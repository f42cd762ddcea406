// Draws an extracted mesh on the CPU, with the ray marcher's camera conventions, so mesh mode
// needs no graphics pipeline and shows the mesh exactly where the ray-marched surface is.
#pragma once

#include <sdfcsg/mesh.h>
#include <sdfcsg/render.h>

#include <cstdint>

namespace sdfcsg::viewer {

struct RasterOptions {
    uint32_t width = 800, height = 600;
    Camera camera;
    bool shaded = true; // false: flat grey, for looking at the wireframe alone
    bool wireframe = false;
    glm::vec3 background{0.6f, 0.72f, 0.85f};
};

// Depth-buffered triangles with vertex colours lit from the eye; triangles reaching behind the
// eye are left out. Edges are drawn over the surface in wireframe mode.
Image rasterize(const Mesh& mesh, const RasterOptions& options);

} // namespace sdfcsg::viewer
