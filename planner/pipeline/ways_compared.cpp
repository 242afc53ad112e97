#include "planner/pipeline/ways_compared.hpp"

#include <algorithm>
#include <cstdio>

#include "common/number_text.hpp"
#include "planner/costing/costs.hpp"

namespace hybridctl::planner {
namespace {

// "stock plate-12, 1 deposit, 2 removals": the plan's steps as a shop counts them.
std::string plan_in_words(const PlanningResult& r, const Plan& plan) {
  std::string stock;
  int deposits = 0, removals = 0;
  for (const PlanStep& s : plan.steps) {
    const Primitive& p = r.primitives[std::size_t(s.primitive)];
    if (p.kind == PrimitiveKind::RawStock)
      stock = p.label.rfind("raw stock ", 0) == 0 ? p.label.substr(10) : p.label;
    else if (p.mode == Mode::Additive)
      ++deposits;
    else
      ++removals;
  }
  const auto count = [](int n, const char* one, const char* many) {
    return std::to_string(n) + " " + (n == 1 ? one : many);
  };
  std::string words = stock.empty() ? std::string("on the build plate") : "from " + stock;
  if (deposits) words += ", " + count(deposits, "deposit", "deposits");
  if (removals) words += ", " + count(removals, "removal", "removals");
  return words;
}

WayOfMaking way_of(const std::string& name, const PlanningResult& r) {
  WayOfMaking way;
  way.name = name;
  if (r.plans.empty() || !r.verdict.manufacturable()) {
    const std::string summary = r.verdict.summary;
    const std::string outcome = r.verdict.outcome == Verdict::Outcome::Undecided ? "undecided" : "no plan";
    way.why_not = outcome + ": " + (summary.size() > 160 ? summary.substr(0, 157) + "..." : summary);
    return way;
  }
  way.planned = true;
  way.plan = plan_in_words(r, r.plans.front());
  const PlanEstimate& estimate = r.estimates.front();
  way.minutes = estimate.total.minutes;
  if (!r.cycle_times.empty() && r.cycle_times.front()) {
    way.minutes = r.cycle_times.front()->seconds / 60.0;
    way.cycle_time = true;
  }
  way.money = r.objective == config::Objective::Money
                  ? (r.ranked_by_toolpaths && !r.toolpath_costs.empty() ? r.toolpath_costs.front() : r.plans.front().cost)
                  : estimate.total.money;
  return way;
}

}  // namespace

WaysCompared compare_ways(const config::Machine& machine, const PlanningResult& result,
                          const std::function<PlanningResult(const config::Machine&)>& plan_on) {
  WaysCompared out;
  out.currency = result.currency;
  out.ways.push_back(way_of("hybrid", result));
  // The same machine without its heads mills from stock; without its tools it deposits only.
  struct Other {
    const char* name;
    bool heads;  // keeps its heads (else its tools)
    const char* lacking;
  };
  for (const Other& o : {Other{"milled from stock", false, "the machine has no cutting tool"},
                         Other{"deposited only", true, "the machine has no head"}}) {
    config::Machine narrowed = machine;
    if (o.heads) narrowed.tools.clear();
    else narrowed.heads.clear();
    if (narrowed.heads.empty() && narrowed.tools.empty())
      out.ways.push_back({o.name, false, {}, 0, false, 0, o.lacking});
    else
      out.ways.push_back(way_of(o.name, plan_on(narrowed)));
  }
  return out;
}

std::string ways_compared_text(const WaysCompared& c) {
  std::string out = "compare     each way of making the part on this machine, its best plan (machine time: its "
                    "program's cycle time, changes included, where known; money as the plans are ranked):\n";
  char line[512];
  for (const WayOfMaking& w : c.ways) {
    if (w.planned)
      std::snprintf(line, sizeof line, "              %-18s %-46s %16s  %s\n", w.name.c_str(), w.plan.c_str(),
                    (w.cycle_time ? format_duration(w.minutes * 60.0) : duration_text(w.minutes) + " est.").c_str(), money_text(w.money, c.currency).c_str());
    else
      std::snprintf(line, sizeof line, "              %-18s %s\n", w.name.c_str(), w.why_not.c_str());
    out += line;
  }
  const WayOfMaking& hybrid = c.ways.front();
  if (!hybrid.planned) return out;
  for (std::size_t k = 1; k < c.ways.size(); ++k) {
    const WayOfMaking& other = c.ways[k];
    if (!other.planned || other.money <= 0) continue;
    const double saved = (other.money - hybrid.money) / other.money;
    out += "            the hybrid plan costs " + trimmed_number(std::abs(saved) * 100, 0) + " % " +
           (saved >= 0 ? "less" : "more") + " than the best plan " + other.name + "\n";
  }
  return out;
}

}  // namespace hybridctl::planner
