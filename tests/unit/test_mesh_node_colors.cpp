// A mesh node's colours (engine/src/field/mesh_field.h): a file's vertex and material colours
// read, stored beside the field's samples and given at the surface by the CPU evaluator and the
// kernels alike, the node's colour where the file has none, and the colours of sdfcsg's own
// exported meshes read back.
#include "field/mesh_field.h"
#include "gpu_probe.h"
#include "io/zip.h"

#include <sdfcsg/export.h>
#include <sdfcsg/mesh.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace sdfcsg::test {
namespace {

const glm::vec3 kRed(1.0f, 0.0f, 0.0f), kBlue(0.0f, 0.0f, 1.0f);

// A file in the temporary folder, written for one test.
std::filesystem::path writeFile(const std::string& name, const std::string& text) {
    const std::filesystem::path path = std::filesystem::temp_directory_path() / name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
}

// The box [-1, 1] x [-0.5, 0.5] x [-0.5, 0.5] as two halves split at x = 0, its triangles
// counter-clockwise seen from outside: half 0 (x < 0) then half 1, without the face between them.
// Each triangle as its three corners.
std::vector<std::array<glm::vec3, 3>> twoHalves(int half) {
    const float lo = half == 0 ? -1.0f : 0.0f, hi = lo + 1.0f;
    const auto corner = [&](int i) { // x from bit 0, y from bit 1, z from bit 2
        return glm::vec3(i & 1 ? hi : lo, i & 2 ? 0.5f : -0.5f, i & 4 ? 0.5f : -0.5f);
    };
    const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                             {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    std::vector<std::array<glm::vec3, 3>> out;
    for (int q = 0; q < 6; ++q) {
        if (q == (half == 0 ? 1 : 0)) continue; // the face at x = 0
        const int* c = quads[q];
        out.push_back({corner(c[0]), corner(c[1]), corner(c[2])});
        out.push_back({corner(c[0]), corner(c[2]), corner(c[3])});
    }
    return out;
}

std::string number(float v) {
    return std::to_string(v);
}

// An ASCII PLY of the two halves, each triangle's corners of its half's colour (0-255).
std::string twoColorPly(glm::uvec3 left, glm::uvec3 right) {
    std::string vertices, faces;
    int count = 0;
    for (int half = 0; half < 2; ++half)
        for (const auto& t : twoHalves(half)) {
            const glm::uvec3 c = half == 0 ? left : right;
            for (const glm::vec3& p : t)
                vertices += number(p.x) + " " + number(p.y) + " " + number(p.z) + " " +
                            std::to_string(c.r) + " " + std::to_string(c.g) + " " +
                            std::to_string(c.b) + "\n";
            faces += "3 " + std::to_string(count) + " " + std::to_string(count + 1) + " " +
                     std::to_string(count + 2) + "\n";
            count += 3;
        }
    return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(count) +
           "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
           "property uchar green\nproperty uchar blue\nelement face " +
           std::to_string(count / 3) + "\nproperty list uchar int vertex_indices\nend_header\n" +
           vertices + faces;
}

// An OBJ of the two halves, with the materials "left" and "right" where `materials`, which its
// .mtl (`mtl`) gives.
std::string twoHalvesObj(const std::string& mtl, bool materials) {
    std::string obj = materials ? "mtllib " + mtl + "\n" : "";
    int count = 0;
    for (int half = 0; half < 2; ++half) {
        if (materials) obj += half == 0 ? "usemtl left\n" : "usemtl right\n";
        for (const auto& t : twoHalves(half)) {
            for (const glm::vec3& p : t)
                obj += "v " + number(p.x) + " " + number(p.y) + " " + number(p.z) + "\n";
            obj += "f " + std::to_string(count + 1) + " " + std::to_string(count + 2) + " " +
                   std::to_string(count + 3) + "\n";
            count += 3;
        }
    }
    return obj;
}

// A 3MF of the two halves, z up as the format is: each triangle of base material 0 (left) or 1
// (right) where `perTriangle`, else each corner of colour 0 or 1 of a colour group.
std::string twoColor3mf(const std::string& left, const std::string& right, bool perTriangle) {
    std::string vertices, triangles;
    int count = 0;
    for (int half = 0; half < 2; ++half)
        for (const auto& t : twoHalves(half)) {
            for (const glm::vec3& p : t) // (x, y, z) -> (x, -z, y)
                vertices += "<vertex x=\"" + number(p.x) + "\" y=\"" + number(-p.z) + "\" z=\"" +
                            number(p.y) + "\"/>\n";
            const std::string c = std::to_string(half);
            triangles += "<triangle v1=\"" + std::to_string(count) + "\" v2=\"" +
                         std::to_string(count + 1) + "\" v3=\"" + std::to_string(count + 2) +
                         "\" p1=\"" + c + (perTriangle ? "" : "\" p2=\"" + c + "\" p3=\"" + c) +
                         "\"/>\n";
            count += 3;
        }
    const std::string group = perTriangle
                                  ? "<basematerials id=\"1\"><base name=\"left\" displaycolor=\"" +
                                        left + "\"/><base name=\"right\" displaycolor=\"" + right +
                                        "\"/></basematerials>\n"
                                  : "<m:colorgroup id=\"1\"><m:color color=\"" + left +
                                        "\"/><m:color color=\"" + right + "\"/></m:colorgroup>\n";
    const std::string model =
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"centimeter\" "
        "xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\" "
        "xmlns:m=\"http://schemas.microsoft.com/3dmanufacturing/material/2015/"
        "02\">\n<resources>\n" +
        group + "<object id=\"2\" pid=\"1\" pindex=\"0\"><mesh><vertices>\n" + vertices +
        "</vertices><triangles>\n" + triangles +
        "</triangles></mesh></object>\n</resources>\n<build><item objectid=\"2\"/></build>\n"
        "</model>\n";
    const detail::ZipEntry entries[] = {{"3D/3dmodel.model", model}};
    return detail::zipArchive(entries).value();
}

Scene sceneFrom(const std::string& json) {
    auto scene = parseScene(json, "test.json");
    if (!scene) ADD_FAILURE() << scene.error().str();
    return scene ? *scene : Scene{};
}

// A scene of one mesh node reading `file`, of colour [0.3, 0.7, 0.2], with `extra` members.
Scene meshScene(const std::filesystem::path& file, const std::string& extra = "") {
    return sceneFrom(R"({"version": 1, "root": {"type": "mesh", "file": ")" + file.string() +
                     R"(", "resolution": 32, "color": [0.3, 0.7, 0.2])" + extra + "}}");
}
const glm::vec3 kNodeColor(0.3f, 0.7f, 0.2f);

