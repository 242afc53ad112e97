#include "planner/search/reduce.hpp"

#include <bit>
#include <map>
#include <memory>
#include <unordered_map>

namespace hybridctl::planner {
namespace {

std::vector<std::uint64_t> class_mask(const PlanningProblem& p, bool must_in) {
  std::vector<std::uint64_t> mask(std::size_t((p.atoms.size() + 63) / 64), 0);
  for (std::size_t a = 0; a < p.atoms.size(); ++a)
    if (must_in ? p.atoms[a].must_in : p.atoms[a].must_out) mask[a / 64] |= std::uint64_t{1} << (a % 64);
  return mask;
}

bool empty(const AtomSet& s) {
  for (std::uint64_t w : s.words())
    if (w) return false;
  return true;
}

}  // namespace

SuffixClosure::SuffixClosure(const PlanningProblem& p) : p_(p) {
  const auto must_in = class_mask(p, true), must_out = class_mask(p, false);
  for (const PrimitiveSpec& prim : p.primitives) {
    const auto& mask = prim.mode == Mode::Additive ? must_out : must_in;
    std::vector<std::uint64_t> wrong(mask.size());
    for (std::size_t w = 0; w < mask.size() && w < prim.atoms.words().size(); ++w) wrong[w] = prim.atoms.words()[w] & mask[w];
    wrong_.push_back(std::move(wrong));
  }
}

std::vector<bool> SuffixClosure::usable(std::vector<bool> candidates) const {
  std::vector<bool> placed(candidates.size(), false);
  std::vector<std::uint64_t> decided(std::size_t((p_.atoms.size() + 63) / 64), 0);
  // Placing one can make others placeable: round after round until none is.
  for (bool more = true; more;) {
    more = false;
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      if (!candidates[i]) continue;
      const auto& wrong = wrong_[i];
      bool covered = true;
      for (std::size_t w = 0; w < wrong.size() && covered; ++w) covered = (wrong[w] & ~decided[w]) == 0;
      if (!covered) continue;
      candidates[i] = false;
      placed[i] = true;
      more = true;
      const auto& atoms = p_.primitives[i].atoms.words();
      for (std::size_t w = 0; w < decided.size() && w < atoms.size(); ++w) decided[w] |= atoms[w];
    }
  }
  return placed;
}

std::vector<std::uint64_t> SuffixClosure::decided(const std::vector<bool>& usable) const {
  std::vector<std::uint64_t> d(std::size_t((p_.atoms.size() + 63) / 64), 0);
  for (std::size_t i = 0; i < usable.size(); ++i)
    if (usable[i])
      for (std::size_t w = 0; w < d.size() && w < p_.primitives[i].atoms.words().size(); ++w) d[w] |= p_.primitives[i].atoms.words()[w];
  return d;
}

