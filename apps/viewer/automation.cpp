// The commands of --script (script.h lists them), applied as the controls would apply them, so
// the tests drive the real window.
#include "viewer.h"

#include "edit.h"
#include "picking.h"

#include <glm/trigonometric.hpp>

#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>

namespace fs = std::filesystem;

namespace sdfcsg::viewer {

bool runScript(Viewer& v) {
    // A script's extraction or write is waited for until finishMesh() has taken its result.
    while (!v.script.empty() && v.pendingShot.empty() && !v.generating && v.meshScript.empty() &&
           v.exportScript.empty()) {
        Command c = v.script.front();
        v.script.pop_front();
        std::string where = v.scriptFile + ":" + std::to_string(c.line) + ": ";
        auto fail = [&](const std::string& message) {
            std::fprintf(stderr, "%s%s\n", where.c_str(), message.c_str());
            v.exitCode = 1;
            return false;
        };
        syncScene(v);
        if (!v.scene && c.verb != "generate" && c.verb != "open") return fail("no scene loaded");
        const std::string arg = c.args.empty() ? "" : c.args[0];
        // Commands that look at the image wait for the full-resolution one of the current state.
        const bool needsImage =
            c.verb == "pick" || c.verb == "print-bounds" || c.verb == "expect-error";
        if ((needsImage && !settled(v)) || (c.verb == "wait-reload" && v.reloads == 0)) {
            if (v.commandWaitStart == 0) v.commandWaitStart = now();
            if (now() - v.commandWaitStart > 300.0)
                return fail(c.verb + ": still waiting after 300 s");
            v.script.push_front(c);
            return true;
        }
        v.commandWaitStart = 0;
        auto selectedNode = [&]() -> std::optional<uint32_t> {
            if (v.selected < 0 || v.selected >= int(v.scene->nodes.size())) return std::nullopt;
            return uint32_t(v.selected);
        };
        auto kindNamed = [](const std::string& name) {
            for (const KindInfo& k : nodeKinds())
                if (k.name == name) return k.kind;
            return NodeKind::Sphere; // parseScript admits known names only
        };
        if (c.verb == "select") {
            if (arg == "none") {
                v.selected = -1;
            } else if (auto n = findNode(*v.scene, arg)) {
                v.selected = int(*n);
            } else {
                return fail("no node named \"" + arg + "\"");
            }
        } else if (c.verb == "set") {
            if (v.selected < 0) return fail("set: no node selected");
            auto edited = setValue(*v.scene, uint32_t(v.selected), arg, c.numbers);
            if (!edited) return fail(edited.error().str());
            commit(v, std::move(edited));
        } else if (c.verb == "mode") {
            v.mode = *parseRenderMode(arg);
        } else if (c.verb == "shadows") {
            v.shadows = arg == "on";
        } else if (c.verb == "ao") {
            v.ao = arg == "on";
        } else if (c.verb == "grid") {
            v.grid = arg == "on";
        } else if (c.verb == "boxes") {
            v.boxes = arg == "none"  ? BoxOverlay::None
                      : arg == "all" ? BoxOverlay::All
                                     : BoxOverlay::Selected;
        } else if (c.verb == "orbit" || c.verb == "drag") {
            orbit(v.camera, glm::radians(c.numbers[0]), glm::radians(c.numbers[1]));
            if (c.verb == "drag") v.lastInteraction = now();
        } else if (c.verb == "zoom") {
            zoom(v.camera, c.numbers[0]);
        } else if (c.verb == "frame") {
            frameSelection(v);
            v.lastInteraction = -1.0;
        } else if (c.verb == "reset") {
            resetCamera(v);
        } else if (c.verb == "undo") {
            undo(v);
        } else if (c.verb == "redo") {
            redo(v);
        } else if (c.verb == "save") {
            fs::path path = !arg.empty() ? fs::path(arg) : savePathOf(v);
            auto saved = v.doc.save(path);
            if (!saved) return fail(saved.error().str());
        } else if (c.verb == "add" || c.verb == "remove" || c.verb == "kind" || c.verb == "op" ||
                   c.verb == "move" || c.verb == "parent") {
            auto node = selectedNode();
            if (!node) return fail(c.verb + ": no node selected");
            uint32_t moved = *node;
            std::optional<uint32_t> parent;
            if (c.verb == "parent" && !(parent = findNode(*v.scene, arg)))
                return fail("no node named \"" + arg + "\"");
            Result<Scene> edited =
                c.verb == "add" ? addChild(*v.scene, *node, kindNamed(arg), &moved)
                : c.verb == "parent"
                    ? reparentNode(*v.scene, *node, *parent,
                                   c.numbers.empty() ? kLastChild : uint32_t(c.numbers[0]), &moved)
                : c.verb == "remove" ? removeNode(*v.scene, *node)
                : c.verb == "move"   ? moveNode(*v.scene, *node, arg == "up" ? -1 : 1, &moved)
                                     : changeKind(*v.scene, *node, kindNamed(arg));
            if (!edited) return fail(edited.error().str());
            commit(v, std::move(edited));
            // As the Node panel's buttons leave the selection.
            if (c.verb == "remove")
                v.selected = -1;
            else
                v.selected = int(moved);
        } else if (c.verb == "open") {
            openFile(v, arg); // a failure shows in the panel, as in the file browser
        } else if (c.verb == "wait-reload") {
            --v.reloads;
        } else if (c.verb == "pick") {
            pick(v, c.numbers[0], c.numbers[1]);
        } else if (c.verb == "ui") {
            v.showUi = arg == "on";
        } else if (c.verb == "print-bounds") {
            auto n = findNode(*v.scene, arg);
            if (!n) return fail("no node named \"" + arg + "\"");
            Evaluator shown(*v.last.scene);
            if (*n >= shown.nodes().size()) return fail("print-bounds: the image shows no " + arg);
            PixelRect r = projectedRect(*v.last.options.camera, v.last.image.width,
                                        v.last.image.height, shown.nodes()[*n].bounds);
            std::printf("bounds %s %d %d %d %d\n", arg.c_str(), r.x0, r.y0, r.x1, r.y1);
            std::fflush(stdout);
        } else if (c.verb == "expect-error") {
            std::string shown = v.doc.error() ? v.doc.error()->str() : "";
            if (v.renderError) shown += (shown.empty() ? "" : "\n") + v.renderError->str();
            if (c.text == "none" ? !shown.empty() : shown.find(c.text) == std::string::npos)
                return fail("expected the error \"" + c.text + "\", shown: \"" + shown + "\"");
        } else if (c.verb == "expect-selected") {
            std::optional<uint32_t> want;
            if (arg != "none") {
                want = findNode(*v.scene, arg);
                if (!want) return fail("no node named \"" + arg + "\"");
            }
            if (selectedNode() != want)
                return fail("expected " + (want ? nodeLabel(*v.scene, *want) : "no node") +
                            " selected, got " +
                            (selectedNode() ? nodeLabel(*v.scene, *selectedNode()) : "none"));
        } else if (c.verb == "screenshot") {
            v.pendingShot = arg;
            v.waitStart = now();
        } else if (c.verb == "mesh" && arg == "extract") {
            // As if set in the panel.
            v.meshResolution = int(c.numbers[0]);
            v.meshMethod = c.args.size() > 2 && c.args[2] == "mc" ? 1 : 0;
            v.meshSimplify = c.numbers[1];
            startMesh(v);
            v.meshScript = where;
        } else if (c.verb == "mesh") { // export
            if (!v.mesh) return fail("mesh export: no mesh extracted");
            if (auto problem = startExport(v, c.args[1])) return fail(*problem);
            v.exportScript = where;
        } else if (c.verb == "view") {
            if (arg == "mesh" && !v.mesh) return fail("view mesh: no mesh extracted");
            v.meshView = arg == "mesh";
        } else if (c.verb == "wireframe") {
            v.wireframe = arg == "on";
        } else if (c.verb == "generate" || c.verb == "edit-scene") {
            std::snprintf(v.prompt, sizeof v.prompt, "%s", c.text.c_str()); // as if typed
            startGeneration(v, c.text, c.verb == "edit-scene");
            v.generationScript = where;
        }
        syncScene(v);
    }
    return true;
}

} // namespace sdfcsg::viewer
