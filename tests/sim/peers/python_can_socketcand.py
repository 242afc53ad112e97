#!/usr/bin/python3
"""A python-can 4.1 client of the socketcand interface against `hybridctl sim serve
--socketcand` (docs/protocol.md, "CAN mapping").

Usage: python_can_socketcand.py HOST PORT [NODE]

Opens the bus through python-can's socketcand interface, waits for a status snapshot
(16 frames on 0x180 + NODE), sends SET_PROGRAM as command frames (0x100 + NODE), a
heartbeat (0x700 + NODE) and one chunk as a segmented transfer on 0x200 + NODE, paced by
the controller's flow control on 0x280 + NODE; after each it waits for a snapshot that
shows it. Prints one line per step, "STEP key=value ...", for the C++ test to check;
exits 1 when a step does not show up within its time.

python-can's client loses a frame that is split across its 1024-byte reads
(../../../shared/PEERS.md): snapshots are taken whole or not at all, a lost flow control
frame restarts the transfer, and a command is repeated with the same sequence number
(the controller executes it once).
"""
import sys
import time
import zlib

import can

STATUS_FRAMES = 16
STATUS_BYTES = 92


def fnv1a64(data):
    h = 0xCBF29CE484222325
    for b in data:
        h = ((h ^ b) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return h


def u16(b, i):
    return (b[i] << 8) | b[i + 1]


def u32(b, i):
    return (u16(b, i) << 16) | u16(b, i + 2)


def parse_status(b):
    # Register r of the status block is bytes 2r, 2r+1 (docs/protocol.md, "Status block").
    return {
        "version": u16(b, 0), "state": u16(b, 2), "alarm": u16(b, 4), "chunk_result": u16(b, 6),
        "command_result": u16(b, 8), "command_seq": u16(b, 10), "command_code": u16(b, 12),
        "heartbeat_echo": u16(b, 14), "last_accepted": u32(b, 28), "next_line": u32(b, 40),
        "program_lines": u32(b, 44), "free_bytes": u32(b, 56),
    }


class Node:
    def __init__(self, bus, node):
        self.bus = bus
        self.node = node
        self.pending = None  # (counter, bytes so far)
        self.flow = []       # flow control frames seen

    def send(self, can_id, data):
        self.bus.send(can.Message(arbitration_id=can_id, data=bytes(data), is_extended_id=False))

    def pump(self, timeout):
        """Handles one received frame; returns a complete status dict or None."""
        msg = self.bus.recv(timeout)
        if msg is None:
            return None
        if msg.arbitration_id == 0x280 + self.node:
            self.flow.append(bytes(msg.data))
            return None
        if msg.arbitration_id != 0x180 + self.node or len(msg.data) < 2:
            return None
        index, counter, payload = msg.data[0], msg.data[1], bytes(msg.data[2:])
        if index == 0:
            self.pending = (counter, payload)
        elif self.pending and self.pending[0] == counter and len(self.pending[1]) == 6 * index:
            self.pending = (counter, self.pending[1] + payload)
        else:
            self.pending = None
            return None
        if index == STATUS_FRAMES - 1 and self.pending and len(self.pending[1]) == STATUS_BYTES:
            status = parse_status(self.pending[1])
            self.pending = None
            return status
        return None

    def wait_status(self, predicate, seconds, on_retry=None):
        end = time.monotonic() + seconds
        retry_at = time.monotonic() + 0.5
        while time.monotonic() < end:
            status = self.pump(0.05)
            if status is not None and predicate(status):
                return status
            if on_retry and time.monotonic() >= retry_at:
                on_retry()
                retry_at = time.monotonic() + 0.5
        return None

    def send_chunk(self, message, transfer_id, seconds):
        """ISO-TP-like transfer: first frame, then consecutive frames as flow control allows."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.flow.clear()
            n = len(message)
            self.send(0x200 + self.node, [0x10 | (n >> 8), n & 0xFF, transfer_id] + list(message[0:5]))
            sent, index, ok = 5, 1, True
            while sent < n and ok:
                fc = self.wait_flow(transfer_id, 1.0)
                if fc is None or fc[0] & 0x0F == 2:
                    ok = False  # lost or refused: start again
                    break
                if fc[0] & 0x0F == 1:
                    continue  # wait
                block = fc[1] or 10**9
                for _ in range(block):
                    if sent >= n:
                        break
                    self.send(0x200 + self.node, [0x20 | (index & 0x0F)] + list(message[sent:sent + 7]))
                    sent += 7
                    index += 1
            if ok:
                return True
        return False

    def wait_flow(self, transfer_id, seconds):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            while self.flow:
                fc = self.flow.pop(0)
                if len(fc) >= 4 and fc[0] >> 4 == 3 and fc[3] == transfer_id:
                    return fc
            self.pump(0.02)
        return None


def show(step, status):
    if status is None:
        print(f"error {step}: no status snapshot showed it in time")
        sys.exit(1)
    print(step, " ".join(f"{k}={v}" for k, v in status.items()))
    sys.stdout.flush()


def main():
    host, port = sys.argv[1], int(sys.argv[2])
    node_id = int(sys.argv[3]) if len(sys.argv) > 3 else 1
    bus = can.Bus(interface="socketcand", channel="can0", host=host, port=port)
    node = Node(bus, node_id)
    try:
        show("status", node.wait_status(lambda s: True, 5))

        lines = ["G21\n", "G90\n", "G0 X10 Y10 Z20\n", "G1 X20 F600\n", "G1 Y20\n", "M2\n"]
        identity = fnv1a64("".join(lines).encode("ascii"))
        args = [identity >> 32, identity & 0xFFFFFFFF, len(lines)]

        def set_program():
            for part, arg in enumerate(args):
                node.send(0x100 + node_id, [1, 0, 1, (part << 4) | 3] + list(arg.to_bytes(4, "big")))

        set_program()
        show("set_program", node.wait_status(lambda s: s["command_seq"] == 1, 5, set_program))

        heartbeat = lambda: node.send(0x700 + node_id, [0x12, 0x34])
        heartbeat()
        show("heartbeat", node.wait_status(lambda s: s["heartbeat_echo"] == 0x1234, 5, heartbeat))

        payload = "".join(lines[0:4]).encode("ascii")
        tag = identity & 0xFFFFFFFF
        message = (b"".join(v.to_bytes(4, "big") for v in (1, tag, 1)) + (4).to_bytes(2, "big")
                   + len(payload).to_bytes(2, "big") + (zlib.crc32(payload) & 0xFFFFFFFF).to_bytes(4, "big") + payload)
        if not node.send_chunk(message, 1, 10):
            print("error chunk1: the transfer never completed (no flow control)")
            return 1
        show("chunk1", node.wait_status(lambda s: s["last_accepted"] == 1, 5))
    finally:
        bus.shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