namespace {

// The merged atoms: an atom's group is its membership in the kept primitives, and for
// each kept primitive with a footing, whether it needs a carrier and which. Groups are
// numbered in the order of their first atom.
std::vector<int> group_atoms(const PlanningProblem& p, const std::vector<int>& kept, const std::vector<std::uint64_t>& decided) {
  std::map<std::vector<std::uint64_t>, int> groups;
  std::vector<int> group(p.atoms.size(), -1);
  for (std::size_t a = 0; a < p.atoms.size(); ++a) {
    if (!((decided[a / 64] >> (a % 64)) & 1)) continue;
    std::vector<std::uint64_t> key((kept.size() + 63) / 64, 0);
    for (std::size_t k = 0; k < kept.size(); ++k) {
      const PrimitiveSpec& prim = p.primitives[std::size_t(kept[k])];
      if (prim.atoms.test(int(a))) key[k / 64] |= std::uint64_t{1} << (k % 64);
      if (!prim.falls_short.words().empty()) key.push_back(prim.falls_short.test(int(a)) ? 3 : 2);
      if (!prim.footing || a >= prim.footing->kind.size()) continue;
      const bool needs = prim.footing->kind[a] == DepositFooting::NeedsCarrier;
      key.push_back(needs);
      if (needs && a < prim.footing->carriers.size())
        key.insert(key.end(), prim.footing->carriers[a].words().begin(), prim.footing->carriers[a].words().end());
    }
    group[a] = groups.emplace(std::move(key), int(groups.size())).first->second;
  }
  return group;
}

// An atom set in the reduced atoms: the groups of its atoms that no longer stand alone.
AtomSet mapped(const AtomSet& set, const std::vector<int>& group, int groups) {
  AtomSet out(groups);
  const auto& w = set.words();
  for (std::size_t k = 0; k < w.size(); ++k)
    for (std::uint64_t b = w[k]; b; b &= b - 1) {
      const std::size_t a = k * 64 + std::size_t(std::countr_zero(b));
      if (a < group.size() && group[a] >= 0) out.set(group[a]);
    }
  return out;
}

using Reach = std::shared_ptr<const AtomRelation>;
using Footing = std::shared_ptr<const DepositFooting>;

Reach mapped_reach(const AtomRelation& blocked_by, const std::vector<int>& group, int groups) {
  std::vector<AtomSet> out(std::size_t(groups), AtomSet{groups});
  // A group is out of reach when material lies over any of its atoms.
  for (std::size_t a = 0; a < blocked_by.size() && a < group.size(); ++a)
    if (group[a] >= 0) {
      auto& into = out[std::size_t(group[a])].words();
      const AtomSet over = mapped(blocked_by[a], group, groups);
      for (std::size_t w = 0; w < into.size(); ++w) into[w] |= over.words()[w];
    }
  return std::make_shared<const AtomRelation>(std::move(out));
}

Footing mapped_footing(const DepositFooting& footing, const std::vector<int>& group, int groups) {
  auto out = std::make_shared<DepositFooting>();
  out->kind.assign(std::size_t(groups), DepositFooting::None);
  std::vector<AtomSet> carriers(std::size_t(groups), AtomSet{groups});
  // The atoms of a group that need a carrier all have the same ones (group_atoms).
  for (std::size_t a = 0; a < footing.kind.size() && a < group.size(); ++a) {
    if (group[a] < 0 || footing.kind[a] == DepositFooting::None) continue;
    auto& kind = out->kind[std::size_t(group[a])];
    if (kind != DepositFooting::NeedsCarrier) kind = footing.kind[a];
    if (footing.kind[a] == DepositFooting::NeedsCarrier && a < footing.carriers.size())
      carriers[std::size_t(group[a])] = mapped(footing.carriers[a], group, groups);
  }
  out->carriers = AtomRelation(std::move(carriers));
  return out;
}

void reduce_atoms(const PlanningProblem& p, const std::vector<int>& group, Reduction& r) {
  for (std::size_t a = 0; a < p.atoms.size(); ++a) {
    const AtomSpec& spec = p.atoms[a];
    if (group[a] < 0) {
      r.infeasible = r.infeasible || spec.must_in;  // no primitive deposits it
      continue;
    }
    if (std::size_t(group[a]) == r.problem.atoms.size()) r.problem.atoms.push_back({});
    AtomSpec& into = r.problem.atoms[std::size_t(group[a])];
    into.volume += spec.volume;
    into.must_in = into.must_in || spec.must_in;
    into.must_out = into.must_out || spec.must_out;
  }
  // Atoms always present together cannot be one in and the other out.
  for (const AtomSpec& a : r.problem.atoms) r.infeasible = r.infeasible || (a.must_in && a.must_out);
}

void reduce_primitives(const PlanningProblem& p, const std::vector<int>& group, Reduction& r) {
  const int groups = int(r.problem.atoms.size());
  std::unordered_map<const void*, Reach> reaches;  // primitives often share one
  std::unordered_map<const void*, Footing> footings;
  for (const int i : r.primitive) {
    PrimitiveSpec prim = p.primitives[std::size_t(i)];
    prim.atoms = mapped(prim.atoms, group, groups);
    if (!prim.falls_short.words().empty()) prim.falls_short = mapped(prim.falls_short, group, groups);
    if (prim.blocked_by) {
      Reach& reach = reaches[prim.blocked_by.get()];
      if (!reach) reach = mapped_reach(*prim.blocked_by, group, groups);
      prim.blocked_by = reach;
    }
    if (prim.footing) {
      Footing& footing = footings[prim.footing.get()];
      if (!footing) footing = mapped_footing(*prim.footing, group, groups);
      prim.footing = footing;
    }
    r.problem.primitives.push_back(std::move(prim));
  }
}

}  // namespace

Reduction reduce(const PlanningProblem& p) {
  Reduction r;
  r.original_atoms = int(p.atoms.size());
  r.problem.fixed = p.fixed;
  r.problem.normaliser = p.normaliser;
  r.problem.max_uses = p.max_uses;
  r.problem.start_from_stock = p.start_from_stock;
  const SuffixClosure closure(p);
  std::vector<bool> candidates;
  for (const PrimitiveSpec& prim : p.primitives) candidates.push_back(!empty(prim.atoms));
  const std::vector<bool> usable = closure.usable(candidates);
  for (std::size_t i = 0; i < usable.size(); ++i)
    if (usable[i]) r.primitive.push_back(int(i));
  r.atom = group_atoms(p, r.primitive, closure.decided(usable));
  reduce_atoms(p, r.atom, r);
  reduce_primitives(p, r.atom, r);
  return r;
}

Plan lift(const Reduction& r, const Plan& plan) {
  Plan out = plan;
  for (PlanStep& step : out.steps) step.primitive = r.primitive[std::size_t(step.primitive)];
  out.final_state = AtomSet(r.original_atoms);
  for (int a = 0; a < r.original_atoms; ++a)
    if (r.atom[std::size_t(a)] >= 0 && plan.final_state.test(r.atom[std::size_t(a)])) out.final_state.set(a);
  return out;
}

}  // namespace hybridctl::planner
