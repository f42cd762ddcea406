// Every primitive's CPU distance (engine/src/field/sdf.h, fed through the table -> kernel parameter
// mapping) against a true distance computed independently in double precision: convex polytopes
// by point-to-triangle distances, solids of revolution by 2D distances to their profile in the
// meridian half-plane, torus and capsule by minimising over their core curve.
#include "field/sdf.h"

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace sdfcsg {
namespace {

using glm::dvec2;
using glm::dvec3;

// ---- Independent truths ----

// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
dvec3 closestOnTriangle(dvec3 p, dvec3 a, dvec3 b, dvec3 c) {
    dvec3 ab = b - a, ac = c - a, ap = p - a;
    double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return a;
    dvec3 bp = p - b;
    double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return b;
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
    dvec3 cp = p - c;
    double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return c;
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    double denom = 1.0 / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

// A convex polytope given by its vertices and faces (vertex index loops).
struct Polytope {
    std::vector<dvec3> vertices;
    std::vector<std::vector<int>> faces;

    double signedDistance(dvec3 p) const {
        dvec3 centre(0.0);
        for (dvec3 v : vertices)
            centre += v;
        centre /= double(vertices.size());
        double outside = INFINITY, planeMax = -INFINITY;
        for (const auto& f : faces) {
            dvec3 a = vertices[size_t(f[0])];
            dvec3 n = normalize(cross(vertices[size_t(f[1])] - a, vertices[size_t(f[2])] - a));
            if (dot(n, centre - a) > 0) n = -n; // outward
            planeMax = std::max(planeMax, dot(n, p - a));
            for (size_t i = 1; i + 1 < f.size(); ++i) {
                dvec3 q =
                    closestOnTriangle(p, a, vertices[size_t(f[i])], vertices[size_t(f[i + 1])]);
                outside = std::min(outside, length(p - q));
            }
        }
        // Inside a convex solid the nearest boundary point lies on the nearest face plane.
        return planeMax <= 0 ? planeMax : outside;
    }
};

Polytope boxPolytope(dvec3 h) {
    Polytope poly;
    for (int i = 0; i < 8; ++i)
        poly.vertices.push_back({i & 1 ? h.x : -h.x, i & 2 ? h.y : -h.y, i & 4 ? h.z : -h.z});
    poly.faces = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4},
                  {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
    return poly;
}

Polytope prismPolytope(double w, double h, double l) {
    Polytope poly;
    for (double z : {-l / 2, l / 2}) {
        poly.vertices.push_back({-w / 2, -h / 2, z});
        poly.vertices.push_back({w / 2, -h / 2, z});
        poly.vertices.push_back({0, h / 2, z});
    }
    poly.faces = {{0, 1, 2}, {3, 4, 5}, {0, 1, 4, 3}, {1, 2, 5, 4}, {2, 0, 3, 5}};
    return poly;
}

double segmentDistance(dvec2 p, dvec2 a, dvec2 b) {
    dvec2 ab = b - a;
    double t = std::clamp(dot(p - a, ab) / dot(ab, ab), 0.0, 1.0);
    return length(p - (a + ab * t));
}

// A solid of revolution about y: its profile is a convex polygon in the (r, y) half-plane whose
// first and last vertices lie on the axis. The axis edge is not surface.
double revolvedDistance(dvec3 p, const std::vector<dvec2>& profile) {
    dvec2 q(std::sqrt(p.x * p.x + p.z * p.z), p.y);
    double d = INFINITY;
    for (size_t i = 0; i + 1 < profile.size(); ++i)
        d = std::min(d, segmentDistance(q, profile[i], profile[i + 1]));
    bool inside = true; // convex and counter-clockwise: left of every edge, the axis edge too
    for (size_t i = 0; i < profile.size(); ++i) {
        dvec2 a = profile[i], b = profile[(i + 1) % profile.size()];
        if ((b.x - a.x) * (q.y - a.y) - (b.y - a.y) * (q.x - a.x) < 0) inside = false;
    }
    return inside ? -d : d;
}

// Minimum of a function that is unimodal on [lo, hi] after bracketing it on a coarse grid.
double minimise(const std::function<double(double)>& f, double lo, double hi, int grid) {
    double best = lo, bestValue = INFINITY;
    for (int i = 0; i <= grid; ++i) {
        double x = lo + (hi - lo) * i / grid;
        if (double v = f(x); v < bestValue) bestValue = v, best = x;
    }
    double step = (hi - lo) / grid, a = std::max(lo, best - step), b = std::min(hi, best + step);
    for (int i = 0; i < 200; ++i) {
        double m1 = a + (b - a) / 3, m2 = b - (b - a) / 3;
        if (f(m1) < f(m2))
            b = m2;
        else
            a = m1;
    }
    return std::min(bestValue, f(0.5 * (a + b)));
}

// The profile of the hull of two circles on the axis (centres (0, y1) and (0, y2), y1 < y2, radii
// r1 and r2) in the (r, y) half-plane, as a fine polygon from the bottom to the top of the axis.
std::vector<dvec2> twoCircleHull(double y1, double r1, double y2, double r2) {
    const double b = (r1 - r2) / (y2 - y1), a = std::sqrt(1 - b * b);
    const double tangent = std::atan2(b, a);
    std::vector<dvec2> out;
    const int n = 6000;
    for (int i = 0; i <= n; ++i) {
        double t = -M_PI / 2 + (tangent + M_PI / 2) * i / n;
        out.push_back({r1 * std::cos(t), y1 + r1 * std::sin(t)});
    }
    for (int i = 0; i <= n; ++i) {
        double t = tangent + (M_PI / 2 - tangent) * i / n;
        out.push_back({r2 * std::cos(t), y2 + r2 * std::sin(t)});
    }
    out.front().x = out.back().x = 0;
    return out;
}

// Distance from p to the arc of the circle of centre c and radius r in the plane spanned by the
// unit vectors u and v, from angle t0 to t1 (radians, measured from u towards v).
double arcDistance(dvec3 p, dvec3 c, dvec3 u, dvec3 v, double r, double t0, double t1) {
    dvec3 q = p - c;
    double t = std::atan2(dot(q, v), dot(q, u));
    while (t < t0)
        t += 2 * M_PI;
    auto at = [&](double a) { return c + r * (std::cos(a) * u + std::sin(a) * v); };
    double d = std::min(length(p - at(t0)), length(p - at(t1)));
    if (t <= t1) d = std::min(d, length(p - at(t)));
    return d;
}

// Signed distance to the ellipsoid with semi-axes e (Eberly, "Distance from a point to an
// ellipse, an ellipsoid or a hyperellipsoid"): the root t of sum (e_i y_i / (t + e_i^2))^2 = 1
// by bisection, for a point off the coordinate planes.
double ellipsoidDistance(dvec3 p, dvec3 e) {
    dvec3 y = abs(p);
    auto f = [&](double t) {
        double s = 0;
        for (int i = 0; i < 3; ++i) {
            double r = e[i] * y[i] / (t + e[i] * e[i]);
            s += r * r;
        }
        return s - 1;
    };
    const double smallest = std::min({e.x, e.y, e.z});
    double lo = -smallest * smallest, hi = length(y) * std::max({e.x, e.y, e.z}) + 1;
    for (int i = 0; i < 200; ++i) {
        double mid = 0.5 * (lo + hi);
        (f(mid) > 0 ? lo : hi) = mid;
    }
    double t = 0.5 * (lo + hi);
    dvec3 x;
    for (int i = 0; i < 3; ++i)
        x[i] = e[i] * e[i] * y[i] / (t + e[i] * e[i]);
    double d = length(y - x);
    return f(0) > 0 ? d : -d;
}

// ---- Cases ----

struct Case {
    std::string label;
    NodeKind kind;
    sdf::Params params;                 // table values: full sizes
    std::function<double(dvec3)> truth; // exact signed distance
    double size;                        // rough extent, for sampling and tolerances
};

std::vector<Case> cases() {
    std::vector<Case> out;
    auto add = [&](std::string label, NodeKind kind, sdf::Params params,
                   std::function<double(dvec3)> truth, double size) {
        out.push_back({std::move(label), kind, params, std::move(truth), size});
    };
    for (double r : {0.5, 1.7})
        add(
            "sphere " + std::to_string(r), NodeKind::Sphere, {float(r)},
            [r](dvec3 p) { return length(p) - r; }, r);
    for (dvec3 s : {dvec3(1, 2, 3), dvec3(0.2, 1.5, 0.4)}) {
        Polytope poly = boxPolytope(s / 2.0);
        add(
            "box", NodeKind::Box, {float(s.x), float(s.y), float(s.z)},
            [poly](dvec3 p) { return poly.signedDistance(p); }, length(s) / 2);
    }
    for (double r : {0.0, 0.15, 0.29}) {
        dvec3 s(1.2, 0.6, 2.0);
        // The rounded box is the inner box grown by r (a Minkowski sum with a ball).
        Polytope inner = boxPolytope(s / 2.0 - r);
        add(
            "round_box r=" + std::to_string(r), NodeKind::RoundBox,
            {float(s.x), float(s.y), float(s.z), float(r)},
            [inner, r](dvec3 p) { return inner.signedDistance(p) - r; }, length(s) / 2);
    }
    {
        dvec3 n = normalize(dvec3(0.3, 1.0, -0.2));
        add(
            "plane", NodeKind::Plane, {0.3f, 1.0f, -0.2f, 0.4f},
            [n](dvec3 p) { return dot(p, n) - 0.4; }, 2.0);
    }
    for (dvec3 whl : {dvec3(2, 1, 3), dvec3(0.5, 2, 0.8), dvec3(3, 0.3, 1)}) {
        Polytope poly = prismPolytope(whl.x, whl.y, whl.z);
        add(
            "triangular_prism", NodeKind::TriangularPrism,
            {float(whl.x), float(whl.y), float(whl.z)},
            [poly](dvec3 p) { return poly.signedDistance(p); }, length(whl) / 2);
    }
    for (dvec2 rr : {dvec2(1.0, 0.25), dvec2(0.6, 0.5)}) {
        double major = rr.x, minor = rr.y;
        // Distance to the core circle, minimised over its angle.
        add(
            "torus", NodeKind::Torus, {float(major), float(minor)},
            [major, minor](dvec3 p) {
                auto f = [&](double a) {
                    return length(p - dvec3(major * std::cos(a), 0, major * std::sin(a)));
                };
                return minimise(f, -M_PI, M_PI, 720) - minor;
            },
            major + minor);
    }
    for (dvec2 rh : {dvec2(0.5, 2.0), dvec2(1.5, 0.4)}) {
        double r = rh.x, hh = rh.y / 2;
        add(
            "cylinder", NodeKind::Cylinder, {float(rh.x), float(rh.y)},
            [r, hh](dvec3 p) {
                return revolvedDistance(p, {{0, -hh}, {r, -hh}, {r, hh}, {0, hh}});
            },
            std::max(r, hh));
    }
    struct ConeCase {
        double r1, h, r2;
    };
    for (ConeCase c : {ConeCase{1.0, 2.0, 0.0}, ConeCase{0.6, 1.0, 0.3}, ConeCase{0.3, 1.5, 0.9}}) {
        double hh = c.h / 2;
        std::vector<dvec2> profile = {{0, -hh}, {c.r1, -hh}, {c.r2, hh}, {0, hh}};
        if (c.r2 == 0) profile.pop_back(); // apex on the axis
        add(
            "cone", NodeKind::Cone, {float(c.r1), float(c.h), float(c.r2)},
            [profile](dvec3 p) { return revolvedDistance(p, profile); }, std::max(c.r1, hh));
    }
    {
        dvec3 a(-0.5, 0.2, 0.1), b(0.7, -0.4, 0.6);
        double r = 0.3;
        add(
            "capsule", NodeKind::Capsule,
            {float(a.x), float(a.y), float(a.z), float(b.x), float(b.y), float(b.z), float(r)},
            [a, b, r](dvec3 p) {
                auto f = [&](double t) { return length(p - (a + (b - a) * t)); };
                return minimise(f, 0, 1, 64) - r;
            },
            1.0);
        add(
            "capsule (a == b)", NodeKind::Capsule, {0.1f, 0.2f, 0.3f, 0.1f, 0.2f, 0.3f, 0.5f},
            [](dvec3 p) { return length(p - dvec3(0.1, 0.2, 0.3)) - 0.5; }, 0.5);
    }
    for (dvec2 rh : {dvec2(0.7, 1.2), dvec2(1.5, 0.3)}) {
        Polytope poly;
        for (double y : {-rh.y / 2, rh.y / 2})
            for (int i = 0; i < 6; ++i)
                poly.vertices.push_back(
                    {rh.x * std::cos(i * M_PI / 3), y, rh.x * std::sin(i * M_PI / 3)});
        poly.faces = {{0, 1, 2, 3, 4, 5}, {6, 7, 8, 9, 10, 11}};
        for (int i = 0; i < 6; ++i)
            poly.faces.push_back({i, (i + 1) % 6, 6 + (i + 1) % 6, 6 + i});
        add(
            "hex_prism", NodeKind::HexPrism, {float(rh.x), float(rh.y)},
            [poly](dvec3 p) { return poly.signedDistance(p); }, std::max(rh.x, rh.y / 2));
    }
    for (double s : {0.9, 2.0}) {
        Polytope poly;
        poly.vertices = {{s, 0, 0}, {-s, 0, 0}, {0, s, 0}, {0, -s, 0}, {0, 0, s}, {0, 0, -s}};
        for (int x : {0, 1})
            for (int y : {2, 3})
                for (int z : {4, 5})
                    poly.faces.push_back({x, y, z});
        add(
            "octahedron", NodeKind::Octahedron, {float(s)},
            [poly](dvec3 p) { return poly.signedDistance(p); }, s);
    }
    for (dvec2 wh : {dvec2(1.2, 1.1), dvec2(2.0, 0.4), dvec2(0.5, 2.5)}) {
        const double w = wh.x / 2, hh = wh.y / 2;
        Polytope poly;
        poly.vertices = {{-w, -hh, -w}, {w, -hh, -w}, {w, -hh, w}, {-w, -hh, w}, {0, hh, 0}};
        poly.faces = {{0, 1, 2, 3}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
        add(
            "pyramid", NodeKind::Pyramid, {float(wh.x), float(wh.y)},
            [poly](dvec3 p) { return poly.signedDistance(p); }, std::max(w, hh));
    }
    for (dvec3 rhr : {dvec3(0.6, 1.4, 0.15), dvec3(1.0, 0.5, 0.25), dvec3(0.4, 2.0, 0.0)}) {
        const double r = rhr.x - rhr.z, hh = rhr.y / 2 - rhr.z, rr = rhr.z;
        add(
            "rounded_cylinder", NodeKind::RoundedCylinder,
            {float(rhr.x), float(rhr.y), float(rhr.z)},
            [r, hh, rr](dvec3 p) {
                return revolvedDistance(p, {{0, -hh}, {r, -hh}, {r, hh}, {0, hh}}) - rr;
            },
            std::max(rhr.x, rhr.y / 2));
    }
    for (dvec3 c : {dvec3(0.5, 0.2, 1.1), dvec3(0.2, 0.6, 0.9), dvec3(0.4, 0.4, 0.5)}) {
        std::vector<dvec2> profile = twoCircleHull(-c.z / 2, c.x, c.z / 2, c.y);
        add(
            "round_cone", NodeKind::RoundCone, {float(c.x), float(c.y), float(c.z)},
            [profile](dvec3 p) { return revolvedDistance(p, profile); },
            c.z / 2 + std::max(c.x, c.y));
    }
    for (dvec3 l : {dvec3(0.6, 0.4, 0.12), dvec3(0.0, 0.7, 0.2)}) {
        const double le = l.x / 2, r1 = l.y, r2 = l.z;
        add(
            "link", NodeKind::Link, {float(l.x), float(l.y), float(l.z)},
            [le, r1, r2](dvec3 p) {
                const dvec3 x(1, 0, 0), y(0, 1, 0);
                double d = std::min({arcDistance(p, {0, le, 0}, x, y, r1, 0, M_PI),
                                     arcDistance(p, {0, -le, 0}, x, y, r1, M_PI, 2 * M_PI)});
                if (le > 0)
                    for (double side : {-r1, r1}) {
                        dvec3 a(side, -le, 0), b(side, le, 0);
                        double t = std::clamp(dot(p - a, b - a) / dot(b - a, b - a), 0.0, 1.0);
                        d = std::min(d, length(p - (a + (b - a) * t)));
                    }
                return d - r2;
            },
            le + r1 + r2);
    }
    for (dvec3 t : {dvec3(0.8, 0.2, 90), dvec3(1.0, 0.3, 250), dvec3(0.6, 0.15, 360)}) {
        const double ra = t.x, rb = t.y, half = t.z / 2 * M_PI / 180;
        add(
            "capped_torus " + std::to_string(int(t.z)), NodeKind::CappedTorus,
            {float(t.x), float(t.y), float(t.z)},
            [ra, rb, half](dvec3 p) {
                // The arc centred on +z in the xz plane: from +z towards +x is angle 0 upwards.
                return arcDistance(p, dvec3(0), {0, 0, 1}, {1, 0, 0}, ra, -half, half) - rb;
            },
            ra + rb);
    }
    return out;
}

float cpu(const Case& c, glm::vec3 p) {
    return sdf::evalPrimitive(c.kind, p, sdf::kernelParams(c.kind, c.params));
}

// Points near the shape (inside and out), farther out, and far away.
std::vector<glm::vec3> samplePoints(double size, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<glm::vec3> points;
    for (float reach : {0.6f, 1.3f, 3.0f, 20.0f})
        for (int i = 0; i < 1500; ++i)
            points.push_back(glm::vec3(u(rng), u(rng), u(rng)) * float(size) * reach);
    return points;
}

TEST(Primitives, EveryKindHasACase) {
    std::vector<bool> seen(kNodeKindCount, false);
    seen[size_t(NodeKind::Ellipsoid)] = true; // a bound: EllipsoidIsABoundWithinItsFactor
    seen[size_t(NodeKind::Heightmap)] = true; // a file's: test_images.cpp, Heightmap.*
    seen[size_t(NodeKind::Mesh)] = true;      // a file's: test_mesh_field.cpp, MeshNode.*
    for (const KindInfo& k : nodeKinds()) // against 3D primitives and brute force: test_profiles
        if (isProfile(k.kind)) seen[size_t(k.kind)] = true;
    for (const Case& c : cases())
        seen[size_t(c.kind)] = true;
    for (const KindInfo& k : nodeKinds())
        EXPECT_TRUE(k.operation || seen[size_t(k.kind)]) << k.name << " has no test case";
}

TEST(Primitives, MatchTrueDistance) {
    for (const Case& c : cases()) {
        SCOPED_TRACE(c.label);
        int inside = 0, failures = 0;
        for (glm::vec3 p : samplePoints(c.size, 7)) {
            double truth = c.truth(dvec3(p));
            float value = cpu(c, p);
            // Single precision on coordinates of magnitude |p| and the shape's size.
            double tolerance = 1e-5 * std::max({1.0, c.size, double(glm::length(p))});
            inside += truth < 0;
            if (std::abs(value - truth) > tolerance && ++failures <= 5)
                ADD_FAILURE() << "at (" << p.x << ", " << p.y << ", " << p.z << "): " << value
                              << " but the true distance is " << truth;
        }
        EXPECT_GT(inside, 20) << "too few samples inside the solid";
    }
}

// Exact distance fields have unit gradients wherever they are differentiable; the check runs
// where the true field is smooth at the scale of the finite difference (off the medial axis).
TEST(Primitives, UnitGradientAwayFromSurface) {
    const double h = 1e-3;
    for (const Case& c : cases()) {
        SCOPED_TRACE(c.label);
        int checked = 0, total = 0;
        for (glm::vec3 pf : samplePoints(c.size, 11)) {
            if (glm::length(pf) > 5 * c.size) continue; // far points add nothing here
            ++total;
            dvec3 p(pf);
            if (std::abs(c.truth(p)) < 4 * h) continue;
            dvec3 g, gt;
            for (int i = 0; i < 3; ++i) {
                dvec3 e(0.0);
                e[i] = h;
                gt[i] = (c.truth(p + e) - c.truth(p - e)) / (2 * h);
                g[i] = (double(cpu(c, glm::vec3(p + e))) - cpu(c, glm::vec3(p - e))) / (2 * h);
            }
            if (std::abs(length(gt) - 1) > 1e-6) continue; // a kink within reach of the stencil
            ++checked;
            EXPECT_NEAR(length(g), 1.0, 2e-3) << "at (" << p.x << ", " << p.y << ", " << p.z << ")";
        }
        EXPECT_GT(checked, total / 2) << "the gradient was checked at too few points";
    }
}

// The ellipsoid's field is not its distance: never above it, at least the distance times the
// smallest over the largest radius, and exact on a sphere.
TEST(Primitives, EllipsoidIsABoundWithinItsFactor) {
    for (dvec3 e : {dvec3(0.9, 0.5, 0.7), dvec3(2.0, 0.3, 1.0), dvec3(0.6, 0.6, 0.6)}) {
        SCOPED_TRACE(std::to_string(e.x) + " " + std::to_string(e.y) + " " + std::to_string(e.z));
        const sdf::Params k =
            sdf::kernelParams(NodeKind::Ellipsoid, {float(e.x), float(e.y), float(e.z)});
        const double factor = std::min({e.x, e.y, e.z}) / std::max({e.x, e.y, e.z});
        int inside = 0;
        for (glm::vec3 p : samplePoints(std::max({e.x, e.y, e.z}), 9)) {
            const double truth = ellipsoidDistance(dvec3(p), e);
            const double value = sdf::evalPrimitive(NodeKind::Ellipsoid, p, k);
            const double tolerance = 1e-5 * std::max(1.0, double(glm::length(p)));
            inside += truth < 0;
            EXPECT_EQ(value < 0, truth < 0) << p.x << " " << p.y << " " << p.z;
            EXPECT_LE(std::abs(value), std::abs(truth) + tolerance);
            EXPECT_GE(std::abs(value), std::abs(truth) * factor - tolerance);
            if (factor == 1.0) { // a sphere: exact (braces, as EXPECT_NEAR is an if-else)
                EXPECT_NEAR(value, truth, tolerance);
            }
        }
        EXPECT_GT(inside, 20);
    }
}

// The kernel parameters are derived from the table's full sizes: spot values by hand.
TEST(Primitives, TableSizesAreFullLengths) {
    auto at = [](NodeKind kind, sdf::Params params, glm::vec3 p) {
        return sdf::evalPrimitive(kind, p, sdf::kernelParams(kind, params));
    };
    EXPECT_FLOAT_EQ(at(NodeKind::Box, {2, 4, 6}, {0, 5, 0}), 3.0f);
    EXPECT_FLOAT_EQ(at(NodeKind::RoundBox, {2, 4, 6, 0.5f}, {0, 0, 4}), 1.0f);
    EXPECT_FLOAT_EQ(at(NodeKind::Cylinder, {1, 2}, {0, 3, 0}), 2.0f);
    EXPECT_FLOAT_EQ(at(NodeKind::Cone, {1, 2, 0}, {0, -3, 0}), 2.0f);
    EXPECT_FLOAT_EQ(at(NodeKind::Cone, {1, 2, 0}, {0, 1.5f, 0}), 0.5f); // above the apex
    EXPECT_FLOAT_EQ(at(NodeKind::TriangularPrism, {2, 1, 4}, {0, -2, 0}), 1.5f);
    EXPECT_FLOAT_EQ(at(NodeKind::TriangularPrism, {2, 1, 4}, {0, 2, 0}), 1.5f); // apex at +h/2
    EXPECT_FLOAT_EQ(at(NodeKind::TriangularPrism, {2, 1, 4}, {0, 0, 5}), 3.0f);
    EXPECT_FLOAT_EQ(at(NodeKind::Plane, {0, 2, 0, 1}, {0, 3, 0}), 2.0f); // normal normalised
    // A round box's radius is clamped to what fits, so it stays a valid rounded box.
    EXPECT_FLOAT_EQ(at(NodeKind::RoundBox, {2, 2, 2, 5}, {0, 0, 0}), -1.0f);
}

// The CSG operators: the smooth forms meet the sharp ones where the operands are k apart, and
// the early exits return an operand's exact bits.
TEST(Primitives, OperatorsBlendAndEndExactly) {
    using sdf::opDifference, sdf::opIntersection, sdf::opUnion;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-2, 2), uk(0.01f, 1.0f);
    for (int i = 0; i < 10000; ++i) {
        float a = u(rng), b = u(rng), k = uk(rng);
        float smin = opUnion(a, b, k), smax = opIntersection(a, b, k);
        EXPECT_LE(smin, std::min(a, b) + 1e-6f);
        EXPECT_GE(smin, std::min(a, b) - k / 4 - 1e-6f);
        EXPECT_GE(smax, std::max(a, b) - 1e-6f);
        EXPECT_LE(smax, std::max(a, b) + k / 4 + 1e-6f);
        EXPECT_EQ(opDifference(a, b, k), opIntersection(a, -b, k));
        if (b - a >= k) {
            EXPECT_EQ(smin, a);
        }
        if (a - b >= k) {
            EXPECT_EQ(smin, b);
        }
        glm::vec4 ca(1, 0, 0, a), cb(0, 0, 1, b);
        glm::vec4 s = opUnion(ca, cb, k);
        EXPECT_EQ(s.w, smin);
        EXPECT_NEAR(s.r + s.b, 1.0f, 1e-6f); // one blend factor for colour
        EXPECT_EQ(opIntersection(ca, cb, k).w, smax);
        // Sharp operators: ties go to the first operand.
        EXPECT_EQ(opUnion(ca, glm::vec4(0, 1, 0, a), 0.0f), ca);
        EXPECT_EQ(opIntersection(ca, glm::vec4(0, 1, 0, a), 0.0f), ca);
        EXPECT_EQ(opUnion(a, b, 0.0f), std::min(a, b));
        EXPECT_EQ(opIntersection(a, b, 0.0f), std::max(a, b));
    }
    // Equal operands blend halfway and dip by k/4.
    EXPECT_FLOAT_EQ(opUnion(1.0f, 1.0f, 0.4f), 0.9f);
    EXPECT_FLOAT_EQ(opIntersection(1.0f, 1.0f, 0.4f), 1.1f);
}

// The sharp forms that generated code uses for a literal k = 0 give opX(a, b, 0)'s bits, ties
// (to the first operand) and signed zeros included.
TEST(Primitives, SharpOperatorsMatchTheSmoothOnesAtZero) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-2, 2);
    auto same = [](float x, float y) { return std::memcmp(&x, &y, sizeof x) == 0; };
    auto sameVec = [](glm::vec4 x, glm::vec4 y) { return std::memcmp(&x, &y, sizeof x) == 0; };
    for (int i = 0; i < 10000; ++i) {
        float a = u(rng), b = i % 3 == 0 ? a : i % 3 == 1 ? -a : u(rng);
        if (i % 100 == 0) a = i % 200 == 0 ? 0.0f : -0.0f, b = -a;
        EXPECT_TRUE(same(sdf::sharpUnion(a, b), sdf::opUnion(a, b, 0.0f))) << a << " " << b;
        EXPECT_TRUE(same(sdf::sharpIntersection(a, b), sdf::opIntersection(a, b, 0.0f)));
        EXPECT_TRUE(same(sdf::sharpDifference(a, b), sdf::opDifference(a, b, 0.0f)));
        glm::vec4 ca(1, 0, 0, a), cb(0, 0, 1, b);
        EXPECT_TRUE(sameVec(sdf::sharpUnion(ca, cb), sdf::opUnion(ca, cb, 0.0f)));
        EXPECT_TRUE(sameVec(sdf::sharpIntersection(ca, cb), sdf::opIntersection(ca, cb, 0.0f)));
        EXPECT_TRUE(sameVec(sdf::sharpDifference(ca, cb), sdf::opDifference(ca, cb, 0.0f)));
    }
}

} // namespace
} // namespace sdfcsg
