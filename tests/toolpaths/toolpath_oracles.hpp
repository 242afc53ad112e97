#pragma once
// Independent checks of toolpaths for the toolpath tests: they share nothing with the
// generators but the Solid type. A tool is the continuous body of revolution the planner
// describes (planner::tool_instrument); a voxel is touched when its centre lies inside
// the tool (the house convention: a voxel belongs to a shape when its centre does).
// Moves are followed at sub-voxel steps.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <variant>
#include <vector>

#include "gcode/toolpath.hpp"
#include "geometry/morphology.hpp"
#include "geometry/solid.hpp"

namespace hybridctl::toolpaths::testing {

using geometry::AxialSection;
using geometry::Index3;
using geometry::Lattice;
using geometry::Solid;
using geometry::Vec3;

// A body of revolution about +Z from the tip: the squared radius at each height above it.
struct ToolProfile {
  std::vector<AxialSection> sections;
  double max_radius = 0;
  double length = 0;  // of the finite part; infinite sections go on

  static ToolProfile from(const std::vector<geometry::StructuringElement>& elements) {
    ToolProfile p;
    for (const auto& e : elements) {
      const auto& body = std::get<geometry::AxialBody>(e);
      for (const auto& s : body.sections) {
        p.sections.push_back(s);
        p.max_radius = std::max(p.max_radius, s.kind == AxialSection::Kind::Torus ? s.ring + s.radius : s.radius);
        if (!std::isinf(s.to)) p.length = std::max(p.length, s.to);
      }
    }
    return p;
  }
  double radius_sq(double dz) const {
    double best = -1;
    for (const auto& s : sections) best = std::max(best, s.radius_squared_at(dz));
    return best;
  }
};

// The voxels of a solid by column, for quick "what is near this axis" questions.
class Columns {
 public:
  explicit Columns(const Solid& s) : lattice_(s.lattice()) {
    s.for_each_voxel([&](Index3 v) { columns_[{v.x, v.y}].push_back(v.z); });
  }
  const Lattice& lattice() const { return lattice_; }
  const std::vector<int>* column(int x, int y) const {
    auto it = columns_.find({x, y});
    return it == columns_.end() ? nullptr : &it->second;
  }

 private:
  Lattice lattice_;
  std::map<std::pair<int, int>, std::vector<int>> columns_;
};

// Whether the tool with its tip at `tip` holds the centre of a voxel of `material` (more
// than grazing it: 1e-9 mm^2 of slack against rounding).
inline bool tool_touches(const ToolProfile& tool, const Columns& material, Vec3 tip, Index3* where = nullptr) {
  const Lattice& l = material.lattice();
  const double h = l.voxel_size;
  const int cx = int(std::floor((tip.x - l.origin.x) / h)), cy = int(std::floor((tip.y - l.origin.y) / h));
  const int R = int(std::ceil(tool.max_radius / h)) + 1;
  for (int y = cy - R; y <= cy + R; ++y)
    for (int x = cx - R; x <= cx + R; ++x) {
      const auto* col = material.column(x, y);
      if (!col) continue;
      const Vec3 c = l.center({x, y, 0});
      const double lateral_sq = (c.x - tip.x) * (c.x - tip.x) + (c.y - tip.y) * (c.y - tip.y);
      if (lateral_sq > tool.max_radius * tool.max_radius) continue;
      for (int z : *col) {
        const double dz = l.origin.z + (z + 0.5) * h - tip.z;
        if (dz < -1e-9) continue;
        if (lateral_sq <= tool.radius_sq(std::max(dz, 0.0)) - 1e-9) {
          if (where) *where = {x, y, z};
          return true;
        }
      }
    }
  return false;
}

// Calls fn(point) along the straight move a -> b every `step` mm, both ends included.
inline void along(Vec3 a, Vec3 b, double step, const std::function<void(Vec3)>& fn) {
  const double len = std::sqrt((b.x - a.x) * (b.x - a.x) + (b.y - a.y) * (b.y - a.y) + (b.z - a.z) * (b.z - a.z));
  const int n = std::max(1, int(std::ceil(len / step)));
  for (int i = 0; i <= n; ++i) {
    const double t = double(i) / n;
    fn({a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.z + t * (b.z - a.z)});
  }
}

// Material that a cutter removes as it moves: a voxel set on a box, updated by stamping
// the cutter at sub-voxel steps along feed moves.
class Stock {
 public:
  Stock(const Solid& initial, const ToolProfile& cutter) : lattice_(initial.lattice()), cutter_(cutter) {
    box_ = initial.bounding_box();
    present_ = initial;
  }
  const Solid& present() const { return present_; }
  void cut_along(Vec3 a, Vec3 b) {
    if (box_.empty()) return;
    const double h = lattice_.voxel_size;
    along(a, b, h / 8, [&](Vec3 p) { stamp(p); });
  }
  void stamp(Vec3 tip) {
    const double h = lattice_.voxel_size;
    const int R = int(std::ceil(cutter_.max_radius / h)) + 1;
    const int cx = int(std::floor((tip.x - lattice_.origin.x) / h)), cy = int(std::floor((tip.y - lattice_.origin.y) / h));
    const int z0 = std::max(box_.lo.z, int(std::floor((tip.z - lattice_.origin.z) / h - 0.5)));
    const int z1 = std::min(box_.hi.z - 1, int(std::ceil((tip.z + cutter_.length - lattice_.origin.z) / h)));
    for (int y = std::max(cy - R, box_.lo.y); y <= std::min(cy + R, box_.hi.y - 1); ++y)
      for (int x = std::max(cx - R, box_.lo.x); x <= std::min(cx + R, box_.hi.x - 1); ++x) {
        const Vec3 c = lattice_.center({x, y, 0});
        const double lateral_sq = (c.x - tip.x) * (c.x - tip.x) + (c.y - tip.y) * (c.y - tip.y);
        if (lateral_sq > cutter_.max_radius * cutter_.max_radius + 1e-9) continue;
        for (int z = z0; z <= z1; ++z) {
          const double dz = lattice_.origin.z + (z + 0.5) * h - tip.z;
          if (dz < -1e-9) continue;
          if (lateral_sq <= cutter_.radius_sq(std::max(dz, 0.0)) + 1e-9 && present_.contains({x, y, z}))
            present_.set({x, y, z}, false);
        }
      }
  }

 private:
  Lattice lattice_;
  ToolProfile cutter_;
  geometry::IndexBox box_;
  Solid present_;
};

// The position before each move: the path's start, then each move's end.
inline std::vector<Vec3> move_starts(const Toolpath& p) {
  std::vector<Vec3> out;
  Vec3 at = p.start;
  for (const auto& m : p.moves) {
    out.push_back(at);
    at = m.to;
  }
  return out;
}

}  // namespace hybridctl::toolpaths::testing
