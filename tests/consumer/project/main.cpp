// The README's library example: load a scene, render it, write a PNG.
#include <sdfcsg/sdfcsg.h>

#include <cstdio>

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: consumer SCENE OUT.png\n");
        return 2;
    }
    auto scene = sdfcsg::loadScene(argv[1]);
    if (!scene) {
        std::fprintf(stderr, "%s\n", scene.error().str().c_str());
        return 1;
    }
    auto context = sdfcsg::Context::create();
    if (!context) return std::fprintf(stderr, "%s\n", context.error().str().c_str()), 1;
    auto renderer = sdfcsg::Renderer::create(**context, *scene);
    if (!renderer) return std::fprintf(stderr, "%s\n", renderer.error().str().c_str()), 1;

    sdfcsg::RenderOptions options;
    options.width = 320;
    options.height = 240;
    auto image = (*renderer)->render(options);
    if (!image) return std::fprintf(stderr, "%s\n", image.error().str().c_str()), 1;
    if (auto ok = sdfcsg::writePng(*image, argv[2]); !ok)
        return std::fprintf(stderr, "%s\n", ok.error().str().c_str()), 1;
    std::printf("rendered %s on %s\n", argv[2], (*context)->deviceName().c_str());
    return (*context)->validationMessageCount() == 0 ? 0 : 1;
}
