#include "planner/search/bound.hpp"

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

// Each raw stock has an id of its own: no change into or out of it costs anything
// (fixed_cost), so none is ever forced.
std::vector<int> ids_of(const PlanningProblem& p, bool setups) {
  std::map<std::string, int> ids;
  std::vector<int> out;
  for (std::size_t i = 0; i < p.primitives.size(); ++i) {
    const PrimitiveSpec& s = p.primitives[i];
    const std::string key = s.raw_stock ? "\x01raw stock " + std::to_string(i) : setups ? s.setup : s.tool;
    out.push_back(ids.emplace(key, int(ids.size())).first->second);
  }
  return out;
}

// Calls fn(a) for each must-in atom of `state` that removal `prim` surely cuts: what it
// holds but was seen not to cut once begun (falls_short).
template <typename F>
void for_each_design_cut(const PrimitiveSpec& prim, const std::vector<std::uint64_t>& state,
                         const std::vector<std::uint64_t>& must_in, F fn) {
  const auto& pa = prim.atoms.words();
  const auto& short_of = prim.falls_short.words();
  for (std::size_t w = 0; w < state.size(); ++w)
    for (std::uint64_t b = pa[w] & state[w] & must_in[w] & ~(w < short_of.size() ? short_of[w] : 0); b; b &= b - 1)
      fn(w * 64 + std::size_t(std::countr_zero(b)));
}

}  // namespace

// Which primitives may still be used, and per atom the cheapest rate at which one of them
// deposits (or removes) it, looked up when asked (usually the first in the list).
struct LowerBound::Rates {
  Rates(const LowerBound& b, std::vector<bool> usable) : bound(b), allowed(std::move(usable)) {
    // Per supplier list (cheapest first) the rate of its first allowed member: every share
    // of the bound asks for these, per atom, many times over. Most primitives are allowed:
    // only the lists a disallowed one leads are looked through again.
    bool stock_allowed = false;
    for (std::size_t i = 0; i < allowed.size(); ++i) stock_allowed = stock_allowed || (allowed[i] && b.p_.primitives[i].raw_stock);
    const Leaders& leaders = b.leaders_[stock_allowed ? 0 : 1];
    rate = leaders.rate;
    // Bytes, not bits, for the lists' members looked up below: this loop is hot.
    const std::vector<char> ok(allowed.begin(), allowed.end());
    for (std::size_t i = 0; i < allowed.size(); ++i) {
      if (ok[i]) continue;
      for (const int l : leaders.led_by[i]) {
        double& r = rate[std::size_t(l)];
        r = kInfinity;
        for (int j : b.lists_[std::size_t(l)])
          if (ok[std::size_t(j)]) {
            r = b.p_.primitives[std::size_t(j)].cost_per_mm3;
            break;
          }
      }
    }
  }
  const LowerBound& bound;
  std::vector<bool> allowed;
  std::vector<double> rate;  // per list
  double deposit(std::size_t a) const { return rate[std::size_t(bound.adder_list_[a])]; }
  // The least its last deposit costs (a must-in atom; any other: deposit()).
  double last_deposit(std::size_t a) const { return rate[std::size_t(bound.last_adder_list_[a])]; }
  double remove(std::size_t a) const { return rate[std::size_t(bound.remover_list_[a])]; }
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
  index_lists();
}

