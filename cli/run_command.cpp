// hybridctl run: stream a plan or a program to a machine, exactly once, and watch it.

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <vector>

#include "cli/commands.hpp"
#include "cli/ranges.hpp"
#include "cli/run_job.hpp"
#include "common/error.hpp"
#include "config/machine_loader.hpp"
#include "drivers/job_restart.hpp"
#include "drivers/journal.hpp"
#include "protocol/chunk.hpp"
#include "drivers/streamer.hpp"
#include "gcode/check.hpp"
#include "gcode/files.hpp"
#include "toolpaths/plan_export.hpp"

namespace hybridctl::cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::atomic<bool> interrupted{false};
extern "C" void on_sigint(int) { interrupted = true; }

std::string hex(std::uint64_t v) {
  char b[17];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(v));
  return b;
}

// Where each action's block starts in the program: the post-processor writes
// "(action K: ...)" before it.
std::vector<std::pair<std::uint32_t, std::string>> action_starts(const std::vector<std::string>& lines) {
  std::vector<std::pair<std::uint32_t, std::string>> out;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string& l = lines[i];
    const auto at = l.find("(action ");
    if (at != std::string::npos && l.find(':', at) != std::string::npos) out.emplace_back(std::uint32_t(i + 1), l.substr(at + 1, l.size() - at - 2));
  }
  return out;
}

bool ask(const std::string& question) {
  if (::isatty(STDIN_FILENO) != 1) return false;
  std::fprintf(stderr, "\n%s [y/N] ", question.c_str());
  std::fflush(stderr);
  std::string answer;
  if (!std::getline(std::cin, answer)) return false;
  return !answer.empty() && (answer[0] == 'y' || answer[0] == 'Y');
}

// What the final report says of one action: when its first and last lines were seen
// executed (host clock, from the status), and the alarms raised while it ran.
struct ActionLog {
  std::uint32_t first = 0, last = 0;  // program lines
  std::string name;
  std::optional<Clock::time_point> started, finished;
  std::vector<std::string> alarms;
};

std::vector<ActionLog> action_logs(const std::vector<std::string>& lines) {
  std::vector<ActionLog> out;
  const auto starts = action_starts(lines);
  for (std::size_t i = 0; i < starts.size(); ++i) {
    ActionLog a;
    a.first = starts[i].first;
    a.last = i + 1 < starts.size() ? starts[i + 1].first - 1 : std::uint32_t(lines.size());
    a.name = starts[i].second;
    out.push_back(std::move(a));
  }
  return out;
}

// The action a program line belongs to (the last one when past the end); null when none.
ActionLog* action_of(std::vector<ActionLog>& actions, std::uint32_t line) {
  ActionLog* found = nullptr;
  for (auto& a : actions)
    if (a.first <= std::max<std::uint32_t>(line, 1)) found = &a;
  return found;
}

// The comment before a program stop: the operator's instructions.
std::string operator_message(const std::vector<std::string>& lines, std::uint32_t stop_line) {
  for (std::uint32_t l = stop_line; l >= 1 && l + 3 > stop_line; --l) {
    const std::string& t = lines[l - 1];
    const auto open = t.find('('), close = t.rfind(')');
    if (open != std::string::npos && close != std::string::npos && close > open) return t.substr(open + 1, close - open - 1);
  }
  return "program stop";
}

}  // namespace

