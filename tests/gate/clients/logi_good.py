#!/usr/bin/env python3
# A small, correct LOGI upper computer that follows hil's external-client
# contract (docs/client-contract.md): operator actions arrive on stdin one
# line at a time, each gets one "ok ..." or "fail ...: reason" line on
# stdout, and "event ..." lines report what the client saw. When stdin
# ends it stops the car if it may be moving, disconnects and exits 0.
#
# It is written from the LOGI protocol notes alone (no hil code), the way a
# client team would write theirs: a stream-safe frame parser, one command
# in flight with an 800 ms feedback timeout, SP/MD/MV:STOP retried twice,
# ST:RUN and GS never resent without "confirm", MV:STOP after a move that
# got no feedback, the emergency stop's ST:STOP repeated every timeout
# until the car answers it, reconnect after 1 s, 2 s, 3 s and then every
# 3 s, a stale warning after more than 2 s without STAT (cleared only by
# a STAT, on this connection or the next), movement refused (and reported
# disabled) until a mode and a speed were sent on the connection, and each
# dropped frame reported as a parse error. Each action runs as its own
# task, so an estop that arrives while a slow command waits goes out at
# once; result lines still come in the order the actions came.
#
# The deliberately broken clients next to it (logi_*_bug.py) are this
# client with one method replaced, so the gate can show that it rejects
# exactly that bug. `--bug NAME` plants one more realistic bug, a small
# change to this file's own code, so the LOGI scenario library's gate
# tests can show which scenario rejects it (BUGS below lists them).
#
# Usage: logi_good.py [--bug NAME] HOST PORT
#        (or HIL_HOST / HIL_PORT in the environment)

import argparse
import asyncio
import os
import signal
import sys
import threading

FEEDBACK_TIMEOUT_S = 0.8
RESENT_KINDS = ("SP", "MD:MAN", "MD:AUTO", "MV:STOP")  # idempotent: resent up to twice
MAX_RETRIES = 2
RECONNECT_DELAYS_S = (1.0, 2.0, 3.0)  # the last one repeats
STALE_AFTER_S = 2.0
CONNECT_TIMEOUT_S = 10.0
DIRECTIONS = ("STOP", "FWD", "BWD", "LEFT", "RIGHT", "LF", "RF", "LB", "RB", "CW", "CCW")

# The bugs `--bug NAME` plants, each the rule of the LOGI car's
# documentation that it breaks.
BUGS = {
    "backoff-never-restarts":
        "the reconnect waits keep growing after a connection that was up (section 5.1)",
    "estop-st-stop-first":
        "the emergency stop writes ST:STOP before MV:STOP (section 5.5)",
    "exit-without-stop":
        "at the end of stdin it disconnects without stopping a car that may be moving",
    "drop-keeps-in-flight":
        "a dropped connection cancels the queue but not the command in flight, which times out later",
    "retry-moves":
        "a move (MV:<dir>) is resent after a feedback timeout, like SP (section 5.3)",
    "retry-gs":
        "GS is resent after a feedback timeout without the operator's confirmation (section 5.3)",
    "any-frame-fresh":
        "any valid frame, FB included, clears the stale warning, not only STAT (section 5.5)",
}


def build_frame(payload):
    base = "LOGI:" + payload
    return "%s:%02X#" % (base, sum(base.encode("ascii")) & 0xFF)


def check_frame(raw):
    """(payload, None) for a valid whole frame (bytes), or (None, why) with
    why naming what was wrong: "bad_format: ..." or "bad_checksum: ..."."""
    try:
        text = raw.decode("ascii")
    except UnicodeDecodeError:
        return None, "bad_format: a byte outside ASCII"
    if not text.startswith("LOGI:") or not text.endswith("#"):
        return None, "bad_format: not a LOGI:...# frame"
    base, sep, cs = text[:-1].rpartition(":")
    if not sep or len(base) <= len("LOGI"):
        return None, "bad_format: no ':' before the checksum"
    if len(cs) != 2 or cs != cs.upper() or any(ch not in "0123456789ABCDEF" for ch in cs):
        return None, "bad_format: checksum '%s' is not two uppercase hex digits" % cs
    expected = sum(base.encode("ascii")) & 0xFF
    if int(cs, 16) != expected:
        return None, "bad_checksum: checksum %s, computed %02X" % (cs, expected)
    payload = base[len("LOGI:"):]
    if not payload:
        return None, "bad_format: an empty payload"
    return payload, None


def frame_payload(raw):
    """The payload of one whole frame (bytes), or None if it is not a valid one."""
    return check_frame(raw)[0]