// After the last deposit of a must-in atom nothing takes it away. So the action that lays
// it last cannot also lay a must-out atom that only removals holding the atom take away
// (it would be cut after, and laid again): such an adder is left out of the atom's list of
// last adders. Per must-out atom, the atoms every removal of it holds are worked out once
// per remover list. A remover's or an adder's atoms are what it changes once begun (less
// what it falls short of): for an adder fewer must-out atoms, so never a last adder too few.
std::vector<std::vector<int>> LowerBound::last_adders() const {
  const PlanningProblem& p = p_;
  const std::size_t words = must_in_.size();
  auto changes = [&](int i) {
    std::vector<std::uint64_t> w = p.primitives[std::size_t(i)].atoms.words();
    w.resize(words, 0);
    const auto& short_of = p.primitives[std::size_t(i)].falls_short.words();
    for (std::size_t k = 0; k < words && k < short_of.size(); ++k) w[k] &= ~short_of[k];
    return w;
  };
  std::map<int, std::vector<std::uint64_t>> held_by_all;  // per remover list id
  auto held = [&](std::size_t b) -> const std::vector<std::uint64_t>& {
    const int l = remover_list_[b];
    auto [it, added] = held_by_all.emplace(l, std::vector<std::uint64_t>(words, ~std::uint64_t{0}));
    if (added)
      for (int r : lists_[std::size_t(l)]) {
        const std::vector<std::uint64_t> cut = changes(r);
        for (std::size_t k = 0; k < words; ++k) it->second[k] &= cut[k];
      }
    return it->second;
  };
  std::vector<std::vector<std::uint64_t>> not_last(p.primitives.size());
  for (std::size_t i = 0; i < p.primitives.size(); ++i) {
    if (p.primitives[i].mode != Mode::Additive) continue;
    not_last[i].assign(words, 0);
    const std::vector<std::uint64_t> laid = changes(int(i));
    for (std::size_t w = 0; w < words; ++w)
      for (std::uint64_t b = laid[w] & must_out_[w]; b; b &= b - 1) {
        const auto& all = held(w * 64 + std::size_t(std::countr_zero(b)));
        for (std::size_t k = 0; k < words; ++k) not_last[i][k] |= all[k];
      }
  }
  std::vector<std::vector<int>> out(static_cast<std::size_t>(atoms_));
  for (int a = 0; a < atoms_; ++a) {
    if (!p.atoms[std::size_t(a)].must_in) {
      out[std::size_t(a)] = adders_[std::size_t(a)];
      continue;
    }
    for (int i : adders_[std::size_t(a)])
      if (!((not_last[std::size_t(i)][std::size_t(a / 64)] >> (a % 64)) & 1u)) out[std::size_t(a)].push_back(i);
  }
  return out;
}

// The distinct supplier lists and the bit masks fixed_part works with.
void LowerBound::index_lists() {
  const PlanningProblem& p = p_;
  std::map<std::vector<int>, int> ids;
  auto id_of = [&](const std::vector<int>& list) {
    const auto [it, added] = ids.emplace(list, int(lists_.size()));
    if (added) lists_.push_back(list);
    return it->second;
  };
  for (int a = 0; a < atoms_; ++a) {
    adder_list_.push_back(id_of(adders_[std::size_t(a)]));
    remover_list_.push_back(id_of(removers_[std::size_t(a)]));
  }
  for (const std::vector<int>& list : last_adders()) last_adder_list_.push_back(id_of(list));
  lays_some_last_.assign(p.primitives.size(), false);
  std::vector<bool> last_list(lists_.size(), false);
  for (int a = 0; a < atoms_; ++a)
    if (p.atoms[std::size_t(a)].must_in) {
      last_list[std::size_t(last_adder_list_[std::size_t(a)])] = true;
      for (int i : lists_[std::size_t(last_adder_list_[std::size_t(a)])]) lays_some_last_[std::size_t(i)] = true;
    }
  for (std::size_t l = 0; l < lists_.size(); ++l)
    if (last_list[l]) last_lists_.push_back(int(l));
  for (std::size_t i = 0; i < p.primitives.size(); ++i)
    if (lays_some_last_[i]) thresholds_.push_back(p.primitives[i].cost_per_mm3);
  std::sort(thresholds_.begin(), thresholds_.end());
  thresholds_.erase(std::unique(thresholds_.begin(), thresholds_.end()), thresholds_.end());
  // The lists, tools and setups as bit masks over the primitives.
  const std::size_t prim_words = (p.primitives.size() + 63) / 64;
  auto mask = [&](auto member) {
    std::vector<std::uint64_t> m(prim_words, 0);
    for (std::size_t i = 0; i < p.primitives.size(); ++i)
      if (member(int(i))) m[i / 64] |= std::uint64_t{1} << (i % 64);
    return m;
  };
  for (const auto& list : lists_)
    list_mask_.push_back(mask([&](int i) { return std::find(list.begin(), list.end(), i) != list.end(); }));
  // Each list's rate with every primitive allowed (and without the raw stocks), and the
  // lists each primitive leads.
  for (int without_stocks = 0; without_stocks < 2; ++without_stocks) {
    Leaders& leaders = leaders_[without_stocks];
    leaders.led_by.assign(p.primitives.size(), {});
    for (std::size_t l = 0; l < lists_.size(); ++l) {
      const auto first = std::find_if(lists_[l].begin(), lists_[l].end(), [&](int i) {
        return !without_stocks || !p.primitives[std::size_t(i)].raw_stock;
      });
      leaders.rate.push_back(first == lists_[l].end() ? kInfinity : p.primitives[std::size_t(*first)].cost_per_mm3);
      if (first != lists_[l].end()) leaders.led_by[std::size_t(*first)].push_back(int(l));
    }
  }
  for (std::size_t t = 0; t < tool_id_.size(); ++t)  // ids are below the primitives' count
    tool_mask_.push_back(mask([&](int i) { return tool_id_[std::size_t(i)] == int(t); }));
  for (std::size_t t = 0; t < setup_id_.size(); ++t)
    setup_mask_.push_back(mask([&](int i) { return setup_id_[std::size_t(i)] == int(t); }));
}

