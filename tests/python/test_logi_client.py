"""The example LOGI client against `hil mock logi` through `hil proxy`,
with the hil_pytest fixtures: a clean run, then each fault a Python team
would put its client through. Times are real, so the bounds are wide."""

import statistics
import time

import pytest

from logi_client import LogiClient, Timeout


@pytest.fixture
def car(hil_mock, hil_proxy):
    """A LOGI mock car behind a proxy route; the client talks to the route."""
    mock = hil_mock("logi")
    return hil_proxy(mock)


def median_round_trip_s(client, times=5):
    return statistics.median(client.round_trip_s() for _ in range(times))


def test_clean_run_answers_at_once_and_the_proxy_counts_it(car):
    with LogiClient(car.host, car.port, timeout_s=2.0) as client:
        assert client.command("SP:050") == "FB:SP:1"
        assert client.command("GS:001") == "FB:GS:1"
        assert client.sent == 2
        assert client.timeouts == 0
        assert client.reconnects == 0
        assert client.bad_frames == 0

        links = car.links()
        assert len(links) == 1
        assert links[0]["open"]
        assert links[0]["frames"]["to_car"] == 2
        assert links[0]["frames"]["to_client"] >= 2
        assert car.metric("hil_proxy_frames_total", direction="to_car") == 2
        assert car.metric("hil_proxy_open_links") == 1
        kinds = [frame["kind"] for frame in car.frames() if frame["direction"] == "to_car"]
        assert kinds == ["SP", "GS"]


def test_latency_toxic_slows_every_answer_and_removing_it_restores_the_pace(car):
    with LogiClient(car.host, car.port, timeout_s=3.0) as client:
        baseline_s = median_round_trip_s(client)
        assert baseline_s < 0.2

        with car.toxics.add("latency", stream="downstream", latency=300) as toxic:
            assert toxic.name == "latency_downstream"
            assert [t.name for t in car.toxics] == ["latency_downstream"]
            slow_s = median_round_trip_s(client)
        assert len(car.toxics) == 0
        after_s = median_round_trip_s(client)

    print(
        "round trip: %.1f ms clean, %.1f ms with 300 ms latency, %.1f ms after"
        % (baseline_s * 1e3, slow_s * 1e3, after_s * 1e3)
    )
    assert slow_s - baseline_s >= 0.28
    assert slow_s < baseline_s + 0.3 + 0.5
    assert after_s < 0.2


def test_updating_a_toxic_changes_the_delay(car):
    with LogiClient(car.host, car.port, timeout_s=3.0) as client:
        toxic = car.toxics.add("latency", stream="downstream", latency=100)
        first_s = median_round_trip_s(client, 3)
        toxic.update(latency=400)
        assert toxic.attributes["latency"] == 400
        second_s = median_round_trip_s(client, 3)
        toxic.remove()
    print("round trip: %.1f ms at 100 ms latency, %.1f ms at 400 ms" % (first_s * 1e3, second_s * 1e3))
    assert 0.095 <= first_s < 0.6
    assert second_s - first_s >= 0.28


def test_a_stall_runs_the_retry_path(car):
    with LogiClient(car.host, car.port, timeout_s=0.3, attempts=10) as client:
        assert client.command("SP:050") == "FB:SP:1"
        car.stall(1000, direction="to_client")
        start = time.monotonic()
        assert client.command("SP:060") == "FB:SP:1"
        waited_s = time.monotonic() - start
    print("answer after a 1000 ms stall: %.0f ms, %d timeout(s)" % (waited_s * 1e3, client.timeouts))
    assert client.timeouts >= 2
    assert client.reconnects == 0
    assert 0.9 <= waited_s < 3.0


def test_a_reset_link_makes_the_client_reconnect(car):
    with LogiClient(car.host, car.port, timeout_s=1.0) as client:
        assert client.command("SP:050") == "FB:SP:1"
        first = car.latest_link()
        car.reset_link(first)
        # The client notices on its next command and comes back on a new link.
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline and any(l["open"] for l in car.links() if l["link"] == first):
            time.sleep(0.02)
        assert client.command("SP:070") == "FB:SP:1"
        assert client.reconnects == 1
    links = {link["link"]: link for link in car.links()}
    assert len(links) == 2
    assert not links[first]["open"]
    assert links[first]["close_reason"]


