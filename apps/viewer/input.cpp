// The mouse and the keyboard: orbit, pan, zoom and picks in the window, and the shortcuts of
// docs/viewer.md. Whatever ImGui takes (a panel under the cursor, a text field) is left to it.
#include "viewer.h"

#include "picking.h"

#include <GLFW/glfw3.h>
#include <imgui.h>

#include <cmath>
#include <cstdint>

namespace sdfcsg::viewer {

void pick(Viewer& v, double x, double y) {
    int w = 1, h = 1;
    glfwGetFramebufferSize(v.window, &w, &h);
    int ww = 1, wh = 1;
    glfwGetWindowSize(v.window, &ww, &wh);
    if (v.meshView && v.mesh && v.evaluator) {
        // The mesh view has no depths from the engine, but it shares the ray marcher's camera:
        // the ray through the pixel meets the scene's surface where the mesh shows it.
        auto p = castRay(*v.evaluator, toCamera(v.camera), uint32_t(w), uint32_t(h),
                         float(x) * float(w) / float(ww), float(y) * float(h) / float(wh));
        v.selected = p ? nearestPrimitive(*v.evaluator, *p) : -1;
        return;
    }
    if (!v.last.scene || v.last.image.rgba.empty() || !v.evaluator) return;
    // Window coordinates -> image pixels (the image fills the window).
    float ix = float(x) * float(w) / float(ww) * float(v.last.image.width) / float(w);
    float iy = float(y) * float(h) / float(wh) * float(v.last.image.height) / float(h);
    auto p = pickPoint(*v.last.options.camera, v.last.image.width, v.last.image.height,
                       v.last.pixels, ix, iy);
    if (!p) {
        v.selected = -1;
        return;
    }
    Evaluator shown(*v.last.scene);
    v.selected = nearestPrimitive(shown, *p);
    if (v.selected >= int(v.scene->nodes.size())) v.selected = -1;
}

void handleInput(Viewer& v) {
    ImGuiIO& io = ImGui::GetIO();
    double x, y;
    glfwGetCursorPos(v.window, &x, &y);
    int ww = 1, wh = 1;
    glfwGetWindowSize(v.window, &ww, &wh);
    for (int b = 0; b < 3; ++b) {
        bool down = glfwGetMouseButton(v.window, b) == GLFW_PRESS;
        if (down && !v.pressed[b] && !io.WantCaptureMouse) {
            v.pressed[b] = true;
            v.pressX = v.lastX = x, v.pressY = v.lastY = y;
            v.dragged = false;
        } else if (!down && v.pressed[b]) {
            v.pressed[b] = false;
            if (b == 0 && !v.dragged) pick(v, x, y);
        }
    }
    double dx = x - v.lastX, dy = y - v.lastY;
    if (std::hypot(x - v.pressX, y - v.pressY) > 3.0) v.dragged = true;
    bool shift = glfwGetKey(v.window, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                 glfwGetKey(v.window, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
    if ((dx != 0 || dy != 0) && v.dragged) {
        if (v.pressed[0] && !shift) {
            orbit(v.camera, -float(dx) * 0.008f, float(dy) * 0.008f);
            v.lastInteraction = now();
        } else if (v.pressed[1] || v.pressed[2] || (v.pressed[0] && shift)) {
            pan(v.camera, float(dx) / float(wh), float(dy) / float(wh));
            v.lastInteraction = now();
        }
    }
    v.lastX = x, v.lastY = y;
    if (!io.WantCaptureMouse && io.MouseWheel != 0.0f) {
        zoom(v.camera, std::pow(0.9f, io.MouseWheel));
        v.lastInteraction = now();
    }
    if (io.WantCaptureKeyboard) return;
    bool ctrl = io.KeyCtrl;
    auto pressedKey = [&](int key) {
        return ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey(key)));
    };
    (void)pressedKey;
    auto held = [&](int key) { return glfwGetKey(v.window, key) == GLFW_PRESS; };
    float step = float(io.DeltaTime) * 1.5f;
    if (held(GLFW_KEY_LEFT) || held(GLFW_KEY_RIGHT) || held(GLFW_KEY_UP) || held(GLFW_KEY_DOWN)) {
        float h = (held(GLFW_KEY_LEFT) ? 1.0f : 0.0f) - (held(GLFW_KEY_RIGHT) ? 1.0f : 0.0f);
        float vv = (held(GLFW_KEY_UP) ? 1.0f : 0.0f) - (held(GLFW_KEY_DOWN) ? 1.0f : 0.0f);
        if (shift)
            pan(v.camera, -h * step * 0.3f, vv * step * 0.3f);
        else
            orbit(v.camera, h * step, -vv * step);
        v.lastInteraction = now();
    }
    if (held(GLFW_KEY_EQUAL) || held(GLFW_KEY_KP_ADD) || held(GLFW_KEY_PAGE_UP)) {
        zoom(v.camera, 1.0f - step * 0.5f);
        v.lastInteraction = now();
    }
    if (held(GLFW_KEY_MINUS) || held(GLFW_KEY_KP_SUBTRACT) || held(GLFW_KEY_PAGE_DOWN)) {
        zoom(v.camera, 1.0f + step * 0.5f);
        v.lastInteraction = now();
    }
    auto hit = [&](int key) { return ImGui::IsKeyPressed(key, false); };
    if (ctrl && hit(GLFW_KEY_Z)) shift ? redo(v) : undo(v);
    if (ctrl && hit(GLFW_KEY_Y)) redo(v);
    if (ctrl && hit(GLFW_KEY_S)) save(v, savePathOf(v));
    if (ctrl) return;
    if (hit(GLFW_KEY_F)) frameSelection(v);
    if (hit(GLFW_KEY_R)) resetCamera(v), v.lastInteraction = now();
    if (hit(GLFW_KEY_1)) v.mode = RenderMode::Shaded;
    if (hit(GLFW_KEY_2)) v.mode = RenderMode::Normals;
    if (hit(GLFW_KEY_3)) v.mode = RenderMode::Depth;
    if (hit(GLFW_KEY_4)) v.mode = RenderMode::Steps;
    if (hit(GLFW_KEY_H)) v.showUi = !v.showUi;
    if (hit(GLFW_KEY_G)) v.grid = !v.grid;
    if (hit(GLFW_KEY_M) && v.mesh) v.meshView = !v.meshView;
    if (hit(GLFW_KEY_B)) v.boxes = BoxOverlay((uint32_t(v.boxes) + 1) % 3);
    if (hit(GLFW_KEY_ESCAPE)) v.selected = -1;
}

} // namespace sdfcsg::viewer
