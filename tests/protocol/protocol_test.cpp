// Chunks, program identity, the status block and commands: what the encoders write, that
// every decoder gives back what was encoded, and that each kind of bad input is refused
// with the result code docs/protocol.md gives for it and a message saying where.

#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

#include "protocol/checksums.hpp"
#include "protocol/chunk.hpp"
#include "protocol/messages.hpp"

namespace {

using namespace hybridctl::protocol;

Chunk sample_chunk() {
  Chunk c;
  c.seq = 7;
  c.identity_tag = 0xDEADBEEF;
  c.first_line = 101;
  c.line_count = 3;
  c.payload = "G0 X0 Y0\nG1 Z-1 F100\nM5\n";
  return c;
}

// ------------------------------------------------------------ program text and identity

TEST(ProgramLines, SplitsOnNewlinesDroppingCarriageReturnsAndKeepsEverythingElse) {
  const auto lines = program_lines("%\r\nG0 X1 (move)\n\nM30\n%");
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0], "%");
  EXPECT_EQ(lines[1], "G0 X1 (move)");
  EXPECT_EQ(lines[2], "");
  EXPECT_EQ(lines[3], "M30");
  EXPECT_EQ(lines[4], "%");  // the last line needs no newline
  EXPECT_EQ(program_lines("G0\n").size(), 1u);  // no empty line after the final newline
  EXPECT_TRUE(program_lines("").empty());
}

TEST(ProgramIdentity, IsFnv1a64OfTheTextAsStreamed) {
  const auto lines = program_lines("G0 X1\r\nM30");
  EXPECT_EQ(program_text(lines), "G0 X1\nM30\n");
  EXPECT_EQ(program_identity(lines), fnv1a64("G0 X1\nM30\n"));
  EXPECT_NE(program_identity(program_lines("G0 X1\nM30\n")), program_identity(program_lines("G0 X2\nM30\n")));
  EXPECT_EQ(identity_tag(0x0123456789ABCDEFull), 0x89ABCDEFu);
}

TEST(MakeChunk, PacksWholeLinesUpToTheLimitAndTheChunksCoverTheProgramExactly) {
  std::vector<std::string> lines;
  for (int i = 1; i <= 50; ++i) lines.push_back("G1 X" + std::to_string(i) + " Y" + std::to_string(2 * i));
  const std::uint64_t identity = program_identity(lines);
  std::string streamed;
  std::uint32_t line = 1;
  std::uint32_t seq = 1;
  while (line <= lines.size()) {
    auto chunk = make_chunk(lines, line, seq, identity, 40);
    ASSERT_TRUE(chunk) << chunk.error().message;
    EXPECT_EQ(chunk->seq, seq);
    EXPECT_EQ(chunk->first_line, line);
    EXPECT_EQ(chunk->identity_tag, identity_tag(identity));
    EXPECT_LE(chunk->payload.size(), 40u);
    EXPECT_FALSE(validate_chunk(*chunk, 40)) << "made chunks are valid";
    if (line + chunk->line_count <= lines.size()) {  // not the last: the next line would not fit
      EXPECT_GT(chunk->payload.size() + lines[line + chunk->line_count - 1].size() + 1, 40u);
    }
    streamed += chunk->payload;
    line += chunk->line_count;
    ++seq;
  }
  EXPECT_EQ(streamed, program_text(lines));
  EXPECT_EQ(fnv1a64(streamed), identity);
}

TEST(MakeChunk, RefusesLinesThatCannotTravelAndNamesThem) {
  const std::vector<std::string> lines = {"G0 X1", std::string(60, 'X'), "G1 X\xC3\xA9"};
  auto too_long = make_chunk(lines, 2, 2, 1, 40);
  ASSERT_FALSE(too_long);
  EXPECT_EQ(too_long.error().code, ResultCode::TooLong);
  EXPECT_NE(too_long.error().message.find("line 2"), std::string::npos) << too_long.error().message;
  // The first chunk stops before the long line instead of failing.
  auto first = make_chunk(lines, 1, 1, 1, 40);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->line_count, 1);
  auto non_ascii = make_chunk(lines, 3, 3, 1, 40);
  ASSERT_FALSE(non_ascii);
  EXPECT_EQ(non_ascii.error().code, ResultCode::BadText);
  EXPECT_NE(non_ascii.error().message.find("line 3, column 5"), std::string::npos) << non_ascii.error().message;
  EXPECT_EQ(make_chunk(lines, 4, 1, 1, 40).error().code, ResultCode::BadValue);
  EXPECT_EQ(make_chunk(lines, 0, 1, 1, 40).error().code, ResultCode::BadValue);
}

// ------------------------------------------------------------ chunk byte form