std::vector<double> LowerBound::per_primitive(const std::vector<double>& per_list) const {
  std::vector<double> out(p_.primitives.size(), 0);
  for (std::size_t l = 0; l < lists_.size(); ++l)
    if (per_list[l] != 0)
      for (int i : lists_[l]) out[std::size_t(i)] += per_list[l];
  return out;
}

bool LowerBound::lays_last(int i, int a) const {
  const std::vector<int>& list = lists_[std::size_t(last_adder_list_[std::size_t(a)])];
  return std::find(list.begin(), list.end(), i) != list.end();
}

std::vector<char> LowerBound::needed_lists(const AtomSet& state, bool last) const {
  std::vector<char> needed(lists_.size(), 0);
  const auto& s = state.words();
  const std::vector<int>& adder_list = last ? last_adder_list_ : adder_list_;
  for (std::size_t w = 0; w < s.size(); ++w) {
    for (std::uint64_t b = must_in_[w] & ~s[w]; b; b &= b - 1) needed[std::size_t(adder_list[w * 64 + std::size_t(std::countr_zero(b))])] = 1;
    for (std::uint64_t b = must_out_[w] & s[w]; b; b &= b - 1) needed[std::size_t(remover_list_[w * 64 + std::size_t(std::countr_zero(b))])] = 1;
  }
  return needed;
}

std::vector<bool> LowerBound::usable(const std::vector<std::uint8_t>& uses, bool first) const {
  std::vector<bool> candidates(p_.primitives.size());
  for (std::size_t i = 0; i < p_.primitives.size(); ++i)
    candidates[i] = uses[i] < p_.max_uses && (first ? !(p_.primitives[i].raw_stock && p_.primitives[i].never_first)
                                                    : !p_.primitives[i].raw_stock);
  return closure_.usable(std::move(candidates));
}

LowerBound::Rates LowerBound::rates(const std::vector<std::uint8_t>& uses, bool first) const {
  return Rates{*this, usable(uses, first)};
}

LowerBound::AtomShares LowerBound::atom_part(const AtomSet& state, const Rates& r) const {
  const auto& s = state.words();
  AtomShares h;
  for (std::size_t w = 0; w < s.size(); ++w) {
    for (std::uint64_t b = must_in_[w] & ~s[w]; b; b &= b - 1) {
      const std::size_t a = w * 64 + std::size_t(std::countr_zero(b));
      h.deposits += r.last_deposit(a) * p_.atoms[a].volume;
    }
    for (std::uint64_t b = must_out_[w] & s[w]; b; b &= b - 1) {
      const std::size_t a = w * 64 + std::size_t(std::countr_zero(b));
      h.removals += r.remove(a) * p_.atoms[a].volume;
    }
  }
  return h;  // infinite when some needed atom has no supplier left
}

