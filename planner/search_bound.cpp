#include "planner/search_bound.hpp"

#include <algorithm>
#include <bit>
#include <limits>
#include <map>
#include <string>

namespace hybridctl::planner {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

template <typename F>
void for_each_bit(const std::vector<std::uint64_t>& words, F f) {
  for (std::size_t w = 0; w < words.size(); ++w)
    for (std::uint64_t b = words[w]; b; b &= b - 1) f(int(w * 64 + std::size_t(std::countr_zero(b))));
}

std::vector<int> ids_of(const PlanningProblem& p, bool setups) {
  std::map<std::string, int> ids;
  std::vector<int> out;
  for (const PrimitiveSpec& s : p.primitives) {
    const std::string& key = setups ? s.setup : s.tool;
    out.push_back(ids.emplace(key, int(ids.size())).first->second);
  }
  return out;
}

}  // namespace

// Which primitives may still be used, and per atom the cheapest rate at which one of them
// deposits (or removes) it, looked up when asked (usually the first in the list).
struct LowerBound::Rates {
  const LowerBound& bound;
  std::vector<bool> allowed;
  double cheapest(const std::vector<int>& suppliers) const {
    for (int i : suppliers)
      if (allowed[std::size_t(i)]) return bound.p_.primitives[std::size_t(i)].cost_per_mm3;
    return kInfinity;
  }
  double deposit(std::size_t a) const { return cheapest(bound.adders_[a]); }
  double remove(std::size_t a) const { return cheapest(bound.removers_[a]); }
};

LowerBound::LowerBound(const PlanningProblem& p)
    : p_(p), closure_(p), atoms_(int(p.atoms.size())), tool_id_(ids_of(p, false)), setup_id_(ids_of(p, true)) {
  const std::size_t words = std::size_t((atoms_ + 63) / 64);
  must_in_.assign(words, 0);
  must_out_.assign(words, 0);
  for (int a = 0; a < atoms_; ++a) {
    if (p.atoms[std::size_t(a)].must_in) must_in_[std::size_t(a / 64)] |= std::uint64_t{1} << (a % 64);
    if (p.atoms[std::size_t(a)].must_out) must_out_[std::size_t(a / 64)] |= std::uint64_t{1} << (a % 64);
  }
  adders_.resize(std::size_t(atoms_));
  removers_.resize(std::size_t(atoms_));
  for (int i = 0; i < int(p.primitives.size()); ++i) {
    const PrimitiveSpec& prim = p.primitives[std::size_t(i)];
    for_each_bit(prim.atoms.words(), [&](int a) {
      if (a < atoms_) (prim.mode == Mode::Additive ? adders_ : removers_)[std::size_t(a)].push_back(i);
    });
    bool dirty = false;
    for (std::size_t w = 0; w < words && prim.mode == Mode::Additive; ++w) dirty = dirty || (prim.atoms.words()[w] & must_out_[w]);
    dirty_.push_back(dirty);
  }
  // The least a change into each setup costs: a refixture when the part is re-clamped for
  // it, else a setup change, or a refixture when coming from a setup that is re-clamped.
  bool any_refixture = false;
  for (const PrimitiveSpec& prim : p.primitives) any_refixture = any_refixture || prim.refixture;
  setup_entry_.assign(setup_id_.size() + 1, 0);
  for (std::size_t i = 0; i < p.primitives.size(); ++i)
    setup_entry_[std::size_t(setup_id_[i])] =
        p.primitives[i].refixture ? p.fixed.refixture
                                  : (any_refixture ? std::min(p.fixed.setup_change, p.fixed.refixture) : p.fixed.setup_change);
  auto by_cost = [&](int x, int y) {
    return p.primitives[std::size_t(x)].cost_per_mm3 < p.primitives[std::size_t(y)].cost_per_mm3;
  };
  for (auto& l : adders_) std::stable_sort(l.begin(), l.end(), by_cost);
  for (auto& l : removers_) std::stable_sort(l.begin(), l.end(), by_cost);
}

