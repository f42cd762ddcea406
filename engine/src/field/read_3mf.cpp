// A 3MF file's triangles and colours (read_3mf.h). The model is XML of up to a gigabyte, parsed by
// expat as zlib inflates it: a streaming parser holds one piece at a time, where a tree would
// hold the whole document several times over. Expat also bounds what entities expand to; 3MF's
// packages may not hold a DTD at all (ECMA-376 part 2, requirement M1.18), so one is refused
// outright.
#include "field/read_3mf.h"

#include "field/mesh_field.h"
#include "io/zip.h"

#include <expat.h>

#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

namespace sdfcsg::detail {
namespace {

constexpr std::string_view kCore = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02",
                           kMaterial =
                               "http://schemas.microsoft.com/3dmanufacturing/material/2015/02",
                           kProduction =
                               "http://schemas.microsoft.com/3dmanufacturing/production/2015/06",
                           kRelationships =
                               "http://schemas.openxmlformats.org/package/2006/relationships",
                           kModelRelationship =
                               "http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel";
constexpr char kSeparator = '|'; // between a name's namespace and its local part, as expat gives
// Objects, components and build items together, each a few dozen bytes of XML that costs more
// than that to keep; and the colours of property groups.
constexpr size_t kMaxElements = size_t(1) << 20, kMaxColors = size_t(1) << 24;
// Components within components: deeper is no model anyone makes. Objects placed, counted with
// each component's: components of empty objects give no triangles but would still be walked.
constexpr int kMaxDepth = 32;
constexpr uint64_t kMaxPlaced = uint64_t(1) << 24;
// Elements within elements, which expat keeps a record of each: a model needs 6, extensions a
// few more.
constexpr size_t kMaxNesting = 64;
// One tag (its attributes), comment or processing instruction: 3MF's are a few hundred bytes.
constexpr uint64_t kMaxToken = uint64_t(4) << 20;

Error problem(std::string text) {
    return Error::message(ErrorKind::Validation, {}, std::move(text));
}

// A name's namespace and local part ("uri|local", or "local" without a namespace).
struct Name {
    std::string_view space, local;
};
Name split(const char* name) {
    const std::string_view s(name);
    const size_t bar = s.rfind(kSeparator);
    if (bar == std::string_view::npos) return {{}, s};
    return {s.substr(0, bar), s.substr(bar + 1)};
}

// An attribute's value for a message, in quotes, cut short where it is long.
std::string quoted(const char* text) {
    const std::string_view s(text);
    return "\"" + std::string(s.substr(0, 40)) + (s.size() > 40 ? "...\"" : "\"");
}

std::string_view trimmed(std::string_view s) {
    while (!s.empty() &&
           (s.front() == ' ' || s.front() == '\t' || s.front() == '\n' || s.front() == '\r'))
        s.remove_prefix(1);
    while (!s.empty() &&
           (s.back() == ' ' || s.back() == '\t' || s.back() == '\n' || s.back() == '\r'))
        s.remove_suffix(1);
    return s;
}

// A whole number under 2^32 with optional spaces about it (ST_ResourceID, ST_ResourceIndex).
std::optional<uint32_t> parseIndex(const char* s) {
    const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
    while (space(*s))
        ++s;
    uint64_t v = 0;
    const char* digits = s;
    for (; *s >= '0' && *s <= '9'; ++s)
        if ((v = v * 10 + uint64_t(*s - '0')) > 0xffffffffu) return std::nullopt;
    const bool some = s != digits;
    while (space(*s))
        ++s;
    return some && *s == '\0' ? std::optional(uint32_t(v)) : std::nullopt;
}

// Whether the attribute name `a` is `name` (of no namespace: expat names the others "uri|name").
bool named(const char* a, std::string_view name) {
    for (char c : name)
        if (*a++ != c) return false;
    return *a == '\0';
}

// The values of the attributes `names`, in one pass over the element's; nullptr where absent.
template <size_t N>
std::array<const char*, N> attributes(const char** atts, const std::string_view (&names)[N]) {
    std::array<const char*, N> values{};
    for (; *atts; atts += 2)
        for (size_t k = 0; k < N; ++k)
            if (named(atts[0], names[k])) values[k] = atts[1];
    return values;
}

// A number of XML Schema's form (ST_Number: a sign, digits, a point, an exponent), or nullptr;
// past a float's range it is infinite, below it zero, and NaN and infinities are left for the
// caller to refuse.
const char* parseNumber(const char* at, const char* end, float& v) {
    if (at != end && *at == '+') ++at;
    double d = 0.0;
    const auto [stop, ec] = std::from_chars(at, end, d);
    if (ec == std::errc::result_out_of_range) {
        const char* e = std::find_if(at, stop, [](char c) { return c == 'e' || c == 'E'; });
        d = e + 1 < stop && e[1] == '-' ? 0.0 : *at == '-' ? -HUGE_VAL : HUGE_VAL;
    } else if (ec != std::errc()) {
        return nullptr;
    }
    constexpr float kInfinity = std::numeric_limits<float>::infinity();
    v = d > double(std::numeric_limits<float>::max())    ? kInfinity
        : d < -double(std::numeric_limits<float>::max()) ? -kInfinity
                                                         : float(d);
    return stop;
}

// "#RRGGBB" or "#RRGGBBAA" (ST_ColorValue) as 0xRRGGBB: a mesh node's colours are opaque.
std::optional<uint32_t> parseColor(std::string_view s) {
    s = trimmed(s);
    if ((s.size() != 7 && s.size() != 9) || s[0] != '#') return std::nullopt;
    uint32_t v = 0;
    const auto [end, ec] = std::from_chars(s.data() + 1, s.data() + s.size(), v, 16);
    if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
    return s.size() == 9 ? v >> 8 : v;
}

// A transform's twelve numbers, m00 m01 m02 m10 ... m32, a 4x3 matrix that multiplies points as
// rows on its left (3MF Core 3.3): row 3 is the translation. As a glm matrix multiplying columns,
// row r of the file's matrix is column r.
std::optional<glm::mat4> parseTransform(std::string_view s) {
    glm::mat4 m(1.0f);
    const char *at = s.data(), *end = s.data() + s.size();
    for (int k = 0; k < 12; ++k) {
        while (at != end && (*at == ' ' || *at == '\t' || *at == '\n' || *at == '\r'))
            ++at;
        float v;
        at = parseNumber(at, end, v);
        if (!at || !std::isfinite(v)) return std::nullopt;
        m[k / 3][k % 3] = v;
    }
    return trimmed(std::string_view(at, size_t(end - at))).empty() ? std::optional(m)
                                                                   : std::nullopt;
}

struct Component {
    uint32_t object; // its index in Package::objects
    glm::mat4 transform;
};

struct Object {
    bool model = true;    // of type "model": supports and others give no triangles
    bool colored = false; // some triangle has a colour: `colors` holds every corner's
    std::optional<uint32_t> pid, pindex;
    std::vector<glm::vec3> vertices;
    std::vector<glm::uvec3> triangles;
    std::vector<uint32_t> colors; // per corner, once `colored`
    std::vector<Component> components;
    uint64_t count = 0;  // its triangles and its components', at most kCountCap
    uint64_t visits = 1; // itself and its components, as often as each is placed
    int depth = 0;       // of its components' nesting
};
constexpr uint64_t kCountCap = uint64_t(1) << 62;

struct PropertyGroup {
    bool colors = false; // base materials or a colour group; else textures and the like
    std::vector<uint32_t> values;
};

// How many millimetres one unit of a model is (3MF Core 3.4, ST_Unit), or nullopt.
std::optional<double> unitMillimetres(std::string_view unit) {
    static constexpr std::pair<std::string_view, double> kUnits[] = {
        {"micron", 0.001}, {"millimeter", 1.0}, {"centimeter", 10.0},
        {"inch", 25.4},    {"foot", 304.8},     {"meter", 1000.0}};
    for (const auto& [name, mm] : kUnits)
        if (trimmed(unit) == name) return mm;
    return std::nullopt;
}

// A p:path as the name of a ZIP entry, or nullopt where it is not a part of the package. A part
// name is absolute ("/3D/Objects/object_1.model"), its segments neither empty, "." nor ".."
// (ECMA-376 part 2, 9.1.1.1), so that it cannot reach outside the package; its ZIP entry is the
// same name without the leading '/' (annex B.3): both are the URI's form, percent-encoded alike,
// so they are compared as they are, only without case (M1.12).
std::optional<std::string_view> partEntryName(std::string_view path) {
    path = trimmed(path);
    if (!path.starts_with('/')) return std::nullopt;
    path.remove_prefix(1);
    for (std::string_view rest = path;;) {
        const size_t slash = rest.find('/');
        const std::string_view segment = rest.substr(0, slash);
        if (segment.empty() || segment == "." || segment == ".." ||
            segment.find('\\') != std::string_view::npos)
            return std::nullopt;
        if (slash == std::string_view::npos) return path;
        rest.remove_prefix(slash + 1);
    }
}

bool sameName(std::string_view a, std::string_view b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
               return std::tolower(uint8_t(x)) == std::tolower(uint8_t(y));
           });
}