// Each must-in atom still to be laid (missing now, or cut by a removal to come) is laid last
// by an adder under a rate threshold or by one at it or above. So a completion pays either
// the side effects of some adder under the threshold that may lay a must-in atom last (the
// waste an overfilling head lays with the design, laid and cut away), or, for each such
// atom, the least rate at or above the threshold instead of the atom part's rate. Per
// threshold (each rate of the adders that may lay design last, but the cheapest): the
// cheaper side effect; what the atoms of each last-adder list cost beyond its rate is
// filled in by relay_extras, when it can count.
std::vector<LowerBound::Relay> LowerBound::relays(const Rates& r, const std::vector<double>& side) const {
  std::vector<Relay> out;
  for (std::size_t k = 1; k < thresholds_.size(); ++k) {
    const double threshold = thresholds_[k];
    Relay relay;
    relay.threshold = threshold;
    relay.cheap_side = kInfinity;
    for (std::size_t i = 0; i < p_.primitives.size(); ++i) {
      const PrimitiveSpec& prim = p_.primitives[i];
      if (!r.allowed[i] || !lays_some_last_[i] || prim.cost_per_mm3 >= threshold) continue;
      // One that falls short may lay less than its side effects: nothing is sure.
      relay.cheap_side = std::min(relay.cheap_side, prim.falls_short.words().empty() ? side[i] : 0.0);
    }
    // Nothing allowed under it: every rate is at or above it, nothing to add.
    if (relay.cheap_side > 0 && relay.cheap_side < kInfinity) out.push_back(std::move(relay));
  }
  return out;
}

void LowerBound::relay_extras(const Rates& r, Relay& relay) const {
  relay.extra.assign(lists_.size(), 0);
  for (const int l : last_lists_) {
    if (r.rate[std::size_t(l)] >= relay.threshold) continue;
    double at_threshold = kInfinity;  // lists are cheapest first
    for (int i : lists_[std::size_t(l)])
      if (r.allowed[std::size_t(i)] && p_.primitives[std::size_t(i)].cost_per_mm3 >= relay.threshold) {
        at_threshold = p_.primitives[std::size_t(i)].cost_per_mm3;
        break;
      }
    relay.extra[std::size_t(l)] = at_threshold - r.rate[std::size_t(l)];
  }
}

