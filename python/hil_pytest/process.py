"""Start `hil mock` and `hil proxy --api` as a user runs them, learn where
they listen from their start lines, and stop them cleanly."""

import os
import re
import shutil
import signal
import subprocess
import tempfile
import threading
import time
import urllib.parse

from .api import HilApi

__all__ = [
    "HilNotFound",
    "HilStartError",
    "HilProcess",
    "MockCar",
    "ProxyServer",
    "Route",
    "find_hil_binary",
    "start_mock",
    "start_proxy",
]

START_TIMEOUT_S = 15.0
STOP_TIMEOUT_S = 5.0


class HilNotFound(RuntimeError):
    """No hil program where one was looked for."""


class HilStartError(RuntimeError):
    """hil did not start (it exited, or printed no start line in time)."""


def find_hil_binary(explicit=None):
    """The path of hil: `explicit` if given, else $HIL_BINARY, else `hil` on
    PATH. Raises HilNotFound saying where it looked."""
    for source, candidate in (("--hil-binary", explicit), ("HIL_BINARY", os.environ.get("HIL_BINARY"))):
        if candidate:
            path = os.path.abspath(os.path.expanduser(candidate))
            if os.path.isfile(path) and os.access(path, os.X_OK):
                return path
            raise HilNotFound("%s names %s, which is not an executable file" % (source, candidate))
    found = shutil.which("hil")
    if found:
        return found
    raise HilNotFound(
        "hil was not found: pass --hil-binary PATH to pytest, set HIL_BINARY, or put hil on PATH "
        "(build it with `cmake --build build --target hil`, or install the hil package)"
    )


class HilProcess:
    """A hil program in the background. Its stdout and stderr are read by a
    thread; `output` holds every line so far (for failure messages)."""

    def __init__(self, args, name):
        self.args = list(args)
        self.name = name
        self.lines = []
        self._cond = threading.Condition()
        self._closed = False
        try:
            self.proc = subprocess.Popen(
                self.args,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT,
                text=True,
                bufsize=1,
                start_new_session=True,
            )
        except OSError as error:
            raise HilStartError("%s: cannot run %s: %s" % (name, self.args[0], error)) from None
        self._reader = threading.Thread(target=self._read, name="hil-output-%s" % name, daemon=True)
        self._reader.start()

    def _read(self):
        for line in self.proc.stdout:
            with self._cond:
                self.lines.append(line.rstrip("\n"))
                self._cond.notify_all()
        with self._cond:
            self._closed = True
            self._cond.notify_all()

    @property
    def output(self):
        with self._cond:
            return "\n".join(self.lines)

    @property
    def pid(self):
        return self.proc.pid

    def running(self):
        return self.proc.poll() is None

    def wait_for_line(self, pattern, timeout_s=START_TIMEOUT_S, start=0):
        """The first match of `pattern` (a regex) in a line from index
        `start` on; raises HilStartError if hil exits or time runs out."""
        regex = re.compile(pattern)
        deadline = time.monotonic() + timeout_s
        index = start
        with self._cond:
            while True:
                while index < len(self.lines):
                    match = regex.search(self.lines[index])
                    index += 1
                    if match:
                        return match
                if self._closed:
                    break
                left = deadline - time.monotonic()
                if left <= 0:
                    break
                self._cond.wait(left)
            exited = self._closed
        self.stop()
        if exited:
            why = "exited with status %s" % self.proc.returncode
        else:
            why = "printed no line matching %r in %.0f s" % (pattern, timeout_s)
        command = " ".join(self.args)
        raise HilStartError("%s %s\ncommand: %s\noutput:\n%s" % (self.name, why, command, self.output))

    def stop(self, timeout_s=STOP_TIMEOUT_S):
        """SIGTERM, wait up to `timeout_s`, then SIGKILL (to hil and anything
        it started: it runs in a process group of its own). Returns the
        exit status."""
        if self.proc.poll() is None:
            self._signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout=timeout_s)
            except subprocess.TimeoutExpired:
                self._signal(signal.SIGKILL)
                self.proc.wait()
        self._reader.join(timeout=timeout_s)
        return self.proc.returncode

    def _signal(self, signum):
        try:
            os.killpg(self.proc.pid, signum)
        except (ProcessLookupError, PermissionError):
            if self.proc.poll() is None:
                self.proc.send_signal(signum)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()


