#include "mesh/mesh_dual.h"

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

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
    // Twice the area of triangle (u, v, w) seen along the edge: the axis'th component of its
    // cross product.
    auto along = [](glm::vec2 u, glm::vec2 v, glm::vec2 w) {
        const glm::vec2 e = v - u, f = w - u;
        return e.x * f.y - e.y * f.x;
    };
    for (size_t q = 0; q + 6 <= mesh.indices.size(); q += 6) {
        uint32_t* t = &mesh.indices[q];
        const uint32_t a = t[0], b = t[1], c = t[2];
        const int axis = t[3] == a ? 0 : t[3] == c ? 1 : 2;
        const uint32_t d = axis == 0 ? t[5] : axis == 1 ? t[4] : t[3];
        // The quad seen along its edge. Each vertex lies strictly inside its cell (kInset in
        // the shader), so it is a simple polygon around the edge, and at least one diagonal
        // lies inside it.
        auto seen = [&](uint32_t k) {
            const glm::vec3& x = p[k];
            return axis == 0   ? glm::vec2(x.y, x.z)
                   : axis == 1 ? glm::vec2(x.z, x.x)
                               : glm::vec2(x.x, x.y);
        };
        const glm::vec2 sa = seen(a), sb = seen(b), sc = seen(c), sd = seen(d);
        const float abc = along(sa, sb, sc), acd = along(sa, sc, sd);
        const float abd = along(sa, sb, sd), bcd = along(sb, sc, sd);
        const float winding = abc + acd;
        const bool acWinds = abc * winding > 0.0f && acd * winding > 0.0f;
        const bool bdWinds = abd * winding > 0.0f && bcd * winding > 0.0f;
        bool alongBd = bdWinds;
        if (acWinds == bdWinds) {
            const float facingAc = std::min(facing(a, b, c, b), facing(a, c, d, d));
            const float facingBd = std::min(facing(a, b, d, a), facing(b, c, d, c));
            // The margin keeps the first diagonal where both fold alike (a flat quad), so that
            // float rounding does not pick between them.
            alongBd = facingBd > facingAc + 1e-3f;
        }
        // Back as (a, b, c), (a, c, d) or (a, b, d), (b, c, d), writing only what changes.
        if (alongBd) {
            const uint32_t split[6] = {a, b, d, b, c, d};
            std::copy(split, split + 6, t);
        } else if (axis != 0) {
            t[3] = a, t[4] = c, t[5] = d;
        }
    }
}

} // namespace sdfcsg::detail
