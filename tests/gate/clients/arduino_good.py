#!/usr/bin/env python3
# A correct Arduino robot client that follows hil's external-client contract
# (docs/client-contract.md): each operator action arrives on stdin as one
# line (`PING`, `V 160`, `M:20`, `wait 1s`, `reconnect`), and gets one
# "ok ..." or "fail ...: reason" line on stdout once it has ended; "event
# ..." lines report the serial link and each request's outcome. When stdin
# ends it stops the robot if a move may still be running, closes the port
# and exits 0.
#
# It is written from the robot's protocol notes (docs/protocols/arduino.md,
# the board's sketch as the "firmware" profile describes it), the way a
# client team would write theirs, with no hil code:
# - frames ^SEQ|CMD|PAYLOAD*CS$, CS the XOR of the bytes between ^ and *;
#   SEQ counts up from 00 and wraps FF -> 00; a command without an argument
#   carries one space as its payload (an empty one is BAD_FMT to the sketch);
# - one request on the line at a time; a reply counts only when its SEQ is
#   the request's (anything else is stale and ignored);
# - no answer: the same frame again, after 0.6 s, then 1.2 s, 2.4 s, 4.8 s
#   (the timeout doubles), and the request fails after the fourth attempt;
# - NACK BAD_CS: the same frame resent at once, at most three times; any
#   other NACK ends the request with the robot's code;
# - an idle link is checked with PING every 5 s; no answer to it (or to a
#   request) closes the port, which is reopened 0.5 s later and proven with
#   PING, with 1 s, 2 s, 4 s between failed attempts, DOWN after four.
#
# `--bug NAME` plants one realistic bug, so hil's gate tests can show that a
# named scenario rejects exactly that bug:
#   no-bad-cs-resend  NACK BAD_CS is taken as a refusal, like any other NACK
#   any-seq-answer    the next reply is taken as the answer, whatever its SEQ
#   fixed-timeout     every attempt waits 0.6 s; the timeout never doubles
#   pipelining        a request is reported done once written, without its answer
#   no-stop-at-exit   at the end of stdin the port is closed with a move running
#
# Usage: arduino_good.py [--bug NAME] [--profile firmware|readme] [PTY]
#        (PTY defaults to HIL_PTY, the profile to HIL_PROFILE, then firmware)

import argparse
import datetime
import math
import os
import select
import sys
import termios
import time
import tty

BASE_TIMEOUT_S = 0.6
MAX_RETRIES = 3
MAX_BAD_CS_RESENDS = 3
HEALTH_CHECK_S = 5.0
RECONNECT_BASE_S = 0.5
MAX_RECONNECT_FAILURES = 4
RECONNECT_PING_RETRIES = 2
FRAME_GUARD = 256
MS_PER_CM = 18.0    # the board times its moves (protocol page, "Moves")
MS_PER_DEG = 6.0
MOVE_MARGIN_S = 0.2  # a move is taken as over this long after its time
EXIT_BUDGET_S = 4.0  # the contract allows 5 s from the end of stdin to the exit
NO_ARGUMENT = ("PING", "STATUS", "S", "B", "I", "HELP")
BUGS = ("no-bad-cs-resend", "any-seq-answer", "fixed-timeout", "pipelining", "no-stop-at-exit")


def say(line):
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


def xor_of(text):
    cs = 0
    for byte in text.encode("ascii"):
        cs ^= byte
    return cs


def build_frame(seq, cmd, payload):
    body = "%02X|%s|%s" % (seq, cmd, payload)
    return ("^%s*%02X$" % (body, xor_of(body))).encode("ascii")


