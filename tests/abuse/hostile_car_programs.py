#!/usr/bin/env python3
"""A hostile car against hil's four client programs.

Each case puts one client program (logi-client, wr8-client, arduino-client,
leka-client), run as a user runs it, in front of a car that misbehaves in
one way: it never reads, it closes (or falls silent) in the middle of a
frame, it floods telemetry, it answers with another sequence number or
COI, or it sends garbage between its frames. The car is `hil mock` with a
fault profile or scripted behaviours, or, for "never reads", a socket or
pty in this script that nobody reads. The case then checks that the
program stayed up (no signal, no hang), said what happened, exited with
its documented code, and left the car stopped where the link still
allowed it (the stop command is in the car's wire log after the move).

Usage: hostile_car.py --hil PATH --bin DIR --case NAME   (--list for names)
"""

import argparse
import json
import os
import pathlib
import re
import socket
import subprocess
import sys
import tempfile
import time

LIMIT = 60  # seconds any program may take before the case fails as hung


def fail(message, output=""):
    print("FAIL: " + message)
    if output:
        print("---- output ----\n" + output.rstrip() + "\n----------------")
    sys.exit(1)


class SilentTcpCar:
    """A listening socket that never accepts: the kernel completes the
    handshake, and whatever the client writes stays unread."""

    def __enter__(self):
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(4)
        self.where = ["--port", str(self.sock.getsockname()[1])]
        return self

    def __exit__(self, *exc):
        self.sock.close()


class SilentPtyCar:
    """A pseudo-terminal whose car end is never read."""

    def __enter__(self):
        self.master, self.slave = os.openpty()
        self.where = ["--port", os.ttyname(self.slave)]
        return self

    def __exit__(self, *exc):
        os.close(self.master)
        os.close(self.slave)


class MockCar:
    """`hil mock CAR` with a fault profile and scripted behaviours, its
    wire log in `folder`."""

    def __init__(self, hil, car, folder, faults=None, behaviours=None, extra=()):
        self.log = folder / "wire.ndjson"
        args = [hil, "mock", car, "--seed", "7", "--log", str(self.log)]
        if car in ("logi", "wr8"):
            args += ["--port", "0"]
            ready = re.compile(r"tcp://[^ :]+:(\d+)")
        else:
            self.device = str(folder / "car0")
            args += ["--pty", self.device]
            ready = re.compile(r"as a serial port at")
        for name, text in (("faults", faults), ("behaviours", behaviours)):
            if text:
                path = folder / (name + ".yaml")
                path.write_text(text)
                args += ["--" + name, str(path)]
        args += list(extra)
        self.process = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                        text=True)
        self.output = ""
        deadline = time.monotonic() + 15
        while time.monotonic() < deadline:
            line = self.process.stdout.readline()
            if not line:
                break
            self.output += line
            m = ready.search(line)
            if m:
                self.where = ["--port", m.group(1)] if car in ("logi", "wr8") else \
                    ["--port", self.device]
                return
        self.process.kill()
        fail("hil mock did not start", self.output)

    def stop(self):
        self.process.send_signal(2)
        try:
            rest, _ = self.process.communicate(timeout=15)
        except subprocess.TimeoutExpired:
            self.process.kill()
            fail("hil mock did not stop on SIGINT", self.output)
        self.output += rest
        if self.process.returncode != 0:
            fail(f"hil mock exited with {self.process.returncode}", self.output)

    def delivered_to_car(self):
        """(link, text) of every chunk the car received, in order."""
        chunks = []
        for line in self.log.read_text().splitlines():
            record = json.loads(line)
            if record.get("event") == "delivered" and record.get("dir") == "to_car":
                chunks.append((record["link"], record.get("text", "")))
        return chunks


def run_client(program, where, args):
    started = time.monotonic()
    try:
        done = subprocess.run([program] + where + args, stdin=subprocess.DEVNULL,
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              timeout=LIMIT)
    except subprocess.TimeoutExpired as e:
        fail(f"{pathlib.Path(program).name} still running after {LIMIT} s: it hung",
             (e.stdout or b"").decode() if isinstance(e.stdout, bytes) else (e.stdout or ""))
    return done.returncode, done.stdout, time.monotonic() - started


LOGI_DRIVE = ["connect", "speed 50", "mode MAN", "press FWD", "wait 1s", "release", "disconnect"]
WR8_DRIVE = ["connect", "drive 30", "turn 10", "wait 500ms", "turn 0", "disconnect"]
ARDUINO_DRIVE = ["PING", "V 160", "M 20", "S"]
LEKA_DRIVE = ["motor all forward 120", "info", "wait 500ms", "stop robot"]

BEHAVIOURS_HALF_THEN_CLOSE = """behaviours:
  - do: send
    {text}
    after: {after}
  - do: close
    after: {after}
"""

FLOOD = """rules:
  - kind: duplicate
    direction: to_client
    match: "{kind}"
    copies: {copies}
"""
GARBAGE = """rules:
  - kind: garbage
    direction: to_client
    length: [1, 16]
"""

