#!/usr/bin/env python3
# `hil proxy --api 0 --config routes.yaml` in front of `hil mock logi`, as a
# user runs them: the route answers a LOGI client, the control API lists
# the route, its link and its counters, a latency toxic added over HTTP
# slows the car's answers and goes away again; --api on every interface
# warns; a bad routes file is named with its line; a command line with
# nothing to proxy is refused.
#
# Usage: hil_proxy_api_cli_test.py HIL_BINARY
# Standard library only.

import json
import os
import re
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request

TIMEOUT_S = 10.0


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


class Program:
    """A hil process whose stdout and stderr lines are collected."""

    def __init__(self, args):
        self.args = args
        self.proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     stdin=subprocess.DEVNULL, text=True)
        self.out = []
        self.err = []
        self.lock = threading.Lock()
        self.threads = [threading.Thread(target=self._read, args=(self.proc.stdout, self.out)),
                        threading.Thread(target=self._read, args=(self.proc.stderr, self.err))]
        for t in self.threads:
            t.daemon = True
            t.start()

    def _read(self, stream, lines):
        for line in stream:
            with self.lock:
                lines.append(line.rstrip("\n"))

    def text(self):
        with self.lock:
            return "\n".join(self.out) + "\n--- stderr:\n" + "\n".join(self.err)

    def wait_for(self, pattern, stream="out"):
        """The first match of `pattern` in a line of that stream."""
        deadline = time.monotonic() + TIMEOUT_S
        while time.monotonic() < deadline:
            with self.lock:
                for line in (self.out if stream == "out" else self.err):
                    m = re.search(pattern, line)
                    if m:
                        return m
            if self.proc.poll() is not None:
                time.sleep(0.2)
                with self.lock:
                    for line in (self.out if stream == "out" else self.err):
                        m = re.search(pattern, line)
                        if m:
                            return m
                fail("%s ended (%s) before printing /%s/:\n%s" %
                     (" ".join(self.args), self.proc.returncode, pattern, self.text()))
            time.sleep(0.05)
        fail("no line matching /%s/ within %.0f s:\n%s" % (pattern, TIMEOUT_S, self.text()))

    def interrupt(self):
        """Ctrl-C, then the exit status."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
        try:
            status = self.proc.wait(timeout=TIMEOUT_S)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            fail("%s did not stop on Ctrl-C:\n%s" % (" ".join(self.args), self.text()))
        for t in self.threads:
            t.join(timeout=2)
        return status

    def kill(self):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()


def http(method, url, body=None, content_type="application/json"):
    """(status, headers, text) of one request; 4xx and 5xx included."""
    data = None
    if body is not None:
        data = body if isinstance(body, bytes) else body.encode("utf-8")
    request = urllib.request.Request(url, data=data, method=method)
    if data is not None:
        request.add_header("Content-Type", content_type)
    try:
        with urllib.request.urlopen(request, timeout=TIMEOUT_S) as reply:
            return reply.status, reply.headers, reply.read().decode("utf-8")
    except urllib.error.HTTPError as error:
        return error.code, error.headers, error.read().decode("utf-8")


def logi_frame(payload):
    head = "LOGI:" + payload
    return ("%s:%02X#" % (head, sum(head.encode("ascii")) & 0xFF)).encode("ascii")


def logi_answer(port, payload="SP:050"):
    """Seconds until the car's FB answer to `payload`, over a new connection."""
    code = payload.split(":", 1)[0]
    with socket.create_connection(("127.0.0.1", port), timeout=TIMEOUT_S) as sock:
        start = time.monotonic()
        sock.sendall(logi_frame(payload))
        data = b""
        while True:
            chunk = sock.recv(4096)
            if not chunk:
                fail("the route closed before answering %s (got %r)" % (payload, data))
            data += chunk
            if re.search(rb"LOGI:FB:" + code.encode("ascii") + rb":[^#]*#", data):
                return time.monotonic() - start


