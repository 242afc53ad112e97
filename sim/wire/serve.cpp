#include "sim/wire/serve.hpp"

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "common/error.hpp"
#include "config/machine_loader.hpp"
#include "plan/start_stock.hpp"
#include "config/transport_uri.hpp"
#include "geometry/memory_estimate.hpp"
#include "geometry/mesh.hpp"
#include "geometry/morphology.hpp"
#include "geometry/surface_mesh.hpp"
#include "geometry/vdb_file.hpp"
#include "plan/plan_file.hpp"
#include "protocol/can_transfer.hpp"
#include "protocol/modbus_map.hpp"
#include "sim/wire/modbus_server.hpp"
#include "sim/wire/run_report.hpp"
#include "sim/wire/serve_loop.hpp"
#include "sim/wire/socketcan_endpoint.hpp"
#include "sim/wire/socketcand_server.hpp"

namespace hybridctl::sim::wire {
namespace {

namespace fs = std::filesystem;
using Reason = ServeRefused::Reason;

std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler needs a lock-free flag");

extern "C" void on_stop_signal(int) { g_stop.store(true); }

// No SA_RESTART: poll() returns at once when a signal arrives.
void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
}

std::optional<config::HostPort> listen_address(const std::string& option, const std::string& text) {
  if (text.empty()) return std::nullopt;
  const config::HostPortResult parsed = config::parse_listen_address(text);
  if (!parsed.host_port) throw ServeRefused(Reason::Usage, option + " " + text + ": " + parsed.error);
  return parsed.host_port;
}

// What the options say once checked: where to listen and the faults to inject.
struct CheckedOptions {
  std::optional<config::HostPort> modbus_at, socketcand_at;
  FaultOptions faults;
};

CheckedOptions check_options(const ServeOptions& o) {
  if (o.modbus.empty() && o.modbus_rtu.empty() && o.socketcand.empty() && o.socketcan.empty())
    throw ServeRefused(Reason::Usage, "nothing to serve: give --modbus, --modbus-rtu, --socketcand or --socketcan");
  CheckedOptions c;
  c.modbus_at = listen_address("--modbus", o.modbus);
  c.socketcand_at = listen_address("--socketcand", o.socketcand);
  for (const auto* at : {&c.modbus_at, &c.socketcand_at}) {
    if (*at && !config::is_loopback_ipv4((*at)->host) && !o.allow_remote)
      throw ServeRefused(Reason::Usage, (*at)->host +
                                            " is not a loopback address: the simulator binds to 127.0.0.1 unless "
                                            "--allow-remote is given");
  }
  if (!o.as_built.empty() && o.stock_plan.empty() && o.stock_vdb.empty())
    throw ServeRefused(Reason::Usage, "--as-built needs a stock (--stock PLAN.json or --stock-vdb FILE)");
  if (!o.as_built.empty()) {
    const std::string ext = fs::path(o.as_built).extension().string();
    if (ext != ".vdb" && ext != ".stl")
      throw ServeRefused(Reason::Usage, "--as-built " + o.as_built + ": expected a .vdb or .stl file name");
  }
  c.faults = o.faults;
  for (const std::string& item : o.reboot_after_lines) {
    const std::string e = parse_line_list(item, c.faults.reboot_after_lines);
    if (!e.empty()) throw ServeRefused(Reason::Usage, "--reboot-after-lines " + e);
  }
  return c;
}

// The stock, and the region the cuts must spare, from a plan directory: the chosen plan's
// first action's primitive when it is a raw stock (else an empty stock), on the plan's
// domain, and the design shrunk by the tolerance. Returns what the stock is, for the report.
std::string stock_from_plan(const ServeOptions& o, const config::Machine& machine, ControllerOptions& options) {
  const plan::PlanFile file = plan::read_plan_file(o.stock_plan);
  if (file.plans.empty()) throw InputError(o.stock_plan + ": the plan file holds no plans (the part was not manufacturable)");
  if (o.plan < 1 || o.plan > int(file.plans.size())) {
    throw InputError("--plan " + std::to_string(o.plan) + ": expected 1.." + std::to_string(file.plans.size()) +
                     " (the plans in " + o.stock_plan + ")");
  }
  const plan::PlanFilePlan& plan = file.plans[std::size_t(o.plan - 1)];
  const plan::PlanFilePrimitive* first =
      plan.actions.empty() ? nullptr : &file.primitives.at(std::size_t(plan.actions.front().primitive));
  std::string described;
  // As validation executes plans (plan/start_stock.hpp): over the plan's domain, the
  // build plate under the first deposit of a plan that starts with deposition.
  options.stock = plan::start_stock(file, plan, machine);
  if (first && first->raw_stock()) {
    described = "raw stock " + first->name + " (" + first->capability + ") of plan " + std::to_string(o.plan);
  } else {
    described = "empty (plan " + std::to_string(o.plan) + " starts with deposition)";
  }
  // The whole design shrunk by the tolerance: the controller does not follow which action
  // a line belongs to, so a removal the plan refills later (SM-cons) counts as gouge here.
  options.protected_region = plan::spared_by_cuts(file);
  return described;
}

// The stock's grids must fit the memory budget, checked from plan.json's grid or the
// .vdb's metadata before any voxel is loaded (geometry/memory_estimate.hpp).
void check_stock_memory(const ServeOptions& o) {
  const std::uint64_t budget = o.memory_budget ? o.memory_budget : geometry::default_memory_budget();
  if (!o.stock_plan.empty()) {
    const plan::PlanGrid grid = plan::read_plan_grid(o.stock_plan);
    const geometry::Box3 region = grid.lattice.extent(grid.domain);
    // The plan as read (design and every primitive), the stock, the spared region and the
    // controller's material: dense solids over the plan's domain.
    const double solids = double(grid.primitives) + 4;
    geometry::check_memory_budget([&](double h) { return solids * geometry::solid_bytes(region, h); },
                                  grid.lattice.voxel_size, budget, "the stock of " + o.stock_plan,
                                  "a plan made with --voxel ");
  }
  if (!o.stock_vdb.empty()) {
    const std::optional<geometry::VdbExtent> extent = geometry::read_vdb_extent(o.stock_vdb);
    if (!extent) return;  // read_vdb says what is wrong with the file
    // The float grid as read (4 bytes a voxel at most), the stock and the controller's material.
    const auto bytes = [&](double h) { return 4 * geometry::grid_voxels(extent->box, h) + 2 * geometry::solid_bytes(extent->box, h); };
    geometry::check_memory_budget(bytes, extent->voxel_size, budget, "the stock " + o.stock_vdb,
                                  "a stock .vdb with a voxel size of ");
  }
}

ControllerOptions controller_options(const ServeOptions& o, const FaultOptions& faults) {
  ControllerOptions options;
  options.time_scale = o.time_scale;
  options.buffer_bytes = o.buffer_bytes;
  // Over CAN alone, chunks may be as large as a CAN transfer carries (fewer round trips);
  // with a Modbus endpoint, as large as its mailbox.
  options.max_chunk_payload = o.modbus.empty() && o.modbus_rtu.empty()
                                  ? std::uint16_t(std::min<std::size_t>(protocol::can::kMaxChunkPayload, o.buffer_bytes))
                                  : std::uint16_t(protocol::modbus::kMaxChunkPayload);
  options.heartbeat_timeout_s = o.heartbeat_timeout_s;
  options.alarm_at_line = faults.alarm_at_line;
  options.hold_at_line = faults.hold_at_line;
  // A reboot lands right after its line: advance() stops there.
  options.break_after_lines.assign(faults.reboot_after_lines.begin(), faults.reboot_after_lines.end());
  std::sort(options.break_after_lines.begin(), options.break_after_lines.end());
  return options;
}

// Every executed line's text, in execution order, one per line, so a test can compare it
// with the program byte for byte. Written to FILE.tmp, renamed when the run has ended.
class LineLog {
 public:
  explicit LineLog(const std::string& path) : path_(path) {
    if (path_.empty()) return;
    file_.reset(std::fopen((path_ + ".tmp").c_str(), "w"));
    if (!file_) throw ServeRefused(Reason::BadInput, "--line-log " + path_ + ": cannot write");
  }
  void attach(ControllerOptions& options) const {
    if (!file_) return;
    options.on_line_executed = [f = file_.get()](std::uint32_t, std::string_view text) {
      std::fwrite(text.data(), 1, text.size(), f);
      std::fputc('\n', f);
    };
  }
  void finish() {
    if (!file_) return;
    std::fflush(file_.get());
    file_.reset();
    fs::rename(path_ + ".tmp", path_);
  }

