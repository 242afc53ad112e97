#include "drivers/executor.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "common/error.hpp"
#include "config/machine_loader.hpp"
#include "drivers/job_restart.hpp"
#include "drivers/journal.hpp"
#include "gcode/check.hpp"
#include "gcode/files.hpp"
#include "gcode/post.hpp"
#include "gcode/program.hpp"
#include "protocol/chunk.hpp"
#include "plan/plan_machine.hpp"
#include "toolpaths/plan_export.hpp"

namespace hybridctl::drivers {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_between(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double>(to - from).count();
}

std::string hex(std::uint64_t v) {
  char b[17];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(v));
  return b;
}

// The program to run and the job it belongs to.
struct Job {
  bool resumed = false;
  bool restarted = false;          // resumed at --from-line as a new program (the controller lost it)
  bool resume_when_ours = false;   // StreamOptions::resume_when_ours
  config::Machine machine;
  std::string embedded_machine;    // a plan's machine text when no machine file was given: kept in the job directory
  JournalHeader header;
  std::optional<Journal> journal;  // `run`'s own record; the cell's is the caller's
  JobRecord* record = nullptr;     // the journal, or the caller's record
  std::string text;                // as read or posted: what `gcode check` reads
  gcode::PostedProgram program;    // its lines as streamed, with its action table
};

void open_resumed_job(const JobRequest& request, Job& job) {
  job.resumed = true;
  job.journal = Journal::open(request.resume);
  job.header = job.journal->header();
  job.text = gcode::read_text_file(job.header.program);
  job.machine = gcode::load_postable_machine(request.machine.empty() ? job.header.machine : request.machine);
  if (request.from_line > 0) {
    job.restarted = true;
    job.text = restart_job(*job.journal, job.machine, request.from_line);
    job.header = job.journal->header();
  }
  if (!request.transport.empty()) job.header.transport = request.transport;
  job.program = gcode::PostedProgram::from_lines(protocol::program_lines(job.text));
}

// A plan is exported and posted now (the program `hybridctl export` writes); a program
// file is taken as it is.
void assemble_new_job(const JobRequest& request, Job& job, JobOperator& op) {
  if (request.input.empty()) throw InputError("expected a PLAN.json or PROGRAM.ngc to run, or --resume JOB");
  if (request.transport.empty()) throw InputError("--transport: expected a URI (" + std::string("modbus-tcp://HOST:PORT, ...") + ")");
  const fs::path in = request.input;
  const bool is_plan = fs::is_directory(in) || in.extension() == ".json";
  if (!is_plan && request.machine.empty()) throw InputError("--machine: expected the machine file");
  if (is_plan) {
    const plan::PlanFile file = plan::read_plan_file(in);
    plan::PlanMachine chosen = plan::plan_machine(file, {request.machine, request.machine_override});
    if (!chosen.note.empty()) op.note(chosen.note);
    job.machine = std::move(chosen.machine);
    if (chosen.file.empty()) job.embedded_machine = std::move(chosen.text);
    job.header.machine = chosen.file.empty() ? "" : fs::absolute(chosen.file).string();
    if (request.rank < 1 || request.rank > int(file.plans.size()))
      throw InputError("--plan " + std::to_string(request.rank) + ": expected 1.." + std::to_string(file.plans.size()));
    const auto& plan = file.plans[std::size_t(request.rank - 1)];
    gcode::PostOptions post;
    post.program_name = "plan-" + std::to_string(request.rank) + " " + plan.expression;
    job.program = request.plan_program
                      ? request.plan_program(file, plan, job.machine, post)
                      : gcode::post_program(toolpaths::export_plan(file, plan, job.machine).programs(), job.machine, post);
    job.text = job.program.text();
    job.header.source = in.string() + " plan " + std::to_string(request.rank);
  } else {
    job.machine = gcode::load_postable_machine(request.machine);
    job.text = gcode::read_text_file(in);
    job.program = gcode::PostedProgram::from_lines(protocol::program_lines(job.text));
    job.header.source = in.string();
    job.header.machine = fs::absolute(request.machine).string();
  }
  job.header.transport = request.transport;
}

// The program must be clean for this machine before anything moves. Returns its cycle
// time.
gcode::TimeEstimate precheck(const std::string& name, const Job& job, JobOperator& op) {
  const gcode::CheckReport check = gcode::check_program(job.text, job.machine, name);
  if (!check.clean()) {
    op.check_failed(check);
    throw InputError("the program does not pass `gcode check` for machine '" + job.machine.name + "': nothing was sent");
  }
  return check.time;
}