std::string lowered(std::string_view s) {
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return out;
}

// The package and what its model parts hold together. How parts are looked up: the root model
// (the one _rels/.rels names) is read first; a component or build item of it with a p:path names
// an object of another model part, which is read whole the first time any names it - the root's
// parsing waiting meanwhile - and its objects' ids kept under its name, so that every later
// reference finds them there and no part is read twice. Only the root may name other parts
// (Production Extension 3.2: a p:path anywhere else is an error), so parts are one level deep
// and cannot name each other in a cycle; their builds are ignored, as that section requires.
struct Package {
    struct Part {
        std::unordered_map<uint32_t, uint32_t> ids; // object id -> index in objects
        double unit = 1.0;                          // millimetres per unit of its coordinates
    };

    Package(std::string_view bytes, std::vector<ZipDirectoryEntry> entries, size_t triangleLimit,
            uint64_t byteLimit)
        : file(bytes), directory(std::move(entries)), maxTriangles(triangleLimit),
          maxBytes(byteLimit) {
        for (const ZipDirectoryEntry& e : directory)
            byName.emplace(lowered(e.name), &e); // the first of a name, as a scan would find
    }
    Package(const Package&) = delete;
    Package& operator=(const Package&) = delete;

    // The entry `name`, found without case (ECMA-376 part 2, requirement M1.12) and at once:
    // every p:path is looked up.
    const ZipDirectoryEntry* find(std::string_view name) const {
        const auto it = byName.find(lowered(name));
        return it == byName.end() ? nullptr : it->second;
    }

