#!/usr/bin/env python3
# A small, correct Leka Alpha master that follows hil's external-client
# contract (docs/client-contract.md): each operator action arrives on stdin
# as one line, a command group in the Leka group language (`ear all 255 0
# 0; motor all forward 120`, `info`, `stop robot`) or `wait 500ms`, and
# gets one "ok ..." or "fail ...: reason" line on stdout once it is done;
# "event connection ..." lines report the serial port opening and closing.
# When stdin ends it stops the motors if they may be turning, makes sure
# the robot has read that stop, closes the port and exits 0.
#
# It is written from the robot's protocol notes (docs/protocols/leka.md,
# the README profile, which is the default) and its mock's main loop
# (docs/mocks/leka.md), not from hil's code:
#   - a frame is 2A 2B 2C 2D, the length of the command group, the group,
#     and the low byte of a 16-bit BSD checksum over the group alone;
#   - a group too large for one frame is cut between commands, never
#     inside one, into frames of at most 64 bytes;
#   - an `info` goes out as its own 7-byte frame at its place in the line
#     and waits up to 200 ms for the robot's line "LEKA key=value ...";
#   - the robot empties its 128-byte serial buffer once per 10 ms loop
#     pass, so at most 64 bytes are written within any 10 ms: a pass can
#     see the bytes of two such windows, and 2 x 64 never overflows it.
#
# `--bug NAME` plants one realistic bug, so the gate can show that it
# rejects exactly that bug (tests/gate/leka.cmake):
#   no-pacing            frames filled up to the spec's 128-byte maximum
#                        and written as soon as they are built
#   length-in-checksum   the checksum also sums the length byte, first, as
#                        the spec's prose says (its worked frames do not)
#   first-command-length the length byte counts only the group's first
#                        command, so a group of several is cut short
#   no-stop-at-exit      the port is closed at the end of the input with
#                        the motors still running
#
# Usage: leka_good.py [--bug NAME] PTY   (or HIL_PTY in the environment)

import argparse
import os
import re
import sys
import termios
import threading
import time
import tty

START = bytes([0x2A, 0x2B, 0x2C, 0x2D])
MAX_GROUP = 122                 # the length byte's limit within a 128-byte frame
FRAME_BYTES = 64                # our own largest frame, and the budget per period
LOOP_PERIOD_S = 0.010           # the robot's main-loop period
INFO_TIMEOUT_S = 0.200
END_STOP_TIMEOUT_S = 0.300
BUGS = ("no-pacing", "length-in-checksum", "first-command-length", "no-stop-at-exit")

# The README profile's command table: name -> (id, names of the data bytes).
COMMANDS = {
    "info": (0x70, ()),
    "stop.led": (0xFD, ()),
    "stop.motor": (0xFE, ()),
    "stop.robot": (0xFF, ()),
    "ear.all": (0x11, ("red", "green", "blue")),
    "ear.single": (0x12, ("led", "red", "green", "blue")),
    "belt.all": (0x13, ("red", "green", "blue")),
    "belt.range": (0x14, ("first", "last", "red", "green", "blue")),
    "belt.single": (0x15, ("led", "red", "green", "blue")),
    "motor.all": (0x21, ("direction", "speed")),
    "motor.duo": (0x22, ("left spin", "left speed", "right spin", "right speed")),
    "motor.left": (0x23, ("spin", "speed")),
    "motor.right": (0x24, ("spin", "speed")),
    "motivator": (0x50, ("id",)),
    "guidance": (0x40, ("id",)),
}
SPIN_FIELDS = ("direction", "spin", "left spin", "right spin")
SPIN_WORDS = {"forward": 0, "backward": 1}


class ActionError(Exception):
    pass


def say(line):
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


def bsd_checksum(data):
    total = 0
    for byte in data:
        total = ((total >> 1) | ((total & 1) << 15)) & 0xFFFF
        total = (total + byte) & 0xFFFF
    return total & 0xFF


# ---------------------------------------------------------------- the language

