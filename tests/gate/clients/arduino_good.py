#!/usr/bin/env python3
# A small, correct Arduino robot client that follows hil's external-client
# contract (docs/client-contract.md): each operator action arrives on stdin
# as one line (`PING`, `V 160`, `M 20`, `wait 1s`), and gets one "ok ..." or
# "fail ...: reason" line on stdout once the board has answered it.
#
# It is written from the robot's protocol notes alone (no hil code), as the
# board's own client sends its frames: ^SEQ|CMD|PAYLOAD*CS$ with SEQ two
# upper-case hex digits counting up from 01, CS the XOR of the bytes
# between ^ and *, and one space as the payload of a command without an
# argument. One request is on the line at a time: the next goes out when
# the answer with the same SEQ is in.
#
# arduino_pipelining_bug.py is this client with one method replaced, so the
# gate can show that it rejects exactly that bug.
#
# Usage: arduino_good.py PTY   (or HIL_PTY in the environment)

import os
import sys
import termios
import threading
import time
import tty

ANSWER_TIMEOUT_S = 2.0
MAX_FRAME = 256


def build_frame(seq, cmd, payload):
    body = "%02X|%s|%s" % (seq, cmd, payload or " ")
    cs = 0
    for byte in body.encode("ascii"):
        cs ^= byte
    return ("^%s*%02X$" % (body, cs)).encode("ascii")


def parse_reply(frame):
    """(seq, kind, info) of one whole ^...$ frame, or None if it is not a valid reply."""
    try:
        text = frame.decode("ascii")
    except UnicodeDecodeError:
        return None
    star = text.rfind("*")
    if not text.startswith("^") or not text.endswith("$") or star < 0 or len(text) - star != 4:
        return None
    body = text[1:star]
    cs = 0
    for byte in body.encode("ascii"):
        cs ^= byte
    try:
        if int(text[star + 1:star + 3], 16) != cs:
            return None
    except ValueError:
        return None
    fields = body.split("|")
    if len(fields) != 3:
        return None
    return fields[0], fields[1], fields[2]


def say(line):
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


class ArduinoClient:
    def __init__(self, path):
        self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
        tty.setraw(self.fd)
        attrs = termios.tcgetattr(self.fd)
        attrs[4] = attrs[5] = termios.B9600
        termios.tcsetattr(self.fd, termios.TCSANOW, attrs)
        self.seq = 0
        self.answers = {}  # SEQ text -> (kind, info)
        self.lock = threading.Condition()
        threading.Thread(target=self.read_forever, daemon=True).start()

    def read_forever(self):
        buf = b""
        while True:
            try:
                data = os.read(self.fd, 256)
            except OSError:
                return
            if not data:
                return
            buf += data
            while True:
                start = buf.find(b"^")
                if start < 0:
                    buf = b""
                    break
                end = buf.find(b"$", start)
                if end < 0:
                    buf = buf[start:][-MAX_FRAME:]
                    break
                reply = parse_reply(buf[start:end + 1])
                buf = buf[end + 1:]
                if reply:
                    with self.lock:
                        self.answers[reply[0]] = (reply[1], reply[2])
                        self.lock.notify_all()

    # ---- the hook the broken client replaces ----

    def request(self, cmd, payload):
        """Sends one request and reports its answer: one request on the line at a time."""
        seq = self.send(cmd, payload)
        deadline = time.monotonic() + ANSWER_TIMEOUT_S
        with self.lock:
            while seq not in self.answers:
                left = deadline - time.monotonic()
                if left <= 0:
                    say("fail %s: no answer within %.1f s" % (cmd, ANSWER_TIMEOUT_S))
                    return
                self.lock.wait(left)
            kind, info = self.answers.pop(seq)
        if kind == "ACK":
            say("ok %s %s" % (cmd, info))
        else:
            say("fail %s: %s %s" % (cmd, kind, info))

    def send(self, cmd, payload):
        self.seq = self.seq % 255 + 1
        os.write(self.fd, build_frame(self.seq, cmd, payload))
        return "%02X" % self.seq

    def act(self, line):
        words = line.split()
        if not words:
            return
        if words[0] == "wait" and len(words) == 2:
            text = words[1]
            seconds = float(text[:-2]) / 1000 if text.endswith("ms") else float(text.rstrip("s"))
            time.sleep(seconds)
            say("ok wait")
            return
        self.request(words[0].upper(), " ".join(words[1:]))


def run(client_class):
    path = sys.argv[1] if len(sys.argv) > 1 else os.environ.get("HIL_PTY", "")
    if not path:
        sys.stderr.write("usage: %s PTY (or HIL_PTY)\n" % sys.argv[0])
        sys.exit(2)
    client = client_class(path)
    for line in sys.stdin:
        client.act(line.strip())
    sys.exit(0)


if __name__ == "__main__":
    run(ArduinoClient)
