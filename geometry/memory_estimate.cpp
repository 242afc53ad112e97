#include "geometry/memory_estimate.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>

#include "common/error.hpp"

namespace hybridctl::geometry {

double grid_voxels(const Box3& region, double h, int pad) {
  auto count = [&](double lo, double hi) { return std::max(0.0, std::floor((hi - lo) / h) + 1 + 2.0 * pad); };
  return count(region.min.x, region.max.x) * count(region.min.y, region.max.y) * count(region.min.z, region.max.z);
}

double solid_bytes(const Box3& region, double h, int pad) {
  const double nx = std::max(0.0, std::floor((region.max.x - region.min.x) / h) + 1 + 2.0 * pad);
  const double words = std::ceil(nx / 64) + 1;  // word-aligned rows
  return words * 8 * grid_voxels(region, h, pad) / std::max(nx, 1.0);
}

std::uint64_t physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), size = ::sysconf(_SC_PAGE_SIZE);
  return pages > 0 && size > 0 ? std::uint64_t(pages) * std::uint64_t(size) : 0;
}

std::uint64_t default_memory_budget() {
  const std::uint64_t physical = physical_memory_bytes();
  return physical ? physical / 2 : std::uint64_t(8) << 30;
}

std::uint64_t parse_memory_size(const std::string& text, const std::string& what) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  const std::string unit = text.substr(used);
  double scale = 0;
  if (unit.empty() || unit == "B") scale = 1;
  else if (unit == "k" || unit == "K" || unit == "KB" || unit == "KiB") scale = 1024.0;
  else if (unit == "M" || unit == "MB" || unit == "MiB") scale = 1024.0 * 1024;
  else if (unit == "G" || unit == "GB" || unit == "GiB") scale = 1024.0 * 1024 * 1024;
  else if (unit == "T" || unit == "TB" || unit == "TiB") scale = 1024.0 * 1024 * 1024 * 1024;
  if (used == 0 || scale == 0 || !(v > 0))
    throw InputError(what + " '" + text + "': expected a size greater than 0 such as 8G, 500M or 64k");
  return std::uint64_t(v * scale);
}

std::string format_bytes(double b) {
  char buf[32];
  if (b >= 1024.0 * 1024 * 1024) std::snprintf(buf, sizeof buf, "%.1f GiB", b / (1024.0 * 1024 * 1024));
  else if (b >= 1024.0 * 1024) std::snprintf(buf, sizeof buf, "%.1f MiB", b / (1024.0 * 1024));
  else std::snprintf(buf, sizeof buf, "%.0f KiB", b / 1024.0);
  return buf;
}

void check_memory_budget(const std::function<double(double)>& estimate, double h, std::uint64_t budget, const std::string& what,
                         const std::string& advice) {
  const double need = estimate(h);
  if (need <= double(budget)) return;
  // Memory falls as the voxel grows: double until it fits, then bisect to 1 %.
  double lo = h, hi = h;
  while (estimate(hi) > double(budget) && hi < 1e6) {
    lo = hi;
    hi *= 2;
  }
  while (hi - lo > 0.01 * hi) {
    const double mid = (lo + hi) / 2;
    (estimate(mid) > double(budget) ? lo : hi) = mid;
  }
  char voxel[32];
  std::snprintf(voxel, sizeof voxel, "%.3g", hi * 1.01);
  throw InputError(what + " needs about " + format_bytes(need) + " of memory, over the budget of " +
                   format_bytes(double(budget)) + " (--memory-budget; default half the physical memory); " + advice + voxel +
                   " or larger fits");
}

}  // namespace hybridctl::geometry
