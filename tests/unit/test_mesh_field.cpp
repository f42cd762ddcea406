// Mesh files read into triangles, and the signed distance field made from them
// (engine/src/field/mesh_field.h): against an analytic sphere, with holes and flipped triangles,
// and with hostile files.
#include "field/mesh_field.h"
#include "field/read_3mf.h"
#include "io/zip.h"

#include <sdfcsg/eval.h>
#include <sdfcsg/export.h>
#include <sdfcsg/mesh.h>
#include <sdfcsg/scene.h>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <string>
#include <vector>

namespace sdfcsg::detail {
namespace {

// A unit sphere: an icosahedron, each triangle split in four `levels` times, pushed onto it.
Mesh icosphere(int levels) {
    const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
    Mesh m;
    m.positions = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                   {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    m.indices = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                 4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
                 6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
    for (glm::vec3& p : m.positions)
        p = glm::normalize(p);
    for (int l = 0; l < levels; ++l) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> middles;
        auto middle = [&](uint32_t a, uint32_t b) {
            const auto key = std::minmax(a, b);
            auto [it, added] = middles.try_emplace(key, uint32_t(m.positions.size()));
            if (added) m.positions.push_back(glm::normalize(m.positions[a] + m.positions[b]));
            return it->second;
        };
        std::vector<uint32_t> next;
        for (size_t i = 0; i < m.indices.size(); i += 3) {
            const uint32_t a = m.indices[i], b = m.indices[i + 1], c = m.indices[i + 2];
            const uint32_t ab = middle(a, b), bc = middle(b, c), ca = middle(c, a);
            next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
        }
        m.indices = std::move(next);
    }
    m.normals = m.positions;
    return m;
}

TriangleMesh triangles(const Mesh& m) {
    TriangleMesh t;
    t.positions = m.positions;
    for (size_t i = 0; i < m.indices.size(); i += 3)
        t.triangles.push_back({m.indices[i], m.indices[i + 1], m.indices[i + 2]});
    return t;
}

std::vector<glm::vec3> randomPoints(uint32_t seed, int count, float reach) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-reach, reach);
    std::vector<glm::vec3> points(count);
    for (glm::vec3& p : points)
        p = {u(rng), u(rng), u(rng)};
    return points;
}

// A binary STL of `count` claimed triangles followed by `mesh`'s.
std::string binaryStl(const TriangleMesh& mesh, uint32_t count) {
    std::string s(80, ' ');
    s.append(reinterpret_cast<const char*>(&count), 4);
    for (const glm::uvec3& t : mesh.triangles) {
        float record[12] = {};
        for (int c = 0; c < 3; ++c)
            std::memcpy(record + 3 + 3 * c, &mesh.positions[t[c]], 12);
        s.append(reinterpret_cast<const char*>(record), sizeof record);
        s.append(2, '\0');
    }
    return s;
}

// A 3MF package of `model`, its model part where _rels/.rels says (`part`).
std::string threeMf(const std::string& model, const std::string& part = "3D/3dmodel.model") {
    const std::string rels =
        R"(<?xml version="1.0" encoding="UTF-8"?>
<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">
 <Relationship Target="/)" +
        part +
        R"(" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>
</Relationships>)";
    const ZipEntry entries[] = {{"_rels/.rels", rels}, {part, model}};
    return zipArchive(entries).value();
}

// A model of `resources` and `build`, all on line 1, in `unit`: by default centimetres, one unit
// of a scene (as sdfcsg writes 3MF), so that its coordinates are read as they are; `more`, more
// attributes of its model element.
std::string modelXml(const std::string& resources, const std::string& build,
                     const std::string& unit = "centimeter", const std::string& more = "") {
    return R"(<?xml version="1.0" encoding="UTF-8"?><model unit=")" + unit + "\" " + more +
           R"(xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02" )"
           R"(xmlns:m="http://schemas.microsoft.com/3dmanufacturing/material/2015/02">)"
           "<resources>" +
           resources + "</resources><build>" + build + "</build></model>";
}

// An object of `mesh`'s vertices and triangles, with `attributes` on the object and `corners`
// on each triangle.
std::string meshObject(const TriangleMesh& mesh, int id, const std::string& attributes = "",
                       const std::string& corners = "") {
    std::string s = "<object id=\"" + std::to_string(id) + "\" type=\"model\"" + attributes +
                    "><mesh><vertices>";
    for (const glm::vec3& p : mesh.positions) {
        char line[128];
        std::snprintf(line, sizeof line, "<vertex x=\"%.9g\" y=\"%.9g\" z=\"%.9g\"/>", p.x, p.y,
                      p.z);
        s += line;
    }
    s += "</vertices><triangles>";
    for (const glm::uvec3& t : mesh.triangles)
        s += "<triangle v1=\"" + std::to_string(t[0]) + "\" v2=\"" + std::to_string(t[1]) +
             "\" v3=\"" + std::to_string(t[2]) + "\"" + corners + "/>";
    return s + "</triangles></mesh></object>";
}

TEST(MeshField, EveryFormatReadsTheSameTriangles) {
    Mesh sphere = icosphere(3);
    const glm::vec3 centre(0.3f, 0.7f, -0.2f); // read back where it was: STL and 3MF turned
    for (glm::vec3& p : sphere.positions)
        p += centre;
    for (MeshFormat format : {MeshFormat::Ply, MeshFormat::Obj, MeshFormat::Stl, MeshFormat::Glb,
                              MeshFormat::ThreeMf}) {
        const std::string name(meshFormatName(format));
        SCOPED_TRACE(name);
        // In the unit sdfcsg writes by default, whose 3MF reads back at the same size.
        auto read = readTriangleMesh(encodeMesh(sphere, format), "." + name);
        ASSERT_TRUE(read) << read.error().str();
        EXPECT_EQ(read->triangles.size(), sphere.indices.size() / 3);
        EXPECT_EQ(read->positions.size(), sphere.positions.size()); // STL's corners welded
        EXPECT_FALSE(meshDefects(*read).any());
        float farthest = 0.0f;
        for (const glm::vec3& p : read->positions)
            farthest = std::max(farthest, std::abs(glm::length(p - centre) - 1.0f));
        EXPECT_LT(farthest, 1e-5f);
    }
    // Binary STL is read without Assimp: an ASCII STL of the same triangles, and a binary one
    // with colours, both read through Assimp, come out the same.
    const TriangleMesh t = triangles(sphere);
    std::string ascii = "solid sphere\n";
    for (const glm::uvec3& f : t.triangles) {
        ascii += "facet normal 0 0 0\nouter loop\n";
        for (int c = 0; c < 3; ++c) {
            char line[128];
            const glm::vec3 p = t.positions[f[c]];
            std::snprintf(line, sizeof line, "vertex %.9g %.9g %.9g\n", p.x, p.y, p.z);
            ascii += line;
        }
        ascii += "endloop\nendfacet\n";
    }
    ascii += "endsolid sphere\n";
    const auto fast = readTriangleMesh(binaryStl(t, uint32_t(t.triangles.size())), ".stl");
    ASSERT_TRUE(fast) << fast.error().str();
    // A triangle's attribute with its top bit set holds its colour (15 bits): that file too.
    std::string attributes = binaryStl(t, uint32_t(t.triangles.size()));
    for (size_t f = 0; f < t.triangles.size(); ++f)
        attributes[84 + 50 * f + 49] = char(0xfc); // red
    EXPECT_TRUE(fast->colors.empty());
    for (const std::string* other : {&ascii, &attributes}) {
        const auto slow = readTriangleMesh(*other, ".stl");
        ASSERT_TRUE(slow) << slow.error().str();
        EXPECT_EQ(slow->positions, fast->positions);
        EXPECT_EQ(slow->triangles, fast->triangles);
        EXPECT_EQ(slow->colors.empty(), other == &ascii);
    }
}