class StreamFrames:
    """Frames out of a byte stream, however it was cut: a buffer, searched
    for the header and the tail, garbage before a header discarded."""

    MAX_FRAME = 512

    def __init__(self):
        self.buf = b""
        self.skipped = 0  # bytes discarded since the last header
        self.garbage = []  # how many bytes each run of garbage had, once a header ended it

    def feed(self, data):
        self.buf += data
        frames = []
        while True:
            start = self.buf.find(b"LOGI:")
            if start < 0:
                # Keep what could be the start of a header cut in two.
                self.skipped += max(0, len(self.buf) - 4)
                self.buf = self.buf[-4:]
                return frames
            if start > 0 or self.skipped:
                self.garbage.append(self.skipped + start)
                self.skipped = 0
                self.buf = self.buf[start:]
                start = 0
            end = self.buf.find(b"#", start)
            if end < 0:
                self.buf = self.buf[start:]
                if len(self.buf) > self.MAX_FRAME:
                    self.buf = self.buf[1:]  # no tail for too long: resync
                    continue
                return frames
            # A header inside the candidate: the frame before it was cut off.
            restart = self.buf.rfind(b"LOGI:", start + 1, end)
            if restart >= 0:
                self.garbage.append(restart - start)
                start = restart
            frames.append(self.buf[start:end + 1])
            self.buf = self.buf[end + 1:]


def say(line):
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


class Command:
    def __init__(self, payload, kind, loop):
        self.payload = payload
        self.kind = kind  # "SP", "MD:MAN", "MV:FWD", "ST:RUN", "GS" ...
        self.code = payload.split(":")[0]  # what its FB names
        self.sends = 0
        self.retries_left = MAX_RETRIES if kind in RESENT_KINDS else 0
        self.mode_switch_left = 1 if kind.startswith("MV:") and kind != "MV:STOP" else 0
        self.done = loop.create_future()  # -> "accepted" | "rejected" | "uncertain" | "cancelled"
        self.timer = None
        self.emergency = False


