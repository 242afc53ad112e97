// The controller's acceptance rules for chunks and commands.

#include "protocol/chunk_acceptor.hpp"

#include "protocol/can_transfer.hpp"
#include "protocol/wire.hpp"

namespace hybridctl::protocol {

bool accepts_chunks(ControllerState state) {
  switch (state) {
    case ControllerState::Idle:
    case ControllerState::Running:
    case ControllerState::FeedHold:
    case ControllerState::ProgramStop:
    case ControllerState::OptionalStop:
      return true;
    case ControllerState::Alarm:
    case ControllerState::Completed:
    case ControllerState::Aborted:
      return false;
  }
  return false;
}

ChunkAcceptor::ChunkAcceptor(AcceptorSettings settings) : settings_(settings) {}

void ChunkAcceptor::set_program(std::uint64_t identity, std::uint32_t line_count) {
  has_program_ = true;
  identity_ = identity;
  line_count_ = line_count;
  last_accepted_ = 0;
  next_line_ = 1;
  discard_queue();
}

void ChunkAcceptor::restore(const SafePoint& sp) {
  discard_queue();
  has_program_ = sp.identity != 0;
  identity_ = sp.identity;
  line_count_ = sp.line_count;
  last_accepted_ = has_program_ ? sp.last_executed_chunk : 0;
  next_line_ = has_program_ ? sp.last_executed_line + 1 : 0;
}

void ChunkAcceptor::discard_queue() {
  queue_.clear();
  used_bytes_ = 0;
}

ChunkVerdict ChunkAcceptor::record(std::uint32_t seq, ResultCode result, std::string message) {
  last_written_ = seq;
  last_result_ = result;
  if (result == ResultCode::Duplicate) ++duplicates_;
  else if (result != ResultCode::Accepted) ++refused_;
  return ChunkVerdict{result, std::move(message)};
}

ChunkVerdict ChunkAcceptor::offer(const Chunk& chunk, ControllerState state) {
  const std::string name = "chunk " + std::to_string(chunk.seq);
  if (!has_program_) return record(chunk.seq, ResultCode::NoProgram, name + ": no program set (SET_PROGRAM first)");
  if (chunk.identity_tag != identity_tag(identity_))
    return record(chunk.seq, ResultCode::IdentityMismatch,
                  name + ": identity tag " + hex_u32(chunk.identity_tag) + ", the set program's is " +
                      hex_u32(identity_tag(identity_)));
  if (chunk.seq <= last_accepted_)
    return record(chunk.seq, ResultCode::Duplicate,
                  name + ": already accepted (last accepted " + std::to_string(last_accepted_) + "); not queued again");
  if (!accepts_chunks(state))
    return record(chunk.seq, ResultCode::NotAccepting,
                  name + ": the controller takes no chunks in state " + std::string(to_string(state)));
  if (chunk.seq != last_accepted_ + 1)
    return record(chunk.seq, ResultCode::Gap,
                  name + ": expected chunk " + std::to_string(last_accepted_ + 1));
  const std::uint64_t last_line = std::uint64_t{chunk.first_line} + chunk.line_count - 1;
  if (chunk.first_line != next_line_ || last_line > line_count_)
    return record(chunk.seq, ResultCode::LineMismatch,
                  name + ": lines " + std::to_string(chunk.first_line) + ".." + std::to_string(last_line) +
                      ", expected the next ones from line " + std::to_string(next_line_) + " of " +
                      std::to_string(line_count_));
  if (chunk.payload.size() > settings_.max_chunk_payload)
    return record(chunk.seq, ResultCode::TooLong,
                  name + ": payload of " + std::to_string(chunk.payload.size()) + " bytes, at most " +
                      std::to_string(settings_.max_chunk_payload));
  if (chunk.payload.size() > free_bytes())
    return record(chunk.seq, ResultCode::BufferFull,
                  name + ": payload of " + std::to_string(chunk.payload.size()) + " bytes, " +
                      std::to_string(free_bytes()) + " free");
  used_bytes_ += static_cast<std::uint32_t>(chunk.payload.size());
  last_accepted_ = chunk.seq;
  next_line_ = chunk.first_line + chunk.line_count;
  queue_.push_back(chunk);
  return record(chunk.seq, ResultCode::Accepted, name + ": accepted");
}

ChunkVerdict ChunkAcceptor::offer_mailbox(std::span<const std::uint16_t> registers, ControllerState state) {
  auto chunk = modbus::decode_mailbox(registers, settings_.max_chunk_payload);
  if (!chunk) {
    const std::uint32_t seq = registers.size() >= 2 ? reg_u32(registers, 0) : 0;
    return record(seq, chunk.error().code, chunk.error().message);
  }
  return offer(chunk.value(), state);
}

ChunkVerdict ChunkAcceptor::offer_message(std::span<const std::uint8_t> message, ControllerState state) {
  auto chunk = can::decode_chunk_message(message, settings_.max_chunk_payload);
  if (!chunk) {
    const std::uint32_t seq = message.size() >= 4 ? get_u32(message, 0) : 0;
    return record(seq, chunk.error().code, chunk.error().message);
  }
  return offer(chunk.value(), state);
}

std::optional<Chunk> ChunkAcceptor::take() {
  if (queue_.empty()) return std::nullopt;
  Chunk chunk = std::move(queue_.front());
  queue_.pop_front();
  used_bytes_ -= static_cast<std::uint32_t>(chunk.payload.size());
  return chunk;
}

void ChunkAcceptor::fill_status(Status& s) const {
  s.chunk_result = last_result_;
  s.last_written_chunk = last_written_;
  s.last_accepted_chunk = last_accepted_;
  s.next_line = next_line_;
  s.program_line_count = line_count_;
  s.identity = identity_;
  s.free_buffer_bytes = free_bytes();
  s.max_chunk_payload = settings_.max_chunk_payload;
  s.duplicate_chunks = duplicates_;
  s.refused_chunks = refused_;
}

CommandGate::Intake CommandGate::offer(std::span<const std::uint16_t> registers) {
  Intake in;
  if (registers.size() <= command_reg::kSeq) {
    in.decision = Decision::Refused;
    in.error = ProtocolError{ResultCode::BadLength, "command block of " + std::to_string(registers.size()) +
                                                        " registers, expected 8"};
    return in;
  }
  const std::uint16_t seq = registers[command_reg::kSeq];
  if (seq == 0 || seq == last_seq_) return in;  // Repeated
  auto command = decode_command(registers);
  if (!command) {
    in.decision = Decision::Refused;
    in.error = command.error();
    last_seq_ = seq;
    last_code_ = command_code_from_wire(registers[command_reg::kCode]).value_or(CommandCode::None);
    last_result_ = in.error.code;
    return in;
  }
  return offer(command.value());
}

CommandGate::Intake CommandGate::offer(const Command& command) {
  Intake in;
  if (command.seq == 0 || command.seq == last_seq_) return in;  // Repeated
  in.decision = Decision::Execute;
  in.command = command;
  last_seq_ = command.seq;
  last_code_ = command.code;
  last_result_ = ResultCode::None;
  return in;
}

void CommandGate::record(ResultCode result) { last_result_ = result; }

void CommandGate::fill_status(Status& s) const {
  s.command_seq = last_seq_;
  s.command_code = last_code_;
  s.command_result = last_result_;
}

}  // namespace hybridctl::protocol
