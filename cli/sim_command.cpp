// hybridctl sim serve: the simulated machine controller on the wire (docs/simulator.md).

#include <atomic>
#include <csignal>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <arpa/inet.h>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/ranges.hpp"
#include "protocol/can_transfer.hpp"
#include "protocol/modbus_map.hpp"
#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "config/machine_loader.hpp"
#include "config/transport_uri.hpp"
#include "protocol/codes.hpp"
#include "geometry/mesh.hpp"
#include "geometry/morphology.hpp"
#include "geometry/surface_mesh.hpp"
#include "geometry/vdb_file.hpp"
#include "planner/plan_file.hpp"
#include "sim/controller.hpp"
#include "sim/wire/fault_injection.hpp"
#include "sim/wire/modbus_server.hpp"
#include "sim/wire/serve_loop.hpp"
#include "sim/wire/socketcan_endpoint.hpp"
#include "sim/wire/socketcand_server.hpp"

namespace hybridctl::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler needs a lock-free flag");

extern "C" void on_stop_signal(int) { g_stop.store(true); }

struct ServeRequest {
  std::string machine;
  std::string modbus;      // tcp://HOST:PORT
  std::string modbus_rtu;  // device
  int baud = 19200;
  std::string parity = "E";
  int unit = 1;
  std::string socketcand;  // HOST:PORT
  std::string socketcan;   // interface
  int node = 1;
  std::uint32_t can_bitrate = 0;
  int status_period_ms = 100;
  int can_block_size = 0;
  double time_scale = 1.0;
  std::uint32_t buffer_bytes = 16384;
  double heartbeat_timeout_s = 2.0;
  std::string stock_plan;
  std::string stock_vdb;
  int plan = 1;
  std::string report;
  std::string as_built;
  std::string line_log;
  bool exit_when_done = false;
  bool allow_remote = false;
  bool modbus_debug = false;
  sim::FaultOptions faults;
  std::vector<std::string> reboot_after_lines;
};

struct HostPort {
  std::string host;  // IPv4 dotted quad
  int port = 0;
};

// "tcp://HOST:PORT", "modbus-tcp://HOST:PORT", "socketcand://HOST:PORT[/CHANNEL]" or
// "HOST:PORT"; HOST an IPv4 address or "localhost"; PORT 0..65535 (0: any free port).
std::optional<HostPort> parse_host_port(std::string text, std::string& error) {
  for (const char* scheme : {"tcp://", "modbus-tcp://", "socketcand://"}) {
    if (text.rfind(scheme, 0) == 0) {
      text = text.substr(std::string(scheme).size());
      break;
    }
  }
  if (const auto slash = text.find('/'); slash != std::string::npos) text = text.substr(0, slash);  // socketcand channel
  if (const auto query = text.find('?'); query != std::string::npos) text = text.substr(0, query);   // ?unit=N
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == text.size()) {
    error = "expected [tcp://]HOST:PORT with an IPv4 HOST (e.g. 127.0.0.1:1502; port 0 picks a free port)";
    return std::nullopt;
  }
  HostPort hp;
  hp.host = text.substr(0, colon);
  if (hp.host == "localhost") hp.host = "127.0.0.1";
  in_addr addr{};
  if (::inet_pton(AF_INET, hp.host.c_str(), &addr) != 1) {
    error = "'" + hp.host + "' is not an IPv4 address (expected e.g. 127.0.0.1)";
    return std::nullopt;
  }
  const std::string port = text.substr(colon + 1);
  if (port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos || std::stoi(port) > 65535) {
    error = "port '" + port + "' is not 0..65535";
    return std::nullopt;
  }
  hp.port = std::stoi(port);
  return hp;
}

bool loopback(const std::string& host) {
  in_addr addr{};
  ::inet_pton(AF_INET, host.c_str(), &addr);
  return (ntohl(addr.s_addr) >> 24) == 127;
}

CLI::Validator host_port_validator() {
  return CLI::Validator(
      [](std::string& value) {
        std::string error;
        return parse_host_port(value, error) ? std::string() : error;
      },
      "[tcp://]HOST:PORT");
}

void print_line(const std::string& line) {
  std::fputs((line + "\n").c_str(), stdout);
  std::fflush(stdout);
}

