#include "sim/replay.hpp"

#include "sim/executor.hpp"

namespace hybridctl::sim {

ReplayResult replay_program(std::string_view text, const config::Machine& machine, const geometry::Solid& stock,
                            const ReplayOptions& options, const std::string& file_name) {
  ReplayResult result;
  ExecutorOptions eo;
  eo.stock = stock;
  eo.protected_region = options.protected_region;
  eo.simulation = options.simulation;
  ProgramExecutor executor(machine, file_name, std::move(eo));
  std::size_t start = 0;
  int number = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    start = end + 1;
    ++number;
    ++result.lines;
    const LineOutcome o = executor.execute_line(line, number);
    result.motions += int(o.motions.size());
    // A replay goes on past what would stop a controller, and reports it.
    if (o.stop == Stop::GcodeError || o.stop == Stop::EnvelopeViolation || o.stop == Stop::ToolNotInMagazine ||
        o.stop == Stop::DepositionWithoutHead || o.stop == Stop::SpindleDepositionConflict)
      result.errors.push_back(o.message);
  }
  result.report = executor.report();
  result.simulated = int(result.report.moves);
  const geometry::Solid built = executor.stock();
  const geometry::IndexBox domain = stock.storage_box();
  if (built.storage_box() == domain) {
    result.stock = built;
  } else {
    result.stock = copied_onto(built, stock.lattice(), domain);
  }
  return result;
}

}  // namespace hybridctl::sim
