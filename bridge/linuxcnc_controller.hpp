#pragma once
// The controller side of hybridctl's protocol for a LinuxCNC machine: the same acceptance
// rule and command gate as the simulator (protocol/), the same wire servers in front
// (sim/wire/, through protocol::ControllerPort), and LinuxCNC behind, reached through
// LinuxcncLink. Accepted lines go to LinuxCNC as segment files (bridge/segments.hpp) run
// in AUTO mode; LinuxCNC's status becomes the status block (docs/bridge.md, "Status").
//
// Not thread-safe: the bridge's loop calls everything on one thread, the wire servers'
// writes and tick() alike.
//
//   LinuxcncController c(link, {.segment_dir = "/tmp/seg"});
//   ModbusTcpServer modbus(c, "127.0.0.1", 1502);
//   ... every 10 ms: c.tick(now);

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bridge/linuxcnc_link.hpp"
#include "bridge/segments.hpp"
#include "protocol/chunk_acceptor.hpp"
#include "protocol/controller_port.hpp"

namespace hybridctl::bridge {

struct ControllerOptions {
  std::string segment_dir;             ///< where segment files are written (LinuxCNC must read them)
  std::uint32_t buffer_bytes = 262144;  ///< program buffer (payload bytes) between two segments
  std::uint16_t max_chunk_payload = 222;
  double heartbeat_timeout_s = 2.0;
  double feed_override = 0;            ///< LinuxCNC's feed override at each start (1 = 100 %); 0 leaves it
  /// Called with every line LinuxCNC executed, in order, and with what the bridge does.
  std::function<void(std::uint32_t number, std::string_view text)> on_line_executed;
  std::function<void(const std::string&)> log;
};

/// What happened, for the bridge's report at the end.
struct BridgeReport {
  std::uint32_t segments = 0;
  std::uint32_t lines_executed = 0;
  std::uint32_t boots = 1;
  std::vector<std::string> alarms;  ///< "line N: NAME: message", in order
};

class LinuxcncController final : public protocol::ControllerPort {
 public:
  LinuxcncController(LinuxcncLink& link, ControllerOptions options);

  protocol::ChunkVerdict write_mailbox(std::span<const std::uint16_t> registers) override;
  protocol::ChunkVerdict write_message(std::span<const std::uint8_t> message) override;
  protocol::ResultCode write_command(std::span<const std::uint16_t> registers) override;
  protocol::ResultCode write_command(const protocol::Command& command) override;
  void write_heartbeat(std::uint16_t counter) override;
  protocol::Status status() const override;
  protocol::ControllerState state() const override { return state_; }
  protocol::AlarmCode alarm() const override { return alarm_; }

  /// Reads LinuxCNC's status and acts on it: lines executed, the next segment, M0/M1
  /// stops, e-stop, errors, LinuxCNC gone or back, the host's heartbeat.
  void tick(std::chrono::steady_clock::time_point now);

  const BridgeReport& report() const { return report_; }
  const LinuxcncStatus& linuxcnc() const { return last_; }

 private:
  protocol::ResultCode command(const protocol::Command& c);
  protocol::ResultCode set_program(const protocol::Command& c);
  protocol::ResultCode start();
  protocol::ResultCode resume();
  protocol::ResultCode abort();
  protocol::ResultCode reset_alarm();
  void raise(protocol::AlarmCode code, std::uint32_t line, const std::string& what);
  void take_messages(const LinuxcncStatus& s);
  void follow_segment(const LinuxcncStatus& s);
  void executed_through(std::uint32_t line);
  void start_next_segment();
  void lost(const std::string& why);
  void back_after_loss();
  void stop_segment_on_alarm();
  void fail_segment(const std::string& message);
  bool ended_normally(const LinuxcncStatus& s) const;
  bool finished() const { return acceptor_.has_program() && last_executed_line_ >= acceptor_.line_count(); }

  LinuxcncLink& link_;
  ControllerOptions options_;
  protocol::ChunkAcceptor acceptor_;
  protocol::CommandGate gate_;
  SegmentFeeder feeder_;
  std::optional<Segment> segment_;  // the segment LinuxCNC runs
  std::string segment_path_;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> chunk_ends_;  // (seq, last line) of chunks taken, not yet executed
  protocol::ControllerState state_ = protocol::ControllerState::Idle;
  protocol::AlarmCode alarm_ = protocol::AlarmCode::None;
  std::uint32_t alarm_line_ = 0;
  std::uint16_t boot_count_ = 1;
  std::uint16_t heartbeat_ = 0;
  std::chrono::steady_clock::time_point now_{}, heartbeat_changed_{};
  std::uint32_t last_executed_line_ = 0, last_executed_chunk_ = 0;
  bool started_ = false, aborted_ = false, prepared_ = false, hold_requested_ = false;
  bool linuxcnc_lost_ = false;
  std::optional<std::chrono::steady_clock::time_point> idle_early_since_;  // LinuxCNC idle before the segment's end
  LinuxcncStatus last_;
  BridgeReport report_;
};

/// The protocol alarm for a message on LinuxCNC's error channel (docs/bridge.md,
/// "Alarms"): soft limits -> ENVELOPE_VIOLATION, an unknown tool -> TOOL_NOT_IN_MAGAZINE,
/// an interpreter error about the program's text -> GCODE_ERROR, anything else
/// LINUXCNC_ERROR.
protocol::AlarmCode alarm_for_message(std::string_view text);

}  // namespace hybridctl::bridge
