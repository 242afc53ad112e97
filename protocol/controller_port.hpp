#pragma once
// The controller side of the protocol as the wire servers see it: what a Modbus register
// write, a CAN message or a heartbeat turns into, and the status block that goes back.
// The servers in sim/wire/ talk to this interface only, so the same servers front the
// simulated machine (sim::Controller) and a real one (bridge::LinuxcncController, the
// LinuxCNC bridge). Every call happens on the serve loop's one thread.

#include <cstdint>
#include <span>

#include "protocol/chunk_acceptor.hpp"
#include "protocol/messages.hpp"

namespace hybridctl::protocol {

class ControllerPort {
 public:
  virtual ~ControllerPort() = default;

  /// A chunk mailbox write (Modbus) or a reassembled chunk message (CAN), through the
  /// acceptance rule (ChunkAcceptor); the verdict is what the status block reports.
  virtual ChunkVerdict write_mailbox(std::span<const std::uint16_t> registers) = 0;
  virtual ChunkVerdict write_message(std::span<const std::uint8_t> message) = 0;
  /// A command block (Modbus) or an assembled command (CAN), through the CommandGate.
  virtual ResultCode write_command(std::span<const std::uint16_t> registers) = 0;
  virtual ResultCode write_command(const Command& command) = 0;
  virtual void write_heartbeat(std::uint16_t counter) = 0;

  virtual Status status() const = 0;
  /// The state and alarm of status(), without building the whole block.
  virtual ControllerState state() const = 0;
  virtual AlarmCode alarm() const = 0;
};

}  // namespace hybridctl::protocol
