#pragma once
// What actions cost in machine time and money (docs/costs.md), and the search's cost
// units for the objective the user chose. One definition for the planner, plan.json and
// what `plan` prints.
//
// Time of an action: its volume over the capability's rate (volume_rate() of a head or
// a tool, mm³/min), plus the changes before it (tool change, head switch
// between milling and deposition, setup change or refixture). Money: the time at the
// machine's hourly rate, plus the material a deposit consumes (the mass deposited over
// the head's efficiency, at its price per kg), plus the wear of the tool (its price over
// its life, per minute of cutting), plus the raw stock bought.

#include <string>
#include <vector>

#include "config/machine.hpp"
#include "planner/primitives/machine_primitives.hpp"
#include "planner/problem/problem.hpp"

namespace hybridctl::planner {

struct Estimate {
  double minutes = 0;
  double money = 0;

  Estimate& operator+=(const Estimate& o) {
    minutes += o.minutes;
    money += o.money;
    return *this;
  }
};

// Per mm³ changed by a primitive: minutes of machine time and money (time at the rate,
// material, wear). A raw stock costs its material and no time; a primitive given as a
// file costs nothing but its cost factor, which is not time or money.
Estimate per_mm3(const config::Machine& machine, const Primitive& primitive);

// What changing from one action to the next costs before the next one's own work.
Estimate change_between(const config::Machine& machine, const Primitive& from, const Primitive& to);

// A plan's steps, each with its change from the step before, and their sum.
struct PlanEstimate {
  std::vector<Estimate> steps;    // each with the change before it
  std::vector<Estimate> changes;  // that change alone
  Estimate total;
};
PlanEstimate estimate_plan(const config::Machine& machine, const std::vector<Primitive>& primitives, const Plan& plan);

// The search's rates and fixed costs for the objective: minutes, money, or the machine
// file's dimensionless factors (cost_per_mm3, fixed_costs), which the primitives carry.
double objective_per_mm3(const config::Machine& machine, config::Objective objective, const Primitive& primitive);
FixedCosts objective_fixed_costs(const config::Machine& machine, config::Objective objective);
// Whether a setup change into or out of this primitive's setup is a refixture.
bool refixture_setup(const config::Machine& machine, const Primitive& primitive);

// "1 h 53 min", "12 min", "45 s".
std::string duration_text(double minutes);
// "245.10 EUR".
std::string money_text(double money, const std::string& currency);

}  // namespace hybridctl::planner
