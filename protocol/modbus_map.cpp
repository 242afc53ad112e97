// The chunk mailbox in registers and the controller's check of request PDUs.

#include "protocol/modbus_map.hpp"

#include <algorithm>

#include "protocol/wire.hpp"

namespace hybridctl::protocol::modbus {

Expected<std::vector<std::uint16_t>> encode_mailbox(const Chunk& chunk, std::size_t max_payload) {
  auto bytes = encode_chunk_bytes(chunk, std::min(max_payload, kMaxChunkPayload));
  if (!bytes) return bytes.error();
  auto& b = bytes.value();
  if (b.size() % 2) b.push_back(0);
  return bytes_to_registers(b);
}

Expected<Chunk> decode_mailbox(std::span<const std::uint16_t> registers, std::size_t max_payload) {
  if (registers.size() < kMailboxHeaderRegisters)
    return ProtocolError{ResultCode::BadLength, "mailbox write of " + std::to_string(registers.size()) +
                                                    " registers, shorter than the 10-register header"};
  const auto header_bytes = registers_to_bytes(registers.first(kMailboxHeaderRegisters));
  const ChunkHeader header = *read_chunk_header(header_bytes);
  const std::string seq = "chunk " + std::to_string(header.seq);
  const std::size_t limit = std::min(max_payload, kMaxChunkPayload);
  if (header.payload_length > limit)
    return ProtocolError{ResultCode::TooLong, seq + ": payload of " + std::to_string(header.payload_length) +
                                                  " bytes (mailbox register 7), at most " + std::to_string(limit) +
                                                  " accepted"};
  const std::size_t needed = mailbox_registers_for(header.payload_length);
  if (registers.size() < needed)
    return ProtocolError{ResultCode::BadLength, seq + ": payload length " + std::to_string(header.payload_length) +
                                                    " needs " + std::to_string(needed) + " mailbox registers, " +
                                                    std::to_string(registers.size()) + " were written"};
  auto payload = registers_to_bytes(registers.subspan(kMailboxHeaderRegisters, needed - kMailboxHeaderRegisters));
  if (payload.size() > header.payload_length) {
    if (payload.back() != 0)
      return ProtocolError{ResultCode::BadLength, seq + ": odd payload length " +
                                                      std::to_string(header.payload_length) + " but the pad byte (low byte of mailbox register " +
                                                      std::to_string(needed - 1) + ") is " + hex_byte(payload.back()) +
                                                      ", expected 0x00"};
    payload.pop_back();
  }
  return chunk_from_parts(header, payload, limit);
}

namespace {

ModbusRequestVerdict refuse(ModbusRequestVerdict v, ModbusException e, std::string message) {
  v.exception = e;
  v.message = std::move(message);
  return v;
}

WriteTarget write_target(std::uint16_t address, std::size_t count) {
  if (address == kHeartbeatAddress && count == 1) return WriteTarget::Heartbeat;
  if (address == kCommandAddress && count == kCommandCount) return WriteTarget::Command;
  if (address == kMailboxAddress && count >= 1 && count <= kMailboxRegisters) return WriteTarget::Mailbox;
  return WriteTarget::None;
}

std::string range(std::uint16_t address, std::size_t count) {
  return std::to_string(address) + ".." + std::to_string(address + count - 1);
}

constexpr const char* kWriteBlocks =
    "a write addresses one block: heartbeat 0 (1 register), command 8..15 (8), mailbox 16.. (1..121)";

}  // namespace

ModbusRequestVerdict inspect_request_pdu(std::span<const std::uint8_t> pdu) {
  ModbusRequestVerdict v;
  if (pdu.empty()) return refuse(v, ModbusException::IllegalDataValue, "empty request PDU");
  ModbusRequest req;
  req.function = pdu[0];
  const std::string fc = "FC" + std::to_string(req.function);
  switch (req.function) {
    case 3:
    case 4: {
      if (pdu.size() != 5)
        return refuse(v, ModbusException::IllegalDataValue,
                      fc + " request of " + std::to_string(pdu.size()) + " bytes, expected 5");
      req.read_address = get_u16(pdu, 1);
      req.read_count = get_u16(pdu, 3);
      break;
    }
    case 6: {
      if (pdu.size() != 5)
        return refuse(v, ModbusException::IllegalDataValue,
                      fc + " request of " + std::to_string(pdu.size()) + " bytes, expected 5");
      req.write_address = get_u16(pdu, 1);
      req.values.push_back(get_u16(pdu, 3));
      break;
    }
    case 16: {
      if (pdu.size() < 6) return refuse(v, ModbusException::IllegalDataValue, fc + " request shorter than 6 bytes");
      req.write_address = get_u16(pdu, 1);
      const std::uint16_t count = get_u16(pdu, 3);
      const std::uint8_t byte_count = pdu[5];
      if (count == 0 || count > kMaxWriteRegisters)
        return refuse(v, ModbusException::IllegalDataValue,
                      fc + " writes " + std::to_string(count) + " registers, expected 1..123");
      if (byte_count != 2 * count || pdu.size() != 6u + byte_count)
        return refuse(v, ModbusException::IllegalDataValue,
                      fc + " byte count " + std::to_string(byte_count) + " and PDU of " + std::to_string(pdu.size()) +
                          " bytes do not match " + std::to_string(count) + " registers");
      req.values = bytes_to_registers(pdu.subspan(6));
      break;
    }
    case 23: {
      if (pdu.size() < 10) return refuse(v, ModbusException::IllegalDataValue, fc + " request shorter than 10 bytes");
      req.read_address = get_u16(pdu, 1);
      req.read_count = get_u16(pdu, 3);
      req.write_address = get_u16(pdu, 5);
      const std::uint16_t count = get_u16(pdu, 7);
      const std::uint8_t byte_count = pdu[9];
      if (count == 0 || count > kMaxReadWriteWrite)
        return refuse(v, ModbusException::IllegalDataValue,
                      fc + " writes " + std::to_string(count) + " registers, expected 1..121");
      if (req.read_count == 0 || req.read_count > kMaxReadWriteRead)
        return refuse(v, ModbusException::IllegalDataValue,
                      fc + " reads " + std::to_string(req.read_count) + " registers, expected 1..125");
      if (byte_count != 2 * count || pdu.size() != 10u + byte_count)
        return refuse(v, ModbusException::IllegalDataValue,
                      fc + " byte count " + std::to_string(byte_count) + " and PDU of " + std::to_string(pdu.size()) +
                          " bytes do not match " + std::to_string(count) + " registers");
      req.values = bytes_to_registers(pdu.subspan(10));
      break;
    }
    default:
      return refuse(v, ModbusException::IllegalFunction,
                    fc + " is not served; the map uses FC3, FC4, FC6, FC16 and FC23");
  }
  v.request = req;
  const ModbusRequest& r = *v.request;
  // Reads.
  if (r.function == 3 || r.function == 4 || r.function == 23) {
    const std::size_t limit = r.function == 4 ? kInputRegisterCount : kHoldingRegisterCount;
    if (r.function != 23 && (r.read_count == 0 || r.read_count > kMaxReadRegisters))
      return refuse(v, ModbusException::IllegalDataValue,
                    fc + " reads " + std::to_string(r.read_count) + " registers, expected 1..125");
    if (std::size_t{r.read_address} + r.read_count > limit)
      return refuse(v, ModbusException::IllegalDataAddress,
                    fc + " reads " + range(r.read_address, r.read_count) + ", the " +
                        (r.function == 4 ? "input" : "holding") + " registers are 0.." + std::to_string(limit - 1));
  }
  // Writes.
  if (r.function == 6 || r.function == 16 || r.function == 23) {
    v.target = write_target(r.write_address, r.values.size());
    if (v.target == WriteTarget::None)
      return refuse(v, ModbusException::IllegalDataAddress,
                    fc + " writes holding registers " + range(r.write_address, r.values.size()) + "; " + kWriteBlocks);
  }
  return v;
}

}  // namespace hybridctl::protocol::modbus
