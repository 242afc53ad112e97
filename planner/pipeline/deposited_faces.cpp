#include "planner/pipeline/deposited_faces.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/number_text.hpp"
#include "planner/problem/actions.hpp"

namespace hybridctl::planner {
namespace {

// Which atoms hold design voxels next to air (`surface`), and per atom the atoms outside
// the core across its voxel faces (`air_beside`), in one pass over the domain.
void find_surface(const AtomDecomposition& atoms, const std::vector<AtomMeasures>& measures, FaceRule& rule) {
  const IndexBox& d = atoms.domain();
  const int n = atoms.atom_count();
  rule.surface.assign(std::size_t(n), false);
  rule.air_beside.assign(std::size_t(n), AtomSet(n));
  const auto beside = [&](int a, int b) {
    if (a != b && measures[std::size_t(b)].atom_class != AtomClass::MustIn) rule.air_beside[std::size_t(a)].set(b);
  };
  for (int z = d.lo.z; z < d.hi.z; ++z)
    for (int y = d.lo.y; y < d.hi.y; ++y)
      for (int x = 0; x < d.hi.x - d.lo.x; ++x) {
        const int a = atoms.atom_at_unchecked(x, y, z);
        const int nb[3] = {x + 1 < d.hi.x - d.lo.x ? atoms.atom_at_unchecked(x + 1, y, z) : -1,
                           y + 1 < d.hi.y ? atoms.atom_at_unchecked(x, y + 1, z) : -1,
                           z + 1 < d.hi.z ? atoms.atom_at_unchecked(x, y, z + 1) : -1};
        for (const int b : nb) {
          if (b < 0 || b == a) continue;
          beside(a, b);
          beside(b, a);
        }
      }
  // An atom is on the surface when it holds design and air itself (the band), or design
  // next to an atom that holds air.
  for (int a = 0; a < n; ++a) {
    const AtomMeasures& m = measures[std::size_t(a)];
    if (m.voxels_in_design == 0) continue;
    bool on = m.voxels_in_design < m.voxels;
    const std::vector<std::uint64_t>& beside_a = rule.air_beside[std::size_t(a)].words();
    for (std::size_t w = 0; w < beside_a.size() && !on; ++w)
      for (std::uint64_t bits = beside_a[w]; bits && !on; bits &= bits - 1) {
        const AtomMeasures& b = measures[w * 64 + std::size_t(__builtin_ctzll(bits))];
        on = b.voxels_in_design < b.voxels;
      }
    rule.surface[std::size_t(a)] = on;
  }
}

}  // namespace

FaceRule make_face_rule(const config::Machine& machine, const std::vector<Primitive>& primitives,
                        const PlanningProblem& problem, const AtomDecomposition& atoms,
                        const std::vector<AtomMeasures>& measures, double tolerance) {
  FaceRule rule;
  find_surface(atoms, measures, rule);
  const int n = atoms.atom_count();
  rule.tight.assign(problem.primitives.size(), AtomSet());
  rule.why.assign(problem.primitives.size(), std::string());
  rule.learned_atoms.assign(problem.primitives.size(), {});
  for (std::size_t i = 0; i < problem.primitives.size() && i < primitives.size(); ++i) {
    const PrimitiveSpec& spec = problem.primitives[i];
    if (spec.mode != Mode::Additive || spec.raw_stock) continue;
    const config::AdditiveHead* head = machine.find_head(primitives[i].capability);
    if (!head) continue;
    const bool coarse = head->accuracy > tolerance;
    const bool allowance = primitives[i].kind == PrimitiveKind::OAm && head->machining_allowance > tolerance;
    if (!coarse && !allowance) continue;
    AtomSet tight(n);
    for (int a = 0; a < n; ++a)
      if (rule.surface[std::size_t(a)] && spec.atoms.test(a)) tight.set(a);
    rule.tight[i] = std::move(tight);
    rule.why[i] = coarse ? "its head " + head->name + " lays material within " + trimmed_number(head->accuracy, 3) +
                               " mm of its beads, coarser than the tolerance " + trimmed_number(tolerance, 3) + " mm"
                         : "it is laid with the machining allowance of " + head->name + ", " +
                               trimmed_number(head->machining_allowance, 3) + " mm beyond the design, for a removal to finish";
  }
  return rule;
}

bool learn_face(FaceRule& rule, const PlanningProblem& problem, const AtomDecomposition& atoms,
                const std::vector<AtomMeasures>& measures, const DepositedFace& face) {
  if (face.primitive < 0 || std::size_t(face.primitive) >= rule.learned_atoms.size()) return false;
  const PrimitiveSpec& spec = problem.primitives[std::size_t(face.primitive)];
  if (spec.mode != Mode::Additive || spec.raw_stock) return false;
  const geometry::Lattice& l = atoms.lattice();
  const geometry::Index3 c{int(std::floor((face.at.x - l.origin.x) / l.voxel_size)),
                           int(std::floor((face.at.y - l.origin.y) / l.voxel_size)),
                           int(std::floor((face.at.z - l.origin.z) / l.voxel_size))};
  // Two voxels around the place: it lies on the part made, up to the deviation off the
  // design. Atoms are large (a blade's whole top and side may be one), so what reaches the
  // face is the air around this place, not beside the atom anywhere.
  constexpr int kReach = 2;
  std::vector<int> on_surface;
  AtomSet air(atoms.atom_count());
  for (int dz = -kReach; dz <= kReach; ++dz)
    for (int dy = -kReach; dy <= kReach; ++dy)
      for (int dx = -kReach; dx <= kReach; ++dx) {
        const geometry::Index3 v{c.x + dx, c.y + dy, c.z + dz};
        if (!atoms.domain().contains(v)) continue;
        const int a = atoms.atom_at(v);
        if (measures[std::size_t(a)].atom_class != AtomClass::MustIn) air.set(a);
        if (rule.surface[std::size_t(a)] && spec.atoms.test(a) &&
            std::find(on_surface.begin(), on_surface.end(), a) == on_surface.end())
          on_surface.push_back(a);
      }
  std::vector<LearnedFaceAtom>& known = rule.learned_atoms[std::size_t(face.primitive)];
  bool added = false;
  for (const int a : on_surface) {
    const auto same = [&](const LearnedFaceAtom& k) { return k.atom == a && k.air_near == air && k.excess == face.excess; };
    if (std::any_of(known.begin(), known.end(), same)) continue;
    known.push_back({a, air, face.excess});
    added = true;
  }
  if (added) {
    rule.learned.push_back(face);
    if (rule.why[std::size_t(face.primitive)].empty())
      rule.why[std::size_t(face.primitive)] = "an executed candidate left it " + fixed_number(face.mm, 3) +
                                              " mm off the STL there as deposited";
  }
  return added;
}

namespace {

// A removal among the plan's steps after `step` cleared an atom of `air`: material stood
// beside the face (the deposit's overfill, stock, an earlier deposit) and the removal's
// region of influence meets the face there, so its finishing passes cut it to the
// design's real surface.
bool cleared_after(const PlanningProblem& problem, const Plan& plan, const std::vector<std::vector<std::uint64_t>>& changed,
                   std::size_t step, const AtomSet& air) {
  const auto& a = air.words();
  for (std::size_t later = step + 1; later < plan.steps.size(); ++later) {
    if (problem.primitives[std::size_t(plan.steps[later].primitive)].mode != Mode::Subtractive) continue;
    const auto& cut = changed[later];
    for (std::size_t w = 0; w < a.size() && w < cut.size(); ++w)
      if (a[w] & cut[w]) return true;
  }
  return false;
}

// A removal among the plan's steps after `step` whose region holds an atom of `air`: it
// meets whatever stands there in the material really present, a bead's overfill included.
bool held_after(const PlanningProblem& problem, const Plan& plan, std::size_t step, const AtomSet& air) {
  const auto& a = air.words();
  for (std::size_t later = step + 1; later < plan.steps.size(); ++later) {
    const PrimitiveSpec& removal = problem.primitives[std::size_t(plan.steps[later].primitive)];
    if (removal.mode != Mode::Subtractive) continue;
    const auto& region = removal.atoms.words();
    const auto& short_of = removal.falls_short.words();  // what execution showed it does not reach
    for (std::size_t w = 0; w < a.size() && w < region.size(); ++w)
      if (a[w] & region[w] & ~(w < short_of.size() ? short_of[w] : 0)) return true;
  }
  return false;
}

}  // namespace

std::optional<FaceLeft> face_left_as_deposited(const PlanningProblem& problem, const FaceRule& rule, const Plan& plan) {
  if (rule.tight.empty()) return std::nullopt;
  const auto held = [&](int p) {
    return !rule.tight[std::size_t(p)].words().empty() || !rule.learned_atoms[std::size_t(p)].empty();
  };
  if (std::none_of(plan.steps.begin(), plan.steps.end(), [&](const PlanStep& s) { return held(s.primitive); }))
    return std::nullopt;
  const int n = int(problem.atoms.size());
  const auto [state, last, changed] = replay_plan(problem, plan);
  const auto laid_last = [&](int a, std::size_t s) { return last[std::size_t(a)] == int(s) && state.test(a); };
  for (std::size_t s = 0; s < plan.steps.size(); ++s) {
    const int p = plan.steps[s].primitive;
    if (!held(p)) continue;
    const AtomSet& tight = rule.tight[std::size_t(p)];
    if (!tight.words().empty())
      for (int a = 0; a < n; ++a)
        if (tight.test(a) && laid_last(a, s) && !cleared_after(problem, plan, changed, s, rule.air_beside[std::size_t(a)]))
          return FaceLeft{s, a};
    for (const LearnedFaceAtom& f : rule.learned_atoms[std::size_t(p)])
      if (laid_last(f.atom, s) && !(f.excess ? held_after(problem, plan, s, f.air_near)
                                             : cleared_after(problem, plan, changed, s, f.air_near)))
        return FaceLeft{s, f.atom};
  }
  return std::nullopt;
}

std::string describe_face_left(const PlanningProblem& problem, const FaceRule& rule, const std::vector<AtomMeasures>& measures,
                               const Plan& plan, const FaceLeft& left) {
  const int p = plan.steps[left.step].primitive;
  const geometry::Vec3& c = measures[std::size_t(left.atom)].centroid;
  char where[96];
  std::snprintf(where, sizeof where, "(%.1f, %.1f, %.1f) mm", c.x, c.y, c.z);
  return problem.primitives[std::size_t(p)].name + " (action " + std::to_string(left.step + 1) + ") leaves the face around " +
         where + " as deposited, and no removal after it reaches that face: " + rule.why[std::size_t(p)];
}

}  // namespace hybridctl::planner
