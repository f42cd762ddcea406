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
    // PLY and OBJ carry vertex colours only (Mesh::colors).
    Ply, // binary little-endian PLY: float positions and normals, uchar RGB colours, uint indices
    Obj, // Wavefront OBJ: "v x y z r g b" (the common colour extension), "vn", "f a//a b//b c//c"
    Stl, // binary STL for printing: z up as 3MF, facet normals from the winding, no colours
    // glTF 2.0 binary: POSITION, NORMAL, COLOR_0 (linear), indices, one mesh and node. With
    // Mesh::triangleColors, one primitive per colour (8-bit) on the shared vertices, each with a
    // material of that base colour, and no COLOR_0.
    Glb,
    // 3MF (3D Manufacturing Format, core and materials specifications), as slicers read it: one
    // object, z up (the scene's y becomes z), in a unit (one scene unit is one of it). With
    // Mesh::triangleColors, a base material per colour (8-bit sRGB) and one per triangle (p1),
    // so that a slicer assigns filaments by region; otherwise per-vertex sRGB colours as a
    // colour group.
    ThreeMf,
};

// The length that one scene unit stands for, where the format says (3MF).
enum class LengthUnit { Millimeter, Centimeter, Meter, Inch };
// Scenes are modelled a few units across (the bundled ones 1.3 to 10): one unit a centimetre
// prints them 1.3 to 10 cm wide, where millimetres, 3MF's own default, made a 1 mm pawn. A mesh
// node reads a 3MF's coordinates into this unit too, so that what is written comes back its size.
inline constexpr LengthUnit kDefaultLengthUnit = LengthUnit::Centimeter;

// The format named by a path's extension (case-insensitive), or nullopt.
std::optional<MeshFormat> meshFormatFromPath(const std::filesystem::path& path);
std::string_view meshFormatName(MeshFormat format); // "ply", "obj", "stl", "glb", "3mf"
// Whether the format writes Mesh::triangleColors (glTF and 3MF), so that a mesh for it is worth
// extracting with MeshOptions::colorRegions.
bool formatHasTriangleColors(MeshFormat format);

// A unit from its short name ("mm", "cm", "m", "inch"), or nullopt.
std::optional<LengthUnit> lengthUnitFromName(std::string_view name);
// How many millimetres one unit is.
double millimetres(LengthUnit unit);

// The file's bytes; empty for a 3MF past what its ZIP container holds (4 GiB).
std::string encodeMesh(const Mesh& mesh, MeshFormat format, LengthUnit unit = kDefaultLengthUnit);

// The file that writeMesh() writes to `path`: the encoded bytes, or its error (naming `path`).
Result<std::string> encodeMeshFile(const Mesh& mesh, const std::filesystem::path& path,
                                   MeshFormat format, LengthUnit unit = kDefaultLengthUnit);

// Encodes and writes atomically (see io.h).
Status writeMesh(const Mesh& mesh, const std::filesystem::path& path, MeshFormat format,
                 LengthUnit unit = kDefaultLengthUnit);

} // namespace sdfcsg
