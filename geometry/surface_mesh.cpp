#include "geometry/surface_mesh.hpp"

#include <openvdb/tools/TopologyToLevelSet.h>
#include <openvdb/tools/VolumeToMesh.h>

#include "geometry/openvdb_bridge.hpp"

namespace hybridctl::geometry {

TriangleMesh surface_mesh(const Solid& solid, double adaptivity) {
  vdb::initialize();
  TriangleMesh mesh;
  if (solid.empty()) return mesh;
  auto topology = vdb::to_bool_grid(solid);
  // No closing or smoothing: the surface should follow the voxels, not improve on them.
  auto level_set = openvdb::tools::topologyToLevelSet(*topology, /*halfWidth=*/3, /*closingSteps=*/0,
                                                      /*dilation=*/0, /*smoothingSteps=*/0);
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(*level_set, points, triangles, quads, 0.0, adaptivity);
  auto p = [&](openvdb::Index32 i) { return Vec3{points[i].x(), points[i].y(), points[i].z()}; };
  mesh.triangles.reserve(triangles.size() + 2 * quads.size());
  // OpenVDB winds its polygons inward-facing; reverse them for outward normals.
  for (const auto& t : triangles) mesh.triangles.push_back({p(t[2]), p(t[1]), p(t[0])});
  for (const auto& q : quads) {
    mesh.triangles.push_back({p(q[2]), p(q[1]), p(q[0])});
    mesh.triangles.push_back({p(q[3]), p(q[2]), p(q[0])});
  }
  return mesh;
}

}  // namespace hybridctl::geometry