TEST(MeshField, DistanceOfASphereMesh) {
    const TriangleMesh sphere = triangles(icosphere(5)); // 20480 triangles, sagitta about 1e-4
    auto field = MeshField::make(sphere, 64);
    ASSERT_TRUE(field) << field.error().str();
    const float cell = field->cell();
    EXPECT_NEAR(cell, 2.0f / 64.0f, 1e-3f);
    int inBand = 0;
    for (const glm::vec3& p : randomPoints(3, 20000, 1.6f)) {
        const float exact = glm::length(p) - 1.0f, d = field->distance(p);
        if (std::abs(exact) < field->band()) {
            ++inBand;
            ASSERT_NEAR(d, exact, 0.05f * cell) << p.x << " " << p.y << " " << p.z;
        } else {
            // Beyond the band: a bound of the right sign.
            ASSERT_EQ(d < 0.0f, exact < 0.0f) << p.x << " " << p.y << " " << p.z << " " << d;
            ASSERT_LE(std::abs(d), std::abs(exact) + 0.05f * cell);
        }
    }
    EXPECT_GT(inBand, 500);
    // Sparse: only bricks near the sphere hold samples.
    EXPECT_LT(field->storedBricks(),
              size_t(field->bricks().x * field->bricks().y * field->bricks().z));
    // Without a step anywhere, where the band ends and the bricks without samples begin
    // included: sphere tracing and pruning need a field that changes no faster than the
    // distance (a tenth more allowed for trilinear interpolation).
    std::mt19937 rng(5);
    std::normal_distribution<float> n(0.0f, 1.0f);
    for (const glm::vec3& p : randomPoints(6, 40000, 1.6f)) {
        const glm::vec3 q = p + 0.5f * cell * glm::normalize(glm::vec3(n(rng), n(rng), n(rng)));
        ASSERT_LE(std::abs(field->distance(p) - field->distance(q)), 1.1f * 0.5f * cell + 1e-6f)
            << p.x << " " << p.y << " " << p.z << ": " << field->distance(p) << " and "
            << field->distance(q);
    }
}

// A sphere with a hole cut in it and some triangles turned over still has the ball as its
// inside; the defects are counted.
TEST(MeshField, HolesAndFlippedTrianglesKeepTheInside) {
    TriangleMesh mesh = triangles(icosphere(4));
    std::vector<glm::uvec3> kept;
    size_t flipped = 0;
    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
        glm::uvec3 t = mesh.triangles[i];
        glm::vec3 c = (mesh.positions[t.x] + mesh.positions[t.y] + mesh.positions[t.z]) / 3.0f;
        if (c.y > 0.93f) continue; // a hole about the top
        if (i % 97 == 0 && c.y < 0.5f) std::swap(t.y, t.z), ++flipped;
        kept.push_back(t);
    }
    mesh.triangles = kept;
    const MeshDefects defects = meshDefects(mesh);
    EXPECT_GT(defects.openEdges, 10u);
    EXPECT_EQ(defects.flippedEdges, 3 * flipped);
    EXPECT_EQ(defects.crowdedEdges, 0u);
    const std::vector<glm::vec3> points = randomPoints(5, 4000, 1.5f);
    const std::vector<float> w = windingNumbers(mesh, points);
    auto field = MeshField::make(mesh, 48);
    ASSERT_TRUE(field) << field.error().str();
    for (size_t i = 0; i < points.size(); ++i) {
        const float r = glm::length(points[i]);
        if (points[i].y > 0.7f || std::abs(r - 1.0f) < 0.1f) continue; // near the hole or surface
        ASSERT_EQ(w[i] > 0.5f, r < 1.0f) << w[i] << " at radius " << r;
        ASSERT_EQ(field->distance(points[i]) < 0.0f, r < 1.0f) << "at radius " << r;
    }
}

// The distance from p to the triangle abc, by brute force: to its plane where p projects inside
// it, else to the nearest of its three edges.
float distanceToTriangle(glm::vec3 p, glm::vec3 a, glm::vec3 b, glm::vec3 c) {
    const auto toSegment = [&](glm::vec3 u, glm::vec3 v) {
        const glm::vec3 e = v - u;
        const float t = glm::clamp(glm::dot(p - u, e) / glm::dot(e, e), 0.0f, 1.0f);
        return glm::length(p - (u + t * e));
    };
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    const glm::vec3 q = p - glm::dot(p - a, n) * n;
    if (glm::dot(glm::cross(b - a, q - a), n) >= 0.0f &&
        glm::dot(glm::cross(c - b, q - b), n) >= 0.0f &&
        glm::dot(glm::cross(a - c, q - c), n) >= 0.0f)
        return std::abs(glm::dot(p - a, n));
    return std::min({toSegment(a, b), toSegment(b, c), toSegment(c, a)});
}

// A lumpy ball: an icosphere's vertices moved in and out at random, so that it has folds and
// hollows, closed and consistently oriented.
TriangleMesh lumpyBall(uint32_t seed) {
    TriangleMesh mesh = triangles(icosphere(3));
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.75f, 1.25f);
    for (glm::vec3& p : mesh.positions)
        p *= u(rng);
    return mesh;
}

// At the field's samples (the grid's points) within the band, the field is the distance to the
// nearest of all the triangles, signed by the winding number; a cell beyond the band, the band
// (its samples, within a tenth of a cell of the distance, read clamped to it); farther, a bound
// of the right sign. Closed meshes and ones with holes and
// flipped triangles alike.
void expectSamplesAreDistances(const TriangleMesh& mesh, int cells, uint32_t seed) {
    auto field = MeshField::make(mesh, cells);
    ASSERT_TRUE(field) << field.error().str();
    const float cell = field->cell(), band = field->band();
    std::mt19937 rng(seed);
    std::vector<glm::vec3> points;
    const glm::ivec3 last = field->bricks() * MeshField::kBrick;
    while (points.size() < 1500) {
        const glm::ivec3 g(std::uniform_int_distribution<int>(0, last.x)(rng),
                           std::uniform_int_distribution<int>(0, last.y)(rng),
                           std::uniform_int_distribution<int>(0, last.z)(rng));
        const glm::vec3 p = field->origin() + cell * glm::vec3(g);
        // Mostly points near the surface, where the field is exact.
        if (field->distance(p) < 2.0f * band || points.size() % 4 == 0) points.push_back(p);
    }
    const std::vector<float> winding = windingNumbers(mesh, points);
    int exact = 0;
    for (size_t i = 0; i < points.size(); ++i) {
        const glm::vec3 p = points[i];
        float d = INFINITY;
        for (const glm::uvec3& t : mesh.triangles)
            d = std::min(d, distanceToTriangle(p, mesh.positions[t.x], mesh.positions[t.y],
                                               mesh.positions[t.z]));
        const float v = field->distance(p);
        SCOPED_TRACE(testing::Message() << p.x << " " << p.y << " " << p.z << ": " << v
                                        << " against " << d << ", winding " << winding[i]);
        if (d < 0.05f * cell) continue; // on the surface: either sign
        if (std::abs(winding[i] - 0.5f) > 0.1f) {
            ASSERT_EQ(v<0.0f, winding[i]> 0.5f);
        }
        if (d < band - 1e-3f * cell) {
            ++exact;
            ASSERT_NEAR(std::abs(v), d, 1e-3f * cell);
        } else if (d < band + cell) { // stored within a tenth of a cell, read clamped to the band
            ASSERT_NEAR(std::abs(v), std::min(d, band), 0.1f * cell);
        } else {
            ASSERT_LE(std::abs(v), d + 0.1f * cell);
        }
    }
    EXPECT_GT(exact, 200);
}

TEST(MeshField, SamplesAreTheDistanceToTheNearestTriangle) {
    for (uint32_t seed : {1u, 2u, 3u}) {
        SCOPED_TRACE(seed);
        expectSamplesAreDistances(lumpyBall(seed), 40, seed);
    }
    // Holes and flipped triangles: signed by the winding number instead.
    TriangleMesh torn = lumpyBall(4);
    std::vector<glm::uvec3> kept;
    for (size_t i = 0; i < torn.triangles.size(); ++i) {
        glm::uvec3 t = torn.triangles[i];
        if (i % 31 == 0) continue;
        if (i % 17 == 0) std::swap(t.y, t.z);
        kept.push_back(t);
    }
    torn.triangles = kept;
    ASSERT_TRUE(meshDefects(torn).any());
    expectSamplesAreDistances(torn, 40, 4);
    // Triangles far smaller than a cell, as meshes of a million triangles have at 128 cells.
    expectSamplesAreDistances(triangles(icosphere(4)), 16, 5);
}

