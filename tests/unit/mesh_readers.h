// Small, independent readers for the mesh formats the exporters write (binary PLY, OBJ, binary
// STL, GLB), so tests can check a file by reading it back rather than by comparing bytes. Each
// reader is strict about what it does not understand and reports it in `error`.
#pragma once

#include <glm/vec3.hpp>

#include <bit>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace sdfcsg::test {

// What a file holds, in the exporters' terms. Colours are 0..1 as the reader found them (PLY
// bytes divided by 255, glTF's linear values as stored).
struct MeshData {
    std::vector<glm::vec3> positions, normals, colors;
    std::vector<uint32_t> indices;
    std::string error; // empty when the file was read completely
};

// ---- A minimal JSON reader (RFC 8259 values; enough for glTF and the validator's report) ----

struct JsonMember;
struct Json {
    enum class Type { Null, Bool, Number, String, Array, Object } type = Type::Null;
    bool boolean = false;
    double number = 0;
    std::string string;
    std::vector<Json> array;
    std::vector<JsonMember> object; // not pairs, which need Json whole where clang checks them

    // Member `key` of an object, or nullptr.
    const Json* get(std::string_view key) const;
    const Json* at(size_t i) const { return i < array.size() ? &array[i] : nullptr; }
};
struct JsonMember {
    std::string key;
    Json value;
};
inline const Json* Json::get(std::string_view key) const {
    for (const auto& [k, v] : object)
        if (k == key) return &v;
    return nullptr;
}

class JsonReader {
  public:
    explicit JsonReader(std::string_view text) : s_(text) {}

    // The document, or nullopt with error() set.
    std::optional<Json> parse() {
        Json value;
        if (!readValue(value, 0)) return std::nullopt;
        skipSpace();
        if (pos_ != s_.size()) {
            fail("trailing characters");
            return std::nullopt;
        }
        return value;
    }
    const std::string& error() const { return error_; }

  private:
    bool fail(const std::string& what) {
        if (error_.empty()) error_ = what + " at offset " + std::to_string(pos_);
        return false;
    }
    void skipSpace() {
        while (pos_ < s_.size() &&
               (s_[pos_] == ' ' || s_[pos_] == '\t' || s_[pos_] == '\n' || s_[pos_] == '\r'))
            ++pos_;
    }
    bool literal(std::string_view word) {
        if (s_.substr(pos_, word.size()) != word) return false;
        pos_ += word.size();
        return true;
    }
    bool readString(std::string& out) {
        if (pos_ >= s_.size() || s_[pos_] != '"') return fail("expected a string");
        ++pos_;
        while (pos_ < s_.size() && s_[pos_] != '"') {
            char c = s_[pos_++];
            if (c != '\\') {
                out += c;
                continue;
            }
            if (pos_ >= s_.size()) break;
            char e = s_[pos_++];
            switch (e) {
            case 'n':
                out += '\n';
                break;
            case 't':
                out += '\t';
                break;
            case 'r':
                out += '\r';
                break;
            case 'b':
                out += '\b';
                break;
            case 'f':
                out += '\f';
                break;
            case 'u': {
                // Only what reports contain in practice: code points below 0x80 stay as they
                // are, anything else becomes '?'.
                unsigned code = 0;
                auto [p, ec] = std::from_chars(s_.data() + pos_, s_.data() + pos_ + 4, code, 16);
                if (ec != std::errc() || p != s_.data() + pos_ + 4) return fail("bad \\u escape");
                pos_ += 4;
                out += code < 0x80 ? char(code) : '?';
                break;
            }
            default:
                out += e;
            }
        }
        if (pos_ >= s_.size()) return fail("unterminated string");
        ++pos_;
        return true;
    }
    bool readValue(Json& v, int depth) {
        if (depth > 64) return fail("nested too deeply");
        skipSpace();
        if (pos_ >= s_.size()) return fail("unexpected end");
        char c = s_[pos_];
        if (c == '{') {
            v.type = Json::Type::Object;
            ++pos_;
            skipSpace();
            if (pos_ < s_.size() && s_[pos_] == '}') return ++pos_, true;
            for (;;) {
                skipSpace();
                std::string key;
                if (!readString(key)) return false;
                skipSpace();
                if (pos_ >= s_.size() || s_[pos_++] != ':') return fail("expected ':'");
                Json member;
                if (!readValue(member, depth + 1)) return false;
                v.object.push_back({std::move(key), std::move(member)});
                skipSpace();
                if (pos_ < s_.size() && s_[pos_] == ',') {
                    ++pos_;
                    continue;
                }
                if (pos_ < s_.size() && s_[pos_] == '}') return ++pos_, true;
                return fail("expected ',' or '}'");
            }
        }
        if (c == '[') {
            v.type = Json::Type::Array;
            ++pos_;
            skipSpace();
            if (pos_ < s_.size() && s_[pos_] == ']') return ++pos_, true;
            for (;;) {
                Json item;
                if (!readValue(item, depth + 1)) return false;
                v.array.push_back(std::move(item));
                skipSpace();
                if (pos_ < s_.size() && s_[pos_] == ',') {
                    ++pos_;
                    continue;
                }
                if (pos_ < s_.size() && s_[pos_] == ']') return ++pos_, true;
                return fail("expected ',' or ']'");
            }
        }
        if (c == '"') {
            v.type = Json::Type::String;
            return readString(v.string);
        }
        if (literal("true") || literal("false")) {
            v.type = Json::Type::Bool;
            v.boolean = s_.substr(pos_ - 4, 4) == "true";
            return true;
        }
        if (literal("null")) return true;
        v.type = Json::Type::Number;
        auto [p, ec] = std::from_chars(s_.data() + pos_, s_.data() + s_.size(), v.number);
        if (ec != std::errc()) return fail("expected a value");
        pos_ = size_t(p - s_.data());
        return true;
    }

