// PNG images that a scene names: the image profile's mask, made into a grid of signed distances
// as shaders/sdf.glsl's sdImage reads it, and the heightmap's heights, as sdHeightmap reads them.
//
// The words (Node::words): word 0 is (samples per row nx, rows ny, sample spacing, 0), word 1
// the image's rectangle (lo xy, hi xy), centred on the origin; from word 2 the nx * ny signed
// distances, four to a word, row by row from the bottom (the image's last row) up. The samples
// sit at the centres of the image's pixels and of a ring of pixels around it that count as
// outside, so every edge of the mask lies inside the rectangle of samples.
//
// A heightmap's words: word 0 is (samples per row nx, rows ny, 1 / its Lipschitz bound, 0), word 1
// (half its size along x, along z, its height, 0); from word 2 the heights at the pixels' centres,
// four to a word, row by row from the image's top (-z) to its bottom (+z).
#pragma once

#include "sdfcsg/error.h"
#include "sdfcsg/scene.h"

#include <glm/vec4.hpp>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

namespace sdfcsg::detail {

// The largest PNG file a scene may name, the most pixels of its image and the longest side
// (checked from its header before it is decoded).
inline constexpr uintmax_t kMaxImageBytes = uintmax_t(16) << 20;
inline constexpr uint64_t kMaxImagePixels = uint64_t(2048) * 2048;
inline constexpr uint32_t kMaxImageSide = 8192;

// An image's pixels as grey levels and coverage, 0 to 1, row by row from the top.
struct GreyImage {
    uint32_t width = 0, height = 0;
    std::vector<float> grey, alpha;
};

// The PNG at `file` (a regular file of at most kMaxImageBytes, sceneFile()). Errors are the
// reason alone, for the caller to place: "not a PNG file", "a PNG of 0 x 0 pixels ...", "a PNG of
// W x H pixels, more than ...", "a PNG that cannot be decoded (...)".
Result<GreyImage> readPng(const std::filesystem::path& file);

// The signed distance, in pixels, from each centre of a w by h grid of pixels to the edges
// between the pixels inside (`inside`, row by row) and those outside: the exact Euclidean
// distance to the nearest centre of the other side, by the transform of Felzenszwalb and
// Huttenlocher ("Distance Transforms of Sampled Functions", 2012), less half a pixel, so that the
// edge lies halfway between two centres; negative inside. A side with no pixels counts as 1e10
// pixels away.
std::vector<float> signedDistances(const std::vector<bool>& inside, uint32_t w, uint32_t h);

// The image node's words (above): its "file" found under `files` and read, the mask made by its
// threshold and "inside", the distances measured and scaled to its size. Errors are for the
// caller to place at the node's "file"; an untrusted scene's problems with the file say
// "unknown image" and nothing of the file system.
Result<std::shared_ptr<const std::vector<glm::vec4>>> buildImage(const Node& node,
                                                                 const SceneFiles& files);

// The heightmap node's words (above): grey levels 0 to 1 as heights 0 to size.y over size.x by
// size.z, and the Lipschitz bound of y - height(x, z), sqrt(1 + sx^2 + sz^2) with sx and sz the
// steepest slopes between neighbouring pixels along x and z. Errors as buildImage's.
Result<std::shared_ptr<const std::vector<glm::vec4>>> buildHeightmap(const Node& node,
                                                                     const SceneFiles& files);

} // namespace sdfcsg::detail
