// hybridctl status: the controller's status block, once or watched (docs/drivers.md).

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <memory>
#include <string>
#include <thread>

#include "cli/commands.hpp"
#include "cli/ranges.hpp"
#include "protocol/codes.hpp"
#include "protocol/messages.hpp"
#include "drivers/transport.hpp"

namespace hybridctl::cli {
namespace {

using protocol::Status;

std::atomic<bool> g_status_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler needs a lock-free flag");
extern "C" void on_status_stop_signal(int) { g_status_stop.store(true); }

struct StatusRequest {
  std::string uri;
  bool watch = false;
  double interval_s = 1.0;
  long count = 0;  // updates to print in watch mode, 0: until Ctrl-C
  int timeout_ms = 1000;
};

std::string format(const char* fmt, auto... args) {
  char buf[512];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

std::string hex64(std::uint64_t v) { return format("0x%016llx", static_cast<unsigned long long>(v)); }

std::string mm(std::int32_t um) { return format("%.3f", um / 1000.0); }

std::string spindle_text(std::int32_t rpm) {
  if (rpm == 0) return "stopped";
  return std::to_string(std::abs(static_cast<long>(rpm))) + " rpm " + (rpm > 0 ? "clockwise (M3)" : "counter-clockwise (M4)");
}

std::string percent(std::uint32_t done, std::uint32_t total) {
  return total ? format("%.1f %%", 100.0 * done / total) : std::string("-");
}

// The whole block, one field per line.
std::string describe_status(const Status& s, const std::string& where, const drivers::TransportCounters& c) {
  std::string out;
  auto line = [&](const char* label, const std::string& text) { out += format("%-14s", label) + text + "\n"; };
  line("controller", where + ": protocol " + std::to_string(s.protocol_version) + ", boot " + std::to_string(s.boot_count));
  line("state", std::string(protocol::to_string(s.state)));
  if (s.alarm == protocol::AlarmCode::None) {
    line("alarm", "none");
  } else {
    const auto& info = protocol::alarm_info(s.alarm);
    line("alarm", std::to_string(static_cast<int>(s.alarm)) + " " + std::string(info.name) +
                      (s.alarm_line ? " at line " + std::to_string(s.alarm_line) : std::string()));
    line("", std::string(info.meaning));
    line("", "What to do: " + std::string(info.action));
  }
  if (s.identity == 0) {
    line("program", "none set");
  } else {
    line("program", "identity " + hex64(s.identity) + ", " + std::to_string(s.program_line_count) + " lines");
    line("executed", "line " + std::to_string(s.last_executed_line) + " of " + std::to_string(s.program_line_count) +
                         " (" + percent(s.last_executed_line, s.program_line_count) + "), chunk " +
                         std::to_string(s.last_executed_chunk));
    line("queued", "chunks through " + std::to_string(s.last_accepted_chunk) + ", next line " + std::to_string(s.next_line));
  }
  line("buffer", std::to_string(s.free_buffer_bytes) + " bytes free, chunks up to " +
                     std::to_string(s.max_chunk_payload) + " bytes");
  line("position", "X " + mm(s.x_um) + "  Y " + mm(s.y_um) + "  Z " + mm(s.z_um) + " mm");
  line("tool", s.active_tool ? "T" + std::to_string(s.active_tool) : std::string("none"));
  line("spindle", spindle_text(s.spindle_rpm));
  line("deposition", s.deposition_on ? "on" : "off");
  line("feed override", std::to_string(s.feed_override_percent) + " %");
  line("last chunk", s.last_written_chunk ? std::to_string(s.last_written_chunk) + ": " +
                                                std::string(protocol::to_string(s.chunk_result))
                                          : std::string("none since boot"));
  line("last command", s.command_seq ? "seq " + std::to_string(s.command_seq) + " " +
                                           std::string(protocol::to_string(s.command_code)) + ": " +
                                           std::string(protocol::to_string(s.command_result))
                                     : std::string("none since boot"));
  line("heartbeat", "echo " + std::to_string(s.heartbeat_echo) + ", timeout " + std::to_string(s.heartbeat_timeout_ms) +
                        " ms");
  line("chunk counts", std::to_string(s.duplicate_chunks) + " duplicate, " + std::to_string(s.refused_chunks) +
                           " refused since boot");
  if (c.timeouts || c.bad_replies || c.reconnects || c.retries)
    line("transport", std::to_string(c.timeouts) + " timeouts, " + std::to_string(c.bad_replies) + " bad replies, " +
                          std::to_string(c.reconnects) + " reconnects, " + std::to_string(c.retries) + " resends");
  return out;
}

std::string clock_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  ::localtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%H:%M:%S", &tm);
  return buf;
}

// One line per update, for logs and pipes.
std::string status_line(const Status& s) {
  std::string out = clock_now() + " " + std::string(protocol::to_string(s.state));
  out += " alarm=" + std::string(protocol::to_string(s.alarm));
  if (s.alarm_line) out += "@" + std::to_string(s.alarm_line);
  out += " line=" + std::to_string(s.last_executed_line) + "/" + std::to_string(s.program_line_count);
  out += " chunk=" + std::to_string(s.last_executed_chunk) + " queued=" + std::to_string(s.last_accepted_chunk);
  out += " free=" + std::to_string(s.free_buffer_bytes);
  out += " x=" + mm(s.x_um) + " y=" + mm(s.y_um) + " z=" + mm(s.z_um);
  out += " tool=" + std::to_string(s.active_tool) + " spindle=" + std::to_string(s.spindle_rpm);
  out += std::string(" deposition=") + (s.deposition_on ? "on" : "off");
  out += " boot=" + std::to_string(s.boot_count);
  return out + "\n";
}

int unreachable(const StatusRequest& request, const drivers::TransportError& e) {
  std::fflush(stdout);
  std::fprintf(stderr, "hybridctl: cannot reach the controller at %s (%s): %s\n", request.uri.c_str(),
               std::string(drivers::to_string(e.kind())).c_str(), e.what());
  return kUnreachable;
}

// Sleeps `seconds` in small steps; false when Ctrl-C came.
bool pause(double seconds) {
  using Clock = std::chrono::steady_clock;
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  while (Clock::now() < end) {
    if (g_status_stop.load()) return false;
    const Clock::duration step = std::chrono::milliseconds(50);
    std::this_thread::sleep_for(std::min(step, end - Clock::now()));
  }
  return !g_status_stop.load();
}

int run_status(const StatusRequest& request) {
  drivers::TransportOptions options;
  options.response_timeout = std::chrono::milliseconds(request.timeout_ms);
  options.reconnect_attempts = 3;  // a status query should fail fast when nobody answers
  std::unique_ptr<drivers::Transport> transport;
  Status status;
  try {
    transport = drivers::open_transport(request.uri, options);
    status = transport->read_status();
  } catch (const drivers::TransportError& e) {
    return unreachable(request, e);
  }
  if (!request.watch) {
    std::fputs(describe_status(status, transport->describe(), transport->counters()).c_str(), stdout);
    std::fflush(stdout);
    return kSuccess;
  }

  g_status_stop.store(false);
  std::signal(SIGINT, on_status_stop_signal);
  std::signal(SIGTERM, on_status_stop_signal);
  const bool terminal = ::isatty(STDOUT_FILENO) == 1;
  long updates = 0;
  bool reachable = true;
  std::string last_error;
  while (true) {
    if (reachable) {
      if (terminal) {
        std::fputs("\033[H\033[J", stdout);  // home, clear screen
        std::fputs(describe_status(status, transport->describe(), transport->counters()).c_str(), stdout);
        std::fprintf(stdout, "\nupdated %s, every %g s; Ctrl-C to stop\n", clock_now().c_str(), request.interval_s);
      } else {
        std::fputs(status_line(status).c_str(), stdout);
      }
    } else {
      std::fprintf(stdout, "%s unreachable: %s\n", clock_now().c_str(), last_error.c_str());
    }
    std::fflush(stdout);
    if (request.count > 0 && ++updates >= request.count) break;
    if (!pause(request.interval_s)) break;
    // Watching goes on through a lost connection: the next round tries again.
    try {
      status = transport->read_status();
      reachable = true;
    } catch (const drivers::TransportError& e) {
      reachable = false;
      last_error = e.what();
    }
  }
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  return kSuccess;
}

}  // namespace

void add_status_command(CLI::App& app, Runner& runner) {
  auto request = std::make_shared<StatusRequest>();
  auto* cmd = app.add_subcommand(
      "status",
      "Read the controller's status block over a transport and print it: state, alarm (name, meaning, what to do), "
      "program identity and progress (last executed line and chunk), queued chunks, free buffer, position (mm), tool, "
      "spindle, deposition, boot count and counters. Read-only: sends no command and no heartbeat. --watch refreshes "
      "it every SECONDS (default 1) until Ctrl-C: the screen on a terminal, one line per update otherwise; a lost "
      "connection is reported and retried. Exit 0 on success, 3 for a malformed URI, 6 when the controller cannot be "
      "reached (nothing answers, the connection fails, or the transport cannot run here, e.g. no SocketCAN in this "
      "kernel). See docs/drivers.md.");
  cmd->add_option("--transport,-t", request->uri,
                  "Transport URI: modbus-tcp://HOST:PORT[?unit=N], modbus-rtu:///dev/DEVICE[?baud=B&parity=N|E|O&unit=N], "
                  "socketcand://HOST:PORT/CHANNEL[?node=N], socketcan://IFACE[?node=N]")
      ->required();
  auto* watch = cmd->add_option("--watch,-w", request->interval_s, "Refresh every SECONDS (default 1) until Ctrl-C")
                    ->expected(0, 1)
                    ->check(between(0.05, 3600.0));
  cmd->add_option("--count", request->count, "With --watch: stop after N updates (0: until Ctrl-C)")
      ->check(at_least(0));
  cmd->add_option("--timeout", request->timeout_ms, "Response timeout, ms (default 1000)")->check(between(1, 60000));
  cmd->callback([&runner, request, watch] {
    request->watch = watch->count() > 0;
    runner = [request] { return run_status(*request); };
  });
}

}  // namespace hybridctl::cli
