#!/usr/bin/env python3
"""`hybridctl bridge linuxcnc` with the real LinuxCNC (Debian's linuxcnc-uspace, headless,
the sim configuration examples/linuxcnc/hybrid-3axis/) behind it and `hybridctl run`
streaming a plan's program to it over 127.0.0.1.

    linuxcnc_bridge_test.py CASE --hybridctl BIN --plan-dir DIR --work DIR

CASE is one of:
  modbus      the whole program over Modbus TCP: LinuxCNC executes every line once, in
              order; the deposition output toggles where the program says, or stays off
              when the program never switches it (sampled from HAL); the tool changes happen; the final position is the program's; the
              host's final report matches LinuxCNC's.
  drop        the bridge closes the host's connection every N requests: no line twice,
              the program completes.
  estop       LinuxCNC e-stopped mid-program: the host stops with EMERGENCY_STOP and the
              line.
  socketcand  the same program over socketcand completes.

LinuxCNC runs as the unprivileged user scripts/setup creates (rtapi_app refuses root),
under `timeout`, and is stopped at the end. A test that cannot start it FAILS with the
reason. Figures (lines/s into LinuxCNC, the longest standstill at a segment boundary from
LinuxCNC's own position stream) are printed as "figure NAME VALUE".
"""

import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time

USER = "hybridctl-cnc"
SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CONFIG = os.path.join(SOURCE, "examples", "linuxcnc", "hybrid-3axis")
PYTHON = "/usr/bin/python3"
FEED_OVERRIDE = "10000"  # percent: a hundred times the program's feeds (the INI's MAX_FEED_OVERRIDE 100)

# HAL's sampler records, every servo period (1 ms), what LinuxCNC's motion did: the
# deposition output, the file line of the motion, the tool in the spindle, the position.
SAMPLER_HAL = """loadrt sampler depth=65536 cfg=bssfff
addf sampler.0 servo-thread
net deposition-on => sampler.0.pin.0
net sampled-line motion.program-line => sampler.0.pin.1
net sampled-tool iocontrol.0.tool-number => sampler.0.pin.2
net sampled-x joint.0.pos-fb => sampler.0.pin.3
net sampled-y joint.1.pos-fb => sampler.0.pin.4
net sampled-z joint.2.pos-fb => sampler.0.pin.5
"""


class Failure(Exception):
    pass


def check(condition, message):
    if not condition:
        raise Failure(message)


def as_user(argv):
    return ["runuser", "-u", USER, "--"] + argv


def prepare_work(work):
    """A fresh copy of the config the LinuxCNC user may write (var file, position file)."""
    if os.path.exists(work):
        shutil.rmtree(work)
    cnc = os.path.join(work, "cnc")
    shutil.copytree(CONFIG, cnc)
    with open(os.path.join(cnc, "sampler.hal"), "w") as f:
        f.write(SAMPLER_HAL)
    ini = os.path.join(cnc, "hybrid-3axis.ini")
    text = open(ini).read().replace("HALFILE = hybrid-3axis.hal", "HALFILE = hybrid-3axis.hal\nHALFILE = sampler.hal")
    open(ini, "w").write(text)
    os.chmod(work, 0o755)
    subprocess.run(["chown", "-R", USER, work], check=True)
    return ini


class Process:
    """A background process in its own session, its output in a file."""

    def __init__(self, argv, log_path, cwd=None):
        self.log_path = log_path
        self.log = open(log_path, "w")
        self.proc = subprocess.Popen(argv, stdout=self.log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                     cwd=cwd, start_new_session=True)

    def output(self):
        if not self.log.closed:
            self.log.flush()
        return open(self.log_path, errors="replace").read()

    def wait_for(self, pattern, timeout):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            m = re.search(pattern, self.output())
            if m:
                return m
            if self.proc.poll() is not None:
                break
            time.sleep(0.05)
        return None

    def stop(self, sig=signal.SIGTERM, timeout=20):
        if self.proc.poll() is None:
            try:
                os.killpg(self.proc.pid, sig)
            except ProcessLookupError:
                pass
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()
        self.log.close()
        return self.proc.returncode


def user_processes(wait_s):
    """The LinuxCNC user's processes still there after up to wait_s seconds (a stopping
    LinuxCNC takes a few)."""
    deadline = time.monotonic() + wait_s
    while True:
        left = subprocess.run(["pgrep", "-u", USER, "-l", "."], capture_output=True, text=True).stdout.strip()
        if not left or time.monotonic() > deadline:
            return left
        time.sleep(0.2)


