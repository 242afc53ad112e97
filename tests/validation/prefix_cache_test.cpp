// Candidates resumed from executed prefixes (validation/prefix_cache.hpp) end exactly as
// executed from the raw stock: same reasons (kind, action, line, message, where), same
// lines, same part as built, same report; and the cache is really used, and stays under
// its cap.

#include "validation/prefix_cache.hpp"

#include <gtest/gtest.h>

#include <set>

#include "validation/execution.hpp"
#include "validation_cases.hpp"

namespace hybridctl::validation {
namespace {

using cases::Case;
using cases::machine;
using geometry::Solid;

// Plans over one part that share prefixes: a step milled from a raw stock (right), then
// a strip at the foot of the step's wall (the nozzle hits the wall), a slot the 10 mm
// cutter cannot enter (unreachable), or a strip clear of the wall.
struct SharedPrefixes {
  Case c{1.0};
  int s, m, m3, wall_strip, free_strip, slot;
  std::vector<plan::PlanFilePlan> plans;

  SharedPrefixes() {
    const Solid raw = c.box({{0, 0, 0}, {30, 20, 25}}), step = c.box({{15, -5, 5}, {35, 25, 30}});
    c.file.design = unite(subtract(raw, step), c.box({{15, 2, 5}, {17, 18, 7}}));
    s = c.stock(raw);
    m = c.mill(step, 1);
    m3 = c.mill(step, 3);
    wall_strip = c.deposit(c.box({{15, 2, 5}, {17, 18, 7}}));
    free_strip = c.deposit(c.box({{25, 2, 5}, {29, 18, 7}}));
    slot = c.mill(c.box({{5, 2, 15}, {9, 18, 30}}), 1);
    for (const std::vector<int>& actions :
         std::vector<std::vector<int>>{{s, m},
                                       {s, m, wall_strip},
                                       {s, m, slot},
                                       {s, m, free_strip},
                                       {s, slot},
                                       {s, m, free_strip, slot},
                                       {s, m, free_strip, wall_strip},
                                       {s, m3, wall_strip},
                                       {s, m, wall_strip},
                                       {s, m}})
      plans.push_back(c.plan(actions));
  }
};

void expect_same(const Execution& cached, const Execution& scratch, const std::string& what) {
  SCOPED_TRACE(what);
  ASSERT_EQ(cached.reasons.size(), scratch.reasons.size()) << describe_reasons(cached.reasons) << "\nvs\n"
                                                           << describe_reasons(scratch.reasons);
  for (std::size_t i = 0; i < scratch.reasons.size(); ++i) {
    const plan::RejectionReason &a = cached.reasons[i], &b = scratch.reasons[i];
    EXPECT_EQ(a.kind, b.kind);
    EXPECT_EQ(a.action, b.action);
    EXPECT_EQ(a.line, b.line);
    EXPECT_EQ(a.message, b.message);
    EXPECT_EQ(a.where.has_value(), b.where.has_value());
    if (a.where && b.where) {
      EXPECT_EQ(a.where->x, b.where->x);
      EXPECT_EQ(a.where->y, b.where->y);
      EXPECT_EQ(a.where->z, b.where->z);
    }
  }
  EXPECT_EQ(cached.stopped_after, scratch.stopped_after);
  EXPECT_TRUE(cached.as_built == scratch.as_built) << "as built differs";
  EXPECT_EQ(cached.as_built.storage_box().lo.z, scratch.as_built.storage_box().lo.z);
  EXPECT_EQ(cached.program.lines, scratch.program.lines);
  EXPECT_EQ(cached.program.actions.size(), scratch.program.actions.size());
  EXPECT_EQ(cached.errors, scratch.errors);
  EXPECT_EQ(cached.report.moves, scratch.report.moves);
  EXPECT_EQ(cached.report.removed, scratch.report.removed);
  EXPECT_EQ(cached.report.deposited, scratch.report.deposited);
  EXPECT_EQ(cached.report.gouge, scratch.report.gouge);
  EXPECT_EQ(cached.report.collision, scratch.report.collision);
  EXPECT_EQ(cached.report.rapid_contact, scratch.report.rapid_contact);
  ASSERT_EQ(cached.report.incidents.size(), scratch.report.incidents.size());
  for (std::size_t i = 0; i < scratch.report.incidents.size(); ++i) {
    EXPECT_EQ(cached.report.incidents[i].line, scratch.report.incidents[i].line);
    EXPECT_EQ(cached.report.incidents[i].voxels, scratch.report.incidents[i].voxels);
  }
  EXPECT_EQ(cached.deviation.under_volume, scratch.deviation.under_volume);
  EXPECT_EQ(cached.deviation.over_volume, scratch.deviation.over_volume);
  EXPECT_EQ(cached.exported.raw_stock, scratch.exported.raw_stock);
  ASSERT_EQ(cached.exported.actions.size(), scratch.exported.actions.size());
  for (std::size_t i = 0; i < scratch.exported.actions.size(); ++i) {
    const toolpaths::ExportedAction &a = cached.exported.actions[i], &b = scratch.exported.actions[i];
    EXPECT_EQ(a.step, b.step);
    EXPECT_EQ(a.primitive, b.primitive);
    EXPECT_EQ(a.makes_gcode, b.makes_gcode);
    EXPECT_EQ(a.note, b.note);
    EXPECT_EQ(a.program.path.moves.size(), b.program.path.moves.size());
  }
}

std::string name_of(const plan::PlanFilePlan& plan) {
  std::string out;
  for (const plan::PlanFileAction& a : plan.actions) out += "P" + std::to_string(a.primitive + 1) + " ";
  return out;
}

void run_all(const SharedPrefixes& t, const ExecutionOptions& options, PrefixCache& cache) {
  for (const plan::PlanFilePlan& plan : t.plans) {
    const Execution scratch = execute_plan(t.c.file, plan, machine(), options);
    const Execution cached = execute_plan(t.c.file, plan, machine(), options, &cache);
    expect_same(cached, scratch, name_of(plan));
  }
}

// The plans are varied enough to test something: some fail, at different actions.
TEST(PrefixCache, ThePlansFailInDifferentWays) {
  const SharedPrefixes t;
  ExecutionOptions options;
  options.run_until = RunUntil::FirstFailingAction;
  std::set<std::string> kinds;
  std::set<int> stops;
  for (const plan::PlanFilePlan& plan : t.plans) {
    const Execution run = execute_plan(t.c.file, plan, machine(), options);
    for (const auto& r : run.reasons) kinds.insert(r.kind);
    stops.insert(run.stopped_after);
  }
  EXPECT_GE(kinds.size(), 2u);
  EXPECT_GE(stops.size(), 2u);
  EXPECT_TRUE(stops.count(0)) << "a plan runs to its end";
}

TEST(PrefixCache, ResumedCandidatesEndAsFromTheRawStock) {
  const SharedPrefixes t;
  ExecutionOptions options;
  options.run_until = RunUntil::FirstFailingAction;  // as the plan validator runs
  PrefixCache cache;
  run_all(t, options, cache);
  const PrefixCacheStats& s = cache.stats();
  EXPECT_EQ(s.lookups, t.plans.size());
  EXPECT_EQ(s.hits, t.plans.size() - 1) << "every plan after the first begins with a prefix run before";
  // Most resume after two actions or more. The last {s, m} lacks the wall strip after its
  // milling, past its last addition (the stock): it resumes from the stock, as a run from
  // the raw stock checks the design's core there (Execution::missing_after_last_addition).
  EXPECT_GE(s.resumed_actions, 2 * (t.plans.size() - 1) - 2);
  EXPECT_EQ(s.evicted, 0u);
  EXPECT_GT(s.bytes, 0u);
  EXPECT_LE(s.bytes, cache.max_bytes());
}

TEST(PrefixCache, ResumedCandidatesRunToTheEndAsFromTheRawStock) {
  const SharedPrefixes t;
  ExecutionOptions options;
  options.run_until = RunUntil::End;
  PrefixCache cache;
  run_all(t, options, cache);
  EXPECT_GT(cache.stats().hits, 0u);
}

// A cap that holds a prefix or two: the least recently used go, results stay the same.
TEST(PrefixCache, StaysUnderItsCap) {
  const SharedPrefixes t;
  ExecutionOptions options;
  options.run_until = RunUntil::FirstFailingAction;
  std::size_t one = 0;
  {
    PrefixCache probe;
    execute_plan(t.c.file, t.c.plan({t.s, t.m}), machine(), options, &probe);
    ASSERT_EQ(probe.stats().entries, 2u);
    one = probe.stats().bytes;
  }
  PrefixCache cache(one + one / 2);
  run_all(t, options, cache);
  EXPECT_GT(cache.stats().evicted, 0u);
  EXPECT_LE(cache.stats().bytes, cache.max_bytes());
  EXPECT_GT(cache.stats().hits, 0u);

  PrefixCache none(1);  // too small for any prefix: every plan from the raw stock
  run_all(t, options, none);
  EXPECT_EQ(none.stats().hits, 0u);
  EXPECT_EQ(none.stats().entries, 0u);
}

// The cache answers for one plan file: given another, it starts again.
TEST(PrefixCache, AnotherFileEmptiesIt) {
  const SharedPrefixes a, b;
  ExecutionOptions options;
  options.run_until = RunUntil::FirstFailingAction;
  PrefixCache cache;
  execute_plan(a.c.file, a.plans[0], machine(), options, &cache);
  EXPECT_GT(cache.stats().entries, 0u);
  const Execution run = execute_plan(b.c.file, b.plans[1], machine(), options, &cache);
  EXPECT_EQ(cache.stats().hits, 0u);
  expect_same(run, execute_plan(b.c.file, b.plans[1], machine(), options), "another file");
}

}  // namespace
}  // namespace hybridctl::validation
