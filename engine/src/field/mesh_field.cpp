// A mesh's signed distance field (mesh_field.h).
#include "field/mesh_field.h"

#include "field/read_3mf.h"
#include "mesh/radix_sort.h"
#include "scene/files.h"
#include "scene/json_writer.h"
#include "scene/parse_util.h"
#include "sdfcsg/export.h"

#include <assimp/BaseImporter.h>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <assimp/MemoryIOWrapper.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vector_relational.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <numbers>
#include <optional>
#include <thread>
#include <tuple>
#include <utility>

namespace sdfcsg::detail {

namespace {

using glm::vec3;

Error reason(std::string text) {
    return Error::message(ErrorKind::Validation, {}, std::move(text));
}

uint32_t read32(const std::string& s, size_t at) {
    uint32_t v = 0;
    for (int i = 3; i >= 0; --i)
        v = (v << 8) | uint8_t(s[at + size_t(i)]);
    return v;
}

// The squared distance from p to the triangle abc, and which feature of it is nearest: 0, 1, 2
// its corners, 3, 4, 5 its edges ab, bc, ca, 6 its face (Ericson, Real-Time Collision Detection,
// 5.1.5).
struct Nearest {
    float distance2;
    int feature;
    vec3 point;
};
Nearest nearestOnTriangle(vec3 p, vec3 a, vec3 b, vec3 c) {
    const auto at = [&](vec3 q, int feature) {
        return Nearest{glm::dot(p - q, p - q), feature, q};
    };
    const vec3 ab = b - a, ac = c - a, ap = p - a;
    const float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0.0f && d2 <= 0.0f) return at(a, 0);
    const vec3 bp = p - b;
    const float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0.0f && d4 <= d3) return at(b, 1);
    const float vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return at(a + ab * (d1 / (d1 - d3)), 3);
    const vec3 cp = p - c;
    const float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0.0f && d5 <= d6) return at(c, 2);
    const float vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return at(a + ac * (d2 / (d2 - d6)), 5);
    const float va = d3 * d6 - d5 * d4;
    if (va <= 0.0f && d4 - d3 >= 0.0f && d5 - d6 >= 0.0f)
        return at(b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))), 4);
    const float sum = va + vb + vc;
    return sum > 0.0f ? at(a + ab * (vb / sum) + ac * (vc / sum), 6) : at(a, 0);
}

// The barycentric coordinates of q, a point of the triangle abc; a degenerate triangle's, its
// first corner's.
vec3 barycentric(vec3 q, vec3 a, vec3 b, vec3 c) {
    const vec3 ab = b - a, ac = c - a, aq = q - a;
    const float d00 = glm::dot(ab, ab), d01 = glm::dot(ab, ac), d11 = glm::dot(ac, ac);
    const float d20 = glm::dot(aq, ab), d21 = glm::dot(aq, ac);
    const float det = d00 * d11 - d01 * d01;
    if (!(det > 0.0f)) return {1.0f, 0.0f, 0.0f};
    const float v = std::clamp((d11 * d20 - d01 * d21) / det, 0.0f, 1.0f),
                w = std::clamp((d00 * d21 - d01 * d20) / det, 0.0f, 1.0f - v);
    return {1.0f - v - w, v, w};
}

// ---- A hierarchy of triangles: boxes for the nearest triangle, dipoles for the winding ----

struct Box {
    vec3 lo{INFINITY}, hi{-INFINITY};
    void add(vec3 p) { lo = glm::min(lo, p), hi = glm::max(hi, p); }
    float distance2(vec3 p) const {
        const vec3 d = glm::max(glm::max(lo - p, p - hi), vec3(0.0f));
        return glm::dot(d, d);
    }
};

class Hierarchy {
  public:
    explicit Hierarchy(const TriangleMesh& mesh) : mesh_(mesh) {
        const size_t n = mesh.triangles.size();
        order_.resize(n);
        centres_.resize(n);
        for (size_t t = 0; t < n; ++t) {
            order_[t] = uint32_t(t);
            centres_[t] = (corner(t, 0) + corner(t, 1) + corner(t, 2)) / 3.0f;
        }
        nodes_.reserve(2 * n / kLeaf + 2);
        build(0, uint32_t(n));
    }

    // The generalised winding number at p.
    float winding(vec3 p) const {
        double sum = 0.0;
        uint32_t stack[64];
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& n = nodes_[stack[--top]];
            const vec3 r = n.centre - p;
            const float d = glm::length(r);
            if (d > kFar * n.radius) { // the cluster as a dipole
                sum += double(glm::dot(n.normal, r)) / (double(d) * d * d);
                continue;
            }
            if (n.count > 0) {
                for (uint32_t k = n.first; k < n.first + n.count; ++k)
                    sum += solidAngle(p, order_[k]);
                continue;
            }
            stack[top++] = n.left;
            stack[top++] = n.right;
        }
        return float(sum / (4.0 * std::numbers::pi));
    }

  private:
    static constexpr uint32_t kLeaf = 4;
    // A cluster farther than this many of its radii counts as a dipole: the order-1 expansion
    // errs by about (radius / distance)^2 of the cluster's own solid angle.
    static constexpr float kFar = 2.5f;

    struct Node {
        Box box;
        vec3 centre{0.0f}, normal{0.0f}; // area-weighted centroid; sum of area times unit normal
        float radius = 0.0f;             // from centre to the box's farthest corner
        uint32_t first = 0, count = 0;   // a leaf's triangles: [first, first + count)
        uint32_t left = 0, right = 0;    // an inner node's children
    };

    vec3 corner(size_t t, int c) const { return mesh_.positions[mesh_.triangles[t][c]]; }

    uint32_t build(uint32_t begin, uint32_t end) {
        const uint32_t index = uint32_t(nodes_.size());
        nodes_.emplace_back();
        Box box, centres;
        vec3 normal(0.0f), weighted(0.0f);
        float area = 0.0f;
        for (uint32_t k = begin; k < end; ++k) {
            const size_t t = order_[k];
            const vec3 a = corner(t, 0), b = corner(t, 1), c = corner(t, 2);
            box.add(a), box.add(b), box.add(c);
            centres.add(centres_[t]);
            const vec3 n = 0.5f * glm::cross(b - a, c - a);
            const float ta = glm::length(n);
            normal += n;
            weighted += ta * centres_[t];
            area += ta;
        }
        Node node;
        node.box = box;
        node.normal = normal;
        node.centre = area > 0.0f ? weighted / area : 0.5f * (box.lo + box.hi);
        node.radius =
            glm::length(glm::max(glm::abs(box.hi - node.centre), glm::abs(box.lo - node.centre)));
        if (end - begin <= kLeaf) {
            node.first = begin, node.count = end - begin;
            nodes_[index] = node;
            return index;
        }
        const vec3 extent = centres.hi - centres.lo;
        const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0
                         : extent.y >= extent.z                       ? 1
                                                                      : 2;
        const uint32_t mid = begin + (end - begin) / 2;
        std::nth_element(
            order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
            [&](uint32_t a, uint32_t b) { return centres_[a][axis] < centres_[b][axis]; });
        node.left = build(begin, mid);
        node.right = build(mid, end);
        nodes_[index] = node; // after the children: they may have moved the array
        return index;
    }

    // The solid angle the triangle subtends at p, signed (Van Oosterom and Strackee 1983).
    double solidAngle(vec3 p, size_t t) const {
        const glm::dvec3 a = glm::dvec3(corner(t, 0) - p), b = glm::dvec3(corner(t, 1) - p),
                         c = glm::dvec3(corner(t, 2) - p);
        const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
        const double det = glm::dot(a, glm::cross(b, c));
        const double div =
            la * lb * lc + glm::dot(a, b) * lc + glm::dot(a, c) * lb + glm::dot(b, c) * la;
        return 2.0 * std::atan2(det, div);
    }

    const TriangleMesh& mesh_;
    std::vector<uint32_t> order_;
    std::vector<vec3> centres_;
    std::vector<Node> nodes_;
};

// The triangles' edges, 3 t + e for the edge from corner e to corner e + 1 of triangle t, ordered
// by the two vertices they join, so that the edges between one pair of vertices make a run: a
// counting sort by the lesser vertex, then each vertex's few edges sorted by the greater. Edges
// from a vertex to itself are left out.
uint64_t edgeKey(const TriangleMesh& mesh, uint32_t edge) {
    const glm::uvec3& t = mesh.triangles[edge / 3];
    const uint32_t u = t[int(edge % 3)], v = t[int(edge % 3 + 1) % 3];
    return (uint64_t(std::min(u, v)) << 32) | std::max(u, v);
}
std::vector<uint32_t> edgesInPairs(const TriangleMesh& mesh) {
    std::vector<uint32_t> start(mesh.positions.size() + 1, 0);
    const uint32_t edges = uint32_t(3 * mesh.triangles.size());
    const auto lesser = [&](uint32_t e) { return uint32_t(edgeKey(mesh, e) >> 32); };
    const auto loop = [&](uint32_t e) { return uint32_t(edgeKey(mesh, e)) == lesser(e); };
    for (uint32_t e = 0; e < edges; ++e)
        if (!loop(e)) ++start[lesser(e) + 1];
    for (size_t v = 1; v < start.size(); ++v)
        start[v] += start[v - 1];
    std::vector<uint32_t> order(start.back());
    std::vector<uint32_t> next(start.begin(), start.end() - 1);
    for (uint32_t e = 0; e < edges; ++e)
        if (!loop(e)) order[next[lesser(e)]++] = e;
    for (size_t v = 0; v + 1 < start.size(); ++v)
        std::sort(order.begin() + start[v], order.begin() + start[v + 1],
                  [&](uint32_t a, uint32_t b) { return edgeKey(mesh, a) < edgeKey(mesh, b); });
    return order;
}

