#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "cli/commands.hpp"
#include "cli/memory_budget.hpp"
#include "cli/ranges.hpp"
#include "cli/progress.hpp"
#include "common/error.hpp"
#include "geometry/png_slices.hpp"
#include "geometry/vdb_file.hpp"
#include "geometry/voxelize.hpp"

namespace hybridctl::cli {
namespace {

// Dense storage needs one bit per voxel of the bounding box; refuse sizes that would
// not fit in memory rather than failing half-way.
constexpr double kMaxStorageBytes = 8.0e9;

struct VoxelizeArgs {
  std::string part;
  std::string output;
  std::string png_dir;
  double voxel = 0.5;
  std::string method = "exact";
  std::string memory_budget;
};

int run_voxelize(const VoxelizeArgs& args) {
  using namespace geometry;
  const auto started = std::chrono::steady_clock::now();
  const TriangleMesh mesh = read_stl(args.part);
  const Box3 b = bounds(mesh);
  const double bits = std::ceil((b.max.x - b.min.x) / args.voxel + 64) * std::ceil((b.max.y - b.min.y) / args.voxel + 1) *
                      std::ceil((b.max.z - b.min.z) / args.voxel + 1);
  if (bits / 8 > kMaxStorageBytes) {
    throw InputError("--voxel " + std::to_string(args.voxel) + ": the part's bounding box would need " +
                     std::to_string(bits / 8e9) + " GB of voxels; expected a larger voxel size");
  }
  check_memory_budget([&](double h) { return solid_bytes(b, h, 1); }, args.voxel,
                      memory_budget(args.memory_budget) ? memory_budget(args.memory_budget) : default_memory_budget(),
                      "voxelizing " + args.part + " at " + std::to_string(args.voxel) + " mm");
  const Lattice lattice{args.voxel, {0, 0, 0}};
  Solid solid;
  {
    ProgressBar bar("voxelizing");
    solid = voxelize(mesh, lattice, args.part,
                     args.method == "openvdb" ? VoxelizeMethod::OpenVdbLevelSet : VoxelizeMethod::ExactScan,
                     [&bar](double f) { bar.update(f); });
  }
  write_vdb(solid, args.output);
  std::size_t slices = 0;
  if (!args.png_dir.empty()) slices = write_png_slices(solid, args.png_dir).size();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  const double mesh_volume = std::abs(signed_volume(clean_mesh(mesh)));
  const IndexBox box = solid.bounding_box();
  const Box3 mm = solid.bounding_box_mm();
  std::printf("part         %s (%zu triangles)\n", args.part.c_str(), mesh.triangles.size());
  std::printf("voxel size   %g mm (%s scan conversion)\n", args.voxel, args.method.c_str());
  std::printf("grid         %d x %d x %d voxels, %lld occupied\n", box.hi.x - box.lo.x, box.hi.y - box.lo.y,
              box.hi.z - box.lo.z, static_cast<long long>(solid.voxel_count()));
  std::printf("bounds       [%g, %g] x [%g, %g] x [%g, %g] mm\n", mm.min.x, mm.max.x, mm.min.y, mm.max.y, mm.min.z,
              mm.max.z);
  std::printf("volume       %.1f mm^3 voxels, %.1f mm^3 mesh (%+.2f%%)\n", solid.volume(), mesh_volume,
              mesh_volume > 0 ? 100.0 * (solid.volume() - mesh_volume) / mesh_volume : 0.0);
  std::printf("wrote        %s", args.output.c_str());
  if (slices) std::printf(" and %zu PNG slices in %s", slices, args.png_dir.c_str());
  std::printf("\ntime         %.2f s\n", seconds);
  return kSuccess;
}

}  // namespace

void add_voxelize_command(CLI::App& app, Runner& runner) {
  auto args = std::make_shared<VoxelizeArgs>();
  auto* cmd = app.add_subcommand("voxelize", "Voxelize a closed STL mesh into a .vdb solid");
  cmd->add_option("PART", args->part, "Part mesh, binary or ASCII STL, in mm")->required();
  cmd->add_option("--voxel", args->voxel, "Voxel edge length in mm")
      ->default_val(0.5)
      ->check(greater_than(0));
  add_memory_budget_option(cmd, args->memory_budget);
  cmd->add_option("-o,--output", args->output, "Output .vdb file (fog volume named 'density')")->required();
  cmd->add_option("--png-slices", args->png_dir, "Also write one PNG per Z layer into this directory");
  cmd->add_option("--method", args->method,
                  "exact: exact scan conversion (default); openvdb: OpenVDB mesh-to-level-set, for comparison")
      ->check(CLI::IsMember({"exact", "openvdb"}));
  cmd->callback([&runner, args] { runner = [args] { return run_voxelize(*args); }; });
}

}  // namespace hybridctl::cli