class MockCar(HilProcess):
    """`hil mock CAR` on a free port (TCP cars) or a pty (serial cars).

    host, port and address ("HOST:PORT") for TCP cars; uri is what hil
    printed as a hil URI (tcp://HOST:PORT, pty:///PATH, rfc2217://...)."""

    def __init__(self, hil, car, args=(), timeout_s=START_TIMEOUT_S):
        self.car = car
        self._pty_dir = None
        cmd = [hil, "mock", car]
        args = list(args)
        #: The car's profile when --profile was given (a proxy route in front
        #: of the car judges frames by it), else None: the car's default.
        self.profile = args[args.index("--profile") + 1] if "--profile" in args[:-1] else None
        if car in ("logi", "wr8") and "--port" not in args:
            cmd += ["--port", "0"]
        elif car not in ("logi", "wr8") and "--pty" not in args and "--rfc2217" not in args:
            # A pty of its own rather than the shared default /tmp/hil-CAR0.
            self._pty_dir = tempfile.mkdtemp(prefix="hil-pytest-")
            cmd += ["--pty", os.path.join(self._pty_dir, car + "0")]
        super().__init__(cmd + args, "hil mock %s" % car)
        match = self.wait_for_line(r"car0 (?:connect to|open|connect an RFC 2217 client to) (\S+)", timeout_s)
        where = match.group(1).rstrip(",")
        #: A serial car's pty path (None for TCP and RFC 2217 cars).
        self.path = where if where.startswith("/") else None
        #: Where the car is, as a hil URI: tcp://..., rfc2217://... or pty:///...
        self.uri = "pty://" + where if self.path else where
        found = re.match(r"(?:tcp|rfc2217)://([^:/]+):(\d+)", where)
        self.host = found.group(1) if found else None
        self.port = int(found.group(2)) if found else None

    def stop(self, timeout_s=STOP_TIMEOUT_S):
        code = super().stop(timeout_s)
        if self._pty_dir:
            shutil.rmtree(self._pty_dir, ignore_errors=True)
        return code

    @property
    def address(self):
        """"HOST:PORT" of a TCP car (Toxiproxy's upstream form)."""
        if self.port is None or not self.uri.startswith("tcp://"):
            raise AttributeError("%s listens on %s, not on TCP" % (self.name, self.uri))
        return "%s:%d" % (self.host, self.port)

    def __repr__(self):
        return "MockCar(%r, %s)" % (self.car, self.uri)


class ProxyServer(HilProcess):
    """`hil proxy --api 0`: the control API on a free port, and no routes
    until some are made (`add_route`). Extra `args` (e.g. --config,
    --listen/--upstream/--protocol) are passed as they are."""

    def __init__(self, hil, args=(), timeout_s=START_TIMEOUT_S):
        args = list(args)
        cmd = [hil, "proxy"]
        if "--api" not in args:
            cmd += ["--api", "127.0.0.1:0"]
        super().__init__(cmd + args, "hil proxy")
        match = self.wait_for_line(r"control API at (http://\S+)", timeout_s)
        self.url = match.group(1).rstrip("/,")
        self.api = HilApi(self.url)

    def add_route(self, upstream, name="car", protocol=None, profile=None, listen="127.0.0.1:0"):
        """A route in front of `upstream` (a MockCar, "HOST:PORT" or a hil
        URI); the Route answers where clients connect."""
        if isinstance(upstream, MockCar):
            protocol = protocol or upstream.car
            profile = profile or upstream.profile
            upstream = upstream.address if upstream.uri.startswith("tcp://") else upstream.uri
        self.api.create_route(name, upstream, listen=listen, protocol=protocol, profile=profile)
        return Route(self.api, name, server=self)

    def route(self, name):
        """A route that already exists (from --config or --listen)."""
        self.api.route(name)
        return Route(self.api, name, server=self)

    def __repr__(self):
        return "ProxyServer(%s)" % self.url


class Toxic:
    """One toxic of a route: update(**attributes), remove(); a context
    manager that removes it on exit."""

    def __init__(self, route, body):
        self.route = route
        self.body = body

    name = property(lambda self: self.body["name"])
    type = property(lambda self: self.body["type"])
    stream = property(lambda self: self.body["stream"])
    attributes = property(lambda self: self.body.get("attributes", {}))

    def update(self, toxicity=None, **attributes):
        self.body = self.route.api.update_toxic(self.route.name, self.name, attributes or None, toxicity)
        return self

    def remove(self):
        self.route.api.remove_toxic(self.route.name, self.name)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.remove()

    def __repr__(self):
        return "Toxic(%r, %r, %r, %r)" % (self.name, self.type, self.stream, self.attributes)


