#pragma once
// A plan search problem as `hybridctl plan -o DIR` recorded it in DIR/plan.json (atoms with
// volumes, classes and codes; primitives with mode, rate, tool and setup; fixed costs and
// the normaliser), or in the reduced form bench/data/*.problem.json keeps of it (the same
// keys, without what the search does not read). planner_bench runs the search on the
// B-axis machine's problems this way, without the minutes of computing primitives.

#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "planner/search/search.hpp"

namespace hybridctl::bench {

inline planner::PlanningProblem problem_of_plan_json(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read");
  const nlohmann::json doc = nlohmann::json::parse(in);
  planner::PlanningProblem p;
  p.normaliser = doc.at("cost_normaliser").get<double>();
  const auto& f = doc.at("fixed_costs");
  p.fixed = {f.at("tool_change").get<double>(), f.at("setup_change").get<double>(), f.at("mode_switch").get<double>()};
  const auto& atoms = doc.at("atoms");
  const int n = int(atoms.size());
  for (const auto& a : atoms) {
    const std::string c = a.at("class").get<std::string>();
    p.atoms.push_back({a.at("volume").get<double>(), c == "must-in" || c == "violating", c == "must-out" || c == "violating"});
  }
  for (const auto& q : doc.at("primitives")) {
    planner::PrimitiveSpec s;
    s.name = q.at("name").get<std::string>();
    s.mode = q.at("mode").get<std::string>() == "additive" ? config::Mode::Additive : config::Mode::Subtractive;
    s.raw_stock = q.at("kind").get<std::string>() == "raw-stock";
    s.cost_per_mm3 = q.at("cost_per_mm3").get<double>();
    s.tool = q.at("capability").get<std::string>();
    s.setup = q.at("setup").get<std::string>();
    s.atoms = planner::AtomSet(n);
    p.primitives.push_back(std::move(s));
  }
  for (int a = 0; a < n; ++a) {
    const std::string code = atoms[std::size_t(a)].at("code").get<std::string>();
    for (std::size_t i = 0; i < code.size() && i < p.primitives.size(); ++i)
      if (code[i] == '1') p.primitives[i].atoms.set(a);
  }
  return p;
}

}  // namespace hybridctl::bench
