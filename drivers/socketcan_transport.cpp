#include "drivers/socketcan_transport.hpp"

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <thread>

namespace hybridctl::drivers {

namespace can = protocol::can;
using Kind = TransportError::Kind;

namespace {

int poll_ms(SteadyTime deadline) {
  const auto now = SteadyClock::now();
  if (deadline <= now) return 0;
  const auto us = std::chrono::duration_cast<std::chrono::microseconds>(deadline - now).count();
  return static_cast<int>(std::min<long long>((us + 999) / 1000, 1'000'000));
}

std::string no_socketcan(int err) {
  return std::string("this kernel has no SocketCAN (AF_CAN): socket(AF_CAN, SOCK_RAW, CAN_RAW) failed: ") +
         std::strerror(err) + " (errno " + std::to_string(err) +
         "); load the can and can_raw modules, or reach the bus through a socketcand daemon: "
         "socketcand://HOST:PORT/CHANNEL";
}

}  // namespace

bool kernel_has_socketcan() {
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) return false;
  ::close(fd);
  return true;
}

SocketCanIo::SocketCanIo(std::string interface_name, std::uint8_t node)
    : interface_name_(std::move(interface_name)), node_(node) {}

SocketCanIo::~SocketCanIo() { close(); }

std::string SocketCanIo::describe() const { return "socketcan " + interface_name_; }

void SocketCanIo::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void SocketCanIo::open(std::chrono::milliseconds timeout) {
  close();
  timeout_ = timeout;
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    const int err = errno;
    if (err == EAFNOSUPPORT || err == EPROTONOSUPPORT) throw TransportError(Kind::Unsupported, describe() + ": " + no_socketcan(err));
    throw TransportError(Kind::Unreachable, describe() + ": cannot open a CAN socket: " + std::strerror(err));
  }
  const unsigned index = ::if_nametoindex(interface_name_.c_str());
  if (index == 0) {
    const int err = errno;
    ::close(fd);
    throw TransportError(Kind::Unreachable, describe() + ": no network interface '" + interface_name_ + "' (" +
                                                std::strerror(err) + "); `ip link` lists them");
  }
  // Only the controller's status and flow control: 11-bit identifiers, data frames.
  const can_filter filters[2] = {
      {can::status_id(node_), CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG},
      {can::flow_control_id(node_), CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG},
  };
  ::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters, sizeof filters);
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(index);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    const int err = errno;
    ::close(fd);
    throw TransportError(Kind::Unreachable, describe() + ": cannot bind to the interface: " + std::strerror(err));
  }
  fd_ = fd;
}

void SocketCanIo::send(std::span<const can::CanFrame> frames) {
  if (fd_ < 0) throw TransportError(Kind::Disconnected, describe() + ": not open");
  const SteadyTime deadline = SteadyClock::now() + timeout_;
  for (const auto& f : frames) {
    can_frame raw{};
    raw.can_id = f.id & CAN_SFF_MASK;
    const auto bytes = f.bytes();
    raw.len = static_cast<__u8>(bytes.size());
    std::memcpy(raw.data, bytes.data(), bytes.size());
    while (true) {
      const ssize_t n = ::write(fd_, &raw, sizeof raw);
      if (n == static_cast<ssize_t>(sizeof raw)) break;
      // The interface's transmit queue is full (ENOBUFS) or the socket buffer is: wait.
      if (n < 0 && (errno == ENOBUFS || errno == EAGAIN || errno == EINTR)) {
        if (SteadyClock::now() >= deadline) {
          close();
          throw TransportError(Kind::Disconnected,
                               describe() + ": the bus takes no frames (transmit queue full for " +
                                   std::to_string(timeout_.count()) + " ms: no other node acknowledges?)");
        }
        pollfd p{fd_, POLLOUT, 0};
        ::poll(&p, 1, 1);
        continue;
      }
      const std::string why = n < 0 ? std::strerror(errno) : "short write";
      close();
      throw TransportError(Kind::Disconnected, describe() + ": " + why);
    }
  }
}

std::optional<can::CanFrame> SocketCanIo::receive(SteadyTime deadline) {
  if (fd_ < 0) throw TransportError(Kind::Disconnected, describe() + ": not open");
  while (true) {
    can_frame raw{};
    const ssize_t n = ::read(fd_, &raw, sizeof raw);
    if (n == static_cast<ssize_t>(sizeof raw)) {
      if ((raw.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_ERR_FLAG)) != 0 || raw.len > 8) {
        ++garbage_;
        continue;
      }
      can::CanFrame f;
      f.id = raw.can_id & CAN_SFF_MASK;
      f.len = raw.len;
      std::memcpy(f.data, raw.data, raw.len);
      return f;
    }
    if (n >= 0) {
      ++garbage_;  // a CAN FD frame or a short read: not ours
      continue;
    }
    if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
      const std::string why = std::strerror(errno);
      close();
      throw TransportError(Kind::Disconnected, describe() + ": " + why);
    }
    if (SteadyClock::now() >= deadline) return std::nullopt;
    pollfd p{fd_, POLLIN, 0};
    ::poll(&p, 1, poll_ms(deadline));
  }
}

}  // namespace hybridctl::drivers
