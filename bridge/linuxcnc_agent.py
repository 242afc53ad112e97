# The bridge's hands on LinuxCNC: a small process that uses LinuxCNC's own Python API
# (the `linuxcnc` module of Debian's linuxcnc-uspace, under /usr/bin/python3) on the
# bridge's behalf. `hybridctl bridge linuxcnc` embeds this file and runs it as a child;
# they talk in JSON lines, one request on stdin, one reply on stdout, in order.
#
# Why a child process: LinuxCNC's status and command channels (NML over shared memory)
# have a documented, stable Python API; its C++ API is internal and unpackaged. The
# agent does nothing on its own: every action is a request from the bridge.
#
# Requests: {"op": "status"} | {"op": "prepare", "feed_override": F} |
#           {"op": "run", "file": PATH} | {"op": "pause"} | {"op": "resume"} |
#           {"op": "abort"} | {"op": "estop"}
# Replies:  {"ok": true, ...} or {"ok": false, "error": TEXT}; every status reply says
#           whether LinuxCNC answers ("connected") and carries the error channel's
#           messages that arrived since the last reply.
import json
import os
import sys
import time

import linuxcnc

TIMEOUT_S = 5.0


class Link:
    def __init__(self):
        self.stat = self.command = self.errors = None
        self.pending = []  # messages read while waiting, for the next status

    def connect(self):
        if self.stat is None:
            self.stat = linuxcnc.stat()
            self.command = linuxcnc.command()
            self.errors = linuxcnc.error_channel()
        self.stat.poll()
        return self.stat

    def drop(self):
        self.stat = self.command = self.errors = None

    def drain_errors(self):
        out, self.pending = self.pending, []
        while self.errors is not None:
            m = self.errors.poll()
            if not m:
                break
            kind, text = m
            out.append({"kind": kind, "error": kind in (linuxcnc.NML_ERROR, linuxcnc.OPERATOR_ERROR), "text": text})
        return out

    def wait(self, what, condition):
        deadline = time.monotonic() + TIMEOUT_S
        while True:
            s = self.connect()
            if condition(s):
                return
            if time.monotonic() > deadline:
                raise RuntimeError("LinuxCNC did not " + what + " within %.0f s" % TIMEOUT_S)
            time.sleep(0.005)

    def set_mode(self, mode):
        if self.connect().task_mode != mode:
            self.command.mode(mode)
            self.command.wait_complete(TIMEOUT_S)
            self.wait("change mode", lambda s: s.task_mode == mode)


def status(link):
    try:
        s = link.connect()
    except Exception as e:  # linuxcnc.error, or SystemError from a half-started LinuxCNC
        link.drop()
        return {"ok": True, "connected": False, "why": str(e)}
    sp = s.spindle[0] if s.spindle else {"speed": 0.0, "direction": 0}
    return {
        "ok": True,
        "connected": True,
        "ini": s.ini_filename,
        "estop": bool(s.estop),
        "enabled": bool(s.enabled),
        "homed": all(s.homed[i] for i in range(s.joints)),
        "task_state": s.task_state,
        "task_mode": s.task_mode,
        "interp_state": s.interp_state,
        "exec_state": s.exec_state,
        "paused": bool(s.paused),
        "file": s.file,
        "motion_line": s.motion_line,
        "current_line": s.current_line,
        "queue": s.queue,
        "inpos": bool(s.inpos),
        "position": list(s.actual_position[:3]),
        "tool": s.tool_in_spindle,
        "spindle_speed": sp["speed"],
        "spindle_direction": sp["direction"],
        "dout": [bool(v) for v in s.dout[:4]],
        "feedrate": s.feedrate,
        "messages": link.drain_errors(),
    }