    std::string_view file;
    const std::vector<ZipDirectoryEntry> directory;
    std::unordered_map<std::string, const ZipDirectoryEntry*> byName; // by lower-case name
    std::string root = "3D/3dmodel.model";                            // the root model's entry name
    size_t maxTriangles;
    uint64_t maxBytes;

    std::vector<Object> objects;                 // every part's
    std::unordered_map<std::string, Part> parts; // those read, by their entry name in lower case
    size_t elements = 0, vertices = 0, triangles = 0, colors = 0;
    uint64_t unpacked = 0; // bytes of model parts inflated, all of them together
};

enum class Tag : uint8_t {
    Other, // unknown, or an extension's that holds nothing to read: it and all within it skipped
    Model,
    Resources,
    Object,
    Mesh,
    Vertices,
    Triangles,
    Components,
    Colors, // basematerials or m:colorgroup
    Build,
    Leaf, // vertex, triangle, component, base, color, item: read at its start
};

class ModelReader {
  public:
    // Reads the model part `part` of `package`, its root model where `root`.
    ModelReader(Package& package, std::string part, bool root)
        : package_(package), part_(std::move(part)), root_(root) {
        parser_ = XML_ParserCreateNS(nullptr, kSeparator);
        XML_SetUserData(parser_, this);
        // The prefixes the root element declares, which its requiredextensions names.
        XML_SetStartNamespaceDeclHandler(parser_,
                                         [](void* self, const char* prefix, const char* uri) {
                                             auto& reader = *static_cast<ModelReader*>(self);
                                             if (reader.open_.empty() && prefix)
                                                 reader.declared_[prefix] = uri ? uri : "";
                                         });
        XML_SetElementHandler(
            parser_,
            [](void* self, const char* name, const char** atts) {
                static_cast<ModelReader*>(self)->start(name, atts);
            },
            [](void* self, const char*) { static_cast<ModelReader*>(self)->end(); });
        XML_SetStartDoctypeDeclHandler(
            parser_, [](void* self, const char*, const char*, const char*, int) {
                static_cast<ModelReader*>(self)->fail("a DTD, which a 3MF model may not hold");
            });
    }
    ~ModelReader() { XML_ParserFree(parser_); }
    ModelReader(const ModelReader&) = delete;
    ModelReader& operator=(const ModelReader&) = delete;

