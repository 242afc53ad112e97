#pragma once
// Banded primitives: the part of a capability's primitive on one side of a level across
// its setup's approach axis (docs/bands.md). A whole-part U-AM or O-AM deposits all of
// the design it holds, and SM-max only ever spares the design, so "mill the stock up to
// here, deposit from here on" is not in the search space without them: the best plan of
// a block with a closed channel deposited the whole block.
//
//   AM band     P = AM ∩ beyond(level)       deposit only past the level, on what is there
//   SM band     P = SM-max ∪ beyond(level)   face everything past the level away, and below
//                                            it remove what SM-max removes
//
// "Beyond" is along the setup's approach (the build direction of its deposits). Facing
// everything past a plane from the approach side is open to a flat cutter, and the
// removal SM-max allows is only easier to reach with that material gone; a band of a
// self-supporting deposit is self-supporting on a state that holds the layer under it,
// which the search's first-layer footing asks of every later deposit.
//
// Levels are guided, not a grid (band_levels): the floors of cavities no tool can open
// (along the approach, when the setup's heads can build around them), and the layers where
// the design's section shrinks to half or less (a plate's top under a boss or ribs) when
// depositing past them costs less than milling the air there. At most kMaxBandLevels in
// all, cavity floors first: each level adds primitives and atoms to the search.

#include <string>
#include <vector>

#include "config/machine.hpp"
#include "geometry/morphology.hpp"
#include "geometry/solid.hpp"
#include "planner/primitives/machine_primitives.hpp"

namespace hybridctl::planner {

inline constexpr int kMaxBandLevels = 2;

// A level across an approach axis: the plane between voxel layers `plane - 1` and `plane`
// of that axis. Beyond it along `build` are the layers >= plane (build.sign > 0) or
// < plane (build.sign < 0).
struct BandLevel {
  geometry::AxisDirection build;
  int plane = 0;
  std::string why;  // "cavity floor", "section shrinks"
  friend bool operator==(const BandLevel&, const BandLevel&) = default;
};

// The candidate levels along `build`, best first, at most kMaxBandLevels: `enclosed` is
// the air every outcome must leave and no removal primitive reaches; `additive` the
// machine's whole-part additive primitives along `build` (a cavity's level counts when one
// of them holds all the design that wraps the cavity beyond it).
std::vector<BandLevel> band_levels(const geometry::Solid& design, const geometry::Solid& enclosed,
                                   geometry::AxisDirection build, const std::vector<const geometry::Solid*>& additive);

// The voxels of `domain` beyond `level`.
geometry::Solid beyond(const geometry::Lattice& lattice, const geometry::IndexBox& domain, const BandLevel& level);

// The most banded primitives banded_primitives may add for `machine`, whatever the part: for
// the memory check before anything is computed.
std::size_t max_banded_primitive_count(const config::Machine& machine);

// The banded primitives of `machine` for `primitives` (its whole-part ones, as
// machine_primitives returns them): the best kMaxBandLevels levels over every approach,
// and per level and setup with that approach every head's AM kinds and the cheapest SM-max
// tool's band (a flat one first). Named on from the last of `primitives`.
std::vector<Primitive> banded_primitives(const config::Machine& machine, const geometry::Solid& design, double tolerance,
                                         const geometry::IndexBox& domain, const std::vector<Primitive>& primitives);

}  // namespace hybridctl::planner
