#pragma once
// The dialect-neutral toolpath of one plan action: moves in the setup's work frame, as
// the toolpath generators (toolpaths/deposition_path, toolpaths/pocket_path) produce them and the
// post-processor (gcode/post) writes them out in a machine's dialect.
//
// Frames: the part frame is the design's (STL) frame. A setup looks at the part from its
// approach direction; its work frame is the part frame turned so that the approach
// direction becomes +Z (the spindle axis), with the same origin. For an approach of +Z
// the two frames are the same. The setup's work offset (G54..G59) places the work frame
// on the machine (config::Setup::work_origin).

#include <string>
#include <vector>

#include "geometry/solid.hpp"

namespace hybridctl::gcode {

using geometry::Vec3;

enum class MoveKind {
  Rapid,    // G0: never into material (the generators guarantee it, the simulator checks)
  Feed,     // G1
  ArcCw,    // G2 in the XY plane
  ArcCcw,   // G3 in the XY plane
};

struct PathMove {
  MoveKind kind = MoveKind::Rapid;
  Vec3 to;                    // mm, work frame
  Vec3 centre;                // arcs: the centre, mm, work frame (z ignored)
  double feed = 0;            // mm/min; Feed and arcs
  // Additive: deposition is on during this move. Subtractive: the move cuts (for
  // statistics only: the spindle runs for the whole toolpath).
  bool process_on = false;
  std::string comment;        // optional, written as a comment before the move
  double spindle = 0;         // rpm of a milling feed move or arc; 0: the tool's spindle_speed
};

enum class Process { Deposition, Milling };

// Something that makes the part wrong if the path runs as it is: a layer skipped under
// material, material the tool cannot reach. Export refuses the plan and validation
// rejects it (docs/export.md); harmless remarks stay in Toolpath::warnings.
struct PathDefect {
  std::string kind;     // "layer_skipped", "unreachable" (plan.json's rejection kinds)
  std::string message;  // one sentence with the figures
  Vec3 where;           // mm, work frame: the middle of what is affected
};

struct Toolpath {
  Process process = Process::Milling;
  std::string instrument;     // head or tool name, as in the machine file
  int tool_number = 0;        // T number (heads: their tool_number in the machine file)
  std::string setup;          // setup name
  Vec3 start;                 // where the path starts, at safe height (work frame)
  double safe_z = 0;          // mm, work frame: above everything the path can meet
  std::vector<PathMove> moves;
  std::vector<std::string> warnings;  // e.g. short raster segments dropped
  std::vector<PathDefect> defects;    // the part will be wrong: see PathDefect
};

// One action of a plan with its toolpath, ready for the post-processor.
struct ActionProgram {
  int action = 0;             // 1-based position in the plan
  std::string primitive;      // e.g. "P4"
  std::string label;          // e.g. "SM-max 10 mm flat rougher @ top"
  bool additive = true;
  double volume = 0;          // mm^3 deposited or removed, as planned
  Toolpath path;
};

}  // namespace hybridctl::gcode
