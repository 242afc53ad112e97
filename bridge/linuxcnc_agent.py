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
# Each request may carry "id": N, which its reply carries back.
# Replies:  {"ok": true, ...} or {"ok": false, "error": TEXT}; every status reply says
#           whether LinuxCNC answers ("connected") and carries the error channel's
#           messages that arrived since the last reply.
import json
import os
import sys
import time

import linuxcnc

TIMEOUT_S = 5.0


def task_name(ini):
    """The task program the INI names ([TASK] TASK, milltask by default), as the kernel
    shows a process's name (its first 15 characters)."""
    name, section = "milltask", None
    try:
        with open(ini) as f:
            for line in f:
                line = line.split("#", 1)[0].strip()
                if line.startswith("["):
                    section = line.strip("[]").strip()
                elif section == "TASK" and "=" in line:
                    key, value = (x.strip() for x in line.split("=", 1))
                    if key == "TASK" and value:
                        name = os.path.basename(value)
    except OSError:
        pass
    return name[:15]


def process_start(pid):
    """The start time of process pid (clock ticks since boot), or None when it is gone."""
    try:
        with open("/proc/%d/stat" % pid) as f:
            return int(f.read().rsplit(")", 1)[1].split()[19])
    except (OSError, IndexError, ValueError):
        return None


def find_task(name):
    """(pid, start time) of the running process called name, or None."""
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/comm" % entry) as f:
                if f.read().strip() != name:
                    continue
        except OSError:
            continue
        start = process_start(int(entry))
        if start is not None:
            return int(entry), start
    return None


class Link:
    """The channels to one run of LinuxCNC, and that run's task process.

    A status channel outlives the LinuxCNC it was opened on: its shared memory stays
    attached after LinuxCNC has gone, and polls go on reading the last status it wrote. So
    the link also follows LinuxCNC's task process (found by name, checked by pid and start
    time): when it ends, the channels are dropped and LinuxCNC counts as not answering;
    a LinuxCNC started again is a new run, opened afresh."""

    def __init__(self):
        self.stat = self.command = self.errors = None
        self.task = None  # (name, pid, start) of the run the channels belong to
        self.pending = []  # messages read while waiting, for the next status

    def connect(self):
        if self.stat is not None and process_start(self.task[1]) != self.task[2]:
            gone = self.task
            self.drop()
            raise RuntimeError("LinuxCNC's task process (%s, pid %d) ended" % (gone[0], gone[1]))
        if self.stat is None:
            stat = linuxcnc.stat()
            stat.poll()
            name = task_name(stat.ini_filename)
            found = find_task(name)
            if found is None:
                raise RuntimeError("LinuxCNC's task process (%s) is not running" % name)
            self.stat, self.task = stat, (name,) + found
            self.command = linuxcnc.command()
            self.errors = linuxcnc.error_channel()
        self.stat.poll()
        return self.stat

    def drop(self):
        self.stat = self.command = self.errors = None
        self.task = None

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
    except Exception as e:  # linuxcnc.error, SystemError from a half-started LinuxCNC, or its task gone
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
        request = {}
        try:
            request = json.loads(line)
            reply = handle(link, request)
        except linuxcnc.error as e:
            link.drop()
            reply = {"ok": False, "error": "LinuxCNC: " + str(e)}
        except Exception as e:  # a reply for every request, whatever went wrong
            reply = {"ok": False, "error": type(e).__name__ + ": " + str(e)}
        # The request's number back: a reply the bridge stopped waiting for is told apart
        # from the one to its next request.
        if isinstance(request, dict) and "id" in request:
            reply["id"] = request["id"]
        replies.write(json.dumps(reply) + "\n")
        replies.flush()


main()
