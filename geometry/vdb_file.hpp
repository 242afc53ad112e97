#pragma once
// .vdb files: the interchange format for solids (opens in Blender, Houdini, and
// OpenVDB's own vdb_print / vdb_view).

#include <filesystem>
#include <optional>
#include <string>

#include "geometry/solid.hpp"

namespace hybridctl::geometry {

// Writes the solid as a fog volume (float grid, 1 inside, named `grid_name`) with the
// lattice in the grid transform. Temporary file, then rename.
void write_vdb(const Solid& solid, const std::filesystem::path& path, const std::string& grid_name = "density");

// Reads the first float or bool grid of a .vdb file: a level set gives its interior,
// a fog or bool volume its active voxels with value above one half (true). The voxel
// size and origin come from the grid's transform, which must be linear and uniform.
// Throws hybridctl::InputError naming the file and what was expected.
Solid read_vdb(const std::filesystem::path& path);

// What read_vdb would allocate for, from the file's grid metadata alone (no voxels read):
// the first float or bool grid's voxel size and the mm box its active voxels span, as
// OpenVDB records it on writing. Nullopt when the file does not say or cannot be read
// (read_vdb then says why).
struct VdbExtent {
  double voxel_size = 0;
  Box3 box;
};
std::optional<VdbExtent> read_vdb_extent(const std::filesystem::path& path);

}  // namespace hybridctl::geometry