TEST(ChunkBytes, HeaderLayoutIsBigEndianAsDocumented) {
  const Chunk c = sample_chunk();
  auto bytes = encode_chunk_bytes(c, 1000);
  ASSERT_TRUE(bytes) << bytes.error().message;
  const std::vector<std::uint8_t>& b = *bytes;
  ASSERT_EQ(b.size(), kChunkHeaderBytes + c.payload.size());
  const std::vector<std::uint8_t> header(b.begin(), b.begin() + 20);
  const std::uint32_t crc = crc32(c.payload);
  const std::vector<std::uint8_t> expected = {
      0, 0, 0, 7,                      // seq
      0xDE, 0xAD, 0xBE, 0xEF,          // identity tag
      0, 0, 0, 101,                    // first line
      0, 3,                            // line count
      0, static_cast<std::uint8_t>(c.payload.size()),  // payload length
      static_cast<std::uint8_t>(crc >> 24), static_cast<std::uint8_t>(crc >> 16),
      static_cast<std::uint8_t>(crc >> 8), static_cast<std::uint8_t>(crc)};
  EXPECT_EQ(header, expected);
  EXPECT_EQ(std::string(b.begin() + 20, b.end()), c.payload);
}

TEST(ChunkBytes, RoundTrip) {
  const Chunk c = sample_chunk();
  auto decoded = decode_chunk_bytes(*encode_chunk_bytes(c, 1000), 1000);
  ASSERT_TRUE(decoded) << decoded.error().message;
  EXPECT_EQ(*decoded, c);
}

/// The byte form of a chunk whose fields are taken as given (CRC computed over the payload).
std::vector<std::uint8_t> raw_chunk(std::uint32_t seq, std::uint32_t first_line, std::uint16_t line_count,
                                    const std::string& payload) {
  std::vector<std::uint8_t> b;
  auto u16 = [&](std::uint16_t v) {
    b.push_back(static_cast<std::uint8_t>(v >> 8));
    b.push_back(static_cast<std::uint8_t>(v));
  };
  auto u32 = [&](std::uint32_t v) {
    u16(static_cast<std::uint16_t>(v >> 16));
    u16(static_cast<std::uint16_t>(v));
  };
  u32(seq);
  u32(1);
  u32(first_line);
  u16(line_count);
  u16(static_cast<std::uint16_t>(payload.size()));
  u32(crc32(payload));
  b.insert(b.end(), payload.begin(), payload.end());
  return b;
}

ResultCode decode_code(const std::vector<std::uint8_t>& bytes, std::size_t max_payload = 1000) {
  auto d = decode_chunk_bytes(bytes, max_payload);
  EXPECT_FALSE(d) << "expected a refusal";
  if (d) return ResultCode::Accepted;
  EXPECT_FALSE(d.error().message.empty());
  return d.error().code;
}

TEST(ChunkBytes, TheHandBuiltChunksBelowAreValidUntilOneFieldIsWrong) {
  EXPECT_TRUE(decode_chunk_bytes(raw_chunk(1, 1, 1, "G0\n"), 1000));
  EXPECT_TRUE(decode_chunk_bytes(raw_chunk(9, 40, 2, "G0\n\n"), 1000));
}

TEST(ChunkBytes, DecodeRefusesBadLengths) {
  auto b = raw_chunk(1, 1, 1, "G0 X1\n");
  EXPECT_EQ(decode_code({b.begin(), b.begin() + 10}), ResultCode::BadLength);  // header cut
  EXPECT_EQ(decode_code({b.begin(), b.end() - 1}), ResultCode::BadLength);     // payload cut
  auto longer = b;
  longer.push_back('\n');
  EXPECT_EQ(decode_code(longer), ResultCode::BadLength);                       // extra byte
}

TEST(ChunkBytes, DecodeRefusesABadCrcAndSaysBoth) {
  auto b = raw_chunk(4, 1, 1, "G0 X1\n");
  b[22] ^= 0x01;  // corrupt the payload, keep the header's CRC
  auto d = decode_chunk_bytes(b, 1000);
  ASSERT_FALSE(d);
  EXPECT_EQ(d.error().code, ResultCode::BadCrc);
  EXPECT_NE(d.error().message.find("chunk 4"), std::string::npos) << d.error().message;
}

TEST(ChunkBytes, DecodeRefusesLineCountsThatDoNotMatch) {
  EXPECT_EQ(decode_code(raw_chunk(1, 1, 2, "G0 X1\n")), ResultCode::BadLines);
  EXPECT_EQ(decode_code(raw_chunk(1, 1, 0, "G0 X1\n")), ResultCode::BadLines);
  EXPECT_EQ(decode_code(raw_chunk(1, 1, 1, "G0 X1\nG0")), ResultCode::BadLines);  // partial last line
  EXPECT_EQ(decode_code(raw_chunk(1, 1, 0, "")), ResultCode::BadLines);           // empty
}