// Calls run(first, last) for each run of `order` (edgesInPairs) along one pair of vertices.
template <class Run>
void forEachPair(const TriangleMesh& mesh, const std::vector<uint32_t>& order, Run&& run) {
    for (size_t k = 0; k < order.size();) {
        size_t end = k + 1;
        while (end < order.size() && edgeKey(mesh, order[end]) == edgeKey(mesh, order[k]))
            ++end;
        run(k, end);
        k = end;
    }
}

MeshDefects countDefects(const TriangleMesh& mesh, const std::vector<uint32_t>& pairs) {
    MeshDefects d;
    for (const glm::uvec3& t : mesh.triangles) {
        const vec3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
        if (glm::length(glm::cross(b - a, c - a)) == 0.0f) ++d.degenerate;
    }
    forEachPair(mesh, pairs, [&](size_t first, size_t last) {
        // How many of the pair's edges run from its lesser vertex to its greater.
        size_t forward = 0;
        for (size_t k = first; k < last; ++k) {
            const glm::uvec3& t = mesh.triangles[pairs[k] / 3];
            forward += t[int(pairs[k] % 3)] < t[int(pairs[k] % 3 + 1) % 3];
        }
        const size_t n = last - first;
        if (n == 1)
            ++d.openEdges;
        else if (n > 2)
            ++d.crowdedEdges;
        else if (forward != 1)
            ++d.flippedEdges;
    });
    return d;
}

// The angle-weighted pseudonormals of a closed, consistently oriented mesh (Baerentzen and Aanaes
// 2005): at the feature of the mesh nearest to p (a face, an edge or a corner), p lies outside
// exactly where it is on the side its pseudonormal points to.
struct Pseudonormals {
    std::vector<vec3> corners;              // per vertex: angle-weighted sum of face normals
    std::vector<std::array<vec3, 3>> edges; // per triangle, edges ab, bc, ca: the two faces' sum
    std::vector<vec3> faces;

    Pseudonormals() = default;
    // `pairs`: the mesh's edgesInPairs.
    Pseudonormals(const TriangleMesh& mesh, const std::vector<uint32_t>& pairs)
        : corners(mesh.positions.size(), vec3(0.0f)), edges(mesh.triangles.size()),
          faces(mesh.triangles.size()) {
        for (size_t t = 0; t < mesh.triangles.size(); ++t) {
            const glm::uvec3 i = mesh.triangles[t];
            const vec3 p[3] = {mesh.positions[i.x], mesh.positions[i.y], mesh.positions[i.z]};
            const vec3 n = glm::cross(p[1] - p[0], p[2] - p[0]);
            faces[t] = glm::length(n) > 0.0f ? glm::normalize(n) : vec3(0.0f);
            for (int c = 0; c < 3; ++c) {
                const vec3 e1 = p[(c + 1) % 3] - p[c], e2 = p[(c + 2) % 3] - p[c];
                const float l = glm::length(e1) * glm::length(e2);
                const float angle =
                    l > 0.0f ? std::acos(glm::clamp(glm::dot(e1, e2) / l, -1.0f, 1.0f)) : 0.0f;
                corners[i[c]] += angle * faces[t];
            }
        }
        forEachPair(mesh, pairs, [&](size_t first, size_t last) {
            vec3 sum(0.0f);
            for (size_t k = first; k < last; ++k)
                sum += faces[pairs[k] / 3];
            for (size_t k = first; k < last; ++k)
                edges[pairs[k] / 3][pairs[k] % 3] = sum;
        });
    }

    vec3 at(const TriangleMesh& mesh, uint32_t t, int feature) const {
        return feature < 3   ? corners[mesh.triangles[t][feature]]
               : feature < 6 ? edges[t][feature - 3]
                             : faces[t];
    }
};

// Runs body(i) for i in [0, count) on every core.
template <class Body> void parallelFor(size_t count, Body&& body) {
    const unsigned threads = std::max(1u, std::min(std::thread::hardware_concurrency(), 16u));
    std::atomic<size_t> next{0};
    auto work = [&] {
        for (size_t i; (i = next.fetch_add(1)) < count;)
            body(i);
    };
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < threads; ++t)
        pool.emplace_back(work);
    work();
    for (std::thread& t : pool)
        t.join();
}

// The files that a mesh file names (a glTF's buffers, an OBJ's materials), read under the rule
// of an untrusted scene in the mesh file's folder whatever the scene's own rule: a file from
// elsewhere must not reach the rest of the file system by the names it holds, nor block on a
// device. At most kMaxMeshFileBytes in all; a file refused is one that does not exist.
class FolderFiles : public Assimp::IOSystem {
  public:
    explicit FolderFiles(std::filesystem::path folder) : files_{std::move(folder), false} {}
    bool Exists(const char* name) const override {
        return bool(sceneFile(name, files_, kMaxMeshFileBytes));
    }
    char getOsSeparator() const override { return '/'; }
    Assimp::IOStream* Open(const char* name, const char* mode) override {
        if (std::strpbrk(mode, "wa+")) return nullptr;
        const auto file = sceneFile(name, files_, kMaxMeshFileBytes - read_);
        if (!file) return nullptr;
        const auto bytes = readFileBytes(*file, kMaxMeshFileBytes - read_);
        if (!bytes) return nullptr;
        read_ += bytes->size();
        auto* copy = new uint8_t[bytes->size()];
        std::memcpy(copy, bytes->data(), bytes->size());
        return new Assimp::MemoryIOStream(copy, bytes->size(), true);
    }
    void Close(Assimp::IOStream* stream) override { delete stream; }

  private:
    SceneFiles files_;
    uintmax_t read_ = 0;
};

uint32_t packColor(vec3 c) {
    const glm::uvec3 b = glm::uvec3(glm::round(glm::clamp(c, 0.0f, 1.0f) * 255.0f));
    return b.r << 16 | b.g << 8 | b.b;
}

// glTF's colours are linear: to sRGB (IEC 61966-2-1), as scene colours are, the inverse of what
// the exporter does.
vec3 linearToSrgb(vec3 c) {
    vec3 out;
    for (int k = 0; k < 3; ++k) {
        const float v = std::clamp(c[k], 0.0f, 1.0f);
        out[k] = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
    }
    return out;
}

// Material `index` of the scene's colour where it is one the file gives (an OBJ's Kd, a glTF's
// baseColorFactor), as 0xRRGGBB: not Assimp's default material (named so; a glTF's is the last,
// which the triangles without a material take), nor one whose colour multiplies a texture, which
// is not read. An OBJ material that its .mtl lacks (or whose .mtl is missing) gets Assimp's
// default grey, 0.6: that grey counts as no colour in an OBJ.
uint32_t materialColor(const aiScene& scene, unsigned index, bool linear) {
    if (index >= scene.mNumMaterials || (linear && index + 1 == scene.mNumMaterials))
        return kNoColor;
    const aiMaterial& m = *scene.mMaterials[index];
    aiString name;
    m.Get(AI_MATKEY_NAME, name);
    if (std::strcmp(name.C_Str(), AI_DEFAULT_MATERIAL_NAME) == 0) return kNoColor;
    if (m.GetTextureCount(aiTextureType_DIFFUSE) + m.GetTextureCount(aiTextureType_BASE_COLOR) > 0)
        return kNoColor;
    aiColor4D c;
    if (m.Get(AI_MATKEY_BASE_COLOR, c) != AI_SUCCESS &&
        m.Get(AI_MATKEY_COLOR_DIFFUSE, c) != AI_SUCCESS)
        return kNoColor;
    const vec3 rgb(c.r, c.g, c.b);
    if (!linear && rgb == vec3(0.6f)) return kNoColor;
    return packColor(linear ? linearToSrgb(rgb) : rgb);
}

} // namespace

