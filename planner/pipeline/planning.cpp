#include "planner/pipeline/planning.hpp"

#include "plan/planning_band.hpp"
#include "planner/pipeline/rank.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <new>
#include <set>
#include <thread>

#include "common/error.hpp"
#include "common/number_text.hpp"
#include "geometry/vdb_file.hpp"
#include "geometry/voxelize.hpp"
#include "instruments/elements.hpp"
#include "planner/primitives/bands.hpp"
#include "planner/atoms/deposit_reach.hpp"
#include "planner/primitives/filled.hpp"
#include "planner/atoms/fine_graining.hpp"
#include "planner/pipeline/memory_estimate.hpp"
#include "planner/pipeline/search_phase.hpp"
#include "planner/pipeline/shop_words.hpp"
#include "planner/pipeline/unreached_corners.hpp"
#include "planner/primitives/repair.hpp"
#include "planner/search/steps.hpp"

namespace hybridctl::planner {
namespace {

using geometry::Box3;
using geometry::IndexBox;
using geometry::Lattice;
using geometry::Solid;

// What the voxelize step makes: the design on the planning grid.
struct PlanningGrid {
  Lattice lattice;
  IndexBox domain;
  Solid design;
  double design_volume = 0;        // mm^3, before clipping to the domain
  double bounding_box_volume = 0;  // mm^3
};

// What the atoms step makes.
struct Atoms {
  AtomDecomposition decomposition;
  std::vector<AtomMeasures> measures;
};

class PhaseClock {
 public:
  explicit PhaseClock(std::vector<std::pair<std::string, double>>& out) : out_(out) {}
  void lap(const std::string& phase) {
    const auto now = std::chrono::steady_clock::now();
    out_.emplace_back(phase, std::chrono::duration<double>(now - last_).count());
    last_ = now;
  }

