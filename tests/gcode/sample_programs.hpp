#pragma once
// Toolpaths for the post-processor tests, built for any machine from its first two
// heads, first two cutting tools and first two setups: deposition with an arc and two
// layers, milling with full and half circles, a tool change, a head change and a setup
// change. Every point stays well inside both example machines' envelopes with the
// default work origins (X, Y mid-travel, Z at the bottom).

#include <string>
#include <vector>

#include "config/machine.hpp"
#include "gcode/toolpath.hpp"

namespace hybridctl::gcode::samples {

inline PathMove rapid(double x, double y, double z) { return {MoveKind::Rapid, {x, y, z}, {}, 0, false, ""}; }
inline PathMove feed(double x, double y, double z, double f, bool on) {
  return {MoveKind::Feed, {x, y, z}, {}, f, on, ""};
}
inline PathMove arc(MoveKind kind, double x, double y, double z, double cx, double cy, double f, bool on) {
  return {kind, {x, y, z}, {cx, cy, 0}, f, on, ""};
}

/// Two layers of a square-with-a-round-end track.
inline ActionProgram deposition_action(int number, const config::AdditiveHead& head, const std::string& setup) {
  ActionProgram a;
  a.action = number;
  a.primitive = "P" + std::to_string(number);
  a.label = "U-AM " + head.name + " @ " + setup;
  a.additive = true;
  a.volume = 1234.5;
  a.path.process = Process::Deposition;
  a.path.instrument = head.name;
  a.path.tool_number = head.tool_number;
  a.path.setup = setup;
  a.path.start = {-20, -20, 30};
  a.path.safe_z = 30;
  auto& m = a.path.moves;
  for (double z : {0.6, 1.2}) {
    m.push_back(rapid(-10, -10, z + 5));
    m.push_back(feed(-10, -10, z, 800, false));
    m.push_back(feed(10, -10, z, 800, true));
    m.push_back(feed(10, 10, z, 800, true));
    m.push_back(arc(MoveKind::ArcCcw, -10, 10, z, 0, 10, 800, true));
    m.push_back(feed(-10, -10, z, 600, true));
    m.push_back(rapid(-10, -10, z + 5));
  }
  m[1].comment = "layer 1";
  m[8].comment = "layer 2";
  return a;
}

/// A full circle and two half circles at two depths.
inline ActionProgram circle_milling_action(int number, const config::CuttingTool& tool, const std::string& setup) {
  ActionProgram a;
  a.action = number;
  a.primitive = "P" + std::to_string(number);
  a.label = "SM-max " + tool.name + " @ " + setup;
  a.additive = false;
  a.volume = 987.25;
  a.path.process = Process::Milling;
  a.path.instrument = tool.name;
  a.path.tool_number = tool.number;
  a.path.setup = setup;
  a.path.start = {0, 0, 30};
  a.path.safe_z = 30;
  auto& m = a.path.moves;
  m.push_back(rapid(25, 0, 5));
  m.push_back(feed(25, 0, 1, 300, false));
  m.push_back(arc(MoveKind::ArcCw, 25, 0, 1, 0, 0, 1200, true));   // full circle
  m.push_back(arc(MoveKind::ArcCw, -25, 0, 1, 0, 0, 1200, true));  // half
  m.push_back(feed(-25, 0, 0.5, 300, false));
  m.push_back(arc(MoveKind::ArcCcw, 25, 0, 0.5, 0, 0, 1200, true));
  m.push_back(rapid(25, 0, 30));
  return a;
}

/// A square pocket outline.
inline ActionProgram square_milling_action(int number, const config::CuttingTool& tool, const std::string& setup) {
  ActionProgram a;
  a.action = number;
  a.primitive = "P" + std::to_string(number);
  a.label = "SM-cons " + tool.name + " @ " + setup;
  a.additive = false;
  a.volume = 400;
  a.path.process = Process::Milling;
  a.path.instrument = tool.name;
  a.path.tool_number = tool.number;
  a.path.setup = setup;
  a.path.start = {0, 0, 30};
  a.path.safe_z = 30;
  auto& m = a.path.moves;
  m.push_back(rapid(10, 10, 5));
  m.push_back(feed(10, 10, 2, 400, false));
  m.push_back(feed(-10, 10, 2, 1500, true));
  m.push_back(feed(-10, -10, 2, 1500, true));
  m.push_back(feed(10, -10, 2, 1500, true));
  m.push_back(rapid(10, -10, 30));
  return a;
}

/// deposition (head 0, setup 0), milling (tool 0, setup 0), milling (tool 1, setup 1),
/// deposition (last head, setup 1): a head change, tool changes and one setup change.
inline std::vector<ActionProgram> sample_actions(const config::Machine& m) {
  const std::string s0 = m.setups.at(0).name, s1 = m.setups.at(1).name;
  return {deposition_action(1, m.heads.at(0), s0), circle_milling_action(2, m.tools.at(0), s0),
          square_milling_action(3, m.tools.at(1), s1), deposition_action(4, m.heads.back(), s1)};
}

}  // namespace hybridctl::gcode::samples
