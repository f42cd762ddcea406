// The ImGui panels: the "sdfcsg" window with its File and View sections, the scene tree
// (nodeTree), the selected node's values (valueEditor), the mesh panel (meshPanel) and the
// Generate panel (generatePanel), and the file browser's window.
#include "viewer.h"

#include "edit.h"

#include <imgui.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace fs = std::filesystem;

namespace sdfcsg::viewer {

namespace {

// A dragged tree node's payload: its index in v.scene.
constexpr const char* kNodePayload = "sdfcsg-node";

// Draws the tree below `node`. A node dropped on another is only recorded in *drop (dragged,
// target), to apply once the tree is drawn: the edit renumbers the nodes being drawn.
void nodeTree(Viewer& v, uint32_t node, std::optional<std::pair<uint32_t, uint32_t>>* drop) {
    const Scene& s = *v.scene;
    const Node& n = s.nodes[node];
    bool operation = kindInfo(n.kind).operation;
    ImGuiTreeNodeFlags flags = ImGuiTreeNodeFlags_OpenOnArrow | ImGuiTreeNodeFlags_DefaultOpen |
                               ImGuiTreeNodeFlags_SpanAvailWidth;
    if (!operation) flags |= ImGuiTreeNodeFlags_Leaf | ImGuiTreeNodeFlags_NoTreePushOnOpen;
    if (int(node) == v.selected) flags |= ImGuiTreeNodeFlags_Selected;
    std::string label = nodeLabel(s, node);
    for (const ParamInfo& p : kindInfo(n.kind).params) // other operations keep other values there
        if (p.name == "smooth" && n.params[p.slot] > 0.0f)
            label += " smooth " + std::to_string(n.params[p.slot]).substr(0, 5);
    bool open = ImGui::TreeNodeEx((void*)(uintptr_t)node, flags, "%s", label.c_str());
    if (ImGui::IsItemClicked() && !ImGui::IsItemToggledOpen()) v.selected = int(node);
    if (node != 0 && ImGui::BeginDragDropSource()) { // the root has nowhere to go
        ImGui::SetDragDropPayload(kNodePayload, &node, sizeof node);
        ImGui::TextUnformatted(nodeLabel(s, node).c_str());
        ImGui::EndDragDropSource();
    }
    if (ImGui::BeginDragDropTarget()) {
        if (const ImGuiPayload* payload = ImGui::AcceptDragDropPayload(kNodePayload)) {
            uint32_t dragged = 0;
            std::memcpy(&dragged, payload->Data, sizeof dragged);
            if (dragged != node) *drop = std::pair(dragged, node);
        }
        ImGui::EndDragDropTarget();
    }
    if (operation && open) {
        for (uint32_t c : n.children)
            nodeTree(v, c, drop);
        ImGui::TreePop();
    }
}

// A use's values for its definition's parameters: numbers are dragged like a node's own, other
// values (arrays, strings) shown as written.
template <class Edit> void useArguments(Viewer& v, uint32_t id, Edit&& edited) {
    const Node& n = v.scene->nodes[id];
    const Definition* definition = nullptr;
    for (const Definition& d : v.scene->definitions)
        if (d.name == n.use->definition) definition = &d;
    if (!definition) return;
    for (const NamedValue& p : definition->parameters) {
        std::string json = p.json;
        bool given = false;
        for (const NamedValue& a : n.use->arguments)
            if (a.name == p.name) json = a.json, given = true;
        const char* end = json.c_str() + json.size();
        char* parsed = nullptr;
        float value = std::strtof(json.c_str(), &parsed);
        if (parsed == end && !json.empty()) {
            if (ImGui::DragFloat(p.name.c_str(), &value, 0.01f, -1e6f, 1e6f, "%.3f"))
                edited(p.name.c_str(), {value});
            if (ImGui::IsItemDeactivatedAfterEdit()) v.doc.history().endMerge();
        } else {
            ImGui::Text("%s: %s", p.name.c_str(), json.c_str());
        }
        if (!given) {
            ImGui::SameLine();
            ImGui::TextDisabled("(default)");
        }
    }
}

// A note on the scene's field (fieldNotes), in the warnings' colour.
void fieldNote(const FieldNote& note) {
    ImGui::PushStyleColor(ImGuiCol_Text, IM_COL32(255, 200, 90, 255));
    ImGui::TextWrapped("note: %s", note.message.c_str());
    ImGui::PopStyleColor();
}

void valueEditor(Viewer& v) {
    if (v.selected < 0 || v.selected >= int(v.scene->nodes.size())) {
        ImGui::TextDisabled("Click a node in the tree or the image to select it.");
        return;
    }
    uint32_t id = uint32_t(v.selected);
    const Node n = v.scene->nodes[id]; // a copy: edits replace the scene
    const KindInfo& info = kindInfo(n.kind);
    ImGui::Text("%s", nodeLabel(*v.scene, id).c_str());
    ImGui::TextDisabled("%s", n.path.c_str());
    for (const FieldNote& note : v.fieldNotes)
        if (note.path == n.path) fieldNote(note);
    if (const int use = copyingUse(*v.scene, id); use >= 0) {
        // The loader makes the copy from the definition: nothing here is the file's to change.
        const Node& u = v.scene->nodes[use];
        ImGui::TextWrapped("Part of the copy that the use of \"%s\" at %s makes: change the "
                           "definition in the scene file, or the use's parameters.",
                           u.use->definition.c_str(), u.path.c_str());
        return;
    }
    auto edited = [&](const char* key, std::vector<float> values) {
        commit(v, setValue(*v.scene, id, key, values), std::to_string(id) + key);
        v.lastInteraction = now(); // previews while a value is dragged, as while the camera moves
    };
    if (n.use) useArguments(v, id, edited);
    for (const ParamInfo& p : n.use ? std::span<const ParamInfo>() : info.params) {
        std::string name(p.name);
        float min = p.check == Check::Positive      ? 1e-3f
                    : p.check == Check::NonNegative ? 0.0f
                                                    : -1e6f;
        if (p.type == ValueType::Choice) {
            const size_t chosen = std::min(size_t(n.params[p.slot]), p.choices.size() - 1);
            if (ImGui::BeginCombo(name.c_str(), std::string(p.choices[chosen]).c_str())) {
                for (size_t c = 0; c < p.choices.size(); ++c)
                    if (ImGui::Selectable(std::string(p.choices[c]).c_str(), c == chosen) &&
                        c != chosen)
                        edited(name.c_str(), {float(c)});
                ImGui::EndCombo();
            }
            continue;
        }
        if (p.type == ValueType::Text) {
            char text[1024];
            std::snprintf(text, sizeof text, "%s", n.strings[p.slot].c_str());
            if (ImGui::InputText(name.c_str(), text, sizeof text,
                                 ImGuiInputTextFlags_EnterReturnsTrue))
                commit(v, setText(*v.scene, id, p.name, text), std::to_string(id) + name);
            continue;
        }
        if (p.type == ValueType::Points) {
            std::vector<float> flat;
            for (glm::vec2 q : n.points)
                flat.insert(flat.end(), {q.x, q.y});
            bool moved = false;
            for (size_t i = 0; i < n.points.size(); ++i)
                moved |= ImGui::DragFloat2(("point " + std::to_string(i)).c_str(), &flat[2 * i],
                                           0.01f, -1e6f, 1e6f, "%.3f");
            if (moved) edited(name.c_str(), flat);
            if (ImGui::IsItemDeactivatedAfterEdit()) v.doc.history().endMerge();
            continue;
        }
        if (p.type == ValueType::Number) {
            float value = n.params[p.slot];
            if (ImGui::DragFloat(name.c_str(), &value, 0.01f, min, std::min(p.maximum, 1e6f),
                                 "%.3f"))
                edited(name.c_str(), {std::clamp(value, min, p.maximum)});
        } else {
            float value[3] = {n.params[p.slot], n.params[p.slot + 1], n.params[p.slot + 2]};
            if (ImGui::DragFloat3(name.c_str(), value, 0.01f, min, 1e6f, "%.3f"))
                edited(name.c_str(),
                       {std::max(value[0], min), std::max(value[1], min), std::max(value[2], min)});
        }
        if (ImGui::IsItemDeactivatedAfterEdit()) v.doc.history().endMerge();
    }
    glm::vec3 t = n.transform.translate, r = n.transform.rotate;
    glm::vec3 s = n.transform.scale;
    if (ImGui::DragFloat3("translate", &t.x, 0.01f)) edited("translate", {t.x, t.y, t.z});
    if (ImGui::IsItemDeactivatedAfterEdit()) v.doc.history().endMerge();
    if (ImGui::DragFloat3("rotate", &r.x, 0.5f)) edited("rotate", {r.x, r.y, r.z});
    if (ImGui::IsItemDeactivatedAfterEdit()) v.doc.history().endMerge();
    if (ImGui::DragFloat3("scale", &s.x, 0.005f, 1e-3f, 1e3f))
        edited("scale", {std::max(s.x, 1e-3f), std::max(s.y, 1e-3f), std::max(s.z, 1e-3f)});
    if (ImGui::IsItemDeactivatedAfterEdit()) v.doc.history().endMerge();
    bool own = n.color.has_value();
    if (ImGui::Checkbox("own colour", &own))
        own ? edited("color", {0.8f, 0.8f, 0.8f}) : edited("color", {});
    if (own) {
        glm::vec3 c = *n.color;
        if (ImGui::ColorEdit3("color", &c.x)) edited("color", {c.x, c.y, c.z});
        if (ImGui::IsItemDeactivatedAfterEdit()) v.doc.history().endMerge();
    }

    ImGui::Separator();
    // Structural edits: the renderer recompiles on the worker thread.
    if (!n.use && ImGui::BeginCombo("kind", std::string(info.name).c_str())) {
        for (const KindInfo& k : nodeKinds())
            if (k.operation == info.operation &&
                ImGui::Selectable(std::string(k.name).c_str(), k.kind == n.kind) &&
                k.kind != n.kind)
                commit(v, changeKind(*v.scene, id, k.kind));
        ImGui::EndCombo();
    }
    if (info.operation && !n.use) {
        if (ImGui::BeginCombo("add child", "choose a kind")) {
            for (const KindInfo& k : nodeKinds())
                if (ImGui::Selectable(std::string(k.name).c_str())) {
                    uint32_t added = 0;
                    if (commit(v, addChild(*v.scene, id, k.kind, &added))) v.selected = int(added);
                }
            ImGui::EndCombo();
        }
    }
    if (ImGui::Button("move up")) {
        uint32_t moved = id;
        if (commit(v, moveNode(*v.scene, id, -1, &moved))) v.selected = int(moved);
    }
    ImGui::SameLine();
    if (ImGui::Button("move down")) {
        uint32_t moved = id;
        if (commit(v, moveNode(*v.scene, id, 1, &moved))) v.selected = int(moved);
    }
    ImGui::SameLine();
    if (ImGui::Button("remove") && commit(v, removeNode(*v.scene, id))) v.selected = -1;
}

void fileBrowser(Viewer& v) {
    if (!v.browserOpen) return;
    ImGui::SetNextWindowSize(ImVec2(420, 360), ImGuiCond_FirstUseEver);
    if (ImGui::Begin("Open scene", &v.browserOpen)) {
        ImGui::TextWrapped("%s", v.browseDir.string().c_str());
        if (ImGui::Selectable("..")) v.browseDir = v.browseDir.parent_path();
        // Listed again on navigation and every second, not every frame: a large or network
        // folder would slow the window down.
        std::error_code ec;
        if (v.browseListed != v.browseDir || now() - v.browseTime > 1.0) {
            v.browseEntries.clear();
            for (const auto& e : fs::directory_iterator(v.browseDir, ec))
                if (e.is_directory(ec) || e.path().extension() == ".json")
                    v.browseEntries.push_back(e);
            std::sort(v.browseEntries.begin(), v.browseEntries.end(), [](auto& a, auto& b) {
                return std::pair(!a.is_directory(), a.path()) <
                       std::pair(!b.is_directory(), b.path());
            });
            v.browseListed = v.browseDir;
            v.browseTime = now();
        }
        const std::vector<fs::directory_entry> entries = v.browseEntries; // may change below
        for (const auto& e : entries) {
            std::string name = e.path().filename().string() + (e.is_directory(ec) ? "/" : "");
            if (ImGui::Selectable(name.c_str())) {
                if (e.is_directory(ec)) {
                    v.browseDir = e.path();
                } else {
                    openFile(v, e.path());
                    v.browserOpen = false;
                }
            }
        }
    }
    ImGui::End();
}

void meshPanel(Viewer& v) {
    ImGui::SliderInt("resolution", &v.meshResolution, 16, 512);
    ImGui::Combo("method", &v.meshMethod, "dual contouring (sharp edges)\0marching cubes\0");
    // Off at 0: a distance in cells, so that one setting serves every resolution.
    ImGui::SliderFloat("simplify", &v.meshSimplify, 0.0f, 1.0f,
                       v.meshSimplify > 0.0f ? "within %.2f cell" : "off");
    ImGui::Checkbox("custom bounds", &v.customBounds);
    if (v.customBounds) {
        ImGui::DragFloat3("min", v.boundsMin, 0.01f);
        ImGui::DragFloat3("max", v.boundsMax, 0.01f);
    }
    if (v.mesher->running()) {
        ImGui::ProgressBar(v.mesher->progress());
        if (ImGui::Button("cancel")) v.mesher->cancel();
    } else if (ImGui::Button("extract mesh") && v.scene) {
        startMesh(v);
    }
    if (!v.meshMessage.empty()) ImGui::TextWrapped("%s", v.meshMessage.c_str());
    if (!v.mesh) return;
    ImGui::Checkbox("show mesh (M)", &v.meshView);
    ImGui::SameLine();
    ImGui::Checkbox("wireframe", &v.wireframe);
    if (v.meshView) {
        if (v.shown.meshPreview)
            ImGui::Text("preview mesh: %u triangles", previewMeshTriangles(*v.presenter));
        else
            ImGui::Text("full mesh: %zu triangles", v.mesh->triangleCount());
        if (v.meshStats.unsimplifiedTriangles > 0)
            ImGui::Text("simplified from %llu triangles, %.3f cell from the surface at most",
                        (unsigned long long)v.meshStats.unsimplifiedTriangles,
                        v.meshStats.simplifiedError / v.meshStats.voxelSize);
        ImGui::Text("mesh frame %.1f ms, last drawn in %.1f ms", v.meshFrameMs, v.meshDrawMs);
        const MeshReport& r = v.meshReport;
        if (r.watertight())
            ImGui::Text("watertight: %zu shell%s, genus %lld", r.shells, r.shells == 1 ? "" : "s",
                        static_cast<long long>(r.genus()));
        else
            ImGui::TextColored(ImVec4(1.0f, 0.6f, 0.3f, 1.0f),
                               "not watertight: %zu boundary, %zu non-manifold, %zu misoriented "
                               "edges, %zu self-intersections",
                               r.boundaryEdges, r.nonManifoldEdges, r.misorientedEdges,
                               r.selfIntersections);
        ImGui::Text("volume %.4g, area %.4g", r.volume, r.area);
        if (!v.meshWalls.empty() && ImGui::Checkbox("thin walls in red", &v.thinWalls)) {
            std::string error;
            if (!uploadShownMesh(v, *v.mesh, error)) v.meshMessage = error;
        }
        if (const auto& p = r.printability; p && p->samples > 0)
            ImGui::Text("thinnest wall %.3g; %.1f%% of the surface thinner than %.3g; overhangs "
                        "%.1f%%",
                        double(p->thinnestWall), r.area > 0 ? 100.0 * p->thinArea / r.area : 0.0,
                        double(p->minWall), r.area > 0 ? 100.0 * p->overhangArea / r.area : 0.0);
    }
    ImGui::InputText("file", v.exportPath, sizeof v.exportPath);
    if (meshFormatFromPath(v.exportPath) == MeshFormat::ThreeMf)
        ImGui::Combo("one scene unit is", &v.exportUnit, "1 mm\0 1 cm\0 1 m\0 1 inch\0");
    ImGui::SameLine();
    if (v.exporter->running()) {
        ImGui::TextDisabled("writing...");
    } else if (ImGui::Button("export")) {
        if (auto problem = startExport(v, v.exportPath)) v.meshMessage = *problem;
    }
}

void generatePanel(Viewer& v) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped("%s", v.endpoint.c_str());
    ImGui::PopStyleColor();
    ImGui::InputTextMultiline("##prompt", v.prompt, sizeof v.prompt,
                              ImVec2(-1, ImGui::GetTextLineHeight() * 4));
    if (v.generating) {
        const GenerateStatus s = v.generator->status();
        ImGui::Text("%c %.0f s", "|/-\\"[int(s.seconds * 8) % 4], s.seconds);
        ImGui::SameLine();
        if (ImGui::Button("Cancel")) v.generator->cancel();
        ImGui::TextWrapped("%s", s.message.c_str());
    } else {
        ImGui::BeginDisabled(!v.prompt[0] || !v.endpointOk);
        if (ImGui::Button("Generate new scene")) startGeneration(v, v.prompt, false);
        ImGui::SameLine();
        ImGui::BeginDisabled(!v.doc.loaded());
        if (ImGui::Button("Edit this scene")) startGeneration(v, v.prompt, true);
        ImGui::EndDisabled();
        ImGui::EndDisabled();
    }
    if (!v.generateSummary.empty()) ImGui::TextWrapped("%s", v.generateSummary.c_str());
    ImGui::PushStyleColor(ImGuiCol_Text, IM_COL32(255, 200, 90, 255));
    for (const Diagnostic& w : v.generateWarnings)
        ImGui::TextWrapped("warning: %s: %s", w.path.c_str(), w.message.c_str());
    ImGui::PopStyleColor();
    if (v.generateError) {
        ImGui::PushStyleColor(ImGuiCol_Text, IM_COL32(255, 110, 110, 255));
        ImGui::TextWrapped("%s", v.generateError->str().c_str());
        ImGui::PopStyleColor();
        ImGui::TextDisabled("the scene was not changed");
    }
}

} // namespace

