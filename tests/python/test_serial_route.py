"""A serial client (the Arduino robot's) with pySerial: the mock robot on
a pty of its own, and a proxy route that gives the client a pty in front
of it. Skipped without pySerial (Debian's python3-serial)."""

import time

import pytest

serial = pytest.importorskip("serial")


def xor_of(text):
    cs = 0
    for byte in text.encode("ascii"):
        cs ^= byte
    return cs


def request(port, seq, cmd, payload=" "):
    """The robot's answer to one request, as text."""
    body = "%02X|%s|%s" % (seq, cmd, payload)
    port.write(("^%s*%02X$" % (body, xor_of(body))).encode("ascii"))
    answer = port.read_until(b"$")
    assert answer.endswith(b"$"), "no whole answer within the port's timeout (got %r)" % answer
    return answer.decode("ascii")


def test_the_mock_robot_answers_on_its_own_pty(hil_mock):
    robot = hil_mock("arduino", baud=0)
    assert robot.uri == "pty://" + robot.path
    assert robot.port is None
    with serial.Serial(robot.path, 9600, timeout=3) as port:
        assert request(port, 1, "PING").startswith("^01|ACK|")


def test_a_serial_route_delays_the_robots_answers(hil_mock, hil_proxy, tmp_path):
    robot = hil_mock("arduino", baud=0)
    route = hil_proxy(robot, listen="pty://%s/robot" % tmp_path)
    assert route.path == str(tmp_path / "robot")
    with serial.Serial(route.path, 9600, timeout=3) as port:
        start = time.monotonic()
        assert request(port, 1, "PING").startswith("^01|ACK|")
        clean_s = time.monotonic() - start
        with route.toxics.add("latency", latency=300):
            start = time.monotonic()
            assert request(port, 2, "PING").startswith("^02|ACK|")
            slow_s = time.monotonic() - start
    print(
        "PING through a pty route: %.0f ms clean, %.0f ms with 300 ms latency"
        % (clean_s * 1e3, slow_s * 1e3)
    )
    # The answer leaves the robot after the request went out, and the
    # toxic holds it 300 ms from there.
    assert slow_s >= 0.29
    assert slow_s < clean_s + 0.3 + 1.0
