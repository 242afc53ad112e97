#pragma once
// PNG images of a solid, one per voxel layer: for looking at what a voxelization or a
// plan state really contains.

#include <filesystem>
#include <vector>

#include "geometry/solid.hpp"

namespace hybridctl::geometry {

// Writes one 8-bit grayscale PNG per Z layer of the solid's bounding box into
// `directory` (created if missing): material white, air black, +Y up, one pixel per
// voxel scaled up so the image is at least `min_width` pixels wide. Files are named
// z0000.png, z0001.png, ... from the lowest layer. Returns the paths written.
std::vector<std::filesystem::path> write_png_slices(const Solid& solid, const std::filesystem::path& directory,
                                                    int min_width = 256);

}  // namespace hybridctl::geometry
