#include "sim/wire/run_report.hpp"

#include <cstdio>
#include <fstream>

#include <nlohmann/json.hpp>

#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "protocol/codes.hpp"

namespace hybridctl::sim::wire {
namespace {

using nlohmann::json;

json counters_json(const ModbusCounters& c) {
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

json counters_json(const CanNodeCounters& c) {
  return {{"frames_in", c.frames_in},           {"frames_ignored", c.frames_ignored},
          {"frames_out", c.frames_out},         {"commands", c.commands},
          {"command_errors", c.command_errors}, {"heartbeats", c.heartbeats},
          {"heartbeat_errors", c.heartbeat_errors}, {"chunks", c.chunks},
          {"transfer_errors", c.transfer_errors}, {"refused_transfers", c.refused_transfers},
          {"status_snapshots", c.status_snapshots}};
}

json faults_json(const FaultCounters& f) {
  return {{"dropped", f.dropped}, {"delayed", f.delayed}, {"corrupted", f.corrupted}, {"busy", f.busy}};
}

json transports_json(const RunReport& r) {
  json transports = json::object();
  if (r.modbus_tcp) {
    json t = counters_json(r.modbus_tcp->counters);
    t["address"] = r.modbus_tcp->address;
    transports["modbus_tcp"] = t;
  }
  if (r.modbus_rtu) {
    json t = counters_json(r.modbus_rtu->counters);
    t["device"] = r.modbus_rtu->device;
    t["unit"] = r.modbus_rtu->unit;
    transports["modbus_rtu"] = t;
  }
  if (r.socketcand) {
    const SocketcandCounters& c = r.socketcand->counters;
    transports["socketcand"] = {{"address", r.socketcand->address},
                                {"connections", c.connections},
                                {"refused_connections", c.refused_connections},
                                {"disconnects", c.disconnects},
                                {"frames_from_hosts", c.frames_from_hosts},
                                {"frames_to_hosts", c.frames_to_hosts},
                                {"errors_sent", c.errors_sent},
                                {"garbage_disconnects", c.garbage_disconnects},
                                {"slow_disconnects", c.slow_disconnects},
                                {"node", counters_json(r.socketcand->node)}};
  }
  if (r.socketcan) {
    const SocketCanCounters& c = r.socketcan->counters;
    transports["socketcan"] = {{"interface", r.socketcan->interface_name},
                               {"frames_read", c.frames_read},
                               {"frames_written", c.frames_written},
                               {"non_data_frames", c.non_data_frames},
                               {"write_errors", c.write_errors},
                               {"node", counters_json(r.socketcan->node)}};
  }
  return transports;
}

json faults_section_json(const RunReport& r) {
  const FaultOptions& faults = r.faults;
  FaultCounters injected;
  json by_transport = json::object();
  auto add = [&](const char* name, const FaultCounters& f) {
    injected.dropped += f.dropped;
    injected.delayed += f.delayed;
    injected.corrupted += f.corrupted;
    injected.busy += f.busy;
    by_transport[name] = faults_json(f);
  };
  if (r.modbus_tcp) add("modbus_tcp", r.modbus_tcp->faults);
  if (r.modbus_rtu) add("modbus_rtu", r.modbus_rtu->faults);
  if (r.socketcand) add("socketcand", r.socketcand->faults);
  if (r.socketcan) add("socketcan", r.socketcan->faults);
  return {{"options",
           {{"drop_every", faults.drop_every},
            {"delay_ms", faults.delay_ms},
            {"corrupt_every", faults.corrupt_every},
            {"exception_every", faults.exception_every},
            {"reboot_after_lines", faults.reboot_after_lines},
            {"alarm_at_line", faults.alarm_at_line},
            {"hold_at_line", faults.hold_at_line},
            {"seed", faults.seed ? json(*faults.seed) : json(nullptr)}}},
          {"injected",
           {{"dropped", injected.dropped},
            {"delayed", injected.delayed},
            {"corrupted", injected.corrupted},
            {"busy", injected.busy},
            {"reboots", r.reboots_injected},
            {"alarm_at_line_raised",
             faults.alarm_at_line != 0 && r.final_status.alarm == protocol::AlarmCode::EmergencyStop}}},
          {"by_transport", by_transport}};
}

}  // namespace

std::string run_report_json(const RunReport& r) {
  const ControllerReport& c = r.controller;
  const protocol::Status& status = r.final_status;
  char identity[24];
  std::snprintf(identity, sizeof identity, "0x%016llX", static_cast<unsigned long long>(c.identity));
  const json doc = {
      {"format", "hybridctl-sim-report"},
      {"version", 1},
      {"machine", r.machine},
      {"machine_file", r.machine_file},
      {"ended_by", r.completed ? "completed" : "signal"},
      {"real_time_s", r.real_time_s},
      {"time_scale", r.time_scale},
      {"stock", r.stock},
      {"program", {{"identity", identity}, {"lines", c.program_lines}, {"completed", c.completed}}},
      {"chunks",
       {{"accepted", c.chunks_accepted}, {"executed", c.chunks_executed}, {"duplicates", c.duplicates}, {"refused", c.refused}}},
      {"lines_executed", c.lines_executed},
      {"virtual_time_s", c.virtual_time_s},
      {"reboots", c.reboots},
      {"alarms", c.alarms},
      {"volumes_mm3",
       {{"removed", c.removed_mm3}, {"deposited", c.deposited_mm3}, {"gouge", c.gouge_mm3}, {"as_built", c.as_built_mm3}}},
      {"final_status",
       {{"state", std::string(protocol::to_string(status.state))},
        {"alarm", std::string(protocol::to_string(status.alarm))},
        {"alarm_line", status.alarm_line},
        {"boot_count", status.boot_count},
        {"last_accepted_chunk", status.last_accepted_chunk},
        {"last_executed_chunk", status.last_executed_chunk},
        {"last_executed_line", status.last_executed_line}}},
      {"transports", transports_json(r)},
      {"faults", faults_section_json(r)},
  };
  return doc.dump(2) + "\n";
}

void write_run_report(const RunReport& report, const std::filesystem::path& path) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temp_path(), std::ios::binary);
    out << run_report_json(report);
    out.flush();
    if (!out) throw InputError(path.string() + ": cannot write");
  }
  file.commit();
}

}  // namespace hybridctl::sim::wire