// A completion removes every must-out atom present, and a removal that cuts design present
// (or design a removal before it cut) is followed by a deposit of that design. Let r* be
// the used removal whose design share R (the design present in it, at the cheapest rates
// that deposit it last) is largest: the completion pays at least R(r*) for deposits, and
// removes each must-out atom present with one of the removals whose R is at most R(r*).
// So the least over thresholds t of t + (each must-out atom present at the cheapest rate of
// a removal with R <= t) bounds this share; t = 0 are the removals that spare the design.
// It never falls by more than a removal costs plus the design it cuts (which the atom
// part's deposits then charge): the threshold that covers the removal taken does as well
// before it.
// `relaid` adds, per threshold, what laying last the design r* cuts and the design missing
// costs beyond those rates (relays): the least over the removals of that threshold. It
// bounds everything but the atom part's deposits and the fixed costs, side effects
// included, so it stands beside the sum of the other shares, not in it; it is worked out
// only where it may be the larger (it exceeds `plain` by at most a cheap side effect).
LowerBound::DesignCut LowerBound::removals_with_design_cut(const AtomSet& state, const Rates& r,
                                                           const SideShares& side, const AtomShares& atoms) const {
  const auto& s = state.words();
  // Each allowed removal's design share in this state: a must-in atom present is cut by
  // exactly the removals of its remover list, so its price is summed per list once.
  std::vector<double> per_list(lists_.size(), 0);
  for (std::size_t w = 0; w < s.size(); ++w)
    for (std::uint64_t b = s[w] & must_in_[w]; b; b &= b - 1) {
      const std::size_t a = w * 64 + std::size_t(std::countr_zero(b));
      per_list[std::size_t(remover_list_[a])] += r.last_deposit(a) * p_.atoms[a].volume;
    }
  const std::vector<double> cut_share = per_primitive(per_list);
  struct Cut {
    double share;
    int removal;
  };
  std::vector<Cut> cuts;
  for (std::size_t i = 0; i < p_.primitives.size(); ++i) {
    const PrimitiveSpec& prim = p_.primitives[i];
    if (prim.mode != Mode::Subtractive || !r.allowed[i]) continue;
    Cut cut{cut_share[i], int(i)};
    if (!prim.falls_short.words().empty()) {  // not what it was seen not to cut
      cut.share = 0;
      for_each_design_cut(prim, s, must_in_, [&](std::size_t a) { cut.share += r.last_deposit(a) * p_.atoms[a].volume; });
    }
    cuts.push_back(cut);
  }
  std::sort(cuts.begin(), cuts.end(), [](const Cut& x, const Cut& y) { return x.share < y.share; });
  // Thresholds: 0 and each distinct share; per removal the first threshold admitting it.
  std::vector<double> threshold{0.0};
  std::vector<int> rank(p_.primitives.size(), -1);
  for (const Cut& cut : cuts) {
    if (cut.share > threshold.back()) threshold.push_back(cut.share);
    rank[std::size_t(cut.removal)] = int(threshold.size()) - 1;
  }
  const std::size_t k = threshold.size();
  // The must-out volume present per remover list: atoms of one list price alike.
  std::vector<double> volume(lists_.size(), 0);
  for (std::size_t w = 0; w < s.size(); ++w)
    for (std::uint64_t b = must_out_[w] & s[w]; b; b &= b - 1) {
      const std::size_t a = w * 64 + std::size_t(std::countr_zero(b));
      volume[std::size_t(remover_list_[a])] += p_.atoms[a].volume;
    }
  // total[j]: the must-out atoms at threshold j, as differences from j to j + 1.
  std::vector<double> step(k + 1, 0);
  std::size_t priced_from = 0;  // the least threshold at which every such atom has a removal
  for (std::size_t l = 0; l < lists_.size(); ++l) {
    if (volume[l] == 0) continue;
    // Cheapest first: a remover admitted at a lower threshold than all cheaper ones sets
    // the price from its threshold up to theirs.
    int lowest = int(k);  // the least threshold at which a cheaper remover is admitted
    for (int i : lists_[l]) {
      const int j = rank[std::size_t(i)];
      if (j < 0 || j >= lowest) continue;
      const double price = p_.primitives[std::size_t(i)].cost_per_mm3 * volume[l];
      step[std::size_t(j)] += price;
      step[std::size_t(lowest)] -= price;
      lowest = j;
    }
    if (lowest == int(k)) return {kInfinity, kInfinity};  // no removal left for these atoms
    priced_from = std::max(priced_from, std::size_t(lowest));  // below it they cannot go
  }
  std::vector<double> base(k, kInfinity);  // threshold plus the must-out atoms' removals
  DesignCut best{kInfinity, 0};
  double total = 0;
  for (std::size_t j = 0; j < k; ++j) {
    total += step[j];
    if (j < priced_from) continue;
    base[j] = threshold[j] + total;
    best.plain = std::min(best.plain, base[j]);
  }

  std::vector<Relay> relay = relays(r, side.of);
  double most = 0;  // what the relay share adds at the most
  for (const Relay& one : relay) most = std::max(most, one.cheap_side);
  const double others = side.deposits + std::max(atoms.removals + side.removals, best.plain);
  if (relay.empty() || best.plain + most <= others) return best;
  best.relaid = relaid_share(state, r, relay, rank, base, priced_from);
  return best;
}

