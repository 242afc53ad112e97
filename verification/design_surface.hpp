#pragma once
// The design's real surface as exact verification samples it: points on the STL's
// triangles with their outward normals, each the foot of a vector that reaches a short way
// into the design and out of it (the point-vector method of NC verification; Jerard et al.,
// IEEE CG&A 9(1), 1989), and the distance from any point to the surface. Built once per
// part; distances and rays use CGAL's AABB tree over the triangles.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "config/machine.hpp"
#include "geometry/mesh.hpp"

namespace hybridctl::verification {

// One sample of the design's surface, part frame, mm.
struct SurfaceSample {
  geometry::Vec3 point;
  geometry::Vec3 normal;  // unit, outward
  double inward = 0;      // how far the vector reaches into the design
  double outward = 0;     // and out of it
  double area = 0;        // mm^2 of the surface the sample stands for
  std::uint32_t triangle = 0;  // the triangle of DesignSurface::triangles() it was cut from
};

class FrameIndex;

struct SamplingOptions {
  double spacing = 0.25;        // mm: a sample stands for a patch of about spacing^2, no edge over 2 x spacing
  double reach = 2.0;           // mm: the vector's length each way, at most
  std::size_t max_samples = 1'500'000;  // more: the spacing grows until they fit
};

// The sampling for a part toleranced at `tolerance` and planned on voxels of `voxel` mm:
// samples about the tolerance apart (at least 0.1 mm, at most a voxel), vectors reaching
// past both the tolerance and the grid's error (4 x tolerance, 2 voxels).
SamplingOptions sampling_for(double tolerance, double voxel);

class DesignSurface {
 public:
  // Samples `mesh` (cleaned first; zero-area triangles are skipped). Each vector's reach
  // is cut to half the distance to the next face along it either way, so that no vector
  // crosses into another feature (the opposite wall of a slot, the far side of a thin
  // wall). Throws hybridctl::InputError naming `name` for a mesh without area.
  DesignSurface(const geometry::TriangleMesh& mesh, const std::string& name, SamplingOptions options);
  ~DesignSurface();
  DesignSurface(DesignSurface&&) noexcept;
  DesignSurface& operator=(DesignSurface&&) noexcept;

  const std::vector<SurfaceSample>& samples() const { return samples_; }
  // The mesh's triangles that were sampled, in the STL's order: the mesh cleaned
  // (geometry::clean_mesh: degenerate and repeated facets dropped) and without the ones
  // of no area. Every sample names the one it was cut from (SurfaceSample::triangle), so
  // a figure per sample can be shown on the design's own facets (the job report).
  const std::vector<geometry::Triangle>& triangles() const { return triangles_; }
  const SamplingOptions& options() const { return options_; }
  double area() const { return area_; }
  // Distance from `p` to the nearest point of the surface, mm.
  double distance(const geometry::Vec3& p) const;
  // The samples' vectors in the work frame of a setup with `approach`, indexed for sweeps
  // (verification/vector_index.hpp): all of them, or a thread's share (`part` of `parts`);
  // made on first use and kept. Safe from any thread.
  const FrameIndex& frame(config::Approach approach, std::size_t part = 0, std::size_t parts = 1) const;

 private:
  struct Tree;
  std::unique_ptr<Tree> tree_;
  std::vector<SurfaceSample> samples_;
  std::vector<geometry::Triangle> triangles_;
  SamplingOptions options_;
  double area_ = 0;
};

}  // namespace hybridctl::verification
