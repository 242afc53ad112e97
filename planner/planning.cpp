#include "planner/planning.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>

#include "common/error.hpp"
#include "geometry/vdb_file.hpp"
#include "geometry/voxelize.hpp"
#include "planner/memory_estimate.hpp"

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

// The machine's primitives, then those given as files.
void add_primitives(const config::Machine& machine, const std::vector<PrimitiveFile>& files, const Progress& progress,
                    PlanningResult& r) {
  r.primitives = machine_primitives(machine, r.design, r.domain, [&](std::size_t done, std::size_t total, const std::string&) {
    progress("primitives", total ? double(done) / double(total) : 1.0);
  });
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

// The symbolic problem the search runs on: atoms with volumes and classes, primitives as
// sets of atoms.
PlanningProblem symbolic_problem(const PlanningResult& r, const config::Planning& defaults, int max_uses) {
  PlanningProblem p;
  p.normaliser = r.bounding_box_volume > 0 ? r.bounding_box_volume : 1.0;
  p.max_uses = max_uses;
  p.fixed = {defaults.tool_change_cost, defaults.setup_change_cost, defaults.mode_switch_cost};
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
    s.atoms = AtomSet(r.atoms.atom_count());
    for (int a = 0; a < r.atoms.atom_count(); ++a)
      if (r.atoms.code(a).test(int(i))) s.atoms.set(a);
    p.primitives.push_back(std::move(s));
  }
  return p;
}

// The search's accept hook from PlanningOptions::validate: rejected plans are kept with
// their reasons (once each, as a weighted search may find them again), and the time the
// validation takes is counted apart from the search's.
std::function<bool(const Plan&)> accept_hook(const PlanningOptions& options, PlanningResult& r, double& seconds) {
  if (!options.validate) return {};
  return [&options, &r, &seconds](const Plan& plan) {
    const auto same_actions = [&plan](const RejectedPlan& known) {
      return std::equal(known.plan.steps.begin(), known.plan.steps.end(), plan.steps.begin(), plan.steps.end(),
                        [](const PlanStep& a, const PlanStep& b) { return a.primitive == b.primitive; });
    };
    if (std::any_of(r.rejected.begin(), r.rejected.end(), same_actions)) return false;
    const auto start = std::chrono::steady_clock::now();
    std::vector<RejectionReason> reasons = options.validate(r, plan);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (reasons.empty()) return true;
    r.rejected.push_back({plan, std::move(reasons)});
    return false;
  };
}

void search_plans(int top_k, const PlanningOptions& options, const Progress& progress, PlanningResult& r,
                  double& validation_seconds) {
  progress("search", 0);
  SearchOptions search{top_k, options.max_expansions};
  // Plans that differ only in the order of one tool's consecutive actions in one setup
  // are one plan to a shop: the search keeps the cheapest order of each such block.
  search.block_orders = BlockOrders::Cheapest;
  search.time_limit = options.search_time;
  search.accept = accept_hook(options, r, validation_seconds);
  search.max_rejected = options.max_rejected;
  r.validated = bool(options.validate);
  r.plans = find_plans(r.problem, search, &r.search);
  progress("search", 1);
  if (r.plans.empty() && !r.verdict.decided_without_search) {
    r.verdict.manufacturable = false;
    r.verdict.summary = !r.rejected.empty()
                            ? "every candidate plan failed when executed (" + std::to_string(r.rejected.size()) +
                                  " rejected" + (r.search.limit_reached ? ", the search stopped at its limit" : "") + ")"
                        : r.search.limit_reached
                            ? "undecided: no plan found within the search limits (" + std::to_string(r.search.expanded) +
                                  " states expanded, weighted A* included); no atom rules the part out, but the "
                                  "primitives may not combine into it"
                            : "no sequence of these primitives makes the design";
  }
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

  // Before anything large is allocated: a grid over the budget is an input error.
  check_planning_memory(geometry::bounds(part), machine, h, r.tolerance, options.memory_budget, part_name);
  voxelize_design(part, part_name, machine, h, progress, r);
  clock.lap("voxelize");
  add_primitives(machine, options.extra_primitives, progress, r);
  clock.lap("primitives");
  decompose_into_atoms(progress, r);
  clock.lap("atoms");
  r.problem = symbolic_problem(r, defaults, options.max_uses);
  r.verdict = check_manufacturability(r.problem, r.measures, r.lattice);
  clock.lap("check");
  double validation_seconds = 0;
  if (r.verdict.manufacturable) search_plans(top_k, options, progress, r, validation_seconds);
  clock.lap("search");
  if (r.validated) {
    // The search's lap holds the validation it called: report them apart.
    r.timings.back().second = std::max(0.0, r.timings.back().second - validation_seconds);
    r.timings.emplace_back("validate", validation_seconds);
  }
  for (const Plan& plan : r.plans)
    r.deviations.push_back(measure_deviation(plan_outcome(r, plan), r.design, r.domain, r.tolerance));
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
    for (std::size_t w = 0; w < state.words().size(); ++w) {
      const std::uint64_t changed = prim.mode == Mode::Additive ? prim.atoms.words()[w] & ~state.words()[w]
                                                                : prim.atoms.words()[w] & state.words()[w];
      if (s == step) roi.words()[w] = changed;
      state.words()[w] = prim.mode == Mode::Additive ? state.words()[w] | prim.atoms.words()[w]
                                                     : state.words()[w] & ~prim.atoms.words()[w];
    }
  }
  return roi;
}

}  // namespace hybridctl::planner
