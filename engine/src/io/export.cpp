// Mesh exporters: binary PLY, OBJ, binary STL, glTF 2.0 binary and 3MF, encoded in memory and
// written atomically. Binary formats are little-endian by specification; values are written
// byte by byte so the output does not depend on the host's byte order.
//
// References: PLY (Greg Turk, "The PLY Polygon File Format"); binary STL (3D Systems,
// "StereoLithography Interface Specification", 1989); glTF 2.0 (Khronos, "glTF 2.0
// Specification": the chapters on accessors and on the GLB file format); 3MF (3MF Consortium,
// "3MF Core Specification" 1.3 and "Materials and Properties Extension" 1.2).
#include "sdfcsg/export.h"
#include "sdfcsg/io.h"

#include "io/zip.h"
#include "scene/json_writer.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

namespace sdfcsg {
namespace {

using detail::formatNumber;

void putU8(std::string& out, uint8_t v) {
    out.push_back(char(v));
}
void putU16(std::string& out, uint16_t v) {
    out.push_back(char(v & 0xff));
    out.push_back(char(v >> 8));
}
void putU32(std::string& out, uint32_t v) {
    for (int shift = 0; shift < 32; shift += 8)
        out.push_back(char((v >> shift) & 0xff));
}
void putF32(std::string& out, float v) {
    putU32(out, std::bit_cast<uint32_t>(v));
}
void putVec3(std::string& out, glm::vec3 v) {
    putF32(out, v.x);
    putF32(out, v.y);
    putF32(out, v.z);
}

uint8_t toByte(float c) {
    return uint8_t(std::lround(std::clamp(c, 0.0f, 1.0f) * 255.0f));
}

// Normals and colours are optional per mesh: a hand-built mesh may leave them empty, and then
// the formats that can omit them do.
bool hasNormals(const Mesh& mesh) {
    return !mesh.positions.empty() && mesh.normals.size() == mesh.positions.size();
}
bool hasColors(const Mesh& mesh) {
    return !mesh.positions.empty() && mesh.colors.size() == mesh.positions.size();
}
bool hasTriangleColors(const Mesh& mesh) {
    return mesh.triangleCount() > 0 && mesh.triangleColors.size() == mesh.triangleCount();
}

uint32_t rgbOf(glm::vec3 c) {
    return uint32_t(toByte(c.r)) << 16 | uint32_t(toByte(c.g)) << 8 | toByte(c.b);
}

// The distinct colours of `colors` as 8-bit RGB (0xRRGGBB), ascending, and each entry's place
// among them.
std::vector<uint32_t> distinctColors(const std::vector<glm::vec3>& colors,
                                     std::vector<uint32_t>& placeOf) {
    std::vector<uint32_t> rgb(colors.size());
    for (size_t i = 0; i < rgb.size(); ++i)
        rgb[i] = rgbOf(colors[i]);
    std::vector<uint32_t> distinct = rgb;
    std::sort(distinct.begin(), distinct.end());
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    placeOf.resize(rgb.size());
    for (size_t i = 0; i < rgb.size(); ++i)
        placeOf[i] =
            uint32_t(std::lower_bound(distinct.begin(), distinct.end(), rgb[i]) - distinct.begin());
    return distinct;
}

std::string hexColor(uint32_t rgb) {
    char text[8];
    std::snprintf(text, sizeof text, "#%06X", rgb);
    return text;
}

std::string encodePly(const Mesh& mesh) {
    const bool normals = hasNormals(mesh), colors = hasColors(mesh);
    std::string out = "ply\nformat binary_little_endian 1.0\ncomment sdfcsg mesh\n";
    out += "element vertex " + std::to_string(mesh.vertexCount()) + "\n";
    out += "property float x\nproperty float y\nproperty float z\n";
    if (normals) out += "property float nx\nproperty float ny\nproperty float nz\n";
    if (colors) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    out += "element face " + std::to_string(mesh.triangleCount()) + "\n";
    out += "property list uchar uint vertex_indices\nend_header\n";
    out.reserve(out.size() + mesh.vertexCount() * 27 + mesh.triangleCount() * 13);
    for (size_t i = 0; i < mesh.vertexCount(); ++i) {
        putVec3(out, mesh.positions[i]);
        if (normals) putVec3(out, mesh.normals[i]);
        if (colors)
            for (int c = 0; c < 3; ++c)
                putU8(out, toByte(mesh.colors[i][c]));
    }
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
        putU8(out, 3);
        for (int k = 0; k < 3; ++k)
            putU32(out, mesh.indices[3 * t + k]);
    }
    return out;
}

// Shortest decimal text that reads back as exactly v (as a float), locale-independent.
void appendFloat(std::string& out, float v) {
    char buf[32];
    auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, ec == std::errc() ? end : buf);
}

