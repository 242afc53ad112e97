#pragma once
// The plan executor behind `hybridctl run` (docs/drivers.md, "hybridctl run"): assembles
// the program (a plan exported and posted now, a program file, or a resumed job's
// program), prechecks it for the machine, opens or resumes the job's journal, streams the
// program through drivers/streamer.hpp and keeps, per action of the program, what the
// final report says: lines executed, time, alarms.
//
// The executor prints nothing and asks nobody: what people see and answer goes through
// JobOperator (the CLI prints, prompts, and watches Ctrl-C).
//
// The per-action report comes from the program's action table (gcode/program.hpp): for a
// plan, the post-processor's; for a program file or a resumed job, what its text says
// (PostedProgram::from_lines reads back our `(action K: ...)` headings; a file without
// them runs with no per-action report).

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "config/machine.hpp"
#include "drivers/job_record.hpp"
#include "drivers/streamer.hpp"
#include "gcode/post.hpp"
#include "plan/plan_file.hpp"
#include "drivers/transport.hpp"

namespace hybridctl::gcode {
struct CheckReport;
}

namespace hybridctl::drivers {

struct JobRequest {
  std::string input;      ///< plan.json (or its directory) or a G-code program; empty with `resume`
  std::string machine;    ///< machine file; with a plan: empty for the one it embeds; with `resume`: empty for the journal's
  std::string transport;  ///< URI; with `resume`: empty for the journal's
  int rank = 1;           ///< with a plan: which plan, by rank
  std::string job;        ///< job directory; empty: jobs/IDENTITY (first 12 hex digits)
  std::string resume;     ///< job directory to resume
  unsigned from_line = 0; ///< with `resume`: restart the program there (the controller lost it)
  bool machine_override = false;  ///< with a plan: take `machine` even when it is not the plan's
  /// With a plan: how its program is made. Unset: toolpaths::export_plan on the plan's
  /// planned states, then gcode::post_program. The CLI gives validation's, which plans each
  /// action against the material present and refuses a plan that does not make the part.
  std::function<gcode::PostedProgram(const plan::PlanFile&, const plan::PlanFilePlan&, const config::Machine&,
                                     const gcode::PostOptions&)>
      plan_program;
  double wait_for_controller_s = 120;  ///< a controller silent mid-stream is waited for this long (StreamOptions)
};

/// The job as it starts streaming.
struct JobStart {
  std::string job_directory;
  std::string program;      ///< the program file in the job directory
  std::size_t lines = 0;
  std::uint64_t identity = 0;
  std::string machine;      ///< the machine's name
  std::string transport;    ///< URI
  double estimated_s = 0;   ///< the program's cycle time under `gcode check`'s model, s
  std::string cycle_time;   ///< that time and what it includes (gcode::TimeEstimate::str)
};

/// Where the stream is, at every status read.
struct JobProgress {
  std::size_t action = 0;   ///< 1-based action the next line belongs to; 0 before the first
  std::size_t actions = 0;  ///< actions in the program (a plan's raw stock has none)
  int action_number = 0;    ///< that action's number in the plan, as its heading and the final report say; 0 before
  std::size_t lines = 0;
  double done = 0;          ///< fraction of the lines executed
  double eta_s = 0;         ///< from the rate so far; 0 until 1 % is done
};

/// What the final report says of one action.
struct ActionReport {
  std::string name;                  ///< its heading: "action 2: primitive P7, subtractive milling with ..."
  std::uint32_t lines = 0;           ///< its lines: from its heading to the next action's (the last: to the end, a closing "%" left out)
  std::uint32_t executed = 0;        ///< of them
  std::optional<double> seconds;     ///< from its first executed line to its last (or the end), as the host saw the status
  std::vector<std::pair<std::string, int>> alarms;  ///< each alarm once, in the order first raised, with how often
};

struct JobResult {
  StreamResult stream;
  TransportCounters transport;
  std::size_t lines = 0;  ///< the lines the controller executes (a closing "%" left out)
  double seconds = 0;  ///< streaming time
  std::vector<ActionReport> actions;
  std::vector<std::pair<std::string, std::uint32_t>> alarms;  ///< every alarm raised, in order, with its line
};

/// What the executor tells people and asks them.
class JobOperator {
 public:
  virtual ~JobOperator() = default;
  /// The program does not pass `gcode check` for the machine; InputError follows.
  virtual void check_failed(const gcode::CheckReport& report) = 0;
  /// The job is set up (journal written or opened); streaming starts next.
  virtual void started(const JobStart& job) = 0;
  /// Every status read.
  virtual void progress(const protocol::Status& status, const JobProgress& progress) = 0;
  /// Something worth a line in the log (reconnects, restarts, where the stream resumed).
  virtual void note(const std::string& text) = 0;
  /// A program stop after `status.last_executed_line`; `message` is the operator's
  /// instruction (the comment before it). True to continue.
  virtual bool continue_after_stop(const protocol::Status& status, const std::string& message) = 0;
  /// An alarm the operator may clear. True to clear it and resume.
  virtual bool clear_alarm(const protocol::Status& status) = 0;
  /// Polled while streaming: true to hold the feed.
  virtual bool hold_requested() = 0;
  /// Held at the operator's request: true to resume, false to abort.
  virtual bool resume_after_hold(const protocol::Status& status) = 0;
};

/// A job whose program and record the caller keeps: the shop cell's machine host, with the
/// program and its progress in the database (cell/stream_journal.hpp). Its program's
/// identity must be its job's alone: a controller found holding it resumes it
/// (StreamOptions::resume_when_ours).
struct RecordedJob {
  config::Machine machine;
  std::string program_text;  ///< the program as streamed (a restart's, after a controller loss)
  std::string program_name;  ///< for people and `gcode check`'s messages
  std::string name;          ///< the job, for people (JobStart::job_directory)
  std::string transport;     ///< URI
  JobRecord* record = nullptr;
  bool resume = false;       ///< the record says lines were sent: the controller must hold the program
  double wait_for_controller_s = 120;
};

/// Runs the job to its end or its stop. Throws InputError for bad input (a program that
/// fails its check, a resume into another program; nothing was sent), TransportError when
/// the controller cannot be reached (the journal lets a later run resume).
JobResult execute_job(const JobRequest& request, JobOperator& op);
/// The same for a job the caller records; the same exceptions.
JobResult execute_recorded_job(const RecordedJob& job, JobOperator& op);

}  // namespace hybridctl::drivers
