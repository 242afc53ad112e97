#pragma once
// `hybridctl run --resume JOB --from-line N`: the job goes on as a new program after the
// controller lost it (docs/drivers.md, "Controller power loss").

#include <cstdint>
#include <string>

#include "config/machine.hpp"

namespace hybridctl::drivers {

class Journal;

// Checks N against what the journal says the controller executed and accepted
// (check_restart_line; N counts lines of the job's original program), builds the restart
// (gcode::restart_program: a preamble restoring the modal state, then lines N..end),
// writes it next to the journal as program-from-line-N.ngc, and records it in the
// journal, whose header then names it. Returns the restart program's text.
std::string restart_job(Journal& journal, const config::Machine& machine, std::uint32_t from_line);

}  // namespace hybridctl::drivers
