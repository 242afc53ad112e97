// The Modbus register map: blocks fit the function codes' limits, the mailbox carries a
// chunk in one write and refuses what does not fit, and a controller's check of request
// PDUs answers every misaddressed or malformed request with the right exception.

#include "protocol/modbus_map.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "protocol/checksums.hpp"

namespace {

using namespace hybridctl::protocol;
using namespace hybridctl::protocol::modbus;

Chunk chunk_of(const std::string& payload, std::uint32_t seq = 1) {
  Chunk c;
  c.seq = seq;
  c.identity_tag = 0x01020304;
  c.first_line = 1;
  for (char ch : payload) c.line_count += ch == '\n';
  c.payload = payload;
  return c;
}

TEST(ModbusMap, BlocksFitTheFunctionCodeLimits) {
  EXPECT_EQ(kMailboxRegisters, 121u) << "one FC23 write (121) and one FC16 write (123)";
  EXPECT_EQ(kMaxChunkPayload, 222u) << "(121 - 10 header registers) * 2 bytes";
  EXPECT_EQ(kStatusCount, 46u);
  EXPECT_LE(kStatusCount, kMaxReadRegisters);
  EXPECT_LE(kStatusCount, kMaxReadWriteRead);
  EXPECT_EQ(kHoldingRegisterCount, 246u);
  EXPECT_EQ(mailbox_registers_for(222), 121u);
  EXPECT_EQ(mailbox_registers_for(1), 11u);
  EXPECT_EQ(mailbox_registers_for(2), 11u);
}

TEST(Mailbox, LayoutIsTheDocumentedOne) {
  const Chunk c = chunk_of("G0\n", 0x00010002);  // odd length: one pad byte
  auto regs = encode_mailbox(c);
  ASSERT_TRUE(regs) << regs.error().message;
  const std::uint32_t crc = crc32(c.payload);
  const std::vector<std::uint16_t> expected = {
      0x0001, 0x0002,  // seq
      0x0102, 0x0304,  // identity tag
      0x0000, 0x0001,  // first line
      0x0001,          // line count
      0x0003,          // payload length
      static_cast<std::uint16_t>(crc >> 16), static_cast<std::uint16_t>(crc),
      ('G' << 8) | '0', ('\n' << 8) | 0x00};
  EXPECT_EQ(*regs, expected);
}

TEST(Mailbox, RoundTripsEvenOddAndLargestPayloads) {
  for (const std::string& payload :
       {std::string("G0\n"), std::string("G0 X1\n"), std::string(221, 'X') + "\n", std::string("\n")}) {
    const Chunk c = chunk_of(payload);
    auto regs = encode_mailbox(c);
    ASSERT_TRUE(regs) << regs.error().message;
    EXPECT_EQ(regs->size(), mailbox_registers_for(payload.size()));
    EXPECT_LE(regs->size(), kMailboxRegisters);
    auto d = decode_mailbox(*regs);
    ASSERT_TRUE(d) << d.error().message;
    EXPECT_EQ(*d, c);
  }
}

TEST(Mailbox, EncoderRefusesAChunkTooLargeForTheMailbox) {
  auto regs = encode_mailbox(chunk_of(std::string(222, 'X') + "\n"));  // 223 bytes
  ASSERT_FALSE(regs);
  EXPECT_EQ(regs.error().code, ResultCode::TooLong);
  // A smaller limit (the controller's advertised max chunk payload) applies too,
  // and a larger one cannot lift the mailbox's.
  EXPECT_EQ(encode_mailbox(chunk_of(std::string(99, 'X') + "\n"), 64).error().code, ResultCode::TooLong);
  EXPECT_EQ(encode_mailbox(chunk_of(std::string(222, 'X') + "\n"), 4000).error().code, ResultCode::TooLong);
}

TEST(Mailbox, DecoderIgnoresRegistersAfterThePayload) {
  const Chunk c = chunk_of("G1 X5\n");
  auto regs = *encode_mailbox(c);
  regs.resize(kMailboxRegisters, 0xABCD);  // the rest of the mailbox region, stale
  auto d = decode_mailbox(regs);
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_EQ(*d, c);
}

TEST(Mailbox, DecoderRefusesShortWrites) {
  auto regs = *encode_mailbox(chunk_of("G1 X5 Y6\n"));
  auto header_only = decode_mailbox(std::span<const std::uint16_t>(regs).first(9));
  EXPECT_EQ(header_only.error().code, ResultCode::BadLength);
  auto cut = decode_mailbox(std::span<const std::uint16_t>(regs).first(regs.size() - 1));
  ASSERT_FALSE(cut);
  EXPECT_EQ(cut.error().code, ResultCode::BadLength);
  EXPECT_NE(cut.error().message.find("chunk 1"), std::string::npos) << cut.error().message;
}

TEST(Mailbox, DecoderRefusesANonZeroPadByte) {
  auto regs = *encode_mailbox(chunk_of("G0\n"));
  regs.back() |= 0x0041;
  auto d = decode_mailbox(regs);
  ASSERT_FALSE(d);
  EXPECT_EQ(d.error().code, ResultCode::BadLength);
  EXPECT_NE(d.error().message.find("pad byte"), std::string::npos) << d.error().message;
}

TEST(Mailbox, DecoderRefusesALengthBeyondTheMailboxBeforeReadingIt) {
  auto regs = *encode_mailbox(chunk_of("G0\n"));
  regs[7] = 223;
  EXPECT_EQ(decode_mailbox(regs).error().code, ResultCode::TooLong);
  regs[7] = 0xFFFF;
  EXPECT_EQ(decode_mailbox(regs).error().code, ResultCode::TooLong);
}

TEST(Mailbox, DecoderRefusesBadCrcLinesAndText) {
  auto regs = *encode_mailbox(chunk_of("G1 X5\nG0\n"));
  auto bad_crc = regs;
  bad_crc[9] ^= 1;
  EXPECT_EQ(decode_mailbox(bad_crc).error().code, ResultCode::BadCrc);
  auto bad_payload = regs;
  bad_payload[10] ^= 0x0100;
  EXPECT_EQ(decode_mailbox(bad_payload).error().code, ResultCode::BadCrc);
  auto bad_lines = regs;
  bad_lines[6] = 3;
  EXPECT_EQ(decode_mailbox(bad_lines).error().code, ResultCode::BadLines);

  // Text errors need a matching CRC to be seen as text errors.
  auto with_text = [&](std::string payload) {
    auto r = regs;
    const std::uint32_t crc = crc32(payload);
    r[8] = static_cast<std::uint16_t>(crc >> 16);
    r[9] = static_cast<std::uint16_t>(crc);
    for (std::size_t i = 0; i < payload.size(); i += 2)
      r[10 + i / 2] = static_cast<std::uint16_t>((static_cast<std::uint8_t>(payload[i]) << 8) |
                                                 static_cast<std::uint8_t>(payload[i + 1]));
    return decode_mailbox(r);
  };
  EXPECT_TRUE(with_text("G1 X6\nG0\n")) << "same length, valid";
  EXPECT_EQ(with_text(std::string("G1\0X6\nG0\n", 9)).error().code, ResultCode::BadText);
  EXPECT_EQ(with_text("G1 X\xB5\nG0\n").error().code, ResultCode::BadText);
}

// ------------------------------------------------------------ request PDUs

std::vector<std::uint8_t> fc16(std::uint16_t address, const std::vector<std::uint16_t>& values) {
  std::vector<std::uint8_t> pdu = {16, static_cast<std::uint8_t>(address >> 8), static_cast<std::uint8_t>(address),
                                   static_cast<std::uint8_t>(values.size() >> 8),
                                   static_cast<std::uint8_t>(values.size()),
                                   static_cast<std::uint8_t>(2 * values.size())};
  for (auto v : values) {
    pdu.push_back(static_cast<std::uint8_t>(v >> 8));
    pdu.push_back(static_cast<std::uint8_t>(v));
  }
  return pdu;
}

std::vector<std::uint8_t> fc23(std::uint16_t read_address, std::uint16_t read_count, std::uint16_t write_address,
                               const std::vector<std::uint16_t>& values) {
  std::vector<std::uint8_t> pdu = {23,
                                   static_cast<std::uint8_t>(read_address >> 8),
                                   static_cast<std::uint8_t>(read_address),
                                   static_cast<std::uint8_t>(read_count >> 8),
                                   static_cast<std::uint8_t>(read_count),
                                   static_cast<std::uint8_t>(write_address >> 8),
                                   static_cast<std::uint8_t>(write_address),
                                   static_cast<std::uint8_t>(values.size() >> 8),
                                   static_cast<std::uint8_t>(values.size()),
                                   static_cast<std::uint8_t>(2 * values.size())};
  for (auto v : values) {
    pdu.push_back(static_cast<std::uint8_t>(v >> 8));
    pdu.push_back(static_cast<std::uint8_t>(v));
  }
  return pdu;
}

std::vector<std::uint8_t> read(std::uint8_t function, std::uint16_t address, std::uint16_t count) {
  return {function, static_cast<std::uint8_t>(address >> 8), static_cast<std::uint8_t>(address),
          static_cast<std::uint8_t>(count >> 8), static_cast<std::uint8_t>(count)};
}

ModbusRequestVerdict inspect(const std::vector<std::uint8_t>& pdu) { return inspect_request_pdu(pdu); }

TEST(RequestPdu, AChunkWrittenWithFc16IsAMailboxWriteCarryingTheChunk) {
  const Chunk c = chunk_of(std::string(221, 'Y') + "\n");
  const auto regs = *encode_mailbox(c);
  const auto v = inspect(fc16(kMailboxAddress, regs));
  ASSERT_FALSE(v.exception) << v.message;
  EXPECT_EQ(v.target, WriteTarget::Mailbox);
  ASSERT_TRUE(v.request);
  auto d = decode_mailbox(v.request->values);
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_EQ(*d, c);
}

TEST(RequestPdu, Fc23WritesTheMailboxAndReadsTheStatusMirrorInOneRequest) {
  const auto regs = *encode_mailbox(chunk_of(std::string(221, 'Y') + "\n"));
  const auto v = inspect(fc23(kStatusMirrorAddress, kStatusCount, kMailboxAddress, regs));
  ASSERT_FALSE(v.exception) << v.message;
  EXPECT_EQ(v.target, WriteTarget::Mailbox);
  EXPECT_EQ(v.request->read_address, kStatusMirrorAddress);
  EXPECT_EQ(v.request->read_count, kStatusCount);
  EXPECT_EQ(v.request->values, regs);
}

TEST(RequestPdu, HeartbeatCommandAndStatusRequestsPass) {
  EXPECT_EQ(inspect({6, 0, 0, 0x12, 0x34}).target, WriteTarget::Heartbeat);
  EXPECT_EQ(inspect({6, 0, 0, 0x12, 0x34}).request->values, std::vector<std::uint16_t>{0x1234});
  EXPECT_EQ(inspect(fc16(kHeartbeatAddress, {7})).target, WriteTarget::Heartbeat);
  const auto cmd = encode_command(Command{CommandCode::Start, 1, 0, 0});
  EXPECT_EQ(inspect(fc16(kCommandAddress, {cmd.begin(), cmd.end()})).target, WriteTarget::Command);
  const auto both = inspect(fc23(kStatusMirrorAddress, kStatusCount, kCommandAddress, {cmd.begin(), cmd.end()}));
  EXPECT_FALSE(both.exception) << both.message;
  EXPECT_EQ(both.target, WriteTarget::Command);
  EXPECT_FALSE(inspect(read(4, kStatusAddress, kStatusCount)).exception);
  EXPECT_FALSE(inspect(read(3, kStatusMirrorAddress, kStatusCount)).exception);
  EXPECT_FALSE(inspect(read(3, 0, 125)).exception);
}

TEST(RequestPdu, WritesOutsideOneWholeBlockAreIllegalDataAddress) {
  const auto cmd = encode_command(Command{CommandCode::Start, 1, 0, 0});
  const std::vector<std::vector<std::uint8_t>> bad = {
      {6, 0, 1, 0, 1},                                           // reserved register 1
      {6, 0, 8, 0, 2},                                           // one register of the command block
      fc16(kHeartbeatAddress, {1, 2}),                           // heartbeat + reserved
      fc16(kCommandAddress, {cmd.begin(), cmd.end() - 1}),       // part of the command block
      fc16(kCommandAddress + 1, {cmd.begin(), cmd.end()}),       // shifted
      fc16(kMailboxAddress + 1, {1, 2, 3}),                      // inside the mailbox
      fc16(kStatusMirrorAddress, {1}),                           // the read-only mirror
      fc16(500, {1}),                                            // outside the map
      fc23(kStatusMirrorAddress, 1, kStatusMirrorAddress, {1}),  // FC23 writing the mirror
  };
  for (const auto& pdu : bad) {
    const auto v = inspect(pdu);
    ASSERT_TRUE(v.exception) << "function " << int(pdu[0]);
    EXPECT_EQ(*v.exception, ModbusException::IllegalDataAddress) << v.message;
    EXPECT_FALSE(v.message.empty());
  }
}

TEST(RequestPdu, ReadsOutsideTheMapAreIllegalDataAddress) {
  EXPECT_EQ(inspect(read(4, 0, 47)).exception, ModbusException::IllegalDataAddress);
  EXPECT_EQ(inspect(read(4, 46, 1)).exception, ModbusException::IllegalDataAddress);
  EXPECT_EQ(inspect(read(3, 200, 47)).exception, ModbusException::IllegalDataAddress);
  EXPECT_EQ(inspect(fc23(200, 47, kHeartbeatAddress, {1})).exception,
            ModbusException::IllegalDataAddress);
}

TEST(RequestPdu, MalformedRequestsAreIllegalDataValue) {
  const std::vector<std::uint16_t> too_many(124, 0);
  EXPECT_EQ(inspect(fc16(kMailboxAddress, too_many)).exception, ModbusException::IllegalDataValue);
  const std::vector<std::uint16_t> fc23_too_many(122, 0);
  EXPECT_EQ(inspect(fc23(200, 46, kMailboxAddress, fc23_too_many)).exception,
            ModbusException::IllegalDataValue);
  EXPECT_EQ(inspect(fc23(200, 126, kHeartbeatAddress, {1})).exception, ModbusException::IllegalDataValue);
  EXPECT_EQ(inspect(read(4, 0, 0)).exception, ModbusException::IllegalDataValue);
  EXPECT_EQ(inspect(read(3, 0, 126)).exception, ModbusException::IllegalDataValue);
  auto wrong_byte_count = fc16(kHeartbeatAddress, {1});
  wrong_byte_count[5] = 4;
  EXPECT_EQ(inspect(wrong_byte_count).exception, ModbusException::IllegalDataValue);
  auto truncated = fc16(kMailboxAddress, {1, 2, 3});
  truncated.pop_back();
  EXPECT_EQ(inspect(truncated).exception, ModbusException::IllegalDataValue);
  EXPECT_EQ(inspect({}).exception, ModbusException::IllegalDataValue);
  EXPECT_EQ(inspect({16, 0}).exception, ModbusException::IllegalDataValue);
  EXPECT_EQ(inspect({4, 0, 0, 0}).exception, ModbusException::IllegalDataValue);
}

TEST(RequestPdu, OtherFunctionsAreIllegalFunction) {
  for (std::uint8_t fc : {1, 2, 5, 15, 22, 43, 0x83}) {
    EXPECT_EQ(inspect({fc, 0, 0, 0, 1}).exception, ModbusException::IllegalFunction) << int(fc);
  }
}

}  // namespace
