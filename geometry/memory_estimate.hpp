#pragma once
// How much memory a voxel grid takes before it is allocated, and the budget it must fit:
// a resource limit is an input error found up front, not a std::bad_alloc half-way
// (docs/hardening.md, "Memory budget").

#include <cstdint>
#include <functional>
#include <string>

#include "geometry/solid.hpp"

namespace hybridctl::geometry {

// Voxels of a grid covering `region` at voxel size `h` (centres within it, plus `pad`
// voxels on every side).
double grid_voxels(const Box3& region, double h, int pad = 0);
// Bytes of one dense Solid over that grid (one bit a voxel, X rows in 64-bit words).
double solid_bytes(const Box3& region, double h, int pad = 0);

// Physical memory (sysconf); 0 when unknown.
std::uint64_t physical_memory_bytes();
// The default budget: half the physical memory (8 GiB when unknown).
std::uint64_t default_memory_budget();
// "8G", "500M", "64k", "1024" (bytes); binary units. Throws InputError naming `what`.
std::uint64_t parse_memory_size(const std::string& text, const std::string& what);
std::string format_bytes(double bytes);

// Refuses (InputError, exit 3) when `estimate(h)` exceeds `budget`: the message names
// the estimate, the budget and the smallest voxel size at which `estimate` fits.
// `what` says what the grid is for ("planning the bracket at 0.01 mm").
// `advice` comes before the voxel size: "--voxel " where the command takes one.
void check_memory_budget(const std::function<double(double)>& estimate, double h, std::uint64_t budget, const std::string& what,
                         const std::string& advice = "--voxel ");

}  // namespace hybridctl::geometry