// Points on the two halves' surface, away from the seam at x = 0 (half 0 first, then half 1),
// and from the edges.
std::vector<std::vector<glm::vec3>> surfacePoints(float size = 1.0f) {
    std::vector<std::vector<glm::vec3>> points(2);
    for (int half = 0; half < 2; ++half) {
        const float s = half == 0 ? -1.0f : 1.0f;
        for (float a : {-0.3f, 0.0f, 0.35f})
            for (float x : {0.3f, 0.6f, 0.85f}) {
                points[size_t(half)].push_back(size * glm::vec3(s * x, 0.5f, a));
                points[size_t(half)].push_back(size * glm::vec3(s * x, -0.5f, a));
                points[size_t(half)].push_back(size * glm::vec3(s * x, a, 0.5f));
                points[size_t(half)].push_back(size * glm::vec3(s * x, a, -0.5f));
            }
        for (float a : {-0.3f, 0.0f, 0.3f})
            points[size_t(half)].push_back(size * glm::vec3(s, a, 0.2f));
    }
    return points;
}

void expectColors(const Evaluator& ev, glm::vec3 left, glm::vec3 right, float tolerance) {
    const auto points = surfacePoints();
    for (int half = 0; half < 2; ++half)
        for (const glm::vec3& p : points[size_t(half)]) {
            const Sample s = ev.sample(p);
            const glm::vec3 want = half == 0 ? left : right;
            EXPECT_LT(std::abs(s.distance), 0.05f) << p.x << " " << p.y << " " << p.z;
            EXPECT_LE(glm::length(s.color - want), tolerance)
                << "at " << p.x << " " << p.y << " " << p.z << ": " << s.color.r << " " << s.color.g
                << " " << s.color.b;
        }
}

