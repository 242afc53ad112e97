#pragma once
// The dialect-neutral toolpath model that toolpaths/ fills in and gcode/'s post-processors
// write out. It is defined in gcode/toolpath.hpp (the language's side of the boundary);
// this header names it in the toolpaths namespace so the generators read as one module.

#include "gcode/toolpath.hpp"

namespace hybridctl::toolpaths {

using gcode::ActionProgram;
using gcode::MoveKind;
using gcode::PathMove;
using gcode::Process;
using gcode::Toolpath;

}  // namespace hybridctl::toolpaths