class LogiClient:
    def __init__(self, host, port, bug=None):
        self.host = host
        self.port = port
        self.bug = bug  # one of BUGS, or None for the correct client
        self.loop = asyncio.get_running_loop()
        self.state = "disconnected"
        self.want_connected = False
        self.conn_task = None
        self.writer = None
        self.connected_waiters = []
        self.queue = []
        self.in_flight = []
        self.mode_sent = False
        self.speed_sent = False
        self.known_mode = None
        self.held = None
        self.last_status = {}
        self.stale = False
        self.stale_timer = None
        self.confirmable = None
        self.movement_reported = None  # the movement state last reported, once one was

    # ---- hooks the broken clients replace ----

    def make_frame_reader(self):
        return StreamFrames()

    def reconnect_delay(self, failures_in_a_row):
        return RECONNECT_DELAYS_S[min(failures_in_a_row, len(RECONNECT_DELAYS_S) - 1)]

    # ---- connection ----

    def set_state(self, state):
        self.state = state
        say("event connection " + state)
        self.update_movement()
        if state == "connected":
            for w in self.connected_waiters:
                if not w.done():
                    w.set_result(True)
            self.connected_waiters = []

    async def connection_loop(self):
        failures = 0
        while self.want_connected:
            self.set_state("connecting")
            got_valid_frame = False
            try:
                reader, writer = await asyncio.open_connection(self.host, self.port)
            except OSError:
                reader = None
            if reader is not None:
                if not self.want_connected:
                    writer.close()
                    return
                self.writer = writer
                self.mode_sent = self.speed_sent = False
                self.set_state("connected")
                self.arm_stale()
                got_valid_frame = await self.read_frames(reader)
                if not self.want_connected:
                    return
                self.lost()
            if got_valid_frame and self.bug != "backoff-never-restarts":
                failures = 0
            self.set_state("reconnecting")
            await asyncio.sleep(self.reconnect_delay(failures))
            failures += 1

    async def read_frames(self, reader):
        """Reads until the connection ends; whether a valid frame came."""
        frames = self.make_frame_reader()
        any_valid = False
        while True:
            try:
                data = await reader.read(4096)
            except (OSError, asyncio.CancelledError):
                data = b""
            if not data:
                return any_valid
            got = frames.feed(data)
            for count in getattr(frames, "garbage", ()):
                say("event parse_error garbage: %d bytes that start no frame" % count)
            if hasattr(frames, "garbage"):
                frames.garbage = []
            for raw in got:
                payload, why = check_frame(raw)
                if payload is None:
                    say("event parse_error " + why)
                    continue
                any_valid = True
                self.on_frame(payload)

    def lost(self):
        """The safe state after a drop or a disconnect."""
        if self.writer is not None:
            self.writer.close()
            self.writer = None
        if self.stale_timer is not None:
            self.stale_timer.cancel()
            self.stale_timer = None
        self.held = None
        self.known_mode = None
        self.mode_sent = self.speed_sent = False
        self.confirmable = None
        self.last_status = {}
        # The stale warning stays up until a STAT arrives, on this connection or the next.
        dropped = self.queue if self.bug == "drop-keeps-in-flight" else self.in_flight + self.queue
        for c in list(dropped):
            self.finish(c, "cancelled")
        if self.bug != "drop-keeps-in-flight":
            self.in_flight = []
        self.queue = []

    async def connect(self):
        if self.state == "connected":
            return True, ""
        waiter = self.loop.create_future()
        self.connected_waiters.append(waiter)
        if not self.want_connected:
            self.want_connected = True
            self.conn_task = self.loop.create_task(self.connection_loop())
        try:
            await asyncio.wait_for(waiter, CONNECT_TIMEOUT_S)
            return True, ""
        except asyncio.TimeoutError:
            await self.disconnect()
            return False, "not connected after %ds" % CONNECT_TIMEOUT_S

    async def disconnect(self):
        was = self.want_connected or self.state != "disconnected"
        self.want_connected = False
        if self.conn_task is not None:
            self.conn_task.cancel()
            self.conn_task = None
        self.lost()
        if was:
            self.set_state("disconnected")

    # ---- telemetry ----

    def arm_stale(self):
        if self.stale_timer is not None:
            self.stale_timer.cancel()
        self.stale_timer = self.loop.call_later(STALE_AFTER_S, self.go_stale)

    def go_stale(self):
        self.stale_timer = None
        if self.state == "connected" and not self.stale:
            self.stale = True
            say("event stale")

    def on_frame(self, payload):
        if self.bug == "any-frame-fresh":
            if self.stale:
                self.stale = False
                say("event fresh")
            self.arm_stale()
        if payload.startswith("STAT:"):
            fields = {}
            for item in payload[len("STAT:"):].split(","):
                key, _, value = item.partition(":")
                fields[key] = value
            self.last_status = fields
            if fields.get("MODE") in ("MAN", "AUTO"):
                self.known_mode = fields["MODE"]
            if self.stale:
                self.stale = False
                say("event fresh")
            self.arm_stale()
            return
        if payload.startswith("FB:"):
            parts = payload.split(":")
            if len(parts) != 3 or parts[2] not in ("0", "1"):
                return
            code, accepted = parts[1], parts[2] == "1"
            for c in self.in_flight:
                if c.code == code:
                    self.on_feedback(c, accepted)
                    return
            sys.stderr.write("feedback that answers nothing sent: %s\n" % payload)

    # ---- commands ----

    def send(self, c):
        c.sends += 1
        self.writer.write(build_frame(c.payload).encode("ascii"))
        say("event command %s sent" % c.kind)
        c.timer = self.loop.call_later(FEEDBACK_TIMEOUT_S, self.on_timeout, c)

    def finish(self, c, outcome):
        if c.timer is not None:
            c.timer.cancel()
            c.timer = None
        if c in self.in_flight:
            self.in_flight.remove(c)
        if not c.done.done():
            say("event command %s %s" % (c.kind, outcome))
            c.done.set_result(outcome)
        self.pump()

    def on_feedback(self, c, accepted):
        if c.timer is not None:
            c.timer.cancel()
            c.timer = None
        if accepted:
            if c.kind.startswith("MD:"):
                self.known_mode = c.kind[3:]
            self.finish(c, "accepted")
            return
        if c.mode_switch_left and not c.emergency:
            # Moves are refused in AUTO: switch to MAN and try once more.
            c.mode_switch_left = 0
            say("event notice Not in manual mode, switching to MAN")
            self.in_flight.remove(c)
            md = Command("MD:MAN", "MD:MAN", self.loop)
            self.queue[0:0] = [md, c]
            self.pump()
            return
        self.finish(c, "rejected")

    def on_timeout(self, c):
        c.timer = None
        if (c.retries_left > 0 or self.resent_anyway(c)) and self.writer is not None:
            c.retries_left -= 1
            self.send(c)
            return
        if c.emergency and c.kind == "ST:STOP" and self.writer is not None:
            # The stop that ends an auto run: repeated until the car answers.
            self.send(c)
            return
        if c.kind in ("ST:RUN", "GS"):
            self.confirmable = c
        if c.kind.startswith("MV:") and c.kind != "MV:STOP":
            # The car may have taken the move: fail safe with MV:STOP, first in line.
            self.queue.insert(0, Command("MV:STOP", "MV:STOP", self.loop))
        self.finish(c, "uncertain")

    def resent_anyway(self, c):
        """Whether a planted bug resends a command the rules say must not be."""
        if c.sends > MAX_RETRIES:
            return False
        if self.bug == "retry-moves" and c.kind.startswith("MV:"):
            return True
        return self.bug == "retry-gs" and c.kind == "GS"

    def pump(self):
        """One command in flight: the next one goes when the line is free."""
        if self.writer is None:
            return
        if any(not c.emergency for c in self.in_flight):
            return
        if self.queue:
            c = self.queue.pop(0)
            self.in_flight.append(c)
            self.send(c)

    async def command(self, payload, kind):
        if self.state != "connected":
            return False, "not connected"
        c = Command(payload, kind, self.loop)
        self.queue.append(c)
        self.pump()
        return self.outcome(kind, await c.done)

    def outcome(self, kind, result):
        if result == "accepted":
            return True, ""
        if result == "rejected":
            return False, "rejected by the car (FB:%s:0)" % kind.split(":")[0]
        if result == "uncertain":
            why = "no feedback to %s, uncertain" % kind
            if kind in ("ST:RUN", "GS"):
                why += "; 'confirm' sends it again"
            return False, why
        return False, "cancelled: the connection was lost"

    def update_movement(self):
        """Reports the movement controls enabled or disabled when that changes."""
        refused = self.movement_refused()
        enabled = refused is None
        if self.movement_reported == enabled:
            return
        self.movement_reported = enabled
        say("event movement enabled" if enabled else "event movement disabled " +
            ("not connected" if self.state != "connected" else "mode and speed not sent"))

    def movement_refused(self):
        if self.state != "connected":
            return "not connected"
        if not (self.mode_sent and self.speed_sent):
            return "refused: movement needs a 'mode' and a 'speed' on this connection first"
        return None

    async def emergency_stop(self):
        if self.state != "connected":
            return False, "not connected"
        self.held = None
        # Queued movement must not undo the stop.
        for c in [c for c in self.queue if c.kind.startswith("MV:") or c.kind == "ST:RUN"]:
            self.queue.remove(c)
            self.finish(c, "cancelled")
        stops = [Command("MV:STOP", "MV:STOP", self.loop)]
        if self.known_mode != "MAN":
            stops.append(Command("ST:STOP", "ST:STOP", self.loop))
        if self.bug == "estop-st-stop-first":
            stops.reverse()
        for c in stops:
            c.emergency = True
            c.mode_switch_left = 0
            self.in_flight.append(c)
            self.send(c)
        results = [await c.done for c in stops]
        if "accepted" in results:
            return True, ""
        return False, "; ".join(self.outcome(c.kind, r)[1] for c, r in zip(stops, results))

    def may_be_moving(self):
        s = self.last_status
        return self.held is not None or s.get("RUN") == "1" or s.get("MAN", "STOP") != "STOP"

    # ---- operator actions ----

    async def action(self, text):
        words = text.split()
        verb = words[0].lower()
        arg = words[1] if len(words) > 1 else None
        if len(words) > 2:
            return False, "unexpected '%s'" % words[2]
        if verb == "connect":
            return await self.connect()
        if verb == "disconnect":
            await self.disconnect()
            return True, ""
        if verb == "speed" and arg is not None and arg.isdigit() and int(arg) <= 100:
            ok, why = await self.command("SP:%03d" % int(arg), "SP")
            if ok:
                self.speed_sent = True
                self.update_movement()
            return ok, why
        if verb == "mode" and arg is not None and arg.upper() in ("MAN", "AUTO"):
            m = arg.upper()
            ok, why = await self.command("MD:" + m, "MD:" + m)
            if ok:
                self.mode_sent = True
                self.update_movement()
            return ok, why
        if verb == "press" and arg is not None and arg.upper() in DIRECTIONS:
            d = arg.upper()
            if d != "STOP":
                refused = self.movement_refused()
                if refused:
                    return False, refused
                self.held = d
            return await self.command("MV:" + d, "MV:" + d)
        if verb == "release" and arg is None:
            if self.held is None:
                return False, "no direction held"
            self.held = None
            return await self.command("MV:STOP", "MV:STOP")
        if verb == "station" and arg is not None and arg.isdigit() and 1 <= int(arg) <= 999:
            return await self.command("GS:%03d" % int(arg), "GS")
        if verb == "run" and arg is None:
            refused = self.movement_refused()
            if refused:
                return False, refused
            return await self.command("ST:RUN", "ST:RUN")
        if verb == "stop" and arg is None:
            return await self.command("ST:STOP", "ST:STOP")
        if verb == "estop" and arg is None:
            return await self.emergency_stop()
        if verb == "wait" and arg is not None:
            seconds = parse_duration(arg)
            if seconds is None:
                return False, "expected a duration with a unit, got '%s'" % arg
            await asyncio.sleep(seconds)
            return True, ""
        if verb == "confirm" and arg is None:
            c = self.confirmable
            self.confirmable = None
            if c is None:
                return False, "nothing to confirm"
            return await self.command(c.payload, c.kind)
        return False, "not an action this client knows"

    async def shut_down(self):
        if self.state == "connected" and self.may_be_moving() and self.bug != "exit-without-stop":
            try:
                await asyncio.wait_for(self.emergency_stop(), 3.0)
            except asyncio.TimeoutError:
                pass
        await self.disconnect()


