#pragma once
// `hybridctl bridge linuxcnc` from its options to its end (docs/bridge.md): the agent
// that reaches LinuxCNC, the controller that speaks the protocol for it, the wire
// servers of `sim serve` in front (Modbus TCP, socketcand, SocketCAN), one poll loop that
// serves the wire and reads LinuxCNC's status every status period, until SIGINT/SIGTERM.
//
//   bridge::BridgeOptions o;  o.ini = "hybrid-3axis.ini";  o.modbus = "tcp://127.0.0.1:1502";
//   bridge::serve_bridge(o, [](const std::string& line) { puts(line.c_str()); });

#include <cstdint>
#include <functional>
#include <string>

#include "bridge/linuxcnc_controller.hpp"
#include "sim/wire/fault_injection.hpp"

namespace hybridctl::bridge {

struct BridgeOptions {
  std::string ini;         ///< the INI file LinuxCNC runs (checked against LinuxCNC's own)
  std::string modbus;      ///< Modbus TCP listen address [tcp://]HOST:PORT
  std::string socketcand;  ///< socketcand listen address HOST:PORT
  std::string socketcan;   ///< kernel CAN interface
  int node = 1;
  bool allow_remote = false;
  std::string segment_dir;  ///< empty: a fresh directory under $TMPDIR (or /tmp)
  std::uint32_t buffer_bytes = 262144;
  double heartbeat_timeout_s = 2.0;
  double feed_override_percent = 0;  ///< set at every start; 0 leaves LinuxCNC's
  int status_period_ms = 10;  ///< how often LinuxCNC's status is read
  double connect_timeout_s = 30;  ///< how long to wait for LinuxCNC at startup
  std::string line_log;       ///< every line LinuxCNC executed, in order
  std::string python = "/usr/bin/python3";
  sim::wire::FaultOptions faults;   ///< the wire servers' fault injection (drop_every, ...)
};

struct BridgeOutcome {
  BridgeReport report;
  protocol::Status final_status;
};

/// Serves until SIGINT or SIGTERM. `say` gets "linuxcnc INI", one "listening TRANSPORT
/// ADDRESS" line per endpoint, then "ready", and the bridge's log lines (segments, alarms,
/// LinuxCNC's messages). Throws InputError for bad options, an INI that is not the one
/// LinuxCNC runs, LinuxCNC not answering within connect_timeout_s, or a port in use.
BridgeOutcome serve_bridge(const BridgeOptions& options, const std::function<void(const std::string&)>& say);

}  // namespace hybridctl::bridge