Result<TriangleMesh> readTriangleMesh(const std::string& bytes, const std::string& extension,
                                      const std::filesystem::path& folder) {
    std::string hint =
        extension.size() > 1 && extension[0] == '.' ? extension.substr(1) : extension;
    std::transform(hint.begin(), hint.end(), hint.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    // One vertex per position across the file's meshes, so that edges between them are shared:
    // the corners sorted by position, each run of equal ones made one vertex.
    struct Corner {
        vec3 p;
        uint32_t at; // triangle * 3 + corner
    };
    std::vector<Corner> corners;
    std::vector<uint32_t> colors; // per corner
    bool colored = false;
    const bool zUp = hint == "stl" || hint == "3mf";
    const bool linear = hint == "gltf" || hint == "glb", materials = linear || hint == "obj";
    const auto add = [&](float x, float y, float z) {
        if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) return false;
        // The printing formats build along z: their z is the scene's y.
        corners.push_back(
            {(zUp ? vec3(x, z, -y) : vec3(x, y, z)) + 0.0f, uint32_t(corners.size())});
        return true;
    };
    const auto tooMany = [](size_t faces) {
        return reason("more than " + std::to_string(kMaxMeshTriangles) + " triangles (" +
                      std::to_string(faces) + ")");
    };
    // A binary STL (an 80-byte header, the triangle count, then 50 bytes per triangle: a normal,
    // three corners, two attribute bytes), the most common mesh file and the one sdfcsg writes,
    // is read here: through Assimp it takes four times as long as the whole field. Those with
    // colours (a triangle's attribute with its top bit set) go to Assimp, which reads them.
    const size_t stlFaces = bytes.size() >= 84 ? read32(bytes, 80) : 0;
    bool plainStl = hint == "stl" && bytes.size() == 84 + 50 * stlFaces;
    for (size_t f = 0; plainStl && f < stlFaces; ++f)
        plainStl = (uint8_t(bytes[84 + 50 * f + 49]) & 0x80) == 0;
    if (hint == "3mf") {
        // Read here: Assimp 5.2 gives each 3MF object one material whatever its triangles say.
        const ThreeMfCorners out{[&](size_t faces) {
                                     corners.reserve(3 * faces);
                                     colors.reserve(3 * faces);
                                 },
                                 [&](vec3 p, uint32_t color) {
                                     add(p.x, p.y, p.z); // finite, as the reader checks
                                     colors.push_back(color);
                                     colored = colored || color != kNoColor;
                                 }};
        if (const Status read = readThreeMf(bytes, out, kMaxMeshTriangles, 4 * kMaxMeshFileBytes,
                                            millimetres(kDefaultLengthUnit));
            !read)
            return read.error();
    } else if (plainStl) {
        if (stlFaces > kMaxMeshTriangles) return tooMany(stlFaces);
        corners.reserve(3 * stlFaces);
        for (size_t f = 0; f < stlFaces; ++f)
            for (size_t c = 0; c < 3; ++c) {
                float v[3];
                std::memcpy(v, bytes.data() + 84 + 50 * f + 12 * (c + 1), sizeof v);
                if (!add(v[0], v[1], v[2])) return reason("a NaN or infinite vertex");
            }
    } else {
        Assimp::Importer importer;
        importer.SetIOHandler(new FolderFiles(folder)); // the importer's to delete
        // Nor does a 3MF under another name reach Assimp's, which unpacks a ZIP's entries whole.
        if (Assimp::BaseImporter* threeMf = importer.GetImporter("3mf");
            threeMf && importer.UnregisterLoader(threeMf) == AI_SUCCESS)
            delete threeMf;
        const aiScene* scene = importer.ReadFileFromMemory(
            bytes.data(), bytes.size(), aiProcess_Triangulate | aiProcess_PreTransformVertices,
            hint.c_str());
        if (!scene)
            return reason("not a mesh file that can be read: " +
                          std::string(importer.GetErrorString()));
        size_t faces = 0;
        for (unsigned m = 0; m < scene->mNumMeshes; ++m)
            faces += scene->mMeshes[m]->mNumFaces;
        if (faces > kMaxMeshTriangles) return tooMany(faces);
        corners.reserve(3 * faces);
        colors.reserve(3 * faces);
        for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
            const aiMesh& part = *scene->mMeshes[m];
            const aiColor4D* vertexColors = part.mColors[0];
            const uint32_t material =
                materials ? materialColor(*scene, part.mMaterialIndex, linear) : kNoColor;
            colored = colored || vertexColors || material != kNoColor;
            for (unsigned f = 0; f < part.mNumFaces; ++f) {
                const aiFace& face = part.mFaces[f];
                if (face.mNumIndices != 3) continue;
                for (int c = 0; c < 3; ++c) {
                    const aiVector3D& v = part.mVertices[face.mIndices[c]];
                    uint32_t color = material;
                    if (vertexColors) {
                        const aiColor4D& k = vertexColors[face.mIndices[c]];
                        const vec3 rgb(k.r, k.g, k.b);
                        color = std::isfinite(k.r + k.g + k.b)
                                    ? packColor(linear ? linearToSrgb(rgb) : rgb)
                                    : kNoColor;
                    }
                    if (!add(v.x, v.y, v.z)) return reason("a NaN or infinite vertex");
                    colors.push_back(color);
                }
            }
        }
    }
    // Sorted by the bits of x and y (a radix sort), then each run of equal ones by z's: equal
    // positions have equal bits, zeros made positive when added.
    const auto bits = [](float v) {
        uint32_t u;
        std::memcpy(&u, &v, sizeof u);
        return u;
    };
    radixSort(corners, 0, 64,
              [&](const Corner& c) { return uint64_t(bits(c.p.x)) << 32 | bits(c.p.y); });
    for (size_t from = 0, to; from < corners.size(); from = to) {
        for (to = from + 1; to < corners.size() && corners[to].p.x == corners[from].p.x &&
                            corners[to].p.y == corners[from].p.y;)
            ++to;
        std::sort(corners.begin() + long(from), corners.begin() + long(to),
                  [&](const Corner& a, const Corner& b) { return bits(a.p.z) < bits(b.p.z); });
    }
    TriangleMesh mesh;
    mesh.triangles.resize(corners.size() / 3);
    for (size_t k = 0; k < corners.size(); ++k) {
        if (k == 0 || corners[k].p != corners[k - 1].p) mesh.positions.push_back(corners[k].p);
        mesh.triangles[corners[k].at / 3][corners[k].at % 3] = uint32_t(mesh.positions.size() - 1);
    }
    if (mesh.triangles.empty()) return reason("no triangles");
    if (colored) mesh.colors = std::move(colors);
    return mesh;
}

MeshDefects meshDefects(const TriangleMesh& mesh) {
    return countDefects(mesh, edgesInPairs(mesh));
}

std::vector<float> windingNumbers(const TriangleMesh& mesh, const std::vector<glm::vec3>& points) {
    const Hierarchy h(mesh);
    std::vector<float> w(points.size());
    parallelFor(points.size(), [&](size_t i) { w[i] = h.winding(points[i]); });
    return w;
}

