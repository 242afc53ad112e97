#pragma once
// `hybridctl run --resume JOB --from-line N`: the job goes on as a new program after the
// controller lost it (docs/drivers.md, "Controller power loss").

#include <cstdint>
#include <string>
#include <vector>

#include "config/machine.hpp"
#include "drivers/job_record.hpp"
#include "gcode/restart.hpp"

namespace hybridctl::drivers {

class Journal;

// Checks N against what the journal says the controller executed and accepted
// (check_restart_line; N counts lines of the job's original program), builds the restart
// (gcode::restart_program: a preamble restoring the modal state, then lines N..end),
// writes it next to the journal as program-from-line-N.ngc, and records it in the
// journal, whose header then names it. Returns the restart program's text.
std::string restart_job(Journal& journal, const config::Machine& machine, std::uint32_t from_line);

// The restart itself, wherever the job is recorded: `original` the job's original program,
// `restart_from_line` and `preamble_lines` those of the restart it runs now (0: none),
// `progress` what its record says of that program.
gcode::RestartProgram restart_for(const std::vector<std::string>& original, std::uint32_t restart_from_line,
                                  std::uint32_t preamble_lines, const JournalProgress& progress,
                                  const config::Machine& machine, std::uint32_t from_line);

}  // namespace hybridctl::drivers