// The samples beyond the band, which the dilation fills from their neighbours' nearest
// triangles: read from the field's words, those within a cell beyond it hold the distance to a
// triangle, so no less than the exact distance, and within a few hundredths of a cell of it; the
// rest no more than their distance (the band plus a cell where nothing reached them).
TEST(MeshField, SamplesBeyondTheBandAreNearTheirDistance) {
    for (const float bandCells : {2.0f, 3.5f}) {
        SCOPED_TRACE(bandCells);
        const TriangleMesh mesh = lumpyBall(7);
        auto field = MeshField::make(mesh, 40, bandCells);
        ASSERT_TRUE(field) << field.error().str();
        const std::vector<glm::vec4> w = field->words();
        const glm::ivec3 bricks = field->bricks();
        const size_t slots = size_t(bricks.x) * size_t(bricks.y) * size_t(bricks.z);
        const size_t samplesAt = 4 * (3 + (slots + 3) / 4);
        const float* words = &w[0].x;
        const float cell = field->cell(), band = field->band(), margin = band + cell;
        constexpr int side = MeshField::kBrick + 1;
        std::mt19937 rng(7);
        int beyond = 0;
        for (size_t slot = 0; slot < slots; ++slot) {
            const float index = words[12 + slot];
            if (index < 0.0f) continue;
            const glm::ivec3 brick(int(slot % size_t(bricks.x)),
                                   int(slot / size_t(bricks.x) % size_t(bricks.y)),
                                   int(slot / (size_t(bricks.x) * size_t(bricks.y))));
            for (int s = 0; s < side * side * side; ++s) {
                if (rng() % 16 != 0) continue; // a sixteenth of them, for time
                const glm::ivec3 g = brick * MeshField::kBrick +
                                     glm::ivec3(s % side, s / side % side, s / (side * side));
                const glm::vec3 p = field->origin() + cell * glm::vec3(g);
                float d = INFINITY;
                for (const glm::uvec3& t : mesh.triangles)
                    d = std::min(d, distanceToTriangle(p, mesh.positions[t.x], mesh.positions[t.y],
                                                       mesh.positions[t.z]));
                const float v =
                    std::abs(words[samplesAt + size_t(index) * side * side * side + size_t(s)]);
                SCOPED_TRACE(testing::Message()
                             << p.x << " " << p.y << " " << p.z << ": " << v << " against " << d);
                if (d < band) {
                    ASSERT_NEAR(v, d, 1e-3f * cell);
                } else if (d < margin - 0.05f * cell) {
                    ++beyond;
                    ASSERT_GE(v, d - 1e-3f * cell);
                    ASSERT_LE(v, d + 0.05f * cell);
                } else {
                    ASSERT_LE(v, std::max(d, margin) + 1e-3f * cell);
                }
            }
        }
        EXPECT_GT(beyond, 400) << beyond << " samples within a cell beyond the band";
    }
}

TEST(MeshField, HostileFilesAreRefused) {
    const TriangleMesh sphere = triangles(icosphere(1));
    auto text = [](const Result<TriangleMesh>& r) {
        return r ? std::string("read") : r.error().diagnostics[0].message;
    };
    // Claims 2^31 triangles, holds 80.
    EXPECT_NE(text(readTriangleMesh(binaryStl(sphere, 1u << 31), ".stl")).find("not a mesh file"),
              std::string::npos);
    TriangleMesh bad = sphere;
    bad.positions[3].x = NAN;
    EXPECT_EQ(text(readTriangleMesh(binaryStl(bad, uint32_t(bad.triangles.size())), ".stl")),
              "a NaN or infinite vertex");
    EXPECT_EQ(text(readTriangleMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\n", ".obj")), "no triangles");
    EXPECT_NE(text(readTriangleMesh(std::string(100, 'x'), ".ply")).find("not a mesh file"),
              std::string::npos);
    EXPECT_NE(text(readTriangleMesh("", ".glb")).find("not a mesh file"), std::string::npos);
    // A 3MF whose directory claims an entry of 4 GiB - 2 (a ZIP bomb's shape): refused unread.
    std::string bomb = encodeMesh(icosphere(1), MeshFormat::ThreeMf, LengthUnit::Millimeter);
    const size_t directory = bomb.rfind(std::string("PK\1\2", 4));
    ASSERT_NE(directory, std::string::npos);
    const uint32_t huge = 0xfffffffeu;
    std::memcpy(&bomb[directory + 24], &huge, 4);
    EXPECT_EQ(text(readTriangleMesh(bomb, ".3mf")),
              "3D/3dmodel.model unpacks to more than 1024 MiB");
    EXPECT_EQ(text(readTriangleMesh("PK", ".3mf")),
              "not a 3MF file: no ZIP directory that can be read");
    // A field too large for memory is refused before it is made.
    auto huge_field = MeshField::make(triangles(icosphere(2)), 100000);
    ASSERT_FALSE(huge_field);
    EXPECT_NE(huge_field.error().str().find("over the limit of 64 MiB"), std::string::npos)
        << huge_field.error().str();
}

// A glTF whose buffer is a file beside it reads as its binary form does. The files that a mesh
// file names are read from its folder alone: one that names a file outside it, or a device, reads
// nothing from there.
TEST(MeshField, FilesAMeshNamesAreReadFromItsFolderAlone) {
    const std::filesystem::path dir =
        std::filesystem::path(SDFCSG_TEST_OUTPUT_DIR) / "mesh_named_files";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir / "part");
    const Mesh sphere = icosphere(2);
    // The binary form's two chunks: its JSON (the buffer named by the JSON's first "byteLength"),
    // then the buffer.
    const std::string glb = encodeMesh(sphere, MeshFormat::Glb, LengthUnit::Millimeter);
    uint32_t jsonLength = 0;
    std::memcpy(&jsonLength, &glb[12], 4);
    std::string json = glb.substr(20, jsonLength);
    const std::string buffer = glb.substr(20 + jsonLength + 8);
    const size_t byteLength = json.find("\"byteLength\"");
    ASSERT_NE(byteLength, std::string::npos) << json;
    auto write = [](const std::filesystem::path& file, const std::string& bytes) {
        std::ofstream(file, std::ios::binary) << bytes;
    };
    write(dir / "part" / "sphere.bin", buffer);
    write(dir / "outside.bin", buffer);
    auto gltf = [&](const std::string& uri) {
        std::string named = json;
        named.insert(byteLength, "\"uri\": \"" + uri + "\", ");
        return named;
    };
    auto besides = readTriangleMesh(gltf("sphere.bin"), ".gltf", dir / "part");
    ASSERT_TRUE(besides) << besides.error().str();
    auto binary = readTriangleMesh(glb, ".glb");
    ASSERT_TRUE(binary) << binary.error().str();
    EXPECT_EQ(besides->positions, binary->positions);
    EXPECT_EQ(besides->triangles, binary->triangles);
    for (const std::string& uri : {std::string("../outside.bin"), (dir / "outside.bin").string(),
                                   std::string("/dev/zero")}) {
        SCOPED_TRACE(uri);
        EXPECT_FALSE(readTriangleMesh(gltf(uri), ".gltf", dir / "part"));
    }
    EXPECT_FALSE(readTriangleMesh(gltf("sphere.bin"), ".gltf")); // no folder: no files
    // An OBJ's material library on a device that never ends: not read, and the triangles are.
    auto obj = readTriangleMesh("mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", ".obj",
                                dir / "part");
    ASSERT_TRUE(obj) << obj.error().str();
    EXPECT_EQ(obj->triangles.size(), 1u);
}

const std::filesystem::path kGearStl =
    std::filesystem::path(SDFCSG_SOURCE_DIR) / "assets/scenes/gear.stl";

Scene meshScene(const std::string& file, int resolution) {
    auto scene = parseScene(R"({"version": 1, "root": {"type": "mesh", "file": ")" + file +
                                R"(", "resolution": )" + std::to_string(resolution) + "}}",
                            "test.json");
    if (!scene) ADD_FAILURE() << scene.error().str();
    return scene ? *scene : Scene{};
}

// The node's field, through the kernels' formula (sdMesh), is the mesh field's, floored at the
// distance to the node's box (KindInfo::floored).
TEST(MeshNode, FieldIsTheMeshFields) {
    std::ifstream in(kGearStl, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    auto mesh = readTriangleMesh(bytes, ".stl");
    ASSERT_TRUE(mesh) << mesh.error().str();
    auto field = MeshField::make(*mesh, 96);
    ASSERT_TRUE(field) << field.error().str();
    const Evaluator node(meshScene(kGearStl.string(), 96));
    const glm::vec3 lo = node.bounds().min, hi = node.bounds().max;
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int i = 0; i < 20000; ++i) {
        // Inside the grid and a little beyond it.
        const glm::vec3 t(u(rng), u(rng), u(rng));
        const glm::vec3 p = lo - 0.2f * (hi - lo) + 1.4f * t * (hi - lo);
        ASSERT_NEAR(node.distance(p), std::max(field->distance(p), node.bounds().signedDistance(p)),
                    1e-5f);
    }
}

void roundTripKeepsTheSurface(const Scene& gear, const std::filesystem::path& file) {
    const Evaluator scene(gear), node(meshScene(file.string(), 128));
    const glm::vec3 size = scene.bounds().max - scene.bounds().min;
    const float cell = std::max({size.x, size.y, size.z}) / 56.0f;
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    int near = 0;
    for (int i = 0; i < 40000; ++i) {
        const glm::vec3 p = scene.bounds().min + glm::vec3(u(rng), u(rng), u(rng)) * size;
        const float d = scene.distance(p), v = node.distance(p);
        if (std::abs(d) < 0.1f * cell) {
            ++near;
            ASSERT_LT(std::abs(v), 0.6f * cell) << p.x << " " << p.y << " " << p.z;
        } else if (std::abs(d) > cell) {
            ASSERT_EQ(v < 0.0f, d < 0.0f) << p.x << " " << p.y << " " << p.z;
        }
    }
    EXPECT_GT(near, 200);
}

