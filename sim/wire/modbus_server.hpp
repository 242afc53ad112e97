#pragma once
// The simulated controller's Modbus side (TCP and RTU), built on libmodbus: the register
// map of docs/protocol.md ("Modbus mapping", protocol/modbus_map.hpp) in front of
// a sim::Controller.
//
// Every request is checked against the map first (protocol::modbus::inspect_request_pdu:
// a write must address exactly one block, counts within the Modbus limits); a refused
// request gets its exception (01, 02 or 03) and changes nothing. A write that passes is
// applied to the controller (heartbeat, command block, chunk mailbox), the status block
// (input registers 0..45) and its mirror (holding registers 200..245) are refreshed from
// controller.status(), and only then does libmodbus build the reply: an FC23 write-and-
// read of the mailbox returns the status after the chunk, as the Modbus spec orders the
// write before the read. libmodbus's own mapping checks stay behind that as a backstop.
//
// TCP: one listening socket, any number of clients (up to max_clients) served by one
// libmodbus context whose socket is switched to the client at hand; requests are framed
// by libmodbus (by function code) and then the MBAP header is checked (protocol id 0,
// length = the bytes that followed it): a client whose framing is lost, or that stalls
// mid-frame longer than byte_timeout, is disconnected, the others carry on. The unit id
// is not checked over TCP (any unit is answered). RTU: a serial device (or a pty), only
// requests for `unit` (and broadcasts, applied without reply) are served; a frame with a
// bad CRC is dropped and the line flushed.
//
// Fault injection (sim/wire/fault_injection.hpp), per server: drop_every closes the client's
// connection instead of answering (RTU: no answer); exception_every answers exception 06
// (SERVER DEVICE BUSY) without processing; corrupt_every damages the reply (TCP: the
// function code byte, so libmodbus and pymodbus clients both reject it; RTU: the last
// byte before the CRC, so the CRC fails); delay_ms holds every reply back that long
// (without blocking the other clients).

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "protocol/controller_port.hpp"
#include "sim/wire/fault_injection.hpp"
#include "sim/wire/serve_loop.hpp"

namespace hybridctl::sim::wire {


struct ModbusCounters {
  std::uint64_t connections = 0;          ///< TCP clients accepted
  std::uint64_t refused_connections = 0;  ///< TCP clients turned away (max_clients reached)
  std::uint64_t disconnects = 0;          ///< TCP clients that closed (or were closed for bad framing)
  std::uint64_t requests = 0;             ///< whole, well-framed requests for us
  std::uint64_t replies = 0;              ///< replies sent (normal and exception)
  std::array<std::uint64_t, 12> exceptions{};  ///< exception replies by code (index = code; 6 = injected busy)
  std::uint64_t bad_frames = 0;           ///< TCP: MBAP mismatch, oversize, stall mid-frame; RTU: bad CRC, timeout
  std::uint64_t other_unit = 0;           ///< RTU: requests for another unit, ignored
  std::uint64_t broadcasts = 0;           ///< RTU: unit 0 requests, applied without reply
  std::uint64_t heartbeat_writes = 0;
  std::uint64_t command_writes = 0;
  std::uint64_t mailbox_writes = 0;
};

struct ModbusServerOptions {
  FaultOptions faults;
  /// Longest silence allowed inside one frame (libmodbus byte timeout). A TCP client that
  /// stalls mid-frame holds the others up this long and is then disconnected.
  std::chrono::milliseconds byte_timeout{50};
  std::size_t max_clients = 16;  ///< TCP clients served at once (libmodbus selects: fds < 1024)
  bool debug = false;            ///< libmodbus's frame dump on stderr
};

class ModbusTcpServer final : public WireEndpoint {
 public:
  /// Listens on `address` (an IPv4 address) and `port` (0: a free port, see port()).
  /// Throws hybridctl::InputError naming the address when it cannot listen.
  ModbusTcpServer(protocol::ControllerPort& controller, const std::string& address, int port, ModbusServerOptions options = {});
  ~ModbusTcpServer() override;
  ModbusTcpServer(const ModbusTcpServer&) = delete;
  ModbusTcpServer& operator=(const ModbusTcpServer&) = delete;

  const std::string& address() const;
  int port() const;  ///< the port actually bound
  std::size_t client_count() const;
  const ModbusCounters& counters() const;
  const FaultCounters& faults() const;

  void collect(std::vector<pollfd>& fds) override;
  void service(std::span<const pollfd> fds, SteadyTime now) override;
  void tick(SteadyTime now) override;
  SteadyTime next_deadline() const override;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

struct ModbusRtuSettings {
  std::string device;  ///< serial device or pty path
  int baud = 19200;    ///< a standard rate (config::kStandardBaudRates); libmodbus makes others 9600
  char parity = 'E';   ///< 'N', 'E' or 'O'
  int unit = 1;        ///< 1..247
};

class ModbusRtuServer final : public WireEndpoint {
 public:
  /// Opens the device. Throws hybridctl::InputError naming the device when it cannot.
  ModbusRtuServer(protocol::ControllerPort& controller, ModbusRtuSettings settings, ModbusServerOptions options = {});
  ~ModbusRtuServer() override;
  ModbusRtuServer(const ModbusRtuServer&) = delete;
  ModbusRtuServer& operator=(const ModbusRtuServer&) = delete;

  const ModbusRtuSettings& settings() const;
  const ModbusCounters& counters() const;
  const FaultCounters& faults() const;

  void collect(std::vector<pollfd>& fds) override;
  void service(std::span<const pollfd> fds, SteadyTime now) override;
  void tick(SteadyTime now) override;
  SteadyTime next_deadline() const override;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace hybridctl::sim::wire