std::string encodeObj(const Mesh& mesh) {
    const bool normals = hasNormals(mesh), colors = hasColors(mesh);
    std::string out = "# sdfcsg mesh: " + std::to_string(mesh.vertexCount()) + " vertices, " +
                      std::to_string(mesh.triangleCount()) + " triangles\n";
    auto vec = [&](const char* tag, glm::vec3 v) {
        out += tag;
        for (int c = 0; c < 3; ++c) {
            out += ' ';
            appendFloat(out, v[c]);
        }
    };
    for (size_t i = 0; i < mesh.vertexCount(); ++i) {
        vec("v", mesh.positions[i]);
        if (colors) vec("", mesh.colors[i]);
        out += '\n';
    }
    if (normals)
        for (size_t i = 0; i < mesh.vertexCount(); ++i) {
            vec("vn", mesh.normals[i]);
            out += '\n';
        }
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
        out += 'f';
        for (int k = 0; k < 3; ++k) {
            const std::string index = std::to_string(uint64_t(mesh.indices[3 * t + k]) + 1);
            out += ' ';
            out += index;
            if (normals) out += "//" + index;
        }
        out += '\n';
    }
    return out;
}

// The position that index i names; the origin for an index out of range (which writeMesh
// rejects before encoding), so encodeMesh never reads out of bounds.
glm::vec3 corner(const Mesh& mesh, size_t i) {
    const uint32_t v = mesh.indices[i];
    return v < mesh.positions.size() ? mesh.positions[v] : glm::vec3(0.0f);
}

// The formats for printing (STL, 3MF) are z up, as slicers build along z: the scene's y becomes
// z, (x, y, z) -> (x, -z, y), a rotation, so windings stay outward.
glm::vec3 zUp(glm::vec3 p) {
    return {p.x, -p.z, p.y};
}

std::string encodeStl(const Mesh& mesh) {
    // The header must not begin with "solid", which readers take for the ASCII variant.
    std::string out = "sdfcsg binary STL";
    out.resize(80, ' ');
    putU32(out, uint32_t(mesh.triangleCount()));
    out.reserve(out.size() + mesh.triangleCount() * 50);
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
        const glm::vec3 a = zUp(corner(mesh, 3 * t)), b = zUp(corner(mesh, 3 * t + 1)),
                        c = zUp(corner(mesh, 3 * t + 2));
        const glm::vec3 n = glm::cross(b - a, c - a);
        const float length = glm::length(n);
        putVec3(out, length > 0.0f ? n / length : glm::vec3(0.0f));
        putVec3(out, a);
        putVec3(out, b);
        putVec3(out, c);
        putU16(out, 0);
    }
    return out;
}