// Scene -> mesh -> mesh node: the scene's surface is the node's, within the mesh's own error (its
// cells at 56) and the field's interpolation; and both agree on the inside away from it. (The
// gear's field is a bound, not a distance, so values away from the surface differ.) The mesh as
// STL, and as 3MF in the unit sdfcsg writes by default, which comes back at the same size.
TEST(MeshNode, RoundTripKeepsTheSurface) {
    auto gear = loadScene(std::filesystem::path(SDFCSG_SOURCE_DIR) / "assets/scenes/gear.json");
    ASSERT_TRUE(gear) << gear.error().str();
    std::ifstream in(kGearStl, std::ios::binary);
    const auto stl = readTriangleMesh(
        std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()),
        ".stl");
    ASSERT_TRUE(stl) << stl.error().str();
    Mesh mesh;
    mesh.positions = stl->positions;
    for (const glm::uvec3& t : stl->triangles)
        mesh.indices.insert(mesh.indices.end(), {t.x, t.y, t.z});
    const std::filesystem::path threeMf =
        std::filesystem::path(SDFCSG_TEST_OUTPUT_DIR) / "gear_round_trip.3mf";
    std::filesystem::create_directories(threeMf.parent_path());
    std::ofstream(threeMf, std::ios::binary) << encodeMesh(mesh, MeshFormat::ThreeMf);
    for (const std::filesystem::path& file : {kGearStl, threeMf}) {
        SCOPED_TRACE(file.filename().string());
        roundTripKeepsTheSurface(*gear, file);
    }
}

// An OBJ of the box from `lo` to `hi`, counter-clockwise seen from outside, less the triangles
// in `left`, and with those in `flipped` turned over.
std::string boxObj(glm::vec3 lo, glm::vec3 hi, std::vector<int> left = {},
                   std::vector<int> flipped = {}) {
    std::string obj;
    for (int i = 0; i < 8; ++i) // corner i: x from bit 0, y from bit 1, z from bit 2
        obj += "v " + std::to_string(i & 1 ? hi.x : lo.x) + " " +
               std::to_string(i & 2 ? hi.y : lo.y) + " " + std::to_string(i & 4 ? hi.z : lo.z) +
               "\n";
    const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                             {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (int t = 0; t < 12; ++t) {
        const int* q = quads[t / 2];
        int a = q[0], b = q[1 + t % 2], c = q[2 + t % 2];
        if (std::count(left.begin(), left.end(), t)) continue;
        if (std::count(flipped.begin(), flipped.end(), t)) std::swap(b, c);
        obj += "f " + std::to_string(a + 1) + " " + std::to_string(b + 1) + " " +
               std::to_string(c + 1) + "\n";
    }
    return obj;
}

// A file beside the tests' scenes, written for one test.
std::filesystem::path writeTestFile(const std::string& name, const std::string& text) {
    const std::filesystem::path path = std::filesystem::temp_directory_path() / name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
}

// "fit" scales the mesh by one factor into the box and centres it: a 2 x 4 x 1 box, fitted to
// 1 x 1 x 1, is 0.5 x 1 x 0.25 about the origin, its field in the scene's units.
// A band wider than its two cells keeps the distance exact as far as it reaches, as a shell or
// an offset of the mesh needs; beyond, the field holds the band.
TEST(MeshNode, ItsBandIsAsWideAsAsked) {
    const auto file =
        writeTestFile("band_box.obj", boxObj({-1.0f, -1.0f, -1.0f}, {1.0f, 1.0f, 1.0f}));
    auto node = [&](const std::string& band) {
        auto scene = parseScene(R"({"version": 1, "root": {"type": "mesh", "file": ")" +
                                    file.string() + R"(", "resolution": 32)" + band + "}}",
                                "test.json");
        EXPECT_TRUE(scene) << scene.error().str();
        return Evaluator(scene ? *scene : Scene{});
    };
    const Evaluator narrow = node(""), wide = node(R"(, "band": 0.5)");
    for (float d : {0.1f, 0.2f, 0.3f, 0.45f}) {
        SCOPED_TRACE(d);
        EXPECT_NEAR(wide.distance({1.0f + d, 0.2f, -0.3f}), d, 1e-3f);
        EXPECT_NEAR(wide.distance({0.3f, 1.0f - d, 0.1f}), -d, 1e-3f);
        // Two cells of 1/16: beyond them, a bound well below the distance.
        const float bound = narrow.distance({1.0f + d, 0.2f, -0.3f});
        if (d < 0.125f)
            EXPECT_NEAR(bound, d, 1e-3f);
        else
            EXPECT_LT(bound, d - 0.05f);
    }
}

TEST(MeshNode, FitScalesIntoTheBox) {
    const auto file = writeTestFile("fit_box.obj", boxObj({3.0f, -1.0f, 2.0f}, {5.0f, 3.0f, 3.0f}));
    auto scene = parseScene(R"({"version": 1, "root": {"type": "mesh", "file": ")" + file.string() +
                                R"(", "resolution": 64, "fit": [1, 1, 1]}})",
                            "test.json");
    ASSERT_TRUE(scene) << scene.error().str();
    const Evaluator node(*scene);
    const glm::vec3 half(0.25f, 0.5f, 0.125f);
    for (int a = 0; a < 3; ++a)
        for (float side : {-1.0f, 1.0f}) {
            glm::vec3 face(0.0f), out(0.0f);
            face[a] = side * half[a];
            out[a] = side * 0.01f;
            SCOPED_TRACE(std::to_string(a) + " " + std::to_string(side));
            EXPECT_NEAR(node.distance(face), 0.0f, 1e-4f);
            // Distances in the scene's units: 0.01 out, 0.01 in (the cell is 1/64).
            EXPECT_NEAR(node.distance(face + out), 0.01f, 1e-4f);
            EXPECT_NEAR(node.distance(face - out), -0.01f, 1e-4f);
        }
    // The bounds are the fitted box and a cell (1/64) (not the field's grid, which reaches a band
    // and a cell beyond it, and up to a whole brick).
    for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(node.bounds().min[a], -half[a] - 1.0f / 64.0f, 1e-4f);
        EXPECT_NEAR(node.bounds().max[a], half[a] + 1.0f / 64.0f, 1e-4f);
    }
}

// A mesh whose file has a hole and a flipped triangle gets one note, with the counts: the box
// less one triangle (three open edges) and with another turned over (three edges between
// triangles wound opposite ways), in a definition used twice.
TEST(MeshNode, ItsRepairsAreNoted) {
    writeTestFile("holed_box.obj", boxObj({-1.0f, -1.0f, -1.0f}, {1.0f, 1.0f, 1.0f}, {0}, {2}));
    ParseOptions options;
    options.files.folder = std::filesystem::temp_directory_path();
    auto scene = parseScene(
        R"({"version": 1, "definitions": {"part": {"node": {"type": "mesh",
               "file": "holed_box.obj", "resolution": 16}}},
            "root": {"type": "union", "children": [
                {"type": "use", "definition": "part"},
                {"type": "use", "definition": "part", "translate": [3, 0, 0]}]}})",
        "test.json", options);
    ASSERT_TRUE(scene) << scene.error().str();
    const std::vector<FieldNote> notes = fieldNotes(*scene, Evaluator(*scene));
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_EQ(notes[0].path, "definitions.part.node");
    EXPECT_EQ(notes[0].message,
              "mesh \"holed_box.obj\" is not closed and consistently oriented: 3 open edges, 3 "
              "edges between triangles wound opposite ways (flipped triangles); its inside comes "
              "from the generalised winding number, which fills holes and outvotes flipped "
              "triangles");
    // Its inside is the box's all the same.
    const Evaluator box(*scene);
    EXPECT_LT(box.distance(glm::vec3(0.0f)), 0.0f);
    EXPECT_LT(box.distance(glm::vec3(-0.9f, 0.0f, 0.0f)), 0.0f); // behind the hole
    EXPECT_GT(box.distance(glm::vec3(-1.2f, 0.0f, 0.0f)), 0.0f);
    // A closed mesh gets none.
    EXPECT_TRUE(
        fieldNotes(meshScene(kGearStl.string(), 32), Evaluator(meshScene(kGearStl.string(), 32)))
            .empty());
}

