#include "validation/execution.hpp"

#include <algorithm>
#include <cstdint>
#include <list>
#include <map>
#include <optional>
#include <span>
#include <utility>

#include "common/error.hpp"
#include "common/number_text.hpp"
#include "gcode/post.hpp"
#include "plan/start_stock.hpp"
#include "sim/executor.hpp"
#include "validation/prefix_cache.hpp"

namespace hybridctl::validation {
namespace {

using geometry::Solid;

// `s` on the plan's lattice with the plan's domain as its storage: the simulated world is
// the domain planning looked at, so deposit beyond the raw stock's box is not lost.
Solid on_domain(const Solid& s, const plan::PlanFile& file) {
  Solid out(file.lattice, file.domain);
  const geometry::IndexBox& d = file.domain;
  const geometry::IndexBox rows = geometry::box_intersection(s.storage_box(), d);
  if (rows.empty()) return out;
  // Word by word: both solids number words from x = 0, so words line up.
  const int w0 = std::max(s.first_word(), out.first_word());
  const int w1 = std::min(s.first_word() + s.words_per_row(), out.first_word() + out.words_per_row());
  for (int z = rows.lo.z; z < rows.hi.z; ++z)
    for (int y = rows.lo.y; y < rows.hi.y; ++y) {
      const std::span<const std::uint64_t> from = s.row(y, z);
      const std::span<std::uint64_t> to = out.row(y, z);
      for (int w = w0; w < w1; ++w) {
        // Only voxels of the domain along x: bits [a, b) of the word.
        const int a = std::max(d.lo.x - w * 64, 0), b = std::min(d.hi.x - w * 64, 64);
        if (a >= b) continue;
        const std::uint64_t upper = b == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << b) - 1;
        to[std::size_t(w - out.first_word())] = from[std::size_t(w - s.first_word())] & upper & (~std::uint64_t{0} << a);
      }
    }
  return out;
}

// What a run holds after a prefix of a plan that went right: all it needs to go on with
// the next action (the programs made so far are those of `actions` that make G-code).
struct PrefixState {
  sim::ProgramExecutor::Snapshot executor;
  std::vector<toolpaths::ExportedAction> actions;  // light: without their solids
  gcode::PostedProgram prefix;
  std::size_t fed = 0;
  int protecting = 0;
  std::vector<std::string> errors;
  std::size_t bytes = 0;
};

std::size_t program_bytes(const gcode::ActionProgram& p) {
  std::size_t n = sizeof(p) + p.path.moves.size() * sizeof(gcode::PathMove);
  for (const gcode::PathMove& m : p.path.moves) n += m.comment.capacity();
  for (const std::string& w : p.path.warnings) n += sizeof(w) + w.capacity();
  return n + p.path.defects.size() * sizeof(gcode::PathDefect);
}

std::size_t state_bytes(const PrefixState& s) {
  std::size_t n = sizeof(s) + s.executor.bytes();
  for (const toolpaths::ExportedAction& a : s.actions) n += sizeof(a) + program_bytes(a.program);
  for (const std::string& l : s.prefix.lines) n += sizeof(l) + l.capacity();
  n += s.prefix.origins.size() * sizeof(gcode::LineOrigin) + s.prefix.actions.size() * sizeof(gcode::ProgramAction);
  return n;
}

}  // namespace

namespace detail {

// Prefixes by the primitives of their actions, least recently used first.
struct PrefixCacheImpl {
  using Entry = std::pair<std::vector<int>, PrefixState>;
  std::size_t max_bytes = 0;
  PrefixCacheStats stats;
  std::list<Entry> lru;  // front: most recently used
  std::map<std::vector<int>, std::list<Entry>::iterator> index;
  const plan::PlanFile* file = nullptr;
  const config::Machine* machine = nullptr;
  std::optional<Solid> core;  // the file's design shrunk by its tolerance, once

