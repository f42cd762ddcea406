// The window's own Vulkan device: a swapchain that shows the engine's images (which come back to
// the host from the engine's headless context) with Dear ImGui drawn on top. Keeping
// presentation on its own device leaves the engine free of window-system extensions.
#pragma once

#include <sdfcsg/render.h>

#include <cstdint>
#include <memory>
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

// Also initialises the ImGui Vulkan backend (the ImGui context must exist). nullptr and a
// message on failure.
PresenterPtr createPresenter(GLFWwindow* window, std::string& error);

// The image to show from the next frame on (copied).
void setImage(Presenter& presenter, const Image& image);

// Draws a frame: the background colour, the image scaled to fill the window, then ImGui.
// With `capture` set, the finished frame is read back into it (RGBA). False when the window
// cannot be drawn right now (minimised); the swapchain follows size changes by itself.
bool drawFrame(Presenter& presenter, ImDrawData* ui, const float background[3], Image* capture);

std::string presenterDeviceName(const Presenter& presenter);

} // namespace sdfcsg::viewer