IGNORE_ONCE_AND_SEND = """behaviours:
  - do: ignore
    match: "{match}"
    times: 1
  - do: send
    {text}
    after: "{match}"
"""

# WR8 packets have no start marker: any byte from 0 to 6 begins one, so
# random garbage takes the next packet with it (docs/faults.md, "garbage").
# Noise of other bytes is what a WR8 receiver can skip.
WR8_NOISE = """rules:
  - kind: garbage
    direction: to_client
    hex: "7F FF 41 0D 0A"
"""

# Each case: the program and its arguments, the car (None: silent), what
# the program must exit with and say, and, where the link allows it, the
# move and the stop that must follow it in what the car received.
CASES = {
    # -- a car that never reads --
    "logi-never-reads": dict(
        program="logi-client", car="logi", silent=True, args=LOGI_DRIVE, exit=1,
        says=[r"FAIL speed 50: no feedback to SP within 800ms \(3 sends\), uncertain",
              r"telemetry stale"]),
    "wr8-never-reads": dict(
        program="wr8-client", car="wr8", silent=True, args=WR8_DRIVE, exit=1,
        says=[r"connect +FAIL +AUTH-REPLY timeout"]),
    "arduino-never-reads": dict(
        program="arduino-client", car="arduino", silent=True, args=ARDUINO_DRIVE, exit=1,
        says=[r"PING -> TIMEOUT \(no answer after 4 attempts\)"]),
    "leka-never-reads": dict(
        program="leka-client", car="leka", silent=True, args=LEKA_DRIVE, exit=1,
        says=[r"info: no answer within"]),
    # -- a car that hangs up (or, on a serial line, falls silent) mid-frame --
    "logi-closes-mid-frame": dict(
        # The wait outlasts the 1 s backoff by far, so that reconnect attempt 1
        # goes out before the release on the slowest (sanitized) build too.
        program="logi-client", car="logi",
        args=[("wait 2s" if a == "wait 1s" else a) for a in LOGI_DRIVE],
        behaviours=BEHAVIOURS_HALF_THEN_CLOSE.format(text='text: "LOGI:STAT:SP:050,STA"',
                                                   after="MV:FWD"),
        exit=1, says=[r"WARN not connected \(lost or refused\); reconnecting",
                      r"link reconnect attempt 1",
                      r"FAIL release: refused: no direction held"]),
    "wr8-closes-mid-frame": dict(
        program="wr8-client", car="wr8", args=WR8_DRIVE,
        behaviours=BEHAVIOURS_HALF_THEN_CLOSE.format(text='hex: "06 00 01"', after="TASK"),
        exit=1, says=[r"drive 30 +FAIL +the connection ended before the answer"]),
    "arduino-closes-mid-frame": dict(
        program="arduino-client", car="arduino", args=ARDUINO_DRIVE,
        behaviours=BEHAVIOURS_HALF_THEN_CLOSE.format(text='text: "^03|ACK|O"', after="M"),
        exit=1, says=[r"M 20 -> ACK ACCEPTED", r"S -> TIMEOUT \(no answer after 4 attempts\)",
                      r"link DEGRADED: no answer to a request"]),
    "leka-closes-mid-frame": dict(
        program="leka-client", car="leka", args=LEKA_DRIVE,
        behaviours="""behaviours:
  - do: ignore
    match: info
    times: 1
""" + BEHAVIOURS_HALF_THEN_CLOSE.format(text='text: "LEKA name=le"', after="info")[len("behaviours:\n"):],
        exit=1, says=[r"arg:2: FAILED: info: no answer within 200 ms"]),
    # -- a car that floods its telemetry (or its answers) --
    "logi-floods-stat": dict(
        program="logi-client", car="logi", args=LOGI_DRIVE, faults=FLOOD.format(kind="STAT", copies=40),
        exit=0, says=[r"ok   release", r"ok   disconnect"], stop=("MV:FWD", "MV:STOP")),
    "wr8-floods-data": dict(
        program="wr8-client", car="wr8", args=WR8_DRIVE, mock_args=["--data-hz", "1000"],
        exit=0, says=[r"drive 30 +ok +completed", r"turn 0 +ok +completed"]),
    "arduino-floods-answers": dict(
        program="arduino-client", car="arduino", args=ARDUINO_DRIVE,
        faults=FLOOD.format(kind="ACK", copies=20), exit=0,
        says=[r"M 20 -> ACK ACCEPTED", r"S -> ACK STOPPED"], stop=("|M|", "|S|")),
    "leka-floods-lines": dict(
        program="leka-client", car="leka", args=LEKA_DRIVE,
        faults=FLOOD.format(kind="reply", copies=50), exit=0,
        says=[r"arg:2: ok, .*info name=leka", r"arg:4: ok"]),
    # -- garbage between the car's frames --
    "logi-garbage-between-frames": dict(
        program="logi-client", car="logi", args=LOGI_DRIVE, faults=GARBAGE,
        exit=0, says=[r"WARN dropped a bad frame from the car \(garbage\)", r"ok   release"],
        stop=("MV:FWD", "MV:STOP")),
    "wr8-garbage-between-frames": dict(
        program="wr8-client", car="wr8", args=WR8_DRIVE, faults=WR8_NOISE, exit=0,
        says=[r"drive 30 +ok +completed", r"turn 0 +ok +completed"]),
    "arduino-garbage-between-frames": dict(
        program="arduino-client", car="arduino", args=ARDUINO_DRIVE, faults=GARBAGE,
        exit=0, says=[r"M 20 -> ACK ACCEPTED", r"S -> ACK STOPPED"], stop=("|M|", "|S|")),
    "leka-garbage-between-frames": dict(
        program="leka-client", car="leka", args=LEKA_DRIVE, faults=GARBAGE, exit=0,
        says=[r"arg:2: ok, .*info name=leka"]),
    # -- a car that answers with another command's feedback, SEQ or COI --
    "logi-answers-another-command": dict(
        program="logi-client", car="logi", args=LOGI_DRIVE,
        behaviours=IGNORE_ONCE_AND_SEND.format(match="SP", text='text: "LOGI:FB:MD:1:23#"'),
        exit=0, says=[r"SP sent again \(attempt 2\)"], stop=("MV:FWD", "MV:STOP")),
    "wr8-answers-another-coi": dict(
        program="wr8-client", car="wr8", args=WR8_DRIVE,
        behaviours=IGNORE_ONCE_AND_SEND.format(match="TASK", text='hex: "05 C8 02"'),
        exit=1, says=[r"drive 30 +FAIL +no answer within 500ms"]),
    "arduino-answers-another-seq": dict(
        program="arduino-client", car="arduino", args=ARDUINO_DRIVE,
        behaviours=IGNORE_ONCE_AND_SEND.format(match="V", text='text: "^7E|ACK|OK*3F$"'),
        exit=0, says=[r"V 160 -> ACK OK", r"S -> ACK STOPPED"], stop=("|M|", "|S|"),
        at_least=0.6, log_says=[r"RX seq=7E \^7E\|ACK\|OK\*3F\$"]),
}