    std::string_view s_;
    size_t pos_ = 0;
    std::string error_;
};

inline std::optional<Json> parseJson(std::string_view text, std::string* error = nullptr) {
    JsonReader reader(text);
    auto value = reader.parse();
    if (!value && error) *error = reader.error();
    return value;
}

// ---- Little-endian binary access ----

class ByteReader {
  public:
    explicit ByteReader(std::string_view bytes, size_t offset = 0) : b_(bytes), pos_(offset) {}
    bool has(size_t n) const { return pos_ <= b_.size() && b_.size() - pos_ >= n; }
    size_t pos() const { return pos_; }
    bool overrun() const { return overrun_; } // a read went past the end (and gave zeros)
    uint8_t u8() {
        if (has(1)) return uint8_t(b_[pos_++]);
        overrun_ = true;
        return 0;
    }
    uint16_t u16() {
        uint16_t lo = u8();
        return uint16_t(lo | uint16_t(u8()) << 8);
    }
    uint32_t u32() {
        uint32_t v = 0;
        for (int shift = 0; shift < 32; shift += 8)
            v |= uint32_t(u8()) << shift;
        return v;
    }
    float f32() { return std::bit_cast<float>(u32()); }
    glm::vec3 vec3() {
        glm::vec3 v;
        v.x = f32();
        v.y = f32();
        v.z = f32();
        return v;
    }

  private:
    std::string_view b_;
    size_t pos_;
    bool overrun_ = false;
};

// ---- PLY (binary little-endian; the vertex and face elements) ----

struct PlyData : MeshData {
    std::vector<std::string> vertexProperties; // "float x", "uchar red", ... in order
    std::string faceProperty;                  // "list uchar uint vertex_indices"
};