// glTF defines COLOR_0 in linear space; scene colours are written as on screen (sRGB), so they
// go through the sRGB transfer function (IEC 61966-2-1) here.
float srgbToLinear(float c) {
    c = std::clamp(c, 0.0f, 1.0f);
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

constexpr uint32_t kGlbMagic = 0x46546C67;  // "glTF"
constexpr uint32_t kChunkJson = 0x4E4F534A; // "JSON"
constexpr uint32_t kChunkBin = 0x004E4942;  // "BIN\0"
constexpr int kFloat = 5126, kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;
constexpr int kTriangles = 4;

// min and max written as the exact values of the floats (as doubles), so they equal the data
// whichever precision a reader compares in.
std::string vec3Text(glm::vec3 v) {
    std::string text = "[";
    for (int c = 0; c < 3; ++c) {
        text += formatNumber(v[c]);
        text += c < 2 ? ',' : ']';
    }
    return text;
}

// Appends pieces of text; plain += chains, which GCC 12 misreports under -Wrestrict when a
// literal starts one.
void cat(std::string& out, std::initializer_list<std::string_view> pieces) {
    for (std::string_view piece : pieces)
        out.append(piece);
}

std::string encodeGlb(const Mesh& mesh) {
    using std::to_string;
    std::string json = R"({"asset":{"version":"2.0","generator":"sdfcsg"},"scene":0,)";
    std::string bin;
    // glTF has no empty accessors or buffers, so a mesh without triangles is a scene without
    // nodes.
    if (mesh.triangleCount() == 0) {
        json += R"("scenes":[{}]})";
    } else {
        std::string views, accessors, attributes;
        uint32_t accessorCount = 0;
        // Each accessor has its own view; all elements are 4 bytes, so every view starts 4-byte
        // aligned.
        auto addView = [&](size_t offset, int target) {
            cat(views, {views.empty() ? "" : ",", R"({"buffer":0,"byteOffset":)", to_string(offset),
                        R"(,"byteLength":)", to_string(bin.size() - offset), R"(,"target":)",
                        to_string(target), "}"});
        };
        auto addVec3 = [&](std::string_view name, const std::vector<glm::vec3>& data,
                           bool linearize, bool bounds) {
            const size_t offset = bin.size();
            glm::vec3 lo(INFINITY), hi(-INFINITY);
            for (glm::vec3 v : data) {
                if (linearize) v = {srgbToLinear(v.x), srgbToLinear(v.y), srgbToLinear(v.z)};
                lo = glm::min(lo, v);
                hi = glm::max(hi, v);
                putVec3(bin, v);
            }
            addView(offset, kArrayBuffer);
            cat(accessors, {accessors.empty() ? "" : ",", R"({"bufferView":)",
                            to_string(accessorCount), R"(,"componentType":)", to_string(kFloat),
                            R"(,"count":)", to_string(data.size()), R"(,"type":"VEC3")"});
            if (bounds) cat(accessors, {R"(,"min":)", vec3Text(lo), R"(,"max":)", vec3Text(hi)});
            accessors += '}';
            cat(attributes,
                {attributes.empty() ? "" : ",", "\"", name, "\":", to_string(accessorCount++)});
        };
        // With triangle colours, one primitive per colour, each with its material, on the
        // shared vertices; COLOR_0 would multiply the material's colour, so it is left out.
        const bool regions = hasTriangleColors(mesh);
        std::vector<uint32_t> materialOf;
        const std::vector<uint32_t> materials =
            regions ? distinctColors(mesh.triangleColors, materialOf) : std::vector<uint32_t>{};
        bin.reserve(mesh.vertexCount() * 36 + mesh.indices.size() * 4);
        addVec3("POSITION", mesh.positions, false, true);
        if (hasNormals(mesh)) addVec3("NORMAL", mesh.normals, false, false);
        if (hasColors(mesh) && !regions) addVec3("COLOR_0", mesh.colors, true, false);

        // The triangles of each material in their order (all of them, without triangle colours).
        std::vector<std::vector<uint32_t>> groups(regions ? materials.size() : 1);
        for (size_t t = 0; t < mesh.triangleCount(); ++t)
            groups[regions ? materialOf[t] : 0].push_back(uint32_t(t));
        std::string primitives;
        for (size_t g = 0; g < groups.size(); ++g) {
            const size_t indexOffset = bin.size(), indexCount = groups[g].size() * 3;
            uint32_t lo = UINT32_MAX, hi = 0;
            for (uint32_t t : groups[g])
                for (int k = 0; k < 3; ++k) {
                    const uint32_t i = mesh.indices[3 * size_t(t) + k];
                    lo = std::min(lo, i);
                    hi = std::max(hi, i);
                    putU32(bin, i);
                }
            addView(indexOffset, kElementArrayBuffer);
            cat(accessors, {R"(,{"bufferView":)", to_string(accessorCount), R"(,"componentType":)",
                            to_string(kUnsignedInt), R"(,"count":)", to_string(indexCount),
                            R"(,"type":"SCALAR","min":[)", to_string(lo), R"(],"max":[)",
                            to_string(hi), "]}"});
            cat(primitives, {g ? "," : "", R"({"attributes":{)", attributes, R"(},"indices":)",
                             to_string(accessorCount++), R"(,"mode":)", to_string(kTriangles)});
            if (regions) cat(primitives, {R"(,"material":)", to_string(g)});
            primitives += '}';
        }
        std::string materialList;
        for (size_t g = 0; g < materials.size(); ++g) {
            const uint32_t rgb = materials[g];
            std::string factor = "[";
            for (int c = 0; c < 3; ++c) {
                factor += formatNumber(srgbToLinear(float((rgb >> (16 - 8 * c)) & 0xFF) / 255.0f));
                factor += ',';
            }
            factor += "1]";
            cat(materialList, {g ? "," : "", R"({"name":")", hexColor(rgb),
                               R"(","pbrMetallicRoughness":{"baseColorFactor":)", factor,
                               R"(,"metallicFactor":0,"roughnessFactor":1}})"});
        }

        cat(json, {R"("scenes":[{"nodes":[0]}],"nodes":[{"mesh":0,"name":"sdfcsg"}],)",
                   R"("meshes":[{"primitives":[)", primitives, "]}],"});
        if (regions) cat(json, {R"("materials":[)", materialList, "],"});
        cat(json, {R"("buffers":[{"byteLength":)", to_string(bin.size()), "}],",
                   R"("bufferViews":[)", views, "],", R"("accessors":[)", accessors, "]}"});
    }

    json.resize((json.size() + 3) & ~size_t(3), ' ');
    bin.resize((bin.size() + 3) & ~size_t(3), '\0');
    const size_t total = 12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size());
    std::string out;
    out.reserve(total);
    putU32(out, kGlbMagic);
    putU32(out, 2);
    putU32(out, uint32_t(total));
    putU32(out, uint32_t(json.size()));
    putU32(out, kChunkJson);
    out += json;
    if (!bin.empty()) {
        putU32(out, uint32_t(bin.size()));
        putU32(out, kChunkBin);
        out += bin;
    }
    return out;
}

