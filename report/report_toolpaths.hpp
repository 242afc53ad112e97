#pragma once
// Each action's toolpath as the report draws it: line segments in the part frame (the
// setup's work frame turned back), each with its kind (rapid, feed with the process off,
// deposition or cutting) and its layer (the Z levels of the work frame at which the process
// runs, in the order the path visits them), and the action's cycle time by the G-code
// time model (gcode::check_program on the action's program).

#include <cstdint>
#include <string>
#include <vector>

#include "config/machine.hpp"
#include "plan/plan_file.hpp"

namespace hybridctl::report {

enum class SegmentKind : std::uint8_t { Rapid = 0, Feed = 1, Process = 2 };

struct ActionPath {
  int step = 0;                      // 1-based in the plan
  std::string primitive;             // P-name
  bool makes_gcode = false;          // false: `note` says why (raw stock, empty region)
  std::string note;
  bool additive = true;
  std::string instrument, setup;
  int tool_number = 0;
  std::vector<float> points;         // two vertices (x, y, z) per segment, mm, part frame
  std::vector<SegmentKind> kinds;    // one per segment
  std::vector<std::uint16_t> layers; // one per segment, non-decreasing from 0
  std::vector<float> layer_z;        // work-frame Z of each layer
  double cycle_s = 0;                // estimated, s
  double process_length = 0, feed_length = 0, rapid_length = 0;  // mm
  std::vector<std::string> warnings;
  std::size_t segments() const { return kinds.size(); }
};

struct PlanPaths {
  std::vector<ActionPath> actions;
  // For each line of the plan's program (gcode::post_program, the program `run` and
  // `dry-run` stream), where the tool is after it, part frame: to place a run's alarms.
  std::vector<geometry::Vec3> line_positions;
  // Why the plan has no toolpaths (what export throws for a plan the machine cannot
  // make); empty when it has them.
  std::string error;
};

// Every plan's actions with their toolpaths (as toolpaths::export_plan makes them against
// the planned states) and cycle times; `states[k]` are plan k's (plan::plan_states).
// An action depends only on the primitives up to it, so plans that begin alike share
// their first actions: each distinct one is exported once. The exports run in parallel,
// the costliest (by the plan's cost of the action) first, so that no long one starts last.
std::vector<PlanPaths> plan_paths(const plan::PlanFile& file, const std::vector<std::vector<geometry::Solid>>& states,
                                  const config::Machine& machine);

}  // namespace hybridctl::report
