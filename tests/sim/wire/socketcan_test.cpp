// `hybridctl sim serve --socketcan IFACE`: the controller on a kernel CAN interface. Kernels
// without AF_CAN (these test machines) cannot run it: the command must say so and exit 3,
// and the test then skips, saying why. With AF_CAN it creates a vcan interface and
// exchanges frames with the controller through a raw CAN socket.

#include <gtest/gtest.h>

#include <cstring>
#include <optional>

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include "protocol/can_frames.hpp"
#include "sim/wire/socketcan_endpoint.hpp"
#include "sim_process.hpp"

namespace hybridctl::test {
namespace {

namespace can = protocol::can;

TEST(SocketCan, ServesOnAKernelCanInterface) {
  std::string why;
  if (!sim::wire::socketcan_available(&why)) {
    const PeerResult r = SimProcess::run_to_exit({"--machine", example_machine(), "--socketcan", "vcan0"});
    EXPECT_EQ(r.exit_code, 3) << r.output;
    EXPECT_NE(r.output.find("this kernel has no SocketCAN (AF_CAN)"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("listening"), std::string::npos) << "nothing may listen when the command fails: " << r.output;
    GTEST_SKIP() << "this kernel has no AF_CAN (" << why
                 << "): kernel SocketCAN cannot be exercised here; the command's refusal was checked";
  }

  // A kernel with SocketCAN: a vcan interface of our own (needs CAP_NET_ADMIN).
  const std::string iface = "vcanhyb" + std::to_string(::getpid() % 10000);
  const std::string ip = require_program("ip");
  ASSERT_FALSE(ip.empty());
  const PeerResult add = run_peer({ip, "link", "add", "dev", iface, "type", "vcan"});
  ASSERT_EQ(add.exit_code, 0) << "cannot create a vcan interface (module vcan, CAP_NET_ADMIN): " << add.output;
  struct Cleanup {
    std::string ip, iface;
    ~Cleanup() { run_peer({ip, "link", "del", "dev", iface}); }
  } cleanup{ip, iface};
  ASSERT_EQ(run_peer({ip, "link", "set", iface, "up"}).exit_code, 0);

  SimProcess sim({"--machine", example_machine(), "--socketcan", iface, "--node", "9"});
  const int fd = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  ASSERT_GE(fd, 0);
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, iface.c_str(), IFNAMSIZ - 1);
  ASSERT_EQ(::ioctl(fd, SIOCGIFINDEX, &ifr), 0);
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);

  protocol::Command c;
  c.code = protocol::CommandCode::SetProgram;
  c.seq = 1;
  c.identity = 0x1234;
  c.line_count = 3;
  for (const can::CanFrame& f : can::encode_command_frames(c, 9)) {
    struct can_frame raw {};
    raw.can_id = f.id;
    raw.can_dlc = f.len;
    std::memcpy(raw.data, f.data, f.len);
    ASSERT_EQ(::write(fd, &raw, sizeof raw), static_cast<ssize_t>(sizeof raw));
  }
  can::StatusAssembler assembler(9);
  std::optional<protocol::Status> status;
  const auto end = std::chrono::steady_clock::now() + 5s;
  while (std::chrono::steady_clock::now() < end && !(status && status->command_seq == 1)) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    struct can_frame raw {};
    if (::read(fd, &raw, sizeof raw) != static_cast<ssize_t>(sizeof raw)) continue;
    if (raw.can_id != can::status_id(9)) continue;
    const auto r = assembler.on_frame(can::make_frame(raw.can_id, {raw.data, raw.can_dlc}));
    if (r.status) status = r.status;
  }
  ::close(fd);
  ASSERT_TRUE(status.has_value()) << "no status snapshot on " << iface;
  EXPECT_EQ(status->command_seq, 1);
  EXPECT_EQ(status->command_result, protocol::ResultCode::Accepted);
  EXPECT_EQ(status->program_line_count, 3u);
  EXPECT_EQ(sim.stop(), 0) << sim.errors();
}

}  // namespace
}  // namespace hybridctl::test
