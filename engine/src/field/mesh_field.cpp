// A mesh's signed distance field (mesh_field.h).
#include "field/mesh_field.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
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

    // The distance from p to the nearest triangle, if nearer than `limit`; else `limit`.
    float nearest(vec3 p, float limit) const {
        float best2 = limit * limit;
        uint32_t stack[64];
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& n = nodes_[stack[--top]];
            if (n.box.distance2(p) >= best2) continue;
            if (n.count > 0) {
                for (uint32_t k = n.first; k < n.first + n.count; ++k)
                    best2 = std::min(best2, triangleDistance2(p, order_[k]));
                continue;
            }
            const float da = nodes_[n.left].box.distance2(p);
            const float db = nodes_[n.right].box.distance2(p);
            // The nearer child is searched first: pushed last.
            stack[top++] = da < db ? n.right : n.left;
            stack[top++] = da < db ? n.left : n.right;
        }
        return std::sqrt(best2);
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

    // Ericson's closest point on a triangle, as a squared distance.
    float triangleDistance2(vec3 p, size_t t) const {
        const vec3 a = corner(t, 0), b = corner(t, 1), c = corner(t, 2);
        const vec3 ab = b - a, ac = c - a, ap = p - a;
        const float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
        vec3 q;
        if (d1 <= 0.0f && d2 <= 0.0f) {
            q = a;
        } else {
            const vec3 bp = p - b;
            const float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
            const vec3 cp = p - c;
            const float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
            const float vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
            if (d3 >= 0.0f && d4 <= d3)
                q = b;
            else if (d6 >= 0.0f && d5 <= d6)
                q = c;
            else if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f)
                q = a + ab * (d1 / (d1 - d3));
            else if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f)
                q = a + ac * (d2 / (d2 - d6));
            else if (va <= 0.0f && d4 - d3 >= 0.0f && d5 - d6 >= 0.0f)
                q = b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
            else {
                const float sum = va + vb + vc;
                q = sum > 0.0f ? a + ab * (vb / sum) + ac * (vc / sum) : a;
            }
        }
        const vec3 d = p - q;
        return glm::dot(d, d);
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

} // namespace

Result<TriangleMesh> readTriangleMesh(const std::string& bytes, const std::string& extension) {
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
    const aiScene* scene = importer.ReadFileFromMemory(
        bytes.data(), bytes.size(),
        aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices,
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
    // One vertex per position across the file's meshes, so that edges between them are shared.
    TriangleMesh mesh;
    std::unordered_map<uint64_t, std::vector<uint32_t>> seen;
    auto vertex = [&](const aiVector3D& v) -> uint32_t {
        const vec3 p(v.x, v.y, v.z);
        uint32_t bits[3];
        std::memcpy(bits, &p, sizeof bits);
        const uint64_t key = (uint64_t(bits[0]) * 0x9E3779B97F4A7C15ull) ^
                             (uint64_t(bits[1]) * 0xC2B2AE3D27D4EB4Full) ^ bits[2];
        std::vector<uint32_t>& same = seen[key];
        for (uint32_t i : same)
            if (mesh.positions[i] == p) return i;
        same.push_back(uint32_t(mesh.positions.size()));
        mesh.positions.push_back(p);
        return same.back();
    };
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh& part = *scene->mMeshes[m];
        for (unsigned f = 0; f < part.mNumFaces; ++f) {
            const aiFace& face = part.mFaces[f];
            if (face.mNumIndices != 3) continue;
            glm::uvec3 t;
            for (int c = 0; c < 3; ++c) {
                const aiVector3D& v = part.mVertices[face.mIndices[c]];
                if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
                    return reason("a NaN or infinite vertex");
                t[c] = vertex(v);
            }
            mesh.triangles.push_back(t);
        }
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
    // Bricks within the band of a triangle's box hold samples.
    size_t stored = 0;
    for (const glm::uvec3& t : mesh.triangles) {
        Box tb;
        for (int c = 0; c < 3; ++c)
            tb.add(mesh.positions[t[c]]);
        const glm::ivec3 lo = brickOf(tb.lo - margin), hi = brickOf(tb.hi + margin);
        for (int z = lo.z; z <= hi.z; ++z)
            for (int y = lo.y; y <= hi.y; ++y)
                for (int x = lo.x; x <= hi.x; ++x) {
                    int32_t& s = f.slots_[slotOf({x, y, z})];
                    if (s == kOutside) s = 0, ++stored;
                }
        if (stored * kBrickSamples * sizeof(float) + slots * sizeof(int32_t) > kMaxMeshFieldBytes)
            return tooLarge(stored * kBrickSamples * sizeof(float) + slots * sizeof(int32_t));
    }
    std::vector<uint32_t> storedSlots;
    storedSlots.reserve(stored);
    for (size_t s = 0; s < slots; ++s)
        if (f.slots_[s] == 0) {
            f.slots_[s] = int32_t(storedSlots.size() * kBrickSamples);
            storedSlots.push_back(uint32_t(s));
        }
    f.samples_.resize(storedSlots.size() * kBrickSamples);
    const Hierarchy h(mesh);
    const auto brickCorner = [&](size_t s) {
        const size_t x = s % size_t(f.bricks_.x),
                     y = (s / size_t(f.bricks_.x)) % size_t(f.bricks_.y),
                     z = s / (size_t(f.bricks_.x) * size_t(f.bricks_.y));
        return f.origin_ + brickSize * vec3(float(x), float(y), float(z));
    };
    // Samples: the distance to the nearest triangle, negative where the winding number says
    // inside. Bricks without samples: their centre's inside.
    const float far = 2.0f * brickSize + margin;
    parallelFor(storedSlots.size(), [&](size_t i) {
        const vec3 corner = brickCorner(storedSlots[i]);
        float* out = &f.samples_[i * kBrickSamples];
        for (int z = 0; z < kBrickSide; ++z)
            for (int y = 0; y < kBrickSide; ++y)
                for (int x = 0; x < kBrickSide; ++x) {
                    const vec3 p = corner + f.cell_ * vec3(float(x), float(y), float(z));
                    const float d = h.nearest(p, far);
                    *out++ = h.winding(p) >= 0.5f ? -d : d;
                }
    });
    parallelFor(slots, [&](size_t s) {
        if (f.slots_[s] != kOutside) return;
        if (h.winding(brickCorner(s) + 0.5f * brickSize) >= 0.5f) f.slots_[s] = kInside;
    });
    return f;
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