    // Parses the next piece of the document (the last where `last`); false once it has failed.
    bool feed(std::string_view piece, bool last) {
        if (error_) return false;
        if ((package_.unpacked += piece.size()) > package_.maxBytes) {
            const uint64_t limit = package_.maxBytes;
            error_ = part_ + ": the model parts unpack to more than " +
                     (limit % (1 << 20) == 0 ? std::to_string(limit >> 20) + " MiB"
                                             : std::to_string(limit) + " bytes") +
                     " together";
            return false;
        }
        if (XML_Parse(parser_, piece.data(), int(piece.size()), last) == XML_STATUS_ERROR) {
            if (!error_) error_ = where() + XML_ErrorString(XML_GetErrorCode(parser_));
            return false;
        }
        // Expat 2.5 scans a token left unfinished at a piece's end again from its start with
        // every piece (2.6 defers that), so one tag or comment of hundreds of MB, deflated to a
        // small file, would take hours: the unfinished token, from where expat stands to the
        // bytes fed, is bounded.
        fed_ += piece.size();
        const XML_Index at = XML_GetCurrentByteIndex(parser_);
        if (at >= 0 && fed_ - uint64_t(at) > kMaxToken) {
            error_ = where() + "a tag, comment or other markup of more than " +
                     std::to_string(kMaxToken >> 20) + " MiB";
            return false;
        }
        return true;
    }
    const std::optional<std::string>& error() const { return error_; }
    // Whether its root element was a 3MF model.
    bool rooted() const { return rooted_; }
    double unit() const { return unit_; }
    const std::vector<Component>& items() const { return items_; }

  private:
    std::string where() const {
        return part_ + ", line " + std::to_string(XML_GetCurrentLineNumber(parser_)) + ": ";
    }
    void fail(const std::string& text) { failWith(where() + text); }
    // Fails with a message that names its own part and line: another part's.
    void failWith(const std::string& message) {
        if (!error_) error_ = message;
        XML_StopParser(parser_, XML_FALSE);
    }

    // The attribute `name` (of no namespace, or of `space`), or nullptr.
    static const char* attribute(const char** atts, std::string_view name,
                                 std::string_view space = {}) {
        for (; *atts; atts += 2) {
            const Name n = split(atts[0]);
            if (n.local == name && n.space == space) return atts[1];
        }
        return nullptr;
    }
    // An index attribute: absent (nullopt) or a whole number, else a failure.
    bool index(const char** atts, const char* what, const char* element,
               std::optional<uint32_t>& v) {
        return index(attribute(atts, what), what, element, v);
    }
    bool index(const char* text, const char* what, const char* element,
               std::optional<uint32_t>& v) {
        if (!text) return true;
        v = parseIndex(text);
        if (!v)
            fail(std::string("a ") + element + "'s " + what + " " + quoted(text) +
                 " that is not a whole number under 2^32");
        return bool(v);
    }
    bool required(const char** atts, const char* what, const char* element,
                  std::optional<uint32_t>& v) {
        if (!index(atts, what, element, v)) return false;
        if (!v) fail(std::string("a ") + element + " without its " + what);
        return bool(v);
    }
    bool countElement() {
        if (++package_.elements <= kMaxElements) return true;
        fail("more than " + std::to_string(kMaxElements) + " objects, components and build items");
        return false;
    }
    // The object that `atts`' objectid names, defined before it in this part or in the one its
    // p:path names, placed by its transform: a component or build item; nullopt after failing.
    std::optional<Component> placed(const char** atts, const char* element);
    const Package::Part* otherPart(const char* path, const char* element);
    bool newResource(uint32_t id) {
        if (objectIds_.count(id) || groups_.count(id)) {
            fail("two resources of id " + std::to_string(id));
            return false;
        }
        return true;
    }

    void start(const char* name, const char** atts);
    void end();
    void vertex(const char** atts);
    void triangle(const char** atts);

    void model(const char** atts);

    Package& package_;
    XML_Parser parser_;
    std::string part_;
    bool root_, rooted_ = false;
    double unit_ = 1.0; // millimetres per unit of its coordinates
    std::optional<std::string> error_;
    std::vector<Tag> open_;                                 // the elements open, outermost first
    std::unordered_map<std::string, std::string> declared_; // the root's prefixes -> namespaces

    std::unordered_map<uint32_t, uint32_t> objectIds_; // id -> index in package_.objects
    std::optional<uint32_t> objectId_;                 // of the object being read
    uint32_t current_ = 0;                             // its index in package_.objects
    std::unordered_map<uint32_t, PropertyGroup> groups_;
    PropertyGroup* group_ = nullptr; // the one being read
    std::vector<Component> items_;
    uint64_t fed_ = 0; // bytes of the document given to expat
};

