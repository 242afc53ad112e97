#include "planner/pipeline/shortfall.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

namespace hybridctl::planner {

namespace {

// The voxels of the domain within two voxels (each way) of a point a reason gives.
template <typename Fn>
void for_each_voxel_near(const AtomDecomposition& atoms, const geometry::Vec3& where, Fn fn) {
  const geometry::Lattice& lattice = atoms.lattice();
  const Index3 at{int(std::floor((where.x - lattice.origin.x) / lattice.voxel_size)),
                  int(std::floor((where.y - lattice.origin.y) / lattice.voxel_size)),
                  int(std::floor((where.z - lattice.origin.z) / lattice.voxel_size))};
  for (int dz = -2; dz <= 2; ++dz)
    for (int dy = -2; dy <= 2; ++dy)
      for (int dx = -2; dx <= 2; ++dx) {
        const Index3 v{at.x + dx, at.y + dy, at.z + dz};
        if (atoms.domain().contains(v)) fn(v);
      }
}

// Per atom: its voxels in the domain and those of them in `built`.
struct AtomFill {
  std::vector<std::int64_t> voxels, present;
};

AtomFill atom_fill(const AtomDecomposition& atoms, const geometry::Solid& built) {
  const int n = atoms.atom_count();
  AtomFill f{std::vector<std::int64_t>(std::size_t(n), 0), std::vector<std::int64_t>(std::size_t(n), 0)};
  const IndexBox& d = atoms.domain();
  for (int z = d.lo.z; z < d.hi.z; ++z)
    for (int y = d.lo.y; y < d.hi.y; ++y)
      for (int x = 0; x < d.hi.x - d.lo.x; ++x) ++f.voxels[std::size_t(atoms.atom_at_unchecked(x, y, z))];
  built.for_each_voxel([&](Index3 v) {
    if (d.contains(v)) ++f.present[std::size_t(atoms.atom_at(v))];
  });
  return f;
}

}  // namespace

std::vector<Shortfall> find_shortfalls(const PlanningProblem& problem, const AtomDecomposition& atoms, const Plan& plan,
                                       std::size_t steps, const geometry::Solid& built) {
  const int n = atoms.atom_count();
  const auto [state, last, changed] = replay_plan(problem, plan, steps);
  const auto [voxels, present] = atom_fill(atoms, built);
  const double voxel_volume = std::pow(atoms.lattice().voxel_size, 3);
  std::vector<Shortfall> out;
  for (int a = 0; a < n; ++a) {
    // Only the last action executed is charged: an atom an earlier one changed may have been
    // changed again since by one the plan did not mean to touch it with (a bead that spills
    // onto a milled face), which execution does not tell apart. Nor the first: what is
    // learned holds once the plan has begun.
    const int s = last[std::size_t(a)];
    if (s <= 0 || std::size_t(s) + 1 != std::min(steps, plan.steps.size()) || voxels[std::size_t(a)] == 0) continue;
    const int primitive = plan.steps[std::size_t(s)].primitive;
    if (problem.primitives[std::size_t(primitive)].raw_stock) continue;
    const AtomSpec& spec = problem.atoms[std::size_t(a)];
    const double built_fraction = double(present[std::size_t(a)]) / double(voxels[std::size_t(a)]);
    const bool missing = spec.must_in && state.test(a) && built_fraction < 0.5;
    const bool left = spec.must_out && !state.test(a) && built_fraction > 0.5;
    if (missing || left) out.push_back({primitive, a, double(voxels[std::size_t(a)]) * voxel_volume});
  }
  return out;
}

std::vector<Shortfall> find_missing_core_shortfalls(const PlanningProblem& problem, const AtomDecomposition& atoms,
                                                    const Plan& plan, std::size_t steps, const geometry::Solid& missing) {
  const std::size_t executed = std::min(steps, plan.steps.size());
  const int n = atoms.atom_count();
  const auto [state, last, changed] = replay_plan(problem, plan, executed);
  const auto removal_after = [&](int s) {
    for (std::size_t k = std::size_t(s) + 1; k < executed; ++k)
      if (problem.primitives[std::size_t(plan.steps[k].primitive)].mode == Mode::Subtractive) return true;
    return false;
  };
  std::vector<char> charged(std::size_t(n), 0);
  std::vector<Shortfall> out;
  missing.for_each_voxel([&](Index3 v) {
    if (!atoms.domain().contains(v)) return;
    const int a = atoms.atom_at(v);
    const int s = last[std::size_t(a)];
    if (charged[std::size_t(a)] || s <= 0 || !state.test(a) || !problem.atoms[std::size_t(a)].must_in) return;
    const int primitive = plan.steps[std::size_t(s)].primitive;
    const PrimitiveSpec& prim = problem.primitives[std::size_t(primitive)];
    if (prim.raw_stock || prim.mode != Mode::Additive || removal_after(s)) return;
    charged[std::size_t(a)] = 1;
    out.push_back({primitive, a, problem.atoms[std::size_t(a)].volume});
  });
  return out;
}

std::vector<Shortfall> find_skipped_layer_shortfalls(const PlanningProblem& problem, const AtomDecomposition& atoms,
                                                     const Plan& plan, std::size_t steps, const geometry::Solid& built,
                                                     const std::vector<plan::RejectionReason>& reasons) {
  const std::size_t executed = std::min(steps, plan.steps.size());
  if (executed < 2) return {};  // never the first action (find_shortfalls)
  const auto [state, last, changed] = replay_plan(problem, plan, executed);
  const int step = int(executed) - 1;
  const int primitive = plan.steps[std::size_t(step)].primitive;
  const PrimitiveSpec& prim = problem.primitives[std::size_t(primitive)];
  if (prim.mode != Mode::Additive || prim.raw_stock) return {};
  std::vector<Shortfall> out;
  for (const plan::RejectionReason& reason : reasons) {
    if (reason.kind != "layer_skipped" || reason.action != int(executed) || !reason.where) continue;
    for_each_voxel_near(atoms, *reason.where, [&](Index3 v) {
      if (built.contains(v)) return;
      const int a = atoms.atom_at(v);
      if (last[std::size_t(a)] != step || !problem.atoms[std::size_t(a)].must_in || !state.test(a)) return;
      if (std::none_of(out.begin(), out.end(), [a](const Shortfall& s) { return s.atom == a; }))
        out.push_back({primitive, a, problem.atoms[std::size_t(a)].volume});
    });
  }
  return out;
}

std::vector<Shortfall> find_spills(const PlanningProblem& problem, const AtomDecomposition& atoms, const Plan& plan,
                                   std::size_t steps, const geometry::Solid& built,
                                   const std::vector<plan::RejectionReason>& reasons) {
  const std::size_t executed = std::min(steps, plan.steps.size());
  int deposit = -1;  // the last deposit executed, raw stock aside
  for (std::size_t k = 0; k < executed; ++k) {
    const PrimitiveSpec& prim = problem.primitives[std::size_t(plan.steps[k].primitive)];
    if (prim.mode == Mode::Additive && !prim.raw_stock) deposit = int(k);
  }
  if (deposit < 0) return {};
  const int n = atoms.atom_count();
  const PlanReplay planned = replay_plan(problem, plan, executed);
  const auto [voxels, present] = atom_fill(atoms, built);
  const int primitive = plan.steps[std::size_t(deposit)].primitive;
  // The atoms with material near the worst excess.
  std::vector<char> near_worst(std::size_t(n), 0);
  for (const plan::RejectionReason& reason : reasons)
    if (reason.kind == "excess_material" && reason.where)
      for_each_voxel_near(atoms, *reason.where, [&](Index3 v) {
        if (built.contains(v)) near_worst[std::size_t(atoms.atom_at(v))] = 1;
      });
  // The removals that spare the design: with one that holds the atom, a plan may clear
  // what spilled there, and the deposit is not to blame for it.
  std::vector<char> sparing(problem.primitives.size(), 0);
  for (std::size_t i = 0; i < problem.primitives.size(); ++i) {
    const PrimitiveSpec& prim = problem.primitives[i];
    if (prim.mode != Mode::Subtractive) continue;
    sparing[i] = 1;
    for (int a = 0; a < n && sparing[i]; ++a) sparing[i] = !(problem.atoms[std::size_t(a)].must_in && prim.atoms.test(a));
  }
  const double voxel_volume = std::pow(atoms.lattice().voxel_size, 3);
  std::vector<Shortfall> out;
  for (int a = 0; a < n; ++a) {
    const bool filled = 2 * present[std::size_t(a)] > voxels[std::size_t(a)] || near_worst[std::size_t(a)];
    if (!problem.atoms[std::size_t(a)].must_out || planned.state.test(a) || !filled) continue;
    // Held by the deposit (the model knows the material there), or by a removal that spares
    // the design (a plan may clear it: the spill is charged only where nothing can).
    bool held = problem.primitives[std::size_t(primitive)].atoms.test(a);
    for (std::size_t i = 0; i < problem.primitives.size(); ++i) held = held || (sparing[i] && problem.primitives[i].atoms.test(a));
    if (!held) out.push_back({primitive, a, double(voxels[std::size_t(a)]) * voxel_volume, true});
  }
  return out;
}

std::vector<Shortfall> spills_beyond_the_grid(std::vector<Shortfall> spills, const AtomDecomposition& atoms,
                                              const std::vector<AtomMeasures>& measures,
                                              const std::optional<plan::ExactDeviation>& exact) {
  if (!exact) return spills;
  // The atoms within two voxels of the worst excess, where it is beyond the tolerance.
  std::vector<char> near_excess(measures.size(), 0);
  if (exact->excess.at && exact->excess.mm > exact->tolerance)
    for_each_voxel_near(atoms, *exact->excess.at, [&](Index3 v) { near_excess[std::size_t(atoms.atom_at(v))] = 1; });
  std::erase_if(spills, [&](const Shortfall& s) {
    const AtomMeasures& m = measures[std::size_t(s.atom)];
    return s.spill && m.thin_gap && m.voxels_beyond_hull == 0 && !near_excess[std::size_t(s.atom)];
  });
  return spills;
}

}  // namespace hybridctl::planner