// A PLY's vertex colours: each half its own, exactly (8-bit colours are stored as they are).
TEST(MeshNodeColors, PlyVertexColoursAreTheSurfaces) {
    const auto file = writeFile("mesh_colors_halves.ply",
                                twoColorPly(glm::uvec3(255, 0, 0), glm::uvec3(0, 0, 255)));
    std::ifstream in(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    auto mesh = detail::readTriangleMesh(bytes, ".ply");
    ASSERT_TRUE(mesh) << mesh.error().str();
    ASSERT_EQ(mesh->colors.size(), 3 * mesh->triangles.size());
    EXPECT_FALSE(detail::meshDefects(*mesh).any()); // the halves' corners are one vertex
    auto field = detail::MeshField::make(*mesh, 32);
    ASSERT_TRUE(field) << field.error().str();
    EXPECT_TRUE(field->hasColors());
    EXPECT_EQ(field->color(glm::vec3(-0.5f, 0.5f, 0.0f), kNodeColor), kRed);
    EXPECT_EQ(field->color(glm::vec3(0.5f, 0.5f, 0.0f), kNodeColor), kBlue);
    EXPECT_EQ(field->color(glm::vec3(9.0f), kNodeColor), kNodeColor); // beyond the grid

    const Evaluator ev(meshScene(file));
    ASSERT_EQ(ev.nodes().size(), 1u);
    EXPECT_TRUE(ev.nodes()[0].ownColors);
    expectColors(ev, kRed, kBlue, 0.0f);
    // Where the field has no samples, the node's colour.
    EXPECT_EQ(ev.sample(glm::vec3(0.0f, 0.0f, 0.0f)).color, kNodeColor);
}

// A 3MF's base materials, one per triangle, and its colour group's colours, per corner (sRGB, as
// 3MF's are; the alpha of #RRGGBBAA left out): each half its own, exactly.
TEST(MeshNodeColors, ThreeMfColoursAreTheSurfaces) {
    for (const bool perTriangle : {true, false}) {
        SCOPED_TRACE(perTriangle ? "base materials" : "colour group");
        const auto file =
            writeFile("mesh_colors_halves.3mf", twoColor3mf("#E6280A", "#145AFA80", perTriangle));
        const Evaluator ev(meshScene(file));
        ASSERT_EQ(ev.nodes().size(), 1u);
        EXPECT_TRUE(ev.nodes()[0].ownColors);
        expectColors(ev, glm::vec3(230, 40, 10) / 255.0f, glm::vec3(20, 90, 250) / 255.0f, 1e-6f);
    }
}

// An OBJ's materials, from the .mtl beside it; the node's colour where it has none, and the
// code then calls no colour formula.
TEST(MeshNodeColors, ObjMaterialColoursAreTheSurfaces) {
    writeFile("mesh_colors_halves.mtl",
              "newmtl left\nKd 0.8 0.4 0.2\nnewmtl right\nKd 0.1 0.5 0.9\n");
    const auto file =
        writeFile("mesh_colors_halves.obj", twoHalvesObj("mesh_colors_halves.mtl", true));
    const Evaluator ev(meshScene(file));
    EXPECT_TRUE(ev.nodes()[0].ownColors);
    expectColors(ev, {0.8f, 0.4f, 0.2f}, {0.1f, 0.5f, 0.9f}, 1.0f / 255.0f); // 8 bits

    const auto plain = writeFile("mesh_colors_plain.obj", twoHalvesObj("", false));
    const Scene scene = meshScene(plain);
    const Evaluator uncolored(scene);
    EXPECT_FALSE(uncolored.nodes()[0].ownColors);
    expectColors(uncolored, kNodeColor, kNodeColor, 0.0f);
    for (bool inlined : {false, true}) {
        CodegenOptions options;
        options.inlineParams = inlined;
        EXPECT_EQ(generateSceneGlsl(scene, options).find("olorMesh"), std::string::npos);
        EXPECT_EQ(generateSceneGlsl(scene, options).find("meshColor"), std::string::npos);
    }
    // A material that its .mtl does not define (Assimp gives it its default grey) is none: the
    // node's colour.
    writeFile("mesh_colors_other.mtl", "newmtl other\nKd 1 1 0\n");
    const auto missing =
        writeFile("mesh_colors_missing.obj", twoHalvesObj("mesh_colors_other.mtl", true));
    expectColors(Evaluator(meshScene(missing)), kNodeColor, kNodeColor, 0.0f);
}

// A coloured mesh node, moved, turned and scaled, beside a sphere: the kernels' colours (values
// read from the node buffer, inlined, and on tapes) are the CPU's.
class MeshNodeColorsGpu : public GpuTest {};

TEST_F(MeshNodeColorsGpu, KernelsGiveTheCpusColours) {
    const auto file = writeFile("mesh_colors_gpu.ply",
                                twoColorPly(glm::uvec3(230, 40, 10), glm::uvec3(20, 90, 250)));
    const Scene scene = sceneFrom(R"({"version": 1, "root": {"type": "union", "children": [
        {"type": "mesh", "file": ")" +
                                  file.string() +
                                  R"(", "resolution": 32, "translate": [0.2, 0.1, 0],
         "rotate": [10, 30, 0], "scale": 1.3, "color": [0.3, 0.7, 0.2]},
        {"type": "sphere", "radius": 0.4, "translate": [0, 1, 0], "color": [0.9, 0.9, 0.1]}]}})");
    ASSERT_FALSE(scene.nodes.empty());
    expectGpuMatchesCpu(context(), scene);
    // The same with values inlined: the colour formula's call written out with literals.
    CodegenOptions options;
    options.inlineParams = true;
    const std::string glsl = generateSceneGlsl(scene, options);
    EXPECT_NE(glsl.find("colorMesh("), std::string::npos);
    Evaluator ev(scene);
    const std::vector<glm::vec4> points = samplePoints(ev, 1024, 7);
    const Probe inlined{"values inlined", true, true, false, false, true};
    const std::vector<glm::vec4> gpu = probeGpu(context(), scene, points, inlined);
    ASSERT_EQ(gpu.size(), points.size());
    size_t badColour = 0, colored = 0;
    for (size_t i = 0; i < points.size(); ++i) {
        const Sample cpu = ev.sample(glm::vec3(points[i]));
        colored += cpu.color != kNodeColor && cpu.color != glm::vec3(0.9f, 0.9f, 0.1f);
        badColour += glm::length(glm::vec3(gpu[i]) - cpu.color) > 1e-3f;
    }
    EXPECT_GT(colored, points.size() / 10); // points on the mesh's surface take its colours
    EXPECT_LE(badColour, points.size() / 500);
}

