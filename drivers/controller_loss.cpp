#include "drivers/controller_loss.hpp"

#include <cstdio>

#include "common/error.hpp"

namespace hybridctl::drivers {
namespace {

using protocol::ControllerState;

std::string hex64(std::uint64_t v) {
  char buf[19];
  std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(v));
  return buf;
}

std::string span(std::uint32_t first, std::uint32_t last) {
  return first == last ? "line " + std::to_string(first) : "lines " + std::to_string(first) + ".." + std::to_string(last);
}

ControllerLoss loss(ControllerLoss::Kind kind, std::string what, const StreamKnowledge& known, std::uint32_t lines) {
  return {kind, std::move(what), known.executed_line, std::max(known.accepted_line, known.executed_line), lines};
}

}  // namespace

std::string_view to_string(ControllerLoss::Kind kind) {
  switch (kind) {
    case ControllerLoss::Kind::NewBootWithoutProgram: return "new-boot-without-program";
    case ControllerLoss::Kind::AnotherProgram: return "another-program";
    case ControllerLoss::Kind::Contradiction: return "contradiction";
  }
  return "?";
}

std::optional<ControllerLoss> detect_loss(const StreamKnowledge& known, const protocol::Status& now, std::uint32_t lines) {
  if (known.identity == 0) return std::nullopt;  // no program of ours set yet
  const bool new_boot = now.boot_count != known.boot;
  const std::string boot = "boot " + std::to_string(now.boot_count) + (new_boot ? " (was " + std::to_string(known.boot) + ")" : "");
  const std::string state = std::string(protocol::to_string(now.state));
  if (now.identity != known.identity) {
    if (now.identity != 0)
      return loss(ControllerLoss::Kind::AnotherProgram,
                  "the controller now holds another program (" + hex64(now.identity) + ", " + boot + ", state " + state + ")", known,
                  lines);
    // Nothing can have run yet: setting the program again loses nothing.
    if (!known.started && known.executed_line == 0) return std::nullopt;
    if (new_boot)
      return loss(ControllerLoss::Kind::NewBootWithoutProgram,
                  "the controller booted again (" + boot + ", state " + state + ") without the program or its safe point", known,
                  lines);
    return loss(ControllerLoss::Kind::Contradiction,
                "the controller holds no program (" + boot + ", state " + state + ") while it had accepted " +
                    span(1, std::max(known.accepted_line, 1u)) + ": a controller restarted without counting the boot",
                known, lines);
  }
  if (now.last_executed_line < known.executed_line)
    return loss(ControllerLoss::Kind::Contradiction,
                "the controller's executed lines went backwards, from " + std::to_string(known.executed_line) + " to " +
                    std::to_string(now.last_executed_line) + " (" + boot + ", state " + state + ")",
                known, lines);
  if (!new_boot && now.last_accepted_chunk < known.accepted_chunk)
    return loss(ControllerLoss::Kind::Contradiction,
                "the controller's accepted chunks went backwards, from " + std::to_string(known.accepted_chunk) + " to " +
                    std::to_string(now.last_accepted_chunk) + " without a new boot (" + boot + ", state " + state + ")",
                known, lines);
  if (known.started && now.state == ControllerState::Idle)
    return loss(ControllerLoss::Kind::Contradiction,
                "the controller shows the program IDLE, not started (" + boot + "), after it ran through line " +
                    std::to_string(known.executed_line),
                known, lines);
  return std::nullopt;
}

std::string describe_loss(const ControllerLoss& l, const std::string& resume_command) {
  const std::uint32_t e = l.executed_line, a = l.accepted_line, n = l.program_lines;
  std::string s = "controller lost the program: " + l.what + ".\n";
  s += "  executed    " + (e ? span(1, e) + ", as the controller reported them" : std::string("no line reported executed")) + "\n";
  if (a > e)
    s += "  uncertain   " + span(e + 1, a) + " (" + std::to_string(a - e) +
         " lines) were accepted but not reported executed: they may have run, in part or whole\n";
  if (a < n) s += "  lost        the controller lost the rest of the program (" + span(a + 1, n) + " were never sent)\n";
  s += "  what to do  check the machine (position, tool, the part: how far the last lines got); then\n";
  s += "              " + (resume_command.empty() ? std::string("hybridctl run --resume JOB") : resume_command) + " --from-line " +
       std::to_string(e + 1) + "\n";
  s += "              (line " + std::to_string(e + 1) + ": the safe point after the last line reported executed";
  if (a > e) s += "; a later line up to " + std::to_string(a + 1) + " if the machine shows the uncertain lines ran";
  s += ")";
  return s;
}

void check_restart_line(std::uint32_t from, std::uint32_t e, std::uint32_t a, std::uint32_t n) {
  a = std::max(a, e);
  const std::string flag = "--from-line " + std::to_string(from) + ": ";
  if (from < 1 || from > n)
    throw InputError(flag + "the program has " + std::to_string(n) + " lines; expected a line 1.." + std::to_string(n));
  const std::string safe = "the safe point is line " + std::to_string(e + 1) +
                           (a > e ? " (or a later line up to " + std::to_string(std::min(a + 1, n)) +
                                        " if the machine shows the uncertain lines ran)"
                                  : std::string());
  if (from <= e)
    throw InputError(flag + "not a safe point: the controller reported " + span(1, e) +
                     " executed, so restarting there runs " + span(from, e) + " twice; " + safe);
  if (from > a + 1)
    throw InputError(flag + "not a safe point: " + span(a + 1, from - 1) +
                     " were never sent to the controller and would be skipped; " + safe);
}

}  // namespace hybridctl::drivers
