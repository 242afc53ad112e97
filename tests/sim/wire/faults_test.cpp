// Fault injection of `hybridctl sim serve` and its run report: each fault shows up on the
// wire as a client sees it, and is counted in the report written at the end.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "protocol/modbus_map.hpp"
#include "geometry/vdb_file.hpp"
#include "sim_process.hpp"
#include "wire_client.hpp"

namespace hybridctl::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using protocol::AlarmCode;
using protocol::CommandCode;
using protocol::ControllerState;
using protocol::ResultCode;

fs::path temp_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("hybridctl-sim-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

json read_json(const fs::path& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  return json::parse(in, nullptr, false);
}

// Streams a program over Modbus the simplest correct way: SET_PROGRAM, every chunk, START.
class Host {
 public:
  Host(ModbusClient& client, std::vector<std::string> lines) : client_(client), lines_(std::move(lines)) {}

  ResultCode command(CommandCode code) {
    protocol::Command c;
    c.code = code;
    c.seq = ++seq_;
    if (code == CommandCode::SetProgram) {
      c.identity = protocol::program_identity(lines_);
      c.line_count = static_cast<std::uint32_t>(lines_.size());
    }
    if (!client_.write_command(c)) return ResultCode::None;
    const auto s = client_.status();
    return s ? s->command_result : ResultCode::None;
  }

  // Every chunk; false on a wire error or a refused chunk.
  bool send_program() {
    std::uint32_t line = 1, seq = 1;
    while (line <= lines_.size()) {
      protocol::Chunk chunk;
      const auto regs = mailbox_of(lines_, line, seq, &chunk);
      const auto s = client_.write_mailbox(regs);
      if (!s || s->chunk_result != ResultCode::Accepted) return false;
      line += chunk.line_count;
      ++seq;
    }
    return true;
  }

  // Polls the status (bumping the heartbeat) until `done` holds or `timeout` passes.
  template <class Done>
  std::optional<protocol::Status> wait(Done done, std::chrono::milliseconds timeout = 10s) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      client_.heartbeat(++heartbeat_);
      const auto s = client_.status();
      if (s && done(*s)) return s;
      std::this_thread::sleep_for(10ms);
    }
    return std::nullopt;
  }

  std::size_t lines() const { return lines_.size(); }

 private:
  ModbusClient& client_;
  std::vector<std::string> lines_;
  std::uint16_t seq_ = 0;
  std::uint16_t heartbeat_ = 0;
};

