#pragma once
// Distances between voxel centres as values the caller keeps: the Euclidean distance
// transform of a solid over a box (the same separable transform the morphology uses,
// geometry/morphology_distance.cpp), and the voxel of one solid farthest from another.
// The planner's tolerance zone and deviation measure are built on these.

#include <optional>
#include <vector>

#include "geometry/solid.hpp"

namespace hybridctl::geometry {

// Squared distances, in voxels^2, from every voxel of `box` to the nearest voxel of
// `to` that lies in `box` (voxels of `to` outside it are not seen). Exact: integers,
// held exactly by float up to 2^24.
class DistanceField {
 public:
  DistanceField(const Solid& to, const IndexBox& box);

  const IndexBox& box() const { return box_; }
  double voxel_size() const { return voxel_size_; }
  // Infinity when `to` has no voxel in the box; `v` must lie in the box.
  float squared(Index3 v) const { return values_[index(v)]; }
  double distance_mm(Index3 v) const;

 private:
  std::size_t index(Index3 v) const {
    return (std::size_t(v.z - box_.lo.z) * std::size_t(box_.hi.y - box_.lo.y) + std::size_t(v.y - box_.lo.y)) *
               std::size_t(box_.hi.x - box_.lo.x) +
           std::size_t(v.x - box_.lo.x);
  }

  IndexBox box_;
  double voxel_size_ = 1;
  std::vector<float> values_;
};

struct FarthestVoxel {
  double distance = 0;          // mm between voxel centres; infinity when `to` is empty
  std::optional<Index3> voxel;  // the voxel of `from` that attains it; none when `from` is empty
};

// The voxel of `from` farthest from its nearest voxel of `to` (the first in z, y, x
// order among equals), and that distance.
FarthestVoxel farthest_voxel(const Solid& from, const Solid& to);

}  // namespace hybridctl::geometry
