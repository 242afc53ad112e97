// hybridctl run: stream a plan or a program to a machine, exactly once, and watch it.

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <memory>

#include "cli/commands.hpp"
#include "cli/ranges.hpp"
#include "cli/run_job.hpp"
#include "drivers/executor.hpp"
#include "gcode/check.hpp"
#include "validation/execution.hpp"

namespace hybridctl::cli {
namespace {

using Clock = std::chrono::steady_clock;

std::atomic<bool> interrupted{false};
extern "C" void on_sigint(int) { interrupted = true; }

// Ctrl-C holds the feed (and asks) once streaming runs; before that it is noted too.
struct SigintHold {
  SigintHold() {
    interrupted = false;
    std::signal(SIGINT, on_sigint);
  }
  ~SigintHold() { std::signal(SIGINT, SIG_DFL); }
};

std::string hex(std::uint64_t v) {
  char b[17];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(v));
  return b;
}

// What a stopped controller waits for, for the status line ("" while it runs).
std::string waiting_for(const protocol::Status& s) {
  using protocol::ControllerState;
  switch (s.state) {
    case ControllerState::FeedHold: return "feed hold: cycle start (RESUME)";
    case ControllerState::ProgramStop:
    case ControllerState::OptionalStop: return "program stop: the operator's acknowledgement";
    case ControllerState::Alarm: return "alarm " + std::string(protocol::to_string(s.alarm)) + ": reset";
    default: return "";
  }
}

// The operator at a terminal (or a log): a live status line and events on stderr,
// questions on the terminal; --yes answers them.
class TerminalOperator : public drivers::JobOperator {
 public:
  explicit TerminalOperator(bool yes) : yes_(yes) {}
  const bool tty = ::isatty(STDERR_FILENO) == 1;

  void check_failed(const gcode::CheckReport& report) override { std::fputs(report.str().c_str(), stdout); }

  void started(const drivers::JobStart& job) override {
    std::printf("job         %s (program %s, %zu lines, identity %s)\n", job.job_directory.c_str(), job.program.c_str(),
                job.lines, hex(job.identity).c_str());
    std::printf("machine     %s via %s\ncycle time  %s\n", job.machine.c_str(), job.transport.c_str(),
                job.cycle_time.c_str());
    std::fflush(stdout);
    last_print_ = Clock::now() - std::chrono::seconds(10);
  }

  void progress(const protocol::Status& s, const drivers::JobProgress& p) override {
    const double every = tty ? 0.1 : 2.0;
    if (std::chrono::duration<double>(Clock::now() - last_print_).count() < every) return;
    last_print_ = Clock::now();
    char buf[256];
    // The plan's action number, as the program's headings and the final report give it, and
    // how far through the program's actions that is (a raw stock action has no lines).
    const std::string action = p.action_number > 0 ? std::to_string(p.action_number) : std::string("-");
    std::snprintf(buf, sizeof buf, "action %s (%zu/%zu)  line %u/%zu  %3.0f%%  ETA %s  %-12s  X%.3f Y%.3f Z%.3f  T%u",
                  action.c_str(), p.action, p.actions, s.last_executed_line, p.lines, p.done * 100, gcode::format_duration(p.eta_s).c_str(),
                  std::string(protocol::to_string(s.state)).c_str(), s.x_um / 1000.0, s.y_um / 1000.0, s.z_um / 1000.0,
                  unsigned(s.active_tool));
    const std::string waiting = waiting_for(s);
    if (!waiting.empty()) std::snprintf(buf + std::strlen(buf), sizeof buf - std::strlen(buf), "  waiting: %s", waiting.c_str());
    if (tty) {
      std::fprintf(stderr, "\r%s", buf);
    } else {
      std::fprintf(stderr, "%s\n", buf);
    }
  }

  void note(const std::string& n) override { std::fprintf(stderr, "%s%s\n", tty ? "\n" : "", n.c_str()); }

  bool continue_after_stop(const protocol::Status& s, const std::string& message) override {
    std::fprintf(stderr, "%sprogram stop after line %u: %s\n", tty ? "\n" : "", s.last_executed_line, message.c_str());
    if (yes_) return true;
    return ask_at_terminal("Operator: done? continue the program");
  }

