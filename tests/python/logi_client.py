"""A small LOGI client, as a Python team would write one for the car
(docs/protocols/logi.md): it sends a command frame and waits for the car's
FB answer to it, skipping the STAT telemetry in between. When no answer
comes in time it sends the command again, and when the connection breaks
it connects again and sends it again, up to `attempts` tries."""

import socket
import time

HEADER = b"LOGI:"


def checksum(text):
    """The LOGI checksum of a frame's text from `LOGI:` through the payload."""
    return sum(text.encode("ascii")) & 0xFF


def encode(payload):
    head = "LOGI:" + payload
    return ("%s:%02X#" % (head, checksum(head))).encode("ascii")


def decode(frame):
    """The payload of one whole frame (bytes from LOGI: to #), or None when
    its checksum is wrong."""
    text = frame.decode("ascii", "replace")
    head, sep, tail = text[:-1].rpartition(":")
    if not sep or len(tail) != 2 or tail != "%02X" % checksum(head):
        return None
    return head[len("LOGI:") :]


class Timeout(Exception):
    pass


class LogiClient:
    def __init__(self, host, port, timeout_s=1.0, attempts=3):
        self.host = host
        self.port = port
        self.timeout_s = timeout_s
        self.attempts = attempts
        self.sock = None
        self.buffer = b""
        # What the client went through, for the tests to look at.
        self.sent = 0
        self.timeouts = 0
        self.reconnects = 0
        self.bad_frames = 0
        self.telemetry = 0

    def connect(self):
        self.close()
        self.sock = socket.create_connection((self.host, self.port), timeout=self.timeout_s)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.buffer = b""

    def close(self):
        if self.sock is not None:
            self.sock.close()
            self.sock = None

    def __enter__(self):
        self.connect()
        return self

    def __exit__(self, *exc):
        self.close()

    def read_frame(self, deadline):
        """The next whole frame's payload; raises Timeout at `deadline` and
        ConnectionError when the car closes the connection."""
        while True:
            start = self.buffer.find(HEADER)
            if start >= 0:
                end = self.buffer.find(b"#", start)
                if end >= 0:
                    frame, self.buffer = self.buffer[start : end + 1], self.buffer[end + 1 :]
                    payload = decode(frame)
                    if payload is None:
                        self.bad_frames += 1
                        continue
                    return payload
            left = deadline - time.monotonic()
            if left <= 0:
                raise Timeout()
            self.sock.settimeout(left)
            try:
                data = self.sock.recv(4096)
            except socket.timeout:
                raise Timeout() from None
            if not data:
                raise ConnectionError("the car closed the connection")
            self.buffer += data

    def command(self, payload):
        """Send `payload` (e.g. "SP:050") and return the car's answer
        payload (e.g. "FB:SP:1"), retrying as described above. Raises
        Timeout or ConnectionError when every attempt failed."""
        code = payload.split(":", 1)[0]
        last_error = None
        for _ in range(self.attempts):
            try:
                if self.sock is None:
                    self.reconnects += 1
                    self.connect()
                self.sock.sendall(encode(payload))
                self.sent += 1
                deadline = time.monotonic() + self.timeout_s
                while True:
                    answer = self.read_frame(deadline)
                    if answer.startswith("FB:%s:" % code):
                        return answer
                    if answer.startswith("STAT:"):
                        self.telemetry += 1
            except Timeout as error:
                self.timeouts += 1
                last_error = error
            except OSError as error:  # reset, refused, closed
                self.close()
                last_error = error
        raise last_error

    def round_trip_s(self, payload="SP:050"):
        """Seconds from sending `payload` to its answer."""
        start = time.monotonic()
        self.command(payload)
        return time.monotonic() - start