// The stock, and the region the cuts must spare, from a plan directory: the chosen plan's
// first action's primitive when it is a raw stock (else an empty stock on the plan's
// domain), and the design shrunk by the tolerance.
void stock_from_plan(const ServeRequest& r, sim::ControllerOptions& options, std::string& described) {
  const planner::PlanFile file = planner::read_plan_file(r.stock_plan);
  if (file.plans.empty()) throw InputError(r.stock_plan + ": the plan file holds no plans (the part was not manufacturable)");
  if (r.plan < 1 || r.plan > int(file.plans.size())) {
    throw InputError("--plan " + std::to_string(r.plan) + ": expected 1.." + std::to_string(file.plans.size()) +
                     " (the plans in " + r.stock_plan + ")");
  }
  const planner::PlanFilePlan& plan = file.plans[std::size_t(r.plan - 1)];
  const planner::PlanFilePrimitive* first =
      plan.actions.empty() ? nullptr : &file.primitives.at(std::size_t(plan.actions.front().primitive));
  if (first && first->raw_stock()) {
    options.stock = first->region;
    described = "raw stock " + first->name + " (" + first->capability + ") of plan " + std::to_string(r.plan);
  } else {
    options.stock = geometry::Solid(file.lattice, file.domain);
    described = "empty (plan " + std::to_string(r.plan) + " starts with deposition)";
  }
  options.protected_region = geometry::erode(file.design, geometry::Ball{file.tolerance});
}

json counters_json(const sim::ModbusCounters& c) {
  json exceptions = json::object();
  for (std::size_t code = 1; code < c.exceptions.size(); ++code)
    if (c.exceptions[code]) exceptions[std::to_string(code)] = c.exceptions[code];
  return {{"connections", c.connections},   {"refused_connections", c.refused_connections},
          {"disconnects", c.disconnects},   {"requests", c.requests},
          {"replies", c.replies},           {"exceptions", exceptions},
          {"bad_frames", c.bad_frames},     {"other_unit", c.other_unit},
          {"broadcasts", c.broadcasts},     {"heartbeat_writes", c.heartbeat_writes},
          {"command_writes", c.command_writes}, {"mailbox_writes", c.mailbox_writes}};
}

json counters_json(const sim::CanNodeCounters& c) {
  return {{"frames_in", c.frames_in},           {"frames_ignored", c.frames_ignored},
          {"frames_out", c.frames_out},         {"commands", c.commands},
          {"command_errors", c.command_errors}, {"heartbeats", c.heartbeats},
          {"heartbeat_errors", c.heartbeat_errors}, {"chunks", c.chunks},
          {"transfer_errors", c.transfer_errors}, {"refused_transfers", c.refused_transfers},
          {"status_snapshots", c.status_snapshots}};
}

json faults_json(const sim::FaultCounters& f) {
  return {{"dropped", f.dropped}, {"delayed", f.delayed}, {"corrupted", f.corrupted}, {"busy", f.busy}};
}

void write_text_atomically(const fs::path& path, const std::string& text) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temp_path(), std::ios::binary);
    out << text;
    out.flush();
    if (!out) throw InputError(path.string() + ": cannot write");
  }
  file.commit();
}

