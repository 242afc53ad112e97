#pragma once
// A controller that lost the program it was running: what the host knew (from its own
// stream and journal) set against what the controller's status now shows. A controller
// that rebooted politely keeps the protocol's safe point (docs/protocol.md, "Controller
// reboot: the safe point"); one that lost power without it, or was replaced, shows a new
// boot without the program, another program, or progress that contradicts what it
// reported before. The host then stops and says what it knows (docs/drivers.md,
// "Controller power loss").

#include <cstdint>
#include <optional>
#include <string>

#include "protocol/messages.hpp"

namespace hybridctl::drivers {

// What the host knew of the controller before the status in question.
struct StreamKnowledge {
  std::uint64_t identity = 0;        // the program the host set (or found) there
  bool started = false;              // START sent or found running: lines may have run
  std::uint16_t boot = 0;            // boot_count of the last status
  std::uint32_t executed_line = 0;   // highest line the controller reported executed
  std::uint32_t accepted_line = 0;   // last line of the last chunk it accepted
  std::uint32_t accepted_chunk = 0;  // highest last_accepted_chunk seen in this boot
};

struct ControllerLoss {
  enum class Kind { NewBootWithoutProgram, AnotherProgram, Contradiction };
  Kind kind = Kind::Contradiction;
  std::string what;                  // what the status showed, in words
  std::uint32_t executed_line = 0;   // the last line the controller reported executed
  std::uint32_t accepted_line = 0;   // lines executed_line+1..this were accepted, not confirmed
  std::uint32_t program_lines = 0;
};

std::string_view to_string(ControllerLoss::Kind kind);

// The loss `now` shows against `known`; nullopt when it shows none (a polite reboot onto
// the safe point, or no program yet before anything could have run).
std::optional<ControllerLoss> detect_loss(const StreamKnowledge& known, const protocol::Status& now, std::uint32_t program_lines);

// What the operator reads: what happened, which lines ran, which may have, that the
// controller lost the rest, and the command that goes on: `resume_command` (the job's
// record's, JobRecord::resume_command) with --from-line; empty: there is no record.
std::string describe_loss(const ControllerLoss& loss, const std::string& resume_command);

// The lines `run --resume DIR --from-line N` may start at after a loss: the protocol's
// safe point executed_line + 1, or a later line of the uncertain span when the machine
// shows that those lines ran (up to accepted_line + 1). Throws InputError for any other N,
// saying why (lines would run twice, or be skipped) and which lines would do.
void check_restart_line(std::uint32_t from_line, std::uint32_t executed_line, std::uint32_t accepted_line,
                        std::uint32_t program_lines);

}  // namespace hybridctl::drivers
