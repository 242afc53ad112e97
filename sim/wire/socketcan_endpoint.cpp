#include "sim/wire/socketcan_endpoint.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <deque>

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include "sim/controller.hpp"

namespace hybridctl::sim::wire {

namespace can = protocol::can;

namespace {

std::string socket_failure(int err) {
  return "socket(PF_CAN, SOCK_RAW, CAN_RAW): " + std::string(std::strerror(err)) + " (errno " + std::to_string(err) + ")";
}

}  // namespace

bool socketcan_available(std::string* why) {
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    if (why) *why = socket_failure(errno);
    return false;
  }
  ::close(fd);
  return true;
}

struct SocketCanEndpoint::Impl {
  Impl(protocol::ControllerPort& controller, std::string iface, CanNodeOptions node_options, FaultOptions fault_options)
      : interface_name(std::move(iface)), node(controller, node_options), faults(fault_options) {}

  struct Outgoing {
    CanMicros due{0};
    can::CanFrame frame;
  };

  std::string interface_name;
  CanNode node;
  FaultInjector faults;
  SocketCanCounters counters;
  int fd = -1;
  std::deque<Outgoing> outgoing;

  void read_frames(CanMicros now) {
    for (;;) {
      struct can_frame raw {};
      const ssize_t n = ::read(fd, &raw, sizeof raw);
      if (n != static_cast<ssize_t>(sizeof raw)) return;  // EAGAIN, or not a classic frame
      ++counters.frames_read;
      if (raw.can_id & (CAN_ERR_FLAG | CAN_RTR_FLAG | CAN_EFF_FLAG)) {
        ++counters.non_data_frames;
        continue;
      }
      can::CanFrame frame;
      frame.id = raw.can_id & CAN_SFF_MASK;
      frame.len = std::min<std::uint8_t>(raw.can_dlc, 8);
      std::memcpy(frame.data, raw.data, frame.len);
      if (faults.drop_request()) continue;  // lost on the way in
      const bool first = frame.id == can::data_id(node.node()) && frame.len >= 1 && (frame.data[0] >> 4) == 1;
      if (first && faults.refuse_request()) {
        node.refuse_transfer(frame);
      } else {
        node.on_frame(frame, now);
      }
    }
  }

  void pump(CanMicros now) {
    node.tick(now);
    auto& outbox = node.outbox();
    while (!outbox.empty()) {
      CanMicros due = now;
      if (faults.delays()) due += std::chrono::duration_cast<CanMicros>(faults.reply_delay());
      outgoing.push_back({due, outbox.front()});
      outbox.pop_front();
    }
    while (!outgoing.empty() && outgoing.front().due <= now) {
      const can::CanFrame& f = outgoing.front().frame;
      if (faults.corrupt_reply()) {  // a frame with a CRC error: the receivers never see it
        outgoing.pop_front();
        continue;
      }
      struct can_frame raw {};
      raw.can_id = f.id & CAN_SFF_MASK;
      raw.can_dlc = std::min<std::uint8_t>(f.len, 8);
      std::memcpy(raw.data, f.data, raw.can_dlc);
      const ssize_t n = ::write(fd, &raw, sizeof raw);
      if (n < 0 && (errno == EAGAIN || errno == ENOBUFS)) return;  // the queue is full: retry on POLLOUT
      if (n != static_cast<ssize_t>(sizeof raw)) {
        ++counters.write_errors;
      } else {
        ++counters.frames_written;
      }
      outgoing.pop_front();
    }
  }
};

SocketCanEndpoint::SocketCanEndpoint(protocol::ControllerPort& controller, const std::string& interface_name, CanNodeOptions node,
                                     FaultOptions faults)
    : impl_(std::make_unique<Impl>(controller, interface_name, node, faults)) {
  Impl& s = *impl_;
  const std::string where = "socketcan " + interface_name;
  if (!can::valid_node(node.node)) throw InputError(where + ": node " + std::to_string(node.node) + " is not 1..127");
  if (interface_name.empty() || interface_name.size() >= IFNAMSIZ) {
    throw InputError(where + ": an interface name of 1.." + std::to_string(IFNAMSIZ - 1) + " characters expected");
  }
  s.fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (s.fd < 0) {
    const int err = errno;
    if (err == EAFNOSUPPORT) {
      throw SocketCanUnavailable(where + ": this kernel has no SocketCAN (AF_CAN): " + socket_failure(err) +
                                 "; use --socketcand to serve the bus over TCP instead");
    }
    throw InputError(where + ": " + socket_failure(err));
  }
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, interface_name.c_str(), IFNAMSIZ - 1);
  if (::ioctl(s.fd, SIOCGIFINDEX, &ifr) < 0) {
    const int err = errno;
    ::close(s.fd);
    throw InputError(where + ": no such CAN interface (" + std::strerror(err) +
                     "); create one with 'ip link add dev vcan0 type vcan && ip link set vcan0 up'");
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (::bind(s.fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) {
    const int err = errno;
    ::close(s.fd);
    throw InputError(where + ": bind: " + std::strerror(err));
  }
}

SocketCanEndpoint::~SocketCanEndpoint() { ::close(impl_->fd); }

const std::string& SocketCanEndpoint::interface_name() const { return impl_->interface_name; }
const SocketCanCounters& SocketCanEndpoint::counters() const { return impl_->counters; }
const CanNodeCounters& SocketCanEndpoint::node_counters() const { return impl_->node.counters(); }
const FaultCounters& SocketCanEndpoint::faults() const { return impl_->faults.counters(); }

void SocketCanEndpoint::collect(std::vector<pollfd>& fds) {
  const bool blocked = !impl_->outgoing.empty() && impl_->outgoing.front().due <= can_now();
  fds.push_back({impl_->fd, static_cast<short>(POLLIN | (blocked ? POLLOUT : 0)), 0});
}

void SocketCanEndpoint::service(std::span<const pollfd> fds, SteadyTime now) {
  const CanMicros t = std::chrono::duration_cast<CanMicros>(now.time_since_epoch());
  if (!fds.empty() && (fds[0].revents & POLLIN)) impl_->read_frames(t);
  impl_->pump(t);
}

void SocketCanEndpoint::tick(SteadyTime now) {
  impl_->pump(std::chrono::duration_cast<CanMicros>(now.time_since_epoch()));
}

SteadyTime SocketCanEndpoint::next_deadline() const {
  CanMicros t = impl_->node.next_deadline();
  // A frame already due waits for POLLOUT (the interface's queue was full): look again in
  // a millisecond at the latest rather than spinning.
  if (!impl_->outgoing.empty()) t = std::min(t, std::max(impl_->outgoing.front().due, can_now() + CanMicros{1000}));
  return SteadyTime(std::chrono::duration_cast<SteadyClock::duration>(t));
}

}  // namespace hybridctl::sim::wire
