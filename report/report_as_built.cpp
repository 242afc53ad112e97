#include "report/report_as_built.hpp"

#include "common/error.hpp"
#include "geometry/morphology.hpp"
#include "geometry/vdb_file.hpp"

namespace hybridctl::report {

AsBuilt as_built(const plan::PlanFile& file, const std::filesystem::path& as_built_vdb) {
  const geometry::Solid read = geometry::read_vdb(as_built_vdb);
  if (!read.empty() && !(read.lattice() == file.lattice))
    throw InputError(as_built_vdb.string() + ": a grid of " + std::to_string(read.voxel_size()) +
                     " mm voxels that is not the plan's lattice (" + std::to_string(file.lattice.voxel_size) +
                     " mm voxels from its origin): expected the as-built stock of a run of this plan");
  AsBuilt out;
  out.built = copied_onto(read, file.lattice, file.domain);
  const geometry::Solid over = subtract(out.built, file.design), under = subtract(file.design, out.built);
  // Within the tolerance as plan::measure_deviation counts it: voxel centres at most the
  // tolerance plus half a voxel apart (the distance to the surface between the voxels).
  const geometry::Ball band{file.band() + file.lattice.voxel_size / 2};
  out.over_beyond = subtract(over, geometry::dilate(file.design, band, file.domain));
  out.over_within = subtract(over, out.over_beyond);
  out.under_beyond = intersect(under, geometry::erode(file.design, band));
  out.under_within = subtract(under, out.under_beyond);
  return out;
}

}  // namespace hybridctl::report
