// The mesh exporters: every format read back by an independent reader (mesh_readers.h) with the
// same counts and values, the binary layouts the specifications require, atomic writes, and the
// .glb accepted by the Khronos glTF-Validator when node and npm can provide it.
#include "mesh_readers.h"

#include <sdfcsg/sdfcsg.h>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace sdfcsg::test {
namespace {

namespace fs = std::filesystem;

// An axis-aligned box with 8 shared corners, 12 triangles counter-clockwise seen from outside,
// normals pointing away from its centre and a different colour per corner. The extents are not
// exact binary fractions, so accessor bounds must be written with all their digits.
Mesh boxMesh() {
    const glm::vec3 lo(-0.5f, -0.1f, 0.3f), hi(0.7f, 1.3f, 2.1f);
    const glm::vec3 centre = 0.5f * (lo + hi);
    Mesh mesh;
    for (uint32_t i = 0; i < 8; ++i) {
        glm::vec3 p(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
        mesh.positions.push_back(p);
        mesh.normals.push_back(glm::normalize(p - centre));
        mesh.colors.push_back({float(i & 1), 0.5f, 0.02f + 0.1f * float(i)});
    }
    for (int axis = 0; axis < 3; ++axis)
        for (uint32_t side = 0; side < 2; ++side) {
            const uint32_t a = 1u << ((axis + 1) % 3), b = 1u << ((axis + 2) % 3);
            const uint32_t base = side << axis;
            uint32_t quad[4] = {base, base | a, base | a | b, base | b};
            glm::vec3 outward(0.0f);
            outward[axis] = side ? 1.0f : -1.0f;
            const glm::vec3 n = glm::cross(mesh.positions[quad[1]] - mesh.positions[quad[0]],
                                           mesh.positions[quad[2]] - mesh.positions[quad[0]]);
            if (glm::dot(n, outward) < 0) std::swap(quad[1], quad[3]);
            mesh.indices.insert(mesh.indices.end(),
                                {quad[0], quad[1], quad[2], quad[0], quad[2], quad[3]});
        }
    return mesh;
}

// The same box with positions and indices only.
Mesh bareBoxMesh() {
    Mesh mesh = boxMesh();
    mesh.normals.clear();
    mesh.colors.clear();
    return mesh;
}

float srgbToLinear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

fs::path outputDir(const std::string& name) {
    fs::path dir = fs::path(SDFCSG_TEST_OUTPUT_DIR) / "export" / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string readFile(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

TEST(Export, FormatFromPath) {
    EXPECT_EQ(meshFormatFromPath("a/b.ply"), MeshFormat::Ply);
    EXPECT_EQ(meshFormatFromPath("b.OBJ"), MeshFormat::Obj);
    EXPECT_EQ(meshFormatFromPath("b.Stl"), MeshFormat::Stl);
    EXPECT_EQ(meshFormatFromPath("b.glb"), MeshFormat::Glb);
    EXPECT_EQ(meshFormatFromPath("b.3MF"), MeshFormat::ThreeMf);
    EXPECT_EQ(meshFormatFromPath("b.gltf"), std::nullopt);
    EXPECT_EQ(meshFormatFromPath("ply"), std::nullopt);
    EXPECT_EQ(meshFormatFromPath("b.ply.txt"), std::nullopt);
    for (MeshFormat f :
         {MeshFormat::Ply, MeshFormat::Obj, MeshFormat::Stl, MeshFormat::Glb, MeshFormat::ThreeMf})
        EXPECT_EQ(meshFormatFromPath("x." + std::string(meshFormatName(f))), f);
}

// 3MF's reading back is tests/cli/read_3mf.py, by Python's ZIP and XML readers; here, what the
// package holds in plain text: its parts' names and a ZIP end record that counts 3.
TEST(Export, ThreeMfIsAZipOfThreeParts) {
    EXPECT_EQ(lengthUnitFromName("mm"), LengthUnit::Millimeter);
    EXPECT_EQ(lengthUnitFromName("inch"), LengthUnit::Inch);
    EXPECT_EQ(lengthUnitFromName("in"), std::nullopt);
    const std::string bytes = encodeMesh(boxMesh(), MeshFormat::ThreeMf, LengthUnit::Inch);
    ASSERT_GT(bytes.size(), 22u);
    EXPECT_EQ(bytes.substr(0, 4), std::string("PK\x03\x04", 4));
    for (const char* name : {"[Content_Types].xml", "_rels/.rels", "3D/3dmodel.model"})
        EXPECT_NE(bytes.find(name), std::string::npos) << name;
    const std::string end = bytes.substr(bytes.size() - 22);
    EXPECT_EQ(end.substr(0, 4), std::string("PK\x05\x06", 4));
    EXPECT_EQ(uint8_t(end[10]), 3u); // entries
}

TEST(Export, PlyRoundTrips) {
    const Mesh mesh = boxMesh();
    const std::string bytes = encodeMesh(mesh, MeshFormat::Ply);
    EXPECT_EQ(bytes.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
    PlyData ply = readPly(bytes);
    ASSERT_EQ(ply.error, "");
    EXPECT_EQ(ply.vertexProperties,
              (std::vector<std::string>{"float x", "float y", "float z", "float nx", "float ny",
                                        "float nz", "uchar red", "uchar green", "uchar blue"}));
    EXPECT_EQ(ply.positions, mesh.positions);
    EXPECT_EQ(ply.normals, mesh.normals);
    EXPECT_EQ(ply.indices, mesh.indices);
    ASSERT_EQ(ply.colors.size(), mesh.colors.size());
    for (size_t i = 0; i < mesh.colors.size(); ++i)
        for (int c = 0; c < 3; ++c) // one byte per channel, rounded to nearest
            EXPECT_NEAR(ply.colors[i][c], mesh.colors[i][c], 0.5f / 255.0f + 1e-6f);
}

TEST(Export, ObjRoundTrips) {
    const Mesh mesh = boxMesh();
    ObjData obj = readObj(encodeMesh(mesh, MeshFormat::Obj));
    ASSERT_EQ(obj.error, "");
    // Floats are written in their shortest round-trip form, so values come back exactly.
    EXPECT_EQ(obj.positions, mesh.positions);
    EXPECT_EQ(obj.normals, mesh.normals);
    EXPECT_EQ(obj.colors, mesh.colors);
    EXPECT_EQ(obj.indices, mesh.indices);
    ASSERT_FALSE(obj.faceLines.empty());
    const uint32_t a = mesh.indices[0] + 1, b = mesh.indices[1] + 1, c = mesh.indices[2] + 1;
    EXPECT_EQ(obj.faceLines[0], "f " + std::to_string(a) + "//" + std::to_string(a) + " " +
                                    std::to_string(b) + "//" + std::to_string(b) + " " +
                                    std::to_string(c) + "//" + std::to_string(c));
}

TEST(Export, StlRoundTripsWithFacetNormalsFromTheWinding) {
    const Mesh mesh = boxMesh();
    StlData stl = readStl(encodeMesh(mesh, MeshFormat::Stl));
    ASSERT_EQ(stl.error, "");
    EXPECT_NE(stl.header.find("sdfcsg"), std::string::npos);
    EXPECT_NE(stl.header.rfind("solid", 0), 0u) << "a binary STL header must not start 'solid'";
    ASSERT_EQ(stl.facetNormals.size(), mesh.triangleCount());
    ASSERT_EQ(stl.corners.size(), mesh.indices.size());
    // z up, as slicers build: the scene's y is z, its z is -y.
    for (size_t i = 0; i < mesh.indices.size(); ++i) {
        const glm::vec3 p = mesh.positions[mesh.indices[i]];
        EXPECT_EQ(stl.corners[i], glm::vec3(p.x, -p.z, p.y)) << "corner " << i;
    }
    const glm::vec3 centre(0.1f, -1.2f, 0.6f); // the box's (0.1, 0.6, 1.2), turned
    for (size_t t = 0; t < stl.facetNormals.size(); ++t) {
        const glm::vec3 n = stl.facetNormals[t];
        EXPECT_NEAR(glm::length(n), 1.0f, 1e-6f);
        // Each facet of the box is perpendicular to one axis, facing away from the centre.
        const glm::vec3 faceCentre = (stl.corners[3 * t] + stl.corners[3 * t + 2]) * 0.5f;
        EXPECT_GT(glm::dot(n, faceCentre - centre), 0.0f) << "facet " << t << " faces inward";
        EXPECT_NEAR(std::max({std::abs(n.x), std::abs(n.y), std::abs(n.z)}), 1.0f, 1e-6f);
        EXPECT_EQ(stl.attributes[t], 0);
    }
}

TEST(Export, GlbRoundTripsWithLinearColours) {
    const Mesh mesh = boxMesh();
    GlbData glb = readGlb(encodeMesh(mesh, MeshFormat::Glb));
    ASSERT_EQ(glb.error, "");
    EXPECT_EQ(glb.attributes, (std::vector<std::string>{"POSITION", "NORMAL", "COLOR_0"}));
    EXPECT_EQ(glb.positions, mesh.positions);
    EXPECT_EQ(glb.normals, mesh.normals);
    EXPECT_EQ(glb.indices, mesh.indices);
    ASSERT_EQ(glb.colors.size(), mesh.colors.size());
    for (size_t i = 0; i < mesh.colors.size(); ++i)
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(glb.colors[i][c], srgbToLinear(mesh.colors[i][c]), 1e-6f);
    // Mid grey: 0.5 as written is about 0.214 in linear light.
    EXPECT_NEAR(glb.colors[0][1], 0.21404f, 1e-5f);
}

// With triangle colours: one primitive per colour on the shared vertices, each triangle once with
// its colour as its material's base colour (linear), and no COLOR_0.
TEST(Export, GlbHasOnePrimitivePerTriangleColour) {
    Mesh mesh = boxMesh();
    const glm::vec3 palette[3] = {{1.0f, 0.2f, 0.0f}, {0.0f, 0.6f, 1.0f}, {0.4f, 0.4f, 0.4f}};
    for (size_t t = 0; t < mesh.triangleCount(); ++t)
        mesh.triangleColors.push_back(palette[(t / 2) % 3]); // each face one colour
    GlbData glb = readGlb(encodeMesh(mesh, MeshFormat::Glb));
    ASSERT_EQ(glb.error, "");
    EXPECT_EQ(glb.attributes, (std::vector<std::string>{"POSITION", "NORMAL"}));
    EXPECT_EQ(glb.positions, mesh.positions);
    EXPECT_EQ(glb.primitives, 3u);
    ASSERT_EQ(glb.indices.size(), mesh.indices.size());
    ASSERT_EQ(glb.triangleColors.size(), mesh.triangleCount());
    std::vector<bool> found(mesh.triangleCount(), false);
    for (size_t t = 0; t < glb.triangleColors.size(); ++t) {
        size_t match = mesh.triangleCount();
        for (size_t u = 0; u < mesh.triangleCount(); ++u)
            if (!found[u] &&
                std::equal(&glb.indices[3 * t], &glb.indices[3 * t] + 3, &mesh.indices[3 * u]))
                match = u;
        ASSERT_LT(match, mesh.triangleCount()) << "triangle " << t;
        found[match] = true;
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(glb.triangleColors[t][c], srgbToLinear(mesh.triangleColors[match][c]),
                        1e-6f);
    }
}

TEST(Export, GlbStructure) {
    const Mesh mesh = boxMesh();
    const std::string bytes = encodeMesh(mesh, MeshFormat::Glb);
    GlbData glb = readGlb(bytes);
    ASSERT_EQ(glb.error, "");
    EXPECT_EQ(glb.magic, 0x46546C67u);
    EXPECT_EQ(glb.version, 2u);
    EXPECT_EQ(glb.length, bytes.size());
    ASSERT_EQ(glb.chunks.size(), 2u);
    EXPECT_EQ(glb.chunks[0].offset, 20u);
    for (const GlbChunk& chunk : glb.chunks) {
        EXPECT_EQ(chunk.length % 4, 0u);
        EXPECT_EQ(chunk.offset % 4, 0u);
    }
    // JSON padded with spaces, BIN with zeros.
    const size_t jsonEnd = glb.jsonText.find_last_not_of(' ');
    EXPECT_EQ(glb.jsonText[jsonEnd], '}');
    EXPECT_LT(glb.jsonText.size() - jsonEnd - 1, 4u);

    const Json& json = glb.json;
    ASSERT_NE(json.get("asset"), nullptr);
    EXPECT_EQ(json.get("asset")->get("version")->string, "2.0");
    EXPECT_EQ(json.get("asset")->get("generator")->string, "sdfcsg");
    ASSERT_NE(json.get("buffers"), nullptr);
    ASSERT_EQ(json.get("buffers")->array.size(), 1u);
    const size_t byteLength = size_t(json.get("buffers")->at(0)->get("byteLength")->number);
    EXPECT_EQ(byteLength, mesh.vertexCount() * 36 + mesh.indices.size() * 4);
    EXPECT_EQ(glb.bin.size(), (byteLength + 3) & ~size_t(3));
    EXPECT_EQ(glb.bin.find_first_not_of('\0', byteLength), std::string::npos);
    for (const Json& view : json.get("bufferViews")->array)
        EXPECT_EQ(size_t(view.get("byteOffset")->number) % 4, 0u);

    const Json* primitive = json.get("meshes")->at(0)->get("primitives")->at(0);
    EXPECT_EQ(primitive->get("mode")->number, 4); // triangles
    auto accessor = [&](const Json* index) {
        return json.get("accessors")->at(size_t(index->number));
    };
    // POSITION's bounds equal the data's exactly, read as doubles.
    const Json* position = accessor(primitive->get("attributes")->get("POSITION"));
    glm::vec3 lo = mesh.positions[0], hi = mesh.positions[0];
    for (glm::vec3 p : mesh.positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    ASSERT_NE(position->get("min"), nullptr);
    ASSERT_NE(position->get("max"), nullptr);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(position->get("min")->at(c)->number, double(lo[c])) << "axis " << c;
        EXPECT_EQ(position->get("max")->at(c)->number, double(hi[c])) << "axis " << c;
    }
    const Json* indices = accessor(primitive->get("indices"));
    EXPECT_EQ(indices->get("componentType")->number, 5125); // UNSIGNED_INT
    EXPECT_EQ(indices->get("type")->string, "SCALAR");
    EXPECT_EQ(indices->get("count")->number, double(mesh.indices.size()));
    EXPECT_EQ(indices->get("min")->at(0)->number, 0.0);
    EXPECT_EQ(indices->get("max")->at(0)->number, 7.0);
}

TEST(Export, MeshWithoutNormalsOrColours) {
    const Mesh mesh = bareBoxMesh();
    PlyData ply = readPly(encodeMesh(mesh, MeshFormat::Ply));
    ASSERT_EQ(ply.error, "");
    EXPECT_EQ(ply.vertexProperties, (std::vector<std::string>{"float x", "float y", "float z"}));
    EXPECT_EQ(ply.positions, mesh.positions);
    EXPECT_EQ(ply.indices, mesh.indices);

    ObjData obj = readObj(encodeMesh(mesh, MeshFormat::Obj));
    ASSERT_EQ(obj.error, "");
    EXPECT_TRUE(obj.normals.empty());
    EXPECT_TRUE(obj.colors.empty());
    EXPECT_EQ(obj.positions, mesh.positions);
    EXPECT_EQ(obj.indices, mesh.indices);
    EXPECT_EQ(obj.faceLines[0].find('/'), std::string::npos);

    GlbData glb = readGlb(encodeMesh(mesh, MeshFormat::Glb));
    ASSERT_EQ(glb.error, "");
    EXPECT_EQ(glb.attributes, std::vector<std::string>{"POSITION"});
    EXPECT_EQ(glb.positions, mesh.positions);
    EXPECT_EQ(glb.indices, mesh.indices);
}

TEST(Export, EmptyMeshGivesValidFiles) {
    const Mesh mesh;
    PlyData ply = readPly(encodeMesh(mesh, MeshFormat::Ply));
    EXPECT_EQ(ply.error, "");
    EXPECT_TRUE(ply.positions.empty());
    EXPECT_TRUE(ply.indices.empty());

    ObjData obj = readObj(encodeMesh(mesh, MeshFormat::Obj));
    EXPECT_EQ(obj.error, "");
    EXPECT_TRUE(obj.positions.empty());

    const std::string stlBytes = encodeMesh(mesh, MeshFormat::Stl);
    EXPECT_EQ(stlBytes.size(), 84u);
    StlData stl = readStl(stlBytes);
    EXPECT_EQ(stl.error, "");
    EXPECT_TRUE(stl.corners.empty());

    // glTF allows no empty buffers or accessors: a scene without nodes and no BIN chunk.
    const std::string glbBytes = encodeMesh(mesh, MeshFormat::Glb);
    GlbData glb = readGlb(glbBytes);
    ASSERT_EQ(glb.error, "");
    EXPECT_EQ(glb.length, glbBytes.size());
    ASSERT_EQ(glb.chunks.size(), 1u);
    EXPECT_EQ(glb.chunks[0].length % 4, 0u);
    EXPECT_EQ(glb.json.get("asset")->get("generator")->string, "sdfcsg");
    EXPECT_EQ(glb.json.get("meshes"), nullptr);
    EXPECT_EQ(glb.json.get("buffers"), nullptr);
    ASSERT_NE(glb.json.get("scenes"), nullptr);
    EXPECT_EQ(glb.json.get("scenes")->array.size(), 1u);
}

TEST(Export, WriteMeshIsAtomicAndLeavesNoTemporary) {
    const fs::path dir = outputDir("atomic");
    const Mesh mesh = boxMesh();
    for (MeshFormat format : {MeshFormat::Ply, MeshFormat::Obj, MeshFormat::Stl, MeshFormat::Glb}) {
        const fs::path path = dir / ("box." + std::string(meshFormatName(format)));
        auto written = writeMesh(mesh, path, format);
        ASSERT_TRUE(written) << written.error().str();
        EXPECT_EQ(readFile(path), encodeMesh(mesh, format));
        // Overwriting replaces the file whole.
        written = writeMesh(Mesh{}, path, format);
        ASSERT_TRUE(written) << written.error().str();
        EXPECT_EQ(readFile(path), encodeMesh(Mesh{}, format));
    }
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir))
        names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names, (std::vector<std::string>{"box.glb", "box.obj", "box.ply", "box.stl"}));
}

TEST(Export, UnwritablePathGivesIoErrorNamingIt) {
    const fs::path dir = outputDir("unwritable");
    const fs::path path = dir / "no" / "such" / "dir" / "box.ply";
    auto written = writeMesh(boxMesh(), path, MeshFormat::Ply);
    ASSERT_FALSE(written);
    EXPECT_EQ(written.error().kind, ErrorKind::Io);
    EXPECT_EQ(written.error().str(),
              path.string() + ": the folder " + path.parent_path().string() + " does not exist");
    EXPECT_TRUE(fs::is_empty(dir));
}

TEST(Export, InconsistentMeshIsRefused) {
    const fs::path dir = outputDir("inconsistent");
    const fs::path path = dir / "bad.glb";
    Mesh mesh = boxMesh();
    mesh.indices.back() = 8;
    auto written = writeMesh(mesh, path, MeshFormat::Glb);
    ASSERT_FALSE(written);
    EXPECT_EQ(written.error().kind, ErrorKind::Usage);
    EXPECT_EQ(written.error().str(), path.string() +
                                         ": cannot write an inconsistent mesh: index 35 is 8, "
                                         "but there are 8 vertices");
    mesh = boxMesh();
    mesh.colors.pop_back();
    written = writeMesh(mesh, path, MeshFormat::Ply);
    ASSERT_FALSE(written);
    EXPECT_EQ(written.error().str(),
              path.string() + ": cannot write an inconsistent mesh: 7 colours for 8 vertices");
    mesh = boxMesh();
    mesh.indices.pop_back();
    written = writeMesh(mesh, path, MeshFormat::Stl);
    ASSERT_FALSE(written);
    EXPECT_EQ(written.error().str(),
              path.string() +
                  ": cannot write an inconsistent mesh: 35 indices is not a whole number of "
                  "triangles");
    EXPECT_TRUE(fs::is_empty(dir));
}

// ---- The Khronos glTF-Validator (npm package gltf-validator, run with node) ----

// Standard output of a shell command, or nullopt when it fails.
std::optional<std::string> capture(const std::string& command) {
    FILE* pipe = ::popen(command.c_str(), "r");
    if (!pipe) return std::nullopt;
    std::string out;
    char buf[4096];
    for (size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;)
        out.append(buf, n);
    return ::pclose(pipe) == 0 ? std::optional(out) : std::nullopt;
}

bool haveCommand(const std::string& name) {
    return std::system(("command -v " + name + " >/dev/null 2>&1").c_str()) == 0;
}

// Prints one JSON object per file: its error, warning and info counts and every message.
constexpr const char* kValidateScript = R"(
const validator = require(process.argv[2]);
const fs = require('fs');
(async () => {
  const results = [];
  for (const file of process.argv.slice(3)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)));
    const issues = report.issues;
    results.push({file, errors: issues.numErrors, warnings: issues.numWarnings,
                  infos: issues.numInfos,
                  messages: issues.messages.map(m =>
                    `severity ${m.severity} ${m.code} ${m.pointer || ''}: ${m.message}`)});
  }
  console.log(JSON.stringify(results));
})().catch(e => { console.error(String(e)); process.exit(1); });
)";