def field_range(name, values):
    """The accepted range of one data byte, given the bytes read before it."""
    if name in SPIN_FIELDS:
        return 0, 1
    if name == "led":
        return (0, 1) if values.get("ear") else (0, 19)
    if name == "first":
        return 0, 19
    if name == "last":
        return values["first"], 19
    if name == "id":
        return (0x51, 0x55) if values.get("motivator") else (0x41, 0x4F)
    return 0, 255


def command_name(words):
    """(dotted name, number of words it took) of a command's first words."""
    dotted = words[0].lower().split(".")
    if dotted[0] == "led" and len(dotted) > 1:
        dotted = dotted[1:]
    elif dotted == ["led"]:
        if len(words) < 2:
            raise ActionError("'led' needs ear or belt after it")
        name, used = command_name(words[1:])
        return name, used + 1
    if len(dotted) > 1:
        return ".".join(dotted), 1
    if dotted[0] in ("info", "motivator", "guidance"):
        return dotted[0], 1
    if dotted[0] in ("stop", "ear", "belt", "motor"):
        if len(words) < 2:
            raise ActionError("'%s' needs a second word" % dotted[0])
        return dotted[0] + "." + words[1].lower(), 2
    raise ActionError("unknown command '%s' (expected info, stop, ear, belt, motor, "
                      "motivator, guidance or wait)" % words[0])


def parse_value(word, field, low, high, command):
    if field in SPIN_FIELDS and word.lower() in SPIN_WORDS:
        return SPIN_WORDS[word.lower()]
    try:
        value = int(word, 16) if word.lower().startswith("0x") else int(word, 10)
    except ValueError:
        raise ActionError("%s: %s must be a number, got '%s'" % (command, field, word))
    if not low <= value <= high:
        raise ActionError("%s: %s must be %d..%d, got %d" % (command, field, low, high, value))
    return value


def parse_command(text):
    """One command's bytes: (name, bytes)."""
    words = text.split()
    name, used = command_name(words)
    if name not in COMMANDS:
        raise ActionError("unknown command '%s'" % " ".join(words[:used]))
    ident, fields = COMMANDS[name]
    args = words[used:]
    if len(args) != len(fields):
        raise ActionError("%s takes %d value(s) (%s), got %d"
                          % (name, len(fields), " ".join(fields) or "none", len(args)))
    values = {"ear": name.startswith("ear."), "motivator": name == "motivator"}
    data = []
    for field, word in zip(fields, args):
        low, high = field_range(field, values)
        values[field] = parse_value(word, field, low, high, name)
        data.append(values[field])
    return name, bytes([ident] + data)


def parse_group(line):
    """The commands of one line, in order, as (name, bytes)."""
    text = line.split("#", 1)[0]
    parts = [p.strip() for p in text.split(";")]
    if not any(parts):
        raise ActionError("an empty line has no command")
    if any(not p for p in parts):
        raise ActionError("an empty command between ';'")
    return [parse_command(p) for p in parts]


def parse_duration(word):
    match = re.fullmatch(r"([0-9]+(?:\.[0-9]+)?)(ms|s)", word)
    if not match:
        raise ActionError("wait: expected a duration such as 500ms or 1.5s, got '%s'" % word)
    seconds = float(match.group(1)) / (1000.0 if match.group(2) == "ms" else 1.0)
    if seconds > 3600:
        raise ActionError("wait: at most 3600 s, got %s" % word)
    return seconds


# ---------------------------------------------------------------- frames

class Framing:
    """How commands become frames; the planted bugs change one rule each."""

    def __init__(self, bug):
        self.bug = bug
        self.frame_bytes = 128 if bug == "no-pacing" else FRAME_BYTES

    def frame(self, commands):
        group = b"".join(data for _, data in commands)
        length = len(group)
        if self.bug == "first-command-length":
            length = len(commands[0][1])
        summed = bytes([length]) + group if self.bug == "length-in-checksum" else group
        return START + bytes([length]) + group + bytes([bsd_checksum(summed)])

    def frames(self, commands):
        """(frame, is_info) in order: infos alone, the rest cut between commands."""
        out, current, size = [], [], 0
        room = min(self.frame_bytes - 6, MAX_GROUP)
        for name, data in commands:
            if name == "info" or size + len(data) > room:
                if current:
                    out.append((self.frame(current), False))
                current, size = [], 0
            if name == "info":
                out.append((self.frame([(name, data)]), True))
            else:
                current.append((name, data))
                size += len(data)
        if current:
            out.append((self.frame(current), False))
        return out


