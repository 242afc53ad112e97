#pragma once
// The exact deviation of each plan on the design's own mesh (docs/report.md, "Exact
// deviation"): every plan's whole program replayed from its start stock as validation
// runs it (validation::execute_plan: each action planned against the material the ones
// before it really left), then measured against the STL's real surface by exact
// verification (verification::measure_program, docs/verification.md), and the samples'
// figures gathered onto the STL's triangles, so the report paints the design's real
// facets, not a voxel surface.
//
// Per triangle the worst of its samples. A sample is cut from exactly one facet
// (verification::SurfaceSample::triangle), so the facet's figure is its own samples'
// and nothing else's; the worst, not a mean, because a narrow gouge or lip beyond the
// tolerance must not be averaged away by the good rest of the facet (a facet painted red
// says "somewhere on it", and the summary's place says where). Colouring per vertex
// instead would need each vertex to take a figure from the samples of every facet around
// it: a defect on one face would bleed onto its neighbours across an edge (a lip under a
// flange onto the wall above it), and on the long thin facets STL cylinders are made of,
// samples lie far from any vertex, so the interpolation would show gradients that were
// never measured. Per triangle is also what keeps the page small: one figure per facet,
// not per sample (10^5 on a fine part).

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "config/machine.hpp"
#include "plan/deviation.hpp"
#include "plan/plan_file.hpp"
#include "report/report_mesh.hpp"

namespace hybridctl::report {

// One plan's part against the design's real surface, per triangle of ExactMaps::design.
struct TriangleDeviations {
  plan::ExactDeviation summary;       // as validation's (plan.json's deviation.exact)
  std::vector<float> excess, gouge;   // mm, the largest of the triangle's samples (0: none)
  std::vector<std::uint16_t> action;  // the action whose move left the worst sample's surface (0: the start stock)
  std::vector<std::uint8_t> deposited;  // 1: most of the triangle's area is left as deposited
  std::string error;                  // why there are no figures (the program cannot be replayed); empty: figures
};

struct ExactMaps {
  std::string stl;     // the STL measured against (the plan directory's design.stl, else the part)
  IndexedMesh design;  // its triangles as verification samples them (cleaned, with area), in its order
  std::vector<TriangleDeviations> plans;  // per plan of the file, in order; none when the STL is over its budget
};

// Null when the plan has no real surface (no design.stl and no part file: a design made on
// voxels). Replays at most `max_plans` plans (the best first); the others get an error
// saying so. An STL of more than `max_triangles` triangles is not replayed for (no plans).
// Throws what reading the STL throws.
std::optional<ExactMaps> exact_maps(const plan::PlanFile& file, const config::Machine& machine, std::size_t max_plans,
                                    std::size_t max_triangles);

// The page's and the snapshots' colour of a signed deviation (excess > 0, gouge < 0) at
// `tolerance`: a neutral grey at 0, to orange at +tolerance and to blue at -tolerance;
// beyond it, a flat dark red (excess) or dark violet (gouge), so that what is beyond the
// tolerance stands apart from the ramp (report.js, exactColour).
std::array<float, 3> exact_colour(double signed_mm, double tolerance);

// A triangle's signed figure: its excess, or minus its gouge when that is larger.
inline double signed_deviation(const TriangleDeviations& d, std::size_t t) {
  return d.excess[t] >= d.gouge[t] ? double(d.excess[t]) : -double(d.gouge[t]);
}

}  // namespace hybridctl::report
