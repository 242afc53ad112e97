#pragma once
// Material simulation: replays moves into a voxel stock and reports what happened.
//
// A cutter removes every voxel its cutting part sweeps (sim/sweep.hpp: exact at voxel
// resolution); its body (shank, holder) must touch no material. A bead adds every voxel
// it sweeps while the process is on. Programmed points: the cutter's tip, the bead's
// bottom (sim/instrument.hpp). docs/simulation.md describes conventions and incidents.
//
//   sim::MaterialSimulation sim(stock, design_grown_by_tolerance);
//   sim.cut(sim::cutter_of(tool), {sim::Motion::Linear, {0, 0, 5}, {20, 0, 5}, {}, false, 42});
//   if (!sim.report().clean()) ... sim.report().incidents ...

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "geometry/solid.hpp"
#include "sim/instrument.hpp"
#include "sim/moves.hpp"

namespace hybridctl::sim {

struct SimulationOptions {
  // Largest distance (mm) between an arc and the chords it is simulated with; 0 means the
  // finer of a tenth of the voxel size and kDefaultArcTolerance.
  double arc_tolerance = 0;
  // The toolpaths' own chord tolerance (toolpaths/arc_fit.hpp, wall finishing's round
  // joins): an arc fitted to a finishing pass is simulated as closely as the G1 chords it
  // replaces, so fitting arcs changes no voxel the pass takes.
  static constexpr double kDefaultArcTolerance = 0.001;
};

enum class IncidentKind {
  RapidIntoMaterial,        // a rapid touched material (cutter or body; bead or nozzle)
  BodyCollision,            // a feed move touched material with the non-cutting body
  Gouge,                    // a move removed voxels of the protected solid
  UnsupportedDeposition,    // bead voxels laid over air beyond the head's cone or bridge: they fell, not added
  DepositionOutsideDomain,  // a bead reached beyond the simulated domain: that part is lost
};
std::string_view to_string(IncidentKind kind);

struct Incident {
  IncidentKind kind = IncidentKind::RapidIntoMaterial;
  int line = 0;           // the move's line
  Vec3 from, to;          // the move's programmed points
  double volume = 0;      // mm^3 of the offending voxels
  std::int64_t voxels = 0;
  geometry::Box3 region;  // mm extent of the offending voxels
};
// One line of text, e.g. "line 12: rapid into material: 3.5 mm^3 in x [1, 2] y [...] z [...]".
std::string describe(const Incident& incident);

// What one move did, mm^3.
struct MoveReport {
  double removed = 0;        // material removed
  double gouge = 0;          // of which inside the protected solid
  double deposited = 0;      // material added (voxels that were empty)
  double overlap = 0;        // bead voxels that were already material
  double outside = 0;        // bead voxels beyond the domain (lost)
  double collision = 0;      // material touched by the body during a feed move
  double rapid_contact = 0;  // material touched during a rapid
  std::vector<Incident> incidents;
};

// Totals over all moves so far, mm^3, and every incident in move order.
struct SimulationReport {
  std::int64_t moves = 0;
  double removed = 0, gouge = 0, deposited = 0, overlap = 0, outside = 0, collision = 0, rapid_contact = 0;
  std::vector<Incident> incidents;
  bool clean() const { return incidents.empty(); }
};

class MaterialSimulation {
 public:
  // `stock`: the material at the start. Its storage box is the simulated domain: nothing
  // exists beyond it, deposition beyond it is lost (and reported), and its lowest voxel
  // layer stands on the build plate; an empty stock stands for a plate whose top is where
  // the first bead is laid. `protected_region`: voxels that must not be removed
  // (e.g. the design shrunk by its tolerance), on the stock's lattice (std::invalid_argument
  // otherwise).
  explicit MaterialSimulation(geometry::Solid stock, std::optional<geometry::Solid> protected_region = std::nullopt,
                              SimulationOptions options = {});

  // Moves the cutter: removes what its cutting part sweeps, checks its body. A rapid
  // also cuts (the spindle turns) and reports all material the cutter or body touched.
  MoveReport cut(const Cutter& cutter, const MaterialMove& move);
  // Moves the head: with the process on, adds what the bead sweeps where the head's layer
  // rule holds it (on the plate under the domain, on material under the bead within its
  // overhang cone, or bridged; docs/simulation.md); what lies over air beyond that falls
  // and is reported (UnsupportedDeposition). Otherwise a rapid reports the material its bead
  // or body would touch, a feed move what its body (the nozzle) touches.
  MoveReport deposit(const Bead& bead, const MaterialMove& move);

  const geometry::Solid& stock() const { return stock_; }
  const std::optional<geometry::Solid>& protected_region() const { return protected_; }
  // The voxels cuts must spare from the next move on (same rules as the constructor's):
  // what a plan protects changes from action to action (plan/start_stock.hpp).
  void set_protected_region(std::optional<geometry::Solid> protected_region);
  const SimulationReport& report() const { return report_; }
  const SimulationOptions& options() const { return options_; }

 private:
  double chord_tolerance() const;
  void finish(const MaterialMove& move, MoveReport& out);

  geometry::Solid stock_;
  std::optional<geometry::Solid> protected_;
  SimulationOptions options_;
  geometry::IndexBox domain_;
  SimulationReport report_;
  // The build plate lies under this layer: the domain's lowest, or, on a stock that was
  // empty, the first bead's lowest layer (docs/support.md, "In the simulator").
  int plate_ = 0;
  bool empty_ = true;  // no material in the stock yet
  // A box holding all material of the stock: deposits grow it, and a cut that empties a
  // face layer moves that face in (shrink_material_box). Sweeps tested against material
  // are clipped to it: most of a holder sweeps air, and a tool working down level by
  // level sweeps its shank and holder through the air above the material.
  geometry::IndexBox material_box_;
  // After a cut that removed voxels within `removed`: each face of the box in it moves in
  // while its layer holds no material.
  void shrink_material_box(const geometry::IndexBox& removed);
  // Reused scratch words for one move's swept voxels (instrument, body).
  std::vector<std::uint64_t> scratch_[2];
};

}  // namespace hybridctl::sim
