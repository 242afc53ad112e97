#include "geometry/voxelize.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>

namespace hybridctl::geometry {
namespace {

// A facet projected onto the YZ plane, counter-clockwise, ready for row tests.
struct ProjectedFacet {
  double u[3], w[3], x[3];  // u = y, w = z, x = depth along the ray
  double area2;             // twice the projected area, > 0
  int j0, j1, k0, k1;       // rows of voxel centres its projection may cover (inclusive)
};

// Inside test for sample (su, sw) against edge p->q of a CCW triangle. A sample exactly
// on the edge counts when a fixed infinitesimal nudge of the sample, u + eps and
// w + eps^2, moves it inside: neighbouring facets then never both count a shared edge or
// vertex, so the even-odd rule holds at every tie.
inline bool inside_edge(double pu, double pw, double qu, double qw, double su, double sw, double& e) {
  const double du = qu - pu, dw = qw - pw;
  e = du * (sw - pw) - dw * (su - pu);
  if (e > 0) return true;
  if (e < 0) return false;
  return dw < 0 || (dw == 0 && du > 0);
}

}  // namespace

Solid voxelize_exact_scan(const TriangleMesh& mesh, const Lattice& lattice, const ProgressFn& progress) {
  const Box3 b = bounds(mesh);
  const IndexBox domain = lattice.centers_within(b);
  Solid out(lattice, domain);
  if (domain.empty() || mesh.triangles.empty()) return out;
  const double h = lattice.voxel_size;
  const Vec3 o = lattice.origin;
  const int ny = domain.hi.y - domain.lo.y, nz = domain.hi.z - domain.lo.z;

  std::vector<ProjectedFacet> facets;
  facets.reserve(mesh.triangles.size());
  std::vector<std::vector<std::uint32_t>> by_slice(static_cast<std::size_t>(nz));
  for (const Triangle& t : mesh.triangles) {
    ProjectedFacet f;
    for (int v = 0; v < 3; ++v) {
      f.u[v] = t[v].y;
      f.w[v] = t[v].z;
      f.x[v] = t[v].x;
    }
    f.area2 = (f.u[1] - f.u[0]) * (f.w[2] - f.w[0]) - (f.w[1] - f.w[0]) * (f.u[2] - f.u[0]);
    if (f.area2 == 0) continue;  // edge-on to the rays: its neighbours carry the crossing
    if (f.area2 < 0) {
      std::swap(f.u[1], f.u[2]);
      std::swap(f.w[1], f.w[2]);
      std::swap(f.x[1], f.x[2]);
      f.area2 = -f.area2;
    }
    const double umin = std::min({f.u[0], f.u[1], f.u[2]}), umax = std::max({f.u[0], f.u[1], f.u[2]});
    const double wmin = std::min({f.w[0], f.w[1], f.w[2]}), wmax = std::max({f.w[0], f.w[1], f.w[2]});
    f.j0 = std::max(domain.lo.y, int(std::ceil((umin - o.y) / h - 0.5)));
    f.j1 = std::min(domain.hi.y - 1, int(std::floor((umax - o.y) / h - 0.5)));
    f.k0 = std::max(domain.lo.z, int(std::ceil((wmin - o.z) / h - 0.5)));
    f.k1 = std::min(domain.hi.z - 1, int(std::floor((wmax - o.z) / h - 0.5)));
    if (f.j0 > f.j1 || f.k0 > f.k1) continue;
    const std::uint32_t index = std::uint32_t(facets.size());
    facets.push_back(f);
    for (int k = f.k0; k <= f.k1; ++k) by_slice[std::size_t(k - domain.lo.z)].push_back(index);
  }

  std::atomic<int> slices_done{0};
  std::mutex progress_mutex;
  tbb::parallel_for(tbb::blocked_range<int>(0, nz), [&](const tbb::blocked_range<int>& range) {
    std::vector<std::vector<double>> crossings(static_cast<std::size_t>(ny));
    for (int kk = range.begin(); kk != range.end(); ++kk) {
      const int k = domain.lo.z + kk;
      const double sw = o.z + (k + 0.5) * h;
      for (auto& row : crossings) row.clear();
      for (std::uint32_t index : by_slice[std::size_t(kk)]) {
        const ProjectedFacet& f = facets[index];
        for (int j = f.j0; j <= f.j1; ++j) {
          const double su = o.y + (j + 0.5) * h;
          double e0, e1, e2;  // e0 is opposite vertex 0, and so on
          if (!inside_edge(f.u[1], f.w[1], f.u[2], f.w[2], su, sw, e0)) continue;
          if (!inside_edge(f.u[2], f.w[2], f.u[0], f.w[0], su, sw, e1)) continue;
          if (!inside_edge(f.u[0], f.w[0], f.u[1], f.w[1], su, sw, e2)) continue;
          crossings[std::size_t(j - domain.lo.y)].push_back((e0 * f.x[0] + e1 * f.x[1] + e2 * f.x[2]) / f.area2);
        }
      }
      for (int jj = 0; jj < ny; ++jj) {
        auto& xs = crossings[std::size_t(jj)];
        if (xs.size() < 2) continue;
        std::sort(xs.begin(), xs.end());
        for (std::size_t c = 0; c + 1 < xs.size(); c += 2) {
          // Voxel i is inside when its centre lies in [xs[c], xs[c+1]).
          const int i0 = std::max(domain.lo.x, int(std::ceil((xs[c] - o.x) / h - 0.5)));
          const int i1 = std::min(domain.hi.x, int(std::ceil((xs[c + 1] - o.x) / h - 0.5)));
          out.set_run(domain.lo.y + jj, k, i0, i1);
        }
      }
      if (progress) {
        // Counted under the lock: counted outside, a thread could report a count below one
        // another thread reported before it (progress must not go back).
        std::lock_guard lock(progress_mutex);
        progress(double(++slices_done) / nz);
      }
    }
  });
  return out;
}

Solid voxelize(const TriangleMesh& mesh, const Lattice& lattice, const std::string& name,
               VoxelizeMethod method, const ProgressFn& progress) {
  MeshReport report;
  const TriangleMesh cleaned = clean_mesh(mesh, &report);
  require_closed(report, name);
  switch (method) {
    case VoxelizeMethod::ExactScan: return voxelize_exact_scan(cleaned, lattice, progress);
    case VoxelizeMethod::OpenVdbLevelSet: {
      Solid s = voxelize_openvdb(cleaned, lattice);
      if (progress) progress(1.0);
      return s;
    }
  }
  return Solid(lattice, {});
}

}  // namespace hybridctl::geometry
