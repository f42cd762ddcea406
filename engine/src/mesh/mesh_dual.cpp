#include "mesh/mesh_dual.h"

#include <glm/geometric.hpp>

#include <algorithm>

namespace sdfcsg::detail {

void foldQuads(Mesh& mesh) {
    const std::vector<glm::vec3>& p = mesh.positions;
    const std::vector<glm::vec3>& n = mesh.normals;
    // How well triangle (u, v, w) faces like vertex `off`'s normal: the cosine, or -2 when it
    // has no area.
    auto facing = [&](uint32_t u, uint32_t v, uint32_t w, uint32_t off) {
        const glm::vec3 c = glm::cross(p[v] - p[u], p[w] - p[u]);
        const float length = glm::length(c);
        return length > 0.0f ? glm::dot(c, n[off]) / length : -2.0f;
    };
    for (size_t q = 0; q + 6 <= mesh.indices.size(); q += 6) {
        uint32_t* t = &mesh.indices[q];
        const uint32_t a = t[0], b = t[1], c = t[2], d = t[5];
        const float alongAc = std::min(facing(a, b, c, b), facing(a, c, d, d));
        const float alongBd = std::min(facing(a, b, d, a), facing(b, c, d, c));
        // The margin keeps the first diagonal where both fold alike (a flat quad), so that float
        // rounding does not pick between them.
        if (alongBd > alongAc + 1e-3f) {
            const uint32_t split[6] = {a, b, d, b, c, d};
            std::copy(split, split + 6, t);
        }
    }
}

} // namespace sdfcsg::detail