  void clear() {
    lru.clear();
    index.clear();
    stats.entries = 0;
    stats.bytes = 0;
    core.reset();
  }
  // Empties the cache when it is asked about another file or machine than the last.
  void serve(const plan::PlanFile& f, const config::Machine& m) {
    if (file == &f && machine == &m) return;
    clear();
    file = &f;
    machine = &m;
  }
  // The longest prefix of `actions` held, marked used.
  const PrefixState* longest(const std::vector<int>& actions) {
    ++stats.lookups;
    for (std::size_t k = actions.size(); k > 0; --k) {
      const auto it = index.find(std::vector<int>(actions.begin(), actions.begin() + std::ptrdiff_t(k)));
      if (it == index.end()) continue;
      lru.splice(lru.begin(), lru, it->second);
      ++stats.hits;
      stats.resumed_actions += k;
      return &it->second->second;
    }
    return nullptr;
  }
  void store(std::vector<int> key, PrefixState state) {
    state.bytes = state_bytes(state);
    if (state.bytes > max_bytes) return;
    if (const auto it = index.find(key); it != index.end()) {
      stats.bytes -= it->second->second.bytes;
      lru.erase(it->second);
      index.erase(it);
      --stats.entries;
    }
    while (!lru.empty() && stats.bytes + state.bytes > max_bytes) {
      stats.bytes -= lru.back().second.bytes;
      index.erase(lru.back().first);
      lru.pop_back();
      --stats.entries;
      ++stats.evicted;
    }
    stats.bytes += state.bytes;
    ++stats.entries;
    ++stats.stored;
    lru.emplace_front(key, std::move(state));
    index.emplace(std::move(key), lru.begin());
  }
};

}  // namespace detail

PrefixCache::PrefixCache(std::size_t max_bytes) : impl_(std::make_unique<detail::PrefixCacheImpl>()) {
  impl_->max_bytes = max_bytes;
}
PrefixCache::~PrefixCache() = default;
const PrefixCacheStats& PrefixCache::stats() const { return impl_->stats; }
std::size_t PrefixCache::max_bytes() const { return impl_->max_bytes; }
void PrefixCache::clear() { impl_->clear(); }

namespace {

// The step of the plan's last action that adds material, the raw stock included (0: none).
int last_addition(const plan::PlanFile& file, const plan::PlanFilePlan& plan) {
  for (std::size_t k = plan.actions.size(); k > 0; --k)
    if (file.primitives.at(std::size_t(plan.actions[k - 1].primitive)).mode == config::Mode::Additive) return int(k);
  return 0;
}

// Where a set of voxels is, in one point: the centre of its voxel nearest to its centroid
// (the first voxel would be a corner of the part whenever an edge is missing).
std::optional<geometry::Vec3> central_voxel(const Solid& voxels) {
  double n = 0, x = 0, y = 0, z = 0;
  voxels.for_each_voxel([&](geometry::Index3 v) { n += 1, x += v.x, y += v.y, z += v.z; });
  if (n == 0) return std::nullopt;
  const double cx = x / n, cy = y / n, cz = z / n;
  geometry::Index3 best{};
  double nearest = -1;
  voxels.for_each_voxel([&](geometry::Index3 v) {
    const double d = (v.x - cx) * (v.x - cx) + (v.y - cy) * (v.y - cy) + (v.z - cz) * (v.z - cz);
    if (nearest < 0 || d < nearest) nearest = d, best = v;
  });
  return voxels.lattice().center(best);
}

// The whole plan's program fed to the simulated machine action by action. After each
// action the program of the actions made so far is posted and its lines up to the end of
// the newest action's block are executed: the post-processor writes an action's block from
// it and the one before only, so these are the lines of the final program, and incidents
// carry its line numbers.
class IncrementalRun {
 public:
  IncrementalRun(const config::Machine& machine, const plan::PlanFile& file, const plan::PlanFilePlan& plan,
                 Solid start, const ExecutionOptions& options)
      : machine_(machine),
        file_(file),
        plan_(plan),
        options_(options),
        executor_(machine, "plan", executor_options(file, start, options)) {}

  // Going on after a prefix of `plan` run before (same file, machine and options).
  IncrementalRun(const config::Machine& machine, const plan::PlanFile& file, const plan::PlanFilePlan& plan,
                 const PrefixState& from, const ExecutionOptions& options)
      : machine_(machine),
        file_(file),
        plan_(plan),
        options_(options),
        executor_(from.executor),
        actions_(from.actions),
        prefix_(from.prefix),
        fed_(from.fed),
        protecting_(from.protecting),
        errors_(from.errors) {
    for (const toolpaths::ExportedAction& a : actions_)
      if (a.makes_gcode) made_.push_back(a.program);
  }