// What the encoders rely on; a mesh that breaks it would give files that readers reject.

const char* unitName(LengthUnit unit) {
    switch (unit) {
    case LengthUnit::Millimeter:
        return "millimeter";
    case LengthUnit::Centimeter:
        return "centimeter";
    case LengthUnit::Meter:
        return "meter";
    case LengthUnit::Inch:
        return "inch";
    }
    return "millimeter";
}

// The model part of a 3MF package: vertices turned z up (zUp), triangles with their own colours
// or their corners', and one build item.
// The specification forbids a triangle that names a vertex twice; such a triangle has no area
// and is left out.
std::string threeMfModel(const Mesh& mesh, LengthUnit unit) {
    const bool colors = hasColors(mesh);
    std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"";
    out += unitName(unit);
    out += "\" xml:lang=\"en-US\" "
           "xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\" "
           "xmlns:m=\"http://schemas.microsoft.com/3dmanufacturing/material/2015/02\">\n"
           "<metadata name=\"Application\">sdfcsg</metadata>\n<resources>\n";
    // The distinct colours, each once, and each vertex's (or with triangle colours, each
    // triangle's) place among them. Triangle colours are base materials, one per colour, which
    // slicers offer to assign filaments to; vertex colours a colour group, blended across each
    // triangle.
    const bool regions = hasTriangleColors(mesh);
    std::vector<uint32_t> colorOf;
    if (regions) {
        out += " <basematerials id=\"1\">\n";
        for (uint32_t c : distinctColors(mesh.triangleColors, colorOf)) {
            const std::string hex = hexColor(c);
            out += "  <base name=\"" + hex + "\" displaycolor=\"" + hex + "\"/>\n";
        }
        out += " </basematerials>\n";
    } else if (colors) {
        out += " <m:colorgroup id=\"1\">\n";
        for (uint32_t c : distinctColors(mesh.colors, colorOf))
            out += "  <m:color color=\"" + hexColor(c) + "\"/>\n";
        out += " </m:colorgroup>\n";
    }
    out += colors || regions ? " <object id=\"2\" type=\"model\" pid=\"1\" pindex=\"0\">\n"
                             : " <object id=\"2\" type=\"model\">\n";
    out += "  <mesh>\n   <vertices>\n";
    out.reserve(out.size() + mesh.vertexCount() * 48 + mesh.triangleCount() * 64);
    for (const glm::vec3& v : mesh.positions) {
        const glm::vec3 turned = zUp(v);
        out += "    <vertex";
        for (int k = 0; k < 3; ++k) {
            out += k == 0 ? " x=\"" : k == 1 ? "\" y=\"" : "\" z=\"";
            appendFloat(out, turned[k] == 0.0f ? 0.0f : turned[k]); // no "-0"
        }
        out += "\"/>\n";
    }
    out += "   </vertices>\n   <triangles>\n";
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
        const uint32_t* v = &mesh.indices[3 * t];
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) continue;
        out += "    <triangle";
        for (int k = 0; k < 3; ++k)
            out += " v" + std::to_string(k + 1) + "=\"" + std::to_string(v[k]) + "\"";
        if (regions)
            out += " p1=\"" + std::to_string(colorOf[t]) + "\"";
        else if (colors)
            for (int k = 0; k < 3; ++k)
                out += " p" + std::to_string(k + 1) + "=\"" + std::to_string(colorOf[v[k]]) + "\"";
        out += "/>\n";
    }
    out += "   </triangles>\n  </mesh>\n </object>\n</resources>\n"
           "<build>\n <item objectid=\"2\"/>\n</build>\n</model>\n";
    return out;
}