def parse_duration(text):
    for unit, scale in (("ms", 0.001), ("min", 60.0), ("s", 1.0), ("m", 60.0)):
        if text.endswith(unit):
            try:
                value = float(text[: -len(unit)])
            except ValueError:
                return None
            return value * scale if value >= 0 else None
    return None


def stdin_lines(loop, queue):
    """Reads stdin on a thread, so the event loop never blocks on it."""
    for line in sys.stdin:
        loop.call_soon_threadsafe(queue.put_nowait, line.rstrip("\r\n"))
    loop.call_soon_threadsafe(queue.put_nowait, None)


def parse_args():
    parser = argparse.ArgumentParser(description="A LOGI client for hil's external-client contract")
    parser.add_argument("host", nargs="?", default=os.environ.get("HIL_HOST", "127.0.0.1"))
    parser.add_argument("port", nargs="?", type=int, default=int(os.environ.get("HIL_PORT", "9000")))
    parser.add_argument("--bug", choices=sorted(BUGS), metavar="NAME",
                        help="plant one known bug: " + "; ".join(
                            "%s: %s" % (name, what) for name, what in sorted(BUGS.items())))
    return parser.parse_args()


def say_result(text, act):
    if not act.done():
        act.cancel()
        say("fail %s: cancelled" % text)
        return
    ok, why = act.result()
    say("ok " + text if ok else "fail %s: %s" % (text, why))