// The model element: its unit, and the extensions it requires, of which only the materials' and
// the production extension's are read (3MF Core 2.3.1: a consumer refuses a document requiring
// one it does not support; any other extension's elements it skips).
void ModelReader::model(const char** atts) {
    rooted_ = true;
    if (const char* unit = attribute(atts, "unit")) {
        const auto mm = unitMillimetres(unit);
        if (!mm)
            return fail("a model unit " + quoted(unit) +
                        " that is not micron, millimeter, centimeter, inch, foot or meter");
        unit_ = *mm;
    }
    const char* required = attribute(atts, "requiredextensions");
    for (std::string_view rest = required ? required : ""; !(rest = trimmed(rest)).empty();) {
        const size_t space = rest.find_first_of(" \t\n\r");
        const std::string prefix(rest.substr(0, space));
        rest.remove_prefix(prefix.size());
        const auto uri = declared_.find(prefix);
        if (uri == declared_.end())
            return fail("a model that requires the extension of prefix " + quoted(prefix.c_str()) +
                        ", which it does not declare");
        if (uri->second != kMaterial && uri->second != kProduction)
            return fail("a model that requires an extension that is not read, \"" +
                        uri->second.substr(0, 100) + (uri->second.size() > 100 ? "...\"" : "\"") +
                        " (of those, only materials and production are)");
    }
}

const Package::Part* ModelReader::otherPart(const char* path, const char* element) {
    const std::string what = std::string("a ") + element + "'s p:path " + quoted(path);
    if (!root_) {
        fail(what + " outside the root model (" + package_.root +
             "), which the production extension forbids");
        return nullptr;
    }
    const auto name = partEntryName(path);
    if (!name) {
        fail(what + " that is not an absolute part name, such as \"/3D/Objects/object_1.model\"");
        return nullptr;
    }
    const std::string key = lowered(*name);
    if (const auto known = package_.parts.find(key); known != package_.parts.end())
        return &known->second;
    const ZipDirectoryEntry* entry = package_.find(*name);
    if (!entry) {
        fail(what + " naming a part the package does not hold");
        return nullptr;
    }
    ModelReader part(package_, entry->name, false);
    const Status unpacked =
        zipUnpack(package_.file, *entry, package_.maxBytes,
                  [&](std::string_view piece) { return part.feed(piece, false); });
    if (!part.error() && unpacked) part.feed({}, true);
    // An error before its root element, within the bytes it may unpack: no model.
    if (part.error() && !part.rooted() && package_.unpacked <= package_.maxBytes) {
        // Its own message names it: what follows its name is why it is no model.
        const std::string& why = *part.error();
        fail(what + " naming " + entry->name + ", which is not a 3MF model part (" +
             why.substr(std::min(why.size(), entry->name.size() + 2)) + ")");
        return nullptr;
    }
    if (part.error() || !unpacked) {
        failWith(part.error() ? *part.error() : unpacked.error().diagnostics[0].message);
        return nullptr;
    }
    return &(package_.parts[key] = {std::move(part.objectIds_), part.unit_});
}

std::optional<Component> ModelReader::placed(const char** atts, const char* element) {
    std::optional<uint32_t> id;
    if (!required(atts, "objectid", element, id)) return std::nullopt;
    const std::unordered_map<uint32_t, uint32_t>* ids = &objectIds_;
    double scale = 1.0; // from the other part's unit to this one's
    const char* path = attribute(atts, "path", kProduction);
    const auto name = path ? partEntryName(path) : std::nullopt;
    if (path && (!root_ || !(name && sameName(*name, part_)))) { // the root's own is no other
        const Package::Part* part = otherPart(path, element);
        if (!part) return std::nullopt;
        ids = &part->ids;
        scale = part->unit / unit_;
    }
    const auto it = ids->find(*id);
    if (it == ids->end()) {
        fail(std::string("a ") + element + " names object " + std::to_string(*id) +
             (ids == &objectIds_ ? ", which no object before it defines"
                                 : " of " + std::string(trimmed(path)) + ", which defines none"));
        return std::nullopt;
    }
    glm::mat4 m(1.0f);
    if (const char* text = attribute(atts, "transform")) {
        const auto parsed = parseTransform(text);
        if (!parsed) {
            fail(std::string("a ") + element + "'s transform " + quoted(text) +
                 " that is not 12 finite numbers");
            return std::nullopt;
        }
        m = *parsed;
    }
    if (scale != 1.0) m = m * glm::mat4(glm::mat3(float(scale)));
    if (!countElement()) return std::nullopt;
    return Component{it->second, m};
}