// The package: the content types, the relationship that names the model, and the model.
std::string encodeThreeMf(const Mesh& mesh, LengthUnit unit) {
    static constexpr std::string_view kContentTypes =
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        "<Types xmlns=\"http://schemas.openxmlformats.org/package/2006/content-types\">\n"
        " <Default Extension=\"rels\" "
        "ContentType=\"application/vnd.openxmlformats-package.relationships+xml\"/>\n"
        " <Default Extension=\"model\" "
        "ContentType=\"application/vnd.ms-package.3dmanufacturing-3dmodel+xml\"/>\n"
        "</Types>\n";
    static constexpr std::string_view kRelationships =
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        "<Relationships xmlns=\"http://schemas.openxmlformats.org/package/2006/relationships\">\n"
        " <Relationship Target=\"/3D/3dmodel.model\" Id=\"rel0\" "
        "Type=\"http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\"/>\n"
        "</Relationships>\n";
    const std::string model = threeMfModel(mesh, unit);
    const detail::ZipEntry entries[] = {{"[Content_Types].xml", kContentTypes},
                                        {"_rels/.rels", kRelationships},
                                        {"3D/3dmodel.model", model}};
    return detail::zipArchive(entries).value_or(std::string());
}

std::optional<std::string> meshProblem(const Mesh& mesh) {
    const size_t n = mesh.vertexCount();
    if (mesh.indices.size() % 3 != 0)
        return std::to_string(mesh.indices.size()) + " indices is not a whole number of triangles";
    if (!mesh.normals.empty() && mesh.normals.size() != n)
        return std::to_string(mesh.normals.size()) + " normals for " + std::to_string(n) +
               " vertices";
    if (!mesh.colors.empty() && mesh.colors.size() != n)
        return std::to_string(mesh.colors.size()) + " colours for " + std::to_string(n) +
               " vertices";
    if (!mesh.triangleColors.empty() && mesh.triangleColors.size() != mesh.indices.size() / 3)
        return std::to_string(mesh.triangleColors.size()) + " triangle colours for " +
               std::to_string(mesh.indices.size() / 3) + " triangles";
    for (size_t i = 0; i < mesh.indices.size(); ++i)
        if (mesh.indices[i] >= n)
            return "index " + std::to_string(i) + " is " + std::to_string(mesh.indices[i]) +
                   ", but there are " + std::to_string(n) + " vertices";
    return std::nullopt;
}

} // namespace

