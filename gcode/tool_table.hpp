#pragma once
// The machine's tools as a LinuxCNC tool table, one line per cutting tool and per head:
//
//   T1 P1 D10 Z0 ;10 mm flat rougher
//   T100 P100 D1.5 Z0 ;head ded (ded-powder)
//
// T is the tool number (a head's tool_number), P the pocket (the same number), D the
// diameter (a head's bead width) and Z the length offset: 0, because hybridctl's
// coordinates are those of the tool tip and the real offsets are measured on the
// machine. The text after ';' is the tool's name. Lines are sorted by tool number.

#include <string>

#include "config/machine.hpp"

namespace hybridctl::gcode {

std::string linuxcnc_tool_table(const config::Machine& machine);

}  // namespace hybridctl::gcode