def parse_reply(raw):
    """(seq, kind, info) of one ^...$ frame from the robot, or a text saying what is wrong."""
    try:
        text = raw.decode("ascii")
    except UnicodeDecodeError:
        return "bad_format: bytes outside ASCII in %r" % raw
    star = text.rfind("*")
    if star < 0 or len(text) - star != 4:
        return "bad_format: no '*' and two checksum digits before '$' in %s" % text
    body, cs_text = text[1:star], text[star + 1:star + 3]
    try:
        cs = int(cs_text, 16)
    except ValueError:
        return "bad_format: checksum '%s' is not hex in %s" % (cs_text, text)
    if cs != xor_of(body):
        return "bad_checksum: %s carries %02X, computed %02X" % (text, cs, xor_of(body))
    fields = body.split("|")
    if len(fields) != 3:
        return "bad_format: %d fields, not 3, in %s" % (len(fields), text)
    seq, kind, info = fields
    try:
        int(seq, 16)
    except ValueError:
        return "bad_format: SEQ '%s' is not two hex digits in %s" % (seq, text)
    if len(seq) != 2 or kind not in ("ACK", "NACK"):
        return "bad_format: not an ACK or NACK with a two-digit SEQ: %s" % text
    return seq.upper(), kind, info


class Framer:
    """Cuts the robot's byte stream into ^...$ frames, with the PC's 256-byte guard."""

    def __init__(self):
        self.buf = b""

    def feed(self, data):
        """Whole frames (bytes) and problems (text) in the order they were read."""
        out = []
        self.buf += data
        while True:
            start = self.buf.find(b"^")
            if start < 0:
                self.buf = b""
                return out
            self.buf = self.buf[start:]
            again = self.buf.find(b"^", 1)
            end = self.buf.find(b"$")
            if again > 0 and (end < 0 or again < end):
                out.append("truncated: a frame cut short by the next '^': %r" % self.buf[:again])
                self.buf = self.buf[again:]
                continue
            if end < 0:
                if len(self.buf) > FRAME_GUARD:
                    out.append("oversized: no '$' within %d bytes" % FRAME_GUARD)
                    self.buf = b""
                return out
            if end + 1 > FRAME_GUARD:
                out.append("oversized: a frame of %d bytes" % (end + 1))
            else:
                out.append(self.buf[:end + 1])
            self.buf = self.buf[end + 1:]


def parse_duration(text):
    """Seconds of `500ms`, `1s`, `1.5s`, or None."""
    for unit, scale in (("ms", 0.001), ("s", 1.0)):
        if text.endswith(unit):
            try:
                value = float(text[:-len(unit)])
            except ValueError:
                return None
            return value * scale if value >= 0 and math.isfinite(value) else None
    return None


def parse_request(words):
    """(cmd, payload, number) of an operator line that is a robot request, or a reason it is not."""
    if len(words) == 1 and ":" in words[0]:  # the robot CLI's raw token, sent as typed
        cmd, _, payload = words[0].partition(":")
        cmd = cmd.upper()
        if not cmd or any(c in words[0] for c in "^$*|"):
            return "'%s' cannot be framed" % words[0]
        try:
            number = int(payload)
        except ValueError:
            number = None
        return cmd, payload, number
    cmd = words[0].upper()
    if cmd in NO_ARGUMENT:
        if len(words) != 1:
            return "%s takes no argument, got '%s'" % (cmd, " ".join(words[1:]))
        return cmd, "", None
    if cmd in ("V", "M", "R"):
        low, high = (0, 255) if cmd == "V" else (-32768, 32767)
        try:
            number = int(words[1]) if len(words) == 2 else None
        except ValueError:
            number = None
        if number is None or not low <= number <= high:
            return "%s needs a whole number %d..%d" % (cmd, low, high)
        return cmd, str(number), number
    return "unknown command '%s'" % words[0]


class Request:
    def __init__(self, cmd, payload, purpose, retries, on_done, number=None):
        self.cmd, self.payload, self.number = cmd, payload, number
        self.purpose = purpose  # "user", "health", "reconnect" or "exit"
        self.retries = retries
        self.on_done = on_done  # on_done(ok, text): text is the ACK's info or the reason
        self.seq = None
        self.frame = b""
        self.move_before = None  # what was known of the robot's motion before it was sent
        self.attempt = 0
        self.bad_cs_resends = 0
        self.deadline = 0.0