  bool clear_alarm(const protocol::Status& s) override {
    const auto& info = protocol::alarm_info(s.alarm);
    std::fprintf(stderr, "%salarm %s at line %u: %s\n  what to do: %s\n", tty ? "\n" : "", std::string(info.name).c_str(),
                 unsigned(s.alarm_line), std::string(info.meaning).c_str(), std::string(info.action).c_str());
    if (yes_) return true;
    return ask_at_terminal("Clear the alarm and resume");
  }

  bool hold_requested() override { return interrupted.exchange(false); }

  bool resume_after_hold(const protocol::Status&) override {
    std::fprintf(stderr, "%sfeed hold (Ctrl-C)\n", tty ? "\n" : "");
    return ask_at_terminal("Resume the program (no: abort it)");
  }

 private:
  bool yes_;
  Clock::time_point last_print_ = Clock::now() - std::chrono::seconds(10);
};

// The end of the run on stdout: how far it got, per action (lines executed, time, alarms),
// and what the stream and the transport went through.
void print_report(const drivers::JobResult& job) {
  const drivers::StreamResult& r = job.stream;
  const std::uint32_t executed = r.final_status.last_executed_line;
  std::printf("%s after %u of %zu lines in %.1f s (%.0f lines/s)\n", r.completed ? "completed" : "STOPPED", executed,
              job.lines, job.seconds, double(executed) / std::max(job.seconds, 1e-9));
  if (!r.completed) std::printf("why         %s\n", r.stopped_because.c_str());
  const protocol::Status& f = r.final_status;
  std::printf("machine     at X%.3f Y%.3f Z%.3f, tool T%u, spindle %d rpm, deposition %s, line %u, state %s\n",
              f.x_um / 1000.0, f.y_um / 1000.0, f.z_um / 1000.0, unsigned(f.active_tool), int(f.spindle_rpm),
              f.deposition_on ? "on" : "off", f.last_executed_line, std::string(protocol::to_string(f.state)).c_str());
  for (const drivers::ActionReport& a : job.actions) {
    // The controller's time for it as the host saw the status: the machine's real time (a
    // simulated controller's, scaled by its --time-scale).
    const std::string time = a.seconds ? "ran " + gcode::format_duration(*a.seconds) : "-";
    std::string alarms;
    for (std::size_t k = 0; k < a.alarms.size(); ++k)
      alarms += (k ? ", " : "  alarms ") + a.alarms[k].first +
                (a.alarms[k].second > 1 ? " x" + std::to_string(a.alarms[k].second) : std::string());
    std::printf("  %-60s %u/%u lines  %s%s\n", a.name.c_str(), a.executed, a.lines, time.c_str(), alarms.c_str());
  }
  const drivers::StreamCounters& c = r.counters;
  const drivers::TransportCounters& tc = job.transport;
  std::printf("counters    chunks %llu sent, %llu accepted, %llu duplicates, %llu refused; %llu reboots seen, %llu alarms "
              "cleared, %llu warnings, %llu link failures recovered; transport %llu requests, %llu timeouts, %llu retries, %llu reconnects, "
              "%llu bad replies\n",
              (unsigned long long)c.chunks_sent, (unsigned long long)c.chunks_accepted, (unsigned long long)c.duplicates,
              (unsigned long long)c.refused, (unsigned long long)c.reboots_seen, (unsigned long long)c.recoveries,
              (unsigned long long)c.warnings, (unsigned long long)c.transport_errors, (unsigned long long)tc.requests, (unsigned long long)tc.timeouts,
              (unsigned long long)tc.retries, (unsigned long long)tc.reconnects, (unsigned long long)tc.bad_replies);
}

// A plan's program as export writes it: each action planned against the material the
// ones before it leave, executed on the simulated machine from the raw stock first; a plan
// that does not make the part is refused (exit 4) before anything is streamed.
gcode::PostedProgram proven_plan_program(const plan::PlanFile& file, const plan::PlanFilePlan& plan,
                                         const config::Machine& machine, const gcode::PostOptions& post) {
  validation::ExecutionOptions options;
  options.export_options.post = post;
  return validation::require_proven(file, plan, machine, options, "plan " + std::to_string(plan.rank) + " (" +
                                                                      plan.expression + ")")
      .program;
}

}  // namespace

