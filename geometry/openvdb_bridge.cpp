#include "geometry/openvdb_bridge.hpp"

#include <mutex>

namespace hybridctl::geometry::vdb {

void initialize() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

openvdb::math::Transform::Ptr transform_of(const Lattice& lattice) {
  auto xform = openvdb::math::Transform::createLinearTransform(lattice.voxel_size);
  const double half = 0.5 * lattice.voxel_size;
  xform->postTranslate(openvdb::Vec3d(lattice.origin.x + half, lattice.origin.y + half, lattice.origin.z + half));
  return xform;
}

openvdb::BoolGrid::Ptr to_bool_grid(const Solid& solid) {
  auto grid = openvdb::BoolGrid::create(false);
  grid->setTransform(transform_of(solid.lattice()));
  auto accessor = grid->getAccessor();
  solid.for_each_voxel([&](Index3 v) { accessor.setValueOn(openvdb::Coord(v.x, v.y, v.z), true); });
  return grid;
}

Solid from_active_voxels(const openvdb::BoolGrid& grid, const Lattice& lattice) {
  const openvdb::CoordBBox bbox = grid.evalActiveVoxelBoundingBox();
  if (bbox.empty()) return Solid(lattice, {});
  Solid out(lattice, {{bbox.min().x(), bbox.min().y(), bbox.min().z()},
                      {bbox.max().x() + 1, bbox.max().y() + 1, bbox.max().z() + 1}});
  for (auto it = grid.cbeginValueOn(); it; ++it) {
    if (!it.getValue()) continue;
    if (it.isVoxelValue()) {
      const openvdb::Coord c = it.getCoord();
      out.set({c.x(), c.y(), c.z()});
    } else {  // an active tile: a whole block
      const openvdb::CoordBBox tile = it.getBoundingBox();
      for (int z = tile.min().z(); z <= tile.max().z(); ++z)
        for (int y = tile.min().y(); y <= tile.max().y(); ++y) out.set_run(y, z, tile.min().x(), tile.max().x() + 1);
    }
  }
  return out;
}

}  // namespace hybridctl::geometry::vdb
