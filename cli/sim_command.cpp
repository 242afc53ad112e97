// hybridctl sim serve: the simulated machine controller on the wire (docs/simulator.md).

#include <cstdio>
#include <memory>
#include <string>

#include "cli/commands.hpp"
#include "cli/memory_budget.hpp"
#include "cli/ranges.hpp"
#include "config/transport_uri.hpp"
#include "protocol/codes.hpp"
#include "sim/wire/serve.hpp"

namespace hybridctl::cli {
namespace {

CLI::Validator listen_address_validator() {
  return CLI::Validator(
      [](std::string& value) {
        const config::HostPortResult parsed = config::parse_listen_address(value);
        return parsed.host_port ? std::string() : parsed.error;
      },
      std::string(config::kListenAddressForm));
}

void print_line(const std::string& line) {
  std::fputs((line + "\n").c_str(), stdout);
  std::fflush(stdout);
}

int run_serve(const sim::wire::ServeOptions& options) {
  sim::wire::ServeOutcome end;
  try {
    end = sim::wire::serve(options, print_line);
  } catch (const sim::wire::ServeRefused& e) {
    std::fprintf(stderr, "hybridctl sim serve: error: %s\n", e.what());
    return e.reason() == sim::wire::ServeRefused::Reason::Usage ? kUsage : kBadInput;
  }
  const sim::ControllerReport& report = end.controller;
  std::printf("stopped (%s): %u chunks accepted, %u executed, %u lines executed, %.3f s virtual time, state %s\n",
              end.completed ? "program completed" : "signal", report.chunks_accepted, report.chunks_executed,
              report.lines_executed, report.virtual_time_s, std::string(protocol::to_string(end.final_status.state)).c_str());
  std::fflush(stdout);
  return kSuccess;
}

}  // namespace

void add_sim_command(CLI::App& app, Runner& runner) {
  auto r = std::make_shared<sim::wire::ServeOptions>();
  auto memory_budget_text = std::make_shared<std::string>();
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
      ->check(listen_address_validator());
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
      ->check(listen_address_validator());
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
                                           "design shrunk by the planning band is protected");
  auto* stock_vdb = serve_cmd->add_option("--stock-vdb", r->stock_vdb, "Stock from a .vdb file")->check(CLI::ExistingFile);
  stock_plan->excludes(stock_vdb);
  add_memory_budget_option(serve_cmd, *memory_budget_text);
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
  serve_cmd->add_option("--hold-at-line", r->faults.hold_at_line,
                        "Feed hold at the machine when program line L is about to run (RESUME goes on)")
      ->group(faults);
  serve_cmd->callback([&runner, r, memory_budget_text] {
    runner = [r, memory_budget_text] {
      r->memory_budget = memory_budget(*memory_budget_text);
      return run_serve(*r);
    };
  });
}

}  // namespace hybridctl::cli
