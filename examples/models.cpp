// Four parametric models built with the modelling API (docs/cpp-api.md): a bracket with bolt
// holes, a gear, a vase made by revolving its wall's profile, and a lattice cut to a sphere.
// examples/models.py builds the same four in Python; the test `examples` holds the two to one
// JSON each.
//
// Usage: sdfcsg_examples FOLDER [--render]: writes FOLDER/NAME.json (and NAME.png) for each.
#include <sdfcsg/sdfcsg.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace m = sdfcsg::model;

// An angle plate: a base and an upright blended together, two bolt holes through each.
m::Shape bracket(double width = 3.0, double thickness = 0.3, double hole = 0.25) {
    const m::Shape base = m::roundBox({width, thickness, 1.5}, 0.05);
    const m::Shape upright = m::roundBox({width, 1.5, thickness}, 0.05).translate({0, 0.6, -0.6});
    const m::Shape bolt = m::cylinder(hole / 2, 1);
    m::Shape holes;
    for (double x : {-width / 3, width / 3})
        holes =
            holes | bolt.translate({x, 0, 0.2}) | bolt.rotate({90, 0, 0}).translate({x, 0.8, -0.6});
    return m::difference({m::union_({base, upright}, 0.15), holes})
        .color("#7c8ea0")
        .name("bracket");
}

// A spur gear of `teeth` teeth: a disc, teeth copied around it, a bore and a keyway.
m::Shape gear(int teeth = 18, double radius = 1.0, double thickness = 0.3) {
    const double tooth = 2 * 3.141592653589793 * radius / teeth / 2;
    const m::Shape disc = m::cylinder(radius, thickness);
    const m::Shape ring = m::box({0.25, thickness, tooth}).polarRepeat(teeth, radius + 0.1);
    const m::Shape bore = m::cylinder(0.25, 1) | m::box({0.1, 1, 0.1}).translate({0.28, 0, 0});
    return ((disc | ring) - bore).color("#c0a040").name("gear");
}

// A vase: the profile of its wall, a band that swells and narrows with height, turned about y.
m::Shape vase(double height = 2.0, double wall = 0.06, int samples = 24) {
    std::vector<glm::vec2> outer, inner;
    for (int i = 0; i <= samples; ++i) {
        const double t = double(i) / samples, y = t * height;
        const double r = 0.45 + 0.25 * std::sin(3.0 * t + 0.4) - 0.1 * t;
        outer.push_back(glm::vec2(float(r), float(y)));
        inner.insert(inner.begin(), glm::vec2(float(r - wall), float(std::max(y, wall))));
    }
    std::vector<glm::vec2> profile = {glm::vec2(0, 0)};
    profile.insert(profile.end(), outer.begin(), outer.end());
    profile.insert(profile.end(), inner.begin(), inner.end());
    profile.push_back(glm::vec2(0, float(wall)));
    return m::polygon(profile)
        .revolve()
        .translate({0, -height / 2, 0})
        .color("#3a7bd5")
        .name("vase");
}

// A cubic lattice of struts, cut to a sphere.
m::Shape lattice(int cells = 5, double spacing = 0.5, double strut = 0.06) {
    const m::Shape x = m::box({spacing, strut, strut}), y = m::box({strut, spacing, strut}),
                   z = m::box({strut, strut, spacing});
    const m::Shape cell = m::union_({x, y, z}, 0.02);
    const m::Shape grid = cell.repeat({cells, cells, cells}, {spacing, spacing, spacing});
    return (grid & m::sphere(spacing * cells * 0.45)).color("#d05030").name("lattice");
}

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: sdfcsg_examples FOLDER [--render]\n");
        return 2;
    }
    const std::filesystem::path folder = argv[1];
    const bool render = argc > 2 && std::string(argv[2]) == "--render";
    std::filesystem::create_directories(folder);
    const std::pair<const char*, m::Shape> models[] = {
        {"bracket", bracket()}, {"gear", gear()}, {"vase", vase()}, {"lattice", lattice()}};
    std::unique_ptr<sdfcsg::Context> context;
    for (const auto& [name, shape] : models) {
        auto scene = m::toScene(shape);
        if (!scene) return std::fprintf(stderr, "%s\n", scene.error().str().c_str()), 1;
        const auto path = folder / (std::string(name) + ".json");
        if (auto ok = sdfcsg::writeFileAtomic(path, sdfcsg::toJson(*scene)); !ok)
            return std::fprintf(stderr, "%s\n", ok.error().str().c_str()), 1;
        if (!render) continue;
        if (!context) context = std::move(*sdfcsg::Context::create());
        auto renderer = sdfcsg::Renderer::create(*context, *scene);
        if (!renderer) return std::fprintf(stderr, "%s\n", renderer.error().str().c_str()), 1;
        sdfcsg::RenderOptions options;
        options.width = 480, options.height = 360, options.aa = 2;
        auto image = (*renderer)->render(options);
        if (!image) return std::fprintf(stderr, "%s\n", image.error().str().c_str()), 1;
        (void)sdfcsg::writePng(*image, folder / (std::string(name) + ".png"));
    }
    return 0;
}