def linuxcnc_answers():
    probe = "import linuxcnc; s = linuxcnc.stat(); s.poll(); print('up', s.task_state)"
    r = subprocess.run(as_user([PYTHON, "-c", probe]), capture_output=True, text=True, timeout=20)
    return r.returncode == 0 and "up" in r.stdout


class Linuxcnc:
    def __init__(self, ini, work):
        self.ini = ini
        self.work = work
        leftovers = user_processes(15)
        check(not leftovers, "processes of " + USER + " still run (another LinuxCNC?):\n" + leftovers)
        self.process = Process(["timeout", "-k", "10", "900"] + as_user(["linuxcnc", ini]),
                               os.path.join(work, "linuxcnc.log"), cwd=os.path.dirname(ini))
        deadline = time.monotonic() + 90
        while not linuxcnc_answers():
            if self.process.proc.poll() is not None or time.monotonic() > deadline:
                out = self.process.output()
                self.stop()
                raise Failure("LinuxCNC did not start (" + ini + ", as user " + USER + "):\n" + out[-3000:])
            time.sleep(0.5)
        self.sampler = self.start_sampler()

    def start_sampler(self):
        """halsampler, once the HAL sampler is there (LinuxCNC's status answers before its
        HAL files are all loaded)."""
        deadline = time.monotonic() + 60
        while True:
            sampler = Process(as_user(["halsampler", "-t"]), os.path.join(self.work, "samples.txt"))
            time.sleep(0.5)
            if sampler.proc.poll() is None:
                return sampler
            out = sampler.output()
            sampler.stop()
            if time.monotonic() > deadline:
                raise Failure("halsampler does not attach to LinuxCNC's sampler:\n" + out[-1000:])

    def estop(self):
        r = subprocess.run(as_user([PYTHON, "-c", "import linuxcnc; c = linuxcnc.command(); "
                                    "c.state(linuxcnc.STATE_ESTOP); c.wait_complete()"]),
                           capture_output=True, text=True, timeout=20)
        check(r.returncode == 0, "could not e-stop LinuxCNC: " + r.stderr)

    def samples(self):
        """(sample number, deposition, file line, tool, x, y, z) per servo period."""
        out = []
        for line in open(self.sampler.log_path):
            f = line.split()
            if len(f) == 7:
                out.append((int(f[0]), f[1] == "1", int(f[2]), int(f[3]), float(f[4]), float(f[5]), float(f[6])))
        return out

    def samples_at(self, wanted, timeout=30):
        """The samples once the last one is at `wanted`, or after `timeout` s: halsampler's
        output lags behind the servo thread on a loaded machine, so the file read the moment
        the host reports the program done may end before the last move did."""
        deadline = time.time() + timeout
        while True:
            out = self.samples()
            last = out[-1][4:] if out else None
            if time.time() > deadline or (last and all(w is not None and abs(a - w) < 0.002 for a, w in zip(last, wanted))):
                return out
            time.sleep(0.2)

    def stop(self):
        if getattr(self, "sampler", None):
            self.sampler.stop()
        self.process.stop(signal.SIGTERM, timeout=30)
        # LinuxCNC's own shutdown (SIGTERM to its script) stops rtapi_app and its helpers;
        # `halrun -U` unloads whatever is left (rtapi_app is setuid root: it outlives a
        # killed script), then the user's leftover processes go. Else the next start fails.
        subprocess.run(as_user(["halrun", "-U"]), capture_output=True, timeout=60)
        pids = [line.split()[0] for line in user_processes(10).splitlines()]
        for pid in pids:
            try:
                os.kill(int(pid), signal.SIGKILL)
            except ProcessLookupError:
                pass


def pick_plan(plan_dir):
    """Plan 3 when it mills with two tools or more (tool changes to check: the flanged
    hub's plan 3, T1 from -Z and T2 from +Z); else the first plan that does. The planner
    may renumber its plans."""
    doc = json.load(open(os.path.join(plan_dir, "plan.json")))
    names = {p["name"]: p.get("label", "") for p in doc["primitives"]}

    def kinds(plan):
        return [(a["mode"], names.get(a["primitive"], "")) for a in plan["actions"]]

    def fits(plan):
        k = kinds(plan)
        tools = set(re.findall(r"\bT\d+\b", " ".join(n for m, n in k if m == "subtractive")))
        return len(tools) >= 2

    plans = doc["plans"]
    for i in ([2] if len(plans) >= 3 else []) + list(range(len(plans))):
        if fits(plans[i]):
            return i + 1
    raise Failure("no plan in " + plan_dir + " mills with two tools or more: " +
                  json.dumps([kinds(p) for p in plans])[:2000])


