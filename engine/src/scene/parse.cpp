// The scene loader: simdjson reads the text, then one walk over the DOM validates every value
// against the node kind table (nodes.h) and builds the flat pre-order Scene. The walk keeps its
// own stack, so hostile nesting cannot overflow the C++ stack.
#include "sdfcsg/scene.h"

#include "sdfcsg/eval.h"

#include "field/bake.h"
#include "field/mesh_field.h"
#include "scene/image.h"
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
#include <deque>
#include <fstream>
#include <map>

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

// Every "type": the kinds, and "use" (a copy of a definition).
std::vector<std::string_view> kindNameList() {
    std::vector<std::string_view> names;
    for (const KindInfo& k : nodeKinds())
        names.push_back(k.name);
    names.push_back("use");
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

// ---- Definitions and uses ----
//
// A use is read as a union of one child, the copy: the walk reads the definition's node again,
// in a Scope that gives its "$name" references the use's values. Before any copy is made, the
// uses as written are checked: a use that comes back to its own definition is refused, and so
// is a scene whose copies would pass Limits::maxNodes, so a hostile file costs no more than the
// nodes it may have.

// A definition may have at most this many parameters, so that what each copy keeps of its
// values stays small.
constexpr size_t kMaxParameters = 64;

// Definition and parameter names: what follows "$" in a reference.
bool isName(std::string_view s) {
    auto letter = [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
    };
    if (s.empty() || s.size() > kMaxNameCharacters || !letter(s[0])) return false;
    return std::all_of(s.begin(), s.end(),
                       [&](char c) { return letter(c) || (c >= '0' && c <= '9'); });
}
constexpr std::string_view kNameRule = "letters, digits and underscores, not starting with a digit";

// The parameter that a "$name" string refers to, or nothing for any other value.
std::optional<std::string_view> referenceIn(element value) {
    if (!value.is_string()) return std::nullopt;
    const std::string_view s = value.get_string().value_unsafe();
    if (s.size() < 2 || s[0] != '$' || !isName(s.substr(1))) return std::nullopt;
    return s.substr(1);
}

// What a parameter's value is, for messages; a use's value must be what the default is. Empty for
// values that no parameter may have.
std::string_view valueKind(element value) {
    return value.is_number()   ? "a number"
           : value.is_string() ? "a string"
           : value.is_array()  ? "an array"
                               : "";
}

// The definition a node as written uses: nothing for a node that is no use, "" for a use that
// names none.
std::optional<std::string_view> useOf(element value) {
    if (!value.is_object()) return std::nullopt;
    element type, name;
    if (asObject(value).at_key("type").get(type) != simdjson::SUCCESS || !type.is_string() ||
        type.get_string().value_unsafe() != "use")
        return std::nullopt;
    if (asObject(value).at_key("definition").get(name) != simdjson::SUCCESS || !name.is_string())
        return std::string_view();
    return name.get_string().value_unsafe();
}

// Visits the nodes of a tree as written, in pre-order, without going into the copies that uses
// make: f(value, path) for each value in a node's place, until f returns false.
template <class F> void forWrittenNodes(element root, std::string path, F&& f) {
    struct Frame {
        dom::array::iterator next, end;
        std::string path; // of the children array
        size_t index;
    };
    std::vector<Frame> stack;
    auto visit = [&](element value, std::string at) {
        if (!f(value, at)) return false;
        element children;
        if (value.is_object() && !useOf(value) &&
            asObject(value).at_key("children").get(children) == simdjson::SUCCESS &&
            children.is_array())
            stack.push_back(
                {asArray(children).begin(), asArray(children).end(), member(at, "children"), 0});
        return true;
    };
    if (!visit(root, std::move(path))) return;
    while (!stack.empty()) {
        Frame& top = stack.back();
        if (!(top.next != top.end)) {
            stack.pop_back();
            continue;
        }
        element value = *top.next;
        ++top.next;
        std::string at = item(top.path, top.index++);
        if (!visit(value, std::move(at))) return; // `top` is not used after this
    }
}

uint64_t addCapped(uint64_t a, uint64_t b) {
    return a > UINT64_MAX - b ? UINT64_MAX : a + b;
}

// A definition as the reader knows it.
struct DefinitionInfo {
    std::string name;
    std::string path; // "definitions.leg"
    element node;     // when hasNode
    bool hasNode = false;
    std::vector<std::string_view> parameters; // names, in the order written
    std::vector<element> defaults;
    bool broken = false;   // refused: no copies are made
    bool tooLarge = false; // a copy would pass the node limit
    // A parameter was refused: its references cannot be judged, so the node is not read alone.
    bool badParameters = false;
    uint64_t size = 0; // nodes in one copy, with the copies its uses make
};

// What "$name" references mean where the walk is: in a copy, the use's values and else the
// defaults; in a definition read on its own, the defaults.
struct Scope {
    uint32_t definition = 0;
    std::vector<element> values; // per parameter of the definition
    bool copy = false;
    std::string usePath;          // of the use that made the copy
    const Scope* outer = nullptr; // the copy the use lies in
};

// Where the walk goes from a node: into its children, or into the copy that a use makes.
struct Next {
    std::optional<dom::array> children;
    const Scope* copy = nullptr;
};

class SceneReader {
  public:
    SceneReader(const ParseOptions& options, Problems& problems)
        : limits_(options.limits), files_(options.files), problems_(problems) {}

    Scene read(element top);

  private:
    void readCamera(element value, Scene& scene);
    void readLights(element value, Scene& scene);
    void readDefinitions(element value, Scene& scene);
    void readParameters(element value, const std::string& path, DefinitionInfo& info,
                        Definition& definition);
    // Refuses uses that recur and definitions whose copies would pass the node limit, then
    // reads each definition on its own, with its defaults.
    void checkDefinitions();
    // Whether the tree under `root`, with the copies its uses make, keeps to the node limit;
    // reports where it passes the limit when copies take it there.
    bool fitsWithCopies(element root);
    // Reads the tree under `root` (the scene's, or a definition's on its own in `scope`) into
    // scene.nodes.
    void readTree(element root, std::string path, Scene& scene, const Scope* scope);
    // Appends the node at `value` to scene.nodes and says where the walk goes next.
    Next readNode(element value, std::string path, uint32_t depth, Scene& scene);
    Next readUse(dom::object object, uint32_t depth, Node& node);
    void readCommon(const std::string& path, std::optional<element> name,
                    std::optional<element> translate, std::optional<element> rotate,
                    std::optional<element> scale, std::optional<element> color, Node& node);
    void readParam(const ParamInfo& p, std::optional<element> value, const std::string& path,
                   Node& node, bool& ok);
    // The value that a "$name" string stands for where the walk is, or the value itself;
    // nothing, and a problem reported, for a reference to no parameter.
    std::optional<element> resolve(element value, const std::string& path);
    // " (in the use of "leg" at root.children[0], ...)" in a copy, else "".
    std::string context() const;

    const Limits& limits_;
    const SceneFiles& files_;
    Problems& problems_;
    size_t outlineWords_ = 0; // polygon and text outlines so far, in vec4s
    std::vector<DefinitionInfo> definitions_;
    std::map<std::string, uint32_t, std::less<>> definitionIndex_;
    std::deque<Scope> scopes_; // stable addresses for the frames that point at them
    const Scope* scope_ = nullptr;
    bool copying_ = true; // false while definitions are read on their own
};

Scene SceneReader::read(element top) {
    Scene scene;
    if (!top.is_object()) {
        problems_.add({}, "expected a scene (an object with \"version\" and \"root\"), got " +
                              describe(top));
        return scene;
    }
    static constexpr std::string_view kKeys[] = {"version", "name",       "description", "camera",
                                                 "lights",  "background", "definitions", "root"};
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
    problems_.setContext([this] { return context(); });
    if (v[6]) {
        readDefinitions(*v[6], scene);
        checkDefinitions();
    }
    if (!v[7])
        problems_.add({}, "missing required key \"root\" (the top node of the scene)");
    else if (fitsWithCopies(*v[7]))
        readTree(*v[7], "root", scene, nullptr);
    problems_.setContext({});
    return scene;
}

void SceneReader::readDefinitions(element value, Scene& scene) {
    if (!value.is_object()) {
        problems_.add("definitions", "expected an object of named definitions, each "
                                     "{\"parameters\": {...}, \"node\": NODE}, got " +
                                         describe(value));
        return;
    }
    static constexpr std::string_view kKeys[] = {"parameters", "node"};
    for (auto [key, body] : asObject(value)) {
        if (!isName(key)) {
            problems_.add("definitions", "expected a definition name of " + std::string(kNameRule) +
                                             ", got " + quote(key));
            continue;
        }
        if (definitionIndex_.contains(key)) {
            problems_.add("definitions", "duplicate key " + quote(key));
            continue;
        }
        DefinitionInfo info;
        info.name = std::string(key);
        info.path = member("definitions", key);
        Definition written;
        written.name = info.name;
        if (!body.is_object()) {
            problems_.add(info.path, "expected a definition (an object with \"node\" and "
                                     "optionally \"parameters\"), got " +
                                         describe(body));
            info.broken = true;
        } else {
            auto v = readMembers(asObject(body), info.path, kKeys, std::size(kKeys),
                                 " for a definition", problems_);
            if (v[0]) readParameters(*v[0], member(info.path, "parameters"), info, written);
            if (v[1]) {
                info.node = *v[1];
                info.hasNode = true;
                written.node = jsonText(*v[1]);
            } else {
                problems_.add(info.path, "missing required key \"node\" (the node that uses "
                                         "copy, whose values may be \"$name\" references to "
                                         "the parameters)");
                info.broken = true;
            }
        }
        definitionIndex_.emplace(info.name, uint32_t(definitions_.size()));
        definitions_.push_back(std::move(info));
        scene.definitions.push_back(std::move(written));
    }
}

void SceneReader::readParameters(element value, const std::string& path, DefinitionInfo& info,
                                 Definition& definition) {
    if (!value.is_object()) {
        problems_.add(path, "expected an object of parameter names and their default values, "
                            "got " +
                                describe(value));
        info.broken = info.badParameters = true;
        return;
    }
    for (auto [name, fallback] : asObject(value)) {
        const std::string at = member(path, name);
        if (!isName(name)) {
            problems_.add(path, "expected a parameter name of " + std::string(kNameRule) +
                                    ", got " + quote(name));
        } else if (std::find(info.parameters.begin(), info.parameters.end(), name) !=
                   info.parameters.end()) {
            problems_.add(path, "duplicate key " + quote(name));
        } else if (info.parameters.size() == kMaxParameters) {
            problems_.add(path,
                          "too many parameters: a definition may have at most " +
                              std::to_string(kMaxParameters),
                          ErrorKind::Limit);
            info.broken = info.badParameters = true;
            return;
        } else if (valueKind(fallback).empty()) {
            problems_.add(at, "expected a default value (a number, a string or an array), got " +
                                  describe(fallback));
        } else if (referenceIn(fallback)) {
            problems_.add(at, "expected a default value, got " + describe(fallback) +
                                  ", a reference (a default cannot refer to a parameter)");
        } else {
            info.parameters.push_back(name);
            info.defaults.push_back(fallback);
            definition.parameters.push_back({std::string(name), jsonText(fallback)});
            continue;
        }
        info.broken = info.badParameters = true;
    }
}

void SceneReader::checkDefinitions() {
    const size_t count = definitions_.size();
    struct UseOf {
        uint32_t definition;
        std::string path;
    };
    std::vector<std::vector<UseOf>> uses(count);
    std::vector<uint64_t> own(count, 0); // nodes written in each definition, its uses included
    for (uint32_t d = 0; d < count; ++d) {
        if (!definitions_[d].hasNode) continue;
        forWrittenNodes(definitions_[d].node, member(definitions_[d].path, "node"),
                        [&](element value, const std::string& path) {
                            ++own[d];
                            if (auto name = useOf(value)) {
                                auto found = definitionIndex_.find(*name);
                                if (found != definitionIndex_.end())
                                    uses[d].push_back({found->second, path});
                            }
                            return true;
                        });
    }
    auto name = [&](uint32_t d) { return quote(definitions_[d].name); };

    // Depth first, with a stack of its own: a use of a definition still open closes a loop.
    // Sizes are summed as each definition closes, after those it uses.
    enum : uint8_t { kNew, kOpen, kDone };
    std::vector<uint8_t> state(count, kNew);
    std::vector<size_t> place(count, 0); // an open definition's place on the stack
    struct Frame {
        uint32_t definition;
        size_t next;
    };
    std::vector<Frame> stack;
    for (uint32_t start = 0; start < count; ++start) {
        if (state[start] != kNew) continue;
        state[start] = kOpen;
        stack.push_back({start, 0});
        while (!stack.empty()) {
            const uint32_t d = stack.back().definition;
            if (stack.back().next < uses[d].size()) {
                const UseOf& use = uses[d][stack.back().next++];
                if (state[use.definition] == kNew) {
                    state[use.definition] = kOpen;
                    place[use.definition] = stack.size();
                    stack.push_back({use.definition, 0});
                } else if (state[use.definition] == kOpen) {
                    std::string loop = name(d) + " uses itself";
                    if (use.definition != d) {
                        loop = name(d) + " uses " + name(use.definition);
                        for (size_t k = place[use.definition] + 1; k < stack.size(); ++k)
                            loop += ", which uses " + name(stack[k].definition);
                    }
                    problems_.add(use.path, "recursive use: " + loop);
                    for (size_t k = place[use.definition]; k < stack.size(); ++k)
                        definitions_[stack[k].definition].broken = true;
                }
                continue;
            }
            DefinitionInfo& info = definitions_[d];
            uint64_t size = own[d];
            for (const UseOf& use : uses[d]) {
                // Without its copies a definition would differ from what was written.
                if (definitions_[use.definition].broken) info.broken = true;
                size = addCapped(size, definitions_[use.definition].size);
            }
            info.size = size;
            if (!info.broken && size > limits_.maxNodes) {
                problems_.add(info.path,
                              "too many nodes: a copy of this definition, with the copies its "
                              "uses make, would have more than " +
                                  std::to_string(limits_.maxNodes) + ", the most a scene may have",
                              ErrorKind::Limit);
                info.broken = info.tooLarge = true;
            }
            state[d] = kDone;
            stack.pop_back();
        }
    }

    // Each definition read on its own, with its defaults, so that its problems are reported
    // once, at its own paths; a definition with problems is not copied.
    copying_ = false;
    const size_t outlineWords = outlineWords_; // the copies count, not these
    for (uint32_t d = 0; d < count; ++d) {
        DefinitionInfo& info = definitions_[d];
        if (!info.hasNode || info.tooLarge || info.badParameters) continue;
        Scope& scope = scopes_.emplace_back();
        scope.definition = d;
        scope.values = info.defaults;
        Scene alone;
        const size_t before = problems_.count();
        readTree(info.node, member(info.path, "node"), alone, &scope);
        if (problems_.count() != before) info.broken = true;
    }
    outlineWords_ = outlineWords;
    copying_ = true;
}

bool SceneReader::fitsWithCopies(element root) {
    uint64_t total = 0;
    bool copies = false, fits = true;
    forWrittenNodes(root, "root", [&](element value, const std::string& path) {
        ++total;
        std::string_view copied;
        if (auto name = useOf(value)) {
            auto found = definitionIndex_.find(*name);
            if (found != definitionIndex_.end() && !definitions_[found->second].broken) {
                total = addCapped(total, definitions_[found->second].size);
                copies = true;
                copied = *name;
            }
        }
        if (total <= limits_.maxNodes) return true;
        // Without copies so far, the walk reports it as it reads the nodes.
        if (copies)
            problems_.add(
                path,
                "too many nodes: a scene may have at most " + std::to_string(limits_.maxNodes) +
                    ", counting the copies that uses make" +
                    (copied.empty() ? std::string()
                                    : ", and the copy of " + quote(copied) + " here passes that"),
                ErrorKind::Limit);
        fits = !copies;
        return false;
    });
    return fits;
}

std::optional<element> SceneReader::resolve(element value, const std::string& path) {
    const auto name = referenceIn(value);
    if (!name) return value;
    if (!scope_) {
        problems_.add(path, describe(value) + " refers to a parameter, and only the nodes of "
                                              "definitions have parameters");
        return std::nullopt;
    }
    const DefinitionInfo& info = definitions_[scope_->definition];
    for (size_t i = 0; i < info.parameters.size(); ++i)
        if (info.parameters[i] == *name) return scope_->values[i];
    std::string hint = didYouMean(*name, info.parameters);
    if (hint.empty())
        hint = info.parameters.empty() ? "; it has none" : "; it has " + joinNames(info.parameters);
    problems_.add(path, describe(value) + " names no parameter of " + quote(info.name) + hint);
    return std::nullopt;
}

std::string SceneReader::context() const {
    std::string out;
    for (const Scope* s = scope_; s && s->copy; s = s->outer)
        out += (out.empty() ? " (in the use of " : ", in the use of ") +
               quote(definitions_[s->definition].name) + " at " + s->usePath;
    return out.empty() ? out : out + ")";
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

void SceneReader::readTree(element root, std::string path, Scene& scene, const Scope* scope) {
    struct Frame {
        dom::array::iterator next, end; // children still to read, when `children`
        bool children;
        const Scope* copy;  // a use's copy, to read before anything else
        const Scope* scope; // where the frame's nodes lie
        uint32_t parent;
        uint32_t depth; // of the children
        size_t index;   // of the next child
    };
    std::vector<Frame> stack;
    auto visit = [&](element value, std::string at, std::optional<uint32_t> parent, uint32_t depth,
                     const Scope* in) {
        scope_ = in;
        if (scene.nodes.size() >= limits_.maxNodes) {
            problems_.add(std::move(at),
                          "too many nodes: a scene may have at most " +
                              std::to_string(limits_.maxNodes),
                          ErrorKind::Limit);
            return false;
        }
        const auto index = static_cast<uint32_t>(scene.nodes.size());
        Next next = readNode(value, std::move(at), depth, scene);
        if (parent) scene.nodes[*parent].children.push_back(index);
        if (next.children)
            stack.push_back({next.children->begin(), next.children->end(), true, nullptr, in, index,
                             depth + 1, 0});
        else if (next.copy)
            stack.push_back({{}, {}, false, next.copy, next.copy, index, depth + 1, 0});
        return true;
    };
    bool going = visit(root, std::move(path), std::nullopt, 0, scope);
    while (going && !stack.empty()) {
        Frame& top = stack.back();
        const uint32_t parent = top.parent, depth = top.depth;
        const Scope* in = top.scope;
        if (top.copy) {
            top.copy = nullptr;
            const DefinitionInfo& info = definitions_[in->definition];
            going = visit(info.node, member(info.path, "node"), parent, depth, in);
            continue;
        }
        if (!top.children || !(top.next != top.end)) {
            stack.pop_back();
            continue;
        }
        element child = *top.next;
        ++top.next;
        std::string at = item(member(scene.nodes[parent].path, "children"), top.index++);
        going = visit(child, std::move(at), parent, depth, in);
    }
    scope_ = nullptr;
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

Next SceneReader::readNode(element value, std::string path, uint32_t depth, Scene& scene) {
    scene.nodes.emplace_back();
    Node& node = scene.nodes.back();
    node.path = std::move(path);
    const std::string& p = node.path;
    if (!value.is_object()) {
        problems_.add(p, "expected a node (an object with \"type\"), got " + describe(value));
        return {};
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
        if (name == "use") return readUse(object, depth, node);
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
            return {asArray(children)};
        return {};
    }
    node.kind = kind->kind;

    const KindKeys& keys = kindKeys(kind->kind);
    auto v =
        readMembers(object, p, keys.keys, keys.listed, " for " + article(kind->name), problems_);
    // A reference to no parameter is reported by resolve(): the key counts as given, not missing.
    std::vector<bool> unresolved(v.size(), false);
    for (size_t i = 0; i < v.size(); ++i)
        if (v[i] && keys.keys[i] != "type" && keys.keys[i] != "children") {
            v[i] = resolve(*v[i], member(p, keys.keys[i]));
            unresolved[i] = !v[i];
        }
    auto at = [&](std::string_view key) {
        return static_cast<size_t>(std::find(keys.keys.begin(), keys.keys.end(), key) -
                                   keys.keys.begin());
    };
    auto valueOf = [&](std::string_view key) { return v[at(key)]; };
    bool paramsOk = true;
    for (const ParamInfo& param : kind->params)
        if (unresolved[at(param.name)])
            paramsOk = false;
        else
            readParam(param, valueOf(param.name), p, node, paramsOk);
    readCommon(p, valueOf("name"), valueOf("translate"), valueOf("rotate"), valueOf("scale"),
               valueOf("color"), node);

    if (kind->kind == NodeKind::Polygon && paramsOk) {
        if (std::string why = polygonProblem(node.points); !why.empty())
            problems_.add(member(p, "points"), why);
        paramsOk = paramsOk && polygonProblem(node.points).empty();
    }
    if (kind->kind == NodeKind::Text || kind->kind == NodeKind::Image) {
        // Each of the three sets the text's or image's size: one at most.
        const std::string what = kind->kind == NodeKind::Text ? "text's" : "image's";
        std::vector<std::string> given;
        for (std::string_view key : {"size", "width", "height"})
            if (valueOf(key)) given.push_back(std::string(key));
        if (given.size() > 1) {
            problems_.add(member(p, given[1]),
                          "expected one of \"size\", \"width\" and \"height\" (each sets the " +
                              what + " size), got both " + quote(given[0]) + " and " +
                              quote(given[1]));
            paramsOk = false;
        }
    }
    // Past the limit, the words that passed it have said so: no more are built.
    if (hasWords(kind->kind) && paramsOk && outlineWords_ <= kMaxOutlineWords) {
        const bool image = kind->kind == NodeKind::Image || kind->kind == NodeKind::Heightmap ||
                           kind->kind == NodeKind::Mesh;
        auto outline = kind->kind == NodeKind::Image       ? buildImage(node, files_)
                       : kind->kind == NodeKind::Heightmap ? buildHeightmap(node, files_)
                       : kind->kind == NodeKind::Mesh      ? buildMesh(node, files_)
                                                           : buildOutline(node, files_);
        if (!outline && image) {
            problems_.add(member(p, "file"), outline.error().diagnostics[0].message);
        } else if (!outline) {
            const bool fontProblem = outline.error().diagnostics[0].path == "font";
            problems_.add(member(p, fontProblem && !node.strings[1].empty() ? "font" : "text"),
                          outline.error().diagnostics[0].message);
        } else if ((*outline)->empty()) {
            problems_.add(member(p, "text"), "expected text with something to see, got only "
                                             "spaces");
        } else if ((outlineWords_ += (*outline)->size()) > kMaxOutlineWords) {
            if (outlineWords_ - (*outline)->size() <= kMaxOutlineWords) // once, where it passes
                problems_.add(p, "the scene's outlines, images and meshes exceed " +
                                     std::to_string(kMaxOutlineWords * 16 >> 20) +
                                     " MiB in all, the limit");
        } else {
            node.words = *outline;
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
    if (kind->kind == NodeKind::TransitionRadial && paramsOk && node.params[4] == node.params[3])
        problems_.add(member(p, "r1"),
                      "expected a radius other than r0, got " + describe(*valueOf("r1")));
    if ((kind->kind == NodeKind::BendLinear || kind->kind == NodeKind::TransitionLinear) &&
        paramsOk) {
        const glm::vec3 p0(node.params[0], node.params[1], node.params[2]);
        const glm::vec3 axis = glm::vec3(node.params[3], node.params[4], node.params[5]) - p0;
        if (!(glm::dot(axis, axis) > 0.0f))
            problems_.add(member(p, "p1"),
                          "expected a point apart from p0, got " + describe(*valueOf("p1")));
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
        return {};
    }
    if (!children) {
        problems_.add(p, "missing required key \"children\" (a non-empty array of nodes)");
        return {};
    }
    if (!children->is_array()) {
        problems_.add(member(p, "children"),
                      "expected a non-empty array of nodes, got " + describe(*children));
        return {};
    }
    dom::array array = asArray(*children);
    if (array.size() == 0) {
        problems_.add(member(p, "children"), "expected at least one child node, got []");
        return {};
    }
    if (isTransition(kind->kind) && array.size() != 2) {
        problems_.add(member(p, "children"),
                      "expected exactly two child nodes (the shapes it morphs between), got " +
                          std::to_string(array.size()));
        return {};
    }
    if (kind->role != Role::Boolean && array.size() != 1) {
        problems_.add(member(p, "children"),
                      "expected exactly one child node (wrap several in a union), got " +
                          std::to_string(array.size()));
        return {};
    }
    if (tooDeep) {
        problems_.add(p,
                      "nesting too deep: more than " + std::to_string(limits_.maxDepth) +
                          " nested operations",
                      ErrorKind::Limit);
        return {};
    }
    return {array};
}

void SceneReader::readCommon(const std::string& p, std::optional<element> name,
                             std::optional<element> translate, std::optional<element> rotate,
                             std::optional<element> scale, std::optional<element> color,
                             Node& node) {
    if (name)
        if (auto s = readString(*name, member(p, "name"), kMaxNameCharacters, problems_))
            node.name = *s;
    if (translate)
        if (auto t = readVec3(*translate, member(p, "translate"), Check::Any, problems_))
            node.transform.translate = *t;
    if (rotate)
        if (auto r = readVec3(*rotate, member(p, "rotate"), Check::Any, problems_))
            node.transform.rotate = *r;
    if (scale) {
        if (scale->is_array()) {
            if (auto s = readVec3(*scale, member(p, "scale"), Check::Positive, problems_))
                node.transform.scale = *s;
        } else if (!scale->is_number()) {
            problems_.add(member(p, "scale"),
                          "expected a positive number or an array of 3 positive numbers, got " +
                              describe(*scale));
        } else if (auto s = readNumber(*scale, member(p, "scale"), Check::Positive, problems_)) {
            node.transform.scale = glm::vec3(static_cast<float>(*s));
        }
    }
    if (color) node.color = readColor(*color, member(p, "color"), problems_);
}

Next SceneReader::readUse(dom::object object, uint32_t depth, Node& node) {
    const std::string& p = node.path;
    static constexpr std::string_view kKeys[] = {"definition", "parameters", "type",  "name",
                                                 "translate",  "rotate",     "scale", "color"};
    auto v = readMembers(object, p, kKeys, std::size(kKeys), " for a use", problems_);
    node.kind = NodeKind::Union;
    for (const ParamInfo& q : kindInfo(NodeKind::Union).params)
        node.params[q.slot] = q.fallback[0];
    node.use.emplace();
    for (size_t i = 3; i < std::size(kKeys); ++i)
        if (v[i]) v[i] = resolve(*v[i], member(p, kKeys[i]));
    readCommon(p, v[3], v[4], v[5], v[6], v[7], node);

    const DefinitionInfo* info = nullptr;
    uint32_t index = 0;
    if (!v[0]) {
        problems_.add(p, "missing required key \"definition\" (the name of one of the scene's "
                         "\"definitions\")");
    } else if (!v[0]->is_string()) {
        problems_.add(member(p, "definition"),
                      "expected the name of a definition, got " + describe(*v[0]));
    } else {
        const std::string_view name = v[0]->get_string().value_unsafe();
        node.use->definition = std::string(name);
        if (auto found = definitionIndex_.find(name); found != definitionIndex_.end()) {
            index = found->second;
            info = &definitions_[index];
        } else {
            // Once the problems are full, only counted: spare the suggestion search.
            std::vector<std::string_view> names;
            if (!problems_.full())
                for (const DefinitionInfo& d : definitions_)
                    names.push_back(d.name);
            std::string hint = didYouMean(name, names);
            if (definitions_.empty())
                hint = "; the scene has no \"definitions\"";
            else if (hint.empty() && !names.empty() && names.size() <= 8)
                hint = "; the scene defines " + joinNames(names);
            problems_.add(member(p, "definition"), "unknown definition " + quote(name) + hint);
        }
    }

    // The use's values, checked against the definition's parameters and their defaults.
    std::vector<std::optional<element>> values(info ? info->parameters.size() : 0);
    bool valuesOk = true;
    if (v[1] && !v[1]->is_object()) {
        problems_.add(member(p, "parameters"),
                      "expected an object of parameter values, got " + describe(*v[1]));
        valuesOk = false;
    } else if (v[1]) {
        const std::string at = member(p, "parameters");
        for (auto [key, value] : asObject(*v[1])) {
            node.use->arguments.push_back({std::string(key), jsonText(value)});
            if (!info) continue;
            const auto found = std::find(info->parameters.begin(), info->parameters.end(), key);
            if (found == info->parameters.end()) {
                std::string hint = problems_.full() ? "" : didYouMean(key, info->parameters);
                if (hint.empty())
                    hint = info->parameters.empty() ? "; it has none"
                                                    : "; it has " + joinNames(info->parameters);
                problems_.add(at, "unknown parameter " + quote(key) + " of " + quote(info->name) +
                                      hint);
                valuesOk = false;
                continue;
            }
            const size_t i = static_cast<size_t>(found - info->parameters.begin());
            if (values[i]) {
                problems_.add(at, "duplicate key " + quote(key));
                valuesOk = false;
                continue;
            }
            const auto resolved = resolve(value, member(at, key));
            const std::string_view expected = valueKind(info->defaults[i]);
            if (resolved && valueKind(*resolved) != expected) {
                const std::string got = referenceIn(value)
                                            ? describe(value) + ", which is " + describe(*resolved)
                                            : describe(value);
                problems_.add(member(at, key), "expected " + std::string(expected) +
                                                   ", as the default of " + quote(key) + " in " +
                                                   quote(info->name) + " is, got " + got);
            }
            if (!resolved || valueKind(*resolved) != expected) {
                valuesOk = false;
                continue;
            }
            values[i] = *resolved;
        }
    }
    if (depth + 1 > limits_.maxDepth) {
        problems_.add(p,
                      "nesting too deep: more than " + std::to_string(limits_.maxDepth) +
                          " nested operations (a use counts as one, above its copy)",
                      ErrorKind::Limit);
        return {};
    }
    if (!copying_ || !info || info->broken || !valuesOk) return {};
    Scope& copy = scopes_.emplace_back();
    copy.definition = index;
    copy.values = info->defaults;
    for (size_t i = 0; i < values.size(); ++i)
        if (values[i]) copy.values[i] = *values[i];
    copy.copy = true;
    copy.usePath = p;
    copy.outer = scope_;
    return {std::nullopt, &copy};
}

// A polygon turned by a revolve, untransformed but for a shift, that meets the axis along an
// edge gets the outline of itself and its mirror image (revolvedOutline in outline.h), so that
// the axis lies inside the solid and not on a surface of zero thickness.
void closeRevolvedProfiles(Scene& scene) {
    for (const Node& node : scene.nodes) {
        if (node.kind != NodeKind::Revolve || node.children.size() != 1) continue;
        Node& child = scene.nodes[node.children[0]];
        if (child.kind != NodeKind::Polygon || !child.words ||
            child.transform.rotate != glm::vec3(0.0f) || child.transform.scale != glm::vec3(1.0f))
            continue;
        if (auto outline =
                revolvedOutline(child.points, -node.params[0] - child.transform.translate.x))
            child.words = std::move(outline);
    }
}

bool finite(glm::vec3 v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// " (in the use of "leg" at root.children[0], ...)" for a node in the copy that a use makes: the
// uses above it, innermost first.
std::string useContext(const Scene& scene, uint32_t node) {
    std::vector<uint32_t> parent(scene.nodes.size(), UINT32_MAX);
    for (uint32_t i = 0; i < scene.nodes.size(); ++i)
        for (uint32_t c : scene.nodes[i].children)
            parent[c] = i;
    std::string out;
    for (uint32_t n = parent[node]; n != UINT32_MAX; n = parent[n])
        if (const Node& above = scene.nodes[n]; above.use)
            out += (out.empty() ? " (in the use of " : ", in the use of ") +
                   quote(above.use->definition) + " at " + above.path;
    return out.empty() ? out : out + ")";
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
    auto report = [&](size_t i, std::string message) {
        problems.add(scene.nodes[i].path, message + useContext(scene, uint32_t(i)));
    };
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
            report(i, article(info.name) + " is a 2D profile: it must be inside an extrude or a "
                                           "revolve");
            return;
        }
        if (info.role == Role::Domain && node.kind != NodeKind::Mirror &&
            node.kind != NodeKind::Elongate && !node.children.empty() &&
            !evaluator.nodes()[node.children[0]].bounds.finite()) {
            report(i, article(info.name) + " needs a bounded child, and its child reaches infinity "
                                           "(a plane does)");
            return;
        }
        if (isTransition(node.kind))
            for (uint32_t c : node.children)
                if (!evaluator.nodes()[c].bounds.finite()) {
                    report(i, article(info.name) + " needs bounded children, and one of its "
                                                   "children reaches infinity (a plane does)");
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
            report(i, combined + ", beyond single precision (about 3.4e+38)");
        else if (scale[i] < FLT_MIN)
            report(i, combined + ", too small for single precision (about 1.2e-38)");
        else if (!std::isfinite(f.smooth))
            report(i, "smooth times the scales above it is beyond single precision "
                      "(about 3.4e+38)");
        else
            report(i, "the translation of this node, in the units of the scales "
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
    detail::bakeOffsets(scene);
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