// Out to the margin by dilation: layer by layer, each sample next to one with its feature
// known takes the nearest of the features nearest to its 26 neighbours, or its own if nearer
// (the nearest feature of a point is also the nearest of the points between it and the
// surface, which lie near its neighbours). `best` and `nearest` hold each sample's squared
// distance and feature, exact within `reach`; `nearer(p, t, best2)` is the squared distance
// from p to feature t where it is below best2 (else best2 or more).
template <class Nearer>
void MeshField::dilate(const MeshField& f, const std::vector<uint32_t>& brickSlots, float reach,
                       float margin, std::vector<float>& best, std::vector<uint32_t>& nearest,
                       const Nearer& nearer) {
    constexpr uint32_t kNone = ~0u;
    const size_t brickCount = brickSlots.size(), sampleCount = brickCount * kBrickSamples;
    const auto brickBase = [&](size_t b) { return f.brickOfSlot(brickSlots[b]) * kBrick; };
    const auto pointAt = [&](glm::ivec3 g) { return f.origin_ + f.cell_ * vec3(g); };
    const auto local = [](int x, int y, int z) {
        return (size_t(z) * kBrickSide + size_t(y)) * kBrickSide + size_t(x);
    };
    // `offer`: the nearest feature of each sample of the front, those that became known with
    // one in the last layer (kNone elsewhere), which their neighbours take up; `touched`: whether
    // a sample has had a neighbour with one. Only the front's neighbours have new features to
    // take up, and only touched samples can become known: a layer visits those alone, not the
    // far samples that make most of the bricks and never change.
    std::vector<uint8_t> known(sampleCount, 0), touched(sampleCount, 0), reached(sampleCount, 0);
    std::vector<uint32_t> offer(sampleCount, kNone), fresh(sampleCount, kNone);
    // Per brick, sets of its samples as bits (x) in rows (y, z): the front, the touched not yet
    // known (a deeper layer may reach them), and those a layer visits.
    using Rows = std::array<uint16_t, kBrickSide * kBrickSide>;
    std::vector<Rows> front(brickCount, Rows{}), pending(brickCount, Rows{}), visits(brickCount);
    std::vector<uint8_t> moving(brickCount, 0); // whether a brick has a front or touched samples
    parallelFor(brickCount, [&](size_t b) {
        for (size_t s = 0; s < kBrickSamples; ++s) {
            const size_t at = b * kBrickSamples + s;
            if (!(best[at] < reach * reach)) continue;
            known[at] = 1, offer[at] = nearest[at];
            if (offer[at] != kNone) front[b][s / kBrickSide] |= uint16_t(1u << (s % kBrickSide));
        }
        moving[b] = std::any_of(front[b].begin(), front[b].end(), [](uint16_t r) { return r; });
    });
    constexpr size_t kNowhere = ~size_t(0);
    // Layers by distance, half a cell deep: a sample is known once it is nearer than the layer's
    // far side, when the samples between it and the surface are known.
    const float step = 0.5f * f.cell_;
    const int layers = int(std::ceil((margin - reach) / step)) + 4;
    for (int layer = 0; layer < layers; ++layer) {
        const float within = reach + float(layer + 1) * step;
        const float within2 = within >= margin ? INFINITY : within * within;
        std::atomic<bool> grew{false};
        parallelFor(brickCount, [&](size_t b) {
            const glm::ivec3 home = brickBase(b) / kBrick;
            // The first samples of this brick and the 26 about it (kNowhere: none stored).
            size_t around[27];
            bool stirred = false;
            for (int k = 0; k < 27; ++k) {
                const glm::ivec3 there = home + glm::ivec3(k % 3, k / 3 % 3, k / 9) - 1;
                const bool in = glm::all(glm::greaterThanEqual(there, glm::ivec3(0))) &&
                                glm::all(glm::lessThan(there, f.bricks_));
                const int32_t slot = in ? f.slots_[f.slotOf(there)] : kOutside;
                around[k] = slot >= 0 ? size_t(slot) : kNowhere;
                stirred = stirred || (slot >= 0 && moving[size_t(slot) / kBrickSamples]);
            }
            Rows& visit = visits[b];
            visit = Rows{};
            if (!stirred) return;
            // The front about the brick, one sample beyond its faces (11 x 11 rows of 11 bits),
            // as its samples read their neighbours (sampleAt below): the brick's own copy of
            // each sample it holds, else the one in from the neighbour's face. Then grown by a
            // sample along each axis: the samples next to it.
            constexpr int kAround = kBrickSide + 2;
            const auto frontRow = [&](int k, int y, int z) -> uint32_t {
                return around[k] == kNowhere ? 0u
                                             : front[around[k] / kBrickSamples][z * kBrickSide + y];
            };
            std::array<uint16_t, kAround * kAround> grown{};
            // Along one axis, place p of the 11 is sample l of the brick o (0, 1, 2: before, this,
            // after).
            const auto place = [](int p, int& o, int& l) {
                o = p == 0 ? 0 : p == kAround - 1 ? 2 : 1;
                l = p == 0 ? kBrick - 1 : p == kAround - 1 ? 1 : p - 1;
            };
            for (int pz = 0; pz < kAround; ++pz)
                for (int py = 0; py < kAround; ++py) {
                    int oy, ly, oz, lz;
                    place(py, oy, ly), place(pz, oz, lz);
                    const int k = 3 * oy + 9 * oz;
                    const uint32_t row = frontRow(k + 1, ly, lz) << 1 |
                                         (frontRow(k, ly, lz) >> (kBrick - 1) & 1u) |
                                         (frontRow(k + 2, ly, lz) >> 1 & 1u) << (kAround - 1);
                    grown[size_t(pz * kAround + py)] = uint16_t(row | row << 1 | row >> 1);
                }
            bool any = false;
            for (int z = 0; z <= kBrick; ++z)
                for (int y = 0; y <= kBrick; ++y) {
                    uint32_t row = 0;
                    for (int dz = 0; dz < 3; ++dz)
                        for (int dy = 0; dy < 3; ++dy)
                            row |= grown[size_t((z + dz) * kAround + y + dy)];
                    const size_t r = size_t(z * kBrickSide + y);
                    visit[r] = uint16_t((row >> 1 & 0x1ffu) | pending[b][r]);
                    any = any || visit[r];
                }
            if (!any) return;
            // A neighbour's sample, this brick's where it holds it (its copy of the faces it
            // shares), else the neighbouring brick's.
            const auto sampleAt = [&](glm::ivec3 l) {
                int k = 13;
                for (int a = 0, weight = 1; a < 3; ++a, weight *= 3)
                    if (l[a] < 0)
                        l[a] += kBrick, k -= weight;
                    else if (l[a] > kBrick)
                        l[a] -= kBrick, k += weight;
                return around[k] == kNowhere ? kNowhere : around[k] + local(l.x, l.y, l.z);
            };
            bool grows = false;
            for (int z = 0; z <= kBrick; ++z)
                for (int y = 0; y <= kBrick; ++y) {
                    uint16_t& row = visit[size_t(z * kBrickSide + y)];
                    for (int x = 0; x <= kBrick; ++x) {
                        const size_t at = b * kBrickSamples + local(x, y, z);
                        if (!(row >> x & 1u)) continue;
                        if (known[at]) {
                            row = uint16_t(row & ~(1u << x));
                            continue;
                        }
                        const bool inside =
                            x > 0 && x < kBrick && y > 0 && y < kBrick && z > 0 && z < kBrick;
                        const vec3 p = pointAt(home * kBrick + glm::ivec3(x, y, z));
                        uint32_t seen[27] = {nearest[at]};
                        int count = 1;
                        fresh[at] = nearest[at];
                        for (int dz = -1; dz <= 1; ++dz)
                            for (int dy = -1; dy <= 1; ++dy)
                                for (int dx = -1; dx <= 1; ++dx) {
                                    const size_t n =
                                        inside ? at + local(dx + 1, dy + 1, dz + 1) - local(1, 1, 1)
                                               : sampleAt(glm::ivec3(x + dx, y + dy, z + dz));
                                    const uint32_t t = n == kNowhere ? kNone : offer[n];
                                    if (t == kNone) continue;
                                    touched[at] = 1;
                                    if (std::find(seen, seen + count, t) != seen + count) continue;
                                    seen[count++] = t;
                                    const float d2 = nearer(p, t, best[at]);
                                    if (d2 < best[at]) best[at] = d2, fresh[at] = t;
                                }
                        // 1: a neighbour with a triangle, 2: and now known itself.
                        reached[at] = touched[at] ? best[at] < within2 ? 2 : 1 : 0;
                        grows = grows || reached[at] == 2;
                    }
                }
            if (grows) grew = true;
        });
        if (!grew) break;
        parallelFor(brickCount, [&](size_t b) {
            Rows& fr = front[b];
            for (size_t r = 0; r < fr.size(); ++r)
                for (int x = 0; x <= kBrick; ++x)
                    if (fr[r] >> x & 1u)
                        offer[b * kBrickSamples + r * kBrickSide + size_t(x)] = kNone;
            fr = Rows{}, pending[b] = Rows{};
            bool any = false;
            for (size_t r = 0; r < fr.size(); ++r)
                for (int x = 0; x <= kBrick; ++x) {
                    if (!(visits[b][r] >> x & 1u)) continue;
                    const size_t at = b * kBrickSamples + r * kBrickSide + size_t(x);
                    if (reached[at] == 1) {
                        nearest[at] = fresh[at];
                        pending[b][r] = uint16_t(pending[b][r] | 1u << x);
                    }
                    if (reached[at] == 2) {
                        nearest[at] = offer[at] = fresh[at], known[at] = 1;
                        if (fresh[at] != kNone) fr[r] = uint16_t(fr[r] | 1u << x);
                    }
                    any = any || reached[at] != 0;
                    reached[at] = 0;
                }
            moving[b] = any;
        });
    }
}