TEST(MeshNode, ItsProblemsAreNamed) {
    auto error = [](const std::string& root, bool trusted = true) {
        ParseOptions options;
        options.files.trusted = trusted;
        options.files.folder = trusted ? "" : SDFCSG_SOURCE_DIR;
        auto scene = parseScene(R"({"version": 1, "root": )" + root + "}", "test.json", options);
        return scene ? "accepted" : scene.error().str();
    };
    EXPECT_EQ(error(R"({"type": "mesh", "file": "nothing.stl"})"),
              "test.json: root.file: cannot load mesh \"nothing.stl\": no such file");
    EXPECT_EQ(error(R"({"type": "mesh", "file": "/etc/passwd"})", false),
              "test.json: root.file: unknown mesh \"/etc/passwd\": name a mesh file in the "
              "scene's folder");
    EXPECT_EQ(error(R"({"type": "mesh", "file": ")" + kGearStl.string() + R"(", "resolution": 4})"),
              "test.json: root.resolution: expected at least 8, got 4");
    EXPECT_EQ(
        error(R"({"type": "mesh", "file": ")" + kGearStl.string() + R"(", "fit": [1, 0, 2]})"),
        "test.json: root.fit[1]: expected a positive number, got 0");
    EXPECT_EQ(error(R"({"type": "mesh", "file": ")" + kGearStl.string() + R"(", "fit": 2})"),
              "test.json: root.fit: expected an array of 3 positive numbers, got 2");
}

} // namespace
} // namespace sdfcsg::detail

namespace sdfcsg::detail {
namespace {

// Objects placed by components and build items, their transforms 4x3 matrices whose last row
// is the translation (3MF Core 3.3), composed component first; a mirroring one keeps the
// triangles facing out.
TEST(MeshField, ThreeMfPlacesItsObjects) {
    const TriangleMesh sphere = triangles(icosphere(2));
    // Object 1 the sphere; object 2 it, moved by (1, 2, 3) and mirrored in x; the build item
    // moves object 2 by (10, 20, 30) and scales it by 2.
    const std::string model = modelXml(
        meshObject(sphere, 1) + R"(<object id="2"><components><component objectid="1" )"
                                R"(transform="-1 0 0 0 1 0 0 0 1 1 2 3"/></components></object>)",
        R"(<item objectid="2" transform="2 0 0 0 2 0 0 0 2 10 20 30"/>)");
    const auto read = readTriangleMesh(threeMf(model), ".3mf");
    ASSERT_TRUE(read) << read.error().str();
    EXPECT_EQ(read->triangles.size(), sphere.triangles.size());
    EXPECT_TRUE(read->colors.empty());
    // In the file, the centre is 2 * (1, 2, 3) + (10, 20, 30) = (12, 24, 36) and the radius 2;
    // turned to y up, (x, z, -y).
    const glm::vec3 centre(12.0f, 36.0f, -24.0f);
    float farthest = 0.0f;
    for (const glm::vec3& p : read->positions)
        farthest = std::max(farthest, std::abs(glm::length(p - centre) - 2.0f));
    EXPECT_LT(farthest, 1e-5f);
    EXPECT_FALSE(meshDefects(*read).any());
    const std::vector<float> inside = windingNumbers(*read, {centre});
    EXPECT_NEAR(inside[0], 1.0f, 0.05f); // facing out: +1 inside (fast winding numbers)
    // Objects outside the build, and supports, give no triangles.
    const auto supported = readTriangleMesh(
        threeMf(modelXml(meshObject(sphere, 1) + meshObject(sphere, 2) +
                             R"(<object id="3" type="support"><components><component )"
                             R"(objectid="1"/></components></object>)",
                         R"(<item objectid="2"/><item objectid="3"/>)"),
                "3D/other.model"),
        ".3mf");
    ASSERT_TRUE(supported) << supported.error().str();
    EXPECT_EQ(supported->triangles.size(), sphere.triangles.size());
}

// A base material per triangle (p1 alone) and a colour group per corner, in one object; a
// triangle of no property group has no colour, and a texture's none either.
TEST(MeshField, ThreeMfColours) {
    TriangleMesh quad;
    quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}};
    quad.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 1}};
    const std::string object =
        R"(<object id="5" pid="1" pindex="1"><mesh><vertices>)"
        R"(<vertex x="0" y="0" z="0"/><vertex x="1" y="0" z="0"/><vertex x="1" y="1" z="0"/>)"
        R"(<vertex x="0" y="1" z="0"/><vertex x="0" y="0" z="1"/></vertices><triangles>)"
        R"(<triangle v1="0" v2="1" v3="2"/>)"                                     // object's: blue
        R"(<triangle v1="0" v2="2" v3="3" pid="2" p1="0" p2="1" p3="2"/>)"        // corners
        R"(<triangle v1="0" v2="3" v3="4" pid="3" p1="0"/>)"                      // a texture's
        R"(<triangle v1="0" v2="4" v3="1" p1="0"/></triangles></mesh></object>)"; // red
    const std::string model = modelXml(
        R"(<basematerials id="1"><base name="red" displaycolor="#FF0000"/>)"
        R"(<base name="blue" displaycolor="#0000ffcc"/></basematerials>)"
        R"(<m:colorgroup id="2"><m:color color="#102030"/><m:color color="#405060FF"/>)"
        R"(<m:color color="#708090"/></m:colorgroup>)"
        R"(<m:texture2dgroup id="3" texid="9"><m:tex2coord u="0" v="0"/></m:texture2dgroup>)" +
            object,
        R"(<item objectid="5"/>)");
    const auto read = readTriangleMesh(threeMf(model), ".3mf");
    ASSERT_TRUE(read) << read.error().str();
    ASSERT_EQ(read->colors.size(), 12u);
    const std::vector<uint32_t> want = {0x0000ff, 0x0000ff, 0x0000ff, 0x102030, 0x405060, 0x708090,
                                        kNoColor, kNoColor, kNoColor, 0xff0000, 0xff0000, 0xff0000};
    EXPECT_EQ(read->colors, want);
}

