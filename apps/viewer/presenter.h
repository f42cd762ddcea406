// The window's own Vulkan device: a swapchain that shows the engine's images (which come back to
// the host from the engine's headless context), or an extracted mesh drawn by a graphics
// pipeline, with Dear ImGui drawn on top. Keeping presentation on its own device leaves the
// engine free of window-system extensions.
#pragma once

#include <sdfcsg/mesh.h>
#include <sdfcsg/render.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

struct GLFWwindow;
struct ImDrawData;

namespace sdfcsg::viewer {

struct Presenter;

void destroyPresenter(Presenter* presenter);
struct PresenterDeleter {
    void operator()(Presenter* p) const { destroyPresenter(p); }
};
using PresenterPtr = std::unique_ptr<Presenter, PresenterDeleter>;

// Also initialises the ImGui Vulkan backend (the ImGui context must exist). `validation`: the
// window's device uses the validation layer where it is installed (as the engine's context does,
// Context::validationEnabled()). nullptr and a message on failure.
PresenterPtr createPresenter(GLFWwindow* window, bool validation, std::string& error);

// The image to show from the next frame on (copied).
void setImage(Presenter& presenter, const Image& image);

// Copies a mesh, and optionally a coarser preview of it for moving views, to the device for the
// mesh view, replacing the previous ones (an empty mesh frees them). Waits for the device: call
// it once per extracted mesh, not per frame. False with a message when the device cannot hold
// the mesh (memory, or more vertices than it can index); the previous meshes are gone then too.
// A preview that does not fit is left out.
bool setMesh(Presenter& presenter, const Mesh& mesh, const Mesh* preview, std::string& error);

// Triangles of the preview given to setMesh(); 0 without one.
uint32_t previewMeshTriangles(const Presenter& presenter);

// How the mesh view draws the mesh given to setMesh().
struct MeshView {
    Camera camera; // as for the ray marcher: the mesh lies where the ray-marched surface is
    bool wireframe = false; // one-pixel edges over the shaded surface
    bool closed = false;    // no bounds cut the surface: back faces never show, skip them
    bool preview = false;   // the camera moves: draw the preview given to setMesh(), if any
    // The ray marcher's ground grid (RenderOptions::grid), hidden behind the mesh.
    std::optional<GroundGrid> grid;
};

// Draws a frame: the background colour, then the image scaled to fill the window, or with `mesh`
// set the mesh instead of the image (drawn again only when the view or the size changed), then
// ImGui. With `capture` set, the finished frame is read
// back into it (RGBA). False when the window cannot be drawn right now (minimised); the
// swapchain follows size changes by itself.
bool drawFrame(Presenter& presenter, ImDrawData* ui, const float background[3],
               const MeshView* mesh, Image* capture);

// The device time of the last drawing of the mesh in milliseconds, from timestamps; negative
// before the first or when the queue has no timestamps.
double meshDrawMilliseconds(const Presenter& presenter);

std::string presenterDeviceName(const Presenter& presenter);

// Messages from the validation layer about the window's device so far (see createPresenter).
uint32_t presenterValidationMessages(const Presenter& presenter);

} // namespace sdfcsg::viewer
