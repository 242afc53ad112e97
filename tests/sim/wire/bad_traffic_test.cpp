// Bad traffic at the Modbus server: garbage, broken MBAP headers, stalls, addresses off the
// map, malformed and oversize chunks. Every case runs while a second, well-behaved client
// keeps asking for the status, and must keep getting it.

#include <gtest/gtest.h>

#include <chrono>
#include <random>

#include "protocol/modbus_map.hpp"
#include "sim_process.hpp"
#include "wire_client.hpp"

namespace hybridctl::test {
namespace {

namespace mb = protocol::modbus;
using protocol::ResultCode;

class BadTraffic : public ::testing::Test {
 protected:
  void SetUp() override {
    sim_ = std::make_unique<SimProcess>(
        std::vector<std::string>{"--machine", example_machine(), "--modbus", "tcp://127.0.0.1:0", "--time-scale", "0"});
    port_ = sim_->modbus_port();
    good_ = std::make_unique<ModbusClient>(port_);
    ASSERT_TRUE(good_->connected()) << good_->last_error();
    ASSERT_TRUE(good_->status().has_value()) << good_->last_error();
  }
  void TearDown() override {
    good_.reset();
    if (sim_) {
      EXPECT_EQ(sim_->stop(), 0) << sim_->errors();
    }
  }
  // The second client is still served, and the status is what it was.
  void expect_good_client_served(const char* after) {
    const auto s = good_->status();
    ASSERT_TRUE(s.has_value()) << "after " << after << ": " << good_->last_error();
    EXPECT_EQ(s->state, protocol::ControllerState::Idle) << after;
  }
  std::optional<protocol::Status> set_program(const std::vector<std::string>& lines) {
    protocol::Command c;
    c.code = protocol::CommandCode::SetProgram;
    c.seq = 1;
    c.identity = protocol::program_identity(lines);
    c.line_count = static_cast<std::uint32_t>(lines.size());
    if (!good_->write_command(c)) return std::nullopt;
    return good_->status();
  }

