// A mesh's signed distance field (mesh_field.h).
#include "field/mesh_field.h"

#include "scene/files.h"
#include "scene/parse_util.h"

#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <assimp/MemoryIOWrapper.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

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
#include <unordered_map>

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
uint32_t read16(const std::string& s, size_t at) {
    return uint32_t(uint8_t(s[at])) | uint32_t(uint8_t(s[at + 1])) << 8;
}

// What a ZIP archive's central directory says its entries unpack to, or nullopt where it cannot
// be read (or uses ZIP64, whose sizes are elsewhere). Assimp unpacks each entry into a buffer of
// the size its directory entry declares, so the declared sizes bound what reading takes.
std::optional<uint64_t> zipUnpackedSize(const std::string& s) {
    if (s.size() < 22) return std::nullopt;
    const size_t lowest = s.size() > 22 + 65535 ? s.size() - 22 - 65535 : 0;
    for (size_t end = s.size() - 22 + 1; end-- > lowest;) {
        if (read32(s, end) != 0x06054b50u) continue;
        const uint32_t entries = read16(s, end + 10), offset = read32(s, end + 16);
        uint64_t total = 0;
        size_t at = offset;
        for (uint32_t e = 0; e < entries; ++e) {
            if (at + 46 > s.size() || read32(s, at) != 0x02014b50u) return std::nullopt;
            const uint32_t size = read32(s, at + 24);
            if (size == 0xffffffffu) return std::nullopt;
            total += size;
            at += 46 + size_t(read16(s, at + 28)) + read16(s, at + 30) + read16(s, at + 32);
        }
        return total;
    }
    return std::nullopt;
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

// The angle-weighted pseudonormals of a closed, consistently oriented mesh (Baerentzen and Aanaes
// 2005): at the feature of the mesh nearest to p (a face, an edge or a corner), p lies outside
// exactly where it is on the side its pseudonormal points to.
struct Pseudonormals {
    std::vector<vec3> corners;              // per vertex: angle-weighted sum of face normals
    std::vector<std::array<vec3, 3>> edges; // per triangle, edges ab, bc, ca: the two faces' sum
    std::vector<vec3> faces;

    explicit Pseudonormals(const TriangleMesh& mesh)
        : corners(mesh.positions.size(), vec3(0.0f)), edges(mesh.triangles.size()),
          faces(mesh.triangles.size()) {
        std::unordered_map<uint64_t, vec3> edgeSums;
        const auto key = [](uint32_t u, uint32_t v) {
            return (uint64_t(std::min(u, v)) << 32) | std::max(u, v);
        };
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
                edgeSums[key(i[c], i[(c + 1) % 3])] += faces[t];
            }
        }
        for (size_t t = 0; t < mesh.triangles.size(); ++t) {
            const glm::uvec3 i = mesh.triangles[t];
            for (int e = 0; e < 3; ++e)
                edges[t][e] = edgeSums[key(i[e], i[(e + 1) % 3])];
        }
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
        std::ifstream in(*file, std::ios::binary);
        std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        if (bytes.size() > kMaxMeshFileBytes - read_) return nullptr;
        read_ += bytes.size();
        auto* copy = new uint8_t[bytes.size()];
        std::memcpy(copy, bytes.data(), bytes.size());
        return new Assimp::MemoryIOStream(copy, bytes.size(), true);
    }
    void Close(Assimp::IOStream* stream) override { delete stream; }

  private:
    SceneFiles files_;
    uintmax_t read_ = 0;
};

} // namespace