// Hostile and broken 3MF files: each refused with its reason, the part and line named where the
// model's XML is at fault.
TEST(MeshField, HostileThreeMfFilesAreRefused) {
    const TriangleMesh sphere = triangles(icosphere(1));
    auto text = [](const Result<TriangleMesh>& r) {
        return r ? std::string("read") : r.error().diagnostics[0].message;
    };
    auto read = [&](const std::string& resources,
                    const std::string& build = R"(<item objectid="1"/>)") {
        return text(readTriangleMesh(threeMf(modelXml(resources, build)), ".3mf"));
    };
    const std::string good = threeMf(modelXml(meshObject(sphere, 1), R"(<item objectid="1"/>)"));
    ASSERT_EQ(text(readTriangleMesh(good, ".3mf")), "read");
    // Truncated: the ZIP's directory, at its end, is gone.
    EXPECT_EQ(text(readTriangleMesh(good.substr(0, good.size() / 2), ".3mf")),
              "not a 3MF file: no ZIP directory that can be read");
    // A ZIP bomb: 64 MiB of the model's XML (spaces inside its root) deflated to a small file,
    // its directory declaring 4096 bytes. Refused as the inflated bytes pass that, not after.
    std::string padded = modelXml(meshObject(sphere, 1), R"(<item objectid="1"/>)");
    padded.insert(padded.find("<resources>"), size_t(64) << 20, ' ');
    std::string bomb = threeMf(padded);
    EXPECT_LT(bomb.size(), size_t(1) << 20);
    const size_t directory = bomb.rfind(std::string("PK\1\2", 4));
    ASSERT_NE(directory, std::string::npos);
    const uint32_t declared = 4096;
    std::memcpy(&bomb[directory + 24], &declared, 4);
    EXPECT_EQ(text(readTriangleMesh(bomb, ".3mf")),
              "3D/3dmodel.model unpacks to more than the 4096 bytes its ZIP directory declares");
    // The same under its true size, with the limit below it: refused from the directory.
    EXPECT_EQ(readThreeMf(threeMf(padded), {}, 100, 1 << 20, 10.0).error().diagnostics[0].message,
              "3D/3dmodel.model unpacks to more than 1 MiB");
    // Triangles past the limit: counted as they are read.
    EXPECT_EQ(readThreeMf(good, {}, 50, 1 << 20, 10.0).error().diagnostics[0].message,
              "3D/3dmodel.model, line 1: more than 50 triangles");
    // Placed past the limit by build items, each object within it.
    EXPECT_EQ(readThreeMf(threeMf(modelXml(meshObject(sphere, 1),
                                           R"(<item objectid="1"/><item objectid="1"/>)")),
                          {}, 100, 1 << 20, 10.0)
                  .error()
                  .diagnostics[0]
                  .message,
              "more than 100 triangles (160)");
    // A damaged deflate stream, and a CRC that does not match.
    std::string damaged = good;
    const size_t data = damaged.find("3D/3dmodel.model") + 16;
    damaged[data + 40] = char(~damaged[data + 40]);
    EXPECT_NE(text(readTriangleMesh(damaged, ".3mf")).find("3D/3dmodel.model"), std::string::npos);
    std::string crc = good;
    const size_t entry = crc.rfind(std::string("PK\1\2", 4)); // the model's, the last
    crc[entry + 16] = char(~crc[entry + 16]);
    EXPECT_EQ(text(readTriangleMesh(crc, ".3mf")),
              "3D/3dmodel.model is damaged: its CRC-32 does not match");
    // Indices: out of range, not whole numbers, 2^31 and past 2^32.
    const std::string vertices =
        R"(<vertex x="0" y="0" z="0"/><vertex x="1" y="0" z="0"/><vertex x="0" y="1" z="0"/>)";
    const auto one = [&](const std::string& triangle, const std::string& more = "") {
        return read(more + R"(<object id="1"><mesh><vertices>)" + vertices +
                    "</vertices><triangles>" + triangle + "</triangles></mesh></object>");
    };
    EXPECT_EQ(one(R"(<triangle v1="0" v2="1" v3="3"/>)"),
              "3D/3dmodel.model, line 1: a triangle's v3 (3) past its object's 3 vertices");
    EXPECT_EQ(one(R"(<triangle v1="0" v2="2147483648" v3="1"/>)"),
              "3D/3dmodel.model, line 1: a triangle's v2 (2147483648) past its object's 3 "
              "vertices");
    EXPECT_EQ(one(R"(<triangle v1="0" v2="1" v3="4294967296"/>)"),
              "3D/3dmodel.model, line 1: a triangle's v3 \"4294967296\" that is not a whole "
              "number under 2^32");
    EXPECT_EQ(one(R"(<triangle v1="0" v2="-1" v3="2"/>)"),
              "3D/3dmodel.model, line 1: a triangle's v2 \"-1\" that is not a whole number under "
              "2^32");
    EXPECT_EQ(one(R"(<triangle v1="0" v2="1"/>)"),
              "3D/3dmodel.model, line 1: a triangle without its v3");
    // Colours: an index past its group, a group not defined, a colour that is not one.
    const std::string group = R"(<m:colorgroup id="7"><m:color color="#ff0000"/></m:colorgroup>)";
    EXPECT_EQ(one(R"(<triangle v1="0" v2="1" v3="2" pid="7" p1="0" p2="1"/>)", group),
              "3D/3dmodel.model, line 1: a triangle's p2 (1) past the 1 entries of property "
              "group 7");
    EXPECT_EQ(one(R"(<triangle v1="0" v2="1" v3="2" pid="8" p1="0"/>)", group),
              "3D/3dmodel.model, line 1: a triangle names property group 8, which no resource "
              "before it defines");
    EXPECT_EQ(one(R"(<triangle v1="0" v2="1" v3="2" pid="7"/>)", group),
              "3D/3dmodel.model, line 1: a triangle with a property group but no index (p1 or "
              "pindex)");
    EXPECT_EQ(read(R"(<m:colorgroup id="7"><m:color color="red"/></m:colorgroup>)"),
              "3D/3dmodel.model, line 1: a colour \"red\" that is not #RRGGBB or #RRGGBBAA");
    // Vertices: NaN, infinite, not a number.
    EXPECT_EQ(read(R"(<object id="1"><mesh><vertices><vertex x="nan" y="0" z="0"/>)"
                   "</vertices></mesh></object>"),
              "3D/3dmodel.model, line 1: a NaN or infinite vertex");
    EXPECT_EQ(read(R"(<object id="1"><mesh><vertices><vertex x="0" y="1e39" z="0"/>)"
                   "</vertices></mesh></object>"),
              "3D/3dmodel.model, line 1: a NaN or infinite vertex");
    EXPECT_EQ(read(R"(<object id="1"><mesh><vertices><vertex x="0" y="one" z="0"/>)"
                   "</vertices></mesh></object>"),
              "3D/3dmodel.model, line 1: a vertex whose y \"one\" is not a number");
    // A transform that moves a vertex out of floats' range.
    EXPECT_EQ(read(meshObject(sphere, 1),
                   R"(<item objectid="1" transform="3e38 0 0 0 1 0 0 0 1 3e38 0 0"/>)"),
              "a NaN or infinite vertex");
    EXPECT_EQ(read(meshObject(sphere, 1), R"(<item objectid="1" transform="1 0 0 0 1 0 0 0 1"/>)"),
              "3D/3dmodel.model, line 1: a build item's transform \"1 0 0 0 1 0 0 0 1\" that is "
              "not 12 finite numbers");
    // Objects: named before they are defined, twice, or in another part.
    EXPECT_EQ(read(meshObject(sphere, 1), R"(<item objectid="2"/>)"),
              "3D/3dmodel.model, line 1: a build item names object 2, which no object before it "
              "defines");
    EXPECT_EQ(read(R"(<object id="2"><components><component objectid="2"/></components></object>)"),
              "3D/3dmodel.model, line 1: a component names object 2, which no object before it "
              "defines");
    EXPECT_EQ(read(meshObject(sphere, 1) + meshObject(sphere, 1)),
              "3D/3dmodel.model, line 1: two resources of id 1");
    // Components nested deeper than 32, and placing objects 27 million times.
    std::string deep = meshObject(sphere, 1);
    for (int id = 2; id <= 40; ++id)
        deep += "<object id=\"" + std::to_string(id) + "\"><components><component objectid=\"" +
                std::to_string(id - 1) + "\"/></components></object>";
    EXPECT_EQ(read(deep), "3D/3dmodel.model, line 1: components nested more than 32 deep");
    std::string wide = R"(<object id="1"><mesh><vertices/><triangles/></mesh></object>)";
    for (int id = 2; id <= 4; ++id) {
        wide += "<object id=\"" + std::to_string(id) + "\"><components>";
        for (int k = 0; k < 300; ++k)
            wide += "<component objectid=\"" + std::to_string(id - 1) + "\"/>";
        wide += "</components></object>";
    }
    EXPECT_EQ(read(wide, R"(<item objectid="4"/>)"),
              "a build that places objects more than 16777216 times");
    // XML: not well-formed, a DTD (entities that expand a billionfold), not a 3MF model.
    EXPECT_EQ(read(R"(<object id="1"><mesh></object>)"),
              "3D/3dmodel.model, line 1: mismatched tag");
    EXPECT_EQ(text(readTriangleMesh(threeMf(R"(<?xml version="1.0"?>
<!DOCTYPE model [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">]>
<model xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">&b;</model>)"),
                                    ".3mf")),
              "3D/3dmodel.model, line 2: a DTD, which a 3MF model may not hold");
    EXPECT_EQ(text(readTriangleMesh(threeMf("<svg/>"), ".3mf")),
              "3D/3dmodel.model, line 1: the document is not a 3MF model (its root is <svg>, not "
              "the core specification's <model>)");
    // One attribute of 8 MiB, which expat 2.5 would scan again with every MiB inflated.
    std::string wideTag = modelXml(meshObject(sphere, 1), R"(<item objectid="1"/>)");
    wideTag.insert(wideTag.find("<vertex x=\"") + 11, size_t(8) << 20, ' ');
    EXPECT_EQ(text(readTriangleMesh(threeMf(wideTag), ".3mf")),
              "3D/3dmodel.model, line 1: a tag, comment or other markup of more than 4 MiB");
    std::string nested;
    for (int k = 0; k < 100; ++k)
        nested += "<x>";
    EXPECT_EQ(read(nested), "3D/3dmodel.model, line 1: elements nested more than 64 deep");
    EXPECT_EQ(text(readTriangleMesh(threeMf(""), ".3mf")),
              "3D/3dmodel.model, line 1: no element found");
    // No model part where _rels/.rels says.
    const ZipEntry lonely[] = {{"3D/model.model", "<model/>"}};
    EXPECT_EQ(text(readTriangleMesh(zipArchive(lonely).value(), ".3mf")),
              "a 3MF without its model part (3D/3dmodel.model)");
    // A 3MF under another name does not reach Assimp's own 3MF reader.
    EXPECT_EQ(text(readTriangleMesh(good, ".zip")).rfind("not a mesh file that can be read", 0),
              0u);
    // A build of nothing.
    EXPECT_EQ(read(meshObject(sphere, 1), ""), "no triangles");
}

// A 3MF package as slicers write their projects: the root model where _rels/.rels says, and
// `parts` (name without its leading '/', contents) that its p:path attributes name, listed in the
// root's own relationships.
std::string threeMfProject(const std::string& root,
                           const std::vector<std::pair<std::string, std::string>>& parts) {
    std::string rels = R"(<?xml version="1.0" encoding="UTF-8"?>
<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">)";
    for (size_t k = 0; k < parts.size(); ++k)
        rels += "<Relationship Target=\"/" + parts[k].first + "\" Id=\"rel" +
                std::to_string(k + 1) +
                "\" Type=\"http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\"/>";
    rels += "</Relationships>";
    std::vector<std::pair<std::string, std::string>> all = {
        {"_rels/.rels",
         R"(<?xml version="1.0" encoding="UTF-8"?>
<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">
 <Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>
</Relationships>)"},
        {"3D/_rels/3dmodel.model.rels", rels},
        {"3D/3dmodel.model", root}};
    all.insert(all.end(), parts.begin(), parts.end());
    std::vector<ZipEntry> entries;
    for (const auto& [name, data] : all)
        entries.push_back({name, data});
    return zipArchive(entries).value();
}

// The production extension's namespace and its requirement, as slicers declare them.
const std::string kProductionModel =
    R"(xmlns:p="http://schemas.microsoft.com/3dmanufacturing/production/2015/06" )"
    R"(requiredextensions="p" )";

// The largest distance of a position of `mesh` from a sphere of `radius` about the nearest of
// `centres`, relative to the radius; and how many positions each centre is nearest to.
std::pair<float, std::vector<size_t>>
offSpheres(const TriangleMesh& mesh, const std::vector<glm::vec3>& centres, float radius) {
    float worst = 0.0f;
    std::vector<size_t> count(centres.size());
    for (const glm::vec3& p : mesh.positions) {
        size_t best = 0;
        for (size_t k = 1; k < centres.size(); ++k)
            if (glm::length(p - centres[k]) < glm::length(p - centres[best])) best = k;
        ++count[best];
        worst = std::max(worst, std::abs(glm::length(p - centres[best]) - radius) / radius);
    }
    return {worst, count};
}

// A project of several model parts, as Bambu Studio, Orca and PrusaSlicer write them: the root
// model's objects are components naming objects of /3D/Objects/object_1.model by p:path, one of
// them twice, and a build item names one there directly. The part is read once, its ids its own
// (object 1 is another in the root), its build ignored, and its millimetres are tenths of a scene
// unit.
TEST(MeshField, ThreeMfPartsOfAProject) {
    const TriangleMesh sphere = triangles(icosphere(2));
    const std::string objects = modelXml(
        meshObject(sphere, 1) + R"(<object id="2"><components><component objectid="1" )"
                                R"(transform="1 0 0 0 1 0 0 0 1 5 0 0"/></components></object>)",
        R"(<item objectid="1" transform="1 0 0 0 1 0 0 0 1 -50 0 0"/>)", "millimeter",
        kProductionModel);
    TriangleMesh big = sphere; // the root's own object 1, of radius 3
    for (glm::vec3& p : big.positions)
        p *= 3.0f;
    const std::string root =
        modelXml(meshObject(big, 1) +
                     R"(<object id="3" p:UUID="00000003-61cb-4c03-9d28-80fed5dfa1dc" type="model">)"
                     R"(<components>)"
                     R"(<component p:path="/3D/Objects/object_1.model" objectid="1" )"
                     R"(transform="1 0 0 0 1 0 0 0 1 0 0 10"/>)"
                     R"(<component p:path="/3D/Objects/object_1.model" objectid="2"/>)"
                     R"(<component objectid="1" transform="1 0 0 0 1 0 0 0 1 0 10 0"/>)"
                     R"(</components></object>)",
                 R"(<item objectid="3" transform="1 0 0 0 1 0 0 0 1 100 0 0" printable="1"/>)"
                 R"(<item p:path="/3d/objects/OBJECT_1.model" objectid="1" )"
                 R"(transform="1 0 0 0 1 0 0 0 1 0 0 -20"/>)",
                 "millimeter", kProductionModel);
    const std::string file = threeMfProject(root, {{"3D/Objects/object_1.model", objects}});
    const auto read = readTriangleMesh(file, ".3mf");
    ASSERT_TRUE(read) << read.error().str();
    EXPECT_EQ(read->triangles.size(), 4 * sphere.triangles.size());
    // In the file's millimetres the small spheres are about (100, 0, 10), (105, 0, 0) and
    // (0, 0, -20), the big one about (100, 10, 0); in scene units, tenths of those turned y up.
    const std::vector<glm::vec3> small = {
        {10.0f, 1.0f, 0.0f}, {10.5f, 0.0f, 0.0f}, {0.0f, -2.0f, 0.0f}};
    TriangleMesh smalls, bigs;
    for (const glm::vec3& p : read->positions)
        (glm::length(p - glm::vec3(10.0f, 0.0f, -1.0f)) < 0.5f ? bigs : smalls)
            .positions.push_back(p);
    const auto [offSmall, perSmall] = offSpheres(smalls, small, 0.1f);
    EXPECT_LT(offSmall, 1e-5f);
    EXPECT_EQ(perSmall, std::vector<size_t>(3, sphere.positions.size()));
    const auto [offBig, perBig] = offSpheres(bigs, {{10.0f, 0.0f, -1.0f}}, 0.3f);
    EXPECT_LT(offBig, 1e-5f);
    EXPECT_EQ(perBig[0], sphere.positions.size());
    // Read once: the parts' bytes together are all it may unpack, and one byte less is refused.
    const uint64_t bytes = root.size() + objects.size();
    EXPECT_TRUE(readThreeMf(file, {[](size_t) {}, [](glm::vec3, uint32_t) {}}, 10000, bytes, 10.0));
    EXPECT_EQ(readThreeMf(file, {}, 10000, bytes - 1, 10.0).error().diagnostics[0].message,
              "3D/Objects/object_1.model: the model parts unpack to more than " +
                  std::to_string(bytes - 1) + " bytes together");
    // A p:path naming the root itself is an object of the root.
    const auto itself =
        readTriangleMesh(threeMf(modelXml(meshObject(sphere, 1),
                                          R"(<item objectid="1" p:path="/3D/3dmodel.model"/>)",
                                          "centimeter", kProductionModel)),
                         ".3mf");
    ASSERT_TRUE(itself) << itself.error().str();
    EXPECT_EQ(itself->triangles.size(), sphere.triangles.size());
}

// Parts that cannot be read, each refused with where it was named and why.
TEST(MeshField, HostileThreeMfPartsAreRefused) {
    const TriangleMesh sphere = triangles(icosphere(1));
    auto text = [](const Result<TriangleMesh>& r) {
        return r ? std::string("read") : r.error().diagnostics[0].message;
    };
    // A root whose object 2 is object 1 of `path`, with `parts` in the package.
    auto read = [&](const std::string& path,
                    const std::vector<std::pair<std::string, std::string>>& parts) {
        const std::string root =
            modelXml(R"(<object id="2"><components><component objectid="1" p:path=")" + path +
                         R"("/></components></object>)",
                     R"(<item objectid="2"/>)", "millimeter", kProductionModel);
        return text(readTriangleMesh(threeMfProject(root, parts), ".3mf"));
    };
    const auto part = [&](const std::string& resources) {
        return modelXml(resources, "", "millimeter", kProductionModel);
    };
    const std::string good = part(meshObject(sphere, 1));
    ASSERT_EQ(read("/3D/Objects/a.model", {{"3D/Objects/a.model", good}}), "read");
    EXPECT_EQ(read("/3D/Objects/missing.model", {{"3D/Objects/a.model", good}}),
              "3D/3dmodel.model, line 1: a component's p:path \"/3D/Objects/missing.model\" "
              "naming a part the package does not hold");
    // Not a part of the package: relative, empty segments, a way up and out.
    for (const char* outside : {"3D/Objects/a.model", "../3D/Objects/a.model", "/3D//a.model",
                                "/3D/../3D/Objects/a.model", "//host/3D/Objects/a.model", "/"})
        EXPECT_EQ(read(outside, {{"3D/Objects/a.model", good}}),
                  "3D/3dmodel.model, line 1: a component's p:path \"" + std::string(outside) +
                      "\" that is not an absolute part name, such as "
                      "\"/3D/Objects/object_1.model\"");
    // Parts that are no models: a thumbnail, a slicer's settings.
    EXPECT_EQ(read("/Metadata/plate_1.png", {{"Metadata/plate_1.png", "\x89PNG\r\n\x1a\n"}}),
              "3D/3dmodel.model, line 1: a component's p:path \"/Metadata/plate_1.png\" naming "
              "Metadata/plate_1.png, which is not a 3MF model part (line 1: not well-formed "
              "(invalid token))");
    EXPECT_EQ(read("/Metadata/model_settings.config",
                   {{"Metadata/model_settings.config", "<config><object id=\"1\"/></config>"}}),
              "3D/3dmodel.model, line 1: a component's p:path \"/Metadata/model_settings.config\" "
              "naming Metadata/model_settings.config, which is not a 3MF model part (line 1: the "
              "document is not a 3MF model (its root is <config>, not the core specification's "
              "<model>))");
    // An object the part does not define, and a part at fault itself, named as it is.
    EXPECT_EQ(read("/3D/Objects/a.model", {{"3D/Objects/a.model", part(meshObject(sphere, 3))}}),
              "3D/3dmodel.model, line 1: a component names object 1 of /3D/Objects/a.model, "
              "which defines none");
    EXPECT_EQ(read("/3D/Objects/a.model",
                   {{"3D/Objects/a.model",
                     part(R"(<object id="1"><mesh><vertices><vertex x="0" y="0" z="0"/>)"
                          R"(</vertices><triangles><triangle v1="0" v2="0" v3="1"/>)"
                          R"(</triangles></mesh></object>)")}}),
              "3D/Objects/a.model, line 1: a triangle's v3 (1) past its object's 1 vertices");
    // A part damaged in its package: its CRC (the last entry's, so the directory's last).
    std::string damaged =
        threeMfProject(modelXml(R"(<object id="2"><components><component objectid="1" )"
                                R"(p:path="/3D/Objects/a.model"/></components></object>)",
                                R"(<item objectid="2"/>)", "millimeter", kProductionModel),
                       {{"3D/Objects/a.model", good}});
    const size_t last = damaged.rfind(std::string("PK\1\2", 4));
    ASSERT_NE(last, std::string::npos);
    damaged[last + 16] = char(~damaged[last + 16]);
    EXPECT_EQ(text(readTriangleMesh(damaged, ".3mf")),
              "3D/Objects/a.model is damaged: its CRC-32 does not match");
    // Parts naming parts, which the production extension forbids: nested, or in a cycle.
    const std::string nested = part(R"(<object id="1"><components><component objectid="1" )"
                                    R"(p:path="/3D/Objects/b.model"/></components></object>)");
    EXPECT_EQ(
        read("/3D/Objects/a.model", {{"3D/Objects/a.model", nested}, {"3D/Objects/b.model", good}}),
        "3D/Objects/a.model, line 1: a component's p:path \"/3D/Objects/b.model\" outside "
        "the root model (3D/3dmodel.model), which the production extension forbids");
    const std::string cycle =
        part(meshObject(sphere, 2) + R"(<object id="1"><components><component objectid="2" )"
                                     R"(p:path="/3D/3dmodel.model"/></components></object>)");
    EXPECT_EQ(read("/3D/Objects/a.model", {{"3D/Objects/a.model", cycle}}),
              "3D/Objects/a.model, line 1: a component's p:path \"/3D/3dmodel.model\" outside the "
              "root model (3D/3dmodel.model), which the production extension forbids");
    // Components nested deeper than 32 across parts: 31 in the part, 2 more in the root.
    std::string deep = meshObject(sphere, 100);
    for (int id = 101; id <= 131; ++id)
        deep += "<object id=\"" + std::to_string(id) + "\"><components><component objectid=\"" +
                std::to_string(id - 1) + "\"/></components></object>";
    EXPECT_EQ(read("/3D/Objects/a.model",
                   {{"3D/Objects/a.model",
                     part(deep + R"(<object id="1"><components><component objectid="131"/>)"
                                 R"(</components></object>)")}}),
              "3D/3dmodel.model, line 1: components nested more than 32 deep");
}

