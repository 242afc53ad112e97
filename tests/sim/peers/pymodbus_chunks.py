#!/usr/bin/python3
"""A pymodbus 3.0 client against `hybridctl sim serve` (docs/protocol.md, "Modbus mapping").

Usage: pymodbus_chunks.py HOST PORT

Reads the status block (FC4), writes SET_PROGRAM into the command block (FC16), then
writes chunks into the mailbox with FC23 (write the mailbox, read the status mirror in
the same request): chunk 1, chunk 1 again (a duplicate), chunk 3 (a gap). Prints one line
per step, "STEP key=value ...", for the C++ test to check; exits 1 on any Modbus error.

The CRC-32 of each payload is zlib.crc32 and the program identity FNV-1a 64, computed here
independently of hybridctl's codec. pymodbus 3.0's readwrite_registers(slave=1) sends unit
0; unit=1 is what reaches the wire (../../../shared/PEERS.md).
"""
import sys
import zlib

from pymodbus.client import ModbusTcpClient

COMMAND_ADDRESS = 8
MAILBOX_ADDRESS = 16
STATUS_MIRROR_ADDRESS = 200
STATUS_COUNT = 46
SET_PROGRAM = 1

# Status block registers (docs/protocol.md, "Status block").
REG = {
    "version": 0, "state": 1, "alarm": 2, "chunk_result": 3, "command_result": 4,
    "command_seq": 5, "command_code": 6,
}
REG32 = {
    "last_written": 12, "last_accepted": 14, "next_line": 20, "program_lines": 22,
    "free_bytes": 28, "duplicates": 42, "refused": 44,
}

LINES = ["G21\n", "G90\n", "G0 X10 Y10 Z20\n", "G1 X20 F600\n", "G1 Y20\n", "M2\n"]


def fnv1a64(data):
    h = 0xCBF29CE484222325
    for b in data:
        h = ((h ^ b) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return h


def describe(regs):
    fields = {k: regs[i] for k, i in REG.items()}
    fields.update({k: (regs[i] << 16) | regs[i + 1] for k, i in REG32.items()})
    return " ".join(f"{k}={v}" for k, v in fields.items())


def mailbox(seq, first_line, lines, tag):
    payload = "".join(lines).encode("ascii")
    crc = zlib.crc32(payload) & 0xFFFFFFFF
    header = [seq >> 16, seq & 0xFFFF, tag >> 16, tag & 0xFFFF, first_line >> 16, first_line & 0xFFFF,
              len(lines), len(payload), crc >> 16, crc & 0xFFFF]
    if len(payload) % 2:
        payload += b"\0"
    return header + [(payload[i] << 8) | payload[i + 1] for i in range(0, len(payload), 2)]


def check(response, what):
    if response.isError():
        print(f"error {what}: {response}")
        sys.exit(1)
    return response


def main():
    host, port = sys.argv[1], int(sys.argv[2])
    client = ModbusTcpClient(host, port=port, timeout=3)
    if not client.connect():
        print(f"error cannot connect to {host}:{port}")
        return 1
    identity = fnv1a64("".join(LINES).encode("ascii"))
    tag = identity & 0xFFFFFFFF

    regs = check(client.read_input_registers(0, STATUS_COUNT, slave=1), "reading the status").registers
    print("status", describe(regs))

    command = [SET_PROGRAM, 1, (identity >> 48) & 0xFFFF, (identity >> 32) & 0xFFFF, (identity >> 16) & 0xFFFF,
               identity & 0xFFFF, 0, len(LINES)]
    check(client.write_registers(COMMAND_ADDRESS, command, slave=1), "writing SET_PROGRAM")
    regs = check(client.read_input_registers(0, STATUS_COUNT, slave=1), "reading the status").registers
    print("set_program", describe(regs))

    def chunk(step, seq, first_line, lines):
        r = check(client.readwrite_registers(read_address=STATUS_MIRROR_ADDRESS, read_count=STATUS_COUNT,
                                             write_address=MAILBOX_ADDRESS,
                                             write_registers=mailbox(seq, first_line, lines, tag), unit=1),
                  f"writing chunk {seq}")
        print(step, describe(r.registers))

    chunk("chunk1", 1, 1, LINES[0:3])
    chunk("duplicate", 1, 1, LINES[0:3])
    chunk("gap", 3, 4, LINES[3:6])
    client.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