void ModelReader::start(const char* name, const char** atts) {
    // Its tag is pushed first: expat may still call end() for it after a failure stops parsing.
    const Tag parent = open_.empty() ? Tag::Other : open_.back();
    const bool root = open_.empty();
    open_.push_back(Tag::Other);
    if (error_) return;
    if (open_.size() > kMaxNesting)
        return fail("elements nested more than " + std::to_string(kMaxNesting) + " deep");
    Tag& tag = open_.back();
    const Name n = split(name);
    const bool core = n.space == kCore || n.space.empty(), material = n.space == kMaterial;
    if (root) {
        if (!core || n.local != "model") {
            fail("the document is not a 3MF model (its root is <" +
                 std::string(n.local.substr(0, 40)) + ">, not the core specification's <model>)");
            return;
        }
        tag = Tag::Model;
        model(atts);
    } else if (parent == Tag::Other || parent == Tag::Leaf) {
        tag = Tag::Other;
    } else if (parent == Tag::Model && core) {
        // Only the root's build places objects (Production Extension 2).
        tag = n.local == "resources"        ? Tag::Resources
              : n.local == "build" && root_ ? Tag::Build
                                            : Tag::Other;
    } else if (parent == Tag::Resources && core && n.local == "object") {
        tag = Tag::Object;
        std::optional<uint32_t> id;
        Object o;
        if (!required(atts, "id", "object", id) || !newResource(*id) ||
            !index(atts, "pid", "object", o.pid) || !index(atts, "pindex", "object", o.pindex) ||
            !countElement())
            return;
        const char* type = attribute(atts, "type");
        o.model = !type || trimmed(type) == "model";
        objectId_ = id;
        current_ = uint32_t(package_.objects.size());
        package_.objects.push_back(std::move(o));
    } else if (parent == Tag::Resources &&
               ((core && n.local == "basematerials") || (material && n.local == "colorgroup") ||
                (material && (n.local == "texture2dgroup" || n.local == "compositematerials" ||
                              n.local == "multiproperties")))) {
        // Every property group takes its id, so that a triangle naming one is not an error; only
        // those of colours hold values.
        std::optional<uint32_t> id;
        const std::string element(n.local);
        if (!required(atts, "id", element.c_str(), id) || !newResource(*id)) return;
        group_ = &groups_[*id];
        group_->colors = n.local == "basematerials" || n.local == "colorgroup";
        tag = group_->colors ? Tag::Colors : Tag::Other;
    } else if (parent == Tag::Object && core) {
        tag = n.local == "mesh"         ? Tag::Mesh
              : n.local == "components" ? Tag::Components
                                        : Tag::Other;
    } else if (parent == Tag::Mesh && core) {
        tag = n.local == "vertices"    ? Tag::Vertices
              : n.local == "triangles" ? Tag::Triangles
                                       : Tag::Other;
    } else if (parent == Tag::Vertices && core && n.local == "vertex") {
        tag = Tag::Leaf;
        vertex(atts);
    } else if (parent == Tag::Triangles && core && n.local == "triangle") {
        tag = Tag::Leaf;
        triangle(atts);
    } else if (parent == Tag::Components && core && n.local == "component") {
        tag = Tag::Leaf;
        // Placed before the object is taken: another part read for it adds objects.
        if (const auto c = placed(atts, "component"))
            package_.objects[current_].components.push_back(*c);
    } else if (parent == Tag::Colors &&
               ((core && n.local == "base") || (material && n.local == "color"))) {
        tag = Tag::Leaf;
        const char* what = n.local == "base" ? "displaycolor" : "color";
        const char* text = attribute(atts, what);
        const auto color = text ? parseColor(text) : std::nullopt;
        if (!text)
            fail("a <" + std::string(n.local) + "> without its " + what);
        else if (!color)
            fail("a colour " + quoted(text) + " that is not #RRGGBB or #RRGGBBAA");
        else if (++package_.colors > kMaxColors)
            fail("more than " + std::to_string(kMaxColors) + " colours");
        else
            group_->values.push_back(*color);
    } else if (parent == Tag::Build && core && n.local == "item") {
        tag = Tag::Leaf;
        if (const auto item = placed(atts, "build item")) items_.push_back(*item);
    }
}

void ModelReader::end() {
    const Tag tag = open_.back();
    open_.pop_back();
    if (error_) return;
    if (tag == Tag::Object && objectId_) {
        // Its count and depth, from its components' (all defined before it, so never itself).
        Object& o = package_.objects[current_];
        o.count = o.triangles.size();
        for (const Component& c : o.components) {
            const Object& part = package_.objects[c.object];
            o.count = std::min(o.count + part.count, kCountCap);
            o.visits = std::min(o.visits + part.visits, kCountCap);
            o.depth = std::max(o.depth, part.depth + 1);
        }
        if (!o.model) o.count = 0;
        if (o.depth > kMaxDepth) {
            fail("components nested more than " + std::to_string(kMaxDepth) + " deep");
            return;
        }
        objectIds_[*objectId_] = current_;
        objectId_.reset();
    }
    if (tag == Tag::Colors) group_ = nullptr;
}