// The relay share beside the design-cut share's thresholds (`rank` of each allowed removal,
// -1 for the others; `base`: each threshold plus the removals it prices).
double LowerBound::relaid_share(const AtomSet& state, const Rates& r, std::vector<Relay>& relay,
                                const std::vector<int>& rank, const std::vector<double>& base,
                                std::size_t priced_from) const {
  const auto& s = state.words();
  for (Relay& one : relay) relay_extras(r, one);
  const std::size_t kinds = relay.size(), k = base.size();
  // Per relay: the missing design's extra, and each removal's (the design it cuts).
  std::vector<double> missing_extra(kinds, 0);
  std::vector<std::vector<double>> extra_per_list(kinds, std::vector<double>(lists_.size(), 0));
  for (std::size_t w = 0; w < s.size(); ++w) {
    for (std::uint64_t b = s[w] & must_in_[w]; b; b &= b - 1) {
      const std::size_t a = w * 64 + std::size_t(std::countr_zero(b));
      for (std::size_t n = 0; n < kinds; ++n)
        if (const double e = relay[n].extra[std::size_t(last_adder_list_[a])]; e > 0)
          extra_per_list[n][std::size_t(remover_list_[a])] += e * p_.atoms[a].volume;
    }
    for (std::uint64_t b = must_in_[w] & ~s[w]; b; b &= b - 1) {
      const std::size_t a = w * 64 + std::size_t(std::countr_zero(b));
      for (std::size_t n = 0; n < kinds; ++n)
        if (const double e = relay[n].extra[std::size_t(last_adder_list_[a])]; e > 0) missing_extra[n] += e * p_.atoms[a].volume;
    }
  }
  std::vector<std::vector<double>> cut_extra;
  for (const auto& e : extra_per_list) cut_extra.push_back(per_primitive(e));
  for (std::size_t i = 0; i < rank.size(); ++i) {
    const PrimitiveSpec& prim = p_.primitives[i];
    if (rank[i] < 0 || prim.falls_short.words().empty()) continue;
    for (auto& e : cut_extra) e[i] = 0;
    for_each_design_cut(prim, s, must_in_, [&](std::size_t a) {
      for (std::size_t n = 0; n < kinds; ++n)
        cut_extra[n][i] += relay[n].extra[std::size_t(last_adder_list_[a])] * p_.atoms[a].volume;
    });
  }
  // Per threshold the least extra of its removals; at 0 nothing need be laid again (no
  // removal may be used at all).
  std::vector<std::vector<double>> least_extra(kinds, std::vector<double>(k, kInfinity));
  for (auto& l : least_extra) l[0] = 0;
  for (std::size_t i = 0; i < rank.size(); ++i) {
    if (rank[i] <= 0) continue;
    for (std::size_t n = 0; n < kinds; ++n)
      least_extra[n][std::size_t(rank[i])] = std::min(least_extra[n][std::size_t(rank[i])], cut_extra[n][i]);
  }
  double best = kInfinity;
  for (std::size_t j = priced_from; j < k; ++j) {
    double relaid = 0;
    for (std::size_t n = 0; n < kinds; ++n)
      relaid = std::max(relaid, std::min(relay[n].cheap_side, missing_extra[n] + least_extra[n][j]));
    best = std::min(best, base[j] + relaid);
  }
  return best;
}

