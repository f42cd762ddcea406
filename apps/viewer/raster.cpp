#include "raster.h"

#include "camera.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace sdfcsg::viewer {

namespace {

struct Projected {
    float x, y, z; // pixels, and distance along the view axis
};

uint8_t toByte(float v) {
    return uint8_t(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f);
}

} // namespace

Image rasterize(const Mesh& mesh, const RasterOptions& o) {
    Image image;
    image.width = o.width;
    image.height = o.height;
    image.rgba.resize(size_t(o.width) * o.height * 4);
    for (size_t i = 0; i < size_t(o.width) * o.height; ++i) {
        image.rgba[4 * i + 0] = toByte(o.background.r);
        image.rgba[4 * i + 1] = toByte(o.background.g);
        image.rgba[4 * i + 2] = toByte(o.background.b);
        image.rgba[4 * i + 3] = 255;
    }
    detail::RayCamera rc = detail::makeRayCamera(o.camera, o.width, o.height);
    const float nearZ = 1.0e-3f;
    std::vector<Projected> p(mesh.positions.size());
    for (size_t i = 0; i < p.size(); ++i) {
        glm::vec3 d = mesh.positions[i] - rc.eye;
        float z = glm::dot(d, rc.forward);
        float zs = std::max(z, nearZ);
        float u = glm::dot(d, rc.right) / (zs * rc.tanHalfFov * rc.aspect);
        float v = glm::dot(d, rc.up) / (zs * rc.tanHalfFov);
        p[i] = {(u + 1.0f) * 0.5f * float(o.width), (1.0f - v) * 0.5f * float(o.height), z};
    }
    std::vector<float> depth(size_t(o.width) * o.height, std::numeric_limits<float>::infinity());
    auto put = [&](int x, int y, glm::vec3 c) {
        size_t i = (size_t(y) * o.width + size_t(x)) * 4;
        image.rgba[i] = toByte(c.r), image.rgba[i + 1] = toByte(c.g),
        image.rgba[i + 2] = toByte(c.b);
    };
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        uint32_t ia = mesh.indices[t], ib = mesh.indices[t + 1], ic = mesh.indices[t + 2];
        const Projected &a = p[ia], &b = p[ib], &c = p[ic];
        if (a.z < nearZ || b.z < nearZ || c.z < nearZ) continue;
        float area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
        if (std::abs(area) < 1e-12f) continue;
        int x0 = std::max(0, int(std::floor(std::min({a.x, b.x, c.x}))));
        int x1 = std::min(int(o.width) - 1, int(std::ceil(std::max({a.x, b.x, c.x}))));
        int y0 = std::max(0, int(std::floor(std::min({a.y, b.y, c.y}))));
        int y1 = std::min(int(o.height) - 1, int(std::ceil(std::max({a.y, b.y, c.y}))));
        for (int y = y0; y <= y1; ++y) {
            for (int x = x0; x <= x1; ++x) {
                float px = float(x) + 0.5f, py = float(y) + 0.5f;
                float w0 = ((b.x - px) * (c.y - py) - (b.y - py) * (c.x - px)) / area;
                float w1 = ((c.x - px) * (a.y - py) - (c.y - py) * (a.x - px)) / area;
                float w2 = 1.0f - w0 - w1;
                if (w0 < 0.0f || w1 < 0.0f || w2 < 0.0f) continue;
                // Perspective-correct: interpolate 1/z in screen space.
                float invZ = w0 / a.z + w1 / b.z + w2 / c.z;
                float z = 1.0f / invZ;
                float& stored = depth[size_t(y) * o.width + size_t(x)];
                if (z >= stored) continue;
                stored = z;
                float q0 = w0 / a.z * z, q1 = w1 / b.z * z, q2 = w2 / c.z * z;
                glm::vec3 n = glm::normalize(q0 * mesh.normals[ia] + q1 * mesh.normals[ib] +
                                             q2 * mesh.normals[ic]);
                glm::vec3 base =
                    o.shaded && !mesh.colors.empty()
                        ? q0 * mesh.colors[ia] + q1 * mesh.colors[ib] + q2 * mesh.colors[ic]
                        : glm::vec3(0.8f);
                glm::vec3 view = detail::rayDirection(rc, px, py, o.width, o.height);
                float light = 0.25f + 0.75f * std::max(0.0f, -glm::dot(n, view));
                glm::vec3 colour = base * light;
                if (o.wireframe) {
                    // Distance in pixels to the nearest edge: the barycentric weight of the
                    // opposite vertex times the height of the triangle over that edge.
                    float edge = std::abs(area) * std::min({w0 / std::hypot(b.x - c.x, b.y - c.y),
                                                            w1 / std::hypot(c.x - a.x, c.y - a.y),
                                                            w2 / std::hypot(a.x - b.x, a.y - b.y)});
                    if (edge < 0.6f) colour = glm::vec3(0.05f);
                }
                put(x, y, colour);
            }
        }
    }
    return image;
}

} // namespace sdfcsg::viewer