int run_job(const RunRequest& request, std::vector<std::pair<std::string, std::uint32_t>>* alarms) {
  TerminalOperator op(request.yes);
  drivers::JobResult result;
  {
    const SigintHold hold;
    result = drivers::execute_job(
        {request.input, request.machine, request.transport, request.rank, request.job, request.resume, request.from_line,
         request.machine_override, proven_plan_program, request.wait_for_controller},
        op);
  }
  if (op.tty) std::fprintf(stderr, "\n");
  print_report(result);
  if (alarms) *alarms = result.alarms;
  return result.stream.completed ? int(kSuccess) : int(kMachineStopped);
}

bool ask_at_terminal(const std::string& question) {
  if (::isatty(STDIN_FILENO) != 1) return false;
  std::fprintf(stderr, "\n%s [y/N] ", question.c_str());
  std::fflush(stderr);
  std::string answer;
  if (!std::getline(std::cin, answer)) return false;
  return !answer.empty() && (answer[0] == 'y' || answer[0] == 'Y');
}

drivers::JobResult run_recorded_job(const drivers::RecordedJob& job, bool yes) {
  TerminalOperator op(yes);
  drivers::JobResult result;
  {
    const SigintHold hold;
    result = drivers::execute_recorded_job(job, op);
  }
  if (op.tty) std::fprintf(stderr, "\n");
  print_report(result);
  return result;
}

void add_run_command(CLI::App& app, Runner& runner) {
  auto request = std::make_shared<RunRequest>();
  auto* cmd = app.add_subcommand(
      "run", "Stream a plan (plan.json: exported now, and executed on the simulated machine first: exit 4 and "
             "nothing streamed when it does not make its part or is unsafe) or a G-code program to a machine over "
             "Modbus or CAN, exactly once, with a live status line; a job journal lets --resume continue after the "
             "host died (exit 5 when the machine stopped before the end)");
  cmd->add_option("INPUT", request->input, "plan.json (or its directory) or a G-code program");
  cmd->add_option("-m,--machine", request->machine,
                  "Machine description (YAML); with a plan: the one plan.json embeds, and another machine is refused "
                  "unless --machine-override; with --resume: the journal's");
  cmd->add_flag("--machine-override", request->machine_override,
                "With a plan and --machine: use it even when it is not the machine the plan was made with");
  cmd->add_option("-t,--transport", request->transport,
                  "modbus-tcp://HOST:PORT[?unit=N], modbus-rtu:///dev/DEV[?baud=B&parity=P], socketcand://HOST:PORT/CHANNEL, "
                  "socketcan://IFACE; with --resume: the journal's");
  cmd->add_option("--plan", request->rank, "With a plan: which plan, by rank")->default_val(1)->check(greater_than(0));
  cmd->add_option("--job", request->job, "Job directory for the journal and the program (default: jobs/IDENTITY)");
  cmd->add_option("--resume", request->resume, "Continue the job in this directory where the controller is");
  cmd->add_option("--from-line", request->from_line,
                  "With --resume, after the controller lost the program: restart it at this line as a new program (the "
                  "line the loss message names, after checking the machine)")
      ->needs("--resume");
  cmd->add_option("--wait-for-controller", request->wait_for_controller,
                  "Seconds to wait for a controller that stops answering mid-program (a power cycle) before giving up "
                  "(exit 6; --resume goes on later)")
      ->default_val(120)
      ->check(CLI::Range(0.0, 86400.0));
  cmd->add_flag("-y,--yes", request->yes, "Unattended: continue after program stops and clear recoverable alarms");
  cmd->callback([&runner, request] { runner = [request] { return run_job(*request); }; });
}

}  // namespace hybridctl::cli