async def report_in_order(pending, wake):
    """Prints each action's result line once it has ended, in the order the
    actions came, however they overlap (an estop beside a slow speed)."""
    while True:
        while pending and pending[0][1].done():
            say_result(*pending.pop(0))
        if pending:
            await asyncio.wait([pending[0][1]])
            continue
        wake.clear()
        await wake.wait()


async def main(client_class):
    args = parse_args()
    loop = asyncio.get_running_loop()
    client = client_class(args.host, args.port, args.bug)
    lines = asyncio.Queue()
    threading.Thread(target=stdin_lines, args=(loop, lines), daemon=True).start()
    stop = loop.create_future()
    for sig in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(sig, lambda: stop.done() or stop.set_result(True))
    # Each action runs as its own task, so one that arrives while another is
    # under way (a scheduled estop) is carried out at once.
    pending = []
    wake = asyncio.Event()
    reporter = loop.create_task(report_in_order(pending, wake))
    while True:
        get = loop.create_task(lines.get())
        await asyncio.wait([get, stop], return_when=asyncio.FIRST_COMPLETED)
        if stop.done():
            get.cancel()
            break
        line = get.result()
        if line is None:
            break
        text = line.split("#")[0].strip()
        if text:
            pending.append((text, loop.create_task(client.action(text))))
            wake.set()
    if pending and not stop.done():
        everything = asyncio.gather(*(act for _, act in pending), return_exceptions=True)
        await asyncio.wait([everything, stop], return_when=asyncio.FIRST_COMPLETED)
    reporter.cancel()
    for text, act in list(pending):
        say_result(text, act)
    await client.shut_down()
    return 130 if stop.done() else 0


def run(client_class=LogiClient):
    sys.exit(asyncio.run(main(client_class)))


if __name__ == "__main__":
    run()
