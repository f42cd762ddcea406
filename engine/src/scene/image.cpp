// PNG images through stb_image, read from memory after their header has been checked against
// the limits, so that a hostile file's claimed size costs nothing.
#include "scene/image.h"

#include "scene/files.h"
#include "scene/json_writer.h"
#include "scene/parse_util.h"

#define STBI_ONLY_PNG
#define STBI_NO_STDIO
#define STBI_FAILURE_USERMSG
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wunused-but-set-variable"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#endif
#include <stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include <algorithm>
#include <cmath>
#include <iterator>
#include <memory>
#include <string>

namespace sdfcsg::detail {

namespace {

Error problem(std::string text) {
    return Error::message(ErrorKind::Validation, {}, std::move(text));
}

uint32_t bigEndian(const unsigned char* b) {
    return uint32_t(b[0]) << 24 | uint32_t(b[1]) << 16 | uint32_t(b[2]) << 8 | uint32_t(b[3]);
}

// Felzenszwalb and Huttenlocher's one-dimensional transform: d[q] = min over r of (q - r)^2 +
// f[r], the lower envelope of the parabolas rooted at each r, in time linear in n. v and z hold
// the envelope's parabolas and the boundaries between them.
void envelope(const float* f, size_t n, float* d, std::vector<size_t>& v, std::vector<double>& z) {
    const auto meet = [&](size_t q, size_t r) { // where the parabolas of q and r cross
        return ((double(f[q]) + double(q) * double(q)) - (double(f[r]) + double(r) * double(r))) /
               (2.0 * double(q) - 2.0 * double(r));
    };
    size_t k = 0;
    v[0] = 0, z[0] = -HUGE_VAL, z[1] = HUGE_VAL;
    for (size_t q = 1; q < n; ++q) {
        double s = meet(q, v[k]);
        while (s <= z[k])
            s = meet(q, v[--k]); // z[0] is -inf: k stays at least 0
        ++k;
        v[k] = q, z[k] = s, z[k + 1] = HUGE_VAL;
    }
    k = 0;
    for (size_t q = 0; q < n; ++q) {
        while (z[k + 1] < double(q))
            ++k;
        const double r = double(q) - double(v[k]);
        d[q] = float(r * r + double(f[v[k]]));
    }
}

// The squared distance from each centre to the nearest centre where inside == want: columns,
// then rows.
std::vector<float> squaredDistances(const std::vector<bool>& inside, bool want, uint32_t w,
                                    uint32_t h) {
    constexpr float far = 1e20f;
    std::vector<float> grid(size_t(w) * h);
    for (size_t i = 0; i < grid.size(); ++i)
        grid[i] = inside[i] == want ? 0.0f : far;
    const size_t longest = std::max(w, h);
    std::vector<float> line(longest), out(longest);
    std::vector<size_t> v(longest);
    std::vector<double> z(longest + 1);
    for (size_t x = 0; x < w; ++x) {
        for (size_t y = 0; y < h; ++y)
            line[y] = grid[x + w * y];
        envelope(line.data(), h, out.data(), v, z);
        for (size_t y = 0; y < h; ++y)
            grid[x + w * y] = out[y];
    }
    for (size_t y = 0; y < h; ++y) {
        envelope(&grid[w * y], w, out.data(), v, z);
        std::copy_n(out.data(), w, &grid[w * y]);
    }
    return grid;
}

} // namespace

Result<GreyImage> readPng(const std::filesystem::path& file) {
    const auto read = readFileBytes(file, kMaxImageBytes);
    if (!read) return read.error();
    const std::string& bytes = *read;
    // The signature, then the IHDR chunk: length, type, width, height.
    static constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    const auto* b = reinterpret_cast<const unsigned char*>(bytes.data());
    if (bytes.size() < 24 || !std::equal(kSignature, kSignature + 8, b) ||
        bytes.compare(12, 4, "IHDR") != 0)
        return problem("not a PNG file");
    const uint32_t w = bigEndian(b + 16), h = bigEndian(b + 20);
    const std::string size = std::to_string(w) + " x " + std::to_string(h) + " pixels";
    if (w == 0 || h == 0) return problem("a PNG of " + size + ", expected at least 1 x 1");
    if (w > kMaxImageSide || h > kMaxImageSide || uint64_t(w) * h > kMaxImagePixels)
        return problem("a PNG of " + size + ", more than the limit of " +
                       std::to_string(kMaxImagePixels) + " pixels and " +
                       std::to_string(kMaxImageSide) + " on a side");
    int x = 0, y = 0, channels = 0;
    // Grey and alpha: stb_image weighs colours as luminance, and gives opaque images alpha 1.
    std::unique_ptr<stbi_uc, void (*)(void*)> pixels(
        stbi_load_from_memory(b, int(bytes.size()), &x, &y, &channels, 2), stbi_image_free);
    if (!pixels || uint32_t(x) != w || uint32_t(y) != h)
        return problem(std::string("a PNG that cannot be decoded (") +
                       (pixels ? "its size changed" : stbi_failure_reason()) + ")");
    GreyImage image{w, h, std::vector<float>(size_t(w) * h), std::vector<float>(size_t(w) * h)};
    for (size_t i = 0; i < image.grey.size(); ++i) {
        image.grey[i] = float(pixels.get()[2 * i]) / 255.0f;
        image.alpha[i] = float(pixels.get()[2 * i + 1]) / 255.0f;
    }
    return image;
}

std::vector<float> signedDistances(const std::vector<bool>& inside, uint32_t w, uint32_t h) {
    const std::vector<float> toInside = squaredDistances(inside, true, w, h);
    const std::vector<float> toOutside = squaredDistances(inside, false, w, h);
    std::vector<float> d(toInside.size());
    for (size_t i = 0; i < d.size(); ++i)
        d[i] = inside[i] ? 0.5f - std::min(std::sqrt(toOutside[i]), 1e10f)
                         : std::min(std::sqrt(toInside[i]), 1e10f) - 0.5f;
    return d;
}

namespace {

// The image that the node's "file" names, found under `files` and read.
Result<GreyImage> nodeImage(const Node& node, const SceneFiles& files) {
    const std::string& name = node.strings[0];
    auto fail = [&](const std::string& why) {
        return problem(
            nodeFileProblem("image", name, files, why, ": name a PNG file in the scene's folder"));
    };
    auto file = sceneFile(name, files, kMaxImageBytes);
    if (!file) return fail(file.error().diagnostics[0].message);
    auto image = readPng(*file);
    if (!image) return fail(image.error().diagnostics[0].message);
    return image;
}

} // namespace

Result<std::shared_ptr<const std::vector<glm::vec4>>> buildImage(const Node& node,
                                                                 const SceneFiles& files) {
    const std::string& name = node.strings[0];
    auto image = nodeImage(node, files);
    if (!image) return image.error();

    // Inside: ink (dark and opaque) at least the threshold, or with "inside": "light", light and
    // opaque; the ring around the image is outside.
    const uint32_t w = image->width, h = image->height, nx = w + 2, ny = h + 2;
    const float threshold = node.params[3];
    const bool light = node.params[4] != 0.0f;
    std::vector<bool> inside(size_t(nx) * ny, false);
    bool any = false;
    for (uint32_t r = 0; r < h; ++r)
        for (uint32_t c = 0; c < w; ++c) {
            const size_t i = c + size_t(w) * r;
            const float ink = image->alpha[i] * (light ? image->grey[i] : 1.0f - image->grey[i]);
            const bool in = ink >= threshold && ink > 0.0f;
            inside[(c + 1) + size_t(nx) * (h - r)] = in; // row r from the top is row h - r
            any = any || in;
        }
    if (!any)
        return problem("expected an image with pixels inside its mask (" +
                       std::string(light ? "light" : "dark") +
                       " and opaque, at least the threshold " + formatFloat(threshold) + "), got " +
                       "none in " + quote(name));
    const std::vector<float> d = signedDistances(inside, nx, ny);

    // "size" sets the longer side, "width" or "height" (slots 1 and 2, 0 when absent) that side.
    const float side = node.params[1] > 0.0f   ? node.params[1] / float(w)
                       : node.params[2] > 0.0f ? node.params[2] / float(h)
                                               : node.params[0] / float(std::max(w, h));
    const glm::vec2 half = 0.5f * side * glm::vec2(float(w), float(h));
    auto words = std::make_shared<std::vector<glm::vec4>>(2 + (d.size() + 3) / 4, glm::vec4(0.0f));
    (*words)[0] = glm::vec4(float(nx), float(ny), side, 0.0f);
    (*words)[1] = glm::vec4(-half.x, -half.y, half.x, half.y);
    for (size_t i = 0; i < d.size(); ++i)
        (*words)[2 + i / 4][int(i % 4)] = d[i] * side;
    return std::shared_ptr<const std::vector<glm::vec4>>(std::move(words));
}

Result<std::shared_ptr<const std::vector<glm::vec4>>> buildHeightmap(const Node& node,
                                                                     const SceneFiles& files) {
    auto image = nodeImage(node, files);
    if (!image) return image.error();
    const uint32_t w = image->width, h = image->height;
    const glm::vec3 size(node.params[0], node.params[1], node.params[2]);
    const glm::vec2 cell(size.x / float(w), size.z / float(h));
    // The interpolation's steepest slope along x and along z bounds its gradient's length.
    double sx = 0.0, sz = 0.0;
    for (uint32_t r = 0; r < h; ++r)
        for (uint32_t c = 0; c < w; ++c) {
            const size_t i = c + size_t(w) * r;
            if (c + 1 < w) sx = std::max(sx, double(std::abs(image->grey[i + 1] - image->grey[i])));
            if (r + 1 < h) sz = std::max(sz, double(std::abs(image->grey[i + w] - image->grey[i])));
        }
    sx *= double(size.y) / double(cell.x), sz *= double(size.y) / double(cell.y);
    auto words =
        std::make_shared<std::vector<glm::vec4>>(2 + (image->grey.size() + 3) / 4, glm::vec4(0.0f));
    (*words)[0] =
        glm::vec4(float(w), float(h), float(1.0 / std::sqrt(1.0 + sx * sx + sz * sz)), 0.0f);
    (*words)[1] = glm::vec4(0.5f * size.x, 0.5f * size.z, size.y, 0.0f);
    for (size_t i = 0; i < image->grey.size(); ++i)
        (*words)[2 + i / 4][int(i % 4)] = image->grey[i] * size.y;
    return std::shared_ptr<const std::vector<glm::vec4>>(std::move(words));
}

} // namespace sdfcsg::detail
