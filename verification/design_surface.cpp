#include "verification/design_surface.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <mutex>
#include <tuple>
#include <vector>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#include <tbb/parallel_for.h>

#include "common/error.hpp"
#include "verification/vector_index.hpp"

namespace hybridctl::verification {

using geometry::Vec3;

namespace {

using K = CGAL::Simple_cartesian<double>;
using Point = K::Point_3;
using Vector = K::Vector_3;
using Triangle3 = K::Triangle_3;
using Primitive = CGAL::AABB_triangle_primitive<K, std::vector<Triangle3>::const_iterator>;
using AabbTree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

Point point(const Vec3& v) { return {v.x, v.y, v.z}; }
Vec3 vec(const Vector& v) { return {v.x(), v.y(), v.z()}; }

// The longest-edge bisection of a triangle until no edge is longer than twice `spacing`
// or the piece is smaller than half a spacing square: each leaf's centroid is a sample
// standing for the leaf's area (about spacing^2 on a large face; a facet smaller than
// that is one sample).
void sample_triangle(const Triangle3& t, const Vector& normal, double spacing, std::uint32_t index,
                     std::vector<SurfaceSample>& out) {
  std::vector<Triangle3> stack{t};
  const double limit = 4 * spacing * spacing;
  // A piece already smaller than half a spacing square is not split on: the slivers of a
  // fan of long thin facets (a cylinder's cap) would otherwise multiply without need.
  const double sliver = std::pow(spacing * spacing / 2, 2);
  while (!stack.empty()) {
    const Triangle3 f = stack.back();
    stack.pop_back();
    double longest = 0;
    int edge = 0;
    for (int i = 0; i < 3; ++i) {
      const double l = CGAL::squared_distance(f[i], f[(i + 1) % 3]);
      if (l > longest) longest = l, edge = i;
    }
    if (longest <= limit || f.squared_area() <= sliver) {
      const Point c = CGAL::centroid(f);
      out.push_back({{c.x(), c.y(), c.z()}, vec(normal), 0, 0, std::sqrt(f.squared_area()), index});
      continue;
    }
    const Point& a = f[edge];
    const Point& b = f[(edge + 1) % 3];
    const Point& o = f[(edge + 2) % 3];
    const Point m = CGAL::midpoint(a, b);
    stack.emplace_back(a, m, o);
    stack.emplace_back(m, b, o);
  }
}

}  // namespace

struct DesignSurface::Tree {
  std::vector<Triangle3> triangles;
  AabbTree tree;
  std::mutex frames_mutex;
  std::map<std::tuple<config::Approach, std::size_t, std::size_t>, std::unique_ptr<FrameIndex>> frames;
};

SamplingOptions sampling_for(double tolerance, double voxel) {
  SamplingOptions o;
  o.spacing = std::clamp(tolerance, 0.1, std::max(0.1, voxel));
  o.reach = std::max(4 * tolerance, 2 * voxel);
  return o;
}

DesignSurface::DesignSurface(const geometry::TriangleMesh& mesh, const std::string& name, SamplingOptions options)
    : tree_(std::make_unique<Tree>()), options_(options) {
  const geometry::TriangleMesh clean = geometry::clean_mesh(mesh);
  for (const geometry::Triangle& t : clean.triangles) {
    Triangle3 tri(point(t[0]), point(t[1]), point(t[2]));
    if (tri.squared_area() > 1e-18) {
      tree_->triangles.push_back(tri);
      triangles_.push_back(t);
    }
  }
  if (tree_->triangles.empty()) throw InputError(name + ": the mesh has no triangle with an area to verify against");
  tree_->tree.insert(tree_->triangles.begin(), tree_->triangles.end());
  tree_->tree.build();
  tree_->tree.accelerate_distance_queries();
  const AabbTree& tree = tree_->tree;

  // Outward normals: the winding's normal, turned where a point just beside the face on
  // that side is inside the mesh (an odd count of crossings along a ray in a direction no
  // face of an axis-aligned part is parallel to).
  const Vector probe(0.5773502691896258, 0.5345224838248488, 0.6172133998483676);
  std::vector<Vector> normals(tree_->triangles.size());
  tbb::parallel_for(std::size_t{0}, normals.size(), [&](std::size_t i) {
    const Triangle3& t = tree_->triangles[i];
    Vector n = CGAL::cross_product(t[1] - t[0], t[2] - t[0]);
    n = n / std::sqrt(n.squared_length());
    const double e = 1e-4;
    const K::Ray_3 ray(CGAL::centroid(t) + e * n, probe);
    if (tree.number_of_intersected_primitives(ray) % 2 == 1) n = -n;
    normals[i] = n;
  });
  for (const Triangle3& t : tree_->triangles) area_ += std::sqrt(t.squared_area());

  for (;;) {
    samples_.clear();
    for (std::size_t i = 0; i < tree_->triangles.size(); ++i)
      sample_triangle(tree_->triangles[i], normals[i], options_.spacing, std::uint32_t(i), samples_);
    if (samples_.size() <= options_.max_samples) break;
    options_.spacing *= 1.05 * std::sqrt(double(samples_.size()) / double(options_.max_samples));
  }

  // Each vector's reach: half the way to the next face along it, at most the reach asked.
  const double start = 1e-7;
  tbb::parallel_for(std::size_t{0}, samples_.size(), [&](std::size_t i) {
    SurfaceSample& s = samples_[i];
    const Vector n(s.normal.x, s.normal.y, s.normal.z);
    auto free_length = [&](const Vector& dir) {
      // Only faces within twice the reach matter: a segment query prunes the tree to them.
      const K::Segment_3 probe(point(s.point) + start * dir, point(s.point) + 2 * options_.reach * dir);
      std::vector<AabbTree::Intersection_and_primitive_id<K::Segment_3>::Type> hits;
      tree.all_intersections(probe, std::back_inserter(hits));
      double nearest = 2 * options_.reach;
      for (const auto& hit : hits) {
        const Point* at = boost::get<Point>(&hit.first);
        const K::Segment_3* along = boost::get<K::Segment_3>(&hit.first);
        nearest = std::min(nearest, std::sqrt(CGAL::squared_distance(point(s.point), at ? *at : along->source())));
      }
      return std::min(options_.reach, 0.5 * nearest);
    };
    s.outward = free_length(n);
    s.inward = free_length(-n);
  });
}

DesignSurface::~DesignSurface() = default;
DesignSurface::DesignSurface(DesignSurface&&) noexcept = default;
DesignSurface& DesignSurface::operator=(DesignSurface&&) noexcept = default;

const FrameIndex& DesignSurface::frame(config::Approach approach, std::size_t part, std::size_t parts) const {
  const std::lock_guard<std::mutex> lock(tree_->frames_mutex);
  std::unique_ptr<FrameIndex>& f = tree_->frames[{approach, part, parts}];
  if (!f) f = std::make_unique<FrameIndex>(samples_, approach, part, parts);
  return *f;
}

double DesignSurface::distance(const Vec3& p) const { return std::sqrt(tree_->tree.squared_distance(point(p))); }

}  // namespace hybridctl::verification
