#pragma once
// The manufacturability check (paper section 6, Theorem 1 with a tolerance zone): a
// verdict before any search, and for every atom that no plan can keep or drop as a
// whole, where it is, how big, and which primitives hold it.

#include <string>
#include <vector>

#include "planner/atoms/atoms.hpp"
#include "planner/search/core_proof.hpp"
#include "planner/search/search.hpp"

namespace hybridctl::planner {

struct ViolatingAtom {
  int atom = -1;
  std::string code;                 // as the paper writes it, P1 first
  std::vector<int> primitives;      // the primitives containing it
  double volume = 0;                // mm^3
  double volume_in_design = 0;      // mm^3
  geometry::Box3 bounds;            // mm
  Vec3 centroid;                    // mm
  // Why it must be kept and why it must not be (planner/atoms/tolerance_zone.hpp).
  bool holds_core = false;          // design deeper than the tolerance
  bool holds_thin_feature = false;  // needed to keep a feature thinner than twice the tolerance
  bool beyond_hull = false;         // air farther than the tolerance from the design
  bool holds_thin_gap = false;      // needed to keep a gap narrower than twice the tolerance open
  std::string description;          // one sentence for people
};

enum class Modality { AdditiveOnly, SubtractiveOnly, Hybrid };

struct Verdict {
  // What hybridctl says of the part (plan.json's verdict.outcome, the exit code, `plan`'s
  // text and the report): manufacturable, with plans; not manufacturable, proven (violating
  // atoms, a proof from a few atoms, an exhausted search or exploration); or undecided, the
  // search stopped at its limits or on primitives corrected by execution, and the summary
  // says why. Before the search the check sets Manufacturable for "not ruled out", and
  // plan_part settles the outcome when the search is over.
  enum class Outcome { Manufacturable, NotManufacturable, Undecided };
  Outcome outcome = Outcome::NotManufacturable;
  bool manufacturable() const { return outcome == Outcome::Manufacturable; }
  // True when the answer was decided without search (violations, or unimodal sets).
  bool decided_without_search = false;
  Modality modality = Modality::Hybrid;
  std::string summary;
  std::vector<ViolatingAtom> violations;
};

// "manufacturable", "not-manufacturable", "undecided": as plan.json writes the outcome.
const char* to_string(Verdict::Outcome outcome);

// An atom located (bounds, centroid), with the primitives holding it and what the tolerance
// zone says of it; its description is the caller's.
ViolatingAtom located_atom(const PlanningProblem& problem, const AtomMeasures& measures, int atom, const Lattice& lattice);

// The verdict of a proof that no plan exists (planner/search/core_proof.hpp): the atoms it needs,
// each located with the primitives that hold it.
Verdict core_verdict(const PlanningProblem& problem, const CoreProof& proof, const std::vector<AtomMeasures>& measures,
                     const Lattice& lattice);

// `problem` carries the primitives' names, modes and atom sets; `measures` the atoms.
Verdict check_manufacturability(const PlanningProblem& problem, const std::vector<AtomMeasures>& measures,
                                const Lattice& lattice);

}  // namespace hybridctl::planner