void panels(Viewer& v) {
    ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(340, 0), ImGuiCond_FirstUseEver);
    ImGui::Begin("sdfcsg");
    if (ImGui::CollapsingHeader("File", ImGuiTreeNodeFlags_DefaultOpen)) {
        ImGui::InputText("##open", v.openPath, sizeof v.openPath);
        ImGui::SameLine();
        if (ImGui::Button("open") && v.openPath[0]) openFile(v, v.openPath);
        ImGui::SameLine();
        if (ImGui::Button("browse")) v.browserOpen = true;
        if (!v.recent.empty() && ImGui::BeginCombo("recent", v.recent[0].c_str())) {
            for (const std::string& r : std::vector<std::string>(v.recent))
                if (ImGui::Selectable(r.c_str())) openFile(v, r);
            ImGui::EndCombo();
        }
        ImGui::InputText("##save", v.savePath, sizeof v.savePath);
        ImGui::SameLine();
        if (ImGui::Button("save") && v.savePath[0]) save(v, v.savePath);
        ImGui::BeginDisabled(!v.doc.history().canUndo());
        if (ImGui::Button("undo")) undo(v);
        ImGui::EndDisabled();
        ImGui::SameLine();
        ImGui::BeginDisabled(!v.doc.history().canRedo());
        if (ImGui::Button("redo")) redo(v);
        ImGui::EndDisabled();
    }
    // Load errors (the file) and compile errors (the edited scene) both keep the last good
    // scene on screen.
    const std::optional<Error>* errors[] = {&v.doc.error(), &v.renderError};
    for (const std::optional<Error>* e : errors) {
        if (!*e) continue;
        ImGui::PushStyleColor(ImGuiCol_Text, IM_COL32(255, 110, 110, 255));
        ImGui::TextWrapped("%s", (*e)->str().c_str());
        ImGui::PopStyleColor();
        if (v.scene) ImGui::TextDisabled("showing the last scene that worked");
    }
    if (!v.status.empty()) ImGui::TextWrapped("%s", v.status.c_str());
    if (ImGui::CollapsingHeader("View", ImGuiTreeNodeFlags_DefaultOpen)) {
        int mode = int(v.mode);
        ImGui::RadioButton("shaded", &mode, 0);
        ImGui::SameLine();
        ImGui::RadioButton("normals", &mode, 1);
        ImGui::SameLine();
        ImGui::RadioButton("depth", &mode, 2);
        ImGui::SameLine();
        ImGui::RadioButton("steps", &mode, 3);
        v.mode = RenderMode(mode);
        ImGui::Checkbox("shadows", &v.shadows);
        ImGui::SameLine();
        ImGui::Checkbox("AO", &v.ao);
        ImGui::SameLine();
        ImGui::Checkbox("grid", &v.grid);
        int boxes = int(v.boxes);
        ImGui::Combo("boxes", &boxes, "none\0all\0selected\0");
        v.boxes = BoxOverlay(boxes);
        if (ImGui::Button("frame (F)")) frameSelection(v);
        ImGui::SameLine();
        if (ImGui::Button("reset (R)")) resetCamera(v), v.lastInteraction = now();
        ImGui::InputText("##shot", v.shotPath, sizeof v.shotPath);
        ImGui::SameLine();
        if (ImGui::Button("screenshot")) v.pendingShot = v.shotPath;
        ImGui::Text("render %.0f ms at %u x %u%s", v.renderMs, v.last.image.width,
                    v.last.image.height,
                    v.haveShown && v.shown.width < wantedKey(v, true).width ? " (preview)" : "");
        if (v.compileMs > 0) ImGui::Text("last compile %.0f ms", v.compileMs);
        ImGui::Text("UI %.1f ms/frame", 1000.0f / std::max(ImGui::GetIO().Framerate, 1.0f));
        ImGui::TextDisabled("%s", v.context->deviceName().c_str());
    }
    if (v.scene && ImGui::CollapsingHeader("Scene", ImGuiTreeNodeFlags_DefaultOpen)) {
        ImGui::BeginChild("tree", ImVec2(0, 220), true);
        std::optional<std::pair<uint32_t, uint32_t>> drop;
        nodeTree(v, 0, &drop);
        ImGui::EndChild();
        uint32_t moved = 0;
        if (drop && commit(v, dropNode(*v.scene, drop->first, drop->second, &moved)))
            v.selected = int(moved);
        if (!v.fieldNotes.empty() &&
            ImGui::TreeNode("fieldnotes", "%zu field note%s", v.fieldNotes.size(),
                            v.fieldNotes.size() == 1 ? "" : "s")) {
            for (const FieldNote& note : v.fieldNotes) {
                ImGui::TextDisabled("%s", note.path.c_str());
                fieldNote(note);
            }
            ImGui::TreePop();
        }
    }
    if (v.scene && ImGui::CollapsingHeader("Node", ImGuiTreeNodeFlags_DefaultOpen)) valueEditor(v);
    if (v.scene && ImGui::CollapsingHeader("Mesh")) meshPanel(v);
    // Open at first when started without a scene: describing one is a way to start.
    if (ImGui::CollapsingHeader("Generate", v.startedEmpty ? ImGuiTreeNodeFlags_DefaultOpen : 0))
        generatePanel(v);
    ImGui::End();
    fileBrowser(v);
}

} // namespace sdfcsg::viewer