int serve(const ServeRequest& r) {
  if (r.modbus.empty() && r.modbus_rtu.empty() && r.socketcand.empty() && r.socketcan.empty()) {
    std::fprintf(stderr,
                 "hybridctl sim serve: error: nothing to serve: give --modbus, --modbus-rtu, --socketcand or "
                 "--socketcan\n");
    return kUsage;
  }
  std::optional<HostPort> modbus_at, socketcand_at;
  std::string error;
  if (!r.modbus.empty()) modbus_at = parse_host_port(r.modbus, error);
  if (!r.socketcand.empty()) socketcand_at = parse_host_port(r.socketcand, error);
  for (const auto* at : {&modbus_at, &socketcand_at}) {
    if (*at && !loopback((*at)->host) && !r.allow_remote) {
      std::fprintf(stderr,
                   "hybridctl sim serve: error: %s is not a loopback address: the simulator binds to 127.0.0.1 "
                   "unless --allow-remote is given\n",
                   (*at)->host.c_str());
      return kUsage;
    }
  }
  if (!r.as_built.empty() && r.stock_plan.empty() && r.stock_vdb.empty()) {
    std::fprintf(stderr, "hybridctl sim serve: error: --as-built needs a stock (--stock PLAN.json or --stock-vdb FILE)\n");
    return kUsage;
  }
  if (!r.as_built.empty()) {
    const std::string ext = fs::path(r.as_built).extension().string();
    if (ext != ".vdb" && ext != ".stl") {
      std::fprintf(stderr, "hybridctl sim serve: error: --as-built %s: expected a .vdb or .stl file name\n",
                   r.as_built.c_str());
      return kUsage;
    }
  }
  sim::FaultOptions faults = r.faults;
  for (const std::string& item : r.reboot_after_lines) {
    const std::string e = sim::parse_line_list(item, faults.reboot_after_lines);
    if (!e.empty()) {
      std::fprintf(stderr, "hybridctl sim serve: error: --reboot-after-lines %s\n", e.c_str());
      return kUsage;
    }
  }

  const config::Machine machine = config::load_machine(r.machine);
  sim::ControllerOptions options;
  options.time_scale = r.time_scale;
  options.buffer_bytes = r.buffer_bytes;
  // Over CAN alone, chunks may be as large as a CAN transfer carries (fewer round trips);
  // with a Modbus endpoint, as large as its mailbox.
  options.max_chunk_payload = r.modbus.empty() && r.modbus_rtu.empty()
                                  ? std::uint16_t(std::min<std::size_t>(protocol::can::kMaxChunkPayload, r.buffer_bytes))
                                  : std::uint16_t(protocol::modbus::kMaxChunkPayload);
  options.heartbeat_timeout_s = r.heartbeat_timeout_s;
  options.alarm_at_line = faults.alarm_at_line;
  // A reboot lands right after its line: advance() stops there.
  options.break_after_lines.assign(faults.reboot_after_lines.begin(), faults.reboot_after_lines.end());
  std::sort(options.break_after_lines.begin(), options.break_after_lines.end());
  std::string stock = "none";
  if (!r.stock_plan.empty()) stock_from_plan(r, options, stock);
  if (!r.stock_vdb.empty()) {
    options.stock = geometry::read_vdb(r.stock_vdb);
    stock = r.stock_vdb;
  }
  // The line log: every executed line's text, in execution order, one per line, so a test
  // can compare it with the program byte for byte. Written to FILE.tmp, renamed at the end.
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> line_log(nullptr, &std::fclose);
  if (!r.line_log.empty()) {
    line_log.reset(std::fopen((r.line_log + ".tmp").c_str(), "w"));
    if (!line_log) {
      std::fprintf(stderr, "hybridctl sim serve: error: --line-log %s: cannot write\n", r.line_log.c_str());
      return kBadInput;
    }
    options.on_line_executed = [f = line_log.get()](std::uint32_t, std::string_view text) {
      std::fwrite(text.data(), 1, text.size(), f);
      std::fputc('\n', f);
    };
  }
  sim::Controller controller(machine, options);

  sim::CanNodeOptions node;
  node.node = static_cast<std::uint8_t>(r.node);
  node.status_period = std::chrono::milliseconds(r.status_period_ms);
  node.reassembler.block_size = static_cast<std::uint8_t>(r.can_block_size);
  sim::ModbusServerOptions modbus_options;
  modbus_options.faults = faults;
  modbus_options.debug = r.modbus_debug;

  std::unique_ptr<sim::ModbusTcpServer> modbus_tcp;
  std::unique_ptr<sim::ModbusRtuServer> modbus_rtu;
  std::unique_ptr<sim::SocketcandServer> socketcand;
  std::unique_ptr<sim::SocketCanEndpoint> socketcan;
  sim::ServeLoopOptions loop_options;
  loop_options.exit_when_done = r.exit_when_done;
  loop_options.reboot_after_lines = faults.reboot_after_lines;
  loop_options.spin_while_executing = r.time_scale == 0;
  sim::ServeLoop loop(controller, loop_options);

  // SocketCAN first: on a kernel without it the command fails before anything listens.
  if (!r.socketcan.empty()) socketcan = std::make_unique<sim::SocketCanEndpoint>(controller, r.socketcan, node, faults);
  if (modbus_at) modbus_tcp = std::make_unique<sim::ModbusTcpServer>(controller, modbus_at->host, modbus_at->port, modbus_options);
  if (!r.modbus_rtu.empty()) {
    sim::ModbusRtuSettings rtu;
    rtu.device = r.modbus_rtu;
    rtu.baud = r.baud;
    rtu.parity = r.parity.empty() ? 'E' : r.parity[0];
    rtu.unit = r.unit;
    modbus_rtu = std::make_unique<sim::ModbusRtuServer>(controller, rtu, modbus_options);
  }
  if (socketcand_at) {
    sim::SocketcandOptions o;
    o.node = node;
    o.faults = faults;
    o.bitrate = r.can_bitrate;
    socketcand = std::make_unique<sim::SocketcandServer>(controller, socketcand_at->host, socketcand_at->port, o);
  }

  // Before "ready": a test may signal as soon as it reads that line.
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: poll() returns at once
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  std::signal(SIGPIPE, SIG_IGN);

  if (modbus_tcp) {
    loop.add(*modbus_tcp);
    print_line("listening modbus-tcp " + modbus_tcp->address() + ":" + std::to_string(modbus_tcp->port()));
  }
  if (modbus_rtu) {
    loop.add(*modbus_rtu);
    print_line("listening modbus-rtu " + r.modbus_rtu);
  }
  if (socketcand) {
    loop.add(*socketcand);
    print_line("listening socketcand " + socketcand->address() + ":" + std::to_string(socketcand->port()));
  }
  if (socketcan) {
    loop.add(*socketcan);
    print_line("listening socketcan " + r.socketcan);
  }
  print_line("ready");

  const sim::ServeExit exit = loop.run(g_stop);

  const sim::ControllerReport report = controller.report();
  if (line_log) {
    std::fflush(line_log.get());
    line_log.reset();
    fs::rename(r.line_log + ".tmp", r.line_log);
  }
  const protocol::Status status = controller.status();
  if (!r.as_built.empty()) {
    const geometry::Solid built = controller.as_built();
    if (fs::path(r.as_built).extension() == ".stl") {
      geometry::write_stl(geometry::surface_mesh(built), r.as_built);
    } else {
      geometry::write_vdb(built, r.as_built, "as_built");
    }
  }

  sim::FaultCounters injected;
  json by_transport = json::object();
  json transports = json::object();
  auto add_faults = [&](const char* name, const sim::FaultCounters& f) {
    injected.dropped += f.dropped;
    injected.delayed += f.delayed;
    injected.corrupted += f.corrupted;
    injected.busy += f.busy;
    by_transport[name] = faults_json(f);
  };
  if (modbus_tcp) {
    json t = counters_json(modbus_tcp->counters());
    t["address"] = modbus_tcp->address() + ":" + std::to_string(modbus_tcp->port());
    transports["modbus_tcp"] = t;
    add_faults("modbus_tcp", modbus_tcp->faults());
  }
  if (modbus_rtu) {
    json t = counters_json(modbus_rtu->counters());
    t["device"] = r.modbus_rtu;
    t["unit"] = r.unit;
    transports["modbus_rtu"] = t;
    add_faults("modbus_rtu", modbus_rtu->faults());
  }
  if (socketcand) {
    const sim::SocketcandCounters& c = socketcand->counters();
    transports["socketcand"] = {{"address", socketcand->address() + ":" + std::to_string(socketcand->port())},
                                {"connections", c.connections},
                                {"refused_connections", c.refused_connections},
                                {"disconnects", c.disconnects},
                                {"frames_from_hosts", c.frames_from_hosts},
                                {"frames_to_hosts", c.frames_to_hosts},
                                {"errors_sent", c.errors_sent},
                                {"garbage_disconnects", c.garbage_disconnects},
                                {"slow_disconnects", c.slow_disconnects},
                                {"node", counters_json(socketcand->node_counters())}};
    add_faults("socketcand", socketcand->faults());
  }
  if (socketcan) {
    const sim::SocketCanCounters& c = socketcan->counters();
    transports["socketcan"] = {{"interface", r.socketcan},
                               {"frames_read", c.frames_read},
                               {"frames_written", c.frames_written},
                               {"non_data_frames", c.non_data_frames},
                               {"write_errors", c.write_errors},
                               {"node", counters_json(socketcan->node_counters())}};
    add_faults("socketcan", socketcan->faults());
  }

  char identity[24];
  std::snprintf(identity, sizeof identity, "0x%016llX", static_cast<unsigned long long>(report.identity));
  json doc = {
      {"format", "hybridctl-sim-report"},
      {"version", 1},
      {"machine", machine.name},
      {"machine_file", r.machine},
      {"ended_by", exit == sim::ServeExit::Completed ? "completed" : "signal"},
      {"real_time_s", loop.real_seconds()},
      {"time_scale", r.time_scale},
      {"stock", stock},
      {"program", {{"identity", identity}, {"lines", report.program_lines}, {"completed", report.completed}}},
      {"chunks",
       {{"accepted", report.chunks_accepted},
        {"executed", report.chunks_executed},
        {"duplicates", report.duplicates},
        {"refused", report.refused}}},
      {"lines_executed", report.lines_executed},
      {"virtual_time_s", report.virtual_time_s},
      {"reboots", report.reboots},
      {"alarms", report.alarms},
      {"volumes_mm3",
       {{"removed", report.removed_mm3},
        {"deposited", report.deposited_mm3},
        {"gouge", report.gouge_mm3},
        {"as_built", report.as_built_mm3}}},
      {"final_status",
       {{"state", std::string(protocol::to_string(status.state))},
        {"alarm", std::string(protocol::to_string(status.alarm))},
        {"alarm_line", status.alarm_line},
        {"boot_count", status.boot_count},
        {"last_accepted_chunk", status.last_accepted_chunk},
        {"last_executed_chunk", status.last_executed_chunk},
        {"last_executed_line", status.last_executed_line}}},
      {"transports", transports},
      {"faults",
       {{"options",
         {{"drop_every", faults.drop_every},
          {"delay_ms", faults.delay_ms},
          {"corrupt_every", faults.corrupt_every},
          {"exception_every", faults.exception_every},
          {"reboot_after_lines", faults.reboot_after_lines},
          {"alarm_at_line", faults.alarm_at_line},
          {"seed", faults.seed ? json(*faults.seed) : json(nullptr)}}},
        {"injected",
         {{"dropped", injected.dropped},
          {"delayed", injected.delayed},
          {"corrupted", injected.corrupted},
          {"busy", injected.busy},
          {"reboots", loop.reboots_injected()},
          {"alarm_at_line_raised",
           faults.alarm_at_line != 0 && status.alarm == protocol::AlarmCode::EmergencyStop}}},
        {"by_transport", by_transport}}},
  };
  if (!r.report.empty()) write_text_atomically(r.report, doc.dump(2) + "\n");

  std::printf("stopped (%s): %u chunks accepted, %u executed, %u lines executed, %.3f s virtual time, state %s\n",
              exit == sim::ServeExit::Completed ? "program completed" : "signal", report.chunks_accepted,
              report.chunks_executed, report.lines_executed, report.virtual_time_s,
              std::string(protocol::to_string(status.state)).c_str());
  std::fflush(stdout);
  return kSuccess;
}

}  // namespace

