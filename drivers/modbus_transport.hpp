#pragma once
// The program-stream protocol over Modbus TCP and RTU, on libmodbus 3.1.6
// (docs/protocol.md, "Modbus mapping"; docs/drivers.md). One request per call:
//
//   read_status     FC4  read input registers 0..45 (the status block)
//   send_command    FC23 write the command block (8 registers at 8), read the status
//                        mirror (46 registers at 200) in the same request
//   send_chunk      FC23 write the mailbox (16.., 10 + ceil(payload/2) registers), read the
//                        status mirror in the same request: the chunk's result comes back
//                        with the write
//   send_heartbeat  FC6  write holding register 0
//
// Failures, and what follows (each counted in TransportCounters):
//   timeout (no reply within response_timeout)   TCP: reconnect; RTU: flush the line; resend
//   connection broken (reset, refused, EOF)      reconnect with backoff; resend
//   corrupt reply (bad CRC, wrong transaction or function, wrong length, a status block
//     that does not decode)                      TCP: reconnect (the byte stream may be out
//                                                of step); RTU: flush; resend
//   exception 04/05/06 (server failure, ack, busy) and other transient exceptions   resend
//   exception 01/02/03 (illegal function, address, value)   TransportError(Protocol) at
//                                                once: resending the same request cannot help
// Resending is safe by the protocol: a chunk seen twice is acknowledged as DUPLICATE and
// queued once, a command's repeated seq is a no-op, heartbeats are idempotent.
// At most request_retries resends per call, reconnect_attempts connection attempts per
// (re)connect, backoff doubling from reconnect_backoff up to 2 s.

#include <memory>
#include <string>

#include "config/machine.hpp"
#include "drivers/transport.hpp"

namespace hybridctl::drivers {

class ModbusTransport final : public Transport {
 public:
  /// `where` is a ModbusTcp or ModbusRtu transport (config::parse_transport_uri). Checks the
  /// settings (InputError: an RTU baud rate libmodbus does not know, a parity other than N,
  /// E, O, a unit out of range), then connects (TransportError Unreachable after the
  /// reconnect attempts).
  ModbusTransport(const config::Transport& where, const TransportOptions& options);
  ~ModbusTransport() override;
  ModbusTransport(const ModbusTransport&) = delete;
  ModbusTransport& operator=(const ModbusTransport&) = delete;

  std::string describe() const override;
  std::size_t max_chunk_payload() const override;
  protocol::Status read_status() override;
  protocol::Status send_command(const protocol::Command& command) override;
  protocol::Status send_chunk(const protocol::Chunk& chunk) override;
  void send_heartbeat(std::uint16_t counter) override;
  TransportCounters counters() const override;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

/// Throws InputError unless libmodbus 3.1.6 takes `baud` as it is (a termios standard rate,
/// config::kStandardBaudRates, up to 4,000,000): libmodbus silently uses 9600 for others.
void check_rtu_baud(int baud);

}  // namespace hybridctl::drivers
