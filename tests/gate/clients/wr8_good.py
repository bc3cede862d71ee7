#!/usr/bin/env python3
# A small, correct WR8 GUI client that follows hil's external-client
# contract (docs/client-contract.md): each operator action arrives on stdin
# as one line (`connect`, `drive 30`, `task blink`, `set servo-zero=92`,
# `wait 1s` ...), and gets one "ok ..." or "fail ...: reason" line on stdout
# when it has ended, in the order the actions came; "event ..." lines
# report what the client saw as it happened. When stdin ends it stops the
# vehicle, closes the connection and exits 0.
#
# It is written from the WR8 wire profile (docs/protocols/wr8.md, profile
# `document`, hil's default for the car) and the vocabulary of
# docs/clients/wr8-client.md, the way a client team would write theirs:
#   - packets are read from a byte stream whatever the reads cut or join
#     (a packet's length follows from its code and size byte);
#   - nothing but AUTH goes out before the AUTH-REPLY; no AUTH-REPLY within
#     2 s, or a close before it, fails the login;
#   - every TASK and SETTINGS takes a request number (COI) that no open
#     request holds, and every RESPONSE is matched to its request by COI,
#     so a blink can run beside a drive;
#   - the first answer must come within 500 ms; a task that has started
#     must end within its kind's time (check 1 s, drive 30 s, turn 3 s,
#     blink 5 s, get-settings 1 s);
#   - after a lost connection it tries again 1 s, 2 s, 4 s, then every 8 s
#     after each failure, and logs in again;
#   - without DATA for 500 ms it warns that the telemetry is stale.
# Operator actions that come while an earlier one is still running (a
# scenario's schedule) are carried out at once; their result lines still
# come in the order the actions came.
#
# `--bug NAME` plants one realistic bug, for hil's gate tests (BUGS below);
# each is a small change to one method, so the gate can show that it
# rejects exactly that bug.
#
# Usage: wr8_good.py [--bug NAME] [HOST PORT]   (or HIL_HOST / HIL_PORT)

import argparse
import asyncio
import math
import os
import signal
import struct
import sys
import threading

AUTH_TEXT = b"HIL-WR8-01"  # the document profile's 10-byte login string
DEFAULT_PORT = 9100
CONNECT_TIMEOUT_S = 10.0
AUTH_TIMEOUT_S = 2.0
ANSWER_TIMEOUT_S = 0.5
STALE_AFTER_S = 0.5
WAIT_DATA_S = 5.0
RECONNECT_DELAYS_S = (1.0, 2.0, 4.0, 8.0)  # the last one repeats
# How long a request may take to end once the vehicle has answered it first.
COMPLETION_S = {"check": 1.0, "drive": 30.0, "turn": 3.0, "blink": 5.0,
                "get_settings": 1.0, "settings": 0.5}

# Task words: (task code, values it takes, the kind its events name).
TASKS = {"check": (0, 0, "check"), "drive": (1, 1, "drive"), "turn": (2, 1, "turn"),
         "blink": (3, 0, "blink"), "get-settings": (4, 0, "get_settings")}
TASK_BY_CODE = {code: word for word, (code, _, _) in TASKS.items()}
# Settings names: (type byte, float or whole number).
SETTINGS = {"p": (0, "float"), "i": (1, "float"), "d": (2, "float"), "servo-zero": (3, "int")}
SETTING_NAMES = {t: name for name, (t, _) in SETTINGS.items()}
STATES = ("FAULT", "RUN", "STOP", "WAIT")
VOCABULARY = ("connect, disconnect, drive CM, turn DEG, task CODE [VALUE...], get-settings, "
              "set NAME=VALUE..., wait DURATION, wait-data")

# ---- the wire (profile `document`: little-endian, size bytes count bytes) ----

FIXED_LENGTH = {0: 1, 1: 11, 2: 4, 5: 3}  # EMPTY, AUTH, AUTH-REPLY, RESPONSE
SIZE_BYTE_AT = {3: 3, 4: 2, 6: 6}  # TASK, SETTINGS, DATA: where the block's size byte is
NAMES = {0: "EMPTY", 1: "AUTH", 2: "AUTH-REPLY", 3: "TASK", 4: "SETTINGS", 5: "RESPONSE",
         6: "DATA"}