TEST(ChunkBytes, DecodeRefusesNulAndNonAsciiBytes) {
  EXPECT_EQ(decode_code(raw_chunk(1, 1, 1, std::string("G0\0X1\n", 6))), ResultCode::BadText);
  EXPECT_EQ(decode_code(raw_chunk(1, 1, 1, "G0 X\x80\n")), ResultCode::BadText);
  EXPECT_EQ(decode_code(raw_chunk(1, 1, 1, "G0 X\xFF\n")), ResultCode::BadText);
}

TEST(ChunkBytes, DecodeRefusesZeroSequenceAndLineNumbers) {
  EXPECT_EQ(decode_code(raw_chunk(0, 1, 1, "G0\n")), ResultCode::BadValue);
  EXPECT_EQ(decode_code(raw_chunk(1, 0, 1, "G0\n")), ResultCode::BadValue);
}

TEST(ChunkBytes, DecodeRefusesPayloadsOverTheLimit) {
  EXPECT_EQ(decode_code(raw_chunk(1, 1, 1, std::string(30, 'X') + "\n"), 30), ResultCode::TooLong);
  EXPECT_TRUE(decode_chunk_bytes(raw_chunk(1, 1, 1, std::string(29, 'X') + "\n"), 30));
}

TEST(ChunkBytes, EncoderRefusesWhatTheDecoderWould) {
  Chunk c = sample_chunk();
  c.line_count = 2;
  EXPECT_EQ(encode_chunk_bytes(c, 1000).error().code, ResultCode::BadLines);
  c = sample_chunk();
  EXPECT_EQ(encode_chunk_bytes(c, c.payload.size() - 1).error().code, ResultCode::TooLong);
}

// ------------------------------------------------------------ status block

Status full_status() {
  Status s;
  s.state = ControllerState::ProgramStop;
  s.alarm = AlarmCode::SpindleDepositionConflict;
  s.chunk_result = ResultCode::BufferFull;
  s.command_result = ResultCode::WrongState;
  s.command_seq = 65535;
  s.command_code = CommandCode::OperatorAck;
  s.heartbeat_echo = 0xBEEF;
  s.boot_count = 3;
  s.heartbeat_timeout_ms = 1500;
  s.alarm_line = 123456;
  s.last_written_chunk = 0xFFFFFFFFu;
  s.last_accepted_chunk = 70000;
  s.last_executed_chunk = 69998;
  s.last_executed_line = 1'000'001;
  s.next_line = 1'000'100;
  s.program_line_count = 2'000'000;
  s.identity = 0xFEDCBA9876543210ull;
  s.free_buffer_bytes = 100000;
  s.max_chunk_payload = 222;
  s.active_tool = 12;
  s.x_um = -123456;
  s.y_um = std::numeric_limits<std::int32_t>::min();
  s.z_um = std::numeric_limits<std::int32_t>::max();
  s.spindle_rpm = -24000;
  s.feed_override_percent = 150;
  s.deposition_on = true;
  s.duplicate_chunks = 5;
  s.refused_chunks = 9;
  return s;
}

TEST(StatusBlock, RoundTripsEveryFieldIncludingNegativePositions) {
  const Status s = full_status();
  const StatusRegisters regs = encode_status(s);
  auto decoded = decode_status(regs);
  ASSERT_TRUE(decoded) << decoded.error().message;
  EXPECT_EQ(*decoded, s);
  auto from_bytes = decode_status_bytes(encode_status_bytes(s));
  ASSERT_TRUE(from_bytes) << from_bytes.error().message;
  EXPECT_EQ(*from_bytes, s);
  EXPECT_EQ(encode_status_bytes(s).size(), kStatusBytes);
}

TEST(StatusBlock, RegisterLayoutIsTheDocumentedOne) {
  const StatusRegisters regs = encode_status(full_status());
  EXPECT_EQ(regs.size(), 46u);
  EXPECT_EQ(regs[0], kProtocolVersion);
  EXPECT_EQ(regs[1], 3);  // PROGRAM_STOP
  EXPECT_EQ(regs[2], 9);  // SPINDLE_DEPOSITION_CONFLICT
  // x = -123456 = 0xFFFE1DC0, high word first
  EXPECT_EQ(regs[status_reg::kX], 0xFFFE);
  EXPECT_EQ(regs[status_reg::kX + 1], 0x1DC0);
  // identity most significant word first
  EXPECT_EQ(regs[status_reg::kIdentity], 0xFEDC);
  EXPECT_EQ(regs[status_reg::kIdentity + 3], 0x3210);
  EXPECT_EQ(regs[status_reg::kFlags], status_reg::kFlagDepositionOn);
  // spindle -24000 rpm: counter-clockwise
  EXPECT_EQ(static_cast<std::int32_t>((regs[status_reg::kSpindleRpm] << 16) | regs[status_reg::kSpindleRpm + 1]),
            -24000);
}

