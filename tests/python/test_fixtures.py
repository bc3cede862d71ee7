"""The hil_pytest fixtures and API client themselves: what a user meets
when hil is missing, the mock's address, a proxy with no routes."""

import os
import re
import socket
import subprocess
import sys
import textwrap

import pytest

import hil_pytest
from hil_pytest import HilApiError, metric_value


def run_inner_pytest(request, tmp_path, test_text, *args):
    """pytest in a child process on one test file, with the hil plugin
    loaded the way this run loaded it (entry point or -p)."""
    (tmp_path / "test_inner.py").write_text(textwrap.dedent(test_text))
    command = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", str(tmp_path)]
    env = dict(os.environ)
    if request.config.pluginmanager.get_plugin("hil") is None:
        command += ["-p", "hil_pytest.plugin"]
        package_parent = os.path.dirname(os.path.dirname(os.path.abspath(hil_pytest.__file__)))
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [package_parent, env.get("PYTHONPATH")]))
    return subprocess.run(
        command + list(args), capture_output=True, text=True, timeout=120, cwd=str(tmp_path), env=env
    )


def set_speed_answer(host, port):
    """Sends LOGI SP:050 to host:port and gives the start of the FB:SP answer."""
    with socket.create_connection((host, port), timeout=5) as sock:
        sock.sendall(b"LOGI:SP:050:D7#")
        answer = b""
        while not re.search(rb"LOGI:FB:SP:[01]:", answer):
            data = sock.recv(4096)
            assert data, "the connection was closed before the answer"
            answer += data
    return re.search(rb"LOGI:FB:SP:[01]:", answer).group(0)


def test_a_missing_hil_is_a_clear_error(request, tmp_path):
    result = run_inner_pytest(
        request,
        tmp_path,
        """
        def test_needs_a_car(hil_mock):
            hil_mock("logi")
        """,
        "--hil-binary",
        str(tmp_path / "no-such-hil"),
    )
    assert result.returncode != 0
    assert "--hil-binary names" in result.stdout
    assert "not an executable file" in result.stdout
    assert "1 error" in result.stdout


def test_the_plugin_registers_its_option(request, tmp_path):
    result = run_inner_pytest(request, tmp_path, "", "--help")
    assert "--hil-binary=PATH" in result.stdout


def test_hil_mock_gives_a_car_that_answers(hil_mock):
    mock = hil_mock("logi", reply_latency="0ms")
    assert mock.uri == "tcp://%s:%d" % (mock.host, mock.port)
    assert mock.address == "%s:%d" % (mock.host, mock.port)
    assert set_speed_answer(mock.host, mock.port) == b"LOGI:FB:SP:1:"
    assert mock.running()
    assert mock.stop() == 0
    assert not mock.running()


def test_a_proxy_with_no_route_is_toxiproxy_shaped(hil_mock, hil_proxy):
    server = hil_proxy()
    api = server.api
    assert api.version().startswith("hil ")
    assert api.routes() == {}
    with pytest.raises(HilApiError) as missing:
        api.route("nope")
    assert missing.value.status == 404
    assert "nope" in missing.value.message

    mock = hil_mock("logi")
    made = api.create_route("car", mock.address, protocol="logi")
    assert made["name"] == "car"
    assert made["upstream"] == mock.address
    assert made["enabled"] is True
    assert made["toxics"] == []
    assert made["listen"].startswith("127.0.0.1:") and not made["listen"].endswith(":0")
    assert list(api.routes()) == ["car"]
    with pytest.raises(HilApiError) as twice:
        api.create_route("car", mock.address)
    assert twice.value.status == 409
    with pytest.raises(HilApiError) as bad:
        api.create_route("other", "")
    assert bad.value.status == 400
    assert "upstream" in bad.value.message

    made = api.populate([{"name": "a", "listen": "127.0.0.1:0", "upstream": mock.address}])
    assert [route["name"] for route in made] == ["a"]
    assert sorted(api.routes()) == ["a", "car"]
    api.delete_route("a")
    assert sorted(api.routes()) == ["car"]
    assert metric_value(api.metrics(), "hil_proxy_route_enabled", route="car") == 1


def test_metric_value_reads_prometheus_text():
    text = textwrap.dedent(
        """\
        # HELP hil_proxy_frames_total Frames seen.
        # TYPE hil_proxy_frames_total counter
        hil_proxy_frames_total{route="car",direction="to_car"} 3
        hil_proxy_frames_total{route="car",direction="to_client"} 5
        hil_proxy_frames_total{route="b",direction="to_car"} 7
        hil_proxy_open_links 2
        """
    )
    assert metric_value(text, "hil_proxy_frames_total", route="car") == 8
    assert metric_value(text, "hil_proxy_frames_total", direction="to_car") == 10
    assert metric_value(text, "hil_proxy_frames_total", route="none") == 0
    assert metric_value(text, "hil_proxy_open_links") == 2


def test_a_route_in_front_of_a_mock_takes_its_car_and_profile(hil_mock, hil_proxy):
    mock = hil_mock("logi", profile="firmware")
    route = hil_proxy(mock)
    info = route.info()
    assert info["protocol"] == "logi"
    assert info["profile"] == "firmware"
    assert info["upstream"] == mock.address
    assert route.links() == []
    with pytest.raises(HilApiError) as no_link:
        route.stall(100, link=7)
    assert no_link.value.status == 404


def test_a_proxy_started_with_listen_and_upstream_has_that_route(hil_mock, hil_proxy):
    mock = hil_mock("logi")
    server = hil_proxy(
        args=["--protocol", "logi", "--listen", "tcp://127.0.0.1:0", "--upstream", mock.uri, "--name", "desk"]
    )
    route = server.route("desk")
    assert list(server.api.routes()) == ["desk"]
    assert route.info()["protocol"] == "logi"
    assert set_speed_answer(route.host, route.port) == b"LOGI:FB:SP:1:"
    with pytest.raises(HilApiError) as missing:
        server.route("proxy")
    assert missing.value.status == 404