# DATA parameters: code -> (name, struct format, bytes).
DATA_PARAMETERS = {0: ("odometry_cm", "<i", 4), 1: ("speed_mps", "<f", 4),
                   2: ("wheel_angle_deg", "<f", 4), 3: ("battery_percent", "<B", 1)}


def packet_length(buf):
    """The length of the packet that starts buf; None if more bytes are needed
    to tell; 0 if buf[0] is no packet code."""
    code = buf[0]
    if code in FIXED_LENGTH:
        return FIXED_LENGTH[code]
    if code in SIZE_BYTE_AT:
        at = SIZE_BYTE_AT[code]
        return at + 1 + buf[at] if len(buf) > at else None
    return 0


class PacketStream:
    """Whole packets out of the vehicle's byte stream, however TCP cut or
    joined them; a run of bytes that start no packet is reported once."""

    def __init__(self):
        self.buf = b""

    def feed(self, data):
        """Packets (bytes) and problems (text), in stream order."""
        self.buf += data
        out = []
        while self.buf:
            n = packet_length(self.buf)
            if n == 0:
                run = 1
                while run < len(self.buf) and packet_length(self.buf[run:]) == 0:
                    run += 1
                out.append("garbage: %d byte(s) that start no packet, first 0x%02X"
                           % (run, self.buf[0]))
                self.buf = self.buf[run:]
                continue
            if n is None or len(self.buf) < n:
                break
            out.append(self.buf[:n])
            self.buf = self.buf[n:]
        return out


class OneReadOnePacket:
    """A reader that takes each read from the socket for one packet."""

    def feed(self, data):
        n = packet_length(data)
        if n == 0 or n is None or len(data) < n:
            return ["truncated: a read of %d byte(s) holds no whole packet" % len(data)]
        return [data[:n]]


def word_of(text, kind):
    """The 4 little-endian bytes of an operator's value: a whole number, a
    number (kind "float"), or 0x and up to 8 hex digits for exact bits."""
    if text.lower().startswith("0x") and 3 <= len(text) <= 10:
        try:
            return struct.pack("<I", int(text[2:], 16))
        except ValueError:
            pass
    try:
        if kind == "float":
            value = float(text)
            if math.isinf(value) and "inf" not in text.lower():
                raise ValueError
            return struct.pack("<f", value)
        value = int(text, 10)
        if not -2**31 <= value < 2**31:
            raise ValueError
        return struct.pack("<i", value)
    except (ValueError, OverflowError):
        what = "a number" if kind == "float" else "a whole number"
        raise ValueError("'%s' is not %s that fits 4 bytes (or 0x and up to 8 hex digits)"
                         % (text, what)) from None


def task_packet(coi, code, words):
    return bytes([3, coi, code, 4 * len(words)]) + b"".join(words)


def settings_packet(coi, entries):
    block = b"".join(bytes([kind]) + word for kind, word in entries)
    return bytes([4, coi, len(block)]) + block


def decode_data(pkt):
    """(state, timestamp_ms, {name: value}) of a DATA packet; ValueError if broken."""
    if pkt[1] > 3:
        raise ValueError("bad_value: DATA state %d is no state code" % pkt[1])
    timestamp = struct.unpack_from("<I", pkt, 2)[0]
    block, values, at = pkt[7:], {}, 0
    while at < len(block):
        parameter = DATA_PARAMETERS.get(block[at])
        if parameter is None:  # a parameter this client does not know: keep what came before
            break
        name, fmt, width = parameter
        if at + 1 + width > len(block):
            raise ValueError("bad_format: DATA parameter %d runs past its block" % block[at])
        values[name] = struct.unpack_from(fmt, block, at + 1)[0]
        at += 1 + width
    return STATES[pkt[1]], timestamp, values


def decode_settings(pkt):
    """{name: value} of the vehicle's SETTINGS answer; ValueError if broken."""
    block = pkt[3:]
    if len(block) % 5:
        raise ValueError("bad_format: SETTINGS block of %d bytes is no whole number of entries"
                         % len(block))
    values = {}
    for at in range(0, len(block), 5):
        kind = block[at]
        if kind not in SETTING_NAMES:
            raise ValueError("unknown_code: SETTINGS entry type %d" % kind)
        fmt = "<i" if kind == 3 else "<f"
        values[SETTING_NAMES[kind]] = struct.unpack_from(fmt, block, at + 1)[0]
    return values


