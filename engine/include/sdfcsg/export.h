// sdfcsg: writing meshes in the formats that 3D printing, game engines and DCC tools read.
#pragma once

#include "sdfcsg/error.h"
#include "sdfcsg/mesh.h"

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace sdfcsg {

enum class MeshFormat {
    Ply, // binary little-endian PLY: float positions and normals, uchar RGB colours, uint indices
    Obj, // Wavefront OBJ: "v x y z r g b" (the common colour extension), "vn", "f a//a b//b c//c"
    Stl, // binary STL: facet normals from the triangle winding, no colours (for printing)
    Glb, // glTF 2.0 binary: POSITION, NORMAL, COLOR_0 (linear), indices, one mesh and node
};

// The format named by a path's extension (case-insensitive), or nullopt.
std::optional<MeshFormat> meshFormatFromPath(const std::filesystem::path& path);
std::string_view meshFormatName(MeshFormat format); // "ply", "obj", "stl", "glb"

// The file's bytes.
std::string encodeMesh(const Mesh& mesh, MeshFormat format);

// Encodes and writes atomically (see io.h).
Status writeMesh(const Mesh& mesh, const std::filesystem::path& path, MeshFormat format);

} // namespace sdfcsg
