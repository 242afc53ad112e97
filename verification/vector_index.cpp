#include "verification/vector_index.hpp"

#include "toolpaths/setup_frame.hpp"

namespace hybridctl::verification {
namespace {

using geometry::Vec3;

Vec3 along(const SurfaceSample& s, double t) {
  return {s.point.x + t * s.normal.x, s.point.y + t * s.normal.y, s.point.z + t * s.normal.z};
}

}  // namespace

FrameIndex::FrameIndex(const std::vector<SurfaceSample>& samples, config::Approach approach, std::size_t part,
                       std::size_t parts) {
  std::vector<Vec3> points, normals;
  points.reserve(samples.size());
  normals.reserve(samples.size());
  std::vector<geometry::Box3> boxes;
  boxes.reserve(samples.size());
  geometry::Box3 box{{1e300, 1e300, 1e300}, {-1e300, -1e300, -1e300}};
  for (const SurfaceSample& s : samples) {
    points.push_back(toolpaths::part_to_work(s.point, approach));
    normals.push_back(toolpaths::part_to_work(s.normal, approach));
    const Vec3 a = toolpaths::part_to_work(along(s, -s.inward), approach);
    const Vec3 b = toolpaths::part_to_work(along(s, s.outward), approach);
    const geometry::Box3 v{{std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)},
                           {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}};
    boxes.push_back(v);
    tallest_ = std::max(tallest_, v.max.z - v.min.z);
    wide_ = std::max({wide_, 0.5 * (v.max.x - v.min.x), 0.5 * (v.max.y - v.min.y)});
    box.min = {std::min(box.min.x, v.min.x), std::min(box.min.y, v.min.y), std::min(box.min.z, v.min.z)};
    box.max = {std::max(box.max.x, v.max.x), std::max(box.max.y, v.max.y), std::max(box.max.z, v.max.z)};
  }
  lo_ = box.min;
  const Vec3 size = box.size();
  // About 16 vectors per column on average, and no column narrower than 0.5 mm.
  cell_ = std::max(0.5, std::sqrt(std::max(1e-6, size.x * size.y) * 16.0 / std::max<double>(1, double(samples.size()))));
  n_[0] = std::max(1, int(std::ceil(size.x / cell_)) + 1);
  n_[1] = std::max(1, int(std::ceil(size.y / cell_)) + 1);
  const std::size_t columns = std::size_t(n_[0]) * std::size_t(n_[1]);
  std::vector<std::uint32_t> count(columns + 1, 0);
  // Each vector in the one column of its box's centre; queries widen by the widest half box.
  auto each_column = [&](const geometry::Box3& b, auto&& fn) {
    const double cx = 0.5 * (b.min.x + b.max.x), cy = 0.5 * (b.min.y + b.max.y);
    fn(column(range(cx, cx, 0).first, range(cy, cy, 1).first));
  };
  auto mine = [&](std::size_t i) { return i % parts == part; };
  for (std::size_t i = 0; i < boxes.size(); ++i)
    if (mine(i)) each_column(boxes[i], [&](std::size_t c) { ++count[c + 1]; });
  for (std::size_t c = 1; c < count.size(); ++c) count[c] += count[c - 1];
  start_ = count;
  entries_.resize(count.back());
  for (std::uint32_t i = 0; i < boxes.size(); ++i)
    if (mine(i))
      each_column(boxes[i], [&](std::size_t c) {
        entries_[count[c]++] = {boxes[i].min.z, boxes[i].max.z, points[i], normals[i], -samples[i].inward,
                                samples[i].outward, i};
      });
  for (std::size_t c = 0; c < columns; ++c)
    std::sort(entries_.begin() + start_[c], entries_.begin() + start_[c + 1],
              [](const Entry& a, const Entry& b) { return a.z0 < b.z0; });
}

const FrameIndex::Entry* FrameIndex::lower_bound(const Entry* first, const Entry* last, double z) {
  return std::lower_bound(first, last, z, [](const Entry& a, double v) { return a.z0 < v; });
}

}  // namespace hybridctl::verification
