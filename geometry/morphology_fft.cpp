// Dilation by any finite offset set as a linear convolution of indicator functions with
// FFTW: a voxel is reached where the convolution counts at least one overlap.

#include <fftw3.h>

#include "geometry/morphology_internal.hpp"

namespace hybridctl::geometry::detail {

namespace {

std::mutex fftw_planner_mutex;  // FFTW's planner is not thread-safe

}  // namespace

Solid dilate_fft(const Solid& solid, const std::vector<Index3>& offsets, const IndexBox& source, const IndexBox& domain) {
  Solid out(solid.lattice(), domain);
  if (source.empty() || offsets.empty()) return out;
  IndexBox ext{{INT32_MAX, INT32_MAX, INT32_MAX}, {INT32_MIN, INT32_MIN, INT32_MIN}};
  for (const Index3& d : offsets) {
    ext.lo = {std::min(ext.lo.x, d.x), std::min(ext.lo.y, d.y), std::min(ext.lo.z, d.z)};
    ext.hi = {std::max(ext.hi.x, d.x + 1), std::max(ext.hi.y, d.y + 1), std::max(ext.hi.z, d.z + 1)};
  }
  // Linear (not cyclic) convolution: pad each axis to source + element - 1.
  const int nx = (source.hi.x - source.lo.x) + (ext.hi.x - ext.lo.x) - 1;
  const int ny = (source.hi.y - source.lo.y) + (ext.hi.y - ext.lo.y) - 1;
  const int nz = (source.hi.z - source.lo.z) + (ext.hi.z - ext.lo.z) - 1;
  const std::size_t real_size = std::size_t(nx) * std::size_t(ny) * std::size_t(nz);
  const std::size_t complex_size = std::size_t(nz) * std::size_t(ny) * std::size_t(nx / 2 + 1);
  std::vector<double> a(real_size, 0.0), b(real_size, 0.0);
  auto at = [&](int x, int y, int z) { return (std::size_t(z) * std::size_t(ny) + std::size_t(y)) * std::size_t(nx) + std::size_t(x); };
  solid.for_each_voxel([&](Index3 s) {
    if (source.contains(s)) a[at(s.x - source.lo.x, s.y - source.lo.y, s.z - source.lo.z)] = 1.0;
  });
  for (const Index3& d : offsets) b[at(d.x - ext.lo.x, d.y - ext.lo.y, d.z - ext.lo.z)] = 1.0;
  fftw_complex* fa = fftw_alloc_complex(complex_size);
  fftw_complex* fb = fftw_alloc_complex(complex_size);
  fftw_plan forward_a, forward_b, backward;
  {
    std::lock_guard lock(fftw_planner_mutex);
    forward_a = fftw_plan_dft_r2c_3d(nz, ny, nx, a.data(), fa, FFTW_ESTIMATE);
    forward_b = fftw_plan_dft_r2c_3d(nz, ny, nx, b.data(), fb, FFTW_ESTIMATE);
    backward = fftw_plan_dft_c2r_3d(nz, ny, nx, fa, a.data(), FFTW_ESTIMATE);
  }
  fftw_execute(forward_a);
  fftw_execute(forward_b);
  for (std::size_t i = 0; i < complex_size; ++i) {
    const double re = fa[i][0] * fb[i][0] - fa[i][1] * fb[i][1];
    const double im = fa[i][0] * fb[i][1] + fa[i][1] * fb[i][0];
    fa[i][0] = re;
    fa[i][1] = im;
  }
  fftw_execute(backward);
  {
    std::lock_guard lock(fftw_planner_mutex);
    fftw_destroy_plan(forward_a);
    fftw_destroy_plan(forward_b);
    fftw_destroy_plan(backward);
  }
  fftw_free(fa);
  fftw_free(fb);
  // A count of overlapping voxels, scaled by the transform size; half a voxel decides.
  const double scale = double(real_size);
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        if (a[at(x, y, z)] / scale <= 0.5) continue;
        const Index3 p{source.lo.x + ext.lo.x + x, source.lo.y + ext.lo.y + y, source.lo.z + ext.lo.z + z};
        if (domain.contains(p)) out.set(p);
      }
  return out;
}

}  // namespace hybridctl::geometry::detail
