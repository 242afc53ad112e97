// docs/protocol.md cannot drift from the code: the alarm and result tables in it are the
// ones the code renders, and its register tables name the offsets the code uses.

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "protocol/codes.hpp"
#include "protocol/messages.hpp"
#include "protocol/modbus_map.hpp"

namespace {

using namespace hybridctl::protocol;

std::string read_doc() {
  std::ifstream in(std::string(HYBRIDCTL_SOURCE_DIR) + "/docs/protocol.md");
  EXPECT_TRUE(in) << "docs/protocol.md is missing";
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The text between <!-- NAME --> and <!-- /NAME -->, without the newline after the opening
/// marker; fails the test if the markers are missing or repeated.
std::string between_markers(const std::string& doc, const std::string& name) {
  const std::string open = "<!-- " + name + " -->\n";
  const std::string close = "<!-- /" + name + " -->";
  const auto a = doc.find(open);
  EXPECT_NE(a, std::string::npos) << open;
  if (a == std::string::npos) return {};
  EXPECT_EQ(doc.find(open, a + 1), std::string::npos) << "marker twice: " << open;
  const auto b = doc.find(close, a);
  EXPECT_NE(b, std::string::npos) << close;
  if (b == std::string::npos) return {};
  return doc.substr(a + open.size(), b - a - open.size());
}

TEST(ProtocolDoc, AlarmTableIsTheOneInCode) {
  EXPECT_EQ(between_markers(read_doc(), "alarm-table"), alarm_table_markdown())
      << "paste alarm_table_markdown() into docs/protocol.md";
}

TEST(ProtocolDoc, ResultTableIsTheOneInCode) {
  EXPECT_EQ(between_markers(read_doc(), "result-table"), result_table_markdown())
      << "paste result_table_markdown() into docs/protocol.md";
}

TEST(ProtocolDoc, TablesHaveOneRowPerCodeWithUniqueNames) {
  std::map<std::string, int> names;
  for (std::uint16_t c = 0; c < kAlarmCodeCount; ++c) {
    EXPECT_EQ(static_cast<std::uint16_t>(alarm_info(static_cast<AlarmCode>(c)).code), c);
    ++names[std::string(to_string(static_cast<AlarmCode>(c)))];
  }
  for (std::uint16_t c = 0; c < kResultCodeCount; ++c) {
    EXPECT_EQ(static_cast<std::uint16_t>(result_info(static_cast<ResultCode>(c)).code), c);
    ++names["result " + std::string(to_string(static_cast<ResultCode>(c)))];
  }
  for (const auto& [name, count] : names) EXPECT_EQ(count, 1) << name;
  EXPECT_FALSE(alarm_code_from_wire(kAlarmCodeCount));
  EXPECT_FALSE(result_code_from_wire(kResultCodeCount));
}

struct Row {
  std::size_t first = 0;
  std::size_t last = 0;
  std::string name;
  std::string type;
};

/// Rows "| A | `name` | type | ... |" or "| A-B | ..." of a Markdown table.
std::vector<Row> rows(const std::string& table) {
  std::vector<Row> out;
  std::istringstream in(table);
  std::string line;
  while (std::getline(in, line)) {
    if (line.size() < 2 || line[0] != '|') continue;
    std::vector<std::string> cells;
    std::string cell;
    for (std::size_t i = 1; i < line.size(); ++i) {
      if (line[i] == '|') {
        const auto s = cell.find_first_not_of(' ');
        const auto e = cell.find_last_not_of(' ');
        cells.push_back(s == std::string::npos ? "" : cell.substr(s, e - s + 1));
        cell.clear();
      } else {
        cell += line[i];
      }
    }
    if (cells.size() < 3 || cells[0].empty() || !std::isdigit(static_cast<unsigned char>(cells[0][0]))) continue;
    Row r;
    const auto dash = cells[0].find('-');
    r.first = std::stoul(cells[0].substr(0, dash));
    r.last = dash == std::string::npos ? r.first : std::stoul(cells[0].substr(dash + 1));
    r.name = cells[1];
    std::erase(r.name, '`');
    r.type = cells[2];
    out.push_back(r);
  }
  return out;
}

TEST(ProtocolDoc, StatusLayoutNamesTheOffsetsTheCodeUses) {
  namespace r = status_reg;
  const std::map<std::string, std::size_t> offsets = {
      {"protocol_version", r::kProtocolVersion}, {"state", r::kState},
      {"alarm", r::kAlarm},                      {"chunk_result", r::kChunkResult},
      {"command_result", r::kCommandResult},     {"command_seq", r::kCommandSeq},
      {"command_code", r::kCommandCode},         {"heartbeat_echo", r::kHeartbeatEcho},
      {"boot_count", r::kBootCount},             {"heartbeat_timeout_ms", r::kHeartbeatTimeoutMs},
      {"alarm_line", r::kAlarmLine},             {"last_written_chunk", r::kLastWrittenChunk},
      {"last_accepted_chunk", r::kLastAcceptedChunk}, {"last_executed_chunk", r::kLastExecutedChunk},
      {"last_executed_line", r::kLastExecutedLine},   {"next_line", r::kNextLine},
      {"program_line_count", r::kProgramLineCount},   {"identity", r::kIdentity},
      {"free_buffer_bytes", r::kFreeBufferBytes},     {"max_chunk_payload", r::kMaxChunkPayload},
      {"active_tool", r::kActiveTool},           {"x_um", r::kX},
      {"y_um", r::kY},                           {"z_um", r::kZ},
      {"spindle_rpm", r::kSpindleRpm},           {"feed_override_percent", r::kFeedOverride},
      {"flags", r::kFlags},                      {"duplicate_chunks", r::kDuplicateChunks},
      {"refused_chunks", r::kRefusedChunks},
  };
  const std::map<std::string, std::size_t> widths = {{"u16", 1}, {"u32", 2}, {"i32", 2}, {"u64", 4}};
  const auto table = rows(between_markers(read_doc(), "status-layout"));
  ASSERT_EQ(table.size(), offsets.size());
  std::size_t next = 0;
  for (const Row& row : table) {
    ASSERT_TRUE(offsets.count(row.name)) << "unknown field " << row.name;
    EXPECT_EQ(row.first, offsets.at(row.name)) << row.name;
    ASSERT_TRUE(widths.count(row.type)) << row.name << ": type " << row.type;
    EXPECT_EQ(row.last - row.first + 1, widths.at(row.type)) << row.name;
    EXPECT_EQ(row.first, next) << row.name << ": the table is in register order without holes";
    next = row.last + 1;
  }
  EXPECT_EQ(next, kStatusRegisters);
}

TEST(ProtocolDoc, HoldingRegisterMapIsTheOneInCode) {
  using namespace hybridctl::protocol::modbus;
  const auto table = rows(between_markers(read_doc(), "holding-map"));
  const std::vector<std::pair<std::size_t, std::size_t>> expected = {
      {kHeartbeatAddress, kHeartbeatAddress},
      {1, kCommandAddress - 1},
      {kCommandAddress, kCommandAddress + kCommandCount - 1},
      {kMailboxAddress, kMailboxAddress + kMailboxRegisters - 1},
      {kStatusMirrorAddress, kStatusMirrorAddress + kStatusCount - 1},
  };
  ASSERT_EQ(table.size(), expected.size());
  for (std::size_t i = 0; i < table.size(); ++i) {
    EXPECT_EQ(table[i].first, expected[i].first) << table[i].name;
    EXPECT_EQ(table[i].last, expected[i].second) << table[i].name;
  }
}

TEST(ProtocolDoc, CommandBlockAndMailboxHeaderLayoutsAreTheOnesInCode) {
  const auto command = rows(between_markers(read_doc(), "command-layout"));
  const std::map<std::string, std::pair<std::size_t, std::size_t>> command_expected = {
      {"code", {command_reg::kCode, command_reg::kCode}},
      {"seq", {command_reg::kSeq, command_reg::kSeq}},
      {"identity", {command_reg::kIdentity, command_reg::kIdentity + 3}},
      {"line_count", {command_reg::kLineCount, command_reg::kLineCount + 1}},
  };
  ASSERT_EQ(command.size(), command_expected.size());
  for (const Row& row : command) {
    ASSERT_TRUE(command_expected.count(row.name)) << row.name;
    EXPECT_EQ(row.first, command_expected.at(row.name).first) << row.name;
    EXPECT_EQ(row.last, command_expected.at(row.name).second) << row.name;
  }
  const auto mailbox = rows(between_markers(read_doc(), "mailbox-layout"));
  const std::vector<std::tuple<std::string, std::size_t, std::size_t>> mailbox_expected = {
      {"seq", 0, 1},         {"identity_tag", 2, 3},   {"first_line", 4, 5},
      {"line_count", 6, 6},  {"payload_length", 7, 7}, {"crc32", 8, 9},
      {"payload", 10, hybridctl::protocol::modbus::kMailboxRegisters - 1},
  };
  ASSERT_EQ(mailbox.size(), mailbox_expected.size());
  for (std::size_t i = 0; i < mailbox.size(); ++i) {
    EXPECT_EQ(mailbox[i].name, std::get<0>(mailbox_expected[i]));
    EXPECT_EQ(mailbox[i].first, std::get<1>(mailbox_expected[i])) << mailbox[i].name;
    EXPECT_EQ(mailbox[i].last, std::get<2>(mailbox_expected[i])) << mailbox[i].name;
  }
}

}  // namespace