def check(case, code, output, seconds, mock, log=None):
    if code < 0:
        fail(f"ended by signal {-code}", output)
    if code != case["exit"]:
        fail(f"exit code {code}, documented {case['exit']} for this case", output)
    for pattern in case.get("says", []):
        if not re.search(pattern, output):
            fail(f"the output does not say /{pattern}/", output)
    for pattern in case.get("log_says", []):
        # The client's own log: the frame it received, taken as valid.
        if not re.search(pattern, log.read_text()):
            fail(f"the client's log does not show /{pattern}/", log.read_text())
    if seconds < case.get("at_least", 0):
        fail(f"done after {seconds:.2f} s: too soon to have waited out the unanswered request",
             output)
    if "stop" in case:
        move, stop = case["stop"]
        wire = "".join(text for _, text in mock.delivered_to_car())
        at = wire.rfind(move)
        if at < 0:
            fail(f"the car never received {move!r}", output + "\n" + wire)
        if wire.find(stop, at) < 0:
            fail(f"the car received {move!r} and no {stop!r} after it: left moving",
                 output + "\n---- the car received ----\n" + wire)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hil")
    parser.add_argument("--bin", help="folder holding <program>/<program>")
    parser.add_argument("--case")
    parser.add_argument("--list", action="store_true")
    parser.add_argument("--probe", action="store_true", help="print, do not judge")
    opts = parser.parse_args()
    if opts.list:
        print("\n".join(CASES))
        return
    case = CASES.get(opts.case)
    if case is None:
        fail(f"no case {opts.case!r}; --list names them")
    program = str(pathlib.Path(opts.bin) / case["program"] / case["program"])
    with tempfile.TemporaryDirectory(prefix="hil-hostile-") as folder:
        folder = pathlib.Path(folder)
        mock = None
        if case.get("silent"):
            silent = SilentTcpCar() if case["car"] in ("logi", "wr8") else SilentPtyCar()
            with silent:
                code, output, seconds = run_client(program, silent.where, case["args"])
        else:
            mock = MockCar(opts.hil, case["car"], folder, case.get("faults"),
                           case.get("behaviours"), case.get("mock_args", ()))
            log = folder / "client-log.txt"
            args = (["--log", str(log)] if "log_says" in case else []) + case["args"]
            try:
                code, output, seconds = run_client(program, mock.where, args)
            finally:
                mock.stop()
        if opts.probe:
            print(f"exit {code} after {seconds:.2f} s\n{output}")
            if mock:
                print("---- car received ----")
                print("".join(t for _, t in mock.delivered_to_car()))
                print("---- mock ----\n" + mock.output)
            return
        check(case, code, output, seconds, mock, None if mock is None else log)
    print(f"PASS {opts.case}: exit {code} after {seconds:.2f} s")


if __name__ == "__main__":
    main()
