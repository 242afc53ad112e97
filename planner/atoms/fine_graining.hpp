#pragma once
// Iterative fine-graining (the paper's section 8; docs/bands.md, "Local primitives"): an
// atom that straddles the design beyond the tolerance (planner/atoms/check.hpp) has an inside
// part Ai = atom ∩ design and an outside part Ao; no plan makes the part while one
// primitive holds both. A new primitive P' with atom ∩ P' = Ao (or Ai) splits it.
//
// The capabilities at hand make P' from the primitives that hold the atom: a deposit cut
// to the neighbourhood of Ai (what it should make), a removal to that of Ao (what it should
// take), grown by what the instrument needs to work there (a bead's width, a cutter's
// diameter, plus the tolerance). A restriction whose neighbourhood leaves some of the
// other part out splits the atom, the cheapest exact split first; a deposit is cut again
// to what builds layer by layer (planner/primitives/support.hpp), a removal keeps only voxels its
// whole-part primitive removes. Whole-part atoms of a code class often lie far apart (a
// pocket's corner and a voxel of the outer wall that no primitive tells apart), and then
// this separates them; where Ai and Ao touch, no restriction of these primitives does,
// and the atom is reported with the capabilities tried and why none split it.
//
// Rounds repeat while atoms still violate and some restriction splits one: the atoms are
// split in place (AtomDecomposition::add_primitive), not recomputed. Bounded: at most
// kMaxFineGrainingRounds rounds and kMaxFineGrainedPrimitives primitives in all, the
// largest violating atoms first; the count goes to the output.

#include <string>
#include <vector>

#include "config/machine.hpp"
#include "planner/atoms/atoms.hpp"
#include "planner/primitives/machine_primitives.hpp"

namespace hybridctl::planner {

inline constexpr int kMaxFineGrainingRounds = 3;
inline constexpr int kMaxFineGrainedPrimitives = 16;

// What fine-graining did, and for each atom still violating, what it tried.
struct FineGraining {
  int rounds = 0;  // rounds that added primitives
  int added = 0;   // primitives added (named and appended to the primitives)
  bool capped = false;  // stopped at kMaxFineGrainedPrimitives with atoms still violating
  struct Unsplit {
    int atom = -1;     // in the final decomposition
    std::string why;   // the capabilities tried and why none splits it, for people
  };
  std::vector<Unsplit> unsplit;
};

// Splits the violating atoms of `atoms` with restricted copies of `primitives` (whole-part,
// banded and repair ones; stocks and files are not restricted), appends what it adds to
// `primitives` (names P<n> on from the last) and to `atoms`, and re-measures `measures`.
// `present` is the stock every plan starts from, when one is given (deposits build on it).
FineGraining fine_grain(const config::Machine& machine, const Solid& design, double tolerance, double sliver_threshold,
                        const Solid* present, std::vector<Primitive>& primitives, AtomDecomposition& atoms,
                        std::vector<AtomMeasures>& measures);

}  // namespace hybridctl::planner