def pick_deposit_plan(plan_dir):
    """The first plan that only deposits (the flanged hub from -Z, validated): a program
    that switches the deposition output on and off thousands of times."""
    doc = json.load(open(os.path.join(plan_dir, "plan.json")))
    names = {p["name"]: p.get("label", "") for p in doc["primitives"]}
    for i, plan in enumerate(doc["plans"]):
        labels = [names.get(a["primitive"], "") for a in plan["actions"]]
        if labels and all(a["mode"] == "additive" for a in plan["actions"]) and \
                all(re.match(r"[UO]-AM ", n) for n in labels):
            return i + 1
    raise Failure("no plan in " + plan_dir + " only deposits")


def program_lines(job_dir):
    """The program the host streamed (its job directory keeps it)."""
    for name in sorted(os.listdir(job_dir)):
        if name.endswith(".ngc"):
            text = open(os.path.join(job_dir, name)).read()
            lines = text.split("\n")
            if lines and lines[-1] == "":
                lines.pop()
            return [l[:-1] if l.endswith("\r") else l for l in lines]
    raise Failure("no program (.ngc) in the job directory " + job_dir + ": " + str(os.listdir(job_dir)))


def start_bridge(args, ini, transport_option, extra=()):
    seg = os.path.join(args.work, "segments")
    os.makedirs(seg, exist_ok=True)
    subprocess.run(["chown", USER, seg], check=True)
    line_log = os.path.join(args.work, "executed.txt")
    argv = as_user([args.hybridctl, "bridge", "linuxcnc", "--ini", ini, transport_option[0], transport_option[1],
                    "--segment-dir", seg, "--line-log", line_log, "--feed-override", FEED_OVERRIDE] + list(extra))
    bridge = Process(argv, os.path.join(args.work, "bridge.log"))
    m = bridge.wait_for(r"listening (modbus-tcp|socketcand) 127\.0\.0\.1:(\d+)\n(.|\n)*ready", 60)
    if not m:
        out = bridge.output()
        bridge.stop()
        raise Failure("the bridge did not get ready:\n" + out[-3000:])
    return bridge, int(m.group(2)), line_log


def run_host(args, plan, uri, job):
    argv = [args.hybridctl, "run", os.path.join(args.plan_dir, "plan.json"), "--plan", str(plan), "--transport", uri,
            "--job", job, "--yes"]
    t0 = time.monotonic()
    r = subprocess.run(argv, capture_output=True, text=True, timeout=900, cwd=args.work)
    return r, time.monotonic() - t0


def executed(line_log):
    out = []
    for line in open(line_log):
        number, _, text = line.rstrip("\n").partition(" ")
        out.append((int(number), text))
    return out


def check_every_line_once(program, ran):
    numbers = [n for n, _ in ran]
    check(numbers == list(range(1, len(program) + 1)),
          "LinuxCNC did not execute lines 1..%d once each in order: %d entries, first wrong at %s" %
          (len(program), len(numbers), next((i for i, n in enumerate(numbers) if n != i + 1), len(numbers))))
    for n, text in ran:
        check(text == program[n - 1], "line %d ran as %r, the program says %r" % (n, text, program[n - 1]))


def segments_of(bridge_log):
    return [(int(a), int(b)) for a, b in re.findall(r"segment \d+: lines (\d+)\.\.(\d+)", bridge_log)]


def check_segments(bridge_log, lines):
    """LinuxCNC got every line in exactly one segment file, in order: nothing re-run."""
    segments = segments_of(bridge_log)
    check(segments and segments[0][0] == 1 and segments[-1][1] == lines and
          all(b[0] == a[1] + 1 for a, b in zip(segments, segments[1:])),
          "the segments LinuxCNC ran do not cover lines 1..%d once each: %s\n%s" % (lines, segments, bridge_log[-2000:]))
    check("alarm" not in bridge_log, "the bridge raised an alarm:\n" + bridge_log[-2000:])
    return segments