Result<MeshField> MeshField::make(const TriangleMesh& mesh, int cells, float bandCells,
                                  size_t maxBytes) {
    Box box;
    for (const vec3& p : mesh.positions)
        box.add(p);
    const vec3 size = box.hi - box.lo;
    const float longest = std::max({size.x, size.y, size.z});
    if (!(longest > 0.0f)) return reason("no extent: every vertex at one point");
    MeshField f;
    f.cell_ = longest / float(std::max(cells, 1));
    f.band_ = std::max(bandCells, std::sqrt(3.0f)) * f.cell_;
    const float margin = f.band_ + f.cell_;
    f.origin_ = box.lo - margin;
    const vec3 span = size + 2.0f * margin;
    f.bricks_ = glm::ivec3(glm::ceil(span / (f.cell_ * float(kBrick))));
    const size_t slots = size_t(f.bricks_.x) * size_t(f.bricks_.y) * size_t(f.bricks_.z);
    const auto tooLarge = [&](size_t bytes) {
        return reason("a field of " + std::to_string(bytes >> 20) + " MiB at " +
                      std::to_string(cells) + " cells, over the limit of " +
                      std::to_string(maxBytes >> 20) + " MiB");
    };
    if (slots > maxBytes / sizeof(int32_t)) return tooLarge(slots * sizeof(int32_t));
    f.slots_.assign(slots, kOutside);
    const float brickSize = f.cell_ * float(kBrick);
    const auto brickOf = [&](vec3 p) {
        return glm::clamp(glm::ivec3(glm::floor((p - f.origin_) / brickSize)), glm::ivec3(0),
                          f.bricks_ - 1);
    };
    const auto corners = [&](uint32_t t) {
        const glm::uvec3 i = mesh.triangles[t];
        return std::array<vec3, 3>{mesh.positions[i.x], mesh.positions[i.y], mesh.positions[i.z]};
    };
    // Calls visit(slot) for each brick that triangle t's box, grown by `grow`, meets.
    const auto forBricksNear = [&](uint32_t t, float grow, auto&& visit) {
        const std::array<vec3, 3> c = corners(t);
        const glm::ivec3 lo = brickOf(glm::min(c[0], glm::min(c[1], c[2])) - grow),
                         hi = brickOf(glm::max(c[0], glm::max(c[1], c[2])) + grow);
        for (int z = lo.z; z <= hi.z; ++z)
            for (int y = lo.y; y <= hi.y; ++y)
                for (int x = lo.x; x <= hi.x; ++x)
                    visit(f.slotOf({x, y, z}));
    };
    const uint32_t triangleCount = uint32_t(mesh.triangles.size());

    // The bricks within `margin` of a triangle's box hold samples, and with colours as many
    // colours.
    const size_t sampleBytes = sizeof(float) * (mesh.colors.empty() ? 1 : 2);
    size_t stored = 0;
    for (uint32_t t = 0; t < triangleCount; ++t) {
        forBricksNear(t, margin, [&](size_t s) {
            if (f.slots_[s] == kOutside) f.slots_[s] = 0, ++stored;
        });
        const size_t bytes = stored * kBrickSamples * sampleBytes + slots * sizeof(int32_t);
        if (bytes > maxBytes) return tooLarge(bytes);
    }
    std::vector<uint32_t> brickSlots; // the stored bricks' slots, in order
    brickSlots.reserve(stored);
    for (size_t s = 0; s < slots; ++s)
        if (f.slots_[s] != kOutside) {
            f.slots_[s] = int32_t(brickSlots.size() * kBrickSamples);
            brickSlots.push_back(uint32_t(s));
        }
    const size_t brickCount = brickSlots.size(), sampleCount = brickCount * kBrickSamples;

    // Each brick's list of the triangles whose box, grown by `reach`, meets it: a counting sort
    // by brick. The lists count against the limit too.
    const float reach = f.band_;
    std::vector<size_t> first(brickCount + 1, 0);
    size_t touches = 0;
    for (uint32_t t = 0; t < triangleCount; ++t) {
        forBricksNear(t, reach,
                      [&](size_t s) { ++first[size_t(f.slots_[s]) / kBrickSamples], ++touches; });
        const size_t bytes =
            sampleCount * sampleBytes + slots * sizeof(int32_t) + touches * sizeof(uint32_t);
        if (bytes > maxBytes) return tooLarge(bytes);
    }
    for (size_t b = 0, sum = 0; b <= brickCount; ++b)
        sum += std::exchange(first[b], sum);
    std::vector<uint32_t> near(first.back());
    {
        std::vector<size_t> next(first.begin(), first.end() - 1);
        for (uint32_t t = 0; t < triangleCount; ++t)
            forBricksNear(t, reach,
                          [&](size_t s) { near[next[size_t(f.slots_[s]) / kBrickSamples]++] = t; });
    }

    // Each sample's squared distance to its nearest triangle, and which, where nearer than the
    // margin. Samples are indexed as the field stores them; a sample's point comes from its
    // place in the whole grid, so that the copies of a sample two bricks share are the same.
    constexpr uint32_t kNone = ~0u;
    std::vector<float> best(sampleCount, margin * margin);
    std::vector<uint32_t> nearest(sampleCount, kNone);
    const auto brickBase = [&](size_t b) { return f.brickOfSlot(brickSlots[b]) * kBrick; };
    const auto pointAt = [&](glm::ivec3 g) { return f.origin_ + f.cell_ * vec3(g); };
    const auto local = [](int x, int y, int z) {
        return (size_t(z) * kBrickSide + size_t(y)) * kBrickSide + size_t(x);
    };
    // The distance to triangle t where it may be less than `best` (its plane's is no more).
    const auto nearer = [&](vec3 p, uint32_t t, float best2) {
        const std::array<vec3, 3> c = corners(t);
        const vec3 normal = glm::cross(c[1] - c[0], c[2] - c[0]);
        const float plane = glm::dot(p - c[0], normal);
        if (plane * plane >= best2 * glm::dot(normal, normal)) return best2;
        return nearestOnTriangle(p, c[0], c[1], c[2]).distance2;
    };

    // Exact within `reach` of the surface: every triangle against the samples near it, those
    // in its box grown by `reach` and in the ball about the box's centre that holds them.
    parallelFor(brickCount, [&](size_t b) {
        const glm::ivec3 base = brickBase(b);
        const vec3 corner = pointAt(base);
        for (size_t k = first[b]; k < first[b + 1]; ++k) {
            const uint32_t t = near[k];
            const std::array<vec3, 3> c = corners(t);
            const vec3 lo = (glm::min(c[0], glm::min(c[1], c[2])) - corner) / f.cell_;
            const vec3 hi = (glm::max(c[0], glm::max(c[1], c[2])) - corner) / f.cell_;
            const vec3 centre = 0.5f * (lo + hi);
            const float ball = glm::length(0.5f * (hi - lo)) + reach / f.cell_ + 1e-3f;
            const glm::ivec3 from =
                glm::max(glm::ivec3(glm::ceil(lo - reach / f.cell_)), glm::ivec3(0));
            const glm::ivec3 to =
                glm::min(glm::ivec3(glm::floor(hi + reach / f.cell_)), glm::ivec3(kBrick));
            const vec3 normal = glm::cross(c[1] - c[0], c[2] - c[0]);
            const float area2 = glm::dot(normal, normal);
            // The triangle lies within `radius` of `middle`: no nearer to p than |p - middle|
            // less that, nor than its plane.
            const vec3 middle = corner + f.cell_ * centre;
            const float radius = f.cell_ * glm::length(0.5f * (hi - lo));
            for (int z = from.z; z <= to.z; ++z)
                for (int y = from.y; y <= to.y; ++y) {
                    const float dy = float(y) - centre.y, dz = float(z) - centre.z;
                    const float row2 = ball * ball - dy * dy - dz * dz;
                    if (row2 < 0.0f) continue;
                    const float row = std::sqrt(row2);
                    const int x0 = std::max(from.x, int(std::ceil(centre.x - row)));
                    const int x1 = std::min(to.x, int(std::floor(centre.x + row)));
                    for (int x = x0; x <= x1; ++x) {
                        const size_t at = b * kBrickSamples + local(x, y, z);
                        const vec3 p = pointAt(base + glm::ivec3(x, y, z));
                        const float far = std::sqrt(best[at]) + radius;
                        if (glm::dot(p - middle, p - middle) >= far * far) continue;
                        const float plane = glm::dot(p - c[0], normal);
                        if (plane * plane >= best[at] * area2) continue;
                        const float d2 = nearestOnTriangle(p, c[0], c[1], c[2]).distance2;
                        if (d2 < best[at]) best[at] = d2, nearest[at] = t;
                    }
                }
        }
    });

    // Out to the margin by dilation (dilate).
    dilate(f, brickSlots, reach, margin, best, nearest,
           [&](vec3 p, uint32_t t, float best2) { return nearer(p, t, best2); });

    // Each sample's colour: the colour of its nearest triangle at the point of it nearest to the
    // sample, from its corners' by the point's barycentric coordinates.
    if (!mesh.colors.empty()) {
        f.colors_.assign(sampleCount, -1.0f);
        parallelFor(brickCount, [&](size_t b) {
            for (int s = 0; s < kBrickSamples; ++s) {
                const size_t at = b * kBrickSamples + size_t(s);
                const uint32_t t = nearest[at];
                if (t == kNone) continue;
                const uint32_t* k = &mesh.colors[3 * size_t(t)];
                if (k[0] == kNoColor || k[1] == kNoColor || k[2] == kNoColor) continue;
                const std::array<vec3, 3> c = corners(t);
                const vec3 q = nearestOnTriangle(
                                   pointAt(brickBase(b) +
                                           glm::ivec3(s % kBrickSide, s / kBrickSide % kBrickSide,
                                                      s / (kBrickSide * kBrickSide))),
                                   c[0], c[1], c[2])
                                   .point;
                const vec3 w = barycentric(q, c[0], c[1], c[2]);
                vec3 rgb(0.0f);
                for (int corner = 0; corner < 3; ++corner)
                    rgb += w[corner] * vec3(float(k[corner] >> 16), float(k[corner] >> 8 & 255u),
                                            float(k[corner] & 255u));
                const glm::uvec3 v = glm::uvec3(glm::round(glm::clamp(rgb, 0.0f, 255.0f)));
                f.colors_[at] = float(v.r * 65536u + v.g * 256u + v.b);
            }
        });
    }

    // The sign: from the pseudonormals where the mesh is closed and consistently oriented, else
    // from the winding number. Samples without a triangle are at least `margin` from the
    // surface, as are their neighbours at least margin - cell: no surface lies between them,
    // and they take a neighbour's sign.
    const std::vector<uint32_t> pairs = edgesInPairs(mesh);
    f.defects_ = countDefects(mesh, pairs);
    const bool clean = !f.defects_.any();
    const Pseudonormals normals = clean ? Pseudonormals(mesh, pairs) : Pseudonormals();
    std::optional<Hierarchy> h;
    if (!clean) h.emplace(mesh);
    f.samples_.resize(sampleCount);
    std::vector<uint8_t> signless(brickCount, 0); // bricks with no sample near a triangle
    parallelFor(brickCount, [&](size_t b) {
        const vec3 corner = pointAt(brickBase(b));
        const size_t at0 = b * kBrickSamples;
        int8_t sign[kBrickSamples] = {};
        const auto point = [&](int s) {
            return pointAt(brickBase(b) + glm::ivec3(s % kBrickSide, s / kBrickSide % kBrickSide,
                                                     s / (kBrickSide * kBrickSide)));
        };
        bool any = false;
        for (int s = 0; s < kBrickSamples; ++s) {
            const uint32_t t = nearest[at0 + size_t(s)];
            if (t == kNone) continue;
            const vec3 p = point(s);
            bool inside;
            if (clean) {
                const std::array<vec3, 3> c = corners(t);
                const Nearest n = nearestOnTriangle(p, c[0], c[1], c[2]);
                inside = glm::dot(p - n.point, normals.at(mesh, t, n.feature)) < 0.0f;
            } else {
                inside = h->winding(p) >= 0.5f;
            }
            sign[s] = inside ? -1 : 1;
            any = true;
        }
        if (!any && clean) signless[b] = 1, sign[0] = 1; // signed below, with the empty bricks
        if (!any && !clean) sign[0] = h->winding(corner) >= 0.5f ? -1 : 1;
        for (bool changed = true; changed;) {
            changed = false;
            for (int s = 0; s < kBrickSamples; ++s) {
                if (sign[s] != 0) continue;
                const int x = s % kBrickSide, y = s / kBrickSide % kBrickSide,
                          z = s / (kBrickSide * kBrickSide);
                const int8_t next = x > 0 && sign[s - 1]                 ? sign[s - 1]
                                    : x < kBrick && sign[s + 1]          ? sign[s + 1]
                                    : y > 0 && sign[s - kBrickSide]      ? sign[s - kBrickSide]
                                    : y < kBrick && sign[s + kBrickSide] ? sign[s + kBrickSide]
                                    : z > 0 && sign[s - kBrickSide * kBrickSide]
                                        ? sign[s - kBrickSide * kBrickSide]
                                    : z < kBrick && sign[s + kBrickSide * kBrickSide]
                                        ? sign[s + kBrickSide * kBrickSide]
                                        : int8_t(0);
                if (next != 0) sign[s] = next, changed = true;
            }
        }
        for (int s = 0; s < kBrickSamples; ++s)
            f.samples_[at0 + size_t(s)] = float(sign[s]) * std::sqrt(best[at0 + size_t(s)]);
    });
    if (!clean) {
        // Bricks without samples: their centre's inside.
        parallelFor(slots, [&](size_t s) {
            if (f.slots_[s] == kOutside &&
                h->winding(pointAt(f.brickOfSlot(s) * kBrick) + 0.5f * brickSize) >= 0.5f)
                f.slots_[s] = kInside;
        });
        return f;
    }
    // On a clean mesh, bricks without samples and those with no sample near a triangle hold no
    // surface (it would be within a cell of a sample): each is all inside or all outside, as the
    // point of its face it shares with a signed brick, whose sample there has its sign. Signed
    // outward from the signed bricks through their neighbours.
    std::vector<int8_t> inside(slots, 0); // of the unsigned: -1 inside, 1 outside, 0 not yet
    std::vector<size_t> queue;
    for (size_t b = 0; b < brickCount; ++b)
        if (!signless[b]) queue.push_back(brickSlots[b]);
    for (size_t k = 0; k < queue.size(); ++k) {
        const size_t s = queue[k];
        const glm::ivec3 here = f.brickOfSlot(s);
        const int32_t slot = f.slots_[s];
        const bool hasSamples = slot >= 0 && !signless[size_t(slot) / kBrickSamples];
        for (int a = 0; a < 3; ++a)
            for (int side = -1; side <= 1; side += 2) {
                glm::ivec3 there = here;
                there[a] += side;
                if (there[a] < 0 || there[a] >= f.bricks_[a]) continue;
                const size_t n = f.slotOf(there);
                const int32_t nslot = f.slots_[n];
                const bool signedThere = nslot >= 0 && !signless[size_t(nslot) / kBrickSamples];
                if (signedThere || inside[n] != 0) continue;
                glm::ivec3 face(kBrick / 2);
                face[a] = side > 0 ? kBrick : 0;
                inside[n] =
                    hasSamples
                        ? (f.samples_[size_t(slot) + local(face.x, face.y, face.z)] < 0.0f ? -1 : 1)
                        : inside[s];
                queue.push_back(n);
            }
    }
    for (size_t s = 0; s < slots; ++s) {
        if (inside[s] >= 0) continue;
        if (f.slots_[s] == kOutside) {
            f.slots_[s] = kInside;
        } else {
            float* samples = &f.samples_[size_t(f.slots_[s])];
            for (int k = 0; k < kBrickSamples; ++k)
                samples[k] = -samples[k];
        }
    }
    return f;
}

