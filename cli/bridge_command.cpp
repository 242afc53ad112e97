// hybridctl bridge linuxcnc: hybridctl's protocol in front of a running LinuxCNC
// (docs/bridge.md).

#include <cstdio>
#include <memory>
#include <string>

#include "bridge/bridge.hpp"
#include "cli/commands.hpp"
#include "cli/ranges.hpp"
#include "config/transport_uri.hpp"
#include "protocol/codes.hpp"

namespace hybridctl::cli {
namespace {

void print_line(const std::string& line) {
  std::fputs((line + "\n").c_str(), stdout);
  std::fflush(stdout);
}

int run_bridge(const bridge::BridgeOptions& options) {
  const bridge::BridgeOutcome end = bridge::serve_bridge(options, print_line);
  std::printf("stopped (signal): %u segments, %u lines executed by LinuxCNC, state %s, last line %u\n",
              end.report.segments, end.report.lines_executed,
              std::string(protocol::to_string(end.final_status.state)).c_str(), end.final_status.last_executed_line);
  std::fflush(stdout);
  return kSuccess;
}

}  // namespace

void add_bridge_command(CLI::App& app, Runner& runner) {
  auto r = std::make_shared<bridge::BridgeOptions>();
  auto* bridge_cmd = app.add_subcommand("bridge", "The controller side of the protocol for a real controller");
  bridge_cmd->require_subcommand(1);
  auto* cnc = bridge_cmd->add_subcommand(
      "linuxcnc",
      "Serve hybridctl's protocol (Modbus TCP, socketcand or SocketCAN) in front of a running LinuxCNC: "
      "accepted lines run in LinuxCNC's own interpreter as segment files, LinuxCNC's status is the "
      "status block (docs/bridge.md). Run it as the user that runs LinuxCNC; stop it with SIGINT/SIGTERM.");
  cnc->add_option("--ini", r->ini, "The INI file LinuxCNC runs (checked against LinuxCNC's own)")->required();
  cnc->add_option("--modbus", r->modbus, "Modbus TCP endpoint tcp://HOST:PORT (port 0: a free port)");
  cnc->add_option("--socketcand", r->socketcand, "socketcand endpoint HOST:PORT (port 0: a free port)");
  cnc->add_option("--socketcan", r->socketcan, "Kernel CAN interface (e.g. can0)");
  cnc->add_option("--node", r->node, "CAN node id of the controller")->capture_default_str()->check(between(1, 127));
  cnc->add_flag("--allow-remote", r->allow_remote, "Allow binding to addresses other than loopback");
  cnc->add_option("--segment-dir", r->segment_dir,
                  "Where segment files go (LinuxCNC must read them); default: a new directory in $TMPDIR or /tmp");
  cnc->add_option("--buffer-bytes", r->buffer_bytes, "Program buffer (payload bytes) the host fills between segments")
      ->capture_default_str()
      ->check(CLI::Range(1024u, 64u << 20));
  cnc->add_option("--heartbeat-timeout", r->heartbeat_timeout_s,
                  "Seconds without a host heartbeat change before LinuxCNC is paused (HOST_HEARTBEAT_LOST); 0: never")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 65.0));
  cnc->add_option("--feed-override", r->feed_override_percent,
                  "Set LinuxCNC's feed override to this percentage at every start (a SIM-ONLY speed-up, up to the "
                  "INI's MAX_FEED_OVERRIDE); default: leave it")
      ->check(between(1, 100000));
  cnc->add_option("--status-period-ms", r->status_period_ms, "How often LinuxCNC's status is read")
      ->capture_default_str()
      ->check(between(1, 1000));
  cnc->add_option("--connect-timeout", r->connect_timeout_s, "Seconds to wait for LinuxCNC at startup")
      ->capture_default_str();
  cnc->add_option("--line-log", r->line_log, "Write every line LinuxCNC executed here, in order (\"N text\")");
  cnc->add_option("--python", r->python, "The Python with Debian's `linuxcnc` module")->capture_default_str();
  auto* faults = "Fault injection (tests)";
  cnc->add_option("--drop-every", r->faults.drop_every, "Close the client's connection at every N-th request")
      ->group(faults);
  cnc->add_option("--delay-ms", r->faults.delay_ms, "Hold every reply back D ms")->group(faults);
  cnc->callback([&runner, r] { runner = [r] { return run_bridge(*r); }; });
}

}  // namespace hybridctl::cli
