#pragma once
// `hybridctl sim serve` from its options to its end (docs/simulator.md): the controller
// with its stock, the wire endpoints in front of it, the serve loop until SIGINT/SIGTERM
// (or the program's completion), then the line log, the as-built stock and the run report.
//
//   sim::ServeOptions o;  o.machine = "m.yaml";  o.modbus = "tcp://127.0.0.1:0";
//   const sim::ServeOutcome end = sim::serve(o, [](const std::string& line) { puts(line.c_str()); });

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "protocol/messages.hpp"
#include "sim/controller.hpp"
#include "sim/wire/fault_injection.hpp"

namespace hybridctl::sim::wire {

struct ServeOptions {
  std::string machine;     // machine file (YAML)
  std::string modbus;      // Modbus TCP listen address, [tcp://]HOST:PORT (config::parse_listen_address)
  std::string modbus_rtu;  // Modbus RTU device
  int baud = 19200;
  std::string parity = "E";
  int unit = 1;
  std::string socketcand;  // socketcand listen address, HOST:PORT
  std::string socketcan;   // kernel CAN interface
  int node = 1;
  std::uint32_t can_bitrate = 0;
  int status_period_ms = 100;
  int can_block_size = 0;
  double time_scale = 1.0;
  std::uint32_t buffer_bytes = 16384;
  double heartbeat_timeout_s = 2.0;
  std::string stock_plan;  // plan.json or its directory
  std::string stock_vdb;
  std::uint64_t memory_budget = 0;  // bytes the stock's grids may take; 0: geometry::default_memory_budget()
  int plan = 1;            // with stock_plan: which plan's stock
  std::string report;      // run report (JSON) path
  std::string as_built;    // .vdb or .stl path
  std::string line_log;    // every executed line, in order
  bool exit_when_done = false;
  bool allow_remote = false;
  bool modbus_debug = false;
  FaultOptions faults;                          // reboot_after_lines comes from the next field
  std::vector<std::string> reboot_after_lines;  // "L" or "L1,L2,..." items (sim::parse_line_list)
};

/// serve() refused to start: the options are at fault (Usage) or what they name (BadInput).
/// The message says which option and what was expected.
class ServeRefused : public std::runtime_error {
 public:
  enum class Reason { Usage, BadInput };
  ServeRefused(Reason reason, const std::string& message) : std::runtime_error(message), reason_(reason) {}
  Reason reason() const { return reason_; }

 private:
  Reason reason_;
};

struct ServeOutcome {
  bool completed = false;  // the program completed (else: a signal stopped it)
  ControllerReport controller;
  protocol::Status final_status;
};

/// Serves until SIGINT or SIGTERM (handlers are installed before "ready") or, with
/// exit_when_done, the program's completion. `say` gets one "listening TRANSPORT ADDRESS"
/// line per endpoint, then "ready". Throws ServeRefused before anything listens, InputError
/// for the machine file, the stock, a port in use, a device that does not open or a kernel
/// without SocketCAN.
ServeOutcome serve(const ServeOptions& options, const std::function<void(const std::string&)>& say);

}  // namespace hybridctl::sim::wire
