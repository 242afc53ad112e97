#pragma once
// A CAN bus on this host through the kernel's SocketCAN: a raw CAN socket (AF_CAN,
// SOCK_RAW, CAN_RAW) bound to one interface (can0, vcan0, ...), filtered to the
// controller's status and flow control identifiers, under the CAN link
// (drivers/can_link.hpp).
//
// A kernel without CAN support refuses the socket with EAFNOSUPPORT: open() then throws
// TransportError(Unsupported) saying so, and that socketcand reaches a bus on another host.

#include <cstdint>
#include <string>

#include "drivers/can_link.hpp"

namespace hybridctl::drivers {

class SocketCanIo final : public CanFrameIo {
 public:
  SocketCanIo(std::string interface_name, std::uint8_t node);
  ~SocketCanIo() override;
  SocketCanIo(const SocketCanIo&) = delete;
  SocketCanIo& operator=(const SocketCanIo&) = delete;

  std::string describe() const override;
  void open(std::chrono::milliseconds timeout) override;
  void close() override;
  bool is_open() const override { return fd_ >= 0; }
  void send(std::span<const protocol::can::CanFrame> frames) override;
  std::optional<protocol::can::CanFrame> receive(SteadyTime deadline) override;
  std::uint64_t garbage() const override { return garbage_; }

 private:
  std::string interface_name_;
  std::uint8_t node_;
  int fd_ = -1;
  std::chrono::milliseconds timeout_{500};
  std::uint64_t garbage_ = 0;
};

/// True when this kernel lets a process open a raw CAN socket (false: no AF_CAN).
bool kernel_has_socketcan();

}  // namespace hybridctl::drivers