void ModelReader::vertex(const char** atts) {
    static constexpr std::string_view kNames[] = {"x", "y", "z"};
    const auto texts = attributes(atts, kNames);
    glm::vec3 p;
    for (int k = 0; k < 3; ++k) {
        const char* axis = kNames[k].data();
        const char* text = texts[size_t(k)];
        if (!text) return fail(std::string("a vertex without its ") + axis);
        const std::string_view s = trimmed(text);
        const char* stop = parseNumber(s.data(), s.data() + s.size(), p[k]);
        if (!stop || stop != s.data() + s.size())
            return fail(std::string("a vertex whose ") + axis + " " + quoted(text) +
                        " is not a number");
    }
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        return fail("a NaN or infinite vertex");
    if (++package_.vertices > 3 * package_.maxTriangles)
        return fail("more than " + std::to_string(3 * package_.maxTriangles) + " vertices");
    package_.objects[current_].vertices.push_back(p);
}

void ModelReader::triangle(const char** atts) {
    Object& o = package_.objects[current_];
    std::optional<uint32_t> v[3], pid, p[3];
    static constexpr std::string_view kNames[] = {"v1", "v2", "v3", "p1", "p2", "p3", "pid"};
    const auto texts = attributes(atts, kNames);
    static const char* const vs[3] = {"v1", "v2", "v3"};
    static const char* const ps[3] = {"p1", "p2", "p3"};
    for (int k = 0; k < 3; ++k) {
        if (!index(texts[size_t(k)], vs[k], "triangle", v[k]) ||
            !index(texts[size_t(k) + 3], ps[k], "triangle", p[k]))
            return;
        if (!v[k]) return fail(std::string("a triangle without its ") + vs[k]);
        if (*v[k] >= o.vertices.size())
            return fail(std::string("a triangle's ") + vs[k] + " (" + std::to_string(*v[k]) +
                        ") past its object's " + std::to_string(o.vertices.size()) + " vertices");
    }
    if (!index(texts[6], "pid", "triangle", pid)) return;
    if (++package_.triangles > package_.maxTriangles)
        return fail("more than " + std::to_string(package_.maxTriangles) + " triangles");
    o.triangles.push_back({*v[0], *v[1], *v[2]});
    // Its colours: its own property group and indices, else its object's.
    if (!pid) pid = o.pid;
    if (!p[0]) p[0] = o.pindex;
    if (!pid) {
        if (o.colored) o.colors.insert(o.colors.end(), 3, kNoColor);
        return;
    }
    const auto group = groups_.find(*pid);
    if (group == groups_.end())
        return fail("a triangle names property group " + std::to_string(*pid) +
                    ", which no resource before it defines");
    uint32_t colors[3] = {kNoColor, kNoColor, kNoColor};
    if (group->second.colors) {
        if (!p[0]) return fail("a triangle with a property group but no index (p1 or pindex)");
        const std::vector<uint32_t>& values = group->second.values;
        for (int k = 0; k < 3; ++k) {
            const uint32_t i = p[k] ? *p[k] : *p[0]; // one index: the whole triangle's
            if (i >= values.size())
                return fail(std::string("a triangle's ") + ps[k] + " (" + std::to_string(i) +
                            ") past the " + std::to_string(values.size()) +
                            " entries of property group " + std::to_string(*pid));
            colors[k] = values[i];
        }
    }
    if (!o.colored && colors[0] != kNoColor) {
        o.colored = true;
        o.colors.assign(3 * (o.triangles.size() - 1), kNoColor);
    }
    if (o.colored) o.colors.insert(o.colors.end(), colors, colors + 3);
}

