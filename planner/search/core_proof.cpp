// A proof that no plan exists, from a few atoms (core_proof.hpp).

#include "planner/search/core_proof.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <tuple>

#include "planner/search/steps.hpp"

namespace hybridctl::planner {
namespace {

// A set of atoms of S, bit k for S's k-th atom, in W words (the fewest that hold S: the
// projected search's time goes into these).
template <int W>
struct Mask {
  static constexpr int kWords = W;
  std::array<std::uint64_t, kWords> w{};
  void set(std::size_t k) { w[k / 64] |= std::uint64_t{1} << (k % 64); }
  bool test(std::size_t k) const { return (w[k / 64] >> (k % 64)) & 1u; }
  bool any() const {
    for (const std::uint64_t x : w)
      if (x) return true;
    return false;
  }
  int count() const {
    int n = 0;
    for (const std::uint64_t x : w) n += std::popcount(x);
    return n;
  }
  friend Mask operator&(Mask a, const Mask& b) {
    for (int i = 0; i < kWords; ++i) a.w[std::size_t(i)] &= b.w[std::size_t(i)];
    return a;
  }
  friend Mask operator|(Mask a, const Mask& b) {
    for (int i = 0; i < kWords; ++i) a.w[std::size_t(i)] |= b.w[std::size_t(i)];
    return a;
  }
  friend Mask operator~(Mask a) {
    for (std::uint64_t& x : a.w) x = ~x;
    return a;
  }
  friend bool operator==(const Mask&, const Mask&) = default;
};

struct MaskHash {
  template <int W>
  std::size_t operator()(const Mask<W>& m) const {
    std::uint64_t h = 0x9E3779B97F4A7C15ull;
    for (const std::uint64_t x : m.w) h = (h ^ x) * 0xBF58476D1CE4E5B9ull, h ^= h >> 31;
    return std::size_t(h);
  }
};

// The members of `set` among the atoms of S, as bits of S's order.
template <int W>
Mask<W> bits_in(const AtomSet& set, const std::vector<int>& s) {
  Mask<W> m;
  if (set.words().empty()) return m;
  for (std::size_t k = 0; k < s.size(); ++k)
    if (set.test(s[k])) m.set(k);
  return m;
}

int members(const AtomSet& set) {
  int n = 0;
  for (const std::uint64_t w : set.words()) n += std::popcount(w);
  return n;
}

// What the projection looks through: atoms, and groups of carriers. A group's bit stands
// for "some atom of it may be present": a deposit that holds one of them sets it, a removal
// that holds them all clears it, nothing else does. Whenever one of its atoms is present
// in the whole problem, the bit is set; so a first layer whose every carrier is in S or in
// such a group, with none of those bits set, has nothing under it. One bit where the atoms
// would be tens of them: the projected states stay few.
struct Core {
  std::vector<int> atoms;          // bit k: atoms[k]
  std::vector<AtomSet> groups;     // bit atoms.size() + g: groups[g]
  std::vector<char> has;           // per atom of the problem: in `atoms`
  std::size_t size() const { return atoms.size() + groups.size(); }
  int group_of(const AtomSet& c) const {
    for (std::size_t g = 0; g < groups.size(); ++g)
      if (groups[g] == c) return int(g);
    return -1;
  }
};

bool meets(const AtomSet& a, const AtomSet& b, const AtomSet& less) {
  const auto &x = a.words(), &y = b.words(), &z = less.words();
  for (std::size_t w = 0; w < x.size() && w < y.size(); ++w)
    if (x[w] & y[w] & ~(w < z.size() ? z[w] : 0)) return true;
  return false;
}

// Whether every member of `c` is in `a` less `less`.
bool holds_all(const AtomSet& a, const AtomSet& c, const AtomSet& less) {
  const auto &x = a.words(), &y = c.words(), &z = less.words();
  for (std::size_t w = 0; w < y.size(); ++w)
    if (y[w] & ~((w < x.size() ? x[w] : 0) & ~(w < z.size() ? z[w] : 0))) return false;
  return true;
}

// A primitive as the projection on S sees it.
template <int W>
struct ProjectedPrimitive {
  using Mask = hybridctl::planner::Mask<W>;
  int index = 0;       // in the problem
  bool additive = false;
  bool first = false;  // may start a plan
  bool later = false;  // may come later
  Mask all;            // its atoms in S
  Mask begun;          // ... less those it falls short of once the plan has begun
  // Per atom of S that something in S blocks the head from: what does. Per atom whose
  // every possible carrier is in S: those. Only these atoms are asked when deposited.
  struct Condition {
    std::size_t atom;
    Mask set;
    friend bool operator==(const Condition&, const Condition&) = default;
  };
  Mask blocked, carried;
  std::vector<Condition> blockers, carriers;

