// A triangle mesh read from a file, and the signed distance field made from it: the exact
// distance to the triangles in a narrow band of bricks about the surface, a bound beyond it, and
// the inside told by the generalised winding number (Jacobson, Kavan and Sorkine-Hornung 2013),
// so that a mesh with holes, flipped or repeated triangles, as files from elsewhere often are,
// still has a sensible inside. The winding number is summed through a hierarchy of triangles, far
// clusters as dipoles (Barill, Dickson, Schmidt, Levin and Jacobson 2018, fast winding numbers).
#pragma once

#include "sdfcsg/error.h"
#include "sdfcsg/scene.h"

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace sdfcsg::detail {

// What a mesh node may read: the file's size, and its triangles once read. A file over either
// is refused before the field is made.
inline constexpr uintmax_t kMaxMeshFileBytes = uintmax_t(256) << 20;
inline constexpr size_t kMaxMeshTriangles = size_t(8) << 20;
// The field's memory: its bricks' samples and the grid of brick slots, as much as a scene's words
// may hold in all (kMaxOutlineWords).
inline constexpr size_t kMaxMeshFieldBytes = size_t(64) << 20;

struct TriangleMesh {
    std::vector<glm::vec3> positions;
    std::vector<glm::uvec3> triangles; // indices into positions, counter-clockwise seen outside
    // Per corner, three per triangle in the triangles' order: the file's colour there as 0xRRGGBB,
    // as shown on screen (sRGB), or kNoColor; empty where the file has no colours at all.
    std::vector<uint32_t> colors;
};
inline constexpr uint32_t kNoColor = ~0u;

// The triangles of an STL (binary or ASCII), OBJ, PLY, glTF (.gltf or binary .glb) or 3MF file,
// read through Assimp with every node's transform applied (a binary STL without colours and a
// 3MF by sdfcsg's own readers: read_3mf.h), points and lines left out, with its colours: per
// vertex where it has them (PLY, OBJ's "v x y z r g b", glTF's COLOR_0, a binary STL's), else its
// materials' diffuse or base colour (OBJ's .mtl Kd, glTF's baseColorFactor; Assimp's default
// material is no colour, nor is an OBJ's Kd of its default grey 0.6, which a material missing
// from the .mtl gets); a 3MF's per triangle or corner, from its base materials' display colours
// and colour groups. A 3MF's unit is converted to centimetres, the scene unit that sdfcsg writes
// 3MF in by default (kDefaultLengthUnit); other formats are read as their numbers are. glTF's
// linear colours are turned to sRGB. STL and 3MF, made for printing, are z up (as sdfcsg writes
// them): they are turned so that their z is +y. `bytes` is the file's contents and `extension` its
// name's (".stl", ...), which tells the format. The files it names (a glTF's buffers, an OBJ's
// materials) are read from `folder` alone, as an untrusted scene's are (SceneFiles): no absolute
// path, no "..", nothing outside it; none where `folder` is empty. Errors are the reason alone, for
// the caller to place ("not a mesh file that can be read: ...", "no triangles", "more than N
// triangles", "a NaN or infinite vertex", a 3MF's "3D/3dmodel.model, line 12: a triangle's v3 (7)
// past its object's 3 vertices").
Result<TriangleMesh> readTriangleMesh(const std::string& bytes, const std::string& extension,
                                      const std::filesystem::path& folder = {});

// What a mesh has that a closed, consistently oriented one would not: the inside it gets from
// the winding number copes with each, and the user is told.
struct MeshDefects {
    size_t openEdges = 0;    // edges of one triangle
    size_t crowdedEdges = 0; // edges of three or more triangles
    size_t flippedEdges = 0; // edges whose two triangles run the same way along them
    size_t degenerate = 0;   // triangles of no area
    bool any() const { return openEdges + crowdedEdges + flippedEdges + degenerate > 0; }
};
MeshDefects meshDefects(const TriangleMesh& mesh);

// The sampled field: a grid of bricks of kBrick cells over the mesh's box grown by the band;
// a brick within the band of a triangle holds (kBrick + 1)^3 samples of the signed distance (its
// corners shared with its neighbours, so that trilinear interpolation never leaves the brick),
// any other the sign of its inside alone. A mesh with colours gives each sample the colour of its
// nearest point of the surface too.
class MeshField {
  public:
    static constexpr int kBrick = 8;

    // `cells`: the cells along the box's longest side; the band reaches `bandCells` cells from
    // the surface (at least the diagonal of one cell, so that every cell the surface crosses
    // has its samples). Samples within the band hold the exact distance to the nearest
    // triangle; those up to a cell beyond it, the distance to the nearest of the triangles
    // nearest to their neighbours (within a few hundredths of a cell of it); the rest, the band
    // plus a cell. Refused where the field would exceed `maxBytes` (a mesh node's limit, unless a
    // test measuring meshes asks for more).
    static Result<MeshField> make(const TriangleMesh& mesh, int cells, float bandCells = 2.0f,
                                  size_t maxBytes = kMaxMeshFieldBytes);

    // The signed distance to the zero set of another field, `value`, that lies between the
    // distance over some factor and the distance (a bound of the same sign: a field that is not
    // a distance, FlatNode::loss), in bricks of `cell` about its surface out to `band` (at least
    // the diagonal of a cell) and a cell beyond, within the box lo..hi that the surface lies in
    // (the grid reaches a cell past the band beyond it). The field is sampled at the grid's
    // points in the bricks it may reach the band in (its value is at most the distance: a brick
    // whose centre's value exceeds the margin by its half-diagonal holds none of it), the
    // surface found where a grid edge changes sign (bisected to a 64th of a cell, then the line
    // through the ends' values), and
    // each sample's distance is that to the nearest of those points, exact within two cells and
    // carried outwards by dilation (a few thousandths of a cell beyond), its sign the field's.
    // A point cloud's distance exceeds the surface's by at most s^2 / 2d at distance d for
    // points s apart, a fraction of a percent at 4 cells and more. `color`, where given, is the
    // colour at a point of the surface, and each sample gets its nearest point's. Both are called
    // from several threads at once. Refused where the field would exceed `maxBytes`.
    static Result<MeshField> fromField(const std::function<float(glm::vec3)>& value,
                                       const std::function<glm::vec3(glm::vec3)>& color,
                                       glm::vec3 lo, glm::vec3 hi, float cell, float band,
                                       size_t maxBytes);

    // The signed distance at p, in the mesh's units: exact to interpolation within the band, a
    // bound of the right sign (the band's width, or the distance to the grid's box plus it)
    // beyond.
    float distance(glm::vec3 p) const;
    // The mesh's colour at p: that of the sample nearest to p (the colour of the surface within
    // a cell of it), or `fallback` (the node's colour) where the mesh has no colours, the sample's
    // nearest corner has none, or p lies in no brick with samples. sdMesh's colour, colorMesh.
    glm::vec3 color(glm::vec3 p, glm::vec3 fallback) const;
    bool hasColors() const { return !colors_.empty(); }

    glm::vec3 origin() const { return origin_; }
    float cell() const { return cell_; }
    float band() const { return band_; }
    glm::ivec3 bricks() const { return bricks_; }
    // The mesh's defects (meshDefects), counted as the field was made.
    const MeshDefects& defects() const { return defects_; }
    size_t storedBricks() const { return samples_.size() / kBrickSamples; }
    size_t bytes() const {
        return (samples_.size() + colors_.size()) * sizeof(float) + slots_.size() * sizeof(int32_t);
    }
    // sdMesh's and colorMesh's words (shaders/sdf.glsl).
    std::vector<glm::vec4> words() const;

    // fromField's: the box of the surface points found, empty where none were.
    glm::vec3 surfaceMin() const { return surfaceMin_; }
    glm::vec3 surfaceMax() const { return surfaceMax_; }

  private:
    // A brick's slot in slots_ (x fastest), and the brick of a slot.
    size_t slotOf(glm::ivec3 b) const {
        return (size_t(b.z) * size_t(bricks_.y) + size_t(b.y)) * size_t(bricks_.x) + size_t(b.x);
    }
    glm::ivec3 brickOfSlot(size_t s) const {
        return glm::ivec3(int(s % size_t(bricks_.x)),
                          int(s / size_t(bricks_.x) % size_t(bricks_.y)),
                          int(s / (size_t(bricks_.x) * size_t(bricks_.y))));
    }
    // make's and fromField's dilation outwards from the surface (mesh_field.cpp).
    template <class Nearer>
    static void dilate(const MeshField& f, const std::vector<uint32_t>& brickSlots, float reach,
                       float margin, std::vector<float>& best, std::vector<uint32_t>& nearest,
                       const Nearer& nearer);

    static constexpr int kBrickSide = kBrick + 1,
                         kBrickSamples = kBrickSide * kBrickSide * kBrickSide;
    static constexpr int32_t kOutside = -1, kInside = -2; // slots of bricks without samples

    glm::vec3 origin_{0.0f}; // the grid's least corner
    float cell_ = 1.0f, band_ = 1.0f;
    glm::ivec3 bricks_{0};
    MeshDefects defects_;
    glm::vec3 surfaceMin_{std::numeric_limits<float>::infinity()},
        surfaceMax_{-std::numeric_limits<float>::infinity()};
    std::vector<int32_t> slots_; // per brick: its samples' index, or kOutside / kInside
    std::vector<float> samples_; // kBrickSamples per stored brick, x fastest
    // As samples_, each sample's colour as r 65536 + g 256 + b (exact in a float), -1 for none;
    // empty for a mesh without colours.
    std::vector<float> colors_;
};

// Scales the mesh by one factor on every axis and moves its box's centre to the origin, so that
// its box fits `box` and touches it on at least one axis (the mesh node's "fit"). Done to the
// triangles before the field is made, the field holds distances in the scene's units, with no
// scale to undo when it is sampled.
void fitMesh(TriangleMesh& mesh, glm::vec3 box);

// The mesh node's words end with one more than MeshField::words(): its file's defects (open,
// crowded and flipped edges, degenerate triangles), which sdMesh does not read, for the note that
// tells the user (fieldNotes in sdfcsg/eval.h). Counts above 2^24 lose their last digits.
glm::vec4 defectsWord(const MeshDefects& defects);
MeshDefects storedDefects(const std::vector<glm::vec4>& words);

// The mesh node's words (Node::words, sdMesh's layout in shaders/sdf.glsl, then defectsWord): its
// "file" found
// under `files` (sceneFile()) and read, fitted to its "fit" (fitMesh) where given, its field made
// at its "resolution". Errors are for the caller to place at the node's "file"; an untrusted
// scene's problems with the file say "unknown mesh" and nothing of the file system.
Result<std::shared_ptr<const std::vector<glm::vec4>>> buildMesh(const Node& node,
                                                                const SceneFiles& files);

// The generalised winding number of the mesh at each of `points`: near 1 inside a closed
// surface, near 0 outside, in between near a hole. Exposed for tests.
std::vector<float> windingNumbers(const TriangleMesh& mesh, const std::vector<glm::vec3>& points);

} // namespace sdfcsg::detail