// The triangles of the build's `items`, each scaled by `scale` last.
Status emit(const Package& package, const std::vector<Component>& items, float scale,
            const ThreeMfCorners& out) {
    const std::vector<Object>& objects = package.objects;
    uint64_t total = 0, placed = 0;
    for (const Component& item : items) {
        total = std::min(total + objects[item.object].count, kCountCap);
        placed = std::min(placed + objects[item.object].visits, kCountCap);
    }
    if (total > package.maxTriangles)
        return problem("more than " + std::to_string(package.maxTriangles) + " triangles (" +
                       (total == kCountCap ? std::string("far more") : std::to_string(total)) +
                       ")");
    if (placed > kMaxPlaced)
        return problem("a build that places objects more than " + std::to_string(kMaxPlaced) +
                       " times");
    out.begin(size_t(total));
    std::vector<Component> stack;
    const glm::mat4 scaled{glm::mat3(scale)};
    for (const Component& item : items) {
        stack.push_back({item.object, scale == 1.0f ? item.transform : scaled * item.transform});
        while (!stack.empty()) {
            const Component visit = stack.back();
            stack.pop_back();
            const Object& o = objects[visit.object];
            if (!o.model) continue;
            for (const Component& c : o.components)
                stack.push_back({c.object, visit.transform * c.transform});
            // Corners moved one by one: an object's vertices may far outnumber its triangles'
            // corners, and the work stays that of the triangles placed.
            const bool moves = visit.transform != glm::mat4(1.0f);
            // A mirroring transform turns the triangles inside out: their corners are reversed.
            const bool mirrored = glm::determinant(glm::mat3(visit.transform)) < 0.0f;
            for (size_t t = 0; t < o.triangles.size(); ++t)
                for (int k = 0; k < 3; ++k) {
                    const int c = mirrored && k > 0 ? 3 - k : k;
                    glm::vec3 p = o.vertices[o.triangles[t][c]];
                    if (moves) {
                        p = glm::vec3(visit.transform * glm::vec4(p, 1.0f));
                        if (!std::isfinite(p.x + p.y + p.z))
                            return problem("a NaN or infinite vertex");
                    }
                    out.corner(p, o.colored ? o.colors[3 * t + size_t(c)] : kNoColor);
                }
        }
    }
    return Ok{};
}

// The part that _rels/.rels names as the 3D model, without its leading '/'; empty where it
// names none.
Result<std::string> modelPartName(std::string_view rels) {
    struct State {
        XML_Parser parser;
        std::string target;
    } state{XML_ParserCreateNS(nullptr, kSeparator), {}};
    XML_SetUserData(state.parser, &state);
    XML_SetStartElementHandler(state.parser, [](void* self, const char* name, const char** atts) {
        State& s = *static_cast<State*>(self);
        const Name n = split(name);
        if (n.space != kRelationships || n.local != "Relationship" || !s.target.empty()) return;
        const char *type = nullptr, *target = nullptr;
        for (; *atts; atts += 2) {
            if (std::strcmp(atts[0], "Type") == 0) type = atts[1];
            if (std::strcmp(atts[0], "Target") == 0) target = atts[1];
        }
        if (type && target && trimmed(type) == kModelRelationship) s.target = trimmed(target);
    });
    XML_SetStartDoctypeDeclHandler(state.parser,
                                   [](void* self, const char*, const char*, const char*, int) {
                                       XML_StopParser(static_cast<State*>(self)->parser, XML_FALSE);
                                   });
    const bool read =
        XML_Parse(state.parser, rels.data(), int(rels.size()), true) != XML_STATUS_ERROR;
    const std::string why = read ? "" : XML_ErrorString(XML_GetErrorCode(state.parser));
    const auto line = XML_GetCurrentLineNumber(state.parser);
    XML_ParserFree(state.parser);
    if (!read) return problem("_rels/.rels, line " + std::to_string(line) + ": " + why);
    const size_t slash = state.target.starts_with('/') ? 1 : 0;
    return state.target.substr(slash);
}

} // namespace

Status readThreeMf(std::string_view file, const ThreeMfCorners& out, size_t maxTriangles,
                   uint64_t maxModelBytes, double unitMillimetres) {
    auto directory = zipDirectory(file);
    if (!directory) return problem("not a 3MF file: " + directory.error().diagnostics[0].message);
    Package package(file, std::move(*directory), maxTriangles, maxModelBytes);
    if (const ZipDirectoryEntry* rels = package.find("_rels/.rels")) {
        std::string text;
        const Status unpacked = zipUnpack(file, *rels, uint64_t(1) << 20, [&](std::string_view s) {
            text += s;
            return true;
        });
        if (!unpacked) return unpacked.error();
        auto named = modelPartName(text);
        if (!named) return named.error();
        if (!named->empty()) package.root = *named;
    }
    const ZipDirectoryEntry* model = package.find(package.root);
    if (!model) return problem("a 3MF without its model part (" + package.root + ")");
    package.root = model->name;
    ModelReader reader(package, model->name, true);
    const Status unpacked = zipUnpack(file, *model, maxModelBytes, [&](std::string_view piece) {
        return reader.feed(piece, false);
    });
    if (reader.error()) return problem(*reader.error());
    if (!unpacked) return unpacked.error();
    if (!reader.feed({}, true)) return problem(*reader.error());
    return emit(package, reader.items(), float(reader.unit() / unitMillimetres), out);
}

} // namespace sdfcsg::detail