void add_sim_command(CLI::App& app, Runner& runner) {
  auto r = std::make_shared<ServeRequest>();
  auto* sim = app.add_subcommand("sim", "The machine simulator");
  sim->require_subcommand(1);
  auto* serve_cmd = sim->add_subcommand(
      "serve",
      "Run the simulated machine controller on the wire: Modbus TCP/RTU and CAN (socketcand, SocketCAN) in front of "
      "a controller that executes the streamed G-code in virtual time (docs/simulator.md). Prints one "
      "'listening TRANSPORT ADDRESS' line per endpoint, then 'ready'; runs until SIGINT/SIGTERM (or, with "
      "--exit-when-done, until the program completed), then writes the run report and the as-built stock.");
  serve_cmd->add_option("--machine,-m", r->machine, "Machine description (YAML), see docs/machine-file.md")
      ->required()
      ->check(CLI::ExistingFile);
  serve_cmd->add_option("--modbus", r->modbus, "Modbus TCP endpoint tcp://HOST:PORT (port 0: a free port)")
      ->check(host_port_validator());
  serve_cmd->add_option("--modbus-rtu", r->modbus_rtu, "Modbus RTU on this serial device or pty");
  serve_cmd->add_option("--baud", r->baud, "RTU baud rate (a standard rate)")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](std::string& value) {
            for (int rate : config::kStandardBaudRates)
              if (value == std::to_string(rate)) return std::string();
            return "'" + value + "' is not a standard baud rate (300 .. 4000000, e.g. 9600, 19200, 115200)";
          },
          "RATE"));
  serve_cmd->add_option("--parity", r->parity, "RTU parity: N, E or O")->capture_default_str()->check(CLI::IsMember({"N", "E", "O"}));
  serve_cmd->add_option("--unit", r->unit, "RTU unit (slave) id; TCP answers any unit")
      ->capture_default_str()
      ->check(between(1, 247));
  serve_cmd->add_option("--socketcand", r->socketcand, "socketcand endpoint HOST:PORT (port 0: a free port)")
      ->check(host_port_validator());
  serve_cmd->add_option("--socketcan", r->socketcan, "Kernel CAN interface (e.g. vcan0)");
  serve_cmd->add_option("--node", r->node, "CAN node id of the controller")->capture_default_str()->check(between(1, 127));
  serve_cmd->add_option("--can-bitrate", r->can_bitrate,
                        "socketcand: pace frames as a CAN bus at this bit rate would (e.g. 1000000; 0: no pacing)")
      ->capture_default_str();
  serve_cmd->add_option("--can-block-size", r->can_block_size,
                        "CAN: consecutive frames the host may send per flow control (0: a whole chunk at once)")
      ->capture_default_str()
      ->check(between(0, 255));
  serve_cmd->add_option("--status-period-ms", r->status_period_ms, "CAN: a status snapshot at least this often")
      ->capture_default_str()
      ->check(between(1, 60000));
  serve_cmd->add_option("--time-scale", r->time_scale,
                        "Virtual seconds per real second (0: execute as fast as possible)")
      ->capture_default_str()
      ->check(between(0.0, 1e6));
  serve_cmd->add_option("--buffer-bytes", r->buffer_bytes, "Program buffer (payload bytes)")
      ->capture_default_str()
      ->check(between(256u, 16u << 20));
  serve_cmd->add_option("--heartbeat-timeout", r->heartbeat_timeout_s,
                        "Seconds RUNNING without a heartbeat change before the alarm (0: never)")
      ->capture_default_str()
      ->check(between(0.0, 65.0));
  auto* stock_plan = serve_cmd->add_option("--stock", r->stock_plan,
                                           "Stock from a plan (plan.json or its directory): the plan's raw stock; the "
                                           "design shrunk by the tolerance is protected");
  auto* stock_vdb = serve_cmd->add_option("--stock-vdb", r->stock_vdb, "Stock from a .vdb file")->check(CLI::ExistingFile);
  stock_plan->excludes(stock_vdb);
  serve_cmd->add_option("--plan", r->plan, "With --stock: which plan (rank) to take the stock from")->capture_default_str();
  serve_cmd->add_option("--report", r->report, "Write the run report (JSON) here at the end");
  serve_cmd->add_option("--line-log", r->line_log, "Write every executed program line here, in execution order");
  serve_cmd->add_option("--as-built", r->as_built, "Write the stock as built at the end (.vdb or .stl)");
  serve_cmd->add_flag("--exit-when-done", r->exit_when_done, "Exit once the program completed (after 0.5 s more)");
  serve_cmd->add_flag("--allow-remote", r->allow_remote, "Allow binding to addresses other than loopback");
  serve_cmd->add_flag("--modbus-debug", r->modbus_debug, "libmodbus's frame dump on stderr");
  auto* faults = "Fault injection";
  serve_cmd->add_option("--drop-every", r->faults.drop_every, "Close the client's connection at every N-th request")
      ->group(faults);
  serve_cmd->add_option("--delay-ms", r->faults.delay_ms, "Hold every reply back D ms")->group(faults);
  serve_cmd->add_option("--corrupt-every", r->faults.corrupt_every, "Damage every N-th reply")->group(faults);
  serve_cmd->add_option("--exception-every", r->faults.exception_every,
                        "Answer every N-th request 'busy' (Modbus exception 6; CAN: the N-th chunk transfer refused)")
      ->group(faults);
  serve_cmd->add_option("--reboot-after-lines", r->reboot_after_lines,
                        "Reboot the controller once it executed L lines (repeatable, or L1,L2,...)")
      ->group(faults);
  serve_cmd->add_option("--fault-seed", r->faults.seed,
                        "Random faults from this seed: each --*-every N strikes with probability 1/N, "
                        "--delay-ms D holds each reply a random 0..D ms")
      ->group(faults);
  serve_cmd->add_option("--alarm-at-line", r->faults.alarm_at_line, "EMERGENCY_STOP when program line L is about to run")
      ->group(faults);
  serve_cmd->callback([&runner, r] { runner = [r] { return serve(*r); }; });
}

}  // namespace hybridctl::cli
