#pragma once
// The simulated controller on a kernel CAN interface (SocketCAN, e.g. vcan0 or can0): a
// raw CAN socket bound to the interface, struct can_frame in and out, the controller node
// of sim/wire/can_node.hpp behind it. On a kernel without AF_CAN (socket() fails with
// EAFNOSUPPORT) the constructor throws SocketCanUnavailable.
//
// Fault injection: drop_every loses the N-th frame received (the bus has no connection to
// close), exception_every refuses the N-th chunk transfer (flow control OVERFLOW/ABORT),
// corrupt_every loses the N-th frame sent (a frame with a CRC error never reaches the
// receiver's application), delay_ms holds the node's frames back.

#include <memory>
#include <string>

#include "common/error.hpp"
#include "sim/wire/can_node.hpp"
#include "sim/wire/fault_injection.hpp"
#include "sim/wire/serve_loop.hpp"

namespace hybridctl::sim::wire {

/// The kernel has no SocketCAN (AF_CAN); the message says so and names the errno.
class SocketCanUnavailable : public InputError {
 public:
  using InputError::InputError;
};

struct SocketCanCounters {
  std::uint64_t frames_read = 0;
  std::uint64_t frames_written = 0;
  std::uint64_t non_data_frames = 0;  ///< error, remote and extended frames, ignored
  std::uint64_t write_errors = 0;     ///< frames the interface would not take (queue full, bus off)
};

class SocketCanEndpoint final : public WireEndpoint {
 public:
  /// Opens a raw CAN socket on `interface_name`. Throws SocketCanUnavailable without
  /// AF_CAN, hybridctl::InputError for a missing interface or another failure.
  SocketCanEndpoint(protocol::ControllerPort& controller, const std::string& interface_name, CanNodeOptions node = {},
                    FaultOptions faults = {});
  ~SocketCanEndpoint() override;
  SocketCanEndpoint(const SocketCanEndpoint&) = delete;
  SocketCanEndpoint& operator=(const SocketCanEndpoint&) = delete;

  const std::string& interface_name() const;
  const SocketCanCounters& counters() const;
  const CanNodeCounters& node_counters() const;
  const FaultCounters& faults() const;

  void collect(std::vector<pollfd>& fds) override;
  void service(std::span<const pollfd> fds, SteadyTime now) override;
  void tick(SteadyTime now) override;
  SteadyTime next_deadline() const override;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

/// Whether this kernel can open an AF_CAN raw socket; when not, `why` says what failed
/// ("socket(PF_CAN, SOCK_RAW, CAN_RAW): Address family not supported by protocol (errno 97)").
bool socketcan_available(std::string* why = nullptr);

}  // namespace hybridctl::sim::wire