LowerBound::SideShares LowerBound::side_effects(const AtomSet& state, const Rates& r) const {
  const auto& s = state.words();
  // What using primitive i costs beyond the atoms the atom part charges: absent atoms
  // that are not must-in (deposited, and removed again when must-out) for an additive
  // one, present atoms that are not must-out (removed, and deposited again when must-in)
  // for a subtractive one.
  // The rates looked up once per list of suppliers, and what changing each atom costs.
  const std::vector<double>& rate = r.rate;
  // An atom is held by exactly the primitives of its supplier lists, so what it costs is
  // summed per list once and each primitive adds up its lists: one pass over the atoms
  // instead of one per primitive.
  std::vector<double> per_list(lists_.size(), 0);
  for (std::size_t w = 0; w < s.size(); ++w) {
    const std::uint64_t valid = w + 1 < s.size() || atoms_ % 64 == 0 ? ~std::uint64_t{0} : (std::uint64_t{1} << (atoms_ % 64)) - 1;
    for (std::uint64_t b = ~s[w] & ~must_in_[w] & valid; b; b &= b - 1) {  // deposited, removed again when must-out
      const std::size_t a = w * 64 + std::size_t(std::countr_zero(b));
      const AtomSpec& atom = p_.atoms[a];
      const std::size_t l = std::size_t(adder_list_[a]);
      if (lists_[l].empty()) continue;
      per_list[l] += atom.volume * (rate[l] + (atom.must_out ? rate[std::size_t(remover_list_[a])] : 0));
    }
    for (std::uint64_t b = s[w] & ~must_out_[w] & valid; b; b &= b - 1) {  // removed, deposited again when must-in
      const std::size_t a = w * 64 + std::size_t(std::countr_zero(b));
      const AtomSpec& atom = p_.atoms[a];
      const std::size_t l = std::size_t(remover_list_[a]);
      if (lists_[l].empty()) continue;
      per_list[l] += atom.volume * (rate[l] + (atom.must_in ? rate[std::size_t(adder_list_[a])] : 0));
    }
  }
  std::vector<double> side = per_primitive(per_list);
  const std::vector<char> needed = needed_lists(state);
  // Per list, the volume of its atoms that are wrong: the first of its suppliers a
  // completion uses changes all of them (no other primitive holds them), at its own rate.
  // What the atom part charged them: the cheapest rate, or for a must-in atom the least its
  // last deposit costs, at most the dearest of those per list (a last deposit by the
  // supplier is charged its rate beyond that; any other deposit of the atom all of it).
  std::vector<double> wrong(lists_.size(), 0), charged = r.rate;
  for (std::size_t w = 0; w < s.size(); ++w) {
    for (std::uint64_t b = must_in_[w] & ~s[w]; b; b &= b - 1) {
      const std::size_t a = w * 64 + std::size_t(std::countr_zero(b));
      const std::size_t l = std::size_t(adder_list_[a]);
      wrong[l] += p_.atoms[a].volume;
      charged[l] = std::max(charged[l], r.last_deposit(a));
    }
    for (std::uint64_t b = must_out_[w] & s[w]; b; b &= b - 1) {
      const std::size_t a = w * 64 + std::size_t(std::countr_zero(b));
      wrong[std::size_t(remover_list_[a])] += p_.atoms[a].volume;
    }
  }
  // Some primitive must change each needed atom: the first of the list's suppliers used
  // pays its side effects and, beyond the rate the atom part charged, its own rate on the
  // list's wrong atoms (not when it falls short: then it may change only some). The
  // dearest such obligation counts.
  auto least = [&](std::size_t l) {
    const std::vector<int>& suppliers = lists_[l];
    double best = kInfinity;
    for (int i : suppliers) {
      if (!r.allowed[std::size_t(i)]) continue;
      const PrimitiveSpec& prim = p_.primitives[std::size_t(i)];
      const double dearer =
          prim.falls_short.words().empty() ? std::max(0.0, prim.cost_per_mm3 - charged[l]) * wrong[l] : 0.0;
      best = std::min(best, side[std::size_t(i)] + dearer);
    }
    return best;
  };
  // Adders and removers are never in one list (a list is of one mode), so each needed list
  // is an obligation of one kind.
  double add = 0, remove = 0;
  for (std::size_t l = 0; l < lists_.size(); ++l) {
    if (!needed[l] || lists_[l].empty()) continue;
    const bool adds = p_.primitives[std::size_t(lists_[l].front())].mode == Mode::Additive;
    (adds ? add : remove) = std::max(adds ? add : remove, least(l));
  }
  return {add, remove, std::move(side)};
}

// The tools and setups some needed atom of `state` can only be changed with.
void LowerBound::force(const AtomSet& state, const Rates& r, std::vector<bool>& tool_forced,
                       std::vector<bool>& setup_forced) const {
  // As bit masks over the primitives: the allowed ones of a list all of one tool (setup)
  // force it.
  std::vector<std::uint64_t> allowed_mask((p_.primitives.size() + 63) / 64, 0);
  for (std::size_t i = 0; i < p_.primitives.size(); ++i)
    if (r.allowed[i]) allowed_mask[i / 64] |= std::uint64_t{1} << (i % 64);
  auto force_one = [&](const std::vector<std::uint64_t>& list, const std::vector<int>& id,
                   const std::vector<std::vector<std::uint64_t>>& of_id, std::vector<bool>& forced) {
    int first_member = -1;
    for (std::size_t w = 0; w < list.size() && first_member < 0; ++w)
      if (list[w] & allowed_mask[w]) first_member = int(w * 64) + std::countr_zero(list[w] & allowed_mask[w]);
    if (first_member < 0) return;
    const auto& same = of_id[std::size_t(id[std::size_t(first_member)])];
    for (std::size_t w = 0; w < list.size(); ++w)
      if (list[w] & allowed_mask[w] & ~same[w]) return;
    forced[std::size_t(id[std::size_t(first_member)])] = true;
  };
  const std::vector<char> needed = needed_lists(state, true);
  for (std::size_t l = 0; l < lists_.size(); ++l)
    if (needed[l]) {
      force_one(list_mask_[l], tool_id_, tool_mask_, tool_forced);
      force_one(list_mask_[l], setup_id_, setup_mask_, setup_forced);
    }
}

