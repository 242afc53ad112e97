// The reference voxelizer through OpenVDB's mesh-to-level-set conversion.

#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/MeshToVolume.h>

#include "geometry/openvdb_bridge.hpp"
#include "geometry/voxelize.hpp"

namespace hybridctl::geometry {

Solid voxelize_openvdb(const TriangleMesh& mesh, const Lattice& lattice) {
  vdb::initialize();
  auto xform = vdb::transform_of(lattice);
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  points.reserve(mesh.triangles.size() * 3);
  triangles.reserve(mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) {
    const auto base = openvdb::Index32(points.size());
    for (const Vec3& v : t) {
      const openvdb::Vec3d index = xform->worldToIndex(openvdb::Vec3d(v.x, v.y, v.z));
      points.emplace_back(float(index.x()), float(index.y()), float(index.z()));
    }
    triangles.emplace_back(base, base + 1, base + 2);
  }
  std::vector<openvdb::Vec4I> quads;
  // Points are already in index space: mesh-to-volume takes them so.
  auto sdf = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
      openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I>(points, triangles), *xform,
      3.0f, 3.0f);
  auto interior = openvdb::tools::sdfInteriorMask(*sdf, 0.0f);
  return vdb::from_active_voxels(*interior, lattice);
}

}  // namespace hybridctl::geometry