// Scene -> mesh (PLY with vertex colours, GLB with linear vertex colours or a material per
// colour, 3MF with a colour group or a base material per colour) -> mesh node: each box keeps its
// colour. A GLB or 3MF without colours (a GLB's triangles take Assimp's default material) takes
// the node's.
TEST_F(MeshNodeColorsGpu, ExportedColoursReadBack) {
    const Scene scene = sceneFrom(R"({"version": 1, "root": {"type": "union", "children": [
        {"type": "box", "size": [1, 1, 1], "translate": [-0.5, 0, 0], "color": [0.8, 0.4, 0.2]},
        {"type": "box", "size": [1, 1, 1], "translate": [0.5, 0, 0], "color": [0.1, 0.5, 0.9]}]}})");
    const struct {
        MeshFormat format;
        bool regions, colors;
    } cases[] = {{MeshFormat::Ply, false, true},     {MeshFormat::Glb, false, true},
                 {MeshFormat::Glb, true, true},      {MeshFormat::Glb, false, false},
                 {MeshFormat::ThreeMf, false, true}, {MeshFormat::ThreeMf, true, true},
                 {MeshFormat::ThreeMf, false, false}};
    for (const auto& c : cases) {
        SCOPED_TRACE(std::string(meshFormatName(c.format)) + (c.regions ? " regions" : "") +
                     (c.colors ? "" : " without colours"));
        MeshOptions options;
        options.resolution = 48;
        options.colorRegions = c.regions;
        auto mesh = extractMesh(context(), scene, options);
        ASSERT_TRUE(mesh) << mesh.error().str();
        if (!c.colors) mesh->colors.clear();
        const auto file = writeFile("mesh_colors_round." + std::string(meshFormatName(c.format)),
                                    encodeMesh(*mesh, c.format));
        const Evaluator ev(meshScene(file));
        ASSERT_FALSE(ev.nodes().empty());
        EXPECT_EQ(ev.nodes()[0].ownColors, c.colors);
        if (c.colors)
            expectColors(ev, {0.8f, 0.4f, 0.2f}, {0.1f, 0.5f, 0.9f}, 1.0f / 255.0f);
        else
            expectColors(ev, kNodeColor, kNodeColor, 0.0f);
    }
}

} // namespace
} // namespace sdfcsg::test
