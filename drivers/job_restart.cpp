#include "drivers/job_restart.hpp"

#include <filesystem>

#include "drivers/controller_loss.hpp"
#include "drivers/journal.hpp"
#include "gcode/files.hpp"
#include "gcode/restart.hpp"
#include "protocol/chunk.hpp"

namespace hybridctl::drivers {
namespace {

// A line of the running program (a restart: preamble, then the original from its restart
// line) as a line of the original program.
std::uint32_t original_line(std::uint32_t restart_from_line, std::uint32_t preamble_lines, std::uint32_t line) {
  if (restart_from_line == 0) return line;
  if (line <= preamble_lines) return restart_from_line - 1;
  return restart_from_line + (line - preamble_lines) - 1;
}

}  // namespace

gcode::RestartProgram restart_for(const std::vector<std::string>& original, std::uint32_t restart_from_line,
                                  std::uint32_t preamble_lines, const JournalProgress& p, const config::Machine& machine,
                                  std::uint32_t from_line) {
  // Without a recorded loss (the host died too): what the record last saw acknowledged.
  const std::uint32_t executed = original_line(restart_from_line, preamble_lines, p.lost ? p.lost_executed_line : p.executed_line);
  const std::uint32_t accepted = original_line(restart_from_line, preamble_lines, p.lost ? p.lost_accepted_line : p.through_line);
  check_restart_line(from_line, executed, accepted, std::uint32_t(original.size()));
  return gcode::restart_program(original, from_line, machine);
}

std::string restart_job(Journal& journal, const config::Machine& machine, std::uint32_t from_line) {
  const JournalHeader& h = journal.header();
  const std::string original = h.original_program.empty() ? h.program : h.original_program;
  const std::vector<std::string> lines = protocol::program_lines(gcode::read_text_file(original));
  const gcode::RestartProgram restart =
      restart_for(lines, h.restart_from_line, h.restart_preamble_lines, journal.progress(), machine, from_line);
  const std::string text = protocol::program_text(restart.lines);
  const std::filesystem::path file =
      journal.file().parent_path() / ("program-from-line-" + std::to_string(from_line) + ".ngc");
  gcode::write_text_file(file, text);
  journal.restarted(std::filesystem::absolute(file).string(), protocol::program_identity(restart.lines),
                    std::uint32_t(restart.lines.size()), from_line, restart.preamble_lines, original);
  return text;
}

}  // namespace hybridctl::drivers