Result<TriangleMesh> readTriangleMesh(const std::string& bytes, const std::string& extension,
                                      const std::filesystem::path& folder) {
    std::string hint =
        extension.size() > 1 && extension[0] == '.' ? extension.substr(1) : extension;
    std::transform(hint.begin(), hint.end(), hint.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (hint == "3mf") {
        const auto unpacked = zipUnpackedSize(bytes);
        if (!unpacked) return reason("not a 3MF file: no ZIP directory that can be read");
        if (*unpacked > 4 * kMaxMeshFileBytes)
            return reason("a 3MF whose parts unpack to more than " +
                          std::to_string((4 * kMaxMeshFileBytes) >> 20) + " MiB");
    }
    Assimp::Importer importer;
    importer.SetIOHandler(new FolderFiles(folder)); // the importer's to delete
    const aiScene* scene = importer.ReadFileFromMemory(
        bytes.data(), bytes.size(), aiProcess_Triangulate | aiProcess_PreTransformVertices,
        hint.c_str());
    if (!scene)
        return reason("not a mesh file that can be read: " +
                      std::string(importer.GetErrorString()));
    size_t faces = 0;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m)
        faces += scene->mMeshes[m]->mNumFaces;
    if (faces > kMaxMeshTriangles)
        return reason("more than " + std::to_string(kMaxMeshTriangles) + " triangles (" +
                      std::to_string(faces) + ")");
    // One vertex per position across the file's meshes, so that edges between them are shared:
    // the corners sorted by position, each run of equal ones made one vertex.
    struct Corner {
        vec3 p;
        uint32_t at; // triangle * 3 + corner
    };
    std::vector<Corner> corners;
    corners.reserve(3 * faces);
    const bool zUp = hint == "stl" || hint == "3mf";
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh& part = *scene->mMeshes[m];
        for (unsigned f = 0; f < part.mNumFaces; ++f) {
            const aiFace& face = part.mFaces[f];
            if (face.mNumIndices != 3) continue;
            for (int c = 0; c < 3; ++c) {
                const aiVector3D& v = part.mVertices[face.mIndices[c]];
                if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
                    return reason("a NaN or infinite vertex");
                // The printing formats build along z: their z is the scene's y.
                const vec3 p = zUp ? vec3(v.x, v.z, -v.y) : vec3(v.x, v.y, v.z);
                corners.push_back({p, uint32_t(corners.size())});
            }
        }
    }
    const auto before = [](const Corner& a, const Corner& b) {
        return a.p.x != b.p.x ? a.p.x < b.p.x : a.p.y != b.p.y ? a.p.y < b.p.y : a.p.z < b.p.z;
    };
    std::sort(corners.begin(), corners.end(), before);
    TriangleMesh mesh;
    mesh.triangles.resize(corners.size() / 3);
    for (size_t k = 0; k < corners.size(); ++k) {
        if (k == 0 || corners[k].p != corners[k - 1].p) mesh.positions.push_back(corners[k].p);
        mesh.triangles[corners[k].at / 3][corners[k].at % 3] = uint32_t(mesh.positions.size() - 1);
    }
    if (mesh.triangles.empty()) return reason("no triangles");
    return mesh;
}

MeshDefects meshDefects(const TriangleMesh& mesh) {
    MeshDefects d;
    // Each undirected edge: how many triangles use it in each direction.
    std::unordered_map<uint64_t, glm::uvec2> edges;
    for (const glm::uvec3& t : mesh.triangles) {
        const vec3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
        if (glm::length(glm::cross(b - a, c - a)) == 0.0f) ++d.degenerate;
        for (int e = 0; e < 3; ++e) {
            const uint32_t u = t[e], v = t[(e + 1) % 3];
            if (u == v) continue;
            const uint64_t key = (uint64_t(std::min(u, v)) << 32) | std::max(u, v);
            ++edges[key][u < v ? 0 : 1];
        }
    }
    for (const auto& [key, uses] : edges) {
        const uint32_t n = uses.x + uses.y;
        if (n == 1)
            ++d.openEdges;
        else if (n > 2)
            ++d.crowdedEdges;
        else if (uses.x != 1)
            ++d.flippedEdges;
    }
    return d;
}

std::vector<float> windingNumbers(const TriangleMesh& mesh, const std::vector<glm::vec3>& points) {
    const Hierarchy h(mesh);
    std::vector<float> w(points.size());
    parallelFor(points.size(), [&](size_t i) { w[i] = h.winding(points[i]); });
    return w;
}