Result<MeshField> MeshField::fromField(const std::function<float(vec3)>& value,
                                       const std::function<vec3(vec3)>& color, vec3 lo, vec3 hi,
                                       float cell, float band, size_t maxBytes) {
    if (!(cell > 0.0f) || !std::isfinite(cell) || !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z) ||
        !std::isfinite(lo.x + lo.y + lo.z + hi.x + hi.y + hi.z))
        return reason("no finite box to bake in");
    MeshField f;
    f.cell_ = cell;
    f.band_ = std::max(band, std::sqrt(3.0f) * cell);
    const float margin = f.band_ + cell;
    f.origin_ = lo - margin;
    const vec3 extent = (hi - lo + 2.0f * margin) / (cell * float(kBrick));
    if (std::max({extent.x, extent.y, extent.z}) > float(maxBytes / sizeof(int32_t)))
        return reason("a cell of " + formatFloat(cell) + " makes too many bricks");
    f.bricks_ = glm::max(glm::ivec3(glm::ceil(extent)), glm::ivec3(1));
    const size_t slots = size_t(f.bricks_.x) * size_t(f.bricks_.y) * size_t(f.bricks_.z);
    const size_t sampleBytes = sizeof(float) * (color ? 2 : 1);
    const auto tooLarge = [&](size_t bytes) {
        return reason("a field of " + std::to_string(bytes >> 20) + " MiB at a cell of " +
                      formatFloat(cell) + ", over the limit of " + std::to_string(maxBytes >> 20) +
                      " MiB");
    };
    if (slots > maxBytes / sizeof(int32_t)) return tooLarge(slots * sizeof(int32_t));
    f.slots_.assign(slots, kOutside);
    const float brickSize = cell * float(kBrick);
    const auto pointAt = [&](glm::ivec3 g) { return f.origin_ + f.cell_ * vec3(g); };
    const auto local = [](int x, int y, int z) {
        return (size_t(z) * kBrickSide + size_t(y)) * kBrickSide + size_t(x);
    };

    // The bricks that may reach within the margin of the surface, coarse to fine: a block of 4^3
    // bricks, then each brick of a block that may. The field is at most the distance, so a box
    // whose centre's value exceeds the margin by its half-diagonal lies beyond it, all on the
    // side of that value's sign.
    constexpr int kBlock = 4;
    const glm::ivec3 blocks = (f.bricks_ + kBlock - 1) / kBlock;
    const size_t blockCount = size_t(blocks.x) * size_t(blocks.y) * size_t(blocks.z);
    std::atomic<size_t> storedCount{0};
    parallelFor(blockCount, [&](size_t k) {
        const glm::ivec3 block(int(k % size_t(blocks.x)),
                               int(k / size_t(blocks.x) % size_t(blocks.y)),
                               int(k / (size_t(blocks.x) * size_t(blocks.y))));
        const glm::ivec3 b0 = block * kBlock, b1 = glm::min(b0 + kBlock, f.bricks_);
        const vec3 c0 = f.origin_ + brickSize * vec3(b0), c1 = f.origin_ + brickSize * vec3(b1);
        const float v = value(0.5f * (c0 + c1));
        if (std::abs(v) - 0.5f * glm::length(c1 - c0) > margin) {
            if (v < 0.0f)
                for (int z = b0.z; z < b1.z; ++z)
                    for (int y = b0.y; y < b1.y; ++y)
                        for (int x = b0.x; x < b1.x; ++x)
                            f.slots_[f.slotOf({x, y, z})] = kInside;
            return;
        }
        const float half = 0.5f * std::sqrt(3.0f) * brickSize;
        size_t count = 0;
        for (int z = b0.z; z < b1.z; ++z)
            for (int y = b0.y; y < b1.y; ++y)
                for (int x = b0.x; x < b1.x; ++x) {
                    const float w = value(f.origin_ + brickSize * (vec3(x, y, z) + 0.5f));
                    if (std::abs(w) - half > margin) {
                        if (w < 0.0f) f.slots_[f.slotOf({x, y, z})] = kInside;
                    } else {
                        f.slots_[f.slotOf({x, y, z})] = 0, ++count;
                    }
                }
        storedCount += count;
    });
    const size_t bytes = storedCount * kBrickSamples * sampleBytes + slots * sizeof(int32_t);
    if (bytes > maxBytes) return tooLarge(bytes);
    std::vector<uint32_t> brickSlots;
    brickSlots.reserve(storedCount);
    for (size_t s = 0; s < slots; ++s)
        if (f.slots_[s] == 0) {
            f.slots_[s] = int32_t(brickSlots.size() * kBrickSamples);
            brickSlots.push_back(uint32_t(s));
        }
    const size_t brickCount = brickSlots.size(), sampleCount = brickCount * kBrickSamples;
    const auto brickBase = [&](size_t b) { return f.brickOfSlot(brickSlots[b]) * kBrick; };
    const auto stored = [&](glm::ivec3 b) {
        return glm::all(glm::greaterThanEqual(b, glm::ivec3(0))) &&
               glm::all(glm::lessThan(b, f.bricks_)) && f.slots_[f.slotOf(b)] >= 0;
    };

    // The field at every sample of those bricks that the surface may cross; in the others,
    // their centre's value, which has every sample's sign.
    std::vector<float> values(sampleCount);
    const float half = 0.5f * std::sqrt(3.0f) * brickSize;
    parallelFor(brickCount, [&](size_t b) {
        const glm::ivec3 base = brickBase(b);
        const float centre = value(pointAt(base) + 0.5f * brickSize);
        if (std::abs(centre) > half) {
            std::fill_n(&values[b * kBrickSamples], kBrickSamples, centre);
            return;
        }
        for (int z = 0; z <= kBrick; ++z)
            for (int y = 0; y <= kBrick; ++y)
                for (int x = 0; x <= kBrick; ++x)
                    values[b * kBrickSamples + local(x, y, z)] =
                        value(pointAt(base + glm::ivec3(x, y, z)));
    });

    // Points of the surface: each grid edge whose ends' signs differ, bisected. An edge on a
    // brick's upper face is its neighbour's there, where that is stored.
    std::vector<std::vector<vec3>> found(brickCount);
    parallelFor(brickCount, [&](size_t b) {
        const glm::ivec3 base = brickBase(b), home = base / kBrick;
        for (int a = 0; a < 3; ++a) {
            glm::ivec3 step(0);
            step[a] = 1;
            bool shared[3];
            for (int o = 0; o < 3; ++o) {
                glm::ivec3 next = home;
                next[o] += 1;
                shared[o] = o != a && stored(next);
            }
            for (int z = 0; z <= kBrick; ++z)
                for (int y = 0; y <= kBrick; ++y)
                    for (int x = 0; x <= kBrick; ++x) {
                        const glm::ivec3 g(x, y, z);
                        if (g[a] == kBrick) continue;
                        bool skip = false;
                        for (int o = 0; o < 3; ++o)
                            skip = skip || (shared[o] && g[o] == kBrick);
                        if (skip) continue;
                        const glm::ivec3 e = g + step;
                        const float va = values[b * kBrickSamples + local(x, y, z)];
                        const float vb = values[b * kBrickSamples + local(e.x, e.y, e.z)];
                        if ((va < 0.0f) == (vb < 0.0f)) continue;
                        // Bisected to a 64th of the cell, then the line through the ends'
                        // values: the field is all but linear along so short a piece.
                        vec3 from = pointAt(base + g), to = pointAt(base + e);
                        float vf = va, vt = vb;
                        for (int i = 0; i < 6; ++i) {
                            const vec3 mid = 0.5f * (from + to);
                            const float vm = value(mid);
                            if ((vm < 0.0f) == (va < 0.0f))
                                from = mid, vf = vm;
                            else
                                to = mid, vt = vm;
                        }
                        const float t = vf != vt ? std::clamp(vf / (vf - vt), 0.0f, 1.0f) : 0.5f;
                        found[b].push_back(glm::mix(from, to, t));
                    }
        }
        // Where the surface comes to a point or an edge sharper than the grid resolves (a
        // twisted box's corners), the crossings stay a few cells short of it: from each sample
        // within two cells of the surface (the field's value being at most the distance), Newton
        // steps along the gradient (four taps about the point, sdf.glsl's valueTap) reach the
        // tip, alternating between the faces that meet there. Points that land within a
        // sixteenth of a cell of one before count once.
        const float h = cell / 64.0f;
        std::vector<vec3> projected;
        const glm::vec3 taps[4] = {{1, -1, -1}, {-1, -1, 1}, {-1, 1, -1}, {1, 1, 1}};
        for (int z = 0; z <= kBrick; ++z)
            for (int y = 0; y <= kBrick; ++y)
                for (int x = 0; x <= kBrick; ++x) {
                    if (!(std::abs(values[b * kBrickSamples + local(x, y, z)]) < 2.0f * cell))
                        continue;
                    const vec3 start = pointAt(base + glm::ivec3(x, y, z));
                    vec3 q = start;
                    float v = 0.0f;
                    for (int i = 0; i < 6; ++i) {
                        vec3 g(0.0f);
                        v = 0.0f;
                        for (const vec3& k : taps) {
                            const float tap = value(q + h * k);
                            g += tap * k, v += tap;
                        }
                        g /= 4.0f * h, v /= 4.0f;
                        const float g2 = glm::dot(g, g);
                        if (!(g2 > 1e-6f)) break;
                        q -= v / g2 * g;
                    }
                    if (std::abs(v) <= 1e-3f * cell && glm::length(q - start) <= 3.0f * cell)
                        projected.push_back(q);
                }
        std::sort(projected.begin(), projected.end(), [&](vec3 a, vec3 c) {
            const glm::ivec3 ka(glm::floor(a * (16.0f / cell))), kc(glm::floor(c * (16.0f / cell)));
            return std::tie(ka.x, ka.y, ka.z) < std::tie(kc.x, kc.y, kc.z);
        });
        for (size_t k = 0; k < projected.size(); ++k)
            if (k == 0 || glm::floor(projected[k] * (16.0f / cell)) !=
                              glm::floor(projected[k - 1] * (16.0f / cell)))
                found[b].push_back(projected[k]);
    });
    std::vector<size_t> firstSeed(brickCount + 1, 0);
    for (size_t b = 0; b < brickCount; ++b)
        firstSeed[b + 1] = firstSeed[b] + found[b].size();
    std::vector<vec3> seeds;
    seeds.reserve(firstSeed.back());
    for (std::vector<vec3>& points : found) {
        seeds.insert(seeds.end(), points.begin(), points.end());
        points = {};
    }
    for (const vec3& p : seeds)
        f.surfaceMin_ = glm::min(f.surfaceMin_, p), f.surfaceMax_ = glm::max(f.surfaceMax_, p);

    // Each sample's nearest point exactly within `reach` (two cells): the points of the brick
    // and the 26 about it against the samples within reach of each.
    constexpr uint32_t kNone = ~0u;
    const float reach = 2.0f * cell;
    std::vector<float> best(sampleCount, margin * margin);
    std::vector<uint32_t> nearest(sampleCount, kNone);
    parallelFor(brickCount, [&](size_t b) {
        const glm::ivec3 base = brickBase(b), home = base / kBrick;
        for (int k = 0; k < 27; ++k) {
            const glm::ivec3 there = home + glm::ivec3(k % 3, k / 3 % 3, k / 9) - 1;
            if (!stored(there)) continue;
            const size_t n = size_t(f.slots_[f.slotOf(there)]) / kBrickSamples;
            for (size_t t = firstSeed[n]; t < firstSeed[n + 1]; ++t) {
                const vec3 g = (seeds[t] - pointAt(base)) / cell;
                const glm::ivec3 from = glm::max(glm::ivec3(glm::ceil(g - 2.0f)), glm::ivec3(0));
                const glm::ivec3 to =
                    glm::min(glm::ivec3(glm::floor(g + 2.0f)), glm::ivec3(kBrick));
                for (int z = from.z; z <= to.z; ++z)
                    for (int y = from.y; y <= to.y; ++y)
                        for (int x = from.x; x <= to.x; ++x) {
                            const vec3 d = vec3(x, y, z) - g;
                            const float d2 = glm::dot(d, d) * cell * cell;
                            const size_t at = b * kBrickSamples + local(x, y, z);
                            if (d2 < best[at]) best[at] = d2, nearest[at] = uint32_t(t);
                        }
            }
        }
    });
    dilate(f, brickSlots, reach, margin, best, nearest, [&](vec3 p, uint32_t t, float) {
        const vec3 d = p - seeds[t];
        return glm::dot(d, d);
    });

    f.samples_.resize(sampleCount);
    for (size_t at = 0; at < sampleCount; ++at)
        f.samples_[at] = (values[at] < 0.0f ? -1.0f : 1.0f) * std::sqrt(best[at]);
    if (color) {
        std::vector<float> seedColors(seeds.size());
        parallelFor(seeds.size(),
                    [&](size_t t) { seedColors[t] = float(packColor(color(seeds[t]))); });
        f.colors_.assign(sampleCount, -1.0f);
        for (size_t at = 0; at < sampleCount; ++at)
            if (nearest[at] != kNone) f.colors_[at] = seedColors[nearest[at]];
    }
    return f;
}

