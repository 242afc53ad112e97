#include "geometry/vdb_file.hpp"

#include <openvdb/io/File.h>
#include <openvdb/tools/LevelSetUtil.h>

#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "geometry/openvdb_bridge.hpp"

namespace hybridctl::geometry {

void write_vdb(const Solid& solid, const std::filesystem::path& path, const std::string& grid_name) {
  vdb::initialize();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setTransform(vdb::transform_of(solid.lattice()));
  grid->setName(grid_name);
  grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  auto accessor = grid->getAccessor();
  solid.for_each_voxel([&](Index3 v) { accessor.setValueOn(openvdb::Coord(v.x, v.y, v.z), 1.0f); });
  grid->insertMeta("hybridctl_voxel_size_mm", openvdb::DoubleMetadata(solid.voxel_size()));
  grid->pruneGrid();

  AtomicFile file(path);
  try {
    openvdb::io::File out(file.temp_path().string());
    out.write({grid});
    out.close();
  } catch (const openvdb::Exception& e) {
    throw InputError(path.string() + ": cannot write: " + e.what());
  }
  file.commit();
}

Solid read_vdb(const std::filesystem::path& path) {
  vdb::initialize();
  const std::string name = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(name + ": cannot read: no such file");
  openvdb::GridBase::Ptr base;
  try {
    openvdb::io::File in(name);
    in.open(false);  // no delayed loading: the file may go away
    openvdb::GridPtrVecPtr grids = in.getGrids();
    in.close();
    for (auto& g : *grids) {
      if (g->isType<openvdb::FloatGrid>() || g->isType<openvdb::BoolGrid>()) {
        base = g;
        break;
      }
    }
    if (!base) throw InputError(name + ": holds no float or bool grid, expected a density, level set or mask volume");
  } catch (const openvdb::Exception& e) {
    throw InputError(name + ": not a readable .vdb file: " + e.what());
  }

  const openvdb::math::Transform& xform = base->transform();
  if (!xform.isLinear() || !xform.hasUniformScale()) {
    throw InputError(name + ": grid '" + base->getName() + "' has a non-uniform or non-linear transform, "
                     "expected cubic voxels");
  }
  const openvdb::Vec3d size = xform.voxelSize();
  const openvdb::Vec3d centre0 = xform.indexToWorld(openvdb::Vec3d(0, 0, 0));
  const double h = size.x();
  if (!(h > 0)) throw InputError(name + ": grid '" + base->getName() + "' has voxel size 0");
  if (xform.indexToWorld(openvdb::Vec3d(1, 1, 1)) - centre0 != openvdb::Vec3d(h, h, h)) {
    throw InputError(name + ": grid '" + base->getName() + "' is rotated, expected an axis-aligned grid");
  }
  const Lattice lattice{h, {centre0.x() - 0.5 * h, centre0.y() - 0.5 * h, centre0.z() - 0.5 * h}};

  if (auto bools = openvdb::gridPtrCast<openvdb::BoolGrid>(base)) return vdb::from_active_voxels(*bools, lattice);
  auto floats = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
  if (floats->getGridClass() == openvdb::GRID_LEVEL_SET) {
    return vdb::from_active_voxels(*openvdb::tools::sdfInteriorMask(*floats, 0.0f), lattice);
  }
  auto mask = openvdb::BoolGrid::create(false);
  auto accessor = mask->getAccessor();
  for (auto it = floats->cbeginValueOn(); it; ++it) {
    if (!(it.getValue() > 0.5f)) continue;
    if (it.isVoxelValue()) {
      accessor.setValueOn(it.getCoord(), true);
    } else {
      mask->fill(it.getBoundingBox(), true, true);
    }
  }
  return vdb::from_active_voxels(*mask, lattice);
}

}  // namespace hybridctl::geometry
