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

#include <functional>
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

// Many removal regions at once: SM-max (`maximal`) or SM-cons of each instrument. Equal,
// voxel for voxel, to calling subtractive_maximal / subtractive_conservative one by one
// (the definitions above). Cutters with their shank and holder are tool sweeps
// (geometry::tool_sweeps): tools along one axis share one distance transform across it
// and each is then a few operations on heightmaps. `done(i)` reports region i.
struct RemovalRequest {
  const Instrument* instrument = nullptr;
  bool maximal = true;
};
std::vector<geometry::Solid> removal_regions(const geometry::Solid& design, const std::vector<RemovalRequest>& requests,
                                             const geometry::IndexBox& domain,
                                             const std::function<void(std::size_t)>& done = {});

}  // namespace hybridctl::planner