def prepare(link, feed_override):
    s = link.connect()
    c = link.command
    if s.task_state == linuxcnc.STATE_ESTOP:
        c.state(linuxcnc.STATE_ESTOP_RESET)
        link.wait("leave e-stop", lambda s: s.task_state != linuxcnc.STATE_ESTOP)
    if link.connect().task_state != linuxcnc.STATE_ON:
        c.state(linuxcnc.STATE_ON)
        link.wait("switch on", lambda s: s.task_state == linuxcnc.STATE_ON)
    s = link.connect()
    if not all(s.homed[i] for i in range(s.joints)):
        link.set_mode(linuxcnc.MODE_MANUAL)
        c.teleop_enable(0)
        c.wait_complete(TIMEOUT_S)
        c.home(-1)
        c.wait_complete(TIMEOUT_S)
        link.wait("home", lambda s: all(s.homed[i] for i in range(s.joints)))
        c.teleop_enable(1)
        c.wait_complete(TIMEOUT_S)
    link.set_mode(linuxcnc.MODE_AUTO)
    if feed_override:
        c.feedrate(feed_override)
        c.wait_complete(TIMEOUT_S)
    return {"ok": True}


def run(link, path):
    link.connect()
    link.set_mode(linuxcnc.MODE_AUTO)
    link.command.program_open(path)
    link.command.wait_complete(TIMEOUT_S)
    link.wait("open " + path, lambda s: s.file == path)
    # AUTO_RUN is not waited for (it completes when the program ends), only until the
    # interpreter left IDLE: a status after this reply is about this program.
    link.command.auto(linuxcnc.AUTO_RUN, 0)
    deadline = time.monotonic() + TIMEOUT_S
    while link.connect().interp_state == linuxcnc.INTERP_IDLE:
        # AUTO_RUN completes when the program ends: a short one may be over already.
        if link.command.wait_complete(0.002) == linuxcnc.RCS_DONE and link.connect().file == path:
            return {"ok": True}
        # A program LinuxCNC refuses at once (a soft limit on its first move) never
        # leaves IDLE: its error says why.
        errors = [m for m in link.drain_errors() if m["error"]]
        if errors:
            link.pending.extend(errors)
            return {"ok": False, "error": errors[0]["text"]}
        if time.monotonic() > deadline:
            raise RuntimeError("LinuxCNC did not start " + path + " within %.0f s" % TIMEOUT_S)
        time.sleep(0.002)
    return {"ok": True}


def switch_off_outputs(link):
    # After an abort: spindle and deposition off, as the protocol's ABORT says.
    link.wait("stop after the abort", lambda s: s.interp_state == linuxcnc.INTERP_IDLE)
    link.set_mode(linuxcnc.MODE_MDI)
    for line in ("M5", "M65 P0", "M65 P1", "M65 P2", "M65 P3"):
        link.command.mdi(line)
        link.command.wait_complete(TIMEOUT_S)
    link.wait("run the MDI lines", lambda s: s.interp_state == linuxcnc.INTERP_IDLE)
    link.set_mode(linuxcnc.MODE_AUTO)


def handle(link, request):
    op = request.get("op")
    if op == "status":
        return status(link)
    if op == "prepare":
        return prepare(link, float(request.get("feed_override", 0)))
    if op == "run":
        return run(link, request["file"])
    link.connect()
    c = link.command
    if op == "pause":
        c.auto(linuxcnc.AUTO_PAUSE)
    elif op == "resume":
        c.auto(linuxcnc.AUTO_RESUME)
    elif op == "abort":
        c.abort()
        c.wait_complete(TIMEOUT_S)
        if link.connect().task_state == linuxcnc.STATE_ON:
            switch_off_outputs(link)
    elif op == "estop":
        c.state(linuxcnc.STATE_ESTOP)
    else:
        return {"ok": False, "error": "unknown request " + json.dumps(op)}
    c.wait_complete(TIMEOUT_S)
    return {"ok": True}


def main():
    # Replies go to a private copy of stdout; LinuxCNC's C code prints notes on fd 1,
    # which from now on is stderr, so they cannot break a reply line.
    replies = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    link = Link()
    for line in sys.stdin:
        try:
            reply = handle(link, json.loads(line))
        except linuxcnc.error as e:
            link.drop()
            reply = {"ok": False, "error": "LinuxCNC: " + str(e)}
        except Exception as e:  # a reply for every request, whatever went wrong
            reply = {"ok": False, "error": type(e).__name__ + ": " + str(e)}
        replies.write(json.dumps(reply) + "\n")
        replies.flush()


main()
