// Fuzz target: the controller side of the Modbus program stream (docs/protocol.md, "Modbus
// mapping"): request PDUs checked against the register map (modbus::inspect_request_pdu),
// mailbox writes decoded and offered to the acceptance rule (ChunkAcceptor), command
// blocks through the exactly-once gate (CommandGate), and the status block the controller
// answers with, as sim/ does with every request.
//
// Input (fuzz/byte_reader.hpp): the acceptor's buffer bytes (u16) and max chunk payload
// (u8, 0: 222), then operations, each an opcode byte (mod 9) and its arguments:
//   0 PDU: a request PDU (length byte + bytes)    1 registers: count byte + u16 each
//   2 chunk: flags, fields, payload; a well-formed chunk (encode_mailbox), fitting the set
//     program or not, one register possibly damaged    3 SET_PROGRAM: u64 identity, u16 lines
//   4 take the oldest chunk   5 reboot onto a safe point   6 ABORT   7 state: u8
//   8 a CAN chunk message (u16 length + bytes)
// Contract: the decoders never throw and refuse bad input with a result code and a
// message; the acceptor's books balance after every operation; the status block it fills
// round-trips through its register form.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "protocol/chunk_acceptor.hpp"
#include "protocol/messages.hpp"
#include "protocol/modbus_map.hpp"
#include "fuzz/byte_reader.hpp"
#include "fuzz/fuzz_check.hpp"

namespace protocol = hybridctl::protocol;
namespace modbus = hybridctl::protocol::modbus;
using protocol::ChunkAcceptor;
using protocol::ControllerState;
using protocol::ResultCode;