inline PlyData readPly(std::string_view bytes) {
    PlyData out;
    const size_t headerEnd = bytes.find("end_header\n");
    if (bytes.substr(0, 4) != "ply\n" || headerEnd == std::string_view::npos) {
        out.error = "not a PLY file";
        return out;
    }
    std::istringstream header(std::string(bytes.substr(0, headerEnd)));
    std::string line, element;
    size_t vertices = 0, faces = 0;
    bool binaryLe = false;
    while (std::getline(header, line)) {
        std::istringstream words(line);
        std::string word;
        words >> word;
        if (word == "format") {
            std::string kind, version;
            words >> kind >> version;
            binaryLe = kind == "binary_little_endian" && version == "1.0";
        } else if (word == "element") {
            size_t count = 0;
            words >> element >> count;
            if (element == "vertex")
                vertices = count;
            else if (element == "face")
                faces = count;
            else
                out.error = "unexpected element " + element;
        } else if (word == "property") {
            std::string rest;
            std::getline(words, rest);
            rest = rest.substr(rest.find_first_not_of(' '));
            if (element == "vertex")
                out.vertexProperties.push_back(rest);
            else
                out.faceProperty = rest;
        } else if (word != "ply" && word != "comment") {
            out.error = "unexpected header line '" + line + "'";
        }
    }
    if (!binaryLe) out.error = "not binary_little_endian 1.0";
    if (!out.error.empty()) return out;

    auto hasProperty = [&](std::string_view p) {
        for (const auto& q : out.vertexProperties)
            if (q == p) return true;
        return false;
    };
    const bool normals = hasProperty("float nx"), colors = hasProperty("uchar red");
    std::vector<std::string> expected = {"float x", "float y", "float z"};
    if (normals) expected.insert(expected.end(), {"float nx", "float ny", "float nz"});
    if (colors) expected.insert(expected.end(), {"uchar red", "uchar green", "uchar blue"});
    if (out.vertexProperties != expected) {
        out.error = "unexpected vertex properties";
        return out;
    }
    if (out.faceProperty != "list uchar uint vertex_indices") {
        out.error = "unexpected face property '" + out.faceProperty + "'";
        return out;
    }
    ByteReader r(bytes, headerEnd + std::strlen("end_header\n"));
    for (size_t i = 0; i < vertices; ++i) {
        out.positions.push_back(r.vec3());
        if (normals) out.normals.push_back(r.vec3());
        if (colors) {
            glm::vec3 c;
            for (int k = 0; k < 3; ++k)
                c[k] = float(r.u8()) / 255.0f;
            out.colors.push_back(c);
        }
    }
    for (size_t f = 0; f < faces; ++f) {
        if (r.u8() != 3) {
            out.error = "face " + std::to_string(f) + " is not a triangle";
            return out;
        }
        for (int k = 0; k < 3; ++k)
            out.indices.push_back(r.u32());
    }
    if (r.overrun())
        out.error = "file too short";
    else if (r.has(1))
        out.error = "trailing bytes";
    return out;
}

// ---- OBJ (v with optional colour, vn, triangular f with a, a//n or a/t/n references) ----

struct ObjData : MeshData {
    std::vector<std::string> faceLines; // the "f ..." lines as written
};