def output_changes(program):
    """(line, on) of every M64/M65 P0 in the program, in order."""
    out = []
    for n, text in enumerate(program, 1):
        code = text.split(";")[0]
        code = re.sub(r"\([^)]*\)", "", code).upper()
        if re.search(r"\bM6[24]\b", code.replace(" ", " ")) and re.search(r"P\s*0\b", code):
            out.append((n, True))
        elif re.search(r"\bM6[35]\b", code) and re.search(r"P\s*0\b", code):
            out.append((n, False))
    return out


def distance(a, b):
    return sum((x - y) ** 2 for x, y in zip(a, b)) ** 0.5


# At a hundred times the program's feed LinuxCNC's blending (G64) rounds corners by up
# to about a millimetre; an output toggle is where the program says within this.
TOGGLE_TOLERANCE_MM = 2.0
# Found with LinuxCNC 2.9.0~pre1 at 100x feed on a loaded host, where its task cannot keep
# the motion queue filled: about 1 toggle in 6000 came a whole move early (M65 while the
# move before it had only begun; docs/bridge.md, "Findings"). More than this many per
# thousand fails the test.
MISPLACED_PER_THOUSAND = 1.0


def check_deposition(program, samples):
    """HAL's deposition output changes as often, in the same order and at the same places
    (the position where the program's M64/M65 P0 takes effect) as the program says; a
    program that never switches it on leaves it off throughout."""
    expected = output_changes(program)
    if not any(on for _, on in expected):
        on = [s for s in samples if s[1]]
        check(not on, "the program never switches the deposition output on, HAL saw it on in %d samples "
              "(the first at line %d)" % (len(on), on[0][2] if on else 0))
        return 0, 0
    where = positions(program)
    seen = [(samples[i][1], samples[i][4:]) for i in range(1, len(samples)) if samples[i][1] != samples[i - 1][1]]
    check(len(seen) == len(expected),
          "HAL saw the deposition output change %d times, the program changes it %d times" % (len(seen), len(expected)))
    misplaced = []
    for (on, at), (line, wanted_on) in zip(seen, expected):
        check(on == wanted_on, "HAL saw deposition %s where line %d switches it %s" % (on, line, wanted_on))
        d = distance(at, where[line - 1])
        if d > TOGGLE_TOLERANCE_MM:
            misplaced.append("deposition %s at %s, %.2f mm from where line %d switches it (%s)" %
                             (on, at, d, line, where[line - 1]))
    for m in misplaced:
        print("finding: " + m)
    check(len(misplaced) * 1000 <= MISPLACED_PER_THOUSAND * len(seen),
          "%d of %d deposition toggles were not where the program says:\n%s" %
          (len(misplaced), len(seen), "\n".join(misplaced[:20])))
    return len(seen), len(misplaced)


def check_tools(program, samples):
    wanted = []
    for text in program:
        m = re.search(r"\bT(\d+)\b.*\bM0?6\b|\bM0?6\b.*\bT(\d+)\b", text.upper())
        if m:
            wanted.append(int(m.group(1) or m.group(2)))
    seen = []
    for s in samples:
        if s[3] and (not seen or seen[-1] != s[3]):
            seen.append(s[3])
    check(wanted, "the program changes no tool")
    check(seen == wanted, "LinuxCNC's tools in the spindle were %s, the program changes to %s" % (seen, wanted))
    return wanted


def longest_boundary_gap(program, samples, segments):
    """The longest standstill (ms: samples with the position unchanged) at the place where
    a segment ends, for every boundary between two segments (it includes a tool change
    when the next segment starts with one)."""
    where = positions(program)
    longest = 0
    for first, last in segments[:-1]:
        boundary = where[last - 1]
        run = best = 0
        for a, b in zip(samples, samples[1:]):
            still = a[4:] == b[4:] and distance(b[4:], boundary) < 0.01
            run = run + 1 if still else 0
            best = max(best, run)
        longest = max(longest, best)
    return longest


def work_offsets():
    """G54.. offsets from the config's parameter file (5221-5223 G54, +20 each next)."""
    params = {}
    for line in open(os.path.join(CONFIG, "hybrid-3axis.var")):
        f = line.split()
        if len(f) == 2:
            params[int(f[0])] = float(f[1])
    return {54 + k: tuple(params.get(5221 + 20 * k + a, 0.0) for a in range(3)) for k in range(6)}


