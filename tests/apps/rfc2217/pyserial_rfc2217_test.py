#!/usr/bin/env python3
# pySerial's own RFC 2217 client, unmodified, against `hil mock arduino
# --rfc2217`: it opens the car as a Windows program opens a redirected COM
# port, talks the robot's protocol, changes the line's rate, is refused as
# a second client, closes and reopens (the board resets), and hil logs no
# problem with any of it.
#
# Usage: pyserial_rfc2217_test.py HIL_BINARY
# Needs a Python with pySerial (Debian's python3-serial); CMake picks one.

import os
import re
import signal
import subprocess
import sys
import tempfile
import time

import serial

TIMEOUT_S = 5.0


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def xor_of(text):
    cs = 0
    for byte in text.encode("ascii"):
        cs ^= byte
    return cs


def frame(seq, cmd, payload=" "):
    body = "%02X|%s|%s" % (seq, cmd, payload)
    return ("^%s*%02X$" % (body, xor_of(body))).encode("ascii")


def read_frame(port):
    """One ^...$ frame from the robot, as text; fails after TIMEOUT_S."""
    data = b""
    deadline = time.monotonic() + TIMEOUT_S
    while not data.endswith(b"$"):
        if time.monotonic() > deadline:
            fail("no whole frame from the robot within %.0f s (got %r)" % (TIMEOUT_S, data))
        data += port.read(1)
        if data and not data.startswith(b"^"):
            fail("bytes before a frame: %r" % data)
    return data.decode("ascii")


class Robot:
    def __init__(self, url, baudrate=9600):
        self.port = serial.serial_for_url(url, baudrate=baudrate, timeout=0.5)
        self.seq = 0

    def request(self, cmd, payload=" "):
        """The ACK's text for one request; fails on anything else."""
        self.seq = (self.seq + 1) % 256
        self.port.write(frame(self.seq, cmd, payload))
        answer = read_frame(self.port)
        m = re.match(r"^\^([0-9A-F]{2})\|ACK\|(.*)\*([0-9A-F]{2})\$$", answer)
        if not m or int(m.group(1), 16) != self.seq:
            fail("%s %r: expected an ACK with SEQ %02X, got %s" % (cmd, payload, self.seq, answer))
        if int(m.group(3), 16) != xor_of(answer[1:answer.rfind("*")]):
            fail("bad checksum in %s" % answer)
        return m.group(2)

    def timed_help(self, times):
        """Seconds for `times` HELP requests and their answers, one after another."""
        start = time.monotonic()
        for _ in range(times):
            self.request("HELP")
        return time.monotonic() - start

    def close(self):
        self.port.close()


def start_hil(hil, ports_file):
    process = subprocess.Popen(
        [hil, "mock", "arduino", "--rfc2217", "127.0.0.1:0", "--ports-file", ports_file,
         "--no-status"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    deadline = time.monotonic() + 20
    while not os.path.exists(ports_file):
        if process.poll() is not None:
            fail("hil mock exited: " + process.stdout.read())
        if time.monotonic() > deadline:
            process.kill()
            fail("hil mock wrote no ports file in 20 s")
        time.sleep(0.05)
    with open(ports_file) as f:
        name, address = f.read().split()
    if name != "car0" or not address.startswith("rfc2217://127.0.0.1:"):
        process.kill()
        fail("unexpected ports file line: %s %s" % (name, address))
    return process, address.split("?")[0]


def main():
    hil = sys.argv[1]
    with tempfile.TemporaryDirectory() as tmp:
        process, url = start_hil(hil, os.path.join(tmp, "ports"))
        try:
            output = exercise(url)
        finally:
            process.send_signal(signal.SIGINT)
            try:
                log, _ = process.communicate(timeout=10)
            except subprocess.TimeoutExpired:
                process.kill()
                log, _ = process.communicate()
        print("hil said:\n" + log)
        check_log(log, process.returncode)
        print(output)
    print("PASS")


def exercise(url):
    robot = Robot(url)
    if robot.request("PING") == "":
        fail("PING's ACK is empty")
    robot.request("V", "200")
    robot.request("M", "500")  # 9 s of driving
    status = robot.request("STATUS")
    if "V=200" not in status or "MOT:MOVE" not in status:
        fail("STATUS after V 200 and M 500: %s" % status)

    # 1,000 bytes of noise (0xFF among them, doubled by pySerial on the
    # wire) and a PING: the answer comes once all of it has crossed the
    # 9600-baud line, about 1.04 s for the noise alone.
    robot.seq = (robot.seq + 1) % 256
    start = time.monotonic()
    robot.port.write(b"\xff" * 10 + b"x" * 990 + frame(robot.seq, "PING"))
    answer = read_frame(robot.port)
    at_1000 = time.monotonic() - start
    if "|ACK|" not in answer:
        fail("PING after 1,000 bytes of noise: %s" % answer)
    if not 0.95 < at_1000 < 2.5:
        fail("1,000 bytes and a PING took %.3f s at 9600 baud (about 1.07 s expected)" % at_1000)

    # The line's rate: HELP's 14-byte request and 44-byte answer take about
    # 60 ms at 9600 baud and four times as long at 2400.
    at_9600 = robot.timed_help(5)
    robot.port.baudrate = 2400  # SET-BAUDRATE, acknowledged before it returns
    at_2400 = robot.timed_help(5)
    robot.port.baudrate = 9600
    if not 0.25 < at_9600 < 1.5:
        fail("5 HELPs at 9600 baud took %.3f s (about 0.32 s expected)" % at_9600)
    if not (at_2400 > 2.5 * at_9600 and at_2400 > 1.0):
        fail("5 HELPs at 2400 baud took %.3f s, at 9600 %.3f s: the rate did not pace the line"
             % (at_2400, at_9600))

    # A second program opening the port is refused while the first has it.
    try:
        serial.serial_for_url(url + "?timeout=1", baudrate=9600, timeout=0.5)
        fail("a second client opened the port while the first had it")
    except serial.SerialException:
        pass
    if "V=200" not in robot.request("STATUS"):
        fail("the first client lost its session to the refused one")

    # Closing and reopening the port resets the board: the move is over and
    # V is back to 140.
    robot.close()
    robot = Robot(url)
    status = robot.request("STATUS")
    if "V=140" not in status or "MOT:IDLE" not in status:
        fail("STATUS after reopening: %s (expected the board reset: V=140, MOT:IDLE)" % status)
    robot.close()
    return ("timings: 1,000 bytes and a PING answered after %.3f s at 9600 baud; 5 HELP round "
            "trips %.3f s at 9600 baud, %.3f s at 2400 baud; after the reopen %s"
            % (at_1000, at_9600, at_2400, status))


def check_log(log, status):
    if status != 0:
        fail("hil mock exited with status %s" % status)
    lines = log.splitlines()
    if sum("client connected" in l for l in lines) != 2:
        fail("expected two sessions (the open and the reopen) in hil's log")
    if not any("refused: the port is in use by 127.0.0.1:" in l for l in lines):
        fail("the refused second client is not in hil's log")
    if not any("the client set 2400 baud 8N1" in l for l in lines):
        fail("the rate change away from the car's 9600 baud is not in hil's log")
    expected = ("client connected", "client gone", "refused: the port is in use",
                "the client set 2400",
                "matches the car's again", "hil mock", "world ", "car0 connect an RFC 2217")
    for line in lines:
        if line.strip() and not any(e in line for e in expected):
            fail("unexpected line in hil's log: " + line)


if __name__ == "__main__":
    main()
