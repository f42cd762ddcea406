# Every dependency of the engine, found in one place. All come from Debian 12 packages
# (scripts/install-deps.sh installs them).
find_package(Threads REQUIRED)  # glslang 12's package config needs Threads first
find_package(Vulkan REQUIRED)
find_package(SPIRV-Tools-opt REQUIRED)
find_package(glslang REQUIRED)
find_package(simdjson REQUIRED)
find_package(glm REQUIRED)
find_package(CURL REQUIRED)  # the language model client (generate.h)
find_package(Freetype REQUIRED)  # glyph outlines for text (engine/src/scene/font.cpp)
find_package(Fontconfig REQUIRED)  # fonts named by family (engine/src/scene/font.cpp)
find_package(ZLIB REQUIRED)  # deflate and CRC-32 for 3MF's ZIP container (engine/src/io/zip.cpp)
find_package(assimp REQUIRED)  # mesh files read by mesh nodes (engine/src/field/mesh_field.cpp)
find_package(EXPAT REQUIRED)  # the XML of 3MF models read by mesh nodes (engine/src/field/read_3mf.cpp)
find_package(meshoptimizer REQUIRED)  # mesh simplification (engine/src/mesh/mesh_simplify.cpp)
find_path(STB_INCLUDE_DIR stb_image_write.h PATH_SUFFIXES stb REQUIRED)
find_program(GLSLANG_VALIDATOR glslangValidator REQUIRED)
