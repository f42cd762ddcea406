// The commands of --script (script.h lists them), applied as the controls would apply them, so
// the tests drive the real window. One table names each command's action and what it waits
// for; runScript() runs the commands in turn.
#include "viewer.h"

#include "edit.h"
#include "picking.h"

#include <glm/trigonometric.hpp>

#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>

namespace fs = std::filesystem;

namespace sdfcsg::viewer {

namespace {

// A command's failure, as the message to print after its file and line; none when it succeeded.
using Failure = std::optional<std::string>;

// What a command waits for before it runs.
enum class Wait {
    None,
    Image,  // the full-resolution image of the current state (commands that look at it)
    Reload, // a reload of the scene's file that no earlier wait-reload answered
};

// The arguments of an action: the command, its first argument ("" when none) and its
// "file:line: " prefix, which the commands that finish later keep for their messages.
struct Step {
    const Command& c;
    const std::string& arg;
    const std::string& where;
};

struct Action {
    std::string_view verb;
    Failure (*run)(Viewer& v, const Step& s);
    Wait wait = Wait::None;
    bool needsScene = true;
};

std::optional<uint32_t> selectedNode(const Viewer& v) {
    if (v.selected < 0 || v.selected >= int(v.scene->nodes.size())) return std::nullopt;
    return uint32_t(v.selected);
}

NodeKind kindNamed(const std::string& name) {
    for (const KindInfo& k : nodeKinds())
        if (k.name == name) return k.kind;
    return NodeKind::Sphere; // parseScript admits known names only
}

Failure noNode(const std::string& name) {
    return "no node named \"" + name + "\"";
}

Failure selectNode(Viewer& v, const Step& s) {
    if (s.arg == "none") {
        v.selected = -1;
    } else if (auto n = findNode(*v.scene, s.arg)) {
        v.selected = int(*n);
    } else {
        return noNode(s.arg);
    }
    return std::nullopt;
}

Failure setSelected(Viewer& v, const Step& s) {
    if (v.selected < 0) return "set: no node selected";
    auto edited = setValue(*v.scene, uint32_t(v.selected), s.arg, s.c.numbers);
    if (!edited) return edited.error().str();
    commit(v, std::move(edited));
    return std::nullopt;
}

Failure saveScene(Viewer& v, const Step& s) {
    fs::path path = !s.arg.empty() ? fs::path(s.arg) : savePathOf(v);
    auto saved = v.doc.save(path);
    if (!saved) return saved.error().str();
    return std::nullopt;
}

// add, remove, kind, op, move and parent: an edit of the tree at the selected node.
Failure editTree(Viewer& v, const Step& s) {
    const std::string& verb = s.c.verb;
    auto node = selectedNode(v);
    if (!node) return verb + ": no node selected";
    uint32_t moved = *node;
    std::optional<uint32_t> parent;
    if (verb == "parent" && !(parent = findNode(*v.scene, s.arg))) return noNode(s.arg);
    const uint32_t index = s.c.numbers.empty() ? kLastChild : uint32_t(s.c.numbers[0]);
    Result<Scene> edited =
        verb == "add"      ? addChild(*v.scene, *node, kindNamed(s.arg), &moved)
        : verb == "parent" ? reparentNode(*v.scene, *node, *parent, index, &moved)
        : verb == "remove" ? removeNode(*v.scene, *node)
        : verb == "move"   ? moveNode(*v.scene, *node, s.arg == "up" ? -1 : 1, &moved)
                           : changeKind(*v.scene, *node, kindNamed(s.arg));
    if (!edited) return edited.error().str();
    commit(v, std::move(edited));
    // As the Node panel's buttons leave the selection.
    v.selected = verb == "remove" ? -1 : int(moved);
    return std::nullopt;
}

Failure printBounds(Viewer& v, const Step& s) {
    auto n = findNode(*v.scene, s.arg);
    if (!n) return noNode(s.arg);
    Evaluator shown(*v.last.scene);
    if (*n >= shown.nodes().size()) return "print-bounds: the image shows no " + s.arg;
    PixelRect r = projectedRect(*v.last.options.camera, v.last.image.width, v.last.image.height,
                                shown.nodes()[*n].bounds);
    std::printf("bounds %s %d %d %d %d\n", s.arg.c_str(), r.x0, r.y0, r.x1, r.y1);
    std::fflush(stdout);
    return std::nullopt;
}

// The field notes the Scene panel lists, a line each.
Failure printNotes(Viewer& v, const Step&) {
    for (const FieldNote& note : v.fieldNotes)
        std::printf("note %s: %s\n", note.path.c_str(), note.message.c_str());
    std::fflush(stdout);
    return std::nullopt;
}

Failure expectError(Viewer& v, const Step& s) {
    const std::string& want = s.c.text;
    std::string shown = v.doc.error() ? v.doc.error()->str() : "";
    if (v.renderError) {
        if (!shown.empty()) shown += '\n';
        shown += v.renderError->str();
    }
    if (want == "none" ? !shown.empty() : shown.find(want) == std::string::npos)
        return "expected the error \"" + want + "\", shown: \"" + shown + "\"";
    return std::nullopt;
}

Failure expectSelected(Viewer& v, const Step& s) {
    std::optional<uint32_t> want;
    if (s.arg != "none") {
        want = findNode(*v.scene, s.arg);
        if (!want) return noNode(s.arg);
    }
    const std::optional<uint32_t> got = selectedNode(v);
    if (got != want)
        return "expected " + (want ? nodeLabel(*v.scene, *want) : "no node") + " selected, got " +
               (got ? nodeLabel(*v.scene, *got) : "none");
    return std::nullopt;
}

// mesh extract (as if set in the panel) and mesh export; the script waits for either to finish.
Failure meshCommand(Viewer& v, const Step& s) {
    if (s.arg == "extract") {
        v.meshResolution = int(s.c.numbers[0]);
        v.meshMethod = s.c.args.size() > 2 && s.c.args[2] == "mc" ? 1 : 0;
        v.meshSimplify = s.c.numbers[1];
        startMesh(v);
        v.meshScript = s.where;
        return std::nullopt;
    }
    if (!v.mesh) return "mesh export: no mesh extracted";
    if (auto problem = startExport(v, s.c.args[1])) return *problem;
    v.exportScript = s.where;
    return std::nullopt;
}

// generate and edit-scene; the script waits for the generation.
Failure generateScene(Viewer& v, const Step& s) {
    std::snprintf(v.prompt, sizeof v.prompt, "%s", s.c.text.c_str()); // as if typed
    startGeneration(v, s.c.text, s.c.verb == "edit-scene");
    v.generationScript = s.where;
    return std::nullopt;
}

// shadows, ao, grid, ui and wireframe: on or off.
template <bool Viewer::*flag> Failure toggle(Viewer& v, const Step& s) {
    v.*flag = s.arg == "on";
    return std::nullopt;
}

Failure showThinWalls(Viewer& v, const Step& s) {
    if (!v.mesh) return "thin-walls: no mesh extracted";
    if (v.meshWalls.empty()) return "thin-walls: the mesh is too large to measure every wall";
    v.thinWalls = s.arg == "on";
    std::string error;
    if (!uploadShownMesh(v, *v.mesh, error)) return "thin-walls: " + error;
    return std::nullopt;
}

Failure setMode(Viewer& v, const Step& s) {
    v.mode = *parseRenderMode(s.arg);
    return std::nullopt;
}

Failure setBoxes(Viewer& v, const Step& s) {
    v.boxes = s.arg == "none"  ? BoxOverlay::None
              : s.arg == "all" ? BoxOverlay::All
                               : BoxOverlay::Selected;
    return std::nullopt;
}

// orbit, and drag: the same as a mouse drag, so the view counts as moving for a moment.
Failure turn(Viewer& v, const Step& s) {
    orbit(v.camera, glm::radians(s.c.numbers[0]), glm::radians(s.c.numbers[1]));
    if (s.c.verb == "drag") v.lastInteraction = now();
    return std::nullopt;
}

Failure zoomBy(Viewer& v, const Step& s) {
    zoom(v.camera, s.c.numbers[0]);
    return std::nullopt;
}

Failure frameView(Viewer& v, const Step&) {
    frameSelection(v);
    v.lastInteraction = -1.0;
    return std::nullopt;
}

template <void (*action)(Viewer&)> Failure call(Viewer& v, const Step&) {
    action(v);
    return std::nullopt;
}

Failure openScene(Viewer& v, const Step& s) {
    openFile(v, s.arg); // a failure shows in the panel, as in the file browser
    return std::nullopt;
}

Failure waitReload(Viewer& v, const Step&) {
    --v.reloads;
    return std::nullopt;
}

Failure pickPixel(Viewer& v, const Step& s) {
    pick(v, s.c.numbers[0], s.c.numbers[1]);
    return std::nullopt;
}

Failure takeScreenshot(Viewer& v, const Step& s) {
    v.pendingShot = s.arg;
    v.waitStart = now();
    return std::nullopt;
}

Failure setView(Viewer& v, const Step& s) {
    if (s.arg == "mesh" && !v.mesh) return "view mesh: no mesh extracted";
    v.meshView = s.arg == "mesh";
    return std::nullopt;
}

const Action kActions[] = {
    {"select", selectNode},
    {"set", setSelected},
    {"mode", setMode},
    {"shadows", toggle<&Viewer::shadows>},
    {"ao", toggle<&Viewer::ao>},
    {"grid", toggle<&Viewer::grid>},
    {"boxes", setBoxes},
    {"orbit", turn},
    {"drag", turn},
    {"zoom", zoomBy},
    {"frame", frameView},
    {"reset", call<resetCamera>},
    {"undo", call<undo>},
    {"redo", call<redo>},
    {"save", saveScene},
    {"add", editTree},
    {"remove", editTree},
    {"kind", editTree},
    {"op", editTree},
    {"move", editTree},
    {"parent", editTree},
    {"open", openScene, Wait::None, false},
    {"wait-reload", waitReload, Wait::Reload},
    {"pick", pickPixel, Wait::Image},
    {"ui", toggle<&Viewer::showUi>},
    {"print-bounds", printBounds, Wait::Image},
    {"print-notes", printNotes, Wait::Image},
    {"expect-error", expectError, Wait::Image},
    {"expect-selected", expectSelected},
    {"screenshot", takeScreenshot},
    {"mesh", meshCommand},
    {"view", setView},
    {"wireframe", toggle<&Viewer::wireframe>},
    {"thin-walls", showThinWalls},
    {"generate", generateScene, Wait::None, false},
    {"edit-scene", generateScene, Wait::None, false},
};

const Action* actionFor(const std::string& verb) {
    for (const Action& a : kActions)
        if (a.verb == verb) return &a;
    return nullptr;
}

bool waiting(Viewer& v, Wait wait) {
    return (wait == Wait::Image && !settled(v)) || (wait == Wait::Reload && v.reloads == 0);
}

} // namespace

bool runScript(Viewer& v) {
    // A script's extraction or write is waited for until finishMesh() has taken its result.
    while (!v.script.empty() && v.pendingShot.empty() && !v.generating && v.meshScript.empty() &&
           v.exportScript.empty()) {
        Command c = v.script.front();
        v.script.pop_front();
        const std::string where = v.scriptFile + ":" + std::to_string(c.line) + ": ";
        auto fail = [&](const std::string& message) {
            std::fprintf(stderr, "%s%s\n", where.c_str(), message.c_str());
            v.exitCode = 1;
            return false;
        };
        syncScene(v);
        const Action* action = actionFor(c.verb);
        if (!action) return fail("unknown command \"" + c.verb + "\"");
        if (!v.scene && action->needsScene) return fail("no scene loaded");
        if (waiting(v, action->wait)) {
            if (v.commandWaitStart == 0) v.commandWaitStart = now();
            if (now() - v.commandWaitStart > 300.0)
                return fail(c.verb + ": still waiting after 300 s");
            v.script.push_front(c);
            return true;
        }
        v.commandWaitStart = 0;
        const std::string arg = c.args.empty() ? "" : c.args[0];
        if (Failure failed = action->run(v, Step{c, arg, where})) return fail(*failed);
        syncScene(v);
    }
    return true;
}

} // namespace sdfcsg::viewer