std::vector<glm::vec4> MeshField::words() const {
    const size_t at = 3 + (slots_.size() + 3) / 4, colorsAt = at + (samples_.size() + 3) / 4;
    std::vector<glm::vec4> w(colorsAt + (colors_.size() + 3) / 4, glm::vec4(0.0f));
    w[0] = glm::vec4(float(bricks_.x), float(bricks_.y), float(bricks_.z), band_);
    w[1] = glm::vec4(origin_, cell_);
    w[2].x = colors_.empty() ? 0.0f : float(colorsAt); // exact: the words stay under 2^24
    for (size_t s = 0; s < slots_.size(); ++s)
        w[3 + s / 4][int(s % 4)] =
            slots_[s] < 0 ? float(slots_[s]) : float(slots_[s] / kBrickSamples);
    for (size_t k = 0; k < samples_.size(); ++k)
        w[at + k / 4][int(k % 4)] = samples_[k];
    for (size_t k = 0; k < colors_.size(); ++k)
        w[colorsAt + k / 4][int(k % 4)] = colors_[k];
    return w;
}

glm::vec3 MeshField::color(glm::vec3 p, glm::vec3 fallback) const {
    const vec3 g = (p - origin_) / cell_;
    if (colors_.empty() || glm::any(glm::lessThan(g, vec3(0.0f))) ||
        glm::any(glm::greaterThan(g, vec3(bricks_ * kBrick))))
        return fallback;
    const glm::ivec3 b = glm::min(glm::ivec3(g) / kBrick, bricks_ - 1);
    const int32_t slot =
        slots_[(size_t(b.z) * size_t(bricks_.y) + size_t(b.y)) * size_t(bricks_.x) + size_t(b.x)];
    if (slot < 0) return fallback;
    const glm::ivec3 i = glm::clamp(glm::ivec3(glm::floor(g - vec3(b * kBrick) + 0.5f)),
                                    glm::ivec3(0), glm::ivec3(kBrick));
    const float c =
        colors_[size_t(slot) + (size_t(i.z) * kBrickSide + size_t(i.y)) * kBrickSide + size_t(i.x)];
    if (c < 0.0f) return fallback;
    const uint32_t v = uint32_t(c);
    return vec3(float(v >> 16), float(v >> 8 & 255u), float(v & 255u)) * (1.0f / 255.0f);
}