namespace {

void check_books(const ChunkAcceptor& acceptor, const protocol::AcceptorSettings& settings) {
  std::uint64_t queued = 0;
  std::uint32_t previous_seq = 0;
  for (const protocol::Chunk& c : acceptor.queue()) {
    queued += c.payload.size();
    FUZZ_CHECK(c.payload.size() <= settings.max_chunk_payload, "no queued chunk is over the advertised payload");
    FUZZ_CHECK(previous_seq == 0 || c.seq == previous_seq + 1, "queued chunks are consecutive");
    FUZZ_CHECK(!protocol::validate_chunk(c, settings.max_chunk_payload), "every queued chunk is valid");
    previous_seq = c.seq;
  }
  FUZZ_CHECK(acceptor.free_bytes() <= settings.buffer_bytes, "free bytes never exceed the buffer");
  FUZZ_CHECK(queued == settings.buffer_bytes - acceptor.free_bytes(), "free bytes are the buffer less the queue");
  if (!acceptor.queue().empty())
    FUZZ_CHECK(acceptor.queue().back().seq == acceptor.last_accepted(), "the last queued chunk is the last accepted");

  protocol::Status status;
  acceptor.fill_status(status);
  const auto registers = protocol::encode_status(status);
  const auto decoded = protocol::decode_status(registers);
  FUZZ_CHECK(decoded.ok(), "the status block a controller fills decodes");
  FUZZ_CHECK(decoded.value() == status, "the status block round-trips through its registers");
}

void check_verdict(const protocol::ChunkVerdict& v, std::size_t queue_before, const ChunkAcceptor& acceptor) {
  FUZZ_CHECK(v.result != ResultCode::None, "every chunk write has a result");
  FUZZ_CHECK(!v.message.empty(), "every chunk write has a message");
  FUZZ_CHECK(acceptor.last_result() == v.result, "the status reports the last result");
  const std::size_t expected = queue_before + (v.result == ResultCode::Accepted ? 1 : 0);
  FUZZ_CHECK(acceptor.queue().size() == expected, "exactly an accepted chunk is queued");
}

ControllerState state_from(std::uint8_t byte) {
  return static_cast<ControllerState>(byte % protocol::kControllerStateCount);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hybridctl::fuzz::ByteReader in({data, size});
  protocol::AcceptorSettings settings;
  settings.buffer_bytes = in.u16();
  const std::uint8_t max_payload = in.u8();
  settings.max_chunk_payload = max_payload == 0 ? modbus::kMaxChunkPayload : max_payload;
  ChunkAcceptor acceptor(settings);
  protocol::CommandGate gate;
  ControllerState state = ControllerState::Idle;

  while (!in.empty()) {
    const std::size_t queue_before = acceptor.queue().size();
    switch (in.u8() % 9) {
      case 0: {  // a request PDU, as the Modbus server hands it over
        const auto pdu = in.sized_bytes();
        const modbus::ModbusRequestVerdict v = modbus::inspect_request_pdu(pdu);
        if (v.exception) {
          FUZZ_CHECK(!v.message.empty(), "a refused PDU says why");
          break;
        }
        FUZZ_CHECK(v.request.has_value(), "a PDU that passes is parsed");
        if (v.target == modbus::WriteTarget::Mailbox) {
          check_verdict(acceptor.offer_mailbox(v.request->values, state), queue_before, acceptor);
        } else if (v.target == modbus::WriteTarget::Command) {
          const auto intake = gate.offer(v.request->values);
          if (intake.decision == protocol::CommandGate::Decision::Execute) {
            if (intake.command.code == protocol::CommandCode::SetProgram)
              acceptor.set_program(intake.command.identity, intake.command.line_count);
            if (intake.command.code == protocol::CommandCode::Abort) acceptor.discard_queue();
            gate.record(ResultCode::Accepted);
          } else if (intake.decision == protocol::CommandGate::Decision::Refused) {
            FUZZ_CHECK(!intake.error.message.empty(), "a refused command says why");
          }
        }
        break;
      }
      case 1: {  // raw mailbox registers
        std::vector<std::uint16_t> registers(in.u8());
        for (auto& r : registers) r = in.u16();
        check_verdict(acceptor.offer_mailbox(registers, state), queue_before, acceptor);
        break;
      }
      case 2: {  // a well-formed chunk, fitting the set program or not, possibly damaged in one register
        const std::uint8_t how = in.u8();
        protocol::Chunk chunk;
        chunk.seq = how & 0x01 ? acceptor.last_accepted() + ((how >> 1) & 3) : in.u32();
        chunk.identity_tag = how & 0x08 ? protocol::identity_tag(acceptor.identity()) : in.u32();
        chunk.first_line = how & 0x10 ? acceptor.next_line() : in.u32();
        chunk.payload = in.sized_string();
        std::uint16_t lines = 0;
        for (char c : chunk.payload) lines += c == '\n';
        chunk.line_count = how & 0x20 ? lines : in.u16();
        auto registers = modbus::encode_mailbox(chunk);
        if (!registers) {
          FUZZ_CHECK(protocol::validate_chunk(chunk, modbus::kMaxChunkPayload).has_value(),
                     "encode_mailbox refuses only what validate_chunk refuses");
          break;
        }
        const auto decoded = modbus::decode_mailbox(registers.value());
        FUZZ_CHECK(decoded.ok() && decoded.value() == chunk, "a chunk round-trips through the mailbox");
        if (how & 0x40) {
          const std::size_t at = in.u8() % registers.value().size();
          registers.value()[at] ^= in.u16();
        }
        check_verdict(acceptor.offer_mailbox(registers.value(), state), queue_before, acceptor);
        break;
      }
      case 3: {  // SET_PROGRAM without the gate
        const std::uint64_t identity = in.u64();
        acceptor.set_program(identity, in.u16());
        break;
      }
      case 4: {  // the executor takes the oldest chunk
        const auto chunk = acceptor.take();
        FUZZ_CHECK(chunk.has_value() == (queue_before > 0), "take() returns a chunk exactly when one is queued");
        break;
      }
      case 5: {  // a reboot: a fresh acceptor on the safe point
        protocol::SafePoint sp;
        sp.identity = in.flag() ? acceptor.identity() : in.u64();
        sp.line_count = in.u32();
        sp.last_executed_chunk = in.u32();
        sp.last_executed_line = in.u32();
        acceptor = ChunkAcceptor(settings);
        acceptor.restore(sp);
        FUZZ_CHECK(acceptor.queue().empty(), "a restored acceptor has an empty queue");
        break;
      }
      case 6:  // ABORT
        acceptor.discard_queue();
        break;
      case 7:
        state = state_from(in.u8());
        break;
      case 8:  // the same bytes as a reassembled CAN message
        check_verdict(acceptor.offer_message(in.sized_bytes(true), state), queue_before, acceptor);
        break;
    }
    check_books(acceptor, settings);
  }
  return 0;
}