std::vector<bool> LowerBound::usable(const std::vector<std::uint8_t>& uses, bool first) const {
  std::vector<bool> candidates(p_.primitives.size());
  for (std::size_t i = 0; i < p_.primitives.size(); ++i)
    candidates[i] = uses[i] < p_.max_uses && (first || !p_.primitives[i].raw_stock);
  return closure_.usable(std::move(candidates));
}

LowerBound::Rates LowerBound::rates(const std::vector<std::uint8_t>& uses, bool first) const {
  return Rates{*this, usable(uses, first)};
}

double LowerBound::atom_part(const AtomSet& state, const Rates& r) const {
  const auto& s = state.words();
  double h = 0;
  for (std::size_t w = 0; w < s.size(); ++w) {
    for (std::uint64_t b = must_in_[w] & ~s[w]; b; b &= b - 1) {
      const std::size_t a = w * 64 + std::size_t(std::countr_zero(b));
      h += r.deposit(a) * p_.atoms[a].volume;
    }
    for (std::uint64_t b = must_out_[w] & s[w]; b; b &= b - 1) {
      const std::size_t a = w * 64 + std::size_t(std::countr_zero(b));
      h += r.remove(a) * p_.atoms[a].volume;
    }
  }
  return h;  // infinite when some needed atom has no supplier left
}

double LowerBound::side_effects(const AtomSet& state, const Rates& r) const {
  const auto& s = state.words();
  // What using primitive i costs beyond the atoms the atom part charges: absent atoms
  // that are not must-in (deposited, and removed again when must-out) for an additive
  // one, present atoms that are not must-out (removed, and deposited again when must-in)
  // for a subtractive one.
  std::vector<double> side(p_.primitives.size(), 0);
  for (std::size_t i = 0; i < p_.primitives.size(); ++i) {
    if (!r.allowed[i]) continue;
    const PrimitiveSpec& prim = p_.primitives[i];
    const auto& pa = prim.atoms.words();
    double c = 0;
    for (std::size_t w = 0; w < s.size(); ++w) {
      const std::uint64_t touched = prim.mode == Mode::Additive ? pa[w] & ~s[w] & ~must_in_[w] : pa[w] & s[w] & ~must_out_[w];
      for (std::uint64_t b = touched; b; b &= b - 1) {
        const std::size_t a = w * 64 + std::size_t(std::countr_zero(b));
        const AtomSpec& atom = p_.atoms[a];
        const bool undo = prim.mode == Mode::Additive ? atom.must_out : atom.must_in;
        c += atom.volume * (prim.mode == Mode::Additive ? r.deposit(a) + (undo ? r.remove(a) : 0)
                                                        : r.remove(a) + (undo ? r.deposit(a) : 0));
      }
    }
    side[i] = c;
  }
  // Some primitive must change each needed atom: the dearest such obligation counts.
  auto least = [&](const std::vector<int>& suppliers) {
    double best = kInfinity;
    for (int i : suppliers)
      if (r.allowed[std::size_t(i)]) best = std::min(best, side[std::size_t(i)]);
    return best;
  };
  double add = 0, remove = 0;
  for (std::size_t w = 0; w < s.size(); ++w) {
    for (std::uint64_t b = must_in_[w] & ~s[w]; b; b &= b - 1) add = std::max(add, least(adders_[w * 64 + std::size_t(std::countr_zero(b))]));
    for (std::uint64_t b = must_out_[w] & s[w]; b; b &= b - 1)
      remove = std::max(remove, least(removers_[w * 64 + std::size_t(std::countr_zero(b))]));
  }
  return add + remove;
}

