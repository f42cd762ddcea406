// The scene loader: simdjson reads the text, then one walk over the DOM validates every value
// against the node kind table (nodes.h) and builds the flat pre-order Scene. The walk keeps its
// own stack, so hostile nesting cannot overflow the C++ stack.
#include "sdfcsg/scene.h"

#include "sdfcsg/eval.h"

#include "scene/json_syntax.h"
#include "scene/json_writer.h"
#include "scene/legacy.h"
#include "scene/outline.h"
#include "scene/parse_util.h"
#include "shared.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <fstream>

namespace sdfcsg {
namespace {

using namespace detail;
namespace dom = simdjson::dom;

// Two JSON levels (the node object and its "children" array) per level of operations, plus the
// scene object and the values inside a node. Never below simdjson's default, so that a tree
// somewhat deeper than the limit still parses and gets the clearer, path-naming message.
size_t jsonDepthLimit(const Limits& limits) {
    return std::max<size_t>(simdjson::DEFAULT_MAX_DEPTH, 2 * size_t(limits.maxDepth) + 8);
}

std::string article(std::string_view noun) {
    return std::string(std::string_view("aeio").find(noun[0]) != std::string_view::npos ? "an "
                                                                                        : "a ") +
           std::string(noun);
}

Error tooLarge(const std::string& file, uintmax_t size, const Limits& limits) {
    return Error::message(ErrorKind::Limit, file,
                          "file too large: " + std::to_string(size) + " bytes (the limit is " +
                              std::to_string(limits.maxFileBytes) + " bytes)");
}

Error syntaxError(const std::string& file, std::string_view text, simdjson::error_code code,
                  size_t maxDepth) {
    if (code == simdjson::MEMALLOC)
        return Error::message(ErrorKind::Io, file, "out of memory while reading JSON");
    auto problem = findSyntaxProblem(text, maxDepth, code == simdjson::NUMBER_ERROR);
    if (!problem) {
        // The scanner and simdjson should agree; if not, simdjson's word is still worth giving.
        return Error::message(ErrorKind::Syntax, file,
                              std::string("invalid JSON: ") + simdjson::error_message(code));
    }
    Diagnostic d{file, {}, std::move(problem->message)};
    lineColumn(text, problem->offset, d.line, d.column);
    return Error(problem->tooDeep ? ErrorKind::Limit : ErrorKind::Syntax, std::move(d));
}

// The keys of each kind's node object: its parameters first (they matter most in a "valid
// keys" list), then the common keys. "children" is last for primitives, so that it can be left
// out of suggestions and reported with its own message.
struct KindKeys {
    std::vector<std::string_view> keys;
    size_t listed;
};

const KindKeys& kindKeys(NodeKind kind) {
    static const auto table = [] {
        std::array<KindKeys, kNodeKindCount> t;
        for (const KindInfo& k : nodeKinds()) {
            KindKeys& kk = t[static_cast<size_t>(k.kind)];
            for (const ParamInfo& p : k.params)
                kk.keys.push_back(p.name);
            for (const CommonKey& c : commonNodeKeys())
                if (c.name != "children") kk.keys.push_back(c.name);
            kk.keys.push_back("children");
            kk.listed = kk.keys.size() - (k.operation ? 0 : 1);
        }
        return t;
    }();
    return table[static_cast<size_t>(kind)];
}

std::vector<std::string_view> kindNameList() {
    std::vector<std::string_view> names;
    for (const KindInfo& k : nodeKinds())
        names.push_back(k.name);
    return names;
}

std::string kindNames() {
    return joinNames(kindNameList(), "or");
}

// A unit vector stays bit-for-bit as written, so that toJson and parseScene round-trip exactly;
// anything else is scaled to unit length.
glm::vec3 normalised(glm::vec3 v) {
    glm::dvec3 d(v);
    double len = std::sqrt(glm::dot(d, d));
    if (std::fabs(len - 1.0) <= 1e-6) return v;
    return glm::vec3(d / len);
}

class SceneReader {
  public:
    SceneReader(const ParseOptions& options, Problems& problems)
        : limits_(options.limits), files_(options.files), problems_(problems) {}