Result<MeshField> MeshField::make(const TriangleMesh& mesh, int cells, float bandCells) {
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
                      std::to_string(kMaxMeshFieldBytes >> 20) + " MiB");
    };
    if (slots > kMaxMeshFieldBytes / sizeof(int32_t)) return tooLarge(slots * sizeof(int32_t));
    f.slots_.assign(slots, kOutside);
    const float brickSize = f.cell_ * float(kBrick);
    const auto brickOf = [&](vec3 p) {
        return glm::clamp(glm::ivec3(glm::floor((p - f.origin_) / brickSize)), glm::ivec3(0),
                          f.bricks_ - 1);
    };
    const auto slotOf = [&](glm::ivec3 b) {
        return (size_t(b.z) * size_t(f.bricks_.y) + size_t(b.y)) * size_t(f.bricks_.x) +
               size_t(b.x);
    };
    // The bricks within reach of each triangle's box hold samples; each lists those triangles.
    std::vector<std::pair<uint32_t, uint32_t>> touches; // (slot, triangle)
    size_t stored = 0;
    for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
        Box tb;
        for (int c = 0; c < 3; ++c)
            tb.add(mesh.positions[mesh.triangles[t][c]]);
        const glm::ivec3 lo = brickOf(tb.lo - margin), hi = brickOf(tb.hi + margin);
        for (int z = lo.z; z <= hi.z; ++z)
            for (int y = lo.y; y <= hi.y; ++y)
                for (int x = lo.x; x <= hi.x; ++x) {
                    const size_t s = slotOf({x, y, z});
                    if (f.slots_[s] == kOutside) f.slots_[s] = 0, ++stored;
                    touches.emplace_back(uint32_t(s), t);
                }
        const size_t bytes = stored * kBrickSamples * sizeof(float) + slots * sizeof(int32_t) +
                             touches.size() * sizeof(touches[0]);
        if (bytes > kMaxMeshFieldBytes) return tooLarge(bytes);
    }
    std::sort(touches.begin(), touches.end());
    // Stored bricks in slot order, each with its range of `touches`.
    std::vector<std::pair<uint32_t, size_t>> bricks; // (slot, first touch)
    for (size_t k = 0; k < touches.size(); ++k)
        if (k == 0 || touches[k].first != touches[k - 1].first) {
            f.slots_[touches[k].first] = int32_t(bricks.size() * kBrickSamples);
            bricks.emplace_back(touches[k].first, k);
        }
    bricks.emplace_back(0, touches.size());
    f.samples_.resize((bricks.size() - 1) * kBrickSamples);
    const auto brickCorner = [&](size_t s) {
        const size_t x = s % size_t(f.bricks_.x),
                     y = (s / size_t(f.bricks_.x)) % size_t(f.bricks_.y),
                     z = s / (size_t(f.bricks_.x) * size_t(f.bricks_.y));
        return f.origin_ + brickSize * vec3(float(x), float(y), float(z));
    };
    // The sign: from the pseudonormals where the mesh is closed and consistently oriented, else
    // from the winding number. Samples beyond every triangle's reach are at least `margin` from
    // the surface, as are their neighbours at least margin - cell: no surface lies between
    // them, and they take a neighbour's sign.
    const bool clean = !meshDefects(mesh).any();
    const Pseudonormals normals(clean ? mesh : TriangleMesh{});
    const Hierarchy h(mesh);
    parallelFor(bricks.size() - 1, [&](size_t b) {
        const vec3 corner = brickCorner(bricks[b].first);
        float* out = &f.samples_[b * kBrickSamples];
        float best[kBrickSamples];
        uint32_t nearest[kBrickSamples];
        std::fill(best, best + kBrickSamples, margin * margin);
        std::fill(nearest, nearest + kBrickSamples, ~0u);
        for (size_t k = bricks[b].second; k < bricks[b + 1].second; ++k) {
            const uint32_t t = touches[k].second;
            const glm::uvec3 i = mesh.triangles[t];
            const vec3 a = mesh.positions[i.x], bb = mesh.positions[i.y], c = mesh.positions[i.z];
            const vec3 lo = (glm::min(a, glm::min(bb, c)) - margin - corner) / f.cell_;
            const vec3 hi = (glm::max(a, glm::max(bb, c)) + margin - corner) / f.cell_;
            const glm::ivec3 from = glm::max(glm::ivec3(glm::ceil(lo)), glm::ivec3(0));
            const glm::ivec3 to = glm::min(glm::ivec3(glm::floor(hi)), glm::ivec3(kBrick));
            const vec3 normal = glm::cross(bb - a, c - a);
            const float area2 = glm::dot(normal, normal);
            for (int z = from.z; z <= to.z; ++z)
                for (int y = from.y; y <= to.y; ++y)
                    for (int x = from.x; x <= to.x; ++x) {
                        const size_t s =
                            (size_t(z) * kBrickSide + size_t(y)) * kBrickSide + size_t(x);
                        const vec3 p = corner + f.cell_ * vec3(float(x), float(y), float(z));
                        // The plane's distance is at most the triangle's: most samples are
                        // already nearer another.
                        const float plane = glm::dot(p - a, normal);
                        if (plane * plane >= best[s] * area2) continue;
                        const float d2 = nearestOnTriangle(p, a, bb, c).distance2;
                        if (d2 < best[s]) best[s] = d2, nearest[s] = t;
                    }
        }
        // Signs of the samples a triangle reached, then passed on to the rest.
        int8_t sign[kBrickSamples] = {};
        const auto point = [&](int s) {
            return corner + f.cell_ * vec3(float(s % kBrickSide),
                                           float(s / kBrickSide % kBrickSide),
                                           float(s / (kBrickSide * kBrickSide)));
        };
        bool any = false;
        for (int s = 0; s < kBrickSamples; ++s) {
            if (nearest[s] == ~0u) continue;
            const vec3 p = point(s);
            bool inside;
            if (clean) {
                const glm::uvec3 i = mesh.triangles[nearest[s]];
                const Nearest n = nearestOnTriangle(p, mesh.positions[i.x], mesh.positions[i.y],
                                                    mesh.positions[i.z]);
                inside = glm::dot(p - n.point, normals.at(mesh, nearest[s], n.feature)) < 0.0f;
            } else {
                inside = h.winding(p) >= 0.5f;
            }
            sign[s] = inside ? -1 : 1;
            any = true;
        }
        if (!any) sign[0] = h.winding(point(0)) >= 0.5f ? -1 : 1;
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
            out[s] = float(sign[s]) * std::sqrt(best[s]);
    });
    // Bricks without samples: their centre's inside.
    parallelFor(slots, [&](size_t s) {
        if (f.slots_[s] == kOutside && h.winding(brickCorner(s) + 0.5f * brickSize) >= 0.5f)
            f.slots_[s] = kInside;
    });
    return f;
}