class Action:
    def __init__(self, index, text):
        self.index, self.text = index, text
        self.result = None  # the result line, once the action has ended
        self.until = None   # when on_time runs: the end of a wait, a reconnect's reopen
        self.on_time = None


class ArduinoClient:
    def __init__(self, path, profile, bug):
        self.path, self.bug = path, bug
        self.empty_payload = "" if profile == "readme" else " "
        self.fd = None
        self.framer = Framer()
        self.state = "disconnected"
        self.seq = -1  # the first request carries SEQ 00
        self.inflight = None
        self.requests = []   # waiting for the line, in order
        self.backlog = []    # replies read while no request was waiting
        self.actions = []    # operator actions not yet started, in order
        self.running = None  # the action under way
        self.results = {}    # index -> result line, printed in order
        self.next_index = self.next_print = 0
        self.last_exchange = time.monotonic()
        self.reconnect_at = None
        self.reconnect_failures = 0
        self.move_until = None  # when a move may still run; math.inf when unknown
        self.log = []
        self.stdin_buf = b""
        self.stdin_open = True

    # ---- the serial port ----

    def open_port(self):
        try:
            fd = os.open(self.path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        except OSError as e:
            return "cannot open %s: %s" % (self.path, e.strerror)
        try:
            tty.setraw(fd)
            attrs = termios.tcgetattr(fd)
            attrs[4] = attrs[5] = termios.B9600
            termios.tcsetattr(fd, termios.TCSANOW, attrs)
        except termios.error as e:
            os.close(fd)
            return "%s is not a serial port: %s" % (self.path, e.args[-1])
        self.fd = fd
        self.framer = Framer()
        self.move_until = None  # opening the port resets the board: its motors stop
        return None

    def close_port(self):
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None

    def set_state(self, state):
        if state != self.state:
            self.state = state
            say("event connection %s" % state)

    def write(self, frame):
        self.log.append((datetime.datetime.now(datetime.timezone.utc), "TX", frame))
        try:
            os.write(self.fd, frame)
        except OSError as e:
            say("write failed: %s" % e.strerror)

    # ---- requests: one on the line at a time ----

    def request(self, cmd, payload, purpose, on_done, retries=MAX_RETRIES, number=None, first=False):
        req = Request(cmd, payload, purpose, retries, on_done, number)
        if self.bug == "pipelining" and purpose == "user" and self.state == "connected":
            self.send_new(req)  # the bug: written at once, reported done without its answer
            on_done(True, "(written)")
            return
        if first:
            self.requests.insert(0, req)
        else:
            self.requests.append(req)
        self.pump()

    def pump(self):
        if self.inflight or self.fd is None or not self.requests:
            return
        if self.state != "connected" and self.requests[0].purpose != "reconnect":
            return
        req = self.requests.pop(0)
        self.inflight = req
        self.send_new(req)
        backlog, self.backlog = self.backlog, []
        for reply in backlog:  # replies that came while nothing waited: stale, unless the bug
            self.on_reply(reply)

    def send_new(self, req):
        self.seq = (self.seq + 1) % 256
        req.seq = "%02X" % self.seq
        req.frame = build_frame(self.seq, req.cmd, req.payload or self.empty_payload)
        req.move_before = self.move_until
        if req.cmd in ("M", "R") and req.number != 0:
            self.move_until = math.inf  # the board may act on it even if its answer is lost
        self.send_current(req)

    def timeout_of(self, attempt):
        return BASE_TIMEOUT_S if self.bug == "fixed-timeout" else BASE_TIMEOUT_S * 2 ** attempt

    def send_current(self, req):
        req.deadline = time.monotonic() + self.timeout_of(req.attempt)
        self.write(req.frame)

    def on_reply(self, reply):
        seq, kind, info = reply
        req = self.inflight
        if req is None:
            if self.bug == "any-seq-answer":
                self.backlog.append(reply)
            else:
                say("ignored a reply with SEQ %s: no request is waiting" % seq)
            return
        if seq != req.seq and self.bug != "any-seq-answer":
            say("ignored a stale reply with SEQ %s while %s waits with SEQ %s" % (seq, req.cmd, req.seq))
            return
        if kind == "NACK" and info == "BAD_CS" and self.bug != "no-bad-cs-resend" \
                and req.bad_cs_resends < MAX_BAD_CS_RESENDS:
            req.bad_cs_resends += 1
            self.send_current(req)  # the same frame, at once; not a retry
            return
        self.finish(kind == "ACK", info if kind == "ACK" else "NACK %s" % info)

    def finish(self, ok, text, answered=True):
        req, self.inflight = self.inflight, None
        if req.cmd in ("M", "R") and answered:
            if not ok:
                self.move_until = req.move_before  # a refused move changes nothing
            elif req.number == 0:
                self.move_until = None
            elif req.number is not None:
                per = MS_PER_CM if req.cmd == "M" else MS_PER_DEG
                self.move_until = time.monotonic() + abs(req.number) * per / 1000 + MOVE_MARGIN_S
        if req.cmd == "S" and ok:
            self.move_until = None
        if req.purpose != "reconnect":
            self.last_exchange = time.monotonic()
        req.on_done(ok, text)
        if not answered and req.purpose in ("user", "health"):
            self.link_failed("no answer to %s" % ("the health check" if req.purpose == "health"
                                                  else req.cmd))
        self.pump()

    # ---- the link: health check and reconnects ----

    def link_failed(self, why):
        if self.state != "connected":
            return
        say("link degraded: %s" % why)
        self.set_state("degraded")
        self.drop_port()
        self.reconnect_at = time.monotonic() + RECONNECT_BASE_S

    def drop_port(self):
        self.close_port()
        if self.inflight:
            req, self.inflight = self.inflight, None
            req.on_done(False, "the port closed before the answer")

    def reconnect_due(self):
        self.reconnect_at = None
        self.set_state("reconnecting")
        why = self.open_port()
        if why:
            self.reconnect_failed(why)
            return

        def proven(ok, text):
            if ok:
                self.reconnect_failures = 0
                self.last_exchange = time.monotonic()
                self.set_state("connected")
                self.pump()
            else:
                self.close_port()
                self.reconnect_failed("no ACK to PING on the reopened port")

        self.request("PING", "", "reconnect", proven, RECONNECT_PING_RETRIES, first=True)

    def reconnect_failed(self, why):
        self.reconnect_failures += 1
        say("reconnect attempt %d failed: %s" % (self.reconnect_failures, why))
        if self.reconnect_failures >= MAX_RECONNECT_FAILURES:
            self.set_state("down")
            for req in self.requests:
                req.on_done(False, "the link is down")
            self.requests = []
        else:
            self.reconnect_at = time.monotonic() + RECONNECT_BASE_S * 2 ** self.reconnect_failures

    def health_due(self):
        """When the idle link's next health-check PING is due, or None."""
        if self.state != "connected" or not self.stdin_open or self.inflight or self.requests:
            return None
        return self.last_exchange + HEALTH_CHECK_S

    def on_timer(self, now):
        if self.inflight and now >= self.inflight.deadline:
            req = self.inflight
            if req.attempt < req.retries:
                req.attempt += 1
                self.send_current(req)
            else:
                why = "no answer after %d attempts (timeout)" % (req.attempt + 1)
                self.finish(False, why, answered=False)
        if self.reconnect_at is not None and now >= self.reconnect_at:
            self.reconnect_due()
        due = self.health_due()
        if due is not None and now >= due:
            self.request("PING", "", "health", lambda ok, text: None)
        action = self.running
        if action and action.until is not None and now >= action.until:
            action.until = None
            action.on_time()

    def next_wakeup(self):
        times = [t for t in (self.inflight and self.inflight.deadline, self.reconnect_at,
                             self.health_due(), self.running and self.running.until)
                 if t is not None]
        return min(times) if times else None

    # ---- operator actions ----

    def on_line(self, text):
        text = text.split("#", 1)[0].strip()
        if not text:
            return
        action = Action(self.next_index, text)
        self.next_index += 1
        # An emergency stop does not wait for the action under way (a wait, a
        # slow request): it takes the line as soon as it is free; its result
        # still comes in order. Behind actions not yet started it keeps its place.
        if text.upper() == "S" and self.running and not self.actions:
            self.start_request(action, text.split())
            return
        self.actions.append(action)
        self.start_next()

    def start_next(self):
        while self.running is None and self.actions:
            action = self.actions.pop(0)
            self.running = action
            self.start(action)

    def start(self, action):
        words = action.text.split()
        verb = words[0].lower()
        if verb == "wait":
            seconds = parse_duration(words[1]) if len(words) == 2 else None
            if seconds is None:
                self.action_done(action, False, "wait needs a duration such as 500ms or 1s")
            else:
                action.until = time.monotonic() + seconds
                action.on_time = lambda: self.action_done(action, True, "")
        elif verb == "reconnect" and len(words) == 1:
            self.reconnect_action(action)
        elif verb in ("quit", "exit") and len(words) == 1:
            self.action_done(action, True, "(the run decides when the client ends)")
        elif verb == "history" and len(words) == 1:
            for line in self.log_lines():
                say("  " + line)
            self.action_done(action, True, "%d frame(s)" % len(self.log))
        elif verb == "save-log" and len(words) >= 2:
            self.save_log(action, action.text.split(None, 1)[1])
        else:
            self.start_request(action, words)

    def start_request(self, action, words):
        parsed = parse_request(words)
        if isinstance(parsed, str):
            self.action_done(action, False, parsed)
            return
        cmd, payload, number = parsed
        if self.state == "down" or (self.fd is None and self.state == "disconnected"):
            self.action_done(action, False, "the link is down")
            return

        def done(ok, text):
            state = "ok" if ok else ("nack" if text.startswith("NACK") else
                                     "timeout" if "timeout" in text else "link_down")
            say("event command %s %s" % (cmd, state))
            self.action_done(action, ok, text)

        urgent = action is not self.running
        self.request(cmd, payload, "user", done, number=number, first=urgent)

    def reconnect_action(self, action):
        self.reconnect_at = None
        self.drop_port()
        self.set_state("disconnected")

        def reopen():
            self.set_state("connecting")
            why = self.open_port()
            if why:
                self.set_state("down")
                self.action_done(action, False, why)
                return
            self.reconnect_failures = 0
            self.last_exchange = time.monotonic()
            self.set_state("connected")
            self.action_done(action, True, "link OPEN")
            self.pump()

        action.until = time.monotonic() + RECONNECT_BASE_S  # the board sees the hang-up
        action.on_time = reopen

    def action_done(self, action, ok, text):
        if action.result is not None:
            return
        action.until = None
        action.result = ("ok %s %s" % (action.text, text)).rstrip() if ok \
            else "fail %s: %s" % (action.text, text)
        self.results[action.index] = action.result
        while self.next_print in self.results:
            say(self.results.pop(self.next_print))
            self.next_print += 1
        if action is self.running:
            self.running = None
            self.start_next()

    def log_lines(self):
        for when, direction, raw in self.log:
            stamp = when.strftime("%Y-%m-%dT%H:%M:%S.") + "%03dZ" % (when.microsecond // 1000)
            yield "%s %s %s" % (stamp, direction, raw.decode("ascii", "replace"))

    def save_log(self, action, path):
        try:
            with open(path, "w", encoding="utf-8") as f:
                for line in self.log_lines():
                    f.write(line + "\n")
        except OSError as e:
            self.action_done(action, False, "cannot write %s (%s)" % (path, e.strerror))
            return
        self.action_done(action, True, "saved %d frame(s) to %s" % (len(self.log), path))

    # ---- input ----

    def read_port(self):
        try:
            data = os.read(self.fd, 512)
        except BlockingIOError:
            return
        except OSError:
            data = b""
        if not data:
            say("the serial port closed")
            self.drop_port()
            if self.state == "connected":
                self.set_state("degraded")
                self.reconnect_at = time.monotonic() + RECONNECT_BASE_S
            return
        for item in self.framer.feed(data):
            raw = item if isinstance(item, bytes) else ("(dropped) " + item).encode("ascii", "replace")
            self.log.append((datetime.datetime.now(datetime.timezone.utc), "RX", raw))
            reply = parse_reply(item) if isinstance(item, bytes) else item
            if isinstance(reply, str):
                say("event parse_error %s" % reply)  # the attempt's timeout will retry
            else:
                self.on_reply(reply)

    def read_stdin(self):
        data = os.read(0, 4096)
        if not data:
            self.stdin_open = False
            if self.stdin_buf:
                self.on_line(self.stdin_buf.decode("utf-8", "replace"))
            return
        self.stdin_buf += data
        while b"\n" in self.stdin_buf:
            line, self.stdin_buf = self.stdin_buf.split(b"\n", 1)
            self.on_line(line.decode("utf-8", "replace"))

    def step(self, until=None):
        """Waits for input or the next timer (at most until `until`), and handles it."""
        now = time.monotonic()
        self.on_timer(now)
        wake = self.next_wakeup()
        if until is not None:
            wake = min(wake, until) if wake else until
        fds = ([0] if self.stdin_open else []) + ([self.fd] if self.fd is not None else [])
        ready, _, _ = select.select(fds, [], [], None if wake is None else max(0.0, wake - now))
        if 0 in ready:
            self.read_stdin()
        if self.fd is not None and self.fd in ready:
            self.read_port()

    # ---- the whole run ----

    def run(self):
        self.set_state("connecting")
        why = self.open_port()
        if why:
            say("link down: %s" % why)
            self.set_state("down")
        else:
            self.set_state("connected")
            self.last_exchange = time.monotonic()
        while self.stdin_open:
            self.step()
        self.finish_run(time.monotonic() + EXIT_BUDGET_S)

    def finish_run(self, deadline):
        """The end of stdin: finish the actions, stop the robot if it may move, close."""
        actions_until = deadline - 1.5  # what is left then is dropped, so S has its time
        while (self.running or self.actions) and time.monotonic() < actions_until:
            self.step(actions_until)
        self.reconnect_at = None
        pending, self.actions = self.actions, []
        action = self.running
        if action is not None and action.result is None and action.until is not None:
            self.action_done(action, False, "the input ended before it was over")
        for action in pending:
            self.action_done(action, False, "the input ended before it started")
        while (self.inflight or self.requests) and time.monotonic() < deadline:
            self.step(deadline)
        moving = self.move_until is not None and time.monotonic() < self.move_until
        if moving and self.bug != "no-stop-at-exit" and self.fd is not None \
                and self.state == "connected":
            stopped = []
            self.request("S", "", "exit", lambda ok, text: stopped.append((ok, text)), retries=1)
            while not stopped and time.monotonic() < deadline:
                self.step(deadline)
            say("stopped the robot at the end: %s" % (stopped[0][1] if stopped else "no answer"))
        self.close_port()
        if self.state not in ("down", "disconnected"):
            self.set_state("disconnected")


def main(argv=None):
    parser = argparse.ArgumentParser(description="An Arduino robot client for hil's gate.")
    parser.add_argument("pty", nargs="?", default=os.environ.get("HIL_PTY", ""))
    parser.add_argument("--profile", default=os.environ.get("HIL_PROFILE") or "firmware",
                        choices=("firmware", "readme"))
    parser.add_argument("--bug", choices=BUGS, help="plant one known bug (for hil's own tests)")
    args = parser.parse_args(argv)
    if not args.pty:
        parser.error("no serial port: give PTY or set HIL_PTY")
    ArduinoClient(args.pty, args.profile, args.bug).run()
    return 0


if __name__ == "__main__":
    sys.exit(main())