  // Keeps the state after every action that went right, as all before it did, in `cache`.
  void keep_in(detail::PrefixCacheImpl* cache) { cache_ = cache; }

  // With RunUntil::FirstFailingAction, once the plan's last action that adds material
  // (the raw stock counts) has run: throws Stopped when part of the design's core is missing, as
  // the actions after it only remove. Every voxel of the core lies farther than the
  // tolerance from the design's other side, so the part would be out of tolerance
  // (plan/deviation.hpp, worst_out); stopping here spares running the removals.
  void check_core_after(int step) {
    if (options_.run_until != RunUntil::FirstFailingAction || core_checked_ || step < last_addition()) return;
    core_checked_ = true;
    const Solid& core = design_core();
    const Solid missing = subtract(core, on_domain(executor_.stock(), file_));
    if (missing.empty()) return;
    const std::optional<geometry::Vec3> where = central_voxel(missing);
    const int last = last_addition();
    const plan::PlanFilePrimitive& p = file_.primitives.at(std::size_t(plan_.actions.at(std::size_t(last - 1)).primitive));
    throw Stopped{step, plan::RejectionReason{
                            "missing_material", last, 0,
                            "after action " + std::to_string(last) + " (" + p.name +
                                "), the last that adds material, " + fixed_number(missing.volume(), 1) +
                                " mm^3 of the design's core (the design shrunk by the planning band, which a part within it "
                                "holds) is missing, and the removals after it cannot add it",
                            where}};
  }
  int last_addition() const { return validation::last_addition(file_, plan_); }

  // The material present now, as after() returns it.
  Solid present() const { return on_domain(executor_.stock(), file_); }

  // Programs made without feedback: executed at finish().
  void take(std::vector<gcode::ActionProgram> programs) { made_ = std::move(programs); }

  // The material present after `made`, its program executed. With
  // RunUntil::FirstFailingAction, throws Stopped after an action that went wrong.
  Solid after(const toolpaths::ExportedAction& made) {
    toolpaths::ExportedAction light;  // what the reasons need, without the solids
    light.step = made.step;
    light.primitive = made.primitive;
    light.makes_gcode = made.makes_gcode;
    light.note = made.note;
    light.program = made.program;
    light.laid = made.laid;  // where a resumed export goes on from
    actions_.push_back(std::move(light));
    if (made.makes_gcode) {
      made_.push_back(made.program);
      prefix_ = gcode::post_program(made_, machine_, options_.export_options.post);
      feed(prefix_, prefix_.actions.back().last_line);
    }
    const bool wrong = !made.program.path.defects.empty() || !errors_.empty() || !executor_.report().incidents.empty();
    if (options_.run_until == RunUntil::FirstFailingAction && wrong) throw Stopped{made.step, std::nullopt};
    // Only a prefix that went right is kept: it is the same whatever RunUntil says (and
    // whatever the plan does after it).
    right_ = right_ && !wrong;
    if (cache_ && right_) keep(made.step);
    check_core_after(made.step);
    return on_domain(executor_.stock(), file_);
  }

  // Thrown by after() to stop at the first action that went wrong; `missing` when it is
  // the core missing after the last addition (check_core_after).
  struct Stopped {
    int action = 0;
    std::optional<plan::RejectionReason> missing;
  };

  // Stopped early: what ran so far.
  void stopped(Execution& out) {
    out.exported.actions = std::move(actions_);
    out.program = std::move(prefix_);
    out.report = executor_.report();
    out.as_built = on_domain(executor_.stock(), file_);
    out.errors = std::move(errors_);
  }

  // The final program, every line of it executed.
  gcode::PostedProgram finish(Execution& out) {
    // A plan with no G-code (the raw stock alone) runs no program.
    gcode::PostedProgram program;
    if (!made_.empty()) program = gcode::post_program(made_, machine_, options_.export_options.post);
    feed(program, program.lines.size());
    out.report = executor_.report();
    out.as_built = on_domain(executor_.stock(), file_);
    out.errors = std::move(errors_);
    return program;
  }