 private:
  std::string path_;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file_{nullptr, &std::fclose};
};

std::string host_port_text(const std::string& address, int port) { return address + ":" + std::to_string(port); }

// The servers in front of the controller, each present when its option was given.
struct Endpoints {
  std::unique_ptr<ModbusTcpServer> modbus_tcp;
  std::unique_ptr<ModbusRtuServer> modbus_rtu;
  std::unique_ptr<SocketcandServer> socketcand;
  std::unique_ptr<SocketCanEndpoint> socketcan;
};

Endpoints open_endpoints(const ServeOptions& o, const CheckedOptions& c, Controller& controller) {
  CanNodeOptions node;
  node.node = static_cast<std::uint8_t>(o.node);
  node.status_period = std::chrono::milliseconds(o.status_period_ms);
  node.reassembler.block_size = static_cast<std::uint8_t>(o.can_block_size);
  ModbusServerOptions modbus;
  modbus.faults = c.faults;
  modbus.debug = o.modbus_debug;
  Endpoints e;
  // SocketCAN first: on a kernel without it the command fails before anything listens.
  if (!o.socketcan.empty()) e.socketcan = std::make_unique<SocketCanEndpoint>(controller, o.socketcan, node, c.faults);
  if (c.modbus_at) e.modbus_tcp = std::make_unique<ModbusTcpServer>(controller, c.modbus_at->host, c.modbus_at->port, modbus);
  if (!o.modbus_rtu.empty()) {
    ModbusRtuSettings rtu;
    rtu.device = o.modbus_rtu;
    rtu.baud = o.baud;
    rtu.parity = o.parity.empty() ? 'E' : o.parity[0];
    rtu.unit = o.unit;
    e.modbus_rtu = std::make_unique<ModbusRtuServer>(controller, rtu, modbus);
  }
  if (c.socketcand_at) {
    SocketcandOptions cand;
    cand.node = node;
    cand.faults = c.faults;
    cand.bitrate = o.can_bitrate;
    e.socketcand = std::make_unique<SocketcandServer>(controller, c.socketcand_at->host, c.socketcand_at->port, cand);
  }
  return e;
}

void add_to_loop(const Endpoints& e, const ServeOptions& o, ServeLoop& loop,
                 const std::function<void(const std::string&)>& say) {
  if (e.modbus_tcp) {
    loop.add(*e.modbus_tcp);
    say("listening modbus-tcp " + host_port_text(e.modbus_tcp->address(), e.modbus_tcp->port()));
  }
  if (e.modbus_rtu) {
    loop.add(*e.modbus_rtu);
    say("listening modbus-rtu " + o.modbus_rtu);
  }
  if (e.socketcand) {
    loop.add(*e.socketcand);
    say("listening socketcand " + host_port_text(e.socketcand->address(), e.socketcand->port()));
  }
  if (e.socketcan) {
    loop.add(*e.socketcan);
    say("listening socketcan " + o.socketcan);
  }
}

void add_transports(const Endpoints& e, const ServeOptions& o, RunReport& report) {
  if (e.modbus_tcp)
    report.modbus_tcp = ModbusTcpReport{host_port_text(e.modbus_tcp->address(), e.modbus_tcp->port()),
                                        e.modbus_tcp->counters(), e.modbus_tcp->faults()};
  if (e.modbus_rtu)
    report.modbus_rtu = ModbusRtuReport{o.modbus_rtu, o.unit, e.modbus_rtu->counters(), e.modbus_rtu->faults()};
  if (e.socketcand)
    report.socketcand = SocketcandReport{host_port_text(e.socketcand->address(), e.socketcand->port()),
                                         e.socketcand->counters(), e.socketcand->node_counters(), e.socketcand->faults()};
  if (e.socketcan)
    report.socketcan =
        SocketCanReport{o.socketcan, e.socketcan->counters(), e.socketcan->node_counters(), e.socketcan->faults()};
}

void write_as_built(const Controller& controller, const std::string& path) {
  const geometry::Solid built = controller.as_built();
  if (fs::path(path).extension() == ".stl") {
    geometry::write_stl(geometry::surface_mesh(built), path);
  } else {
    geometry::write_vdb(built, path, "as_built");
  }
}

}  // namespace

