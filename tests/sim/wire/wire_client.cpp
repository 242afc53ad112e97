#include "wire_client.hpp"

#include <algorithm>
#include <cerrno>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include "protocol/modbus_map.hpp"

namespace hybridctl::test {

namespace mb = protocol::modbus;

ModbusClient::ModbusClient(int port, std::chrono::milliseconds timeout) {
  ctx_ = modbus_new_tcp("127.0.0.1", port);
  if (!ctx_) return;
  const auto us = std::chrono::duration_cast<std::chrono::microseconds>(timeout).count();
  modbus_set_response_timeout(ctx_, static_cast<std::uint32_t>(us / 1'000'000), static_cast<std::uint32_t>(us % 1'000'000));
  modbus_set_slave(ctx_, 1);
  connected_ = modbus_connect(ctx_) == 0;
  if (!connected_) errno_ = errno;
}

ModbusClient::~ModbusClient() {
  if (ctx_) {
    modbus_close(ctx_);
    modbus_free(ctx_);
  }
}

std::optional<protocol::Status> ModbusClient::status() {
  protocol::StatusRegisters regs{};
  if (modbus_read_input_registers(ctx_, mb::kStatusAddress, mb::kStatusCount, regs.data()) != int(mb::kStatusCount)) {
    errno_ = errno;
    return std::nullopt;
  }
  auto s = protocol::decode_status(regs);
  if (!s) return std::nullopt;
  return *s;
}

bool ModbusClient::write_command(const protocol::Command& command) {
  const protocol::CommandRegisters regs = protocol::encode_command(command);
  if (modbus_write_registers(ctx_, mb::kCommandAddress, mb::kCommandCount, regs.data()) != int(mb::kCommandCount)) {
    errno_ = errno;
    return false;
  }
  return true;
}

std::optional<protocol::Status> ModbusClient::write_mailbox(const std::vector<std::uint16_t>& registers) {
  protocol::StatusRegisters regs{};
  const int rc = modbus_write_and_read_registers(ctx_, mb::kMailboxAddress, int(registers.size()), registers.data(),
                                                 mb::kStatusMirrorAddress, mb::kStatusCount, regs.data());
  if (rc != int(mb::kStatusCount)) {
    errno_ = errno;
    return std::nullopt;
  }
  auto s = protocol::decode_status(regs);
  if (!s) return std::nullopt;
  return *s;
}

bool ModbusClient::heartbeat(std::uint16_t counter) {
  if (modbus_write_register(ctx_, mb::kHeartbeatAddress, counter) != 1) {
    errno_ = errno;
    return false;
  }
  return true;
}

std::vector<std::string> test_program(int moves) {
  std::string p = "G21 G90 G17\nG54\nT1 M6\nS8000 M3\nG0 X0 Y0 Z20\n";
  for (int i = 0; i < moves; ++i) p += "G1 X" + std::to_string(i % 50) + " Y" + std::to_string(i % 30) + " Z20 F1200\n";
  p += "M5\nM2\n";
  return protocol::program_lines(p);
}

std::vector<std::uint16_t> mailbox_of(const std::vector<std::string>& lines, std::uint32_t first_line,
                                      std::uint32_t seq, protocol::Chunk* chunk) {
  const auto c = protocol::make_chunk(lines, first_line, seq, protocol::program_identity(lines), mb::kMaxChunkPayload);
  if (chunk) *chunk = *c;
  return *mb::encode_mailbox(*c);
}

RawSocket::RawSocket(int port) {
  fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  ::inet_pton(AF_INET, "127.0.0.1", &addr.sin_addr);
  if (::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd_);
    fd_ = -1;
  }
}

RawSocket::~RawSocket() {
  if (fd_ >= 0) ::close(fd_);
}

bool RawSocket::send(const std::string& bytes) {
  return ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(bytes.size());
}

std::string RawSocket::receive(std::chrono::milliseconds wait, const std::string& until) {
  std::string out;
  const auto end = std::chrono::steady_clock::now() + wait;
  while (std::chrono::steady_clock::now() < end) {
    if (!until.empty() && out.find(until) != std::string::npos) break;
    pollfd p{fd_, POLLIN, 0};
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now());
    if (::poll(&p, 1, static_cast<int>(std::max<long>(0, left.count()))) <= 0) break;
    char buffer[4096];
    const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
    if (n <= 0) break;
    out.append(buffer, static_cast<std::size_t>(n));
  }
  return out;
}

std::string RawSocket::receive_bytes(std::size_t count, std::chrono::milliseconds wait) {
  std::string out;
  const auto end = std::chrono::steady_clock::now() + wait;
  while (out.size() < count && std::chrono::steady_clock::now() < end) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, 20) <= 0) continue;
    char buffer[512];
    const ssize_t n = ::recv(fd_, buffer, std::min(sizeof buffer, count - out.size()), 0);
    if (n <= 0) break;
    out.append(buffer, static_cast<std::size_t>(n));
  }
  return out;
}

bool RawSocket::closed_by_peer(std::chrono::milliseconds wait) {
  const auto end = std::chrono::steady_clock::now() + wait;
  while (std::chrono::steady_clock::now() < end) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, 20) <= 0) continue;
    char buffer[512];
    const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
    if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR)) return true;
  }
  return false;
}

}  // namespace hybridctl::test