class Pacer:
    """At most `budget` bytes written within any `period` (half-open window)."""

    def __init__(self, budget, period, enabled):
        self.budget, self.period, self.enabled = budget, period, enabled
        self.sent = []  # (time, bytes)

    def delay_for(self, size, now):
        """How long a frame of `size` bytes must wait before it may go out."""
        if not self.enabled:
            return 0.0
        self.sent = [(t, n) for t, n in self.sent if t > now - self.period]
        total = sum(n for _, n in self.sent)
        for t, n in self.sent:
            if total + size <= self.budget:
                break
            total -= n
            if total + size <= self.budget:
                return t + self.period - now
        return 0.0

    def note(self, size, now):
        if self.enabled:
            self.sent.append((now, size))


# ---------------------------------------------------------------- the robot

class InfoRequest:
    def __init__(self):
        self.done = threading.Event()
        self.reply = None


class Robot:
    """The serial port: frames out through the pacer, info lines in."""

    def __init__(self, path, framing):
        self.framing = framing
        self.pacer = Pacer(FRAME_BYTES, LOOP_PERIOD_S, framing.bug != "no-pacing")
        self.write_lock = threading.Lock()
        self.infos = []  # InfoRequests waiting, in the order their frames went out
        self.infos_lock = threading.Lock()
        self.may_move = False
        say("event connection connecting")
        self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
        tty.setraw(self.fd)
        attrs = termios.tcgetattr(self.fd)
        attrs[4] = attrs[5] = termios.B115200
        termios.tcsetattr(self.fd, termios.TCSANOW, attrs)
        say("event connection connected")
        threading.Thread(target=self.read_forever, daemon=True).start()

    def read_forever(self):
        pending = b""
        while True:
            try:
                data = os.read(self.fd, 256)
            except OSError:
                return
            if not data:
                return
            pending += data
            while b"\n" in pending:
                line, pending = pending.split(b"\n", 1)
                self.on_line(line.rstrip(b"\r").decode("ascii", "replace"))
            pending = pending[-512:]

    def on_line(self, line):
        words = line.split()
        fields = dict(w.split("=", 1) for w in words[1:] if "=" in w)
        if not words or words[0] != "LEKA" or "name" not in fields:
            say("event parse_error not an info line: %r" % line)
            return
        with self.infos_lock:
            request = self.infos.pop(0) if self.infos else None
        if request is None:
            say("an info line nobody asked for: %s" % line)
            return
        request.reply = " ".join(words[1:])
        request.done.set()

    def send(self, commands):
        """Writes a group's frames, paced; returns (frames, bytes, info requests)."""
        frames = self.framing.frames(commands)
        infos, total = [], 0
        with self.write_lock:
            for frame, is_info in frames:
                delay = self.pacer.delay_for(len(frame), time.monotonic())
                while delay > 0:
                    time.sleep(delay)
                    delay = self.pacer.delay_for(len(frame), time.monotonic())
                if is_info:
                    request = InfoRequest()
                    with self.infos_lock:
                        self.infos.append(request)
                    infos.append((request, time.monotonic()))
                os.write(self.fd, frame)
                self.pacer.note(len(frame), time.monotonic())
                total += len(frame)
        self.note_motion(commands)
        return len(frames), total, infos

    def note_motion(self, commands):
        for name, data in commands:
            if name in ("stop.motor", "stop.robot"):
                self.may_move = False
            elif name.startswith("motor.") or name == "motivator":
                self.may_move = True

    def await_infos(self, infos):
        """The replies of a line's infos, in order; ActionError if one is missing."""
        replies = []
        for request, sent_at in infos:
            left = sent_at + INFO_TIMEOUT_S - time.monotonic()
            if not request.done.wait(max(0.0, left)):
                with self.infos_lock:
                    if request in self.infos:
                        self.infos.remove(request)
                raise ActionError("info: no answer within %d ms" % (INFO_TIMEOUT_S * 1000))
            replies.append(request.reply)
        return replies

    def close(self):
        say("event connection disconnected")
        try:
            os.close(self.fd)
        except OSError:
            pass