 private:
  static sim::ExecutorOptions executor_options(const plan::PlanFile& file, Solid start,
                                               const ExecutionOptions& options) {
    sim::ExecutorOptions o;
    o.stock = std::move(start);
    o.protected_region = plan::spared_by_cuts(file);  // the header's lines, before any action
    o.simulation = options.simulation;
    return o;
  }
  void keep(int actions) {
    std::vector<int> key;
    for (int k = 0; k < actions; ++k) key.push_back(plan_.actions[std::size_t(k)].primitive);
    PrefixState state;
    state.executor = executor_.snapshot();
    state.actions = actions_;
    state.prefix = prefix_;
    state.fed = fed_;
    state.protecting = protecting_;
    state.errors = errors_;
    cache_->store(std::move(key), std::move(state));
  }
  void feed(const gcode::PostedProgram& program, std::size_t up_to) {
    for (; fed_ < up_to && fed_ < program.lines.size(); ++fed_) {
      protect_for(program.action_at(std::uint32_t(fed_ + 1)));
      const sim::LineOutcome o = executor_.execute_line(program.lines[fed_], int(fed_ + 1));
      if (o.stop != sim::Stop::None && o.stop != sim::Stop::RapidIntoMaterial) errors_.push_back(o.message);
    }
  }

  // Each action's lines spare what that action keeps of the design, not the whole design:
  // a removal may cut design material a later deposit builds again (plan/start_stock.hpp).
  void protect_for(const gcode::ProgramAction* action) {
    if (!action || action->number == protecting_) return;
    protecting_ = action->number;
    const plan::PlanFilePrimitive& p =
        file_.primitives.at(std::size_t(plan_.actions.at(std::size_t(action->number - 1)).primitive));
    executor_.set_protected_region(plan::spared_by_cuts(file_, &p));
  }

  const Solid& design_core() {
    if (cache_) {
      if (!cache_->core) cache_->core = plan::spared_by_cuts(file_);
      return *cache_->core;
    }
    if (!core_) core_ = plan::spared_by_cuts(file_);
    return *core_;
  }