class Toxics:
    """route.toxics: add("latency", latency=200), list(), get(name),
    remove(name), clear(); iterating gives the current toxics."""

    def __init__(self, route):
        self.route = route

    def add(self, type, stream="downstream", toxicity=1.0, name=None, **attributes):
        body = self.route.api.add_toxic(self.route.name, type, stream, toxicity, name, attributes)
        return Toxic(self.route, body)

    def list(self):
        return [Toxic(self.route, body) for body in self.route.api.toxics(self.route.name)]

    def get(self, name):
        return Toxic(self.route, self.route.api.toxic(self.route.name, name))

    def remove(self, name):
        self.route.api.remove_toxic(self.route.name, name)

    def clear(self):
        for toxic in self.list():
            toxic.remove()

    def __iter__(self):
        return iter(self.list())

    def __len__(self):
        return len(self.list())


class Faults:
    """route.faults: set(yaml_or_dict), get(), clear()."""

    def __init__(self, route):
        self.route = route

    def set(self, profile):
        return self.route.api.set_faults(self.route.name, profile)

    def get(self):
        return self.route.api.faults(self.route.name)

    def clear(self):
        return self.route.api.clear_faults(self.route.name)


class Route:
    """One route of a hil proxy: where clients connect (host, port,
    address, listen), its toxics and faults, and its links."""

    def __init__(self, api, name, server=None):
        self.api = api
        self.name = name
        self.server = server
        self.toxics = Toxics(self)
        self.faults = Faults(self)

    def info(self):
        return self.api.route(self.name)

    @property
    def listen(self):
        return self.info()["listen"]

    @property
    def host(self):
        return self._host_port()[0]

    @property
    def port(self):
        return self._host_port()[1]

    @property
    def address(self):
        host, port = self._host_port()
        return "%s:%d" % (host, port)

    @property
    def path(self):
        """The pty a serial client opens, for a route that listens on one."""
        listen = self.listen
        if not listen.startswith("pty://"):
            raise AttributeError("route %s listens on %s, not on a pty" % (self.name, listen))
        return urllib.parse.urlsplit(listen).path

    def _host_port(self):
        listen = self.listen
        found = re.match(r"(?:tcp://)?\[?([^\]/]*?)\]?:(\d+)$", listen)
        if not found:
            raise AttributeError("route %s listens on %s, not on TCP" % (self.name, listen))
        return found.group(1) or "127.0.0.1", int(found.group(2))

    def set_faults(self, profile):
        return self.faults.set(profile)

    def links(self, open_only=False):
        links = self.api.links(self.name)
        return [link for link in links if link.get("open")] if open_only else links

    def latest_link(self, timeout_s=5.0):
        """The id of the newest open link, waiting up to `timeout_s` for one."""
        deadline = time.monotonic() + timeout_s
        while True:
            links = self.links(open_only=True)
            if links:
                return max(link["link"] for link in links)
            if time.monotonic() > deadline:
                raise AssertionError("route %s has no open link after %.1f s" % (self.name, timeout_s))
            time.sleep(0.02)

    def stall(self, duration_ms, direction="both", link=None):
        """Hold the link's bytes for duration_ms (the newest link by default)."""
        self.api.stall(self.name, self.latest_link() if link is None else link, duration_ms, direction)

    def reset_link(self, link=None):
        """Reset (RST) a link, the newest by default."""
        self.api.reset_link(self.name, self.latest_link() if link is None else link)

    def frames(self, limit=50):
        return self.api.frames(self.name, limit)

    def metric(self, family, **labels):
        return self.api.metric(family, route=self.name, **labels)

    def enable(self):
        return self.api.enable(self.name)

    def disable(self):
        return self.api.disable(self.name)

    def update(self, **fields):
        return self.api.update_route(self.name, **fields)

    def remove(self):
        self.api.delete_route(self.name)

    def __repr__(self):
        return "Route(%r at %s)" % (self.name, self.api.url)


def start_mock(car, hil=None, args=()):
    """`hil mock CAR` on a free port; stop it with .stop() or `with`."""
    return MockCar(find_hil_binary(hil), car, args)


def start_proxy(hil=None, args=()):
    """`hil proxy --api 0`; stop it with .stop() or `with`."""
    return ProxyServer(find_hil_binary(hil), args)
