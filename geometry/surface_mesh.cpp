#include "geometry/surface_mesh.hpp"

#include <openvdb/tools/TopologyToLevelSet.h>
#include <openvdb/tools/VolumeToMesh.h>

#include "geometry/openvdb_bridge.hpp"

namespace hybridctl::geometry {

namespace {

openvdb::FloatGrid::Ptr occupancy_grid(const Solid& solid) {
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setTransform(vdb::transform_of(solid.lattice()));
  auto accessor = grid->getAccessor();
  solid.for_each_voxel([&](Index3 v) { accessor.setValue(openvdb::Coord(v.x, v.y, v.z), 1.0f); });
  return grid;
}

}  // namespace

TriangleMesh surface_mesh(const Solid& solid, double adaptivity, SurfaceMethod method) {
  vdb::initialize();
  TriangleMesh mesh;
  if (solid.empty()) return mesh;
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  if (method == SurfaceMethod::Occupancy) {
    openvdb::tools::volumeToMesh(*occupancy_grid(solid), points, triangles, quads, 0.5, adaptivity);
  } else {
    auto topology = vdb::to_bool_grid(solid);
    // No closing or smoothing: the surface should follow the voxels, not improve on them.
    auto level_set = openvdb::tools::topologyToLevelSet(*topology, /*halfWidth=*/3, /*closingSteps=*/0,
                                                        /*dilation=*/0, /*smoothingSteps=*/0);
    openvdb::tools::volumeToMesh(*level_set, points, triangles, quads, 0.0, adaptivity);
  }
  auto p = [&](openvdb::Index32 i) { return Vec3{points[i].x(), points[i].y(), points[i].z()}; };
  // OpenVDB winds its polygons inward-facing (either way); reverse them for outward normals.
  auto add = [&](openvdb::Index32 a, openvdb::Index32 b, openvdb::Index32 c) {
    mesh.triangles.push_back({p(c), p(b), p(a)});
  };
  mesh.triangles.reserve(triangles.size() + 2 * quads.size());
  for (const auto& t : triangles) add(t[0], t[1], t[2]);
  for (const auto& q : quads) {
    add(q[0], q[1], q[2]);
    add(q[0], q[2], q[3]);
  }
  return mesh;
}

}  // namespace hybridctl::geometry