std::optional<MeshFormat> meshFormatFromPath(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".ply") return MeshFormat::Ply;
    if (ext == ".obj") return MeshFormat::Obj;
    if (ext == ".stl") return MeshFormat::Stl;
    if (ext == ".glb") return MeshFormat::Glb;
    if (ext == ".3mf") return MeshFormat::ThreeMf;
    return std::nullopt;
}

std::optional<LengthUnit> lengthUnitFromName(std::string_view name) {
    if (name == "mm") return LengthUnit::Millimeter;
    if (name == "cm") return LengthUnit::Centimeter;
    if (name == "m") return LengthUnit::Meter;
    if (name == "inch") return LengthUnit::Inch;
    return std::nullopt;
}

double millimetres(LengthUnit unit) {
    switch (unit) {
    case LengthUnit::Millimeter:
        return 1.0;
    case LengthUnit::Centimeter:
        return 10.0;
    case LengthUnit::Meter:
        return 1000.0;
    case LengthUnit::Inch:
        return 25.4;
    }
    return 1.0;
}

std::string_view meshFormatName(MeshFormat format) {
    switch (format) {
    case MeshFormat::Ply:
        return "ply";
    case MeshFormat::Obj:
        return "obj";
    case MeshFormat::Stl:
        return "stl";
    case MeshFormat::Glb:
        return "glb";
    case MeshFormat::ThreeMf:
        return "3mf";
    }
    return "?";
}

bool formatHasTriangleColors(MeshFormat format) {
    return format == MeshFormat::Glb || format == MeshFormat::ThreeMf;
}

std::string encodeMesh(const Mesh& mesh, MeshFormat format, LengthUnit unit) {
    switch (format) {
    case MeshFormat::Ply:
        return encodePly(mesh);
    case MeshFormat::Obj:
        return encodeObj(mesh);
    case MeshFormat::Stl:
        return encodeStl(mesh);
    case MeshFormat::Glb:
        return encodeGlb(mesh);
    case MeshFormat::ThreeMf:
        return encodeThreeMf(mesh, unit);
    }
    return {};
}

Result<std::string> encodeMeshFile(const Mesh& mesh, const std::filesystem::path& path,
                                   MeshFormat format, LengthUnit unit) {
    if (auto problem = meshProblem(mesh))
        return Error::message(ErrorKind::Usage, path.string(),
                              "cannot write an inconsistent mesh: " + *problem);
    std::string bytes = encodeMesh(mesh, format, unit);
    if (bytes.empty())
        return Error::message(ErrorKind::Limit, path.string(),
                              "the mesh is too large for a 3MF file (its ZIP container holds "
                              "4 GiB); write .ply, or mesh at a lower resolution");
    return bytes;
}

Status writeMesh(const Mesh& mesh, const std::filesystem::path& path, MeshFormat format,
                 LengthUnit unit) {
    auto bytes = encodeMeshFile(mesh, path, format, unit);
    if (!bytes) return bytes.error();
    return writeFileAtomic(path, *bytes);
}

} // namespace sdfcsg
