// Files embedded at build time by cmake/EmbedFiles.cmake.
#pragma once

#include <span>
#include <string_view>

namespace sdfcsg::detail {

struct EmbeddedFile {
    std::string_view name; // file name within shaders/, e.g. "sdf.glsl"
    std::string_view text;
};

std::span<const EmbeddedFile> embeddedShaders();
// The bundled scenes that the language model prompt shows as examples (assets/scenes/).
std::span<const EmbeddedFile> embeddedExampleScenes();

} // namespace sdfcsg::detail