def settings_text(values):
    return " ".join("%s=%s" % (name, ("%g" % v) if isinstance(v, float) else v)
                    for name, v in values.items())


def parse_duration(text):
    """Seconds of `500ms`, `1s`, `1.5s`, `2min`, or None."""
    for unit, scale in (("ms", 0.001), ("min", 60.0), ("s", 1.0)):
        if text.endswith(unit):
            try:
                value = float(text[:-len(unit)])
            except ValueError:
                return None
            return value * scale if value >= 0 and math.isfinite(value) else None
    return None


def say(line):
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


def note(line):
    sys.stderr.write("wr8_good: " + line + "\n")
    sys.stderr.flush()


class ConnectionClosed(Exception):
    pass


class Request:
    def __init__(self, kind, coi, loop):
        self.kind, self.coi = kind, coi
        self.result = loop.create_future()  # -> (ok, detail)
        self.timer = None
        self.settings = None  # what a get-settings read back


class Wr8Client:
    def __init__(self, host, port):
        self.host, self.port = host, port
        self.loop = asyncio.get_running_loop()
        self.state = "disconnected"
        self.want_connected = False
        self.conn_task = None
        self.reader_task = None
        self.writer = None
        self.login = None  # the future of the AUTH-REPLY on this connection
        self.connected_waiters = []
        self.requests = []  # open requests, oldest first
        self.last_coi = 0  # COI 0 is never taken first: the vehicle's "idle" in real software
        self.live = {}
        self.stale = False
        self.stale_timer = None
        self.data_waiters = []

    # ---- what the bugs replace ----

    def make_packet_stream(self):
        return PacketStream()

    def reconnect_delay(self, failures_in_a_row):
        return RECONNECT_DELAYS_S[min(failures_in_a_row, len(RECONNECT_DELAYS_S) - 1)]

    async def await_login(self):
        """Waits for the AUTH-REPLY; (ok, reason)."""
        try:
            await asyncio.wait_for(asyncio.shield(self.login), AUTH_TIMEOUT_S)
            return True, ""
        except asyncio.TimeoutError:
            return False, "AUTH-REPLY timeout"
        except ConnectionClosed:
            return False, "closed before AUTH-REPLY"

    def request_for_answer(self, coi):
        """The open request a RESPONSE or SETTINGS with this COI answers."""
        for r in self.requests:
            if r.coi == coi:
                return r
        return None

    # ---- connection ----

    def set_state(self, state):
        if state == self.state:
            return
        self.state = state
        say("event connection " + state)
        if state == "connected":
            for w in self.connected_waiters:
                if not w.done():
                    w.set_result(True)
            self.connected_waiters = []

    async def connection_loop(self, outcome):
        """The operator's attempt, then the reconnect series until disconnect."""
        failures = 0
        while self.want_connected:
            self.set_state("connecting")
            ok, reason = await self.open_and_log_in()
            if ok:
                failures = 0
                self.set_state("connected")
                if not outcome.done():
                    outcome.set_result((True, "logged in"))
                await self.reader_task
                if not self.want_connected:
                    return
                self.lost("the connection was lost")
            elif not outcome.done():
                # The operator's own connect failed: tell them, no retries.
                self.want_connected = False
                self.set_state("disconnected")
                outcome.set_result((False, reason))
                return
            self.set_state("reconnecting")
            await asyncio.sleep(self.reconnect_delay(failures))
            failures += 1

    async def open_and_log_in(self):
        try:
            reader, writer = await asyncio.wait_for(
                asyncio.open_connection(self.host, self.port), CONNECT_TIMEOUT_S)
        except OSError as e:
            return False, "connect failed (%s)" % (e.strerror or e)
        except asyncio.TimeoutError:
            return False, "connect failed (no connection within %d s)" % CONNECT_TIMEOUT_S
        self.writer = writer
        self.login = self.loop.create_future()
        self.login.add_done_callback(lambda f: f.cancelled() or f.exception())
        self.set_state("authenticating")
        self.reader_task = self.loop.create_task(self.read_packets(reader))
        writer.write(bytes([1]) + AUTH_TEXT)
        ok, reason = await self.await_login()
        if not ok:
            say("event login failed " + reason)
            self.close_writer()
            await self.reader_task
        return ok, reason

    async def read_packets(self, reader):
        stream = self.make_packet_stream()
        while True:
            try:
                data = await reader.read(4096)
            except (OSError, asyncio.CancelledError):
                data = b""
            if not data:
                break
            for item in stream.feed(data):
                if isinstance(item, str):
                    say("event parse_error " + item)
                else:
                    self.on_packet(item)
        if not self.login.done():
            self.login.set_exception(ConnectionClosed())

    def close_writer(self):
        if self.writer is not None:
            self.writer.close()
            self.writer = None

    def lost(self, why):
        """The safe state after a drop or a disconnect: every request ends."""
        self.close_writer()
        if self.stale_timer is not None:
            self.stale_timer.cancel()
            self.stale_timer = None
        self.stale = False
        self.live = {}
        for r in list(self.requests):
            self.finish(r, "cancelled", False, "cancelled: " + why)
        for w in self.data_waiters:
            if not w.done():
                w.set_exception(ConnectionClosed())
        self.data_waiters = []

    async def connect(self):
        if self.state == "connected":
            return True, "already logged in"
        if self.want_connected:  # a reconnect series is under way: wait for it
            waiter = self.loop.create_future()
            self.connected_waiters.append(waiter)
            try:
                await asyncio.wait_for(waiter, CONNECT_TIMEOUT_S)
                return True, "logged in"
            except asyncio.TimeoutError:
                return False, "not logged in within %d s" % CONNECT_TIMEOUT_S
        self.want_connected = True
        outcome = self.loop.create_future()
        self.conn_task = self.loop.create_task(self.connection_loop(outcome))
        return await outcome

    async def disconnect(self):
        was = self.want_connected or self.state != "disconnected"
        self.want_connected = False
        if self.conn_task is not None:
            self.conn_task.cancel()
            self.conn_task = None
        self.lost("the operator disconnected")
        if self.reader_task is not None:
            await asyncio.gather(self.reader_task, return_exceptions=True)
            self.reader_task = None
        if was:
            self.set_state("disconnected")

    # ---- what the vehicle sends ----

    def on_packet(self, pkt):
        code = pkt[0]
        try:
            if code == 2:
                self.on_auth_reply(pkt)
            elif code == 5:
                self.on_response(pkt[1], pkt[2])
            elif code == 6:
                self.on_data(*decode_data(pkt))
            elif code == 4:
                self.on_settings(pkt[1], decode_settings(pkt))
            elif code != 0:  # EMPTY is a keepalive
                say("event parse_error unknown_code: the vehicle does not send %s" % NAMES[code])
        except ValueError as e:
            say("event parse_error %s" % e)

    def on_auth_reply(self, pkt):
        if pkt[3] > 3:
            raise ValueError("bad_value: AUTH-REPLY state %d is no state code" % pkt[3])
        if self.login is not None and not self.login.done():
            self.login.set_result(True)
            say("event login ok")
            note("logged in: device %d, id %d, %s" % (pkt[1], pkt[2], STATES[pkt[3]]))

    def on_data(self, state, timestamp, values):
        self.live = dict(values, state=state, timestamp_ms=timestamp)
        if self.stale:
            self.stale = False
            say("event fresh")
        if self.stale_timer is not None:
            self.stale_timer.cancel()
        self.stale_timer = self.loop.call_later(STALE_AFTER_S, self.go_stale)
        for w in self.data_waiters:
            if not w.done():
                w.set_result((state, timestamp))
        self.data_waiters = []

    def go_stale(self):
        self.stale_timer = None
        if self.state == "connected" and not self.stale:
            self.stale = True
            say("event stale")

    def on_response(self, coi, code):
        if code > 2:
            raise ValueError("unknown_code: RESPONSE code %d for COI %d" % (code, coi))
        r = self.request_for_answer(coi)
        if r is None:
            note("RESPONSE for COI %d answers no open request (late or unknown): ignored" % coi)
            return
        if code == 1:
            say("event command %s started" % r.kind)
            self.arm(r, COMPLETION_S[r.kind], "not completed within %g s of its start"
                     % COMPLETION_S[r.kind])
        elif code == 2:
            if r.kind == "get_settings" and r.settings is None:
                self.finish(r, "error", False, "completed without sending the settings")
            else:
                detail = settings_text(r.settings) if r.settings is not None else "completed"
                self.finish(r, "completed", True, detail)
        else:
            self.finish(r, "error", False, "the vehicle answered error")

    def on_settings(self, coi, values):
        r = self.request_for_answer(coi)
        if r is None or r.kind != "get_settings":
            note("SETTINGS for COI %d answers no open get-settings: ignored" % coi)
            return
        r.settings = values
        self.arm(r, COMPLETION_S[r.kind], "no RESPONSE after the SETTINGS within 1 s")

    # ---- requests ----

    def take_coi(self):
        taken = {r.coi for r in self.requests}
        for step in range(1, 257):
            coi = (self.last_coi + step) % 256
            if coi not in taken:
                self.last_coi = coi
                return coi
        return None

    def arm(self, r, seconds, reason):
        if r.timer is not None:
            r.timer.cancel()
        r.timer = self.loop.call_later(seconds, self.finish, r, "timed_out", False, reason)

    def finish(self, r, state, ok, detail):
        if r.timer is not None:
            r.timer.cancel()
            r.timer = None
        if r in self.requests:
            self.requests.remove(r)
        if not r.result.done():
            say("event command %s %s" % (r.kind, state))
            r.result.set_result((ok, detail))

    async def request(self, kind, build):
        """Sends one TASK or SETTINGS and waits for its end: (ok, detail)."""
        if self.state != "connected" or self.writer is None:
            return False, "refused: not connected"
        coi = self.take_coi()
        if coi is None:
            return False, "refused: all 256 request numbers are in use"
        r = Request(kind, coi, self.loop)
        self.requests.append(r)
        self.writer.write(build(coi))
        say("event command %s sent" % kind)
        self.arm(r, ANSWER_TIMEOUT_S, "no answer to the TASK or SETTINGS within 500 ms")
        return await r.result

    async def wait_data(self):
        if self.state != "connected":
            return False, "not connected"
        waiter = self.loop.create_future()
        self.data_waiters.append(waiter)
        try:
            state, timestamp = await asyncio.wait_for(waiter, WAIT_DATA_S)
            return True, "DATA %s at %d ms" % (state, timestamp)
        except asyncio.TimeoutError:
            return False, "no DATA within %g s" % WAIT_DATA_S
        except ConnectionClosed:
            return False, "the connection was closed"

    def may_be_moving(self):
        if any(r.kind in ("drive", "turn") for r in self.requests):
            return True
        return self.live.get("state") == "RUN" or abs(self.live.get("speed_mps", 0.0)) > 0.0

    # ---- operator actions ----

    async def action(self, text):
        words = text.split()
        verb, args = words[0].lower(), words[1:]
        if verb in ("connect", "disconnect", "get-settings", "wait-data") and args:
            return False, "%s takes nothing after it, got '%s'" % (verb, " ".join(args))
        if verb == "connect":
            return await self.connect()
        if verb == "disconnect":
            await self.disconnect()
            return True, "disconnected"
        if verb == "wait-data":
            return await self.wait_data()
        if verb == "wait":
            seconds = parse_duration(args[0]) if len(args) == 1 else None
            if seconds is None:
                return False, "expected one duration with a unit (500ms, 1s, 2min)"
            await asyncio.sleep(seconds)
            return True, "waited"
        if verb in ("drive", "turn", "get-settings"):
            return await self.task(verb, args)
        if verb == "task":
            if not args:
                return False, "task needs a code: check, drive, turn, blink, get-settings or 0..4"
            word = args[0].lower()
            word = TASK_BY_CODE.get(int(word), word) if word.isdigit() else word
            return await self.task(word, args[1:])
        if verb == "set":
            return await self.set_settings(args)
        return False, "unknown action '%s'; expected %s" % (words[0], VOCABULARY)

    async def task(self, word, args):
        if word not in TASKS:
            return False, "unknown task '%s'; expected check, drive, turn, blink, " \
                          "get-settings or 0..4" % word
        code, count, kind = TASKS[word]
        if len(args) != count:
            return False, "refused: bad request (%s takes %d value(s), got %d)" % (
                word, count, len(args))
        try:
            values = [word_of(a, "int") for a in args]
        except ValueError as e:
            return False, str(e)
        return await self.request(kind, lambda coi: task_packet(coi, code, values))

    async def set_settings(self, args):
        if not args:
            return False, "set needs NAME=VALUE entries (p, i, d, servo-zero)"
        entries = []
        for arg in args:
            name, sep, value = arg.partition("=")
            setting = SETTINGS.get(name.lower())
            if not sep or setting is None:
                return False, "'%s' is not NAME=VALUE with NAME one of p, i, d, servo-zero" % arg
            try:
                entries.append((setting[0], word_of(value, setting[1])))
            except ValueError as e:
                return False, str(e)
        if len(entries) > 51:
            return False, "refused: bad request (at most 51 settings fit one packet)"
        return await self.request("settings", lambda coi: settings_packet(coi, entries))

    async def shut_down(self):
        """stdin ended: stop the vehicle, close the connection.

        The document's protocol has no stop or cancel packet; its vehicle stops
        and drops its tasks when its GUI's connection closes (docs/mocks/wr8.md,
        "Disconnect"), so closing the connection is how this client stops it."""
        if self.writer is not None and self.may_be_moving():
            note("stopping the vehicle: closing the connection ends its drive or turn")
        await self.disconnect()


