// The README's library examples: load a scene, render it, write a PNG; and with a fourth
// argument, build a scene in code (sdfcsg/model.h), render it, change a value and render again.
#include <sdfcsg/sdfcsg.h>

#include <cstdio>
#include <string>

namespace m = sdfcsg::model;

int fail(const sdfcsg::Error& error) {
    std::fprintf(stderr, "%s\n", error.str().c_str());
    return 1;
}

// A plate with a hole and a rounded peg, made in code.
m::Shape bracket() {
    const m::Shape plate = m::roundBox({2, 0.3, 1}, 0.05).color("#4080c0");
    const m::Shape hole = m::cylinder(0.2, 1).translate({0.6, 0, 0});
    const m::Shape peg = m::capsule({-0.6, 0, 0}, {-0.6, 0.6, 0}, 0.15).name("peg");
    return m::union_({plate - hole, peg}, 0.05);
}

int main(int argc, char** argv) {
    if (argc != 3 && argc != 4) {
        std::fprintf(stderr, "usage: consumer SCENE OUT.png [MODELLED.png]\n");
        return 2;
    }
    auto scene = sdfcsg::loadScene(argv[1]);
    if (!scene) return fail(scene.error());
    auto context = sdfcsg::Context::create();
    if (!context) return fail(context.error());
    auto renderer = sdfcsg::Renderer::create(**context, *scene);
    if (!renderer) return fail(renderer.error());

    sdfcsg::RenderOptions options;
    options.width = 320;
    options.height = 240;
    auto image = (*renderer)->render(options);
    if (!image) return fail(image.error());
    if (auto ok = sdfcsg::writePng(*image, argv[2]); !ok) return fail(ok.error());
    std::printf("rendered %s on %s\n", argv[2], (*context)->deviceName().c_str());

    if (argc == 4) {
        auto modelled = m::toScene(bracket());
        if (!modelled) return fail(modelled.error());
        auto second = sdfcsg::Renderer::create(**context, *modelled);
        if (!second) return fail(second.error());
        // A live edit: the peg grows, and the renderer takes the new value.
        auto peg = m::findNode(*modelled, "peg");
        if (!peg) return fail(peg.error());
        if (auto ok = m::setValue(*modelled, *peg, "radius", 0.2); !ok) return fail(ok.error());
        if (auto ok = (*second)->updateValues(*modelled); !ok) return fail(ok.error());
        auto edited = (*second)->render(options);
        if (!edited) return fail(edited.error());
        if (auto ok = sdfcsg::writePng(*edited, argv[3]); !ok) return fail(ok.error());
        std::printf("rendered %s, built in code\n", argv[3]);
    }
    return (*context)->validationMessageCount() == 0 ? 0 : 1;
}
