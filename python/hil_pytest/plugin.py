"""The pytest plugin (entry point `pytest11`, name `hil`).

Fixtures:
  hil_binary  the path of hil (--hil-binary, else $HIL_BINARY, else PATH)
  hil_mock    factory: hil_mock("logi") starts `hil mock logi` on a free
              port and gives a MockCar (host, port, address, uri)
  hil_proxy   factory: hil_proxy(mock_or_address) starts `hil proxy --api`
              with one route in front of it and gives the Route (host,
              port, address, toxics, faults, stall(), reset_link(), ...)
Everything a test starts is stopped (SIGTERM) when the test ends.
"""

import pytest

from .process import HilNotFound, HilStartError, MockCar, ProxyServer, find_hil_binary


def pytest_addoption(parser):
    group = parser.getgroup("hil", "hil mock cars and fault-injecting proxy")
    group.addoption(
        "--hil-binary",
        action="store",
        default=None,
        metavar="PATH",
        help="the hil program the hil_* fixtures run (default: $HIL_BINARY, else hil on PATH)",
    )


def pytest_configure(config):
    config.addinivalue_line("markers", "hil: a test that runs hil mock or hil proxy")


def _options_to_args(options):
    """{"profile": "firmware", "reply_latency": "0"} -> --profile firmware --reply-latency 0;
    True gives the bare flag, False and None leave it out."""
    args = []
    for key, value in options.items():
        if value is None or value is False:
            continue
        flag = "--" + key.replace("_", "-")
        args.append(flag)
        if value is not True:
            args.append(str(value))
    return args


@pytest.fixture(scope="session")
def hil_binary(request):
    """The path of the hil program; the test errors out, saying where it
    looked, when there is none."""
    try:
        return find_hil_binary(request.config.getoption("--hil-binary"))
    except HilNotFound as error:
        message = str(error)
    pytest.fail(message, pytrace=False)


@pytest.fixture
def hil_mock(hil_binary):
    """Factory: hil_mock("logi", profile="firmware", faults="f.yaml",
    args=[...]) starts `hil mock` on a free port (or a pty of its own for
    serial cars) and gives the MockCar. Keyword options become hil's
    options (reply_latency="0" -> --reply-latency 0)."""
    started = []

    def start(car="logi", args=(), **options):
        try:
            mock = MockCar(hil_binary, car, _options_to_args(options) + list(args))
        except HilStartError as error:
            message = str(error)
        else:
            started.append(mock)
            return mock
        pytest.fail(message, pytrace=False)

    yield start
    for mock in reversed(started):
        mock.stop()


@pytest.fixture
def hil_proxy(hil_binary):
    """Factory: hil_proxy(target, protocol=None, profile=None, name="car",
    listen="127.0.0.1:0", args=[...]) starts `hil proxy --api 0` with one
    route, NAME, in front of `target` (a MockCar from hil_mock, "HOST:PORT"
    or a hil URI; listen may be a pty:// URI for a serial client), and gives
    the Route: clients connect to its host/port/address; .toxics, .faults,
    .stall(), .reset_link(), .links(), .frames(), .disable() act on it,
    .api is the whole control API and .server the process. With target
    None the proxy starts with no route and the ProxyServer is given."""
    started = []

    def start(target=None, protocol=None, profile=None, name="car", listen="127.0.0.1:0", args=()):
        try:
            server = ProxyServer(hil_binary, list(args))
        except HilStartError as error:
            message = str(error)
        else:
            started.append(server)
            return server if target is None else server.add_route(target, name, protocol, profile, listen)
        pytest.fail(message, pytrace=False)

    yield start
    for server in reversed(started):
        server.stop()