TEST(Export, GlbPassesTheKhronosValidator) {
    if (!haveCommand("node") || !haveCommand("npm"))
        GTEST_SKIP() << "node and npm are needed to run the Khronos glTF-Validator "
                        "(npm package gltf-validator); not found on PATH";
    // Installed once into the build tree and reused by later runs.
    const fs::path npmDir = fs::path(SDFCSG_TEST_OUTPUT_DIR).parent_path() / "npm";
    const fs::path module = npmDir / "node_modules" / "gltf-validator";
    if (!fs::exists(module / "package.json")) {
        fs::create_directories(npmDir);
        const fs::path log = npmDir / "install.log";
        const std::string install = "npm install --prefix '" + npmDir.string() +
                                    "' --no-audit --no-fund --loglevel=error "
                                    "--fetch-retries=1 --fetch-timeout=30000 gltf-validator >'" +
                                    log.string() + "' 2>&1";
        if (std::system(install.c_str()) != 0 || !fs::exists(module / "package.json"))
            GTEST_SKIP() << "could not install the npm package gltf-validator (offline?); "
                            "see "
                         << log.string();
    }

    const fs::path dir = outputDir("validator");
    const fs::path script = dir / "validate.js";
    std::ofstream(script) << kValidateScript;
    struct Case {
        const char* name;
        Mesh mesh;
    };
    const Case cases[] = {{"box.glb", boxMesh()}, {"bare.glb", bareBoxMesh()}, {"empty.glb", {}}};
    std::string files;
    for (const Case& c : cases) {
        auto written = writeMesh(c.mesh, dir / c.name, MeshFormat::Glb);
        ASSERT_TRUE(written) << written.error().str();
        files += " '" + (dir / c.name).string() + "'";
    }
    auto output = capture("node '" + script.string() + "' '" + module.string() + "'" + files);
    ASSERT_TRUE(output) << "the validator did not run";
    std::string error;
    auto report = parseJson(*output, &error);
    ASSERT_TRUE(report) << error << " in: " << *output;
    ASSERT_EQ(report->array.size(), std::size(cases));
    for (const Json& result : report->array) {
        std::string messages;
        for (const Json& m : result.get("messages")->array)
            messages += "\n  " + m.string;
        const std::string file = result.get("file")->string;
        EXPECT_EQ(result.get("errors")->number, 0) << file << messages;
        EXPECT_EQ(result.get("warnings")->number, 0) << file << messages;
        if (!messages.empty()) std::printf("%s:%s\n", file.c_str(), messages.c_str());
    }
}

} // namespace
} // namespace sdfcsg::test