std::vector<std::string> serve_args(std::vector<std::string> extra) {
  std::vector<std::string> args = {"--machine", example_machine(), "--modbus", "tcp://127.0.0.1:0", "--time-scale", "0"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

TEST(SimServe, ExitsWhenTheProgramIsDoneAndReportsTheRun) {
  const fs::path dir = temp_dir("report");
  SimProcess sim(serve_args({"--exit-when-done", "--report", (dir / "run.json").string()}));
  ModbusClient client(sim.modbus_port());
  ASSERT_TRUE(client.connected());
  Host host(client, test_program(60));
  ASSERT_EQ(host.command(CommandCode::SetProgram), ResultCode::Accepted);
  ASSERT_TRUE(host.send_program()) << client.last_error();
  ASSERT_EQ(host.command(CommandCode::Start), ResultCode::Accepted);
  const auto done = host.wait([](const protocol::Status& s) { return s.state == ControllerState::Completed; });
  ASSERT_TRUE(done.has_value()) << sim.errors();
  EXPECT_EQ(done->last_executed_line, host.lines());
  EXPECT_NE(done->heartbeat_echo, 0) << "the FC6 heartbeat writes reach the controller";

  ASSERT_EQ(sim.wait(10s), 0) << "exit when done: " << sim.errors();
  EXPECT_NE(sim.output().find("stopped (program completed)"), std::string::npos) << sim.output();
  const json report = read_json(dir / "run.json");
  ASSERT_FALSE(report.is_discarded());
  EXPECT_EQ(report["format"], "hybridctl-sim-report");
  EXPECT_EQ(report["ended_by"], "completed");
  EXPECT_EQ(report["lines_executed"], host.lines());
  EXPECT_EQ(report["program"]["lines"], host.lines());
  EXPECT_EQ(report["program"]["completed"], true);
  EXPECT_GE(report["chunks"]["accepted"].get<int>(), 2);
  EXPECT_EQ(report["chunks"]["accepted"], report["chunks"]["executed"]);
  EXPECT_EQ(report["chunks"]["duplicates"], 0);
  EXPECT_EQ(report["chunks"]["refused"], 0);
  EXPECT_GT(report["virtual_time_s"].get<double>(), 0.0);
  EXPECT_EQ(report["final_status"]["state"], "COMPLETED");
  EXPECT_EQ(report["transports"]["modbus_tcp"]["mailbox_writes"], report["chunks"]["accepted"]);
  EXPECT_EQ(report["faults"]["injected"]["dropped"], 0);
  fs::remove_all(dir);
}

TEST(SimServe, DropEveryClosesTheConnectionAtEveryNthRequest) {
  const fs::path dir = temp_dir("drop");
  SimProcess sim(serve_args({"--drop-every", "3", "--report", (dir / "run.json").string()}));
  {
    ModbusClient client(sim.modbus_port());
    EXPECT_TRUE(client.status().has_value());
    EXPECT_TRUE(client.status().has_value());
    EXPECT_FALSE(client.status().has_value()) << "request 3 is dropped";
    EXPECT_FALSE(client.status().has_value()) << "and the connection with it";
  }
  ModbusClient again(sim.modbus_port());
  ASSERT_TRUE(again.connected()) << "a dropped client reconnects";
  EXPECT_TRUE(again.status().has_value());
  ASSERT_EQ(sim.stop(), 0);
  const json report = read_json(dir / "run.json");
  EXPECT_EQ(report["faults"]["injected"]["dropped"], 1);
  EXPECT_EQ(report["faults"]["by_transport"]["modbus_tcp"]["dropped"], 1);
  fs::remove_all(dir);
}

TEST(SimServe, ExceptionEveryAnswersBusyWithoutProcessing) {
  const fs::path dir = temp_dir("busy");
  SimProcess sim(serve_args({"--exception-every", "2", "--report", (dir / "run.json").string()}));
  ModbusClient client(sim.modbus_port());
  ASSERT_TRUE(client.status().has_value());  // request 1
  protocol::Command c;
  c.code = CommandCode::SetProgram;
  c.seq = 1;
  c.identity = 99;
  c.line_count = 5;
  EXPECT_FALSE(client.write_command(c)) << "request 2 is answered busy";
  EXPECT_EQ(client.last_errno(), EMBXSBUSY);
  const auto s = client.status();  // request 3
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->command_seq, 0) << "a busy answer means the write was not applied";
  ASSERT_EQ(sim.stop(), 0);
  const json report = read_json(dir / "run.json");
  EXPECT_EQ(report["faults"]["injected"]["busy"], 1);
  EXPECT_EQ(report["transports"]["modbus_tcp"]["exceptions"]["6"], 1);
  fs::remove_all(dir);
}

TEST(SimServe, CorruptEveryDamagesTheNthReply) {
  const fs::path dir = temp_dir("corrupt");
  SimProcess sim(serve_args({"--corrupt-every", "2", "--report", (dir / "run.json").string()}));
  {
    ModbusClient client(sim.modbus_port());
    EXPECT_TRUE(client.status().has_value());
    EXPECT_FALSE(client.status().has_value()) << "reply 2 is damaged";
    EXPECT_EQ(client.last_errno(), EMBBADDATA) << client.last_error();
  }
  ModbusClient next(sim.modbus_port());
  EXPECT_TRUE(next.status().has_value()) << "reply 3 is whole";
  ASSERT_EQ(sim.stop(), 0);
  EXPECT_EQ(read_json(dir / "run.json")["faults"]["injected"]["corrupted"], 1);
  fs::remove_all(dir);
}

TEST(SimServe, DelayedRepliesDoNotHoldUpOtherClients) {
  SimProcess sim(serve_args({"--delay-ms", "300"}));
  ModbusClient a(sim.modbus_port(), 2s), b(sim.modbus_port(), 2s);
  ASSERT_TRUE(a.connected() && b.connected());
  const auto start = std::chrono::steady_clock::now();
  bool a_ok = false, b_ok = false;
  std::thread ta([&] { a_ok = a.status().has_value(); });
  std::thread tb([&] { b_ok = b.status().has_value(); });
  ta.join();
  tb.join();
  const auto elapsed = std::chrono::steady_clock::now() - start;
  EXPECT_TRUE(a_ok && b_ok);
  EXPECT_GE(elapsed, 290ms) << "each reply is held back 300 ms";
  EXPECT_LT(elapsed, 550ms) << "two clients waited one after the other: the delay blocked the server";
  EXPECT_EQ(sim.stop(), 0);
}

TEST(SimServe, RebootAfterLinesRestartsTheControllerMidProgram) {
  const fs::path dir = temp_dir("reboot");
  SimProcess sim(serve_args({"--reboot-after-lines", "8", "--report", (dir / "run.json").string()}));
  ModbusClient client(sim.modbus_port());
  Host host(client, test_program(40));
  ASSERT_EQ(host.command(CommandCode::SetProgram), ResultCode::Accepted);
  ASSERT_TRUE(host.send_program());
  // At time scale 0 the reboot may come before the START's result is read back (and a
  // reboot forgets the last command): only the reboot is waited for.
  host.command(CommandCode::Start);
  const auto s = host.wait([](const protocol::Status& st) { return st.boot_count == 2; });
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->state, ControllerState::Alarm);
  EXPECT_EQ(s->alarm, AlarmCode::ControllerRestarted);
  EXPECT_GE(s->last_executed_line, 8u);
  EXPECT_EQ(s->last_accepted_chunk, s->last_executed_chunk) << "the queue was lost; the host resends from here";
  ASSERT_EQ(sim.stop(), 0);
  const json report = read_json(dir / "run.json");
  EXPECT_EQ(report["faults"]["injected"]["reboots"], 1);
  EXPECT_EQ(report["reboots"], 1);
  fs::remove_all(dir);
}

