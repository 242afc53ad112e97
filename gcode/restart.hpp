#pragma once
// Restarting a program at one of its lines on a controller that knows nothing of it (a
// controller that lost power and its program): the lines from the restart line on,
// after a short preamble that puts the machine in the modal state the program had after
// the line before (units, distance mode, plane, work offset, tool and its length offset,
// spindle, coolant, deposition, feed) and approaches the position it had there from the
// top of the Z travel. docs/drivers.md, "Controller power loss".

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "config/machine.hpp"

namespace hybridctl::gcode {

struct RestartProgram {
  std::vector<std::string> lines;  // the preamble, then the program's lines from_line..end
  std::uint32_t preamble_lines = 0;
  std::uint32_t from_line = 0;
};

// Interprets lines 1..from_line-1 of `lines` for `machine` and builds the restart.
// Throws InputError when from_line is not 1..lines.size() or the program before it does
// not interpret.
RestartProgram restart_program(std::span<const std::string> lines, std::uint32_t from_line, const config::Machine& machine);

}  // namespace hybridctl::gcode