// The model's unit: a scene unit is a centimetre, as sdfcsg writes 3MF by default, so a file in
// inches comes in 2.54 units a unit; a part in another unit than the root's is converted to it.
TEST(MeshField, ThreeMfUnits) {
    const TriangleMesh sphere = triangles(icosphere(2));
    const std::pair<const char*, float> units[] = {{"micron", 1e-4f},    {"millimeter", 0.1f},
                                                   {"centimeter", 1.0f}, {"inch", 2.54f},
                                                   {"foot", 30.48f},     {"meter", 100.0f}};
    for (const auto& [unit, scale] : units) {
        SCOPED_TRACE(unit);
        const auto read = readTriangleMesh(
            threeMf(modelXml(meshObject(sphere, 1),
                             R"(<item objectid="1" transform="1 0 0 0 1 0 0 0 1 2 0 0"/>)", unit)),
            ".3mf");
        ASSERT_TRUE(read) << read.error().str();
        EXPECT_LT(offSpheres(*read, {{2.0f * scale, 0.0f, 0.0f}}, scale).first, 1e-5f);
    }
    // Absent: millimetres, the specification's default.
    std::string none = modelXml(meshObject(sphere, 1), R"(<item objectid="1"/>)");
    none.erase(none.find("unit=\"centimeter\""), 17);
    const auto inMillimetres = readTriangleMesh(threeMf(none), ".3mf");
    ASSERT_TRUE(inMillimetres) << inMillimetres.error().str();
    EXPECT_LT(offSpheres(*inMillimetres, {glm::vec3(0.0f)}, 0.1f).first, 1e-5f);
    // A root in inches placing a part's millimetres one inch along x: 2.54 units, radius 0.1.
    const std::string root =
        modelXml(R"(<object id="2"><components><component objectid="1" )"
                 R"(p:path="/3D/Objects/a.model" transform="1 0 0 0 1 0 0 0 1 1 0 0"/>)"
                 R"(</components></object>)",
                 R"(<item objectid="2"/>)", "inch", kProductionModel);
    const auto mixed = readTriangleMesh(
        threeMfProject(root,
                       {{"3D/Objects/a.model", modelXml(meshObject(sphere, 1), "", "millimeter")}}),
        ".3mf");
    ASSERT_TRUE(mixed) << mixed.error().str();
    EXPECT_LT(offSpheres(*mixed, {{2.54f, 0.0f, 0.0f}}, 0.1f).first, 1e-5f);
    // What sdfcsg writes in each unit comes back at its printed size.
    Mesh ball = icosphere(2);
    for (LengthUnit unit : {LengthUnit::Millimeter, LengthUnit::Centimeter, LengthUnit::Inch}) {
        const auto back = readTriangleMesh(encodeMesh(ball, MeshFormat::ThreeMf, unit), ".3mf");
        ASSERT_TRUE(back) << back.error().str();
        const float radius = float(millimetres(unit) / 10.0);
        EXPECT_LT(offSpheres(*back, {glm::vec3(0.0f)}, radius).first, 1e-5f);
    }
    EXPECT_EQ(
        readTriangleMesh(
            threeMf(modelXml(meshObject(sphere, 1), R"(<item objectid="1"/>)", "furlong")), ".3mf")
            .error()
            .diagnostics[0]
            .message,
        "3D/3dmodel.model, line 1: a model unit \"furlong\" that is not micron, millimeter, "
        "centimeter, inch, foot or meter");
}