// A resumed job must still have its program; a new one gets its directory, the program
// file and the journal.
void open_journal(const JobRequest& request, Job& job, std::uint64_t identity) {
  if (job.journal) {
    if (job.header.identity != identity)
      throw InputError(job.header.program + ": the program changed since the job started (identity " + hex(identity) +
                       ", journal " + hex(job.header.identity) + "): refusing to resume");
    return;
  }
  const fs::path dir = request.job.empty() ? fs::path("jobs") / hex(identity).substr(0, 12) : fs::path(request.job);
  fs::create_directories(dir);
  const fs::path program = fs::absolute(dir / "program.ngc");
  const std::string text = protocol::program_text(job.program.lines);
  if (!fs::exists(program) || gcode::read_text_file(program) != text) gcode::write_text_file(program, text);
  if (!job.embedded_machine.empty()) {
    // The plan's embedded machine, as a file a resume loads it from.
    const fs::path machine = fs::absolute(dir / "machine.yaml");
    gcode::write_text_file(machine, job.embedded_machine);
    job.header.machine = machine.string();
  }
  job.header.program = program.string();
  job.header.identity = identity;
  job.header.lines = std::uint32_t(job.program.lines.size());
  job.journal = Journal::create(dir, job.header);
}

// The lines the controller executes: the program's, without the tape markers ("%") and
// blank lines it may end with, which carry no block (a program posted for LinuxCNC ends
// in "%" after its M30; the status never reports that line executed).
std::size_t executable_lines(const std::vector<std::string>& lines) {
  std::size_t n = lines.size();
  while (n > 0 && lines[n - 1].find_first_not_of(" \t\r%") == std::string::npos) --n;
  return n;
}

// Per action of the program: when its first and last lines were seen executed (host
// clock, from the status), and the alarms raised while it ran. An action's lines run from
// its heading to the next action's; the last action's to the program's end (the end
// block runs as part of it).
class ActionTracker {
 public:
  explicit ActionTracker(const gcode::PostedProgram& program) {
    const auto& table = program.actions;
    for (std::size_t i = 0; i < table.size(); ++i) {
      Span s;
      s.first = table[i].first_line;
      s.last = i + 1 < table.size() ? table[i + 1].first_line - 1 : std::uint32_t(executable_lines(program.lines));
      s.name = table[i].heading();
      s.number = table[i].number;
      spans_.push_back(std::move(s));
    }
  }

  std::size_t size() const { return spans_.size(); }
  // The plan's number of the 1-based `action`; 0 for none.
  int number(std::size_t action) const { return action == 0 ? 0 : spans_[action - 1].number; }

  void seen(const protocol::Status& s, Clock::time_point now) {
    for (auto& a : spans_) {
      if (!a.started && s.last_executed_line >= a.first) a.started = now;
      if (!a.finished && s.last_executed_line >= a.last) a.finished = now;
    }
  }

  // 1-based: the action the next line to execute belongs to; 0 before the first.
  std::size_t current(const protocol::Status& s) const {
    std::size_t action = 0;
    for (std::size_t i = 0; i < spans_.size(); ++i)
      if (spans_[i].first <= s.last_executed_line + 1) action = i + 1;
    return action;
  }

  // On the action of the alarm's line (the last action when past the end); none before the first.
  void alarm(const protocol::Status& s) {
    if (s.alarm == protocol::AlarmCode::None) return;
    const std::uint32_t line = std::max<std::uint32_t>(s.alarm_line ? s.alarm_line : s.last_executed_line + 1, 1);
    Span* found = nullptr;
    for (auto& a : spans_)
      if (a.first <= line) found = &a;
    if (found) found->alarms.emplace_back(protocol::to_string(s.alarm));
    raised_.emplace_back(protocol::to_string(s.alarm), line);
  }

  // Every alarm raised so far, in order, with its line.
  const std::vector<std::pair<std::string, std::uint32_t>>& raised() const { return raised_; }

  std::vector<ActionReport> report(std::uint32_t executed, Clock::time_point end) const {
    std::vector<ActionReport> out;
    for (const Span& a : spans_) {
      ActionReport r;
      r.name = a.name;
      r.lines = a.last - a.first + 1;
      r.executed = executed < a.first ? 0 : std::min(a.last, executed) - a.first + 1;
      if (a.started) r.seconds = seconds_between(*a.started, a.finished.value_or(end));
      for (const std::string& name : a.alarms) {
        auto it = std::find_if(r.alarms.begin(), r.alarms.end(), [&](const auto& c) { return c.first == name; });
        if (it == r.alarms.end())
          r.alarms.emplace_back(name, 1);
        else
          ++it->second;
      }
      out.push_back(std::move(r));
    }
    return out;
  }

