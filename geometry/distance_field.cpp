#include "geometry/distance_field.hpp"

#include <cmath>

#include "geometry/morphology_internal.hpp"

namespace hybridctl::geometry {

using namespace detail;

namespace {

DenseGrid<float> squared_distances(const Solid& to, const IndexBox& box) {
  DenseGrid<float> g = distance_seed<float>(to, box);
  distance_pass(g, Axis::X, 1.0, kInf, true);
  distance_pass(g, Axis::Y, 1.0, kInf, false);
  distance_pass(g, Axis::Z, 1.0, kInf, false);
  return g;
}

// The largest squared distance (voxels^2) from `from` to `to` inside `work`, and where.
// Exact whenever it is at most the squared margin `work` leaves around `from`: a nearer
// voxel of `to` outside `work` would be farther than that.
std::pair<double, std::optional<Index3>> farthest_within(const Solid& from, const Solid& to, const IndexBox& work) {
  const DenseGrid<float> g = squared_distances(to, work);
  double worst = -1;
  std::optional<Index3> at;
  from.for_each_voxel([&](Index3 v) {
    const double d = double(g.values[g.index(v.x - work.lo.x, v.y - work.lo.y, v.z - work.lo.z)]);
    if (d > worst) {
      worst = d;
      at = v;
    }
  });
  return {worst, at};
}

IndexBox grown_by(const IndexBox& b, int n) {
  return {{b.lo.x - n, b.lo.y - n, b.lo.z - n}, {b.hi.x + n, b.hi.y + n, b.hi.z + n}};
}

}  // namespace

DistanceField::DistanceField(const Solid& to, const IndexBox& box) : box_(box), voxel_size_(to.voxel_size()) {
  if (box.empty()) return;
  DenseGrid<float> g = squared_distances(to, box);
  values_ = std::move(g.values);
}

double DistanceField::distance_mm(Index3 v) const { return std::sqrt(double(squared(v))) * voxel_size_; }

FarthestVoxel farthest_voxel(const Solid& from, const Solid& to) {
  const IndexBox fb = from.bounding_box();
  if (fb.empty()) return {};
  const IndexBox tb = to.bounding_box();
  if (tb.empty()) {
    std::optional<Index3> first;
    from.for_each_voxel([&](Index3 v) {
      if (!first) first = v;
    });
    return {std::numeric_limits<double>::infinity(), first};
  }
  // Deviations are usually a few voxels deep: look near `from` first, and over the
  // whole extent only when something there is farther than the margin.
  constexpr int kNear = 16;
  auto [worst, at] = farthest_within(from, to, box_intersection(box_union(fb, tb), grown_by(fb, kNear)));
  if (worst > double(kNear) * double(kNear)) std::tie(worst, at) = farthest_within(from, to, box_union(fb, tb));
  return {std::sqrt(worst) * from.voxel_size(), at};
}

}  // namespace hybridctl::geometry