void fitMesh(TriangleMesh& mesh, glm::vec3 box) {
    Box b;
    for (const vec3& p : mesh.positions)
        b.add(p);
    const vec3 size = b.hi - b.lo, centre = 0.5f * (b.lo + b.hi);
    float scale = std::numeric_limits<float>::infinity();
    for (int a = 0; a < 3; ++a)
        if (size[a] > 0.0f) scale = std::min(scale, box[a] / size[a]);
    if (!std::isfinite(scale)) return; // one point: MeshField::make refuses it
    for (vec3& p : mesh.positions)
        p = (p - centre) * scale;
}

Result<std::shared_ptr<const std::vector<glm::vec4>>> buildMesh(const Node& node,
                                                                const SceneFiles& files) {
    const std::string& name = node.strings[0];
    auto fail = [&](const std::string& why) {
        return reason(
            nodeFileProblem("mesh", name, files, why, ": name a mesh file in the scene's folder"));
    };
    auto file = sceneFile(name, files, kMaxMeshFileBytes);
    if (!file) return fail(file.error().diagnostics[0].message);
    const auto bytes = readFileBytes(*file, kMaxMeshFileBytes);
    if (!bytes) return fail(bytes.error().diagnostics[0].message);
    auto mesh = readTriangleMesh(*bytes, file->extension().string(), file->parent_path());
    if (!mesh) return fail(mesh.error().diagnostics[0].message);
    const vec3 fit(node.params[1], node.params[2], node.params[3]);
    if (fit != vec3(0.0f)) fitMesh(*mesh, fit);
    // The band: two cells, or as far as the node's "band" reaches.
    const int cells = int(node.params[0]);
    float bandCells = 2.0f;
    if (const float band = node.params[4]; band > 0.0f) {
        Box box;
        for (const vec3& p : mesh->positions)
            box.add(p);
        const vec3 size = box.hi - box.lo;
        if (const float longest = std::max({size.x, size.y, size.z}); longest > 0.0f)
            bandCells = std::max(bandCells, band * float(cells) / longest);
    }
    auto field = MeshField::make(*mesh, cells, bandCells);
    if (!field) return fail(field.error().diagnostics[0].message);
    std::vector<glm::vec4> words = field->words();
    // After sdMesh's words, which it never reads past: the box of its inside, for the kind's
    // bounds (its size, and how far its least corner lies from the grid's), then the repairs for
    // the notes. A closed, consistently oriented mesh's inside lies in its triangles' box; where
    // triangles are flipped, the winding number can pass a half beyond it, and the box is the
    // grid's.
    const MeshDefects defects = field->defects();
    Box box;
    for (const vec3& p : mesh->positions)
        box.add(p);
    if (defects.any()) {
        box.lo = field->origin();
        box.hi = box.lo + field->cell() * float(MeshField::kBrick) * vec3(field->bricks());
    }
    words.push_back(glm::vec4(box.hi - box.lo, box.lo.x - field->origin().x));
    words.push_back(defectsWord(defects));
    return std::make_shared<const std::vector<glm::vec4>>(std::move(words));
}

glm::vec4 defectsWord(const MeshDefects& d) {
    return {float(d.openEdges), float(d.crowdedEdges), float(d.flippedEdges), float(d.degenerate)};
}

MeshDefects storedDefects(const std::vector<glm::vec4>& words) {
    if (words.empty()) return {};
    const glm::vec4 d = words.back();
    return {size_t(d.x), size_t(d.y), size_t(d.z), size_t(d.w)};
}

float MeshField::distance(glm::vec3 p) const {
    const vec3 g = (p - origin_) / cell_;
    const vec3 extent = vec3(bricks_ * kBrick);
    const vec3 outside = glm::max(glm::max(-g, g - extent), vec3(0.0f));
    if (outside != vec3(0.0f)) return glm::length(outside) * cell_ + band_;
    const glm::ivec3 b = glm::min(glm::ivec3(g) / kBrick, bricks_ - 1);
    const int32_t slot =
        slots_[(size_t(b.z) * size_t(bricks_.y) + size_t(b.y)) * size_t(bricks_.x) + size_t(b.x)];
    if (slot == kOutside) return band_;
    if (slot == kInside) return -band_;
    const vec3 local = glm::min(g - vec3(b * kBrick), vec3(float(kBrick)));
    const glm::ivec3 i = glm::min(glm::ivec3(local), glm::ivec3(kBrick - 1));
    const vec3 t = local - vec3(i);
    const float* s = &samples_[size_t(slot)];
    const auto at = [&](int x, int y, int z) {
        return s[(size_t(i.z + z) * kBrickSide + size_t(i.y + y)) * kBrickSide + size_t(i.x + x)];
    };
    const float x00 = glm::mix(at(0, 0, 0), at(1, 0, 0), t.x),
                x10 = glm::mix(at(0, 1, 0), at(1, 1, 0), t.x);
    const float x01 = glm::mix(at(0, 0, 1), at(1, 0, 1), t.x),
                x11 = glm::mix(at(0, 1, 1), at(1, 1, 1), t.x);
    return std::clamp(glm::mix(glm::mix(x00, x10, t.y), glm::mix(x01, x11, t.y), t.z), -band_,
                      band_); // as sdMesh: no step where the bricks without samples begin
}

} // namespace sdfcsg::detail