int run_job(const RunRequest& request) {
  // Ctrl-C holds the feed (and asks) once streaming runs; before that it is noted too.
  interrupted = false;
  std::signal(SIGINT, on_sigint);
  // What to run: a resumed job's program, a program file, or a plan exported now.
  drivers::JournalHeader header;
  std::optional<drivers::Journal> journal;
  std::string text;
  config::Machine machine;
  if (!request.resume.empty()) {
    journal = drivers::Journal::open(request.resume);
    header = journal->header();
    text = gcode::read_text_file(header.program);
    machine = config::load_machine(request.machine.empty() ? header.machine : request.machine);
    if (request.from_line > 0) {
      text = drivers::restart_job(*journal, machine, request.from_line);
      header = journal->header();
    }
    if (!request.transport.empty()) header.transport = request.transport;
  } else {
    if (request.input.empty()) throw InputError("expected a PLAN.json or PROGRAM.ngc to run, or --resume JOB");
    if (request.machine.empty()) throw InputError("--machine: expected the machine file");
    if (request.transport.empty()) throw InputError("--transport: expected a URI (" + std::string("modbus-tcp://HOST:PORT, ...") + ")");
    machine = config::load_machine(request.machine);
    const fs::path in = request.input;
    if (fs::is_directory(in) || in.extension() == ".json") {
      const planner::PlanFile file = planner::read_plan_file(in);
      if (request.rank < 1 || request.rank > int(file.plans.size()))
        throw InputError("--plan " + std::to_string(request.rank) + ": expected 1.." + std::to_string(file.plans.size()));
      const auto& plan = file.plans[std::size_t(request.rank - 1)];
      gcode::PostOptions post;
      post.program_name = "plan-" + std::to_string(request.rank) + " " + plan.expression;
      text = gcode::write_program(toolpaths::export_plan(file, plan, machine).programs(), machine, post);
      header.source = in.string() + " plan " + std::to_string(request.rank);
    } else {
      text = gcode::read_text_file(in);
      header.source = in.string();
    }
    header.machine = fs::absolute(request.machine).string();
    header.transport = request.transport;
  }
  const std::vector<std::string> lines = protocol::program_lines(text);
  const std::uint64_t identity = protocol::program_identity(lines);

  // Prechecks: the program must be clean for this machine before anything moves.
  const gcode::CheckReport check = gcode::check_program(text, machine, header.program.empty() ? request.input : header.program);
  if (!check.clean()) {
    std::fputs(check.str().c_str(), stdout);
    throw InputError("the program does not pass `gcode check` for machine '" + machine.name + "': nothing was sent");
  }
  if (journal) {
    if (header.identity != identity)
      throw InputError(header.program + ": the program changed since the job started (identity " + hex(identity) +
                       ", journal " + hex(header.identity) + "): refusing to resume");
  } else {
    const fs::path job = request.job.empty() ? fs::path("jobs") / hex(identity).substr(0, 12) : fs::path(request.job);
    fs::create_directories(job);
    const fs::path program = fs::absolute(job / "program.ngc");
    if (!fs::exists(program) || gcode::read_text_file(program) != protocol::program_text(lines))
      gcode::write_text_file(program, protocol::program_text(lines));
    header.program = program.string();
    header.identity = identity;
    header.lines = std::uint32_t(lines.size());
    journal = drivers::Journal::create(job, header);
  }
  std::printf("job         %s (program %s, %zu lines, identity %s)\n", journal->file().parent_path().string().c_str(),
              header.program.c_str(), lines.size(), hex(identity).c_str());
  std::printf("machine     %s via %s; estimated %s\n", machine.name.c_str(), header.transport.c_str(),
              gcode::format_duration(check.time.total).c_str());
  std::fflush(stdout);

  auto transport = drivers::open_transport(header.transport);
  std::vector<ActionLog> actions = action_logs(lines);
  const bool tty = ::isatty(STDERR_FILENO) == 1;
  const auto begun = Clock::now();
  auto last_print = Clock::now() - std::chrono::seconds(10);
  auto add_alarm = [&](const protocol::Status& s) {
    if (s.alarm == protocol::AlarmCode::None) return;
    if (ActionLog* a = action_of(actions, s.alarm_line ? s.alarm_line : s.last_executed_line + 1))
      a->alarms.emplace_back(protocol::to_string(s.alarm));
  };

  drivers::StreamCallbacks cb;
  cb.status = [&](const protocol::Status& s) {
    const auto now = Clock::now();
    for (auto& a : actions) {
      if (!a.started && s.last_executed_line >= a.first) a.started = now;
      if (!a.finished && s.last_executed_line >= a.last) a.finished = now;
    }
    const double every = tty ? 0.1 : 2.0;
    if (std::chrono::duration<double>(Clock::now() - last_print).count() < every) return;
    last_print = Clock::now();
    std::size_t action = 0;
    for (std::size_t i = 0; i < actions.size(); ++i)
      if (actions[i].first <= s.last_executed_line + 1) action = i + 1;
    const double done = lines.empty() ? 1 : double(s.last_executed_line) / double(lines.size());
    const double elapsed = std::chrono::duration<double>(Clock::now() - begun).count();
    const double eta = done > 0.01 ? elapsed * (1 - done) / done : 0;
    char buf[256];
    std::snprintf(buf, sizeof buf, "action %zu/%zu  line %u/%zu  %3.0f%%  ETA %s  %-12s  X%.3f Y%.3f Z%.3f  T%u", action,
                  actions.size(), s.last_executed_line, lines.size(), done * 100,
                  gcode::format_duration(eta).c_str(), std::string(protocol::to_string(s.state)).c_str(), s.x_um / 1000.0,
                  s.y_um / 1000.0, s.z_um / 1000.0, unsigned(s.active_tool));
    if (tty) {
      std::fprintf(stderr, "\r%s", buf);
    } else {
      std::fprintf(stderr, "%s\n", buf);
    }
  };
  cb.note = [&](const std::string& n) { std::fprintf(stderr, "%s%s\n", tty ? "\n" : "", n.c_str()); };
  cb.program_stop = [&](const protocol::Status& s) {
    const std::string message = operator_message(lines, s.last_executed_line);
    std::fprintf(stderr, "%sprogram stop after line %u: %s\n", tty ? "\n" : "", s.last_executed_line, message.c_str());
    if (request.yes) return true;
    return ask("Operator: done? continue the program");
  };
  cb.recover = [&](const protocol::Status& s) {
    add_alarm(s);
    const auto& info = protocol::alarm_info(s.alarm);
    std::fprintf(stderr, "%salarm %s: %s\n  what to do: %s\n", tty ? "\n" : "", std::string(info.name).c_str(),
                 std::string(info.meaning).c_str(), std::string(info.action).c_str());
    if (request.yes) return true;
    return ask("Clear the alarm and resume");
  };
  cb.hold_requested = [&] { return interrupted.exchange(false); };
  cb.resume_after_hold = [&](const protocol::Status&) {
    std::fprintf(stderr, "%sfeed hold (Ctrl-C)\n", tty ? "\n" : "");
    return ask("Resume the program (no: abort it)");
  };

  drivers::StreamOptions options;
  options.resume = !request.resume.empty() && request.from_line == 0;
  options.resume_host_hold = options.resume && journal->progress().held_by_host;
  const drivers::StreamResult r = drivers::stream_program(*transport, lines, options, cb, &*journal);
  std::signal(SIGINT, SIG_DFL);
  if (tty) std::fprintf(stderr, "\n");

  const double seconds = std::chrono::duration<double>(Clock::now() - begun).count();
  const auto tc = transport->counters();
  std::printf("%s after %u of %zu lines in %.1f s (%.0f lines/s)\n", r.completed ? "completed" : "STOPPED",
              r.final_status.last_executed_line, lines.size(), seconds, double(r.final_status.last_executed_line) / std::max(seconds, 1e-9));
  if (!r.completed) {
    std::printf("why         %s\n", r.stopped_because.c_str());
    add_alarm(r.final_status);
  }
  // Per action: lines executed, the time from its first executed line to its last (as the
  // host saw the status), and the alarms raised in it.
  const auto end = Clock::now();
  for (const ActionLog& a : actions) {
    const std::uint32_t executed = r.final_status.last_executed_line;
    const std::uint32_t done = executed < a.first ? 0 : std::min(a.last, executed) - a.first + 1;
    std::string time = "-";
    if (a.started) time = gcode::format_duration(std::chrono::duration<double>(a.finished.value_or(end) - *a.started).count());
    // Each alarm once, in the order first raised, with how often when more than once.
    std::vector<std::pair<std::string, int>> counted;
    for (const std::string& name : a.alarms) {
      auto it = std::find_if(counted.begin(), counted.end(), [&](const auto& c) { return c.first == name; });
      if (it == counted.end()) counted.emplace_back(name, 1);
      else ++it->second;
    }
    std::string alarms;
    for (std::size_t k = 0; k < counted.size(); ++k)
      alarms += (k ? ", " : "  alarms ") + counted[k].first +
                (counted[k].second > 1 ? " x" + std::to_string(counted[k].second) : std::string());
    std::printf("  %-60s %u/%u lines  %s%s\n", a.name.c_str(), done, a.last - a.first + 1, time.c_str(), alarms.c_str());
  }
  std::printf("counters    chunks %llu sent, %llu accepted, %llu duplicates, %llu refused; %llu reboots seen, %llu alarms "
              "cleared, %llu link failures recovered; transport %llu requests, %llu timeouts, %llu retries, %llu reconnects, "
              "%llu bad replies\n",
              (unsigned long long)r.counters.chunks_sent, (unsigned long long)r.counters.chunks_accepted,
              (unsigned long long)r.counters.duplicates, (unsigned long long)r.counters.refused,
              (unsigned long long)r.counters.reboots_seen, (unsigned long long)r.counters.recoveries,
              (unsigned long long)r.counters.transport_errors,
              (unsigned long long)tc.requests, (unsigned long long)tc.timeouts, (unsigned long long)tc.retries,
              (unsigned long long)tc.reconnects, (unsigned long long)tc.bad_replies);
  return r.completed ? int(kSuccess) : int(kMachineStopped);
}

void add_run_command(CLI::App& app, Runner& runner) {
  auto request = std::make_shared<RunRequest>();
  auto* cmd = app.add_subcommand(
      "run", "Stream a plan (plan.json: exported now) or a G-code program to a machine over Modbus or CAN, exactly once, "
             "with a live status line; a job journal lets --resume continue after the host died (exit 5 when the "
             "machine stopped before the end)");
  cmd->add_option("INPUT", request->input, "plan.json (or its directory) or a G-code program");
  cmd->add_option("-m,--machine", request->machine, "Machine description (YAML); with --resume: the journal's");
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
  cmd->add_flag("-y,--yes", request->yes, "Unattended: continue after program stops and clear recoverable alarms");
  cmd->callback([&runner, request] { runner = [request] { return run_job(*request); }; });
}

}  // namespace hybridctl::cli