# ---------------------------------------------------------------- actions

class Actions:
    """Carries out each action on its own thread; results print in order."""

    def __init__(self, robot):
        self.robot = robot
        self.cancelled = threading.Event()
        self.results = {}
        self.next_to_print = 0
        self.count = 0
        self.lock = threading.Lock()
        self.threads = []

    def start(self, line):
        index = self.count
        self.count += 1
        thread = threading.Thread(target=self.run, args=(index, line))
        self.threads.append(thread)
        thread.start()

    def run(self, index, line):
        try:
            detail = self.carry_out(line)
            result = "ok %s (%s)" % (line, detail)
        except ActionError as error:
            result = "fail %s: %s" % (line, error)
        except OSError as error:
            result = "fail %s: the port failed (%s)" % (line, error.strerror or error)
        except Exception as error:  # never leave an action without its result
            result = "fail %s: internal error (%r)" % (line, error)
        with self.lock:
            self.results[index] = result
            while self.next_to_print in self.results:
                say(self.results.pop(self.next_to_print))
                self.next_to_print += 1

    def carry_out(self, line):
        words = line.split("#", 1)[0].split()
        if words and words[0].lower() == "wait":
            if len(words) != 2:
                raise ActionError("wait takes one duration, e.g. wait 500ms")
            seconds = parse_duration(words[1])
            self.cancelled.wait(seconds)
            return "waited %d ms" % round(seconds * 1000)
        commands = parse_group(line)
        frames, total, infos = self.robot.send(commands)
        replies = self.robot.await_infos(infos)
        detail = "%d command%s, %d frame%s, %d bytes sent" % (
            len(commands), "" if len(commands) == 1 else "s", frames,
            "" if frames == 1 else "s", total)
        return detail + "".join("; info %s" % r for r in replies)

    def finish(self):
        """Stdin ended: let the actions end (a wait is cut short)."""
        self.cancelled.set()
        for thread in self.threads:
            thread.join()


def stop_at_end(robot):
    """Stops the motors if they may turn, and waits for the robot's next pass
    to have read the stop: an info behind it is answered in that pass."""
    if not robot.may_move:
        return
    try:
        _, _, infos = robot.send([parse_command("stop motor"), parse_command("info")])
        request, sent_at = infos[0]
        if request.done.wait(max(0.0, sent_at + END_STOP_TIMEOUT_S - time.monotonic())):
            say("stopped the motors at the end")
        else:
            say("sent stop motor at the end; the robot did not confirm it")
    except OSError as error:
        sys.stderr.write("leka_good: could not stop the motors: %s\n" % error)


def main():
    parser = argparse.ArgumentParser(description="A Leka Alpha client for hil's gate")
    parser.add_argument("--bug", choices=BUGS, help="plant one realistic bug")
    parser.add_argument("pty", nargs="?", default=os.environ.get("HIL_PTY", ""))
    args = parser.parse_args()
    if not args.pty:
        parser.error("no serial device: give PTY or set HIL_PTY")
    profile = os.environ.get("HIL_PROFILE", "readme")
    if profile != "readme":
        sys.stderr.write("leka_good: this client speaks the readme profile only, not '%s'\n"
                         % profile)
        sys.exit(2)
    try:
        robot = Robot(args.pty, Framing(args.bug))
    except OSError as error:
        sys.stderr.write("leka_good: cannot open %s: %s\n" % (args.pty, error.strerror))
        sys.exit(1)
    actions = Actions(robot)
    for raw in sys.stdin:
        actions.start(raw.strip())
    actions.finish()
    if args.bug != "no-stop-at-exit":
        stop_at_end(robot)
    robot.close()
    sys.exit(0)


if __name__ == "__main__":
    main()