TEST(SimServe, AlarmAtLineStopsTheMachineThere) {
  const fs::path dir = temp_dir("alarm");
  SimProcess sim(serve_args({"--alarm-at-line", "7", "--report", (dir / "run.json").string()}));
  ModbusClient client(sim.modbus_port());
  Host host(client, test_program(20));
  ASSERT_EQ(host.command(CommandCode::SetProgram), ResultCode::Accepted);
  ASSERT_TRUE(host.send_program());
  ASSERT_EQ(host.command(CommandCode::Start), ResultCode::Accepted);
  const auto s = host.wait([](const protocol::Status& st) { return st.state == ControllerState::Alarm; });
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->alarm, AlarmCode::EmergencyStop);
  EXPECT_EQ(s->last_executed_line, 6u);
  ASSERT_EQ(sim.stop(), 0);
  const json report = read_json(dir / "run.json");
  EXPECT_EQ(report["faults"]["injected"]["alarm_at_line_raised"], true);
  ASSERT_FALSE(report["alarms"].empty());
  EXPECT_NE(report["alarms"][0].get<std::string>().find("EMERGENCY_STOP"), std::string::npos) << report["alarms"];
  fs::remove_all(dir);
}

TEST(SimServe, WritesTheAsBuiltStockOfAVdbStock) {
  const fs::path dir = temp_dir("as-built");
  // A 20 x 20 x 10 mm block on a 0.5 mm lattice, far below the moves of the program.
  const geometry::Lattice lattice{0.5, {0, 0, -200}};
  const geometry::Solid block = geometry::Solid::filled(lattice, geometry::IndexBox{{0, 0, 0}, {40, 40, 20}});
  geometry::write_vdb(block, dir / "stock.vdb");
  SimProcess sim(serve_args({"--exit-when-done", "--stock-vdb", (dir / "stock.vdb").string(), "--as-built",
                             (dir / "built.vdb").string(), "--report", (dir / "run.json").string()}));
  ModbusClient client(sim.modbus_port());
  Host host(client, test_program(10));
  ASSERT_EQ(host.command(CommandCode::SetProgram), ResultCode::Accepted);
  ASSERT_TRUE(host.send_program());
  ASSERT_EQ(host.command(CommandCode::Start), ResultCode::Accepted);
  ASSERT_TRUE(host.wait([](const protocol::Status& s) { return s.state == ControllerState::Completed; }).has_value());
  ASSERT_EQ(sim.wait(10s), 0) << sim.errors();
  const geometry::Solid built = geometry::read_vdb(dir / "built.vdb");
  EXPECT_NEAR(built.volume(), block.volume(), 1e-6) << "nothing was cut";
  const json report = read_json(dir / "run.json");
  EXPECT_NEAR(report["volumes_mm3"]["as_built"].get<double>(), block.volume(), 1e-6);
  EXPECT_EQ(report["stock"], (dir / "stock.vdb").string());
  fs::remove_all(dir);
}