ServeOutcome serve(const ServeOptions& o, const std::function<void(const std::string&)>& say) {
  const CheckedOptions checked = check_options(o);
  const config::Machine machine = config::load_machine(o.machine);
  check_stock_memory(o);
  ControllerOptions options = controller_options(o, checked.faults);
  std::string stock = "none";
  if (!o.stock_plan.empty()) stock = stock_from_plan(o, machine, options);
  if (!o.stock_vdb.empty()) {
    options.stock = geometry::read_vdb(o.stock_vdb);
    stock = o.stock_vdb;
  }
  LineLog line_log(o.line_log);
  line_log.attach(options);
  Controller controller(machine, options);
  ServeLoopOptions loop_options;
  loop_options.exit_when_done = o.exit_when_done;
  loop_options.reboot_after_lines = checked.faults.reboot_after_lines;
  loop_options.spin_while_executing = o.time_scale == 0;
  ServeLoop loop(controller, loop_options);
  const Endpoints endpoints = open_endpoints(o, checked, controller);
  install_stop_handlers();  // before "ready": a test may signal as soon as it reads that line
  add_to_loop(endpoints, o, loop, say);
  say("ready");

  const ServeExit exit = loop.run(g_stop);

  ServeOutcome outcome{exit == ServeExit::Completed, controller.report(), {}};
  line_log.finish();
  outcome.final_status = controller.status();
  if (!o.as_built.empty()) write_as_built(controller, o.as_built);
  if (!o.report.empty()) {
    RunReport report;
    report.machine = machine.name;
    report.machine_file = o.machine;
    report.completed = outcome.completed;
    report.real_time_s = loop.real_seconds();
    report.time_scale = o.time_scale;
    report.stock = stock;
    report.controller = outcome.controller;
    report.final_status = outcome.final_status;
    add_transports(endpoints, o, report);
    report.faults = checked.faults;
    report.reboots_injected = loop.reboots_injected();
    write_run_report(report, o.report);
  }
  return outcome;
}

}  // namespace hybridctl::sim::wire
