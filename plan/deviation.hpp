#pragma once
// How far a made solid M is from the design D, both ways: one measure for the planner's
// plans (plan.json's `deviation`, docs/plan-format.md) and for what a run built
// (`hybridctl dry-run`, validation by execution).
//
// M is within the tolerance t of D when every point of M's surface is within t of D's
// surface and every point of D's surface within t of M's (the two-sided Hausdorff
// distance of the surfaces). On voxels: a voxel stands for the cube around its centre and
// a surface is the faces between material and air. Every point of M's surface that is
// not on D's lies on a voxel where M and D differ, and so does every point of D's that is
// not on M's; a wrong voxel whose centre is e from the nearest voxel centre across a
// surface reaches at most e from it (exactly e along an axis). So:
//
//   worst_out      the largest such e from D's other side over the voxels where M and D
//                  differ: bounds how far M's surface gets from D's, and how deep wrong
//                  material or a wrong hole goes (which catches a filled internal channel);
//   worst_missing  the largest such e from M's other side: bounds how far D's surface gets
//                  from M's (a missing fin: its tip from the plate left; a filled slot:
//                  its floor from the surface over it).
//
// Both at most t is `within_tolerance`. The half-voxel convention makes one layer too many
// or too few one voxel (h) off both ways; a layer's voxel round an edge or a corner, meeting
// the other side at an edge or a corner only, is sqrt(2) or sqrt(3) h off, and where t >= h
// (always, within the planning band) it is within t too: it is the same one layer the
// grid resolves, and the real surface is exact verification's to judge. The older fields `worst_over` and
// `worst_under` keep their meaning, the depth of the wrong voxel's centre, h/2 less.

#include <cstddef>
#include <optional>
#include <string>

#include "geometry/solid.hpp"

namespace hybridctl::plan {

struct Deviation {
  double over_volume = 0;     // mm^3 of material outside the design
  double under_volume = 0;    // mm^3 of the design left empty
  double worst_over = 0;      // mm: the centre of the farthest voxel outside the design from its surface
  double worst_under = 0;     // mm: the centre of the farthest empty voxel of the design from its surface
  double worst_distance = 0;  // mm: the larger of the two
  double worst_out = 0;       // mm: M's surface (and wrong material or holes) from D's surface
  std::optional<geometry::Vec3> worst_out_at;      // mm, part frame: the voxel centre where
  double worst_missing = 0;   // mm: D's surface from M's surface; infinite when M is empty
  std::optional<geometry::Vec3> worst_missing_at;  // mm, part frame: the voxel centre where
  bool within_tolerance = false;  // worst_out and worst_missing both at most the tolerance
};

// The part made measured against the design's real surface, independent of the voxel
// (verification/exact_deviation.hpp, docs/verification.md): plan.json's `deviation.exact`.
struct ExactPlace {
  double mm = 0;                     // how far the part made is from the design's surface there
  std::optional<geometry::Vec3> at;  // mm, part frame: the point of the part made (none: no deviation)
  int action = 0;                    // 1-based action whose move left that surface; 0: the start stock
  int line = 0;                      // its line in the plan's whole program; 0: none
  bool as_deposited = false;         // a bead's surface, widened by its head's as-deposited accuracy
  bool at_least = false;             // the deviation reaches the end of the vector: this much or more
  friend bool operator==(const ExactPlace&, const ExactPlace&) = default;
};

struct ExactDeviation {
  ExactPlace excess;          // material beyond the design's surface
  ExactPlace gouge;           // design material missing under its surface
  double within_share = 0;    // share of the design's surface area within the tolerance both ways
  double tolerance = 0;       // mm, the part's
  double spacing = 0;         // mm between the surface samples
  std::size_t samples = 0;
  bool within_tolerance() const { return excess.mm <= tolerance && gouge.mm <= tolerance; }
  friend bool operator==(const ExactDeviation&, const ExactDeviation&) = default;
};

// One line for people: "excess 0.24 mm at (x, y, z) by action 2 (line 812), gouge 0.12 mm
// at ... ; 97.1 % of the surface within 0.5 mm: within tolerance".
std::string exact_deviation_text(const ExactDeviation& d);

// How far (mm) worst_out and worst_missing may go and still be within `tolerance` on a grid
// of `voxel` mm: where one layer is within it, one layer in any direction is (above).
double judged_limit(double tolerance, double voxel);

// `made` and `design` on one lattice. Everything outside `made` is air, also beyond
// `domain` (kept for callers; the distances do not depend on it).
Deviation measure_deviation(const geometry::Solid& made, const geometry::Solid& design,
                            const geometry::IndexBox& domain, double tolerance);

// One line for people, as `plan` and `dry-run` print it: volumes over and under, both
// directions (with where, when beyond `band`), and "within the planning band" only when
// both hold. The voxels are judged within the planning band (plan/planning_band.hpp), never
// the drawing's tolerance: that is exact_deviation_text's to say.
std::string deviation_text(const Deviation& d, double band);

}  // namespace hybridctl::plan
