#include "planner/shortfall.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace hybridctl::planner {

std::vector<Shortfall> find_shortfalls(const PlanningProblem& problem, const AtomDecomposition& atoms, const Plan& plan,
                                       std::size_t steps, const geometry::Solid& built) {
  const int n = atoms.atom_count();
  // The plan's state after `steps` actions, and per atom the step that last changed it.
  std::vector<int> last(std::size_t(n), -1);
  AtomSet state(n);
  for (std::size_t s = 0; s < std::min(steps, plan.steps.size()); ++s) {
    const PrimitiveSpec& prim = problem.primitives[std::size_t(plan.steps[s].primitive)];
    const bool adds = prim.mode == Mode::Additive;
    for (int a = 0; a < n; ++a)
      if (prim.atoms.test(a) && state.test(a) != adds) {
        state.set(a, adds);
        last[std::size_t(a)] = int(s);
      }
  }
  std::vector<std::int64_t> voxels(std::size_t(n), 0), present(std::size_t(n), 0);
  const IndexBox& d = atoms.domain();
  for (int z = d.lo.z; z < d.hi.z; ++z)
    for (int y = d.lo.y; y < d.hi.y; ++y)
      for (int x = 0; x < d.hi.x - d.lo.x; ++x) ++voxels[std::size_t(atoms.atom_at_unchecked(x, y, z))];
  built.for_each_voxel([&](Index3 v) {
    if (d.contains(v)) ++present[std::size_t(atoms.atom_at(v))];
  });
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

}  // namespace hybridctl::planner