 private:
  struct Span {
    std::uint32_t first = 0, last = 0;  // program lines
    std::string name;
    int number = 0;  // the plan's action number
    std::optional<Clock::time_point> started, finished;
    std::vector<std::string> alarms;
  };
  std::vector<Span> spans_;
  std::vector<std::pair<std::string, std::uint32_t>> raised_;
};

// The comment before a program stop: the operator's instructions.
std::string operator_message(const std::vector<std::string>& lines, std::uint32_t stop_line) {
  for (std::uint32_t l = stop_line; l >= 1 && l + 3 > stop_line; --l) {
    const std::string& t = lines[l - 1];
    const auto open = t.find('('), close = t.rfind(')');
    if (open != std::string::npos && close != std::string::npos && close > open) return t.substr(open + 1, close - open - 1);
  }
  return "program stop";
}

StreamCallbacks stream_callbacks(JobOperator& op, ActionTracker& actions, const std::vector<std::string>& lines,
                                 Clock::time_point begun) {
  StreamCallbacks cb;
  cb.status = [&op, &actions, &lines, begun](const protocol::Status& s) {
    const auto now = Clock::now();
    actions.seen(s, now);
    JobProgress p;
    p.action = actions.current(s);
    p.actions = actions.size();
    p.action_number = actions.number(p.action);
    p.lines = executable_lines(lines);
    p.done = p.lines == 0 ? 1 : std::min(1.0, double(s.last_executed_line) / double(p.lines));
    p.eta_s = p.done > 0.01 ? seconds_between(begun, now) * (1 - p.done) / p.done : 0;
    op.progress(s, p);
  };
  cb.note = [&op](const std::string& n) { op.note(n); };
  cb.program_stop = [&op, &lines](const protocol::Status& s) {
    return op.continue_after_stop(s, operator_message(lines, s.last_executed_line));
  };
  cb.recover = [&op, &actions](const protocol::Status& s) {
    actions.alarm(s);
    return op.clear_alarm(s);
  };
  cb.warning = [&actions](const protocol::Status& s) { actions.alarm(s); };
  cb.hold_requested = [&op] { return op.hold_requested(); };
  cb.resume_after_hold = [&op](const protocol::Status& s) { return op.resume_after_hold(s); };
  return cb;
}

JobResult stream_job(Job& job, JobOperator& op, double wait_for_controller_s) {
  auto transport = open_transport(job.header.transport);
  ActionTracker actions(job.program);
  const auto begun = Clock::now();
  const StreamCallbacks cb = stream_callbacks(op, actions, job.program.lines, begun);
  StreamOptions options;
  options.resume = job.resumed && !job.restarted;
  options.resume_when_ours = job.resume_when_ours;
  options.controller_back_within_s = wait_for_controller_s;
  options.resume_host_hold = options.resume && job.record->progress().held_by_host;
  JobResult result;
  result.stream = stream_program(*transport, job.program.lines, options, cb, job.record);
  result.seconds = seconds_between(begun, Clock::now());
  result.transport = transport->counters();
  result.lines = executable_lines(job.program.lines);
  if (!result.stream.completed) actions.alarm(result.stream.final_status);
  result.actions = actions.report(result.stream.final_status.last_executed_line, Clock::now());
  result.alarms = actions.raised();
  return result;
}

}  // namespace

JobResult execute_job(const JobRequest& request, JobOperator& op) {
  Job job;
  if (!request.resume.empty())
    open_resumed_job(request, job);
  else
    assemble_new_job(request, job, op);
  const std::uint64_t identity = protocol::program_identity(job.program.lines);
  const gcode::TimeEstimate time = precheck(job.header.program.empty() ? request.input : job.header.program, job, op);
  open_journal(request, job, identity);
  job.record = &*job.journal;
  op.started({job.journal->file().parent_path().string(), job.header.program, job.program.lines.size(), identity,
              job.machine.name, job.header.transport, time.total, time.str()});
  return stream_job(job, op, request.wait_for_controller_s);
}

JobResult execute_recorded_job(const RecordedJob& recorded, JobOperator& op) {
  Job job;
  job.resumed = recorded.resume;
  job.resume_when_ours = true;
  job.machine = recorded.machine;
  job.text = recorded.program_text;
  job.program = gcode::PostedProgram::from_lines(protocol::program_lines(job.text));
  job.header.transport = recorded.transport;
  job.record = recorded.record;
  const std::uint64_t identity = protocol::program_identity(job.program.lines);
  const gcode::TimeEstimate time = precheck(recorded.program_name, job, op);
  op.started({recorded.name, recorded.program_name, job.program.lines.size(), identity, job.machine.name, recorded.transport,
              time.total, time.str()});
  return stream_job(job, op, recorded.wait_for_controller_s);
}

}  // namespace hybridctl::drivers
