#include <cmath>
#include <cstdio>
#include <memory>

#include "cli/commands.hpp"
#include "common/error.hpp"
#include "geometry/mesh.hpp"
#include "geometry/vdb_file.hpp"

namespace hybridctl::cli {
namespace {

int inspect_vdb(const std::string& path) {
  const geometry::Solid solid = geometry::read_vdb(path);
  const geometry::IndexBox box = solid.bounding_box();
  const geometry::Box3 mm = solid.bounding_box_mm();
  const geometry::Vec3 o = solid.lattice().origin;
  std::printf("file         %s (voxel solid)\n", path.c_str());
  std::printf("voxel size   %g mm, lattice origin (%g, %g, %g) mm\n", solid.voxel_size(), o.x, o.y, o.z);
  std::printf("voxels       %lld occupied in a %d x %d x %d box\n", static_cast<long long>(solid.voxel_count()),
              box.hi.x - box.lo.x, box.hi.y - box.lo.y, box.hi.z - box.lo.z);
  std::printf("volume       %.3f mm^3\n", solid.volume());
  std::printf("bounds       [%g, %g] x [%g, %g] x [%g, %g] mm\n", mm.min.x, mm.max.x, mm.min.y, mm.max.y, mm.min.z,
              mm.max.z);
  return kSuccess;
}

int inspect_stl(const std::string& path) {
  const geometry::TriangleMesh mesh = geometry::read_stl(path);
  geometry::MeshReport report;
  const geometry::TriangleMesh cleaned = geometry::clean_mesh(mesh, &report);
  const geometry::Box3 b = geometry::bounds(cleaned);
  std::printf("file         %s (triangle mesh)\n", path.c_str());
  std::printf("triangles    %zu (%zu duplicate, %zu degenerate removed)\n", report.triangles, report.duplicate_facets,
              report.degenerate_facets);
  std::printf("bounds       [%g, %g] x [%g, %g] x [%g, %g] mm\n", b.min.x, b.max.x, b.min.y, b.max.y, b.min.z, b.max.z);
  std::printf("closed       %s", report.closed() ? "yes" : "no");
  if (!report.closed()) std::printf(" (%zu boundary edges)", report.boundary_edges);
  if (report.nonmanifold_edges) std::printf(", %zu non-manifold edges", report.nonmanifold_edges);
  std::printf("\n");
  if (report.closed()) std::printf("volume       %.3f mm^3 (signed tetrahedra)\n", std::abs(geometry::signed_volume(cleaned)));
  std::fflush(stdout);
  geometry::require_closed(report, path);
  return kSuccess;
}

}  // namespace

void add_inspect_command(CLI::App& app, Runner& runner) {
  auto path = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("inspect", "Describe a voxel solid (.vdb) or a triangle mesh (.stl)");
  cmd->add_option("FILE", *path, "A .vdb or .stl file")->required();
  cmd->callback([&runner, path] {
    runner = [path] {
      std::string ext = std::filesystem::path(*path).extension().string();
      for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
      if (ext == ".vdb") return inspect_vdb(*path);
      if (ext == ".stl") return inspect_stl(*path);
      throw InputError(*path + ": unknown file type '" + ext + "', expected a .vdb or .stl file");
    };
  });
}

}  // namespace hybridctl::cli
