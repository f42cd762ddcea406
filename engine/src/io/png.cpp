// PNG output through stb_image_write, encoded in memory and written atomically.
#include "sdfcsg/io.h"
#include "sdfcsg/render.h"

#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wshadow"
#endif
#include <stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include <string>

namespace sdfcsg {
namespace {

void append(void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
}

} // namespace

Result<std::string> encodePng(const Image& image, const std::filesystem::path& path) {
    if (image.width == 0 || image.height == 0 ||
        image.rgba.size() != size_t(image.width) * image.height * 4)
        return Error::message(ErrorKind::Usage, path.string(),
                              "cannot write an empty or inconsistent image as PNG");
    std::string png;
    int ok = stbi_write_png_to_func(append, &png, int(image.width), int(image.height), 4,
                                    image.rgba.data(), int(image.width * 4));
    if (!ok || png.empty())
        return Error::message(ErrorKind::Io, path.string(), "PNG encoding failed");
    return png;
}

Status writePng(const Image& image, const std::filesystem::path& path) {
    auto png = encodePng(image, path);
    if (!png) return png.error();
    return writeFileAtomic(path, *png);
}

} // namespace sdfcsg
