#pragma once
// A small libmodbus client for the wire tests (the host drivers are tested elsewhere): reads
// the status block, writes commands and mailboxes, and a program to stream. Plus a raw TCP
// socket for sending bytes no Modbus client would.

#include <modbus/modbus.h>

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "protocol/chunk.hpp"
#include "protocol/messages.hpp"

namespace hybridctl::test {

class ModbusClient {
 public:
  /// Connects to 127.0.0.1:port; connected() says whether it worked.
  explicit ModbusClient(int port, std::chrono::milliseconds timeout = std::chrono::milliseconds(2000));
  ~ModbusClient();
  ModbusClient(const ModbusClient&) = delete;
  ModbusClient& operator=(const ModbusClient&) = delete;

  bool connected() const { return connected_; }
  modbus_t* ctx() { return ctx_; }
  /// errno of the last failed call, and libmodbus's text for it.
  int last_errno() const { return errno_; }
  std::string last_error() const { return modbus_strerror(errno_); }

  /// FC4 of the status block, decoded; nullopt on a Modbus error or a block that does not decode.
  std::optional<protocol::Status> status();
  /// FC16 of the command block; false on a Modbus error.
  bool write_command(const protocol::Command& command);
  /// FC23: the registers into the mailbox, the status mirror back; nullopt on an error.
  std::optional<protocol::Status> write_mailbox(const std::vector<std::uint16_t>& registers);
  /// FC6 of the heartbeat register.
  bool heartbeat(std::uint16_t counter);

 private:
  modbus_t* ctx_ = nullptr;
  bool connected_ = false;
  int errno_ = 0;
};

/// A program of `moves` feed moves for the example machine (hybrid-3axis), its lines.
std::vector<std::string> test_program(int moves);

/// The mailbox registers of chunk `seq` of `lines` starting at 1-based `first_line`
/// (as many whole lines as fit in the Modbus payload limit).
std::vector<std::uint16_t> mailbox_of(const std::vector<std::string>& lines, std::uint32_t first_line,
                                      std::uint32_t seq, protocol::Chunk* chunk = nullptr);

/// A connected TCP socket to 127.0.0.1:port (-1 on failure), closed at destruction.
class RawSocket {
 public:
  explicit RawSocket(int port);
  ~RawSocket();
  RawSocket(const RawSocket&) = delete;
  RawSocket& operator=(const RawSocket&) = delete;
  int fd() const { return fd_; }
  bool send(const std::string& bytes);
  /// Reads what arrives within `wait` (stops early once `until` appears, if given).
  std::string receive(std::chrono::milliseconds wait, const std::string& until = {});
  /// Reads until `count` bytes arrived or `wait` passed.
  std::string receive_bytes(std::size_t count, std::chrono::milliseconds wait);
  /// True when the peer closed the connection (EOF or reset) within `wait`.
  bool closed_by_peer(std::chrono::milliseconds wait);

 private:
  int fd_ = -1;
};

}  // namespace hybridctl::test