inline ObjData readObj(std::string_view text) {
    ObjData out;
    std::istringstream in{std::string(text)};
    std::string line;
    std::vector<uint32_t> normalRefs;
    auto number = [](const std::string& word, float& v) {
        auto [p, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
        return ec == std::errc() && p == word.data() + word.size();
    };
    for (int lineNo = 1; std::getline(in, line); ++lineNo) {
        std::istringstream words(line);
        std::string tag, word;
        words >> tag;
        std::vector<std::string> args;
        while (words >> word)
            args.push_back(word);
        const std::string where = "line " + std::to_string(lineNo) + ": ";
        if (tag.empty() || tag[0] == '#') continue;
        if (tag == "v" || tag == "vn") {
            if (args.size() != 3 && !(tag == "v" && args.size() == 6)) {
                out.error = where + "bad vertex";
                return out;
            }
            float v[6];
            for (size_t k = 0; k < args.size(); ++k)
                if (!number(args[k], v[k])) {
                    out.error = where + "bad number '" + args[k] + "'";
                    return out;
                }
            (tag == "v" ? out.positions : out.normals).push_back({v[0], v[1], v[2]});
            if (args.size() == 6) out.colors.push_back({v[3], v[4], v[5]});
        } else if (tag == "f") {
            out.faceLines.push_back(line);
            if (args.size() != 3) {
                out.error = where + "not a triangle";
                return out;
            }
            for (const std::string& ref : args) {
                const size_t slash = ref.find('/');
                const std::string vertex = ref.substr(0, slash);
                uint32_t v = 0, n = 0;
                auto [p, ec] = std::from_chars(vertex.data(), vertex.data() + vertex.size(), v);
                if (ec != std::errc() || v == 0 || p != vertex.data() + vertex.size()) {
                    out.error = where + "bad vertex reference '" + ref + "'";
                    return out;
                }
                out.indices.push_back(v - 1);
                if (slash != std::string::npos) {
                    const std::string normal = ref.substr(ref.rfind('/') + 1);
                    std::from_chars(normal.data(), normal.data() + normal.size(), n);
                    normalRefs.push_back(n - 1);
                }
            }
        } else {
            out.error = where + "unexpected '" + tag + "'";
            return out;
        }
    }
    if (!out.colors.empty() && out.colors.size() != out.positions.size())
        out.error = "colours on some vertices only";
    // The exporters use the vertex's own index for its normal; anything else would need
    // de-indexing, which these tests never want.
    for (size_t i = 0; i < normalRefs.size(); ++i)
        if (normalRefs.size() != out.indices.size() || normalRefs[i] != out.indices[i])
            out.error = "normal references differ from vertex references";
    return out;
}

// ---- Binary STL (an unindexed triangle list with facet normals) ----

struct StlData {
    std::string header;                  // the 80 header bytes
    std::vector<glm::vec3> facetNormals; // one per triangle
    std::vector<glm::vec3> corners;      // three per triangle
    std::vector<uint16_t> attributes;    // one per triangle
    std::string error;
};

inline StlData readStl(std::string_view bytes) {
    StlData out;
    if (bytes.size() < 84) {
        out.error = "shorter than the 84-byte header";
        return out;
    }
    out.header = std::string(bytes.substr(0, 80));
    ByteReader r(bytes, 80);
    const uint32_t count = r.u32();
    if (bytes.size() != 84 + size_t(count) * 50) {
        out.error = "size " + std::to_string(bytes.size()) + " does not match " +
                    std::to_string(count) + " triangles";
        return out;
    }
    for (uint32_t t = 0; t < count; ++t) {
        out.facetNormals.push_back(r.vec3());
        for (int k = 0; k < 3; ++k)
            out.corners.push_back(r.vec3());
        out.attributes.push_back(r.u16());
    }
    return out;
}

// ---- GLB (glTF 2.0 binary container; one mesh primitive of float VEC3 attributes) ----

struct GlbChunk {
    uint32_t length = 0, type = 0;
    size_t offset = 0; // of the chunk's data in the file
};

struct GlbData : MeshData {
    uint32_t magic = 0, version = 0, length = 0;
    std::vector<GlbChunk> chunks;
    std::string jsonText; // the JSON chunk, padding included
    std::string bin;      // the BIN chunk, padding included
    Json json;
    std::vector<std::string> attributes; // attribute names of the primitive, in JSON order
    size_t primitives = 0;
    // Per triangle, its primitive's material's baseColorFactor (linear RGB), where the
    // primitives name materials; the triangles come primitive after primitive.
    std::vector<glm::vec3> triangleColors;
};

inline GlbData readGlb(std::string_view bytes) {
    GlbData out;
    ByteReader r(bytes);
    out.magic = r.u32();
    out.version = r.u32();
    out.length = r.u32();
    if (bytes.size() < 12) {
        out.error = "shorter than the 12-byte header";
        return out;
    }
    while (r.has(8)) {
        GlbChunk chunk;
        chunk.length = r.u32();
        chunk.type = r.u32();
        chunk.offset = r.pos();
        if (!r.has(chunk.length)) {
            out.error = "chunk runs past the end of the file";
            return out;
        }
        out.chunks.push_back(chunk);
        r = ByteReader(bytes, chunk.offset + chunk.length);
    }
    if (r.has(1)) {
        out.error = "trailing bytes after the chunks";
        return out;
    }
    if (out.chunks.empty() || out.chunks[0].type != 0x4E4F534A) {
        out.error = "the first chunk is not JSON";
        return out;
    }
    out.jsonText = std::string(bytes.substr(out.chunks[0].offset, out.chunks[0].length));
    if (out.chunks.size() > 1) {
        if (out.chunks[1].type != 0x004E4942) {
            out.error = "the second chunk is not BIN";
            return out;
        }
        out.bin = std::string(bytes.substr(out.chunks[1].offset, out.chunks[1].length));
    }
    std::string jsonError;
    auto json = parseJson(out.jsonText, &jsonError);
    if (!json) {
        out.error = "JSON: " + jsonError;
        return out;
    }
    out.json = std::move(*json);

    const Json* meshes = out.json.get("meshes");
    if (!meshes) return out; // a scene without meshes
    const Json* primitive = meshes->at(0) && meshes->at(0)->get("primitives")
                                ? meshes->at(0)->get("primitives")->at(0)
                                : nullptr;
    const Json* accessors = out.json.get("accessors");
    const Json* views = out.json.get("bufferViews");
    if (!primitive || !accessors || !views || !primitive->get("attributes")) {
        out.error = "no primitive, accessors or bufferViews";
        return out;
    }
    // The bytes of accessor i, checked to lie inside its view and the BIN chunk.
    auto accessorBytes = [&](const Json* index, int componentType, std::string_view type,
                             size_t elementSize, size_t& count) -> std::optional<std::string_view> {
        const Json* a = index ? accessors->at(size_t(index->number)) : nullptr;
        if (!a || !a->get("bufferView") || !a->get("count") || !a->get("componentType") ||
            !a->get("type"))
            return std::nullopt;
        if (int(a->get("componentType")->number) != componentType || a->get("type")->string != type)
            return std::nullopt;
        const Json* v = views->at(size_t(a->get("bufferView")->number));
        if (!v || !v->get("byteLength")) return std::nullopt;
        count = size_t(a->get("count")->number);
        const size_t viewOffset = v->get("byteOffset") ? size_t(v->get("byteOffset")->number) : 0;
        const size_t accessorOffset =
            a->get("byteOffset") ? size_t(a->get("byteOffset")->number) : 0;
        const size_t viewLength = size_t(v->get("byteLength")->number);
        if (accessorOffset + count * elementSize > viewLength ||
            viewOffset + viewLength > out.bin.size())
            return std::nullopt;
        return std::string_view(out.bin).substr(viewOffset + accessorOffset, count * elementSize);
    };
    for (const auto& [name, index] : primitive->get("attributes")->object) {
        out.attributes.push_back(name);
        size_t count = 0;
        auto data = accessorBytes(&index, 5126, "VEC3", 12, count);
        if (!data) {
            out.error = "attribute " + name + ": not a readable float VEC3 accessor";
            return out;
        }
        std::vector<glm::vec3>* target = name == "POSITION"  ? &out.positions
                                         : name == "NORMAL"  ? &out.normals
                                         : name == "COLOR_0" ? &out.colors
                                                             : nullptr;
        if (!target) {
            out.error = "unexpected attribute " + name;
            return out;
        }
        ByteReader br(*data);
        for (size_t i = 0; i < count; ++i)
            target->push_back(br.vec3());
    }
    // Every primitive shares the first one's vertex attributes (the same accessors).
    const Json* materials = out.json.get("materials");
    for (const Json& p : meshes->at(0)->get("primitives")->array) {
        const Json* attributes = p.get("attributes");
        if (!attributes ||
            attributes->object.size() != primitive->get("attributes")->object.size()) {
            out.error = "a primitive with other attributes than the first";
            return out;
        }
        for (const auto& [name, index] : attributes->object) {
            const Json* first = primitive->get("attributes")->get(name);
            if (!first || first->number != index.number) {
                out.error = "a primitive with other attributes than the first";
                return out;
            }
        }
        size_t count = 0;
        auto indices = accessorBytes(p.get("indices"), 5125, "SCALAR", 4, count);
        if (!indices) {
            out.error = "indices: not a readable UNSIGNED_INT SCALAR accessor";
            return out;
        }
        ByteReader br(*indices);
        for (size_t i = 0; i < count; ++i)
            out.indices.push_back(br.u32());
        if (const Json* m = p.get("material")) {
            const Json* material = materials ? materials->at(size_t(m->number)) : nullptr;
            const Json* pbr = material ? material->get("pbrMetallicRoughness") : nullptr;
            const Json* factor = pbr ? pbr->get("baseColorFactor") : nullptr;
            if (!factor || factor->array.size() != 4) {
                out.error = "a primitive's material has no baseColorFactor";
                return out;
            }
            const glm::vec3 colour(factor->at(0)->number, factor->at(1)->number,
                                   factor->at(2)->number);
            out.triangleColors.insert(out.triangleColors.end(), count / 3, colour);
        }
        ++out.primitives;
    }
    return out;
}

} // namespace sdfcsg::test
