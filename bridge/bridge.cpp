#include "bridge/bridge.hpp"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <system_error>
#include <thread>

#include <poll.h>
#include <time.h>

#include "common/error.hpp"
#include "config/transport_uri.hpp"
#include "protocol/can_transfer.hpp"
#include "protocol/modbus_map.hpp"
#include "sim/wire/modbus_server.hpp"
#include "sim/wire/socketcan_endpoint.hpp"
#include "sim/wire/socketcand_server.hpp"

namespace hybridctl::bridge {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::atomic<bool> g_stop{false};
extern "C" void on_bridge_stop_signal(int) { g_stop.store(true); }

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_bridge_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: poll() returns at once
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
}

std::optional<config::HostPort> listen_address(const std::string& option, const std::string& text, bool allow_remote) {
  if (text.empty()) return std::nullopt;
  const config::HostPortResult parsed = config::parse_listen_address(text);
  if (!parsed.host_port) throw InputError(option + " " + text + ": " + parsed.error);
  if (!allow_remote && !config::is_loopback_ipv4(parsed.host_port->host))
    throw InputError(option + " " + text + ": not a loopback address; the bridge binds to 127.0.0.1 unless --allow-remote is given");
  return parsed.host_port;
}

// LinuxCNC must be up and running the INI the bridge was given: a bridge in front of
// another machine's configuration would report the wrong envelope and tools.
LinuxcncStatus wait_for_linuxcnc(LinuxcncLink& link, const BridgeOptions& o) {
  const auto deadline = Clock::now() + std::chrono::duration<double>(o.connect_timeout_s);
  LinuxcncStatus s;
  for (;;) {
    s = link.status();
    if (s.connected && !s.ini.empty()) break;  // a starting LinuxCNC answers before it names its INI
    if (s.connected) s.why = "LinuxCNC is still starting";
    if (Clock::now() > deadline)
      throw InputError("--ini " + o.ini + ": LinuxCNC does not answer after " + std::to_string(int(o.connect_timeout_s)) +
                       " s (" + s.why + "); start it first: linuxcnc " + o.ini);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  std::error_code ec;
  if (!fs::equivalent(fs::path(s.ini), fs::path(o.ini), ec))
    throw InputError("--ini " + o.ini + ": LinuxCNC runs " + s.ini + ", not this configuration");
  return s;
}

std::string make_segment_dir(const BridgeOptions& o) {
  if (!o.segment_dir.empty()) {
    fs::create_directories(o.segment_dir);
    return o.segment_dir;
  }
  const char* tmp = std::getenv("TMPDIR");
  std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/hybridctl-bridge-XXXXXX";
  if (!mkdtemp(pattern.data())) throw InputError("cannot create a segment directory " + pattern);
  fs::permissions(pattern, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                               fs::perms::others_read | fs::perms::others_exec);
  return pattern;
}

struct Endpoints {
  std::unique_ptr<sim::wire::ModbusTcpServer> modbus;
  std::unique_ptr<sim::wire::SocketcandServer> socketcand;
  std::unique_ptr<sim::wire::SocketCanEndpoint> socketcan;
  std::vector<sim::wire::WireEndpoint*> all;
};

Endpoints open_endpoints(const BridgeOptions& o, protocol::ControllerPort& controller,
                         const std::function<void(const std::string&)>& say) {
  const auto modbus_at = listen_address("--modbus", o.modbus, o.allow_remote);
  const auto socketcand_at = listen_address("--socketcand", o.socketcand, o.allow_remote);
  sim::wire::CanNodeOptions node;
  node.node = static_cast<std::uint8_t>(o.node);
  Endpoints e;
  if (!o.socketcan.empty()) {
    e.socketcan = std::make_unique<sim::wire::SocketCanEndpoint>(controller, o.socketcan, node, o.faults);
    e.all.push_back(e.socketcan.get());
    say("listening socketcan " + o.socketcan);
  }
  if (modbus_at) {
    sim::wire::ModbusServerOptions modbus;
    modbus.faults = o.faults;
    e.modbus = std::make_unique<sim::wire::ModbusTcpServer>(controller, modbus_at->host, modbus_at->port, modbus);
    e.all.push_back(e.modbus.get());
    say("listening modbus-tcp " + e.modbus->address() + ":" + std::to_string(e.modbus->port()));
  }
  if (socketcand_at) {
    sim::wire::SocketcandOptions cand;
    cand.node = node;
    cand.faults = o.faults;
    e.socketcand = std::make_unique<sim::wire::SocketcandServer>(controller, socketcand_at->host, socketcand_at->port, cand);
    e.all.push_back(e.socketcand.get());
    say("listening socketcand " + e.socketcand->address() + ":" + std::to_string(e.socketcand->port()));
  }
  return e;
}

// One thread: the wire servers' descriptors in one poll(), LinuxCNC's status read every
// status period (the controller is not thread-safe; everything happens here).
void run_loop(const std::vector<sim::wire::WireEndpoint*>& endpoints, LinuxcncController& controller,
              std::chrono::milliseconds status_period) {
  std::vector<pollfd> fds;
  std::vector<std::size_t> counts(endpoints.size());
  Clock::time_point next_tick = Clock::now();
  while (!g_stop.load(std::memory_order_relaxed)) {
    fds.clear();
    for (std::size_t i = 0; i < endpoints.size(); ++i) {
      const std::size_t before = fds.size();
      endpoints[i]->collect(fds);
      counts[i] = fds.size() - before;
    }
    Clock::time_point now = Clock::now();
    Clock::time_point wake = next_tick;
    for (const sim::wire::WireEndpoint* e : endpoints) wake = std::min(wake, e->next_deadline());
    const auto wait = std::max(std::chrono::nanoseconds(0), std::chrono::nanoseconds(wake - now));
    timespec ts{static_cast<time_t>(wait.count() / 1'000'000'000), static_cast<long>(wait.count() % 1'000'000'000)};
    const int rc = ::ppoll(fds.data(), fds.size(), &ts, nullptr);
    if (rc < 0 && errno != EINTR) throw std::system_error(errno, std::generic_category(), "bridge: poll");
    now = Clock::now();
    if (now >= next_tick) {
      controller.tick(now);
      next_tick = now + status_period;
    }
    if (rc > 0) {
      std::size_t at = 0;
      for (std::size_t i = 0; i < endpoints.size(); ++i) {
        endpoints[i]->service(std::span<const pollfd>(fds.data() + at, counts[i]), now);
        at += counts[i];
      }
    }
    for (sim::wire::WireEndpoint* e : endpoints) e->tick(now);
  }
}

}  // namespace

