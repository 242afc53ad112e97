#pragma once
// The run report of `hybridctl sim serve` (docs/simulator.md, "Run report"): what the
// controller did, its final status, every served transport's counters and the faults
// injected, gathered as a value when the serve loop has ended and written as JSON.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "protocol/messages.hpp"
#include "sim/controller.hpp"
#include "sim/wire/can_node.hpp"
#include "sim/wire/fault_injection.hpp"
#include "sim/wire/modbus_server.hpp"
#include "sim/wire/socketcan_endpoint.hpp"
#include "sim/wire/socketcand_server.hpp"

namespace hybridctl::sim::wire {

struct ModbusTcpReport {
  std::string address;  // HOST:PORT bound
  ModbusCounters counters;
  FaultCounters faults;
};

struct ModbusRtuReport {
  std::string device;
  int unit = 1;
  ModbusCounters counters;
  FaultCounters faults;
};

struct SocketcandReport {
  std::string address;  // HOST:PORT bound
  SocketcandCounters counters;
  CanNodeCounters node;
  FaultCounters faults;
};

struct SocketCanReport {
  std::string interface_name;
  SocketCanCounters counters;
  CanNodeCounters node;
  FaultCounters faults;
};

struct RunReport {
  std::string machine;       // the machine's name
  std::string machine_file;  // as given
  bool completed = false;    // ended because the program completed (else: a signal)
  double real_time_s = 0;
  double time_scale = 1;
  std::string stock;  // "none", a .vdb path, or what the plan's stock was
  ControllerReport controller;
  protocol::Status final_status;
  // Only the transports that were served.
  std::optional<ModbusTcpReport> modbus_tcp;
  std::optional<ModbusRtuReport> modbus_rtu;
  std::optional<SocketcandReport> socketcand;
  std::optional<SocketCanReport> socketcan;
  FaultOptions faults;  // as applied (reboot lines parsed)
  std::uint32_t reboots_injected = 0;
};

// The JSON document, as text (format "hybridctl-sim-report", version 1).
std::string run_report_json(const RunReport& report);

// Writes run_report_json() to `path` atomically. Throws InputError when it cannot.
void write_run_report(const RunReport& report, const std::filesystem::path& path);

}  // namespace hybridctl::sim::wire