def test_a_timeout_toxic_holds_everything_then_closes_the_link(car):
    car.toxics.add("timeout", stream="upstream", timeout=500)
    with LogiClient(car.host, car.port, timeout_s=3.0, attempts=1) as client:
        start = time.monotonic()
        with pytest.raises(ConnectionError):
            client.command("SP:050")
        closed_after_s = time.monotonic() - start
    print("the timeout toxic closed the link after %.0f ms" % (closed_after_s * 1e3))
    assert 0.45 <= closed_after_s < 2.0

    car.toxics.remove("timeout_upstream")
    with LogiClient(car.host, car.port, timeout_s=2.0) as client:
        assert client.command("SP:050") == "FB:SP:1"


def test_a_timeout_toxic_of_zero_never_answers(car):
    car.toxics.add("timeout", stream="downstream", timeout=0)
    with LogiClient(car.host, car.port, timeout_s=0.3, attempts=2) as client:
        with pytest.raises(Timeout):
            client.command("SP:050")
        assert client.timeouts == 2


LOSE_FIRST_FEEDBACK = """\
description: the car's first answer to SP is lost on the way back
rules:
  - kind: drop
    name: lose first FB:SP
    direction: to_client
    match: "FB:SP"
    first: 1
"""


def test_set_faults_yaml_drops_the_first_answer_and_the_client_retries(car):
    assert car.faults.set(LOSE_FIRST_FEEDBACK) == 1
    assert car.faults.get()["rules"] == 1
    with LogiClient(car.host, car.port, timeout_s=0.3) as client:
        assert client.command("SP:050") == "FB:SP:1"
        assert client.sent == 2
        assert client.timeouts == 1
        assert client.command("SP:050") == "FB:SP:1"
        assert client.sent == 3
    (link,) = car.links()
    assert link["faults"].get("drop") == 1
    assert car.metric("hil_proxy_faults_total", kind="drop") == 1


def test_set_faults_as_a_dict_and_clearing_them(car):
    rule = {"kind": "drop", "direction": "to_client", "match": "FB:SP"}
    assert car.faults.set({"rules": [rule]}) == 1
    with LogiClient(car.host, car.port, timeout_s=0.3, attempts=2) as client:
        with pytest.raises(Timeout):
            client.command("SP:050")
        car.faults.clear()
        assert car.faults.get()["rules"] == 0
        assert client.command("SP:050") == "FB:SP:1"


def test_a_bad_fault_profile_is_refused_with_the_field_named(car):
    from hil_pytest import HilApiError

    with pytest.raises(HilApiError) as refused:
        car.faults.set("rules:\n  - kind: drop\n    frist: 1\n")
    assert refused.value.status == 400
    assert "frist" in refused.value.message


def test_disabling_the_route_cuts_the_link_and_refuses_new_ones(car):
    address = (car.host, car.port)
    with LogiClient(*address, timeout_s=1.0, attempts=1) as client:
        assert client.command("SP:050") == "FB:SP:1"
        assert car.disable()["enabled"] is False
        with pytest.raises(ConnectionError):
            client.command("SP:050")
    with pytest.raises(ConnectionRefusedError):
        LogiClient(*address, timeout_s=1.0).connect()

    car.enable()
    with LogiClient(car.host, car.port, timeout_s=2.0) as client:
        assert client.command("SP:050") == "FB:SP:1"


def test_reset_clears_api_made_toxics(car):
    car.toxics.add("latency", latency=1000)
    car.disable()
    car.api.reset()
    assert car.info()["enabled"] is True
    assert car.info()["toxics"] == []
    with LogiClient(car.host, car.port, timeout_s=0.5) as client:
        assert client.command("SP:050") == "FB:SP:1"