 private:
  std::vector<std::pair<std::string, double>>& out_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

Solid load_primitive_file(const PrimitiveFile& f, const Lattice& lattice) {
  const std::string ext = std::filesystem::path(f.path).extension().string();
  if (ext == ".stl" || ext == ".STL") return geometry::voxelize(geometry::read_stl(f.path), lattice, f.path);
  if (ext == ".vdb") {
    Solid s = geometry::read_vdb(f.path);
    const double h = lattice.voxel_size;
    const auto& o = s.lattice().origin;
    if (std::abs(s.voxel_size() - h) > 1e-9 * h || std::abs(o.x) > 1e-6 * h || std::abs(o.y) > 1e-6 * h ||
        std::abs(o.z) > 1e-6 * h) {
      throw InputError(f.path + ": voxel size " + std::to_string(s.voxel_size()) + " mm, lattice origin (" +
                       std::to_string(o.x) + ", " + std::to_string(o.y) + ", " + std::to_string(o.z) +
                       "); expected voxel size " + std::to_string(h) + " mm with the origin at (0, 0, 0), as "
                       "`hybridctl voxelize --voxel " + std::to_string(h) + "` writes");
    }
    return copied_onto(s, lattice, s.bounding_box());
  }
  throw InputError(f.path + ": unknown primitive file type '" + ext + "', expected .stl or .vdb");
}

// The design on the planning lattice, clipped to the domain planning looks at.
PlanningGrid voxelize_design(const geometry::TriangleMesh& part, const std::string& part_name,
                             const config::Machine& machine, double h, double tolerance, const Progress& progress) {
  PlanningGrid g;
  g.lattice = {h, {0, 0, 0}};
  g.design = geometry::voxelize(part, g.lattice, part_name, geometry::VoxelizeMethod::ExactScan,
                                [&](double f) { progress("voxelize", f); });
  if (g.design.empty()) throw InputError(part_name + ": no voxel centre lies inside the part at " + std::to_string(h) +
                                         " mm; expected a smaller --voxel");
  g.design_volume = g.design.volume();
  const Box3 bb = g.design.bounding_box_mm();
  g.bounding_box_volume = (bb.max.x - bb.min.x) * (bb.max.y - bb.min.y) * (bb.max.z - bb.min.z);
  g.domain = planning_domain(machine, g.lattice, bb, tolerance);
  g.design = intersect(g.design, Solid::filled(g.lattice, g.domain));
  return g;
}

// The raw stocks given as files (else the machine's), the machine's primitives (deposits cut
// to what builds on the one stock given), the banded ones, then primitives given as files.
std::vector<Primitive> all_primitives(const config::Machine& machine, const PlanningOptions& options,
                                      const Progress& progress, const PlanningResult& r) {
  std::vector<Primitive> primitives;
  config::Machine without_stocks;
  std::vector<Primitive> stocks;
  for (const std::string& file : options.stock_files) {
    Primitive p;
    p.kind = PrimitiveKind::RawStock;
    p.mode = Mode::Additive;
    p.capability = file;
    p.from_file = true;
    p.label = "raw stock from " + file;
    p.region = intersect(load_primitive_file({file, Mode::Additive, 0}, r.lattice), Solid::filled(r.lattice, r.domain));
    if (p.region.empty())
      throw InputError(file + ": the stock has no voxel inside the planning domain around the part; expected a stock "
                       "placed in the part's frame, over the part");
    stocks.push_back(std::move(p));
  }
  if (!stocks.empty()) {
    // The stocks given replace the machine file's: the shop says what it starts from.
    without_stocks = machine;
    without_stocks.raw_stocks.clear();
  }
  const config::Machine& offering = stocks.empty() ? machine : without_stocks;
  // One stock given: every plan starts on it, and deposits may build on it.
  const Solid* present = stocks.size() == 1 ? &stocks.front().region : nullptr;
  primitives = machine_primitives(
      offering, r.design, r.domain,
      [&](std::size_t done, std::size_t total, const std::string&) {
        progress("primitives", total ? double(done) / double(total) : 1.0);
      },
      present);
  primitives.insert(primitives.begin(), std::make_move_iterator(stocks.begin()), std::make_move_iterator(stocks.end()));
  for (std::size_t i = 0; i < primitives.size(); ++i) primitives[i].name = primitive_name(i);
  // In the objective's units before the bands weigh milling against depositing.
  for (Primitive& p : primitives) p.cost_per_mm3 = objective_per_mm3(machine, r.objective, p);
  // From the whole-part O-AMs (not the bands'); numbered after the bands.
  std::vector<Primitive> filled;
  if (options.filled) filled = filled_primitives(machine, r.design, r.domain, primitives);
  if (options.bands) {
    for (Primitive& p : banded_primitives(machine, r.design, r.band, r.domain, primitives))
      primitives.push_back(std::move(p));
  }
  for (Primitive& p : filled) {
    p.name = primitive_name(primitives.size());
    primitives.push_back(std::move(p));
  }
  if (stocks.size() == 1) {
    // A repair: deposits near what the stock lacks, milled back where the head reaches.
    for (Primitive& p : repair_primitives(machine, r.design, primitives.front().region, r.band, r.domain, primitives)) {
      p.name = primitive_name(primitives.size());
      primitives.push_back(std::move(p));
    }
  }
  const std::vector<PrimitiveFile>& files = options.extra_primitives;
  for (const PrimitiveFile& f : files) {
    Primitive p;
    p.kind = PrimitiveKind::File;
    p.mode = f.mode;
    p.capability = f.path;
    p.cost_per_mm3 = f.cost_per_mm3;
    p.label = std::string(f.mode == Mode::Additive ? "additive" : "subtractive") + " primitive from " + f.path;
    p.region = load_primitive_file(f, r.lattice);
    p.name = primitive_name(primitives.size());
    primitives.push_back(std::move(p));
  }
  if (primitives.empty()) throw InputError("the machine offers no primitives: expected heads, tools or stocks");
  return primitives;
}

// The atoms of the primitives' regions, measured and classed against the design.
Atoms decompose_into_atoms(const Progress& progress, const PlanningResult& r) {
  Atoms out{AtomDecomposition(r.lattice, r.domain), {}};
  for (std::size_t i = 0; i < r.primitives.size(); ++i) {
    out.decomposition.add_primitive(r.primitives[i].region);
    progress("atoms", double(i + 1) / double(r.primitives.size()));
  }
  out.measures = measure_atoms(out.decomposition, r.design, make_tolerance_zone(r.design, r.band), r.sliver_threshold);
  return out;
}

// The head of a machine's U-AM or O-AM primitive; null for any other primitive.
const config::AdditiveHead* deposition_head(const config::Machine& machine, const Primitive& prim) {
  if (prim.kind != PrimitiveKind::UAm && prim.kind != PrimitiveKind::OAm) return nullptr;
  return machine.find_head(prim.capability);
}

// Per head and setup, which present atoms keep the head from an atom: over it in its
// column, or in the nozzle's way (deposit_reach.hpp); setups that share an approach share
// the relation.
std::shared_ptr<const AtomRelation> reach_limits(const PlanningResult& r, const config::Machine& machine,
                                                const Primitive& prim,
                                                std::map<std::pair<int, int>, std::shared_ptr<const AtomRelation>>& cache) {
  const config::AdditiveHead* head = deposition_head(machine, prim);
  const config::Setup* setup = head ? machine.find_setup(prim.setup) : nullptr;
  if (!setup) return nullptr;
  const geometry::AxisDirection approach = instruments::approach_direction(setup->approach);
  const int gap = deposit_reach_gap(head->layer_height, r.lattice.voxel_size);
  auto& slot = cache[{int(approach.axis) * 2 + (approach.sign > 0), gap * 1000 + int(head - machine.heads.data())}];
  if (slot) return slot;
  std::vector<AtomSet> blocked = atoms_above(r.atoms, approach, gap);
  if (head->nozzle) {
    const double h = r.lattice.voxel_size;
    const NozzleReach nozzle{head->nozzle->diameter / 2 / h, int(std::ceil(head->nozzle->standoff / h - 1e-9)),
                             int(std::floor(head->nozzle->length / h + 1e-9))};
    const std::vector<AtomSet> touched = atoms_in_nozzle_reach(r.atoms, approach, nozzle);
    for (std::size_t a = 0; a < blocked.size(); ++a) {
      if (touched[a].words().empty()) continue;
      if (blocked[a].words().empty()) {
        blocked[a] = touched[a];
        continue;
      }
      for (std::size_t w = 0; w < blocked[a].words().size(); ++w) blocked[a].words()[w] |= touched[a].words()[w];
    }
  }
  slot = std::make_shared<const AtomRelation>(std::move(blocked));
  return slot;
}

// What must carry the first layer of a head's primitive when the plan does not start with
// it (deposit_reach.hpp). Only must-in atoms are held to it: a free atom's first layer with
// nothing under it is left out by the toolpath, and the part may still be within
// tolerance; a must-in atom's cannot be, and everything built on it goes with it.
std::shared_ptr<const DepositFooting> first_layer_carriers(const PlanningResult& r, const config::Machine& machine,
                                                           const Primitive& prim, const std::vector<AtomSpec>& atoms) {
  const config::AdditiveHead* head = deposition_head(machine, prim);
  const config::Setup* setup = head ? machine.find_setup(prim.setup) : nullptr;
  if (!setup) return nullptr;
  // A bead's width, the cone over two layers and a voxel of slack, generously.
  const int reach = int(std::ceil(head->bead.width / r.lattice.voxel_size)) + 2;
  DepositFooting footing = deposit_footing(r.atoms, prim.region, instruments::approach_direction(setup->approach), reach);
  for (std::size_t a = 0; a < atoms.size(); ++a)
    if (!atoms[a].must_in && footing.kind[a] == DepositFooting::NeedsCarrier) footing.kind[a] = DepositFooting::None;
  return std::make_shared<const DepositFooting>(std::move(footing));
}

// The symbolic problem the search runs on: atoms with volumes and classes, primitives as
// sets of atoms, deposits with what the plan's state may rule out.
PlanningProblem symbolic_problem(const PlanningResult& r, const config::Machine& machine, int max_uses) {
  std::map<std::pair<int, int>, std::shared_ptr<const AtomRelation>> reach_cache;
  PlanningProblem p;
  // Cost factors are normalised so that parts compare; minutes and money are read as such.
  const bool factors = r.objective == config::Objective::CostFactor;
  p.normaliser = factors && r.bounding_box_volume > 0 ? r.bounding_box_volume : 1.0;
  p.max_uses = max_uses;
  p.fixed = objective_fixed_costs(machine, r.objective);
  for (const AtomMeasures& m : r.measures) {
    AtomSpec a;
    a.volume = m.volume;
    a.must_in = m.atom_class == AtomClass::MustIn || m.atom_class == AtomClass::Violating;
    a.must_out = m.atom_class == AtomClass::MustOut || m.atom_class == AtomClass::Violating;
    p.atoms.push_back(a);
  }
  for (std::size_t i = 0; i < r.primitives.size(); ++i) {
    const Primitive& prim = r.primitives[i];
    PrimitiveSpec s;
    s.name = prim.name;
    s.mode = prim.mode;
    s.raw_stock = prim.kind == PrimitiveKind::RawStock;
    s.cost_per_mm3 = prim.cost_per_mm3;
    s.tool = prim.capability;
    s.setup = prim.setup;
    s.refixture = refixture_setup(machine, prim);
    s.blocked_by = reach_limits(r, machine, prim, reach_cache);
    s.footing = first_layer_carriers(r, machine, prim, p.atoms);
    s.atoms = AtomSet(r.atoms.atom_count());
    for (int a = 0; a < r.atoms.atom_count(); ++a)
      if (r.atoms.code(a).test(int(i))) s.atoms.set(a);
    p.primitives.push_back(std::move(s));
  }
  return p;
}

}  // namespace

PlanningResult plan_part(const geometry::TriangleMesh& part, const std::string& part_name,
                         const config::Machine& machine, const PlanningOptions& options) {
  PlanningResult r;
  PhaseClock clock(r.timings);
  const Progress progress = [&](const std::string& phase, double f) {
    if (options.progress) options.progress(phase, f);
  };
  const config::Planning& defaults = machine.planning;
  const double h = options.voxel_size > 0 ? options.voxel_size : defaults.voxel_size;
  r.tolerance = options.tolerance >= 0 ? options.tolerance : defaults.tolerance;
  r.band = plan::planning_band(r.tolerance, h);
  r.design_mesh = part;
  r.sliver_threshold = options.sliver_threshold >= 0 ? options.sliver_threshold : defaults.sliver_threshold;
  const int top_k = options.top_k > 0 ? options.top_k : defaults.top_k;
  r.objective = options.objective.value_or(defaults.objective);
  r.currency = machine.costs.currency;

  // Before anything large is allocated: a grid over the budget is an input error.
  check_planning_memory(geometry::bounds(part), machine, h, r.band, options.memory_budget, part_name);
  PlanningGrid grid = voxelize_design(part, part_name, machine, h, r.band, progress);
  r.lattice = grid.lattice;
  r.domain = grid.domain;
  r.design = std::move(grid.design);
  r.design_volume = grid.design_volume;
  r.bounding_box_volume = grid.bounding_box_volume;
  clock.lap("voxelize");
  r.primitives = all_primitives(machine, options, progress, r);
  clock.lap("primitives");
  Atoms atoms = decompose_into_atoms(progress, r);
  r.atoms = std::move(atoms.decomposition);
  r.measures = std::move(atoms.measures);
  clock.lap("atoms");
  if (options.fine_graining) {
    const Solid* present = options.stock_files.size() == 1 ? &r.primitives.front().region : nullptr;
    r.fine_graining = fine_grain(machine, r.design, r.band, r.sliver_threshold, present, r.primitives, r.atoms, r.measures);
    clock.lap("fine-graining");
  }
  r.problem = symbolic_problem(r, machine, options.max_uses);
  r.problem.start_from_stock = !options.stock_files.empty();
  r.verdict = check_manufacturability(r.problem, r.measures, r.lattice);
  r.faces = make_face_rule(machine, r.primitives, r.problem, r.atoms, r.measures, r.tolerance);
  for (ViolatingAtom& v : r.verdict.violations)
    for (const FineGraining::Unsplit& u : r.fine_graining.unsplit)
      if (u.atom == v.atom) v.description += "; " + u.why;
  clock.lap("check");
  double validation_seconds = 0;
  if (r.verdict.manufacturable() && r.verdict.modality == Modality::Hybrid) {
    // Cheap where it works (the B-axis overhang: milliseconds) and bounded where it does
    // not; the search cannot prove a hybrid problem infeasible short of exhausting it.
    r.core_proof = prove_by_core(r.problem);
    if (r.core_proof.outcome == CoreProof::Outcome::Proven) r.verdict = core_verdict(r.problem, r.core_proof, r.measures, r.lattice);
    else r.stock_starts = prove_stock_starts(r.problem, quick_proof_limits());
    clock.lap("proof");
  }
  // After the proofs, which say more of what they find (a closed space, an overhang), and
  // before the search, which cannot see what lies within a voxel.
  if (const WallsAsDeposited walls = walls_as_deposited(machine, r.tolerance);
      r.verdict.manufacturable() && options.corners && !walls.within) {
    r.unreached_corners = corners_no_instrument_makes(r, walls, options.corners);
    if (!r.unreached_corners.empty()) r.verdict = corner_refusal(r.unreached_corners, walls, r.tolerance);
    clock.lap("corners");
  }
  if (r.verdict.manufacturable()) search_phase(top_k, options, progress, r, validation_seconds);
  settle_outcome(r);
  r.in_shop_words = refusal_in_shop_words(machine, r);
  clock.lap("search");
  if (r.validated) {
    // The search's lap holds the validation it called: report them apart.
    r.timings.back().second = std::max(0.0, r.timings.back().second - validation_seconds);
    r.timings.emplace_back("validate", validation_seconds);
  }
  for (const Plan& plan : r.plans) {
    r.deviations.push_back(plan::measure_deviation(plan_outcome(r, plan), r.design, r.domain, r.band));
    r.estimates.push_back(estimate_plan(machine, r.primitives, plan));
    if (options.toolpath_minutes) r.toolpath_minutes.push_back(options.toolpath_minutes(plan));
    r.cycle_times.push_back(options.cycle_time ? options.cycle_time(plan) : std::nullopt);
    r.exact_deviations.push_back(options.exact_deviation ? options.exact_deviation(plan) : std::nullopt);
  }
  rank_by_toolpaths(machine, r);
  clock.lap("deviation");
  return r;
}

Solid plan_outcome(const PlanningResult& r, const Plan& plan) {
  std::vector<bool> selected(static_cast<std::size_t>(r.atoms.atom_count()));
  for (int a = 0; a < r.atoms.atom_count(); ++a) selected[std::size_t(a)] = plan.final_state.test(a);
  return r.atoms.union_of(selected);
}

AtomSet step_region(const PlanningResult& r, const Plan& plan, std::size_t step) {
  AtomSet roi(r.atoms.atom_count());
  PlanReplay replay = replay_plan(r.problem, plan, step + 1);
  if (step < replay.changed.size()) roi.words() = std::move(replay.changed[step]);
  return roi;
}

}  // namespace hybridctl::planner