def positions(program):
    """Where each line leaves the machine (machine frame): the X, Y, Z of its moves in
    absolute mode with the work offsets (G53 lines in machine coordinates)."""
    offsets = work_offsets()
    offset = offsets[54]
    pos = [None, None, None]
    out = []
    for text in program:
        code = re.sub(r"\([^)]*\)", "", text.split(";")[0]).upper()
        for g in re.findall(r"G\s*(\d+)", code):
            if 54 <= int(g) <= 59:
                offset = offsets[int(g)]
        machine = re.search(r"G\s*53\b", code) is not None
        if not re.search(r"G\s*(10|43|92)\b", code):
            for a, letter in enumerate("XYZ"):
                m = re.search(letter + r"\s*(-?\d*\.?\d+)", code)
                if m:
                    pos[a] = float(m.group(1)) + (0.0 if machine else offset[a])
        out.append(tuple(pos))
    return out


def final_position_of_program(program):
    return positions(program)[-1]


def case_modbus(args, ini, plan, faults=()):
    cnc = Linuxcnc(ini, args.work)
    try:
        bridge, port, line_log = start_bridge(args, ini, ("--modbus", "tcp://127.0.0.1:0"), faults)
        try:
            r, seconds = run_host(args, plan, "modbus-tcp://127.0.0.1:%d" % port, os.path.join(args.work, "job"))
            time.sleep(0.5)
        finally:
            bridge.stop()
        log = bridge.output()
        check(r.returncode == 0, "hybridctl run exited %d:\n%s\n%s\nbridge:\n%s" %
              (r.returncode, r.stdout[-3000:], r.stderr[-3000:], log[-3000:]))
        program = program_lines(os.path.join(args.work, "job"))
        ran = executed(line_log)
        check_every_line_once(program, ran)
        segments = check_segments(log, len(program))
        print("figure lines %d" % len(program))
        print("figure segments %d" % len(segments))
        print("figure lines_per_second %.0f (%.1f s for the whole run)" % (len(program) / seconds, seconds))
        return cnc, r, program, segments, log
    except BaseException:
        cnc.stop()
        raise


def main():
    p = argparse.ArgumentParser()
    p.add_argument("case", choices=["modbus", "estop", "socketcand"])
    p.add_argument("--hybridctl", required=True)
    p.add_argument("--plan-dir", required=True)
    p.add_argument("--work", required=True)
    args = p.parse_args()
    args.hybridctl = os.path.abspath(args.hybridctl)
    args.plan_dir = os.path.abspath(args.plan_dir)
    args.work = os.path.abspath(args.work)
    ini = prepare_work(args.work)
    plan = pick_deposit_plan(args.plan_dir) if args.case == "socketcand" else pick_plan(args.plan_dir)
    print("plan %d of %s" % (plan, args.plan_dir))
    try:
        globals()["run_" + args.case](args, ini, plan)
    except Failure as e:
        print("FAILED: " + str(e))
        return 1
    print("passed")
    return 0


def run_modbus(args, ini, plan):
    # The link to the bridge is dropped every 500 requests and restored: every check below
    # then also shows that no line ran twice across reconnects and that the program completed.
    cnc, r, program, segments, log = case_modbus(args, ini, plan, faults=("--drop-every", "500"))
    try:
        samples = cnc.samples_at(final_position_of_program(program))
    finally:
        cnc.stop()
    check(samples, "HAL's sampler recorded nothing")
    overruns = [s for a, s in zip(samples, samples[1:]) if s[0] != a[0] + 1]
    print("figure hal_samples %d (%d overruns)" % (len(samples), len(overruns)))
    toggles, misplaced = check_deposition(program, samples)
    tools = check_tools(program, samples)
    print("deposition toggled %d times (%d not within %.0f mm of the program's place), tools %s" %
          (toggles, misplaced, TOGGLE_TOLERANCE_MM, tools))
    print("figure longest_boundary_gap_ms %d" % longest_boundary_gap(program, samples, segments))
    x, y, z = samples[-1][4:]
    hal = (x, y, z)
    wanted = final_position_of_program(program)
    check(all(w is not None and abs(a - w) < 0.002 for a, w in zip(hal, wanted)),
          "LinuxCNC ended at %s (HAL), the program ends at %s" % (hal, wanted))
    m = re.search(r"machine +at X(-?[\d.]+) Y(-?[\d.]+) Z(-?[\d.]+), tool T(\d+), spindle (-?\d+) rpm, "
                  r"deposition (on|off), line (\d+), state (\w+)", r.stdout)
    check(m, "the host's final report gives no machine state:\n" + r.stdout[-2000:])
    host = tuple(float(v) for v in m.groups()[:3])
    check(all(abs(a - b) < 0.002 for a, b in zip(host, hal)),
          "the host reports the end at %s, LinuxCNC's HAL at %s" % (host, hal))
    check(int(m.group(4)) == samples[-1][3], "the host reports tool T%s, LinuxCNC has T%d" % (m.group(4), samples[-1][3]))
    check(m.group(6) == ("on" if samples[-1][1] else "off"), "the host reports deposition %s, HAL %s" %
          (m.group(6), samples[-1][1]))
    check(int(m.group(7)) == len(program) and m.group(8) == "COMPLETED",
          "the host's final report says line %s, state %s; the program has %d lines" % (m.group(7), m.group(8), len(program)))
    m = re.search(r"(\d+) reconnects", r.stdout)
    check(m, "the host's report names no reconnects:\n" + r.stdout[-2000:])
    print("figure host_reconnects %s" % m.group(1))
    check(int(m.group(1)) >= 1, "the host never reconnected: the fault did not strike\n" + r.stdout[-2000:])


