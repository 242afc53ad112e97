#pragma once
// --objective time|money|cost-factor: what `plan` and `dry-run` rank plans by
// (planner/costing/costs.hpp, docs/costs.md); default the machine file's.

#include <CLI/CLI.hpp>

#include <optional>
#include <string>

#include "config/machine.hpp"

namespace hybridctl::cli {

inline CLI::Option* add_objective_option(CLI::App* cmd, std::string& into) {
  return cmd
      ->add_option("--objective", into,
                   "What plans are ranked by: time (minutes of machine time), money (time at the machine's rate, "
                   "material, tool wear) or cost-factor (the machine file's dimensionless cost_per_mm3); default: the "
                   "machine file's planning.objective, money when it has a costs section (docs/costs.md)")
      ->check(CLI::IsMember({"time", "money", "cost-factor"}));
}

// Unset when not given (the machine file's objective).
inline std::optional<config::Objective> objective(const std::string& text) {
  if (text == "time") return config::Objective::Time;
  if (text == "money") return config::Objective::Money;
  if (text == "cost-factor") return config::Objective::CostFactor;
  return std::nullopt;
}

}  // namespace hybridctl::cli
