#include "planner/planning.hpp"
#include "planner/toolpath_rank.hpp"

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
#include "planner/bands.hpp"
#include "planner/deposit_reach.hpp"
#include "planner/filled_deposits.hpp"
#include "planner/fine_graining.hpp"
#include "planner/memory_estimate.hpp"
#include "planner/repair_primitives.hpp"
#include "planner/search_steps.hpp"

namespace hybridctl::planner {
namespace {

using geometry::Box3;
using geometry::IndexBox;
using geometry::Lattice;
using geometry::Solid;

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
    Solid on_lattice(lattice, s.bounding_box());
    s.for_each_voxel([&](geometry::Index3 v) { on_lattice.set(v); });
    return on_lattice;
  }
  throw InputError(f.path + ": unknown primitive file type '" + ext + "', expected .stl or .vdb");
}

using Progress = std::function<void(const std::string& phase, double fraction)>;

// The design on the planning lattice, clipped to the domain planning looks at.
void voxelize_design(const geometry::TriangleMesh& part, const std::string& part_name, const config::Machine& machine,
                     double h, const Progress& progress, PlanningResult& r) {
  r.lattice = {h, {0, 0, 0}};
  r.design = geometry::voxelize(part, r.lattice, part_name, geometry::VoxelizeMethod::ExactScan,
                                [&](double f) { progress("voxelize", f); });
  if (r.design.empty()) throw InputError(part_name + ": no voxel centre lies inside the part at " + std::to_string(h) +
                                         " mm; expected a smaller --voxel");
  r.design_volume = r.design.volume();
  const Box3 bb = r.design.bounding_box_mm();
  r.bounding_box_volume = (bb.max.x - bb.min.x) * (bb.max.y - bb.min.y) * (bb.max.z - bb.min.z);
  r.domain = planning_domain(machine, r.lattice, bb, r.tolerance);
  r.design = intersect(r.design, Solid::filled(r.lattice, r.domain));
}