# ---- the bugs ----


class TaskBeforeLoginBug(Wr8Client):
    """`connect` succeeds once AUTH is written, without waiting for the
    AUTH-REPLY, so the first TASK can reach the vehicle before its login."""

    async def await_login(self):
        return True, ""


class NewestTaskBug(Wr8Client):
    """Every RESPONSE is taken for the newest open request, whatever its COI."""

    def request_for_answer(self, coi):
        return self.requests[-1] if self.requests else None


class NoBackoffBug(Wr8Client):
    """Reconnects every 100 ms after a drop or a failed attempt, forever."""

    def reconnect_delay(self, failures_in_a_row):
        return 0.1


class OneReadOnePacketBug(Wr8Client):
    """Takes each read from the socket for one whole packet."""

    def make_packet_stream(self):
        return OneReadOnePacket()


BUGS = {"task-before-login": TaskBeforeLoginBug, "newest-task": NewestTaskBug,
        "no-backoff": NoBackoffBug, "one-read-one-packet": OneReadOnePacketBug}

# ---- the contract's loop ----


def stdin_lines(loop, queue):
    """Reads stdin on a thread, so the event loop never blocks on it."""
    for line in sys.stdin:
        loop.call_soon_threadsafe(queue.put_nowait, line.rstrip("\r\n"))
    loop.call_soon_threadsafe(queue.put_nowait, None)