  std::unique_ptr<SimProcess> sim_;
  std::unique_ptr<ModbusClient> good_;
  int port_ = 0;
};

std::string bytes(std::initializer_list<int> values) {
  std::string s;
  for (int v : values) s.push_back(static_cast<char>(v));
  return s;
}

TEST_F(BadTraffic, RawGarbageClosesThatConnectionOnly) {
  RawSocket raw(port_);
  ASSERT_GE(raw.fd(), 0);
  ASSERT_TRUE(raw.send("GET / HTTP/1.1\r\nHost: controller\r\n\r\n"));
  EXPECT_TRUE(raw.closed_by_peer(2s)) << "garbage should cost the sender its connection";
  expect_good_client_served("HTTP garbage");
  ModbusClient fresh(port_);
  ASSERT_TRUE(fresh.connected());
  EXPECT_TRUE(fresh.status().has_value()) << "new clients are still accepted";
}

TEST_F(BadTraffic, WrongMbapLengthOrProtocolIdClosesThatConnection) {
  {
    RawSocket raw(port_);
    // FC4 of the status block, but the MBAP length says 10 bytes follow where 6 do.
    ASSERT_TRUE(raw.send(bytes({0, 1, 0, 0, 0, 10, 1, 4, 0, 0, 0, 46})));
    EXPECT_TRUE(raw.closed_by_peer(2s));
  }
  expect_good_client_served("a wrong MBAP length");
  {
    RawSocket raw(port_);
    ASSERT_TRUE(raw.send(bytes({0, 1, 0, 7, 0, 6, 1, 4, 0, 0, 0, 46})));  // protocol id 7
    EXPECT_TRUE(raw.closed_by_peer(2s));
  }
  expect_good_client_served("a wrong protocol id");
  {
    // The same request well formed is answered: 9 bytes of header and byte count + 92.
    RawSocket raw(port_);
    ASSERT_TRUE(raw.send(bytes({0, 1, 0, 0, 0, 6, 1, 4, 0, 0, 0, 46})));
    const std::string reply = raw.receive(2s);
    ASSERT_EQ(reply.size(), 9u + 92u);
    EXPECT_EQ(reply[7], 4);
    EXPECT_EQ(static_cast<unsigned char>(reply[8]), 92);
  }
}

TEST_F(BadTraffic, AClientStalledMidFrameIsDroppedWhileTheOtherIsServed) {
  RawSocket raw(port_);
  ASSERT_TRUE(raw.send(bytes({0, 1, 0, 0, 0})));  // five bytes of an MBAP header, then silence
  const auto start = std::chrono::steady_clock::now();
  expect_good_client_served("a stalled frame");
  EXPECT_LT(std::chrono::steady_clock::now() - start, 1s);
  EXPECT_TRUE(raw.closed_by_peer(2s));
}

TEST_F(BadTraffic, RegistersOffTheMapGetException02AndChangeNothing) {
  std::uint16_t regs[16] = {};
  modbus_t* ctx = good_->ctx();
  EXPECT_EQ(modbus_read_input_registers(ctx, 40, 10, regs), -1);  // 40..49: past the 46 status registers
  EXPECT_EQ(errno, EMBXILADD);
  EXPECT_EQ(modbus_read_registers(ctx, 240, 10, regs), -1);  // past the status mirror
  EXPECT_EQ(errno, EMBXILADD);
  EXPECT_EQ(modbus_write_register(ctx, 3, 1), -1);  // reserved
  EXPECT_EQ(errno, EMBXILADD);
  EXPECT_EQ(modbus_write_registers(ctx, mb::kStatusMirrorAddress, 2, regs), -1);  // the mirror is read-only
  EXPECT_EQ(errno, EMBXILADD);
  const std::uint16_t half_command[4] = {1, 5, 0, 0};
  EXPECT_EQ(modbus_write_registers(ctx, mb::kCommandAddress, 4, half_command), -1);  // not the whole block
  EXPECT_EQ(errno, EMBXILADD);
  std::uint8_t bits[8];
  EXPECT_EQ(modbus_read_bits(ctx, 0, 8, bits), -1);  // coils are not served
  EXPECT_EQ(errno, EMBXILFUN);
  const auto s = good_->status();
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->command_seq, 0) << "a refused write changes nothing";
  EXPECT_EQ(s->heartbeat_echo, 0);
}

TEST_F(BadTraffic, MalformedCountsGetException03WithoutStallingTheServer) {
  RawSocket raw(port_);
  // FC3 of 200 registers (the limit is 125): exception 03 at once (libmodbus itself would
  // sleep its response timeout and flush before answering).
  const auto start = std::chrono::steady_clock::now();
  ASSERT_TRUE(raw.send(bytes({0, 9, 0, 0, 0, 6, 1, 3, 0, 0, 0, 200})));
  const std::string reply = raw.receive_bytes(9, 2s);
  ASSERT_EQ(reply.size(), 9u) << "an exception reply";
  EXPECT_EQ(static_cast<unsigned char>(reply[7]), 0x83);
  EXPECT_EQ(reply[8], 3);
  EXPECT_LT(std::chrono::steady_clock::now() - start, 300ms);
  expect_good_client_served("a bad count");
}

TEST_F(BadTraffic, OversizeChunkIsRefusedAndNothingQueued) {
  const std::vector<std::string> lines = test_program(40);
  ASSERT_TRUE(set_program(lines).has_value());
  const auto before = good_->status();
  ASSERT_TRUE(before.has_value());

  // A header announcing a 300-byte payload (the Modbus limit is 222) in a full mailbox.
  std::vector<std::uint16_t> regs = mailbox_of(lines, 1, 1);
  regs[7] = 300;
  regs.resize(mb::kMailboxRegisters, 0x4731);
  const auto too_long = good_->write_mailbox(regs);
  ASSERT_TRUE(too_long.has_value()) << good_->last_error();
  EXPECT_EQ(too_long->chunk_result, ResultCode::TooLong);
  EXPECT_EQ(too_long->last_accepted_chunk, 0u);
  EXPECT_EQ(too_long->free_buffer_bytes, before->free_buffer_bytes);

  // A header announcing more payload than the write carries.
  std::vector<std::uint16_t> short_write = mailbox_of(lines, 1, 1);
  short_write.resize(short_write.size() - 20);
  const auto bad_length = good_->write_mailbox(short_write);
  ASSERT_TRUE(bad_length.has_value());
  EXPECT_EQ(bad_length->chunk_result, ResultCode::BadLength);
  EXPECT_EQ(bad_length->last_accepted_chunk, 0u);
  EXPECT_EQ(bad_length->refused_chunks, 2u);

  // More registers than the mailbox has: exception 02, nothing happens.
  // (FC16: libmodbus's FC23 refuses more than 121 before sending.)
  std::vector<std::uint16_t> overflow(mb::kMailboxRegisters + 1, 0);
  EXPECT_EQ(modbus_write_registers(good_->ctx(), mb::kMailboxAddress, int(overflow.size()), overflow.data()), -1);
  EXPECT_EQ(errno, EMBXILADD);

  ModbusClient second(port_);  // another client sees the same, untouched buffer
  const auto after = second.status();
  ASSERT_TRUE(after.has_value());
  EXPECT_EQ(after->free_buffer_bytes, before->free_buffer_bytes);
  EXPECT_EQ(after->last_accepted_chunk, 0u);
}

TEST_F(BadTraffic, BadCrcIsRefusedThenTheGoodChunkIsAccepted) {
  const std::vector<std::string> lines = test_program(40);
  ASSERT_TRUE(set_program(lines).has_value());
  ModbusClient second(port_);
  ASSERT_TRUE(second.connected());

  std::vector<std::uint16_t> regs = mailbox_of(lines, 1, 1);
  regs[9] ^= 0x0001;  // CRC-32, low word
  const auto bad = good_->write_mailbox(regs);
  ASSERT_TRUE(bad.has_value());
  EXPECT_EQ(bad->chunk_result, ResultCode::BadCrc);
  EXPECT_EQ(bad->last_accepted_chunk, 0u);
  const auto seen_by_second = second.status();
  ASSERT_TRUE(seen_by_second.has_value()) << second.last_error();
  EXPECT_EQ(seen_by_second->chunk_result, ResultCode::BadCrc);

  regs[9] ^= 0x0001;
  const auto good = good_->write_mailbox(regs);
  ASSERT_TRUE(good.has_value());
  EXPECT_EQ(good->chunk_result, ResultCode::Accepted);
  EXPECT_EQ(good->last_accepted_chunk, 1u);
}

// Random bytes, and well-framed requests with random PDUs, from many short connections:
// the server answers or drops each, and never stops serving the good client.
TEST_F(BadTraffic, RandomTrafficNeverTakesTheServerDown) {
  std::mt19937 random(20261125);
  auto byte = [&] { return static_cast<char>(random() & 0xFF); };
  for (int i = 0; i < 300; ++i) {
    RawSocket raw(port_);
    ASSERT_GE(raw.fd(), 0) << "connection " << i;
    std::string frame;
    if (i % 2 == 0) {  // raw garbage
      frame.resize(1 + random() % 300);
      for (char& c : frame) c = byte();
    } else {  // a good MBAP header around a random PDU (function codes around the served ones)
      std::string pdu(1 + random() % 250, 0);
      for (char& c : pdu) c = byte();
      pdu[0] = static_cast<char>(std::vector<int>{3, 4, 6, 16, 23, 1, 0x2B, 0x80 | 3}[random() % 8]);
      frame = bytes({int(random() & 0xFF), int(random() & 0xFF), 0, 0, int((pdu.size() + 1) >> 8),
                     int((pdu.size() + 1) & 0xFF), 1}) +
              pdu;
    }
    raw.send(frame);
    raw.receive(5ms);
    if (i % 25 == 0) expect_good_client_served("random traffic");
  }
  expect_good_client_served("random traffic");
}

}  // namespace
}  // namespace hybridctl::test