def run_socketcand(args, ini, plan):
    cnc = Linuxcnc(ini, args.work)
    try:
        bridge, port, line_log = start_bridge(args, ini, ("--socketcand", "127.0.0.1:0"))
        try:
            r, seconds = run_host(args, plan, "socketcand://127.0.0.1:%d/can0" % port, os.path.join(args.work, "job"))
        finally:
            bridge.stop()
        check(r.returncode == 0, "hybridctl run over socketcand exited %d:\n%s\n%s\nbridge:\n%s" %
              (r.returncode, r.stdout[-3000:], r.stderr[-3000:], bridge.output()[-3000:]))
        program = program_lines(os.path.join(args.work, "job"))
        check_every_line_once(program, executed(line_log))
        print("figure segments %d" % len(check_segments(bridge.output(), len(program))))
        print("figure socketcand_seconds %.1f" % seconds)
        samples = cnc.samples()
    finally:
        cnc.stop()
    check(samples, "HAL's sampler recorded nothing")
    toggles, misplaced = check_deposition(program, samples)
    check(toggles > 0, "the depositing program never switched LinuxCNC's deposition output")
    print("deposition toggled %d times (%d not within %.0f mm of the program's place)" %
          (toggles, misplaced, TOGGLE_TOLERANCE_MM))


def run_estop(args, ini, plan):
    cnc = Linuxcnc(ini, args.work)
    try:
        bridge, port, line_log = start_bridge(args, ini, ("--modbus", "tcp://127.0.0.1:0"))
        try:
            # Without --yes: an operator who does not clear an e-stop (stdin is not a terminal).
            argv = [args.hybridctl, "run", os.path.join(args.plan_dir, "plan.json"), "--plan", str(plan), "--transport",
                    "modbus-tcp://127.0.0.1:%d" % port, "--job", os.path.join(args.work, "job")]
            host = Process(argv, os.path.join(args.work, "host.log"), cwd=args.work)
            # Mid-program: once LinuxCNC executed 1500 lines (of the flanged hub's 6251).
            deadline = time.monotonic() + 300
            while time.monotonic() < deadline and host.proc.poll() is None:
                if os.path.exists(line_log) and sum(1 for _ in open(line_log)) > 1500:
                    break
                time.sleep(0.1)
            check(host.proc.poll() is None, "the host ended before the e-stop:\n" + host.output()[-2000:])
            cnc.estop()
            try:
                host.proc.wait(120)
            except subprocess.TimeoutExpired:
                host.stop()
                raise Failure("the host did not stop within 120 s of the e-stop:\n" + host.output()[-2000:])
            code = host.stop()
        finally:
            bridge.stop()
        out = host.output()
        ran = executed(line_log)
        check(code == 5, "hybridctl run exited %d after the e-stop, expected 5 (the machine stopped):\n%s" %
              (code, out[-2000:]))
        m = re.search(r"EMERGENCY_STOP", out)
        check(m, "the host does not name the alarm EMERGENCY_STOP:\n" + out[-2000:])
        line = ran[-1][0] + 1
        check(re.search(r"line %d\b" % line, out), "the host does not name line %d (LinuxCNC executed through %d):\n%s" %
              (line, ran[-1][0], out[-2000:]))
        check([n for n, _ in ran] == list(range(1, len(ran) + 1)), "lines before the e-stop did not run once each in order")
    finally:
        cnc.stop()


if __name__ == "__main__":
    sys.exit(main())
