#pragma once
// Faces a deposit may not leave as it lays them (docs/search.md, "Faces left as
// deposited"): the hybrid rule that a face stays as deposited only where the tolerance
// allows it, and elsewhere a removal after the deposit finishes it. The search passes over
// plans that break it before anything is executed.
//
// Three things say where a deposit's faces may not stay as laid:
// - its head's as-deposited accuracy (config::AdditiveHead::accuracy) is coarser than the
//   part's tolerance: none of its faces may stay as laid;
// - it is an overfill deposit (O-AM), laid with the head's machining allowance
//   (config::AdditiveHead::machining_allowance) beyond the design, and the allowance is more
//   than the tolerance: none of its faces may stay as laid;
// - an executed candidate left a face of it beyond the tolerance as deposited (exact
//   verification names the place and the action): that face, wherever the plan stands,
//   since the bead's shape there does not depend on what came before (a judgement, like
//   validation's own skip rules, that spares executing the same face again in every order).
//
// A face counts as finished when a removal after the deposit clears air next to it (or,
// for a learned face that stands out, holds air next to it: LearnedFaceAtom):
// material stood there (an O-AM primitive's machining allowance, stock, an earlier
// deposit), and the removal's region of influence meets the face, so its finishing passes
// cut it to the design's real surface; exact verification judges the result. A deposit laid near-net (U-AM) and a
// removal that only runs in air beside it leave the face as laid. The rule is lenient on
// purpose: it only spares executions whose outcome is already known.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "config/machine.hpp"
#include "geometry/solid.hpp"
#include "planner/atoms/atoms.hpp"
#include "planner/primitives/machine_primitives.hpp"
#include "planner/problem/problem.hpp"

namespace hybridctl::planner {

// A face an executed candidate left beyond the tolerance as deposited.
struct DepositedFace {
  int primitive = -1;  // the deposit that laid it
  geometry::Vec3 at;   // mm, part frame: the place exact verification named
  double mm = 0;       // how far off, the head's accuracy included
  bool excess = true;  // it stands out of the design there (else it falls short of it)
};

// An atom whose face a deposit left beyond the tolerance at one place, with the atoms free
// of the design around that place. Where the deposit stands out there, a removal after it
// whose region holds one of those atoms finishes the face: it is planned against the
// material really present (docs/export.md), the bead's overfill included, and its
// finishing passes cut that to the design's real surface. Where the deposit falls short,
// only one that clears material laid beyond the face there (an overfill deposit's) does.
struct LearnedFaceAtom {
  int atom = -1;
  AtomSet air_near;
  bool excess = true;
};

struct FaceRule {
  // Per primitive: the atoms whose faces it may not leave as deposited anywhere (empty:
  // none), from its head's accuracy.
  std::vector<AtomSet> tight;
  // Per primitive: the faces executed candidates showed it leaves beyond the tolerance.
  std::vector<std::vector<LearnedFaceAtom>> learned_atoms;
  // Per primitive: why, in a phrase ("its head's accuracy 1 mm is coarser than the
  // tolerance 0.3 mm"); empty where nothing is tight.
  std::vector<std::string> why;
  // Per atom: the atoms not bound to be present (free or must-out) that share a voxel face
  // with it; a removal holding one of them reaches its face.
  std::vector<AtomSet> air_beside;
  // Per atom: it holds design and air, or design beside an atom that holds air.
  std::vector<bool> surface;
  std::vector<DepositedFace> learned;
  std::int64_t passed_over = 0;  // goal plans the search passed over for the rule
  std::string first_passed;      // what the first of them left, in a sentence
};

// The rule before any execution: the surface atoms of every deposit whose head is coarser
// than the tolerance. `primitives` as plan_part computed them, `problem` its symbolic form.
FaceRule make_face_rule(const config::Machine& machine, const std::vector<Primitive>& primitives,
                        const PlanningProblem& problem, const AtomDecomposition& atoms,
                        const std::vector<AtomMeasures>& measures, double tolerance);

// Takes in a face an executed candidate left as deposited: the surface atoms around its
// place that the deposit holds, each with the air around that place. False when nothing
// new was learned.
bool learn_face(FaceRule& rule, const PlanningProblem& problem, const AtomDecomposition& atoms,
                const std::vector<AtomMeasures>& measures, const DepositedFace& face);

// The first face `plan` leaves as deposited against the rule: the step that laid it and an
// atom of it; none when every tight face it lays is finished by a removal after it.
struct FaceLeft {
  std::size_t step = 0;
  int atom = -1;
};
std::optional<FaceLeft> face_left_as_deposited(const PlanningProblem& problem, const FaceRule& rule, const Plan& plan);

// "P3 leaves the face around (x, y, z) mm as deposited (its head's accuracy ...)".
std::string describe_face_left(const PlanningProblem& problem, const FaceRule& rule, const std::vector<AtomMeasures>& measures,
                               const Plan& plan, const FaceLeft& left);

}  // namespace hybridctl::planner