std::vector<glm::vec4> MeshField::words() const {
    std::vector<glm::vec4> w(2 + (slots_.size() + 3) / 4 + (samples_.size() + 3) / 4,
                             glm::vec4(0.0f));
    w[0] = glm::vec4(float(bricks_.x), float(bricks_.y), float(bricks_.z), band_);
    w[1] = glm::vec4(origin_, cell_);
    for (size_t s = 0; s < slots_.size(); ++s)
        w[2 + s / 4][int(s % 4)] =
            slots_[s] < 0 ? float(slots_[s]) : float(slots_[s] / kBrickSamples);
    const size_t at = 2 + (slots_.size() + 3) / 4;
    for (size_t k = 0; k < samples_.size(); ++k)
        w[at + k / 4][int(k % 4)] = samples_[k];
    return w;
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
    std::ifstream in(*file, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in && !in.eof()) return fail("cannot be read");
    auto mesh = readTriangleMesh(bytes, file->extension().string(), file->parent_path());
    if (!mesh) return fail(mesh.error().diagnostics[0].message);
    const vec3 fit(node.params[1], node.params[2], node.params[3]);
    if (fit != vec3(0.0f)) fitMesh(*mesh, fit);
    auto field = MeshField::make(*mesh, int(node.params[0]));
    if (!field) return fail(field.error().diagnostics[0].message);
    std::vector<glm::vec4> words = field->words();
    words.push_back(defectsWord(meshDefects(*mesh)));
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
    return glm::mix(glm::mix(x00, x10, t.y), glm::mix(x01, x11, t.y), t.z);
}

} // namespace sdfcsg::detail