async def print_results(running):
    """One result line per action, in the order the actions came."""
    while True:
        text, act = await running.get()
        try:
            ok, detail = await act
        except asyncio.CancelledError:
            ok, detail = False, "cancelled: input ended first"
        except Exception as e:  # a fault of this client: say so, keep answering
            ok, detail = False, "internal error (%s: %s)" % (e.__class__.__name__, e)
        if ok:
            say("ok %s%s" % (text, " (%s)" % detail if detail else ""))
        else:
            say("fail %s: %s" % (text, detail))
        running.task_done()


async def main(client_class, host, port):
    loop = asyncio.get_running_loop()
    client = client_class(host, port)
    lines, running = asyncio.Queue(), asyncio.Queue()
    threading.Thread(target=stdin_lines, args=(loop, lines), daemon=True).start()
    printer = loop.create_task(print_results(running))
    stop = loop.create_future()
    for sig in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(sig, lambda: stop.done() or stop.set_result(True))
    actions = []
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
            act = loop.create_task(client.action(text))
            actions.append(act)
            running.put_nowait((text, act))
    for act in actions:
        act.cancel()
    await running.join()
    printer.cancel()
    await client.shut_down()
    return 130 if stop.done() else 0


def run():
    parser = argparse.ArgumentParser(description="A WR8 client for hil's external-client gate")
    parser.add_argument("--bug", choices=sorted(BUGS), help="plant one known bug")
    parser.add_argument("host", nargs="?", default=os.environ.get("HIL_HOST", "127.0.0.1"))
    parser.add_argument("port", nargs="?", type=int,
                        default=int(os.environ.get("HIL_PORT", DEFAULT_PORT)))
    args = parser.parse_args()
    client_class = BUGS[args.bug] if args.bug else Wr8Client
    sys.exit(asyncio.run(main(client_class, args.host, args.port)))


if __name__ == "__main__":
    run()