// The raw stocks given as files (else the machine's), the machine's primitives (deposits cut
// to what builds on the one stock given), the banded ones, then primitives given as files.
void add_primitives(const config::Machine& machine, const PlanningOptions& options, const Progress& progress,
                    PlanningResult& r) {
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
  r.primitives = machine_primitives(
      offering, r.design, r.domain,
      [&](std::size_t done, std::size_t total, const std::string&) {
        progress("primitives", total ? double(done) / double(total) : 1.0);
      },
      present);
  r.primitives.insert(r.primitives.begin(), std::make_move_iterator(stocks.begin()), std::make_move_iterator(stocks.end()));
  for (std::size_t i = 0; i < r.primitives.size(); ++i) r.primitives[i].name = "P" + std::to_string(i + 1);
  // In the objective's units before the bands weigh milling against depositing.
  for (Primitive& p : r.primitives) p.cost_per_mm3 = objective_per_mm3(machine, r.objective, p);
  // From the whole-part O-AMs (not the bands'); numbered after the bands.
  std::vector<Primitive> filled;
  if (options.filled) filled = filled_primitives(machine, r.design, r.domain, r.primitives);
  if (options.bands) {
    for (Primitive& p : banded_primitives(machine, r.design, r.tolerance, r.domain, r.primitives))
      r.primitives.push_back(std::move(p));
  }
  for (Primitive& p : filled) {
    p.name = "P" + std::to_string(r.primitives.size() + 1);
    r.primitives.push_back(std::move(p));
  }
  if (stocks.size() == 1) {
    // A repair: deposits near what the stock lacks, milled back where the head reaches.
    for (Primitive& p : repair_primitives(machine, r.design, r.primitives.front().region, r.tolerance, r.domain, r.primitives)) {
      p.name = "P" + std::to_string(r.primitives.size() + 1);
      r.primitives.push_back(std::move(p));
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
    p.name = "P" + std::to_string(r.primitives.size() + 1);
    r.primitives.push_back(std::move(p));
  }
  if (r.primitives.empty()) throw InputError("the machine offers no primitives: expected heads, tools or stocks");
}

void decompose_into_atoms(const Progress& progress, PlanningResult& r) {
  r.atoms = AtomDecomposition(r.lattice, r.domain);
  for (std::size_t i = 0; i < r.primitives.size(); ++i) {
    r.atoms.add_primitive(r.primitives[i].region);
    progress("atoms", double(i + 1) / double(r.primitives.size()));
  }
  r.measures = measure_atoms(r.atoms, r.design, make_tolerance_zone(r.design, r.tolerance), r.sliver_threshold);
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

// What the rejections of one search taught, before the next search takes it in.
struct Learning {
  std::vector<Shortfall> pending;  // not yet taken out of the problem's primitives
  // Candidates proven by execution: a search started again finds them again, and
  // execution would only repeat itself.
  std::set<std::vector<int>> proven;
};

std::vector<int> primitives_of(const Plan& plan) {
  std::vector<int> sequence;
  for (const PlanStep& s : plan.steps) sequence.push_back(s.primitive);
  return sequence;
}

// The search's accept hook from PlanningOptions::validate: rejected plans are kept with
// their reasons (once each, as a weighted search may find them again), their shortfalls
// wait in `learning` for the next round, and the time the validation takes is counted
// apart from the search's.
std::function<bool(const Plan&)> accept_hook(const PlanningOptions& options, PlanningResult& r, double& seconds,
                                             Learning& learning) {
  if (!options.validate) return {};
  return [&options, &r, &seconds, &learning](const Plan& plan) {
    const std::vector<int> sequence = primitives_of(plan);
    if (learning.proven.count(sequence)) return true;
    const auto same_actions = [&sequence](const RejectedPlan& known) { return primitives_of(known.plan) == sequence; };
    if (std::any_of(r.rejected.begin(), r.rejected.end(), same_actions)) return false;
    const auto start = std::chrono::steady_clock::now();
    CandidateCheck check = options.validate(r, plan);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (check.reasons.empty()) {
      learning.proven.insert(sequence);
      return true;
    }
    for (const Shortfall& s : check.shortfalls) {
      const PrimitiveSpec& prim = r.problem.primitives[std::size_t(s.primitive)];
      const AtomSet& known = s.spill ? prim.atoms : prim.falls_short;
      const bool learned = !known.words().empty() && known.test(s.atom);
      if (!learned && std::find(learning.pending.begin(), learning.pending.end(), s) == learning.pending.end())
        learning.pending.push_back(s);
    }
    r.rejected.push_back({plan, std::move(check.reasons)});
    return false;
  };
}

// Plans that begin with the actions a rejected plan failed in, up to the failing action:
// execution depends only on the actions before (validation/prefix_cache.hpp), so they
// fail the same way, and the search passes over them without executing them. The design's
// core missing after the last deposit is such a failure only for a plan that, like the
// rejected one, only removes after that action.
std::function<bool(const Plan&)> known_failure_hook(const PlanningOptions& options, const PlanningResult& r) {
  if (!options.validate) return {};
  return [&r](const Plan& plan) {
    const auto only_removes_after = [&](std::size_t k) {
      return std::all_of(plan.steps.begin() + std::ptrdiff_t(k), plan.steps.end(), [&](const PlanStep& s) {
        return r.problem.primitives[std::size_t(s.primitive)].mode == Mode::Subtractive;
      });
    };
    for (const RejectedPlan& known : r.rejected)
      for (const plan::RejectionReason& reason : known.reasons) {
        const std::size_t k = std::size_t(reason.action);
        if (k == 0 || k > plan.steps.size() || k > known.plan.steps.size()) continue;
        if (reason.kind == "missing_material" && !only_removes_after(k)) continue;
        if (std::equal(plan.steps.begin(), plan.steps.begin() + std::ptrdiff_t(k), known.plan.steps.begin(),
                       [](const PlanStep& a, const PlanStep& b) { return a.primitive == b.primitive; }))
          return true;
      }
    return false;
  };
}

// What the nearest state the exploration reached lacks and holds beyond the design: its
// largest wrong atoms with where they are and what holds them.
std::string nearest_text(const PlanningResult& r, const Reachability& reach) {
  struct Wrong {
    int atom;
    double volume;
  };
  std::vector<Wrong> missing, extra;
  double missing_volume = 0, extra_volume = 0;
  for (std::size_t a = 0; a < r.problem.atoms.size(); ++a) {
    const AtomSpec& spec = r.problem.atoms[a];
    const bool present = reach.nearest.test(int(a));
    if (spec.must_in && !present) missing.push_back({int(a), spec.volume}), missing_volume += spec.volume;
    if (spec.must_out && present) extra.push_back({int(a), spec.volume}), extra_volume += spec.volume;
  }
  const auto largest = [&](std::vector<Wrong>& atoms) {
    const auto big = std::max_element(atoms.begin(), atoms.end(), [](const Wrong& a, const Wrong& b) { return a.volume < b.volume; });
    const AtomMeasures& m = r.measures[std::size_t(big->atom)];
    char where[96];
    std::snprintf(where, sizeof where, "%.3g mm\u00B3 around (%.1f, %.1f, %.1f) mm", m.volume, m.centroid.x, m.centroid.y,
                  m.centroid.z);
    std::string in;
    for (std::size_t i = 0; i < r.problem.primitives.size(); ++i)
      if (r.problem.primitives[i].atoms.test(big->atom)) in += (in.empty() ? "" : ", ") + r.problem.primitives[i].name;
    return std::string(where) + (in.empty() ? ", in no primitive" : ", in " + in);
  };
  std::string s = "lacks " + trimmed_number(missing_volume, 1) + " mm\u00B3 of design in " + std::to_string(missing.size()) +
                  " atoms";
  if (!missing.empty()) s += " (largest: " + largest(missing) + ")";
  s += " and holds " + trimmed_number(extra_volume, 1) + " mm\u00B3 outside it in " + std::to_string(extra.size()) + " atoms";
  if (!extra.empty()) s += " (largest: " + largest(extra) + ")";
  return s;
}

}  // namespace

namespace {

// "N primitives falling short of the model on M atoms (V mm³; largest ...)" for the
// shortfalls, or the spills, learned.
std::string learned_kind_text(const PlanningResult& r, bool spills) {
  std::set<int> primitives;
  double volume = 0;
  int atoms = 0;
  const Shortfall* largest = nullptr;
  for (const Shortfall& s : r.learned) {
    if (s.spill != spills) continue;
    primitives.insert(s.primitive);
    volume += s.volume;
    ++atoms;
    if (!largest || s.volume > largest->volume) largest = &s;
  }
  if (!largest) return {};
  const AtomMeasures& m = r.measures[std::size_t(largest->atom)];
  char where[96];
  std::snprintf(where, sizeof where, "%.3g mm\u00B3 around (%.1f, %.1f, %.1f) mm", m.volume, m.centroid.x, m.centroid.y,
                m.centroid.z);
  return std::to_string(primitives.size()) + " primitive" + (primitives.size() == 1 ? "" : "s") +
         (spills ? " spilling onto " : " falling short of the model on ") + std::to_string(atoms) + " atom" +
         (atoms == 1 ? "" : "s") + (spills ? " outside them" : "") + " (" + trimmed_number(volume, 1) +
         " mm\u00B3; largest " + where + ", by " + r.problem.primitives[std::size_t(largest->primitive)].name + ")";
}

}  // namespace

std::string learned_text(const PlanningResult& r) {
  if (r.learned.empty()) return {};
  const std::string short_of = learned_kind_text(r, false), spilled = learned_kind_text(r, true);
  const std::string how = short_of.empty() ? "added to them" : spilled.empty() ? "taken out of them" : "corrected";
  return "executed candidates showed " + short_of + (short_of.empty() || spilled.empty() ? "" : " and ") + spilled +
         ", " + how + " over " + std::to_string(r.search_rounds) + (r.search_rounds == 1 ? " search" : " searches") +
         (r.replay_rounds == 0 ? ""
          : " and " + std::to_string(r.replay_rounds) + " replay" + (r.replay_rounds == 1 ? "" : "s") + " of the proof");
}

namespace {

std::string unreachable_text(const PlanningResult& r, const Reachability& reach) {
  return "no sequence of these primitives makes the design: none of the " + std::to_string(reach.states) +
         " states they reach (costs aside, each primitive any number of times) is within tolerance. The nearest " +
         nearest_text(r, reach) +
         ". Deposits cannot reach under material already there, and removals cannot spare design they pass through";
}

// Takes what execution showed out of the problem's primitives.
void take_in(Learning& learning, PlanningResult& r) {
  for (const Shortfall& s : learning.pending) {
    PrimitiveSpec& prim = r.problem.primitives[std::size_t(s.primitive)];
    if (s.spill) {
      prim.atoms.set(s.atom);  // it deposits there too, wherever the plan stands
    } else {
      if (prim.falls_short.words().empty()) prim.falls_short = AtomSet(int(r.problem.atoms.size()));
      prim.falls_short.set(s.atom);
    }
    r.learned.push_back(s);
  }
  learning.pending.clear();
}

// What execution showed may leave the corrected problem with no plan: the proof (a quarter
// of the first one's budget) says so in a moment, where a search would run to its limit.
// A plan it replays is executed before another search (which would likely offer it first);
// failing, it corrects the problem again without a search; passing, it leads the next
// search's seeds, ahead of the stocks' (one no longer reaching the design is passed over).
CoreProof correct_by_replays(SearchOptions& search, std::int64_t max_rejected, Learning& learning, PlanningResult& r) {
  for (;;) {
    CoreProof corrected = prove_by_core(r.problem, quick_proof_limits());
    if (corrected.outcome != CoreProof::Outcome::Feasible) return corrected;
    search.seeds = start_seeds(r.stock_starts);
    search.seeds.insert(search.seeds.begin(), corrected.sequence);
    Plan replay;
    if (!search.accept || !detail::simulate(r.problem, corrected.sequence, replay) || !is_goal(r.problem, replay.final_state) ||
        std::int64_t(r.rejected.size()) >= max_rejected || r.search_rounds + r.replay_rounds >= kMaxLearningRounds)
      return corrected;
    const std::size_t rejected = r.rejected.size();
    if (search.accept(replay) || learning.pending.empty()) {
      if (r.rejected.size() > rejected) search.seeds.erase(search.seeds.begin());  // failed, showed nothing
      return corrected;
    }
    ++r.replay_rounds;
    take_in(learning, r);
  }
}

void search_plans(int top_k, const PlanningOptions& options, const Progress& progress, PlanningResult& r,
                  double& validation_seconds) {
  progress("search", 0);
  SearchOptions search{top_k, options.max_expansions};
  // Plans that differ only in the order of one tool's consecutive actions in one setup
  // are one plan to a shop: the search keeps the cheapest order of each such block.
  search.block_orders = BlockOrders::Cheapest;
  search.distinct_effects = true;
  search.time_limit = options.search_time;
  Learning learning;
  search.accept = accept_hook(options, r, validation_seconds, learning);
  search.known_to_fail = known_failure_hook(options, r);
  search.max_rejected = options.max_rejected;
  if (r.core_proof.outcome == CoreProof::Outcome::Feasible) search.seeds.push_back(r.core_proof.sequence);
  for (std::vector<int>& seed : start_seeds(r.stock_starts)) search.seeds.push_back(std::move(seed));
  // A rejection that showed a primitive falling short stops the search: the next one runs
  // on the problem without what the primitive does not do (planner/shortfall.hpp).
  if (options.learn)
    search.interrupt = [&learning, &r]() {
      return !learning.pending.empty() && r.search_rounds + r.replay_rounds < kMaxLearningRounds;
    };
  r.validated = bool(options.validate);
  const auto started = std::chrono::steady_clock::now();
  SearchStats total;
  bool proven_after_learning = false;
  for (;;) {
    ++r.search_rounds;
    SearchStats round;
    r.plans = find_plans(r.problem, search, &round);
    total.expanded += round.expanded;
    total.generated += round.generated;
    total.rejected += round.rejected;
    total.known_to_fail += round.known_to_fail;
    total.seconds += round.seconds;
    total.exhausted = round.exhausted;
    total.limit_reached = round.limit_reached;
    total.weight = round.weight;
    total.lower_bound = round.lower_bound;
    if (!round.interrupted) break;
    take_in(learning, r);
    CoreProof corrected = correct_by_replays(search, options.max_rejected, learning, r);
    if (corrected.outcome == CoreProof::Outcome::Proven) {
      r.plans.clear();
      r.core_proof = std::move(corrected);
      proven_after_learning = true;
      break;
    }
    // The rounds share the budgets: turned-down plans and seconds.
    search.max_rejected = std::max<std::int64_t>(1, options.max_rejected - std::int64_t(r.rejected.size()));
    if (options.search_time > 0)
      search.time_limit = std::max(
          0.05, options.search_time - std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
  }
  r.search = total;
  if (proven_after_learning) {
    r.search.limit_reached = false;
    r.search.exhausted = true;
    // A correction is not a proof (docs/validation.md): the verdict stays undecided, and
    // says that the search is over and why.
    r.verdict = core_verdict(r.problem, r.core_proof, r.measures, r.lattice);
    r.verdict.decided_without_search = false;
    r.verdict.summary = "no plan is left once the primitives are corrected by what execution showed (" +
                        std::to_string(r.rejected.size()) + " candidate" + (r.rejected.size() == 1 ? "" : "s") +
                        " rejected; " + learned_text(r) + "): on the corrected primitives, " + r.verdict.summary +
                        ". The correction may also rule out plans that would work";
    progress("search", 1);
    return;
  }
  std::string undecided_hint;
  if (r.plans.empty() && r.search.limit_reached && !r.verdict.decided_without_search) {
    // The search stopped without a plan: maybe none exists. Exploring what the primitives
    // reach at all, costs aside, can prove it.
    const Reachability reach = explore_reachable(r.problem);
    if (reach.complete && !reach.goal && r.learned.empty()) {
      r.search.limit_reached = false;
      r.search.exhausted = true;
      r.verdict.manufacturable = false;
      r.verdict.summary = unreachable_text(r, reach);
      progress("search", 1);
      return;
    }
    if (!reach.goal)
      undecided_hint = "; of the " + std::to_string(reach.states) +
                       " states explored (costs aside, the exploration's limit), none is within tolerance, and the "
                       "nearest " + nearest_text(r, reach);
  }
  progress("search", 1);
  const CoreProof& proof = r.core_proof;
  if (r.plans.empty() && !r.verdict.decided_without_search && proof.reuse_needed > r.problem.max_uses) {
    std::string sequence;
    for (const int i : proof.sequence) sequence += (sequence.empty() ? "" : ", ") + r.problem.primitives[std::size_t(i)].name;
    undecided_hint += "; the proof before the search found a sequence that makes the design using a primitive " +
                      std::to_string(proof.reuse_needed) + " times (" + sequence + "): --reuse " +
                      std::to_string(proof.reuse_needed) + " lets the search take it";
  }
  if (r.plans.empty() && !r.verdict.decided_without_search && !r.learned.empty())
    undecided_hint += "; " + learned_text(r) + ", which may also rule out plans that would work";
  if (r.plans.empty() && !r.verdict.decided_without_search) {
    r.verdict.manufacturable = false;
    r.verdict.summary = !r.rejected.empty()
                            ? "every candidate plan failed when executed (" + std::to_string(r.rejected.size()) +
                                  " rejected" + (r.search.limit_reached ? ", the search stopped at its limit" : "") + ")" +
                                  (r.learned.empty() ? std::string()
                                                     : "; " + learned_text(r) +
                                                           ", which may also rule out plans that would work")
                        : r.search.limit_reached
                            ? "undecided: no plan found within the search limits (" + std::to_string(r.search.expanded) +
                                  " states expanded, weighted A* included); no atom rules the part out, but the "
                                  "primitives may not combine into it" + undecided_hint
                            : "no sequence of these primitives makes the design";
  }
}

// When the proof before the search stopped at its budget, a longer one runs on another
// core while the search does: it decides parts the search cannot, and is stopped as soon
// as the search has a plan. It works on its own copy of the problem, the one before any
// learning: the search corrects its problem as candidates fail.
void search_beside_a_longer_proof(int top_k, const PlanningOptions& options, const Progress& progress,
                                  PlanningResult& r, double& validation_seconds) {
  if (r.core_proof.outcome != CoreProof::Outcome::Unknown || r.verdict.modality != Modality::Hybrid) {
    search_plans(top_k, options, progress, r, validation_seconds);
    return;
  }
  std::atomic<bool> stop{false};
  CoreProofLimits limits;
  limits.max_states = kLongerProofStates;
  limits.stop = &stop;
  const PlanningProblem problem = r.problem;
  CoreProof longer;
  std::thread prover([&] {
    try {
      longer = prove_by_core(problem, limits);
    } catch (const std::bad_alloc&) {
      longer = {};  // out of memory: no verdict from it, the search's stands
    }
  });
  try {
    search_plans(top_k, options, progress, r, validation_seconds);
  } catch (...) {
    stop = true;
    prover.join();
    throw;
  }
  if (!r.plans.empty()) stop = true;
  prover.join();
  if (!r.plans.empty() || longer.outcome != CoreProof::Outcome::Proven) return;
  r.core_proof = std::move(longer);
  r.verdict = core_verdict(problem, r.core_proof, r.measures, r.lattice);
  r.search.limit_reached = false;
  r.search.exhausted = true;
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
  r.sliver_threshold = options.sliver_threshold >= 0 ? options.sliver_threshold : defaults.sliver_threshold;
  const int top_k = options.top_k > 0 ? options.top_k : defaults.top_k;
  r.objective = options.objective.value_or(defaults.objective);
  r.currency = machine.costs.currency;

  // Before anything large is allocated: a grid over the budget is an input error.
  check_planning_memory(geometry::bounds(part), machine, h, r.tolerance, options.memory_budget, part_name);
  voxelize_design(part, part_name, machine, h, progress, r);
  clock.lap("voxelize");
  add_primitives(machine, options, progress, r);
  clock.lap("primitives");
  decompose_into_atoms(progress, r);
  clock.lap("atoms");
  if (options.fine_graining) {
    const Solid* present = options.stock_files.size() == 1 ? &r.primitives.front().region : nullptr;
    r.fine_graining = fine_grain(machine, r.design, r.tolerance, r.sliver_threshold, present, r.primitives, r.atoms, r.measures);
    clock.lap("fine-graining");
  }
  r.problem = symbolic_problem(r, machine, options.max_uses);
  r.problem.start_from_stock = !options.stock_files.empty();
  r.verdict = check_manufacturability(r.problem, r.measures, r.lattice);
  for (ViolatingAtom& v : r.verdict.violations)
    for (const FineGraining::Unsplit& u : r.fine_graining.unsplit)
      if (u.atom == v.atom) v.description += "; " + u.why;
  clock.lap("check");
  double validation_seconds = 0;
  if (r.verdict.manufacturable && r.verdict.modality == Modality::Hybrid) {
    // Cheap where it works (the B-axis overhang: milliseconds) and bounded where it does
    // not; the search cannot prove a hybrid problem infeasible short of exhausting it.
    r.core_proof = prove_by_core(r.problem);
    if (r.core_proof.outcome == CoreProof::Outcome::Proven) r.verdict = core_verdict(r.problem, r.core_proof, r.measures, r.lattice);
    else r.stock_starts = prove_stock_starts(r.problem, quick_proof_limits());
    clock.lap("proof");
  }
  if (r.verdict.manufacturable) search_beside_a_longer_proof(top_k, options, progress, r, validation_seconds);
  clock.lap("search");
  if (r.validated) {
    // The search's lap holds the validation it called: report them apart.
    r.timings.back().second = std::max(0.0, r.timings.back().second - validation_seconds);
    r.timings.emplace_back("validate", validation_seconds);
  }
  for (const Plan& plan : r.plans) {
    r.deviations.push_back(plan::measure_deviation(plan_outcome(r, plan), r.design, r.domain, r.tolerance));
    r.estimates.push_back(estimate_plan(machine, r.primitives, plan));
    if (options.toolpath_minutes) r.toolpath_minutes.push_back(options.toolpath_minutes(plan));
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
  // Replay the plan on atom sets up to `step`.
  AtomSet state(r.atoms.atom_count());
  AtomSet roi(r.atoms.atom_count());
  for (std::size_t s = 0; s <= step && s < plan.steps.size(); ++s) {
    const PrimitiveSpec& prim = r.problem.primitives[std::size_t(plan.steps[s].primitive)];
    // As the search applies it (search_steps.hpp): once begun, not what it falls short on.
    const auto& short_of = prim.falls_short.words();
    const bool begun = s > 0;
    for (std::size_t w = 0; w < state.words().size(); ++w) {
      const std::uint64_t does =
          begun && w < short_of.size() ? prim.atoms.words()[w] & ~short_of[w] : prim.atoms.words()[w];
      const std::uint64_t changed = prim.mode == Mode::Additive ? does & ~state.words()[w] : does & state.words()[w];
      if (s == step) roi.words()[w] = changed;
      state.words()[w] = prim.mode == Mode::Additive ? state.words()[w] | does : state.words()[w] & ~changed;
    }
  }
  return roi;
}

}  // namespace hybridctl::planner