BridgeOutcome serve_bridge(const BridgeOptions& o, const std::function<void(const std::string&)>& say) {
  if (o.modbus.empty() && o.socketcand.empty() && o.socketcan.empty())
    throw InputError("nothing to serve: give --modbus, --socketcand or --socketcan");
  if (o.ini.empty() || !fs::is_regular_file(o.ini)) throw InputError("--ini " + o.ini + ": expected LinuxCNC's INI file");
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> line_log(nullptr, &std::fclose);
  if (!o.line_log.empty()) {
    line_log.reset(std::fopen(o.line_log.c_str(), "w"));
    if (!line_log) throw InputError("--line-log " + o.line_log + ": cannot write");
  }
  LinuxcncLink::Options link_options;
  link_options.python = o.python;
  LinuxcncLink link(link_options);
  const LinuxcncStatus first = wait_for_linuxcnc(link, o);
  say("linuxcnc " + first.ini);

  ControllerOptions options;
  options.segment_dir = make_segment_dir(o);
  options.buffer_bytes = o.buffer_bytes;
  // Over CAN alone, chunks as large as a CAN transfer carries; with Modbus, its mailbox.
  options.max_chunk_payload = o.modbus.empty()
                                  ? std::uint16_t(std::min<std::size_t>(protocol::can::kMaxChunkPayload, o.buffer_bytes))
                                  : std::uint16_t(protocol::modbus::kMaxChunkPayload);
  options.heartbeat_timeout_s = o.heartbeat_timeout_s;
  options.feed_override = o.feed_override_percent / 100.0;
  options.log = say;
  if (line_log) {
    options.on_line_executed = [f = line_log.get()](std::uint32_t number, std::string_view text) {
      std::fprintf(f, "%u %.*s\n", number, int(text.size()), text.data());
    };
  }
  LinuxcncController controller(link, options);
  controller.tick(Clock::now());
  const Endpoints endpoints = open_endpoints(o, controller, say);
  install_stop_handlers();
  say("ready");
  run_loop(endpoints.all, controller, std::chrono::milliseconds(std::max(1, o.status_period_ms)));
  if (line_log) std::fflush(line_log.get());
  return {controller.report(), controller.status()};
}

}  // namespace hybridctl::bridge
