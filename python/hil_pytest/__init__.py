"""hil for Python tests: mock cars, the fault-injecting proxy and its
control API, and pytest fixtures for them (see README.md)."""

from .api import HilApi, HilApiError, metric_value
from .process import (
    HilNotFound,
    HilProcess,
    HilStartError,
    MockCar,
    ProxyServer,
    Route,
    find_hil_binary,
    start_mock,
    start_proxy,
)

__version__ = "0.1.0"

__all__ = [
    "HilApi",
    "HilApiError",
    "HilNotFound",
    "HilProcess",
    "HilStartError",
    "MockCar",
    "ProxyServer",
    "Route",
    "find_hil_binary",
    "metric_value",
    "start_mock",
    "start_proxy",
]