TEST(StatusBlock, DecodeRefusesAnotherVersionFirstThenAnotherLength) {
  StatusRegisters regs = encode_status(Status{});
  regs[0] = 2;
  auto v2 = decode_status(regs);
  ASSERT_FALSE(v2);
  EXPECT_EQ(v2.error().code, ResultCode::BadValue);
  EXPECT_NE(v2.error().message.find("version 2"), std::string::npos) << v2.error().message;
  std::vector<std::uint16_t> longer(regs.begin(), regs.end());
  longer.push_back(0);
  EXPECT_EQ(decode_status(longer).error().code, ResultCode::BadValue) << "version still reported first";
  longer[0] = kProtocolVersion;
  EXPECT_EQ(decode_status(longer).error().code, ResultCode::BadLength);
  EXPECT_EQ(decode_status(std::span<const std::uint16_t>(longer).first(45)).error().code, ResultCode::BadLength);
  EXPECT_EQ(decode_status({}).error().code, ResultCode::BadLength);
}

TEST(StatusBlock, DecodeRefusesUndefinedCodesNamingTheRegister) {
  for (std::size_t reg : {status_reg::kState, status_reg::kAlarm, status_reg::kChunkResult,
                          status_reg::kCommandResult, status_reg::kCommandCode}) {
    StatusRegisters regs = encode_status(Status{});
    regs[reg] = 999;
    auto d = decode_status(regs);
    ASSERT_FALSE(d) << "register " << reg;
    EXPECT_EQ(d.error().code, ResultCode::BadValue);
    EXPECT_NE(d.error().message.find("status register " + std::to_string(reg)), std::string::npos)
        << d.error().message;
  }
}

TEST(StatusBlock, ReservedFlagBitsAreIgnored) {
  StatusRegisters regs = encode_status(Status{});
  regs[status_reg::kFlags] = 0xFFFE;
  auto d = decode_status(regs);
  ASSERT_TRUE(d);
  EXPECT_FALSE(d->deposition_on);
}

// ------------------------------------------------------------ commands

TEST(CommandBlock, RoundTripsEveryCommand) {
  std::uint16_t seq = 65534;
  for (std::uint16_t code = 1; code < kCommandCodeCount; ++code) {
    Command c;
    c.code = static_cast<CommandCode>(code);
    c.seq = seq;
    if (c.code == CommandCode::SetProgram) {
      c.identity = 0x0102030405060708ull;
      c.line_count = 70000;
    }
    auto d = decode_command(encode_command(c));
    ASSERT_TRUE(d) << d.error().message;
    EXPECT_EQ(*d, c) << to_string(c.code);
    seq = next_command_seq(seq);
  }
  EXPECT_EQ(next_command_seq(65535), 1) << "seq 0 is never used";
}

TEST(CommandBlock, LayoutIsTheDocumentedOne) {
  const Command c{CommandCode::SetProgram, 42, 0x0102030405060708ull, 0x00010002};
  const CommandRegisters r = encode_command(c);
  const CommandRegisters expected = {1, 42, 0x0102, 0x0304, 0x0506, 0x0708, 0x0001, 0x0002};
  EXPECT_EQ(r, expected);
}

TEST(CommandBlock, DecodeRefusesBadBlocks) {
  CommandRegisters r = encode_command(Command{CommandCode::Start, 1, 0, 0});
  EXPECT_EQ(decode_command(std::span<const std::uint16_t>(r).first(7)).error().code, ResultCode::BadLength);
  r[command_reg::kSeq] = 0;
  EXPECT_EQ(decode_command(r).error().code, ResultCode::BadValue);
  r[command_reg::kSeq] = 5;
  r[command_reg::kCode] = 0;
  EXPECT_EQ(decode_command(r).error().code, ResultCode::UnknownCommand);
  r[command_reg::kCode] = 99;
  EXPECT_EQ(decode_command(r).error().code, ResultCode::UnknownCommand);
  const CommandRegisters empty_program = encode_command(Command{CommandCode::SetProgram, 3, 77, 0});
  EXPECT_EQ(decode_command(empty_program).error().code, ResultCode::BadArgument);
}

TEST(CommandBlock, ArgumentsOfOtherCommandsAreIgnored) {
  CommandRegisters r = encode_command(Command{CommandCode::Abort, 9, 0, 0});
  r[command_reg::kIdentity] = 0x1234;
  auto d = decode_command(r);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->identity, 0u);
}

TEST(Expected, ValueOfAnErrorIsAProgrammingError) {
  Expected<int> e(ResultCode::BadCrc, "bad");
  EXPECT_FALSE(e);
  EXPECT_THROW((void)e.value(), std::logic_error);
  Expected<int> ok(3);
  EXPECT_EQ(ok.error().code, ResultCode::None);
}

}  // namespace