  bool same(const ProjectedPrimitive& o) const {
    return additive == o.additive && first == o.first && later == o.later && all == o.all && begun == o.begun &&
           blockers == o.blockers && carriers == o.carriers;
  }
};

template <int W>
struct Projection {
  using Mask = hybridctl::planner::Mask<W>;
  // One of each: primitives that act alike on S are one to the projected search.
  std::vector<ProjectedPrimitive<W>> primitives;
  Mask must_in, must_out;
};

template <int W>
Projection<W> project(const PlanningProblem& p, const Core& core) {
  using Mask = hybridctl::planner::Mask<W>;
  const std::vector<int>& s = core.atoms;
  const std::size_t a0 = s.size();  // the first group's bit
  const AtomSet none;
  Projection<W> pr;
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (p.atoms[std::size_t(s[k])].must_in) pr.must_in.set(k);
    if (p.atoms[std::size_t(s[k])].must_out) pr.must_out.set(k);
  }
  const std::vector<std::uint8_t> no_uses(p.primitives.size(), 0);
  for (std::size_t i = 0; i < p.primitives.size(); ++i) {
    const PrimitiveSpec& prim = p.primitives[i];
    ProjectedPrimitive<W> q;
    q.index = int(i);
    q.additive = prim.mode == Mode::Additive;
    q.first = detail::allowed(p, int(i), true, no_uses) && members(prim.atoms) > 0;  // a step changes something
    q.later = detail::allowed(p, int(i), false, no_uses);
    q.all = bits_in<W>(prim.atoms, s);
    q.begun = q.all & ~bits_in<W>(prim.falls_short, s);
    for (std::size_t g = 0; g < core.groups.size(); ++g) {
      const AtomSet& c = core.groups[g];
      if (q.additive ? meets(prim.atoms, c, none) : holds_all(prim.atoms, c, none)) q.all.set(a0 + g);
      if (q.additive ? meets(prim.atoms, c, prim.falls_short) : holds_all(prim.atoms, c, prim.falls_short))
        q.begun.set(a0 + g);
    }
    for (std::size_t k = 0; k < s.size() && q.additive; ++k) {
      if (!q.all.test(k)) continue;
      if (const Mask over = prim.blocked_by ? bits_in<W>((*prim.blocked_by)[std::size_t(s[k])], s) : Mask{}; over.any())
        q.blocked.set(k), q.blockers.push_back({k, over});
      if (!prim.footing || prim.footing->kind[std::size_t(s[k])] != DepositFooting::NeedsCarrier) continue;
      // A carrier outside S is taken as present: only carriers all in S, or in a group
      // of S, can be missing.
      const AtomSet& carriers = prim.footing->carriers[std::size_t(s[k])];
      Mask in_s = bits_in<W>(carriers, s);
      const bool exact = in_s.count() == members(carriers);
      if (!exact) {  // the group's bit only where the atoms do not tell (it may be set with none present)
        const int g = core.group_of(carriers);
        if (g < 0) continue;
        in_s.set(a0 + std::size_t(g));
      }
      q.carried.set(k), q.carriers.push_back({k, in_s});
    }
    if (std::none_of(pr.primitives.begin(), pr.primitives.end(), [&](const ProjectedPrimitive<W>& o) { return o.same(q); }))
      pr.primitives.push_back(std::move(q));
  }
  return pr;
}

// The projected state after primitive q, or false when it changes nothing in S or may not
// be taken there.
template <int W>
bool step(const ProjectedPrimitive<W>& q, const Mask<W>& state, bool first, Mask<W>& next) {
  using Mask = hybridctl::planner::Mask<W>;
  const Mask& does = first ? q.all : q.begun;
  if (!q.additive) {
    const Mask changed = does & state;
    next = state & ~changed;
    return changed.any();
  }
  const Mask changed = does & ~state;
  if (!changed.any() && !first) return false;
  if ((changed & q.blocked).any())
    for (const auto& c : q.blockers)
      if (changed.test(c.atom) && (c.set & state).any()) return false;
  if (!first && (changed & q.carried).any())
    for (const auto& c : q.carriers)
      if (changed.test(c.atom) && !(c.set & state).any()) return false;
  next = state | changed;
  return true;
}

enum class Search { NoPlan, Plan, Limit };

// Breadth first over the projected states; on Plan, `sequence` reaches the projected goal.
// `states` counts the states reached, and the search stops when it passes `max_states`.
template <int W>
Search search_projection(const Projection<W>& pr, const CoreProofLimits& limits, std::int64_t& states,
                         std::vector<int>& sequence) {
  using Mask = hybridctl::planner::Mask<W>;
  struct Node {
    Mask state;
    int parent;  // -1: the plan's first action made it
    int primitive;
  };
  std::vector<Node> nodes;  // in the order reached: breadth first, they are the queue
  // Begun states, as indices into `nodes` plus one (0: empty), open addressing; the start
  // (nothing, not begun) is apart.
  std::vector<std::uint32_t> slots(std::size_t(1) << 12, 0);
  const auto slot_of = [&](const Mask& m) {
    std::size_t h = MaskHash{}(m) & (slots.size() - 1);
    while (slots[h] && !(nodes[slots[h] - 1].state == m)) h = (h + 1) & (slots.size() - 1);
    return h;
  };
  const auto grow = [&] {
    std::vector<std::uint32_t> old(slots.size() * 2, 0);
    old.swap(slots);
    for (const std::uint32_t n : old)
      if (n) slots[slot_of(nodes[n - 1].state)] = n;
  };
  const auto goal = [&](const Mask& m) { return (m & pr.must_in) == pr.must_in && !(m & pr.must_out).any(); };
  // Every successor of a node (-1: the start), until the goal or the limit.
  const auto expand = [&](int at) {
    const bool first = at < 0;
    const Mask state = first ? Mask{} : nodes[std::size_t(at)].state;
    for (const ProjectedPrimitive<W>& q : pr.primitives) {
      Mask next;
      if (!(first ? q.first : q.later) || !step(q, state, first, next)) continue;
      const std::size_t h = slot_of(next);
      if (slots[h]) continue;
      if (++states > limits.max_states || (limits.stop && states % 4096 == 0 && limits.stop->load())) return Search::Limit;
      nodes.push_back({next, at, q.index});
      slots[h] = std::uint32_t(nodes.size());
      if (goal(next)) {
        sequence.clear();
        for (int n = int(nodes.size()) - 1; n >= 0; n = nodes[std::size_t(n)].parent)
          sequence.push_back(nodes[std::size_t(n)].primitive);
        std::reverse(sequence.begin(), sequence.end());
        return Search::Plan;
      }
      if (nodes.size() * 2 > slots.size()) grow();
    }
    return Search::NoPlan;
  };
  for (int at = -1; at < int(nodes.size()); ++at)
    if (const Search s = expand(at); s != Search::NoPlan) return s;
  return Search::NoPlan;
}

// Atoms and carrier groups that join S, and why.
struct Explanation {
  std::vector<int> atoms;
  std::vector<AtomSet> groups;
  CoreProof::Why why = CoreProof::Why::WrongAtTheEnd;
};

// Where a projected plan goes wrong in the whole problem: the atoms outside S that show it
// (empty with `goal` when it makes the part, empty without when nothing explains it).
struct Replay {
  bool goal = false;
  bool too_many_uses = false;  // a primitive used more than max_uses times (before the goal)
  std::size_t steps = 0;  // on goal: the steps taken when it was first reached
  Explanation what;       // else: what joins S
};

// What keeps a deposit from being taken in `state`: an atom out of reach and a present
// atom that blocks it, or an atom of a first layer and its carriers (as a group, or all of
// them when the group is already in S); of these, the explanation that adds the fewest
// members to S: S stays small, and the projected states with it.
Explanation why_refused(const PlanningProblem& p, const PrimitiveSpec& prim, const AtomSet& state, bool first,
                        const Core& core) {
  constexpr int kMostCarriers = 256;
  const auto& s = state.words();
  const auto& a = prim.atoms.words();
  const auto& short_of = prim.falls_short.words();
  Explanation best;
  int fewest = kMostCarriers + 2;
  const auto consider = [&](Explanation e) {
    int added = int(e.groups.size());
    for (const int x : e.atoms) added += core.has[std::size_t(x)] == 0;
    for (const AtomSet& g : e.groups) added -= core.group_of(g) >= 0;
    if (added > 0 && added < fewest) fewest = added, best = std::move(e);
  };
  for (std::size_t w = 0; w < a.size(); ++w) {
    const std::uint64_t does = !first && w < short_of.size() ? a[w] & ~short_of[w] : a[w];
    for (std::uint64_t b = does & ~s[w]; b; b &= b - 1) {
      const int atom = int(w * 64) + std::countr_zero(b);
      if (prim.blocked_by && prim.blocked_by->meets(std::size_t(atom), s)) {
        const auto& blockers = (*prim.blocked_by)[std::size_t(atom)].words();
        // A present one, in S when one is, else one that must be made or left empty, the
        // largest: the body of the part in the head's way rather than a row of voxels
        // along one of its edges, which would join S only to stand for it (docs/search.md).
        int blocker = -1;
        const auto rank = [&](int x) {
          const AtomSpec& spec = p.atoms[std::size_t(x)];
          return std::tuple{core.has[std::size_t(x)] != 0, spec.must_in || spec.must_out, spec.volume};
        };
        for (std::size_t v = 0; v < blockers.size(); ++v)
          for (std::uint64_t hit = blockers[v] & s[v]; hit; hit &= hit - 1) {
            const int x = int(v * 64) + std::countr_zero(hit);
            if (blocker < 0 || rank(x) > rank(blocker)) blocker = x;
          }
        consider({{atom, blocker}, {}, CoreProof::Why::OutOfReach});
      }
      if (first || !prim.footing || prim.footing->kind[std::size_t(atom)] != DepositFooting::NeedsCarrier ||
          prim.footing->carriers.meets(std::size_t(atom), s))
        continue;
      const AtomSet& carriers = prim.footing->carriers[std::size_t(atom)];
      consider({{atom}, {carriers}, CoreProof::Why::NothingUnder});
      if (members(carriers) > kMostCarriers) continue;
      Explanation each{{atom}, {}, CoreProof::Why::NothingUnder};
      for (int c = 0; c < int(p.atoms.size()) && !carriers.words().empty(); ++c)
        if (carriers.test(c)) each.atoms.push_back(c);
      consider(std::move(each));
    }
  }
  return best;
}

Replay replay(const PlanningProblem& p, const std::vector<int>& sequence, const Core& core, int atoms_per_round) {
  Replay r;
  AtomSet state(int(p.atoms.size()));
  bool first = true;
  std::vector<int> uses(p.primitives.size(), 0);
  for (const int i : sequence) {
    // The projection allows any number of uses: a plan that needs more is no plan, but
    // where it goes wrong otherwise still names atoms.
    r.too_many_uses = r.too_many_uses || ++uses[std::size_t(i)] > p.max_uses;
    AtomSet next;
    double volume = 0;
    if (!apply(p, state, i, next, volume, first)) {
      r.what = why_refused(p, p.primitives[std::size_t(i)], state, first, core);
      return r;
    }
    state = std::move(next);
    first = false;
    ++r.steps;
    if (is_goal(p, state)) return r.goal = true, r;
  }
  // Atoms wrong at the end: the largest first (docs/search.md: with carriers as groups,
  // this needs the fewest projected states on the bundled parts).
  std::vector<int> wrong;
  for (int a = 0; a < int(p.atoms.size()); ++a) {
    const AtomSpec& spec = p.atoms[std::size_t(a)];
    if (spec.must_in != state.test(a) && (spec.must_in || spec.must_out)) wrong.push_back(a);
  }
  std::stable_sort(wrong.begin(), wrong.end(),
                   [&](int x, int y) { return p.atoms[std::size_t(x)].volume > p.atoms[std::size_t(y)].volume; });
  wrong.resize(std::min(wrong.size(), std::size_t(atoms_per_round)));
  r.what.atoms = std::move(wrong);
  return r;
}

// Whether no projected plan gets every atom of `core` right: a proof on its own.
// Limit when the search passes `max_states` (counted in `states`).
Search search_core(const PlanningProblem& p, const Core& core, const CoreProofLimits& limits, std::int64_t& states) {
  std::vector<int> sequence;
  const std::size_t n = core.size();
  return n <= 64    ? search_projection(project<1>(p, core), limits, states, sequence)
         : n <= 128 ? search_projection(project<2>(p, core), limits, states, sequence)
         : n <= 256 ? search_projection(project<4>(p, core), limits, states, sequence)
                    : search_projection(project<8>(p, core), limits, states, sequence);
}

// S as the refinement leaves it holds every atom that refuted some projected plan on the
// way, many of them needed by none of the later ones: a row of voxels along an edge that
// an undersized deposit leaves out, a blocker of a deposit that a later atom rules out
// anyway. The verdict names S's atoms, so each is dropped in turn where the smaller S
// still proves: what is left are atoms the proof needs, every one (none of them can go).
// The band's atoms are tried first (they only carry or block), then the smallest, and
// air that only a cut into the design clears last, so that what stays is rather what the
// part cannot get than a voxel layer along its faces. Each drop is a proof on its own, so
// running out of `limits.minimise_states` (or being stopped) leaves a proof too, a larger one.
void minimise(const PlanningProblem& p, Core& core, const CoreProofLimits& given, std::int64_t& states) {
  std::vector<std::pair<std::tuple<bool, bool, double>, int>> keyed;
  for (const int a : core.atoms) {
    const AtomSpec& spec = p.atoms[std::size_t(a)];
    keyed.push_back({{cleared_only_by_cutting(p, a), spec.must_in || spec.must_out, spec.volume}, a});
  }
  std::stable_sort(keyed.begin(), keyed.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<int> order;
  for (const auto& [key, a] : keyed) order.push_back(a);
  CoreProofLimits limits = given;
  limits.max_states = given.minimise_states;
  std::int64_t spent = 0;
  for (const int a : order) {
    if (core.atoms.size() <= 1) break;
    Core smaller = core;
    std::erase(smaller.atoms, a);
    smaller.has[std::size_t(a)] = 0;
    std::int64_t tried = spent;
    const Search s = search_core(p, smaller, limits, tried);
    states += tried - spent;
    spent = tried;
    if (s == Search::Limit) return;
    if (s == Search::NoPlan) core = std::move(smaller);
  }
}

}  // namespace

bool projection_refutes(const PlanningProblem& p, const std::vector<int>& atoms, const std::vector<AtomSet>& groups,
                        std::int64_t max_states) {
  Core core;
  core.has.assign(p.atoms.size(), 0);
  for (const int a : atoms)
    if (!core.has[std::size_t(a)]) core.atoms.push_back(a), core.has[std::size_t(a)] = 1;
  core.groups = groups;
  if (core.size() > std::size_t(64 * kCoreWords)) return false;
  CoreProofLimits limits;
  limits.max_states = max_states;
  std::int64_t states = 0;
  return search_core(p, core, limits, states) == Search::NoPlan;
}

bool cleared_only_by_cutting(const PlanningProblem& p, int atom) {
  if (!p.atoms[std::size_t(atom)].must_out) return false;
  AtomSet design(int(p.atoms.size()));
  for (std::size_t a = 0; a < p.atoms.size(); ++a)
    if (p.atoms[a].must_in) design.set(int(a));
  bool in_stock = false;
  for (const PrimitiveSpec& prim : p.primitives) {
    if (!prim.atoms.test(atom)) continue;
    if (prim.mode == Mode::Additive) in_stock = in_stock || prim.raw_stock;
    else if (!meets(prim.atoms, design, AtomSet{})) return false;
  }
  return in_stock;
}

CoreProof prove_by_core(const PlanningProblem& p, const CoreProofLimits& limits) {
  CoreProof proof;
  Core core;
  core.has.assign(p.atoms.size(), 0);
  for (;;) {
    ++proof.rounds;
    std::vector<int> sequence;
    const std::size_t n = core.size();
    const Search found = n <= 64    ? search_projection(project<1>(p, core), limits, proof.states, sequence)
                         : n <= 128 ? search_projection(project<2>(p, core), limits, proof.states, sequence)
                         : n <= 256 ? search_projection(project<4>(p, core), limits, proof.states, sequence)
                                    : search_projection(project<8>(p, core), limits, proof.states, sequence);
    if (found == Search::Limit) return proof;
    if (found == Search::NoPlan) {
      proof.outcome = CoreProof::Outcome::Proven;
      proof.found = int(core.atoms.size());
      minimise(p, core, limits, proof.minimising_states);
      proof.core = core.atoms;
      proof.groups = core.groups;
      std::sort(proof.core.begin(), proof.core.end());
      return proof;
    }
    Replay r = replay(p, sequence, core, limits.atoms_per_round);
    if (r.goal && r.too_many_uses) {
      sequence.resize(r.steps);
      for (const int i : sequence)
        proof.reuse_needed = std::max(proof.reuse_needed, int(std::count(sequence.begin(), sequence.end(), i)));
      proof.sequence = std::move(sequence);
      return proof;
    }
    if (r.goal) {
      proof.outcome = CoreProof::Outcome::Feasible;
      sequence.resize(r.steps);
      proof.sequence = std::move(sequence);
      return proof;
    }
    std::vector<int>& atoms = r.what.atoms;
    std::sort(atoms.begin(), atoms.end());  // an atom may carry itself: once in S
    atoms.erase(std::unique(atoms.begin(), atoms.end()), atoms.end());
    std::erase_if(atoms, [&](int a) { return core.has[std::size_t(a)] != 0; });
    std::erase_if(r.what.groups, [&](const AtomSet& g) { return core.group_of(g) >= 0; });
    const std::size_t added = atoms.size() + r.what.groups.size();
    if (added == 0 || int(core.size() + added) > limits.max_atoms) return proof;
    for (const int a : atoms) core.atoms.push_back(a), core.has[std::size_t(a)] = 1;
    for (AtomSet& g : r.what.groups) core.groups.push_back(std::move(g));
    proof.joined[int(r.what.why)] += int(added);
  }
}

}  // namespace hybridctl::planner
