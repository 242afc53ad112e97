// The program executor's protected region on a part turned over (the bottom setup, G55):
// a cut into the design shrunk by the tolerance is a gouge where it happened in the part
// frame, a cut that stays out of it is none, and the region spared can change between
// lines (validation spares per action what that action keeps of the design).

#include "sim/executor.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "config/machine_loader.hpp"
#include "geometry/morphology.hpp"
#include "geometry/shapes.hpp"

namespace hybridctl::sim {
namespace {

using geometry::Box3;
using geometry::Solid;

const config::Machine& machine() {
  static const config::Machine m = config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml");
  return m;
}

const geometry::Lattice kLattice{0.5, {0, 0, 0}};
// A 30 x 20 x 10 block 2 mm above the part origin, in a world with room around it.
const Box3 kBlock{{5, 5, 2}, {35, 25, 12}};

Solid world_with_block() {
  Solid world(kLattice, {{-40, -40, -40}, {120, 100, 60}});
  return unite(world, geometry::make_box(kLattice, kBlock));
}

Solid core_of(const Solid& design) { return geometry::erode(design, geometry::Ball{0.5}); }

// The 10 mm flat from below (G55: work (x, -y, -z)) across the block at part y 10..20 with
// its tip at part height `tip_z`; `between` runs once the tool stands beside the block.
SimulationReport cut_from_below(double tip_z, std::optional<Solid> spared,
                                const std::function<void(ProgramExecutor&)>& between = {}) {
  ExecutorOptions o;
  o.stock = world_with_block();
  o.protected_region = std::move(spared);
  ProgramExecutor ex(machine(), "below.ngc", o);
  const std::string z = std::to_string(-tip_z);
  std::vector<std::string> lines = {"G21 G90 G17", "G55", "T1 M6", "S8000 M3", "G0 X-10 Y-15 Z10", "G0 Z" + z};
  int n = 0;
  for (const auto& l : lines) EXPECT_EQ(ex.execute_line(l, ++n).stop, Stop::None) << l;
  if (between) between(ex);
  for (const std::string l : {"G1 X50 F1200", "G0 Z10", "M5"}) EXPECT_EQ(ex.execute_line(l, ++n).stop, Stop::None) << l;
  return ex.report();
}

const Incident* first_gouge(const SimulationReport& r) {
  for (const Incident& i : r.incidents)
    if (i.kind == IncidentKind::Gouge) return &i;
  return nullptr;
}

TEST(ProgramExecutor, ACutFromBelowIntoTheCoreIsAGougeAndOneShortOfItIsNone) {
  const Solid design = geometry::make_box(kLattice, kBlock);
  // Tip at part z 4: 1.5 mm into the core (z 2.5 .. 11.5) over x 5.5 .. 34.5, y 10 .. 20.
  const SimulationReport into = cut_from_below(4, core_of(design));
  const Incident* g = first_gouge(into);
  ASSERT_NE(g, nullptr);
  EXPECT_NEAR(into.gouge, 29 * 10 * 1.5, 0.1 * 29 * 10 * 1.5);
  // The region is in the work frame: part z 2.5 .. 4 is work z -4 .. -2.5.
  EXPECT_NEAR(g->region.min.z, -4, 0.5);
  EXPECT_NEAR(g->region.max.z, -2.5, 0.5);
  // Tip at part z 2.25: the design's lowest voxel layer goes, the core stays.
  const SimulationReport skin = cut_from_below(2.25, core_of(design));
  EXPECT_GT(skin.removed, 0);
  EXPECT_EQ(first_gouge(skin), nullptr);
  EXPECT_EQ(skin.gouge, 0);
}

TEST(ProgramExecutor, TheRegionSparedCanChangeBetweenLines) {
  const Solid design = geometry::make_box(kLattice, kBlock);
  const Solid step = geometry::make_box(kLattice, {{0, 5, 0}, {40, 25, 4.5}});  // what the cut may take
  const SimulationReport r = cut_from_below(4, core_of(design), [&](ProgramExecutor& ex) {
    ex.set_protected_region(core_of(subtract(design, step)));
  });
  EXPECT_GT(r.removed, 0);
  EXPECT_EQ(first_gouge(r), nullptr);
  EXPECT_EQ(r.gouge, 0);
}

}  // namespace
}  // namespace hybridctl::sim
