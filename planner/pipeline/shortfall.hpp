#pragma once
// What executing a candidate plan shows about the symbolic model (docs/validation.md,
// "Learning from rejected candidates"). The model says an additive action deposits all of
// its primitive's atoms that are missing and a subtractive one clears all of its atoms that
// are present; the toolpaths and the material simulation sometimes cannot (a layer under
// material the head cannot reach past, a region no pass covers, a bead that falls off an
// edge). When an atom the plan needs is not as planned after the action that last changed
// it, that action's primitive fell short on that atom. The planner then takes the atom out
// of the primitive and searches again, instead of offering validation thousands of plans
// that count on the same action for the same atom. A deposit can also put material on an
// atom outside its primitive (a spill): that atom is added to the primitive instead.

#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "geometry/solid.hpp"
#include "planner/atoms/atoms.hpp"
#include "planner/pipeline/deposited_faces.hpp"
#include "plan/deviation.hpp"
#include "plan/rejection.hpp"
#include "planner/search/search.hpp"

namespace hybridctl::planner {

struct Shortfall {
  int primitive = -1;  // the action's primitive
  int atom = -1;       // the atom it did not deposit (additive) or did not clear (subtractive)
  double volume = 0;   // mm^3: the atom's
  // The other way round: a deposit that put material on an atom outside its primitive
  // (find_spills); learned as an atom it deposits too.
  bool spill = false;
  friend bool operator==(const Shortfall&, const Shortfall&) = default;
};

// What validation says of one candidate: no reasons, it makes the part; else why not, and
// the shortfalls its execution showed (possibly none).
struct CandidateCheck {
  CandidateCheck(std::vector<plan::RejectionReason> reasons = {}, std::vector<Shortfall> shortfalls = {})
      : reasons(std::move(reasons)), shortfalls(std::move(shortfalls)) {}
  std::vector<plan::RejectionReason> reasons;
  std::vector<Shortfall> shortfalls;
  // Faces the candidate left beyond the tolerance as deposited (exact verification).
  std::vector<DepositedFace> faces;
};

// An atom the plan needs falls short when, after the plan's first `steps` actions, less
// than half of it is as planned: a must-in atom the plan holds by then of which less than
// half was built, or a must-out atom the plan has cleared of which more than half is still
// there, when the last of those steps is the one that changed it last in the plan (an
// earlier action's atom may have been changed since by a later one's spill). Raw stock is
// never charged (it is there or the plan does not start). `built`: the material after
// those actions, on the atoms' lattice.
//
// What is learned holds once the plan has begun (PrimitiveSpec::falls_short): the plan's
// first action works on the plate, where what failed later (material over the layer,
// nothing under it) is not in its way.
std::vector<Shortfall> find_shortfalls(const PlanningProblem& problem, const AtomDecomposition& atoms, const Plan& plan,
                                       std::size_t steps, const geometry::Solid& built);

// A plan whose additions are done with part of the design's core missing (validation's
// "missing_material": removals cannot put it back) often misses it by a strip along an edge,
// a bead's inset, which is a small part of each atom it touches and made by an action
// before the last. `missing`: the core voxels absent from the material (on the atoms'
// lattice). Each atom holding one is charged to the action that deposited it last in the
// plan, when no removal follows that action (additions never take material away, so what
// is missing is that deposit's) and it is not the first action nor raw stock.
std::vector<Shortfall> find_missing_core_shortfalls(const PlanningProblem& problem, const AtomDecomposition& atoms,
                                                    const Plan& plan, std::size_t steps, const geometry::Solid& missing);

// A layer the last executed action skipped (a "layer_skipped" reason: material over it the
// head cannot reach past, which may be a bead an earlier deposit spilled, not in the plan's
// state) leaves a few voxels of a large atom missing, far less than find_shortfalls' half.
// The toolpath has said where, so the atoms missing voxels within two voxels of that point,
// which that action is the one to deposit in the plan, are charged to its primitive: with
// them taken out, the search stops offering the same deposit to fill the same spot.
std::vector<Shortfall> find_skipped_layer_shortfalls(const PlanningProblem& problem, const AtomDecomposition& atoms,
                                                     const Plan& plan, std::size_t steps, const geometry::Solid& built,
                                                     const std::vector<plan::RejectionReason>& reasons);

// A deposit's beads reach past its primitive where the model does not see it (under a
// leaning wall the bead's edge lies out beyond the tolerance where no cutter from above
// reaches). A must-out atom the plan leaves empty after `steps` actions that holds material
// (more than half of it, or any within two voxels of where an "excess_material" reason
// says the part is worst), and that no removal after the deposit holds, is charged to the
// last deposit executed that is not raw stock: with the atom added to what that primitive
// deposits, the search knows the material it leaves and that nothing clears it.
std::vector<Shortfall> find_spills(const PlanningProblem& problem, const AtomDecomposition& atoms, const Plan& plan,
                                   std::size_t steps, const geometry::Solid& built,
                                   const std::vector<plan::RejectionReason>& reasons);

// The spills that are the deposit's, not the grid's. An atom that must stay empty only to
// keep a gap open (thin_gap, and none of its voxels beyond the tolerance zone's hull) may
// be a concave corner's voxels within a voxel of the STL's faces, which a bead laid up to
// the real faces fills: unless the worst excess `exact` (the candidate's exact
// verification) names lies beyond the tolerance within two voxels of it, the spill is
// dropped (a place the worst one hides shows once that is mended). Without an exact
// verification all are kept.
std::vector<Shortfall> spills_beyond_the_grid(std::vector<Shortfall> spills, const AtomDecomposition& atoms,
                                              const std::vector<AtomMeasures>& measures,
                                              const std::optional<plan::ExactDeviation>& exact);

}  // namespace hybridctl::planner