TEST(SimServe, ABeadOverAirIsAWarningOnTheWireAndTheProgramGoesOn) {
  const fs::path dir = temp_dir("over-air");
  // A plate, a pillar 8 mm high at x [0, 10], and a post at the far corner so the simulated
  // world reaches above the pillar; the DED head (T100) lays a track on the pillar's top
  // from x 2 and on past its edge into the air to x 20 (line 7).
  const geometry::Lattice lattice{0.5, {0, 0, 0}};
  geometry::Solid stock = geometry::Solid::filled(lattice, geometry::IndexBox{{0, 0, 0}, {80, 40, 4}});
  stock = geometry::unite(stock, geometry::Solid::filled(lattice, geometry::IndexBox{{0, 0, 4}, {20, 40, 20}}));
  stock = geometry::unite(stock, geometry::Solid::filled(lattice, geometry::IndexBox{{76, 36, 4}, {80, 40, 40}}));
  geometry::write_vdb(stock, dir / "stock.vdb");
  SimProcess sim(serve_args({"--exit-when-done", "--stock-vdb", (dir / "stock.vdb").string(), "--as-built",
                             (dir / "built.vdb").string(), "--report", (dir / "run.json").string()}));
  ModbusClient client(sim.modbus_port());
  Host host(client, {"G21 G90", "G54", "T100 M6", "G0 X2 Y10 Z30", "G1 Z10 F800", "M64 P0", "G1 X20 F800", "M65 P0",
                     "G1 Z30 F800", "M2"});
  ASSERT_EQ(host.command(CommandCode::SetProgram), ResultCode::Accepted);
  ASSERT_TRUE(host.send_program());
  ASSERT_EQ(host.command(CommandCode::Start), ResultCode::Accepted);
  const auto s = host.wait([](const protocol::Status& st) { return st.state == ControllerState::Completed; });
  ASSERT_TRUE(s.has_value()) << "the program runs to its end";
  EXPECT_EQ(s->alarm, AlarmCode::DepositionOverAir);
  EXPECT_EQ(s->alarm_line, 7u);
  ASSERT_EQ(sim.wait(10s), 0) << sim.errors();
  const json report = read_json(dir / "run.json");
  ASSERT_EQ(report["alarms"].size(), 1u) << report["alarms"];
  EXPECT_EQ(report["alarms"][0].get<std::string>().rfind("line 7: DEPOSITION_OVER_AIR (warning): line 7: unsupported deposition", 0), 0u)
      << report["alarms"];
  // What lies over air beyond the pillar's edge (and the cone's reach) was not added.
  const geometry::Solid added = geometry::subtract(geometry::read_vdb(dir / "built.vdb"), stock);
  EXPECT_GT(added.volume(), 0);
  EXPECT_LE(added.bounding_box_mm().max.x, 11.0);
  fs::remove_all(dir);
}

TEST(SimServe, TakesTheStockFromAPlan) {
  const fs::path dir = temp_dir("plan-stock");
  // --no-validate: the subject is the stock `sim serve --stock` takes from a plan's first
  // action, not whether the plan makes the part. The flanged hub's plans that pass
  // execution all start from a raw stock; unvalidated, one of its first plans at 1 mm
  // deposits from nothing (the 7th, by money).
  const PeerResult plan = run_peer({HYBRIDCTL_EXE, "plan", std::string(HYBRIDCTL_SOURCE_DIR) + "/examples/parts/flanged-hub.stl",
                                    "--machine", example_machine(), "--voxel", "1", "--top", "8", "--no-validate", "-o",
                                    (dir / "plan").string()});
  ASSERT_EQ(plan.exit_code, 0) << plan.output;
  // The ranks of a plan that starts from a raw stock and of one that starts by depositing.
  const json plans = read_json(dir / "plan" / "plan.json");
  std::map<std::string, std::string> kind;
  for (const json& p : plans["primitives"]) kind[p["name"]] = p["kind"];
  int from_stock = 0, from_nothing = 0;
  for (const json& p : plans["plans"]) {
    const bool raw = kind[p["actions"][0]["primitive"]] == "raw-stock";
    int& rank = raw ? from_stock : from_nothing;
    if (rank == 0) rank = p["rank"];
  }
  ASSERT_GT(from_stock, 0) << "the flanged hub's plans should include one from a raw stock";
  ASSERT_GT(from_nothing, 0) << "the flanged hub's plans should include one that starts by depositing";
  const geometry::Solid design = geometry::read_vdb(dir / "plan" / "design.vdb");

  auto serve_plan = [&](int rank, json& report, geometry::Solid& built) {
    SimProcess sim(serve_args({"--stock", (dir / "plan" / "plan.json").string(), "--plan", std::to_string(rank),
                               "--as-built", (dir / "built.vdb").string(), "--report", (dir / "run.json").string()}));
    ASSERT_EQ(sim.stop(), 0) << sim.errors();
    report = read_json(dir / "run.json");
    built = geometry::read_vdb(dir / "built.vdb");
  };
  json report;
  geometry::Solid built;
  serve_plan(from_stock, report, built);
  EXPECT_EQ(report["stock"].get<std::string>().rfind("raw stock ", 0), 0u) << report["stock"];
  EXPECT_GT(built.volume(), design.volume()) << "the raw stock holds the part";
  EXPECT_NEAR(report["volumes_mm3"]["as_built"].get<double>(), built.volume(), 1e-6);
  serve_plan(from_nothing, report, built);
  EXPECT_EQ(report["stock"].get<std::string>().rfind("empty", 0), 0u) << report["stock"];
  EXPECT_EQ(built.volume(), 0.0) << "a plan that starts by depositing starts from nothing";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace hybridctl::test