    Scene read(element top);

  private:
    void readCamera(element value, Scene& scene);
    void readLights(element value, Scene& scene);
    void readTree(element root, Scene& scene);
    // Appends the node at `value` to scene.nodes and returns its children when the walk
    // should go on into them.
    std::optional<dom::array> readNode(element value, std::string path, uint32_t depth,
                                       Scene& scene);
    void readParam(const ParamInfo& p, std::optional<element> value, const std::string& path,
                   Node& node, bool& ok);

    const Limits& limits_;
    const SceneFiles& files_;
    Problems& problems_;
    size_t outlineWords_ = 0; // polygon and text outlines so far, in vec4s
};

Scene SceneReader::read(element top) {
    Scene scene;
    if (!top.is_object()) {
        problems_.add({}, "expected a scene (an object with \"version\" and \"root\"), got " +
                              describe(top));
        return scene;
    }
    static constexpr std::string_view kKeys[] = {"version", "name",       "description", "camera",
                                                 "lights",  "background", "root"};
    auto v = readMembers(asObject(top), {}, kKeys, std::size(kKeys), {}, problems_);
    if (!v[0]) {
        problems_.add({}, "missing required key \"version\" (the format version, " +
                              std::to_string(kSceneVersion) + ")");
    } else if (!v[0]->is_number()) {
        problems_.add("version", "expected the number " + std::to_string(kSceneVersion) + ", got " +
                                     describe(*v[0]));
    } else if (v[0]->get_double().value_unsafe() != kSceneVersion) {
        problems_.add("version", "unsupported version " + describe(*v[0]) + "; expected " +
                                     std::to_string(kSceneVersion));
    }
    if (v[1])
        if (auto s = readString(*v[1], "name", kMaxNameCharacters, problems_)) scene.name = *s;
    if (v[2])
        if (auto s = readString(*v[2], "description", 0, problems_)) scene.description = *s;
    if (v[3]) readCamera(*v[3], scene);
    if (v[4]) readLights(*v[4], scene);
    if (v[5])
        if (auto c = readColor(*v[5], "background", problems_)) scene.background = *c;
    if (v[6])
        readTree(*v[6], scene);
    else
        problems_.add({}, "missing required key \"root\" (the top node of the scene)");
    return scene;
}

void SceneReader::readCamera(element value, Scene& scene) {
    if (!value.is_object()) {
        problems_.add("camera", "expected a camera (an object with \"eye\" and \"target\"), got " +
                                    describe(value));
        return;
    }
    static constexpr std::string_view kKeys[] = {"eye", "target", "up", "fov"};
    auto v = readMembers(asObject(value), "camera", kKeys, std::size(kKeys), " for the camera",
                         problems_);
    Camera camera;
    std::optional<glm::vec3> eye, target, up;
    for (int i = 0; i < 2; ++i)
        if (!v[i])
            problems_.add("camera", "missing required key \"" + std::string(kKeys[i]) + "\" (" +
                                        expectedText(ValueType::Vec3, Check::Any) + ")");
    if (v[0]) eye = readVec3(*v[0], "camera.eye", Check::Any, problems_);
    if (v[1]) target = readVec3(*v[1], "camera.target", Check::Any, problems_);
    if (v[2]) up = readVec3(*v[2], "camera.up", Check::NonZero, problems_);
    if (v[3]) {
        auto fov = readNumber(*v[3], "camera.fov", Check::Any, problems_);
        if (fov && !(*fov > 0.0 && *fov < 180.0))
            problems_.add("camera.fov", "expected an angle in degrees between 0 and 180 "
                                        "(exclusive), got " +
                                            describe(*v[3]));
        else if (fov)
            camera.fov = static_cast<float>(*fov);
    }
    if (eye && target && *eye == *target)
        problems_.add("camera.target",
                      "expected a point other than camera.eye, got " + describe(*v[1]));
    else if (eye && target && (up || !v[2])) {
        const glm::vec3 dir = glm::normalize(*target - *eye);
        const bool parallel =
            glm::length(glm::cross(glm::normalize(up.value_or(camera.up)), dir)) < 1e-6f;
        if (parallel && up)
            problems_.add("camera.up", "expected a direction not parallel to the line of sight, "
                                       "got " +
                                           describe(*v[2]));
        else if (parallel)
            problems_.add("camera", "missing required key \"up\" (the line of sight is vertical, "
                                    "so the default up [0, 1, 0] cannot be used)");
    }
    if (eye) camera.eye = *eye;
    if (target) camera.target = *target;
    if (up) camera.up = *up;
    scene.camera = camera;
}

void SceneReader::readLights(element value, Scene& scene) {
    const std::string limit = std::to_string(SDFCSG_MAX_LIGHTS);
    if (!value.is_array()) {
        problems_.add("lights",
                      "expected an array of at most " + limit + " lights, got " + describe(value));
        return;
    }
    dom::array lights = asArray(value);
    if (lights.size() > SDFCSG_MAX_LIGHTS) {
        problems_.add("lights", "expected at most " + limit + " lights, got " +
                                    std::to_string(lights.size()));
        return;
    }
    static constexpr std::string_view kKeys[] = {"direction", "color", "intensity"};
    size_t index = 0;
    for (element e : lights) {
        const std::string path = item("lights", index++);
        if (!e.is_object()) {
            problems_.add(path,
                          "expected a light (an object with \"direction\"), got " + describe(e));
            continue;
        }
        auto v = readMembers(asObject(e), path, kKeys, std::size(kKeys), " for a light", problems_);
        Light light;
        if (!v[0])
            problems_.add(path, "missing required key \"direction\" (" +
                                    expectedText(ValueType::Vec3, Check::NonZero) + ")");
        else if (auto d = readVec3(*v[0], member(path, "direction"), Check::NonZero, problems_))
            light.direction = *d;
        if (v[1])
            if (auto c = readColor(*v[1], member(path, "color"), problems_)) light.color = *c;
        if (v[2])
            if (auto i =
                    readNumber(*v[2], member(path, "intensity"), Check::NonNegative, problems_))
                light.intensity = static_cast<float>(*i);
        scene.lights.push_back(light);
    }
}

void SceneReader::readTree(element root, Scene& scene) {
    struct Frame {
        dom::array::iterator next, end;
        uint32_t parent;
        uint32_t depth; // of the children
        size_t index;   // of the next child
    };
    std::vector<Frame> stack;
    auto visit = [&](element value, std::string path, std::optional<uint32_t> parent,
                     uint32_t depth) {
        if (scene.nodes.size() >= limits_.maxNodes) {
            problems_.add(std::move(path),
                          "too many nodes: a scene may have at most " +
                              std::to_string(limits_.maxNodes),
                          ErrorKind::Limit);
            return false;
        }
        const auto index = static_cast<uint32_t>(scene.nodes.size());
        auto children = readNode(value, std::move(path), depth, scene);
        if (parent) scene.nodes[*parent].children.push_back(index);
        if (children) stack.push_back({children->begin(), children->end(), index, depth + 1, 0});
        return true;
    };
    if (!visit(root, "root", std::nullopt, 0)) return;
    while (!stack.empty()) {
        Frame& top = stack.back();
        if (!(top.next != top.end)) {
            stack.pop_back();
            continue;
        }
        element child = *top.next;
        ++top.next;
        const uint32_t parent = top.parent, depth = top.depth;
        std::string path = item(member(scene.nodes[parent].path, "children"), top.index++);
        if (!visit(child, std::move(path), parent, depth)) return;
    }
}

void SceneReader::readParam(const ParamInfo& p, std::optional<element> value,
                            const std::string& path, Node& node, bool& ok) {
    float* slot = node.params.data() + p.slot;
    if (!value) {
        if (p.required) {
            problems_.add(path, "missing required key \"" + std::string(p.name) + "\" (" +
                                    expectedText(p) + ")");
            ok = false;
        }
        if (p.type != ValueType::Points && p.type != ValueType::Text)
            std::copy_n(p.fallback, p.type == ValueType::Vec3 ? 3 : 1, slot);
        return;
    }
    const std::string keyPath = member(path, p.name);
    if (p.type == ValueType::Text) {
        auto s = readString(*value, keyPath, kMaxTextCharacters, problems_);
        if (s) node.strings[p.slot] = *s;
        ok = ok && s.has_value();
    } else if (p.type == ValueType::Points) {
        const bool array = value->is_array();
        const size_t n = array ? asArray(*value).size() : 0;
        if (!array || n < 3 || n > kMaxPolygonPoints) {
            problems_.add(keyPath, "expected " + expectedText(p) + ", got " +
                                       (array ? std::to_string(n) + " points" : describe(*value)));
            ok = false;
            return;
        }
        int i = 0;
        for (element e : asArray(*value)) {
            const std::string at = item(keyPath, i++);
            if (!e.is_array() || asArray(e).size() != 2) {
                problems_.add(at, "expected a point [x, y], got " + describe(e));
                ok = false;
                continue;
            }
            glm::vec2 q(0.0f);
            int k = 0;
            for (element c : asArray(e)) {
                auto x = readNumber(c, item(at, k), Check::Any, problems_);
                if (x) q[k] = static_cast<float>(*x);
                ok = ok && x.has_value();
                ++k;
            }
            node.points.push_back(q);
        }
    } else if (p.type == ValueType::Choice) {
        std::string_view name;
        if (value->is_string()) name = value->get_string().value_unsafe();
        const auto found = std::find(p.choices.begin(), p.choices.end(), name);
        if (value->is_string() && found != p.choices.end()) {
            *slot = float(found - p.choices.begin());
            return;
        }
        std::string hint = value->is_string() ? didYouMean(name, p.choices) : "";
        problems_.add(keyPath, "expected " + expectedText(p) + ", got " + describe(*value) + hint);
        ok = false;
    } else if (p.type == ValueType::Number) {
        auto n = readNumber(*value, keyPath, p.check, problems_);
        if (n && *n > p.maximum) {
            problems_.add(keyPath, "expected at most " + formatFloat(p.maximum) + ", got " +
                                       describe(*value));
            n.reset();
        } else if (n && p.check == Check::Count && *n < p.least) {
            problems_.add(keyPath, "expected at least " + formatFloat(p.least) + ", got " +
                                       describe(*value));
            n.reset();
        }
        if (n) *slot = static_cast<float>(*n);
        ok = ok && n.has_value();
    } else {
        auto v = readVec3(*value, keyPath, p.check, problems_);
        if (v && p.check == Check::NonZero) *v = normalised(*v);
        if (v) std::copy_n(&v->x, 3, slot);
        ok = ok && v.has_value();
    }
}

std::optional<dom::array> SceneReader::readNode(element value, std::string path, uint32_t depth,
                                                Scene& scene) {
    scene.nodes.emplace_back();
    Node& node = scene.nodes.back();
    node.path = std::move(path);
    const std::string& p = node.path;
    if (!value.is_object()) {
        problems_.add(p, "expected a node (an object with \"type\"), got " + describe(value));
        return std::nullopt;
    }
    dom::object object = asObject(value);

    const KindInfo* kind = nullptr;
    element typeValue;
    if (object.at_key("type").get(typeValue) != simdjson::SUCCESS) {
        problems_.add(p, "missing required key \"type\" (one of " + kindNames() + ")");
    } else if (!typeValue.is_string()) {
        problems_.add(member(p, "type"), "expected a node type name, got " + describe(typeValue));
    } else {
        std::string_view name = typeValue.get_string().value_unsafe();
        kind = findKind(name);
        if (!kind) {
            std::string hint = didYouMean(name, kindNameList());
            if (hint.empty()) hint = "; expected one of " + kindNames();
            problems_.add(member(p, "type"), "unknown node type " + quote(name) + hint);
        }
    }
    const bool tooDeep = depth + 1 > limits_.maxDepth;
    if (!kind) {
        // The keys cannot be judged without a kind, but the children can still be checked.
        element children;
        if (object.at_key("children").get(children) == simdjson::SUCCESS && children.is_array() &&
            !tooDeep)
            return asArray(children);
        return std::nullopt;
    }
    node.kind = kind->kind;

    const KindKeys& keys = kindKeys(kind->kind);
    auto v =
        readMembers(object, p, keys.keys, keys.listed, " for " + article(kind->name), problems_);
    auto valueOf = [&](std::string_view key) {
        return v[static_cast<size_t>(std::find(keys.keys.begin(), keys.keys.end(), key) -
                                     keys.keys.begin())];
    };
    bool paramsOk = true;
    for (const ParamInfo& param : kind->params)
        readParam(param, valueOf(param.name), p, node, paramsOk);
    if (auto e = valueOf("name"))
        if (auto s = readString(*e, member(p, "name"), kMaxNameCharacters, problems_))
            node.name = *s;
    if (auto e = valueOf("translate"))
        if (auto t = readVec3(*e, member(p, "translate"), Check::Any, problems_))
            node.transform.translate = *t;
    if (auto e = valueOf("rotate"))
        if (auto r = readVec3(*e, member(p, "rotate"), Check::Any, problems_))
            node.transform.rotate = *r;
    if (auto e = valueOf("scale")) {
        if (e->is_array()) {
            if (auto s = readVec3(*e, member(p, "scale"), Check::Positive, problems_))
                node.transform.scale = *s;
        } else if (!e->is_number()) {
            problems_.add(member(p, "scale"),
                          "expected a positive number or an array of 3 positive numbers, got " +
                              describe(*e));
        } else if (auto s = readNumber(*e, member(p, "scale"), Check::Positive, problems_)) {
            node.transform.scale = glm::vec3(static_cast<float>(*s));
        }
    }
    if (auto e = valueOf("color")) node.color = readColor(*e, member(p, "color"), problems_);

    if (kind->kind == NodeKind::Polygon && paramsOk) {
        if (std::string why = polygonProblem(node.points); !why.empty())
            problems_.add(member(p, "points"), why);
        paramsOk = paramsOk && polygonProblem(node.points).empty();
    }
    // Past the limit, the outline that passed it has said so: no more are built.
    if (hasOutline(kind->kind) && paramsOk && outlineWords_ <= kMaxOutlineWords) {
        auto outline = buildOutline(node, files_);
        if (!outline) {
            const bool fontProblem = outline.error().diagnostics[0].path == "font";
            problems_.add(member(p, fontProblem && !node.strings[1].empty() ? "font" : "text"),
                          outline.error().diagnostics[0].message);
        } else if ((*outline)->empty()) {
            problems_.add(member(p, "text"), "expected text with something to see, got only "
                                             "spaces");
        } else if ((outlineWords_ += (*outline)->size()) > kMaxOutlineWords) {
            if (outlineWords_ - (*outline)->size() <= kMaxOutlineWords) // once, where it passes
                problems_.add(p, "the scene's polygon and text outlines exceed " +
                                     std::to_string(kMaxOutlineWords * 16 >> 20) +
                                     " MiB in all, the limit");
        } else {
            node.outline = *outline;
        }
    }
    if (kind->kind == NodeKind::Repeat && paramsOk) {
        for (int a = 0; a < 3; ++a)
            if (node.params[a] > 1.0f && !(node.params[3 + a] > 0.0f)) {
                problems_.add(member(p, "spacing"),
                              std::string("expected a spacing greater than 0 along ") + "xyz"[a] +
                                  ", which has " + formatFloat(node.params[a]) + " copies, got " +
                                  formatFloat(node.params[3 + a]));
                break;
            }
    }
    if (kind->kind == NodeKind::RoundBox && paramsOk) {
        const float* size = node.params.data();
        float limit = 0.5f * std::min({size[0], size[1], size[2]});
        if (node.params[3] > limit)
            problems_.add(member(p, "radius"), "expected at most half the smallest size (" +
                                                   formatFloat(limit) + "), got " +
                                                   describe(*valueOf("radius")));
    }

    auto children = valueOf("children");
    if (!kind->operation) {
        if (children) {
            std::vector<std::string_view> operations;
            for (const KindInfo& k : nodeKinds())
                if (k.operation) operations.push_back(k.name);
            problems_.add(p, article(kind->name) + " takes no \"children\"; only operations (" +
                                 joinNames(operations, "and") + ") do");
        }
        return std::nullopt;
    }
    if (!children) {
        problems_.add(p, "missing required key \"children\" (a non-empty array of nodes)");
        return std::nullopt;
    }
    if (!children->is_array()) {
        problems_.add(member(p, "children"),
                      "expected a non-empty array of nodes, got " + describe(*children));
        return std::nullopt;
    }
    dom::array array = asArray(*children);
    if (array.size() == 0) {
        problems_.add(member(p, "children"), "expected at least one child node, got []");
        return std::nullopt;
    }
    if (kind->role != Role::Boolean && array.size() != 1) {
        problems_.add(member(p, "children"),
                      "expected exactly one child node (wrap several in a union), got " +
                          std::to_string(array.size()));
        return std::nullopt;
    }
    if (tooDeep) {
        problems_.add(p,
                      "nesting too deep: more than " + std::to_string(limits_.maxDepth) +
                          " nested operations",
                      ErrorKind::Limit);
        return std::nullopt;
    }
    return array;
}

// A polygon turned by a revolve, untransformed but for a shift, that meets the axis along an
// edge gets the outline of itself and its mirror image (revolvedOutline in outline.h), so that
// the axis lies inside the solid and not on a surface of zero thickness.
void closeRevolvedProfiles(Scene& scene) {
    for (const Node& node : scene.nodes) {
        if (node.kind != NodeKind::Revolve || node.children.size() != 1) continue;
        Node& child = scene.nodes[node.children[0]];
        if (child.kind != NodeKind::Polygon || !child.outline ||
            child.transform.rotate != glm::vec3(0.0f) || child.transform.scale != glm::vec3(1.0f))
            continue;
        if (auto outline =
                revolvedOutline(child.points, -node.params[0] - child.transform.translate.x))
            child.outline = std::move(outline);
    }
}

bool finite(glm::vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Each value is within single precision on its own, but the renderer works in every node's local
// units: scales multiply down the tree and translations are divided by them, and a product beyond
// single precision would put inf into the generated code and the node buffer. Reports the first
// such node; its descendants inherit the problem.
void checkCombinedTransforms(const Scene& scene, Problems& problems) {
    const Evaluator evaluator(scene);
    // The products of the smallest and of the largest factors: the parent's, until multiplied.
    std::vector<double> scale(scene.nodes.size(), 1.0), largest(scene.nodes.size(), 1.0);
    std::vector<bool> inCut(scene.nodes.size(), false); // inside an extrude or a revolve
    for (size_t i = 0; i < scene.nodes.size(); ++i) {
        const Node& node = scene.nodes[i];
        const glm::vec3 s = node.transform.scale;
        scale[i] *= std::min({s.x, s.y, s.z});
        largest[i] *= std::max({s.x, s.y, s.z});
        for (uint32_t c : node.children)
            scale[c] = scale[i], largest[c] = largest[i];
        const FlatNode& f = evaluator.nodes()[i];
        const KindInfo& info = kindInfo(node.kind);
        const bool cuts = node.kind == NodeKind::Extrude || node.kind == NodeKind::Revolve;
        for (uint32_t c : node.children)
            inCut[c] = inCut[i] || cuts;
        if (isProfile(node.kind) && !inCut[i]) {
            problems.add(node.path, article(info.name) +
                                        " is a 2D profile: it must be inside an extrude or a "
                                        "revolve");
            return;
        }
        if (info.role == Role::Domain && node.kind != NodeKind::Mirror &&
            node.kind != NodeKind::Elongate && !node.children.empty() &&
            !evaluator.nodes()[node.children[0]].bounds.finite()) {
            problems.add(node.path, article(info.name) +
                                        " needs a bounded child, and its child reaches infinity "
                                        "(a plane does)");
            return;
        }
        if (std::isfinite(f.scale) && f.scale > 0.0f && finite(f.toLocal[0]) &&
            finite(f.toLocal[1]) && finite(f.toLocal[2]) && finite(f.offset) &&
            std::isfinite(f.smooth))
            continue;
        const bool huge = largest[i] > FLT_MAX;
        char product[32]; // the product of floats, to the digits that matter here
        std::snprintf(product, sizeof product, "%.3g", huge ? largest[i] : scale[i]);
        const std::string combined =
            std::string("the scales of this node and the operations above it multiply to ") +
            product;
        if (huge)
            problems.add(node.path, combined + ", beyond single precision (about 3.4e+38)");
        else if (scale[i] < FLT_MIN)
            problems.add(node.path, combined + ", too small for single precision (about 1.2e-38)");
        else if (!std::isfinite(f.smooth))
            problems.add(node.path, "smooth times the scales above it is beyond single precision "
                                    "(about 3.4e+38)");
        else
            problems.add(node.path, "the translation of this node, in the units of the scales "
                                    "above it, is beyond single precision (about 3.4e+38)");
        return;
    }
}

} // namespace

Result<Scene> parseScene(std::string_view json, std::string_view file, const Limits& limits) {
    ParseOptions options;
    options.limits = limits;
    return parseScene(json, file, options);
}

Result<Scene> parseScene(std::string_view json, std::string_view file,
                         const ParseOptions& options) {
    const Limits& limits = options.limits;
    const std::string fileName = file.empty() ? "<input>" : std::string(file);
    if (json.size() > limits.maxFileBytes) return tooLarge(fileName, json.size(), limits);
    if (json.starts_with("\xEF\xBB\xBF")) json.remove_prefix(3); // editors' byte order mark

    const size_t maxDepth = jsonDepthLimit(limits);
    dom::parser parser;
    if (parser.allocate(std::max<size_t>(json.size(), 64), maxDepth) != simdjson::SUCCESS)
        return Error::message(ErrorKind::Io, fileName, "out of memory while reading JSON");
    element top;
    if (auto code = parser.parse(json.data(), json.size()).get(top))
        return syntaxError(fileName, json, code, maxDepth);

    Problems problems(fileName);
    Scene scene = isLegacyScene(top) ? convertLegacy(asObject(top), limits, problems)
                                     : SceneReader(options, problems).read(top);
    if (problems.empty()) closeRevolvedProfiles(scene);
    if (problems.empty()) checkCombinedTransforms(scene, problems);
    if (!problems.empty()) return problems.error();
    scene.file = fileName;
    scene.files = options.files;
    return scene;
}

Result<Scene> loadScene(const std::filesystem::path& path, const Limits& limits) {
    const std::string file = path.string();
    std::error_code ec;
    const uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) return Error::message(ErrorKind::Io, file, "cannot read file: " + ec.message());
    // Refused before reading, so a huge file costs nothing.
    if (size > limits.maxFileBytes) return tooLarge(file, size, limits);
    std::ifstream in(path, std::ios::binary);
    std::string text(static_cast<size_t>(size), '\0');
    in.read(text.data(), static_cast<std::streamsize>(size));
    if (!in && !in.eof()) return Error::message(ErrorKind::Io, file, "cannot read file");
    text.resize(static_cast<size_t>(in.gcount()));
    ParseOptions options;
    options.limits = limits;
    options.files.folder = path.parent_path();
    return parseScene(text, file, options);
}

std::vector<Light> defaultLights() {
    // A warm key light from the upper front left and a dim cool fill from the right, so that
    // shapes read as solid from the default front view.
    return {
        Light{glm::normalize(glm::vec3(0.6f, -0.8f, -0.5f)), glm::vec3(1.0f, 0.94f, 0.84f), 1.0f},
        Light{glm::normalize(glm::vec3(-0.7f, -0.2f, -0.4f)), glm::vec3(0.72f, 0.82f, 1.0f), 0.35f},
    };
}

} // namespace sdfcsg
