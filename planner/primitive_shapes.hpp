#pragma once
// The shapes of manufacturing primitives for one instrument at one fixed setup, by
// morphology (paper section 5; ../shared/ARCHITECTURE.md "The planning core"). The
// instrument is its minimum manufacturable neighbourhood B (bead, cutting edge) and its
// non-cutting body C (nozzle, shank, holder); D = B u C. Here A (-) E is the Minkowski
// difference {p : p - E inside A}, i.e. geometry::erode(A, -E), so S (-) -D is where the
// whole instrument fits inside S.
//
//   U-AM    P = (S (-) -D) (+) B          the most that can be deposited inside S
//   O-AM    P = (S (-) -C) (+) B          conservative overfill; S (+) B when C is empty
//   SM-max  P = domain - ((S (+) -D) (-) B)   the most that can be removed, never cutting S
//   SM-cons P = domain - ((S (+) -C) (-) B)   conservative over-cut; domain - (S (-) B)

#include <vector>

#include "geometry/morphology.hpp"
#include "geometry/solid.hpp"

namespace hybridctl::planner {

struct Instrument {
  std::vector<geometry::StructuringElement> cutting;  // B, as a union of elements
  std::vector<geometry::StructuringElement> body;     // C, as a union; may be empty
};

geometry::Solid additive_maximal(const geometry::Solid& design, const Instrument& instrument);
geometry::Solid additive_conservative(const geometry::Solid& design, const Instrument& instrument);
// Subtractive primitives are regions of removal, clipped to the planning `domain`.
geometry::Solid subtractive_maximal(const geometry::Solid& design, const Instrument& instrument,
                                    const geometry::IndexBox& domain);
geometry::Solid subtractive_conservative(const geometry::Solid& design, const Instrument& instrument,
                                         const geometry::IndexBox& domain);

}  // namespace hybridctl::planner
