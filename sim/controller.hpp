#pragma once
// The simulated machine controller: what sits behind the wire in `hybridctl sim serve`.
// It owns the program buffer (the protocol's acceptance rule, protocol/), executes
// the G-code in virtual time with the machine's feed and acceleration limits, keeps
// position, tool, spindle and deposition state, applies the material simulation to a
// voxel stock, and raises the alarms a real controller would.
//
// Not thread-safe: the server owns one Controller and serialises every call (the wire
// handlers and the execution clock run on one thread, or under one mutex).
//
//   Controller c(machine, options);
//   c.write_command(...);  c.write_mailbox(registers);   // from the wire
//   c.advance(elapsed_real_seconds);                      // from the server loop
//   protocol::Status s = c.status();                      // to the wire

#include <chrono>
#include <cstdint>
#include <functional>
#include <string_view>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "config/machine.hpp"
#include "protocol/chunk_acceptor.hpp"
#include "protocol/controller_port.hpp"
#include "protocol/messages.hpp"
#include "geometry/solid.hpp"

namespace hybridctl::sim {

struct ControllerOptions {
  // Virtual seconds per real second; 0 executes as fast as possible (every advance()
  // runs what is queued, up to max_lines_per_advance lines).
  double time_scale = 0;
  std::uint32_t buffer_bytes = 16384;  // program buffer (payload bytes)
  // The largest chunk payload accepted and advertised: what one Modbus mailbox write
  // carries by default; a controller reached only over CAN takes CAN's larger transfers.
  std::uint16_t max_chunk_payload = 222;
  double heartbeat_timeout_s = 2.0;    // RUNNING without a heartbeat change -> feed hold + alarm
  std::uint32_t max_lines_per_advance = 2000;
  // The stock the material simulation starts from (part frame), and the region it must
  // not cut into (e.g. the design shrunk by the tolerance). Without a stock, motions are
  // executed and timed but nothing is cut or deposited.
  std::optional<geometry::Solid> stock;
  std::optional<geometry::Solid> protected_region;
  // Fault injection: when line `alarm_at_line` is about to execute, raise EMERGENCY_STOP
  // (0: never).
  std::uint32_t alarm_at_line = 0;
  // Fault injection: when line `hold_at_line` is about to execute, hold the feed as an
  // operator at the machine would (0: never); RESUME goes on.
  std::uint32_t hold_at_line = 0;
  // advance() returns right after executing any of these lines (sorted ascending), so a
  // fault injector can reboot the controller exactly there.
  std::vector<std::uint32_t> break_after_lines;
  // Called after every executed line with its number and text (the run's line log).
  std::function<void(std::uint32_t number, std::string_view text)> on_line_executed;
};

// The run report (`sim serve` writes it as JSON at the end).
struct ControllerReport {
  std::uint64_t identity = 0;
  std::uint32_t program_lines = 0;
  std::uint32_t chunks_accepted = 0;
  std::uint32_t chunks_executed = 0;
  std::uint32_t lines_executed = 0;
  std::uint32_t duplicates = 0, refused = 0;
  std::uint32_t reboots = 0;
  double virtual_time_s = 0;
  std::vector<std::string> alarms;       // "LINE n: NAME: what" in order
  double removed_mm3 = 0, deposited_mm3 = 0, gouge_mm3 = 0;
  double as_built_mm3 = 0;
  bool completed = false;
};

class Controller final : public protocol::ControllerPort {
 public:
  // `machine` must outlive the controller.
  Controller(const config::Machine& machine, ControllerOptions options = {});
  ~Controller() override;
  Controller(const Controller&) = delete;
  Controller& operator=(const Controller&) = delete;

  // --- the wire: each returns what the status block will report.
  protocol::ChunkVerdict write_mailbox(std::span<const std::uint16_t> registers) override;  // Modbus
  protocol::ChunkVerdict write_message(std::span<const std::uint8_t> message) override;     // CAN
  // A command block (Modbus) or an assembled command (CAN). Repeats of the last seq are
  // ignored (protocol::CommandGate).
  protocol::ResultCode write_command(std::span<const std::uint16_t> registers) override;
  protocol::ResultCode write_command(const protocol::Command& command) override;
  void write_heartbeat(std::uint16_t counter) override;
  protocol::Status status() const override;
  // The state and alarm of status(), without building the whole block (the CAN node
  // checks them after every step to send a snapshot when they change).
  protocol::ControllerState state() const override;
  protocol::AlarmCode alarm() const override;

  // --- time: runs the program for `real_seconds` of wall time (scaled by time_scale),
  // or, at time scale 0, executes whatever is queued (bounded per call).
  void advance(double real_seconds);

  // --- fault injection
  // A reboot: the queue and all machine state are lost; the program identity and how far
  // it ran are kept (protocol::SafePoint), boot count +1, state ALARM
  // (CONTROLLER_RESTARTED) until RESET_ALARM.
  void reboot();
  void emergency_stop();

  // --- what happened
  ControllerReport report() const;
  // Global line numbers in the order they executed (each exactly once if all went well).
  const std::vector<std::uint32_t>& executed_lines() const;
  // The stock as built so far (part frame); empty when the controller has no stock.
  geometry::Solid as_built() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hybridctl::sim
