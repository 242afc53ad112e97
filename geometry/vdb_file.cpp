#include "geometry/vdb_file.hpp"

#include <openvdb/io/File.h>
#include <tbb/parallel_for.h>

#include <bit>
#include <vector>
#include <openvdb/tools/LevelSetUtil.h>

#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "geometry/openvdb_bridge.hpp"

namespace hybridctl::geometry {
namespace {

// A fog volume (1 inside, 0 outside) built leaf by leaf from the solid's words: eight
// voxels of a leaf row are one byte of a word, so no per-voxel tree descent. Leaves are
// made in parallel, one z slab of leaves per task, then added to the tree in order.
openvdb::FloatGrid::Ptr fog_grid(const Solid& solid) {
  using Leaf = openvdb::FloatTree::LeafNodeType;
  auto grid = openvdb::FloatGrid::create(0.0f);
  const IndexBox b = solid.bounding_box();
  if (b.empty()) return grid;
  const int bx0 = b.lo.x >> 3, bx1 = (b.hi.x - 1) >> 3, by0 = b.lo.y >> 3, by1 = (b.hi.y - 1) >> 3;
  const int bz0 = b.lo.z >> 3, bz1 = (b.hi.z - 1) >> 3;
  std::vector<std::vector<Leaf*>> slabs(std::size_t(bz1 - bz0 + 1));
  tbb::parallel_for(bz0, bz1 + 1, [&](int bz) {
    auto& leaves = slabs[std::size_t(bz - bz0)];
    for (int by = by0; by <= by1; ++by)
      for (int bx = bx0; bx <= bx1; ++bx) {
        const int x0 = bx * 8;
        Leaf* leaf = nullptr;
        for (int dz = 0; dz < 8; ++dz)
          for (int dy = 0; dy < 8; ++dy) {
            const int y = by * 8 + dy, z = bz * 8 + dz;
            std::uint64_t byte = (solid.word_at(x0 >> 6, y, z) >> (x0 & 63)) & 0xFFu;
            if (!byte) continue;
            if (!leaf) leaf = new Leaf(openvdb::Coord(x0, by * 8, bz * 8), 0.0f);
            for (; byte; byte &= byte - 1) leaf->setValueOn(openvdb::Coord(x0 + std::countr_zero(byte), y, z), 1.0f);
          }
        if (leaf) leaves.push_back(leaf);
      }
  });
  for (auto& leaves : slabs)
    for (Leaf* leaf : leaves) grid->tree().addLeaf(leaf);  // the tree takes ownership
  return grid;
}

}  // namespace

void write_vdb(const Solid& solid, const std::filesystem::path& path, const std::string& grid_name) {
  vdb::initialize();
  auto grid = fog_grid(solid);
  grid->setTransform(vdb::transform_of(solid.lattice()));
  grid->setName(grid_name);
  grid->setGridClass(openvdb::GRID_FOG_VOLUME);
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

std::optional<VdbExtent> read_vdb_extent(const std::filesystem::path& path) {
  vdb::initialize();
  try {
    openvdb::io::File in(path.string());
    in.open(false);
    const openvdb::GridPtrVecPtr grids = in.readAllGridMetadata();
    in.close();
    for (const auto& g : *grids) {
      if (!g->isType<openvdb::FloatGrid>() && !g->isType<openvdb::BoolGrid>()) continue;
      const auto lo = g->getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MIN);
      const auto hi = g->getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MAX);
      if (!lo || !hi) return std::nullopt;
      const openvdb::math::Transform& xform = g->transform();
      const openvdb::Vec3d a = xform.indexToWorld(openvdb::Vec3d(lo->value()));
      const openvdb::Vec3d b = xform.indexToWorld(openvdb::Vec3d(hi->value()));
      return VdbExtent{xform.voxelSize()[0], {{a.x(), a.y(), a.z()}, {b.x(), b.y(), b.z()}}};
    }
  } catch (const openvdb::Exception&) {
  }
  return std::nullopt;
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