def check_routes_file_and_api(hil, workdir):
    mock = Program([hil, "mock", "logi", "--port", "0"])
    try:
        car_port = int(mock.wait_for(r"tcp://127\.0\.0\.1:(\d+)").group(1))
        routes = os.path.join(workdir, "routes.yaml")
        with open(routes, "w") as f:
            f.write("routes:\n"
                    "  - name: car\n"
                    "    protocol: logi\n"
                    "    listen: 127.0.0.1:0\n"
                    "    upstream: tcp://127.0.0.1:%d\n" % car_port)
        proxy = Program([hil, "proxy", "--api", "0", "--config", routes, "-q"])
        try:
            api = proxy.wait_for(r"control API at (http://127\.0\.0\.1:\d+)").group(1)
            route_port = int(proxy.wait_for(
                r"route car: clients connect to tcp://127\.0\.0\.1:(\d+)").group(1))
            if "reachable from other machines" in proxy.text():
                fail("a warning for an API on loopback:\n" + proxy.text())

            logi_answer(route_port)

            status, _, text = http("GET", api + "/version")
            if status != 200 or not text.startswith("hil "):
                fail("GET /version: %s %s" % (status, text))
            status, _, text = http("GET", api + "/proxies")
            proxies = json.loads(text)
            if status != 200 or list(proxies) != ["car"]:
                fail("GET /proxies: %s %s" % (status, text))
            car = proxies["car"]
            if car["listen"] != "127.0.0.1:%d" % route_port or car["protocol"] != "logi" \
                    or car["enabled"] is not True:
                fail("the route as the API shows it: %s" % text)
            status, _, text = http("GET", api + "/hil/links")
            links = json.loads(text)
            if status != 200 or len(links) != 1 or links[0]["route"] != "car" \
                    or links[0]["bytes"]["to_car"] < len(logi_frame("SP:050")):
                fail("GET /hil/links after one exchange: %s %s" % (status, text))

            # A toxic over HTTP slows the car's answers, and is removed.
            toxic = {"type": "latency", "stream": "downstream", "attributes": {"latency": 400}}
            status, _, text = http("POST", api + "/proxies/car/toxics", json.dumps(toxic))
            if status != 200 or json.loads(text)["name"] != "latency_downstream":
                fail("POST a toxic: %s %s" % (status, text))
            slow = logi_answer(route_port)
            if slow < 0.38:
                fail("an answer %.3f s after the command with 400 ms of latency" % slow)
            status, _, text = http("DELETE", api + "/proxies/car/toxics/latency_downstream")
            if status != 204:
                fail("DELETE the toxic: %s %s" % (status, text))
            logi_answer(route_port)

            # What a bad request gets, and the route still answers.
            status, _, text = http("POST", api + "/proxies/car/toxics", "{not json")
            if status != 400 or not json.loads(text)["error"].startswith("body: not JSON"):
                fail("bad JSON: %s %s" % (status, text))
            status, _, text = http("GET", api + "/nothing")
            if status != 404 or "/nothing" not in json.loads(text)["error"]:
                fail("an unknown path: %s %s" % (status, text))
            logi_answer(route_port)

            status, headers, text = http("GET", api + "/metrics")
            if status != 200 or not headers["Content-Type"].startswith("text/plain; version=0.0.4"):
                fail("GET /metrics: %s %s" % (status, headers))
            if 'hil_proxy_connections_total{route="car"} 4' not in text:
                fail("four connections counted on the route:\n" + text)

            if proxy.interrupt() != 0:
                fail("hil proxy did not exit 0 on Ctrl-C:\n" + proxy.text())
            if "hil proxy: stopping (4 link(s) served" not in proxy.text():
                fail("no stopping line:\n" + proxy.text())
        finally:
            proxy.kill()
    finally:
        mock.kill()


def check_api_beyond_loopback_warns(hil):
    proxy = Program([hil, "proxy", "--api", "0.0.0.0:0"])
    try:
        proxy.wait_for(r"control API at http://0\.0\.0\.0:\d+")
        proxy.wait_for(r"^warning: .*0\.0\.0\.0.*reachable from other machines", stream="err")
        if proxy.interrupt() != 0:
            fail("hil proxy --api 0.0.0.0:0 did not exit 0 on Ctrl-C:\n" + proxy.text())
    finally:
        proxy.kill()


def check_bad_routes_file(hil, workdir):
    routes = os.path.join(workdir, "bad-routes.yaml")
    with open(routes, "w") as f:
        f.write("routes:\n"
                "  - name: car\n"
                "    protocol: logi\n"
                "    listn: 127.0.0.1:0\n"
                "    upstream: tcp://127.0.0.1:9\n")
    run = subprocess.run([hil, "proxy", "--api", "0", "--config", routes],
                         capture_output=True, text=True, timeout=TIMEOUT_S)
    if run.returncode == 0:
        fail("a bad routes file was accepted:\n" + run.stdout + run.stderr)
    if not re.search(re.escape(routes) + r":4:\d+: .*listn", run.stderr):
        fail("the error does not name the file, line 4 and the key:\n" + run.stderr)


def check_refused_command_lines(hil):
    for args, says in (([], "nothing to proxy"),
                       (["--listen", "tcp://127.0.0.1:0"], "--upstream is required with --listen"),
                       (["--api", "port"], "--api port: expected [ADDR:]PORT")):
        run = subprocess.run([hil, "proxy"] + args, capture_output=True, text=True,
                             timeout=TIMEOUT_S)
        if run.returncode != 2 or says not in run.stderr:
            fail("hil proxy %s: exit %d, expected 2 and '%s':\n%s" %
                 (" ".join(args), run.returncode, says, run.stderr))


def main():
    if len(sys.argv) != 2:
        fail("usage: hil_proxy_api_cli_test.py HIL_BINARY")
    hil = sys.argv[1]
    with tempfile.TemporaryDirectory(prefix="hil-proxy-api-") as workdir:
        check_refused_command_lines(hil)
        check_bad_routes_file(hil, workdir)
        check_api_beyond_loopback_warns(hil)
        check_routes_file_and_api(hil, workdir)
    print("ok")


if __name__ == "__main__":
    main()