// Extensions: those a model requires are read or the model refused; any other's elements are
// skipped, wherever they are (3MF Core 2.3.1).
TEST(MeshField, ThreeMfExtensions) {
    const TriangleMesh sphere = triangles(icosphere(1));
    auto text = [](const Result<TriangleMesh>& r) {
        return r ? std::string("read") : r.error().diagnostics[0].message;
    };
    const std::string beams =
        R"(xmlns:b="http://schemas.microsoft.com/3dmanufacturing/beamlattice/2017/02" )";
    const std::string slices =
        R"(xmlns:s="http://schemas.microsoft.com/3dmanufacturing/slice/2015/07" )";
    auto read = [&](const std::string& more, const std::string& resources) {
        return text(readTriangleMesh(
            threeMf(modelXml(resources, R"(<item objectid="1"/>)", "centimeter", more)), ".3mf"));
    };
    const std::string ball = meshObject(sphere, 1);
    EXPECT_EQ(read(R"(requiredextensions=" m " )", ball), "read");
    EXPECT_EQ(read(beams + R"(requiredextensions="m b" )", ball),
              "3D/3dmodel.model, line 1: a model that requires an extension that is not read, "
              "\"http://schemas.microsoft.com/3dmanufacturing/beamlattice/2017/02\" (of those, "
              "only materials and production are)");
    EXPECT_EQ(read(R"(requiredextensions="sc" )", ball),
              "3D/3dmodel.model, line 1: a model that requires the extension of prefix \"sc\", "
              "which it does not declare");
    // Not required: a slice stack among the resources, a beam lattice in the mesh, elements of
    // no known namespace among the vertices and triangles and in the build, all skipped.
    std::string lattice = ball;
    lattice.insert(lattice.find("</mesh>"),
                   R"(<b:beamlattice radius="1"><b:beams><b:beam v1="0" v2="9999"/></b:beams>)"
                   R"(</b:beamlattice>)");
    lattice.insert(lattice.find("<vertex "), R"(<x:vertex x="nan" y="0" z="0"/>)");
    lattice.insert(lattice.find("<triangle "), R"(<x:triangle v1="0" v2="1" v3="99999"/>)");
    const auto skipped = readTriangleMesh(
        threeMf(modelXml(R"(<s:slicestack id="7"><s:slice ztop="1"/></s:slicestack>)" + lattice,
                         R"(<x:item objectid="99"/><item objectid="1"/>)", "centimeter",
                         beams + slices + R"(xmlns:x="urn:example:unknown" )")),
        ".3mf");
    ASSERT_TRUE(skipped) << skipped.error().str();
    EXPECT_EQ(skipped->triangles.size(), sphere.triangles.size());
    EXPECT_EQ(skipped->positions.size(), sphere.positions.size());
}

} // namespace
} // namespace sdfcsg::detail