  const config::Machine& machine_;
  const plan::PlanFile& file_;
  const plan::PlanFilePlan& plan_;
  const ExecutionOptions& options_;
  sim::ProgramExecutor executor_;
  std::vector<gcode::ActionProgram> made_;
  std::vector<toolpaths::ExportedAction> actions_;
  gcode::PostedProgram prefix_;
  std::size_t fed_ = 0;
  int protecting_ = 0;  // the action whose spared region the executor holds (0: none yet)
  std::vector<std::string> errors_;
  detail::PrefixCacheImpl* cache_ = nullptr;
  std::optional<Solid> core_;  // without a cache
  bool core_checked_ = false;
  bool right_ = true;  // every action so far went right (a resumed run starts from such a prefix)
};

// The part a plan that passed on the voxels makes, against the design's real surface: its
// figures, and a reason for each direction beyond the tolerance.
void verify_exactly(Execution& out, const plan::PlanFile& file, const plan::PlanFilePlan& plan,
                    const config::Machine& machine, const ExecutionOptions& options) {
  verification::DesignSurfaces read_here;
  verification::DesignSurfaces& surfaces = options.surfaces ? *options.surfaces : read_here;
  const verification::DesignSurface* surface = surfaces.for_plan(file);
  if (!surface) return;
  out.exact = verification::verify_program(*surface, machine, out.program, plan::start_stock(file, plan, machine),
                                           {file.tolerance});
  const auto reason = [&](const char* kind, const char* what, const plan::ExactPlace& p) {
    out.reasons.push_back({kind, p.action, p.line,
                           std::string("the part made ") + what + " the design's surface by " + (p.at_least ? "at least " : "") +
                               fixed_number(p.mm, 3) + " mm (exact verification, tolerance " +
                               shortest_number(file.tolerance) + " mm" + (p.as_deposited ? ", as deposited" : "") + ")",
                           p.at});
  };
  if (out.exact->excess.mm > file.tolerance) reason("exact_excess", "stands out of", out.exact->excess);
  if (out.exact->gouge.mm > file.tolerance) reason("exact_gouge", "lies inside", out.exact->gouge);
}

// Exports and executes `plan` with `run`, from `start` when it resumes a prefix.
Execution run_plan(const plan::PlanFile& file, const plan::PlanFilePlan& plan, const config::Machine& machine,
                   const ExecutionOptions& options, IncrementalRun& run, std::optional<toolpaths::ExportStart> start) {
  Execution out;
  if (options.planned_against == PlannedAgainst::MaterialPresent) {
    try {
      // A resumed prefix may already hold the last addition.
      if (start) run.check_core_after(int(start->actions.size()));
      const toolpaths::MaterialAfter after = [&run](const toolpaths::ExportedAction& made) { return run.after(made); };
      out.exported = start ? toolpaths::export_plan(file, plan, machine, options.export_options, after, std::move(*start))
                           : toolpaths::export_plan(file, plan, machine, options.export_options, after);
    } catch (const IncrementalRun::Stopped& stop) {
      run.stopped(out);
      out.stopped_after = stop.action;
      out.reasons = rejection_reasons(out, file, machine);
      if (stop.missing) {
        out.missing_after_last_addition = true;
        out.reasons.push_back(*stop.missing);
      }
      return out;
    }
  } else {
    out.exported = toolpaths::export_plan(file, plan, machine, options.export_options);
    run.take(out.exported.programs());
  }
  out.program = run.finish(out);
  out.deviation = plan::measure_deviation(out.as_built, file.design, file.domain, file.band());
  out.reasons = rejection_reasons(out, file, machine);
  if (out.reasons.empty() && options.verify_exactly && options.planned_against == PlannedAgainst::MaterialPresent)
    verify_exactly(out, file, plan, machine, options);
  return out;
}

}  // namespace

Execution execute_plan(const plan::PlanFile& file, const plan::PlanFilePlan& plan, const config::Machine& machine,
                       const ExecutionOptions& options) {
  IncrementalRun run(machine, file, plan, plan::start_stock(file, plan, machine), options);
  return run_plan(file, plan, machine, options, run, std::nullopt);
}

Execution execute_plan(const plan::PlanFile& file, const plan::PlanFilePlan& plan, const config::Machine& machine,
                       const ExecutionOptions& options, PrefixCache* cache) {
  // The planned state does not depend on what the simulation holds: nothing to resume.
  if (!cache || options.planned_against != PlannedAgainst::MaterialPresent)
    return execute_plan(file, plan, machine, options);
  detail::PrefixCacheImpl& c = cache->impl();
  c.serve(file, machine);
  std::vector<int> key;
  for (const plan::PlanFileAction& a : plan.actions) key.push_back(a.primitive);
  const PrefixState* from = c.longest(key);
  if (from && options.run_until == RunUntil::FirstFailingAction) {
    // From the raw stock, the run stops after the last addition when the design's core is
    // missing there (check_core_after); a prefix past it with the core missing resumes
    // from that addition at the latest, so that the run ends the same.
    const std::size_t last = std::size_t(last_addition(file, plan));
    if (from->actions.size() > last) {
      if (!c.core) c.core = plan::spared_by_cuts(file);
      if (!subtract(*c.core, IncrementalRun(machine, file, plan, *from, options).present()).empty()) {
        // One lookup, counted as the one that resumes.
        --c.stats.lookups;
        --c.stats.hits;
        c.stats.resumed_actions -= from->actions.size();
        key.resize(last);
        from = c.longest(key);
      }
    }
  }
  if (from) {
    IncrementalRun run(machine, file, plan, *from, options);
    run.keep_in(&c);
    toolpaths::ExportStart start{from->actions, run.present()};
    return run_plan(file, plan, machine, options, run, std::move(start));
  }
  IncrementalRun run(machine, file, plan, plan::start_stock(file, plan, machine), options);
  run.keep_in(&c);
  return run_plan(file, plan, machine, options, run, std::nullopt);
}

}  // namespace hybridctl::validation