double LowerBound::fixed_part(const AtomSet& state, const Rates& r, int last) const {
  const FixedCosts& f = p_.fixed;
  if (f.mode_switch == 0 && f.tool_change == 0 && f.setup_change == 0 && f.refixture == 0) return 0;
  // Right after a raw stock the next action comes with no change, as the first does
  // (fixed_cost): its tool and setup are free, and so is its mode.
  const bool first = last < 0;
  const bool after_stock = !first && p_.primitives[std::size_t(last)].raw_stock;
  const bool fresh = first || after_stock;
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
  bool stock_first = false;
  for (int i = 0; first && i < int(p_.primitives.size()); ++i) stock_first = stock_first || (p_.primitives[std::size_t(i)].raw_stock && allowed(i));
  int switches = 0;
  const bool removing = !first && p_.primitives[std::size_t(last)].mode == Mode::Subtractive;
  if (stock_first) {
    switches = 0;  // a raw stock, then removals alone: no switch is due (fixed_cost)
  } else if (after_stock) {
    // Both modes to come, or a deposit that leaves what a removal must take: one switch.
    switches = (need_add && (need_remove || every_adder_dirty)) ? 1 : 0;
  } else if (removing) {
    switches = need_add ? 1 + int(every_adder_dirty) : 0;
  } else {
    switches = need_remove || ((need_add || first) && every_adder_dirty) ? 1 : 0;
  }
  // Tools (setups) that some needed atom can only be changed with.
  std::vector<bool> tool_forced(tool_id_.size() + 1, false), setup_forced(setup_id_.size() + 1, false);
  force(state, r, tool_forced, setup_forced);
  for (std::size_t i = 0; i < p_.primitives.size(); ++i)
    if (p_.primitives[i].raw_stock) tool_forced[std::size_t(tool_id_[i])] = setup_forced[std::size_t(setup_id_[i])] = false;
  // Each forced tool other than the current one is changed to at least once; at the
  // start, the first action's tool comes free.
  auto changes = [&](const std::vector<bool>& forced, int current) {
    int n = 0;
    for (std::size_t t = 0; t < forced.size(); ++t) n += forced[t] && int(t) != current;
    return fresh ? std::max(0, n - 1) : n;
  };
  const int tools = changes(tool_forced, fresh ? -1 : tool_id_[std::size_t(last)]);
  // Each forced setup other than the current one is entered at least once, at no less than
  // its entry cost; at the start the dearest entry comes free (the first action's setup
  // is one of them, or none is forced).
  const int current = fresh ? -1 : setup_id_[std::size_t(last)];
  double setups = 0, dearest = 0;
  for (std::size_t t = 0; t < setup_forced.size(); ++t)
    if (setup_forced[t] && int(t) != current) setups += setup_entry_[t], dearest = std::max(dearest, setup_entry_[t]);
  if (fresh) setups -= dearest;
  return f.mode_switch * switches + f.tool_change * tools + setups;
}

double LowerBound::quick(const AtomSet& state, const std::vector<std::uint8_t>& uses, int last) const {
  return quick(state, usable(uses, last < 0), last);
}

double LowerBound::quick(const AtomSet& state, const std::vector<bool>& within, int last) const {
  const Rates r{*this, within};
  const AtomShares atoms = atom_part(state, r);
  if (atoms.deposits + atoms.removals == kInfinity) return kInfinity;
  return (atoms.deposits + atoms.removals + fixed_part(state, r, last)) / p_.normaliser;
}

double LowerBound::operator()(const AtomSet& state, const std::vector<std::uint8_t>& uses, int last) const {
  const Rates r = rates(uses, last < 0);
  const AtomShares atoms = atom_part(state, r);
  if (atoms.deposits + atoms.removals == kInfinity) return kInfinity;
  const SideShares side = side_effects(state, r);
  if (side.deposits + side.removals == kInfinity) return kInfinity;
  // Removing what is present (and depositing again the design a removal cuts) is one share,
  // bounded two ways: the larger counts. The design cut with what laying design last costs
  // beyond the atom part bounds that share and the side effects together.
  const DesignCut cut = removals_with_design_cut(state, r, side, atoms);
  const double removals = std::max(atoms.removals + side.removals, cut.plain);
  const double rest = std::max(side.deposits + removals, cut.relaid);
  return (atoms.deposits + rest + fixed_part(state, r, last)) / p_.normaliser;
}

}  // namespace hybridctl::planner