double LowerBound::fixed_part(const AtomSet& state, const Rates& r, int last) const {
  const FixedCosts& f = p_.fixed;
  if (f.mode_switch == 0 && f.tool_change == 0 && f.setup_change == 0 && f.refixture == 0) return 0;
  const bool first = last < 0;
  const auto& s = state.words();
  auto allowed = [&](int i) { return bool(r.allowed[std::size_t(i)]); };
  bool need_add = false, need_remove = false;
  for (std::size_t w = 0; w < s.size(); ++w) {
    need_add = need_add || (must_in_[w] & ~s[w]);
    need_remove = need_remove || (must_out_[w] & s[w]);
  }
  // Does the last additive action of every completion leave a must-out atom behind?
  bool every_adder_dirty = true;
  for (int i = 0; i < int(p_.primitives.size()); ++i)
    if (p_.primitives[std::size_t(i)].mode == Mode::Additive && allowed(i) && !dirty_[std::size_t(i)]) every_adder_dirty = false;
  int switches = 0;
  const bool removing = !first && p_.primitives[std::size_t(last)].mode == Mode::Subtractive;
  if (removing) {
    switches = need_add ? 1 + int(every_adder_dirty) : 0;
  } else {
    switches = need_remove || ((need_add || first) && every_adder_dirty) ? 1 : 0;
  }
  // Tools (setups) that some needed atom can only be changed with.
  std::vector<bool> tool_forced(tool_id_.size() + 1, false), setup_forced(setup_id_.size() + 1, false);
  auto force = [&](const std::vector<int>& suppliers) {
    int tool = -1, setup = -1;
    bool one_tool = true, one_setup = true;
    for (int i : suppliers) {
      if (!allowed(i)) continue;
      if (tool < 0) tool = tool_id_[std::size_t(i)], setup = setup_id_[std::size_t(i)];
      one_tool = one_tool && tool_id_[std::size_t(i)] == tool;
      one_setup = one_setup && setup_id_[std::size_t(i)] == setup;
    }
    if (tool >= 0 && one_tool) tool_forced[std::size_t(tool)] = true;
    if (setup >= 0 && one_setup) setup_forced[std::size_t(setup)] = true;
  };
  for (std::size_t w = 0; w < s.size(); ++w) {
    for (std::uint64_t b = must_out_[w] & s[w]; b; b &= b - 1) force(removers_[w * 64 + std::size_t(std::countr_zero(b))]);
    for (std::uint64_t b = must_in_[w] & ~s[w]; b; b &= b - 1) force(adders_[w * 64 + std::size_t(std::countr_zero(b))]);
  }
  // Each forced tool other than the current one is changed to at least once; at the
  // start, the first action's tool comes free.
  auto changes = [&](const std::vector<bool>& forced, int current) {
    int n = 0;
    for (std::size_t t = 0; t < forced.size(); ++t) n += forced[t] && int(t) != current;
    return first ? std::max(0, n - 1) : n;
  };
  const int tools = changes(tool_forced, first ? -1 : tool_id_[std::size_t(last)]);
  // Each forced setup other than the current one is entered at least once, at no less than
  // its entry cost; at the start the dearest entry comes free (the first action's setup
  // is one of them, or none is forced).
  const int current = first ? -1 : setup_id_[std::size_t(last)];
  double setups = 0, dearest = 0;
  for (std::size_t t = 0; t < setup_forced.size(); ++t)
    if (setup_forced[t] && int(t) != current) setups += setup_entry_[t], dearest = std::max(dearest, setup_entry_[t]);
  if (first) setups -= dearest;
  return f.mode_switch * switches + f.tool_change * tools + setups;
}

double LowerBound::quick(const AtomSet& state, const std::vector<std::uint8_t>& uses, int last) const {
  const Rates r = rates(uses, last < 0);
  const double atoms = atom_part(state, r);
  if (atoms == kInfinity) return kInfinity;
  return (atoms + fixed_part(state, r, last)) / p_.normaliser;
}

double LowerBound::operator()(const AtomSet& state, const std::vector<std::uint8_t>& uses, int last) const {
  const Rates r = rates(uses, last < 0);
  const double atoms = atom_part(state, r);
  if (atoms == kInfinity) return kInfinity;
  const double side = side_effects(state, r);
  if (side == kInfinity) return kInfinity;
  return (atoms + side + fixed_part(state, r, last)) / p_.normaliser;
}

}  // namespace hybridctl::planner
