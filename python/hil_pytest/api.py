"""A client for the control API of `hil proxy --api` (standard library only).

The routes and toxics endpoints have Toxiproxy 2.x's shapes, so the names
here follow Toxiproxy's: a route is what Toxiproxy calls a proxy. hil's own
endpoints (fault profiles, links, stalls, frames, metrics) live under /hil/.
"""

import json
import time
import urllib.error
import urllib.parse
import urllib.request

__all__ = ["HilApi", "HilApiError"]


class HilApiError(Exception):
    """A request the control API refused (or could not be reached for).

    `status` is the HTTP status (0 when no answer came), `message` the
    API's own text, e.g. ``upstream: expected HOST:PORT or a URI``.
    """

    def __init__(self, method, url, status, message):
        self.method = method
        self.url = url
        self.status = status
        self.message = message
        where = "%s %s" % (method, url)
        if status:
            super().__init__("%s: HTTP %d: %s" % (where, status, message))
        else:
            super().__init__("%s: %s" % (where, message))


def _quote(name):
    return urllib.parse.quote(str(name), safe="")


class HilApi:
    """The control API at `url` (e.g. ``http://127.0.0.1:8474``).

    Every method raises HilApiError on an HTTP error status, with the
    API's message. A 429 (too many requests) is retried after the
    Retry-After the API names, up to `retries_429` times.
    """

    def __init__(self, url, timeout_s=10.0, retries_429=5):
        self.url = url.rstrip("/")
        self.timeout_s = timeout_s
        self.retries_429 = retries_429

    def __repr__(self):
        return "HilApi(%r)" % self.url

    # -- plumbing ----------------------------------------------------------

    def request(self, method, path, body=None, content_type=None, raw=False):
        """One request; the decoded JSON answer (None when empty), or the
        text when `raw` is set. `body` is sent as JSON unless it is a str
        or bytes (then as it is, with `content_type`)."""
        data = None
        headers = {}
        if body is not None:
            if isinstance(body, (bytes, bytearray)):
                data = bytes(body)
            elif isinstance(body, str):
                data = body.encode("utf-8")
            else:
                data = json.dumps(body).encode("utf-8")
                content_type = content_type or "application/json"
            headers["Content-Type"] = content_type or "application/octet-stream"
        url = self.url + path
        for attempt in range(self.retries_429 + 1):
            req = urllib.request.Request(url, data=data, method=method, headers=headers)
            try:
                with urllib.request.urlopen(req, timeout=self.timeout_s) as answer:
                    text = answer.read().decode("utf-8")
                break
            except urllib.error.HTTPError as error:
                text = error.read().decode("utf-8", "replace")
                if error.code == 429 and attempt < self.retries_429:
                    time.sleep(_retry_after_s(error.headers.get("Retry-After")))
                    continue
                raise HilApiError(method, url, error.code, _error_message(text)) from None
            except (urllib.error.URLError, OSError) as error:
                reason = getattr(error, "reason", error)
                raise HilApiError(method, url, 0, "the control API is not reachable (%s)" % reason) from None
        if raw:
            return text
        if not text.strip():
            return None
        return json.loads(text)

    def get(self, path, raw=False):
        return self.request("GET", path, raw=raw)

    def post(self, path, body=None, **kwargs):
        return self.request("POST", path, body, **kwargs)

    def put(self, path, body=None, **kwargs):
        return self.request("PUT", path, body, **kwargs)

    def delete(self, path):
        return self.request("DELETE", path)

    # -- Toxiproxy-compatible routes ("proxies") ---------------------------

    def version(self):
        """The version text, e.g. ``hil 0.1.0 (Toxiproxy API 2.x)``."""
        return self.get("/version", raw=True).strip()

    def routes(self):
        """Every route: {name: route}."""
        return self.get("/proxies")

    def route(self, name):
        return self.get("/proxies/" + _quote(name))

    def create_route(self, name, upstream, listen="127.0.0.1:0", protocol=None, profile=None, enabled=True):
        """A new route; `listen` "127.0.0.1:0" takes a free port (the
        answer's ``listen`` names it). `protocol` (logi, wr8, arduino,
        leka, raw) makes faults frame-aware."""
        body = {"name": name, "listen": listen, "upstream": upstream, "enabled": enabled}
        if protocol:
            body["protocol"] = protocol
        if profile:
            body["profile"] = profile
        return self.post("/proxies", body)

    def update_route(self, name, **fields):
        """Change listen, upstream or enabled of a route."""
        return self.post("/proxies/" + _quote(name), fields)

    def delete_route(self, name):
        self.delete("/proxies/" + _quote(name))

    def populate(self, routes):
        """Create several routes at once (a list of create_route's bodies)."""
        return self.post("/populate", list(routes))["proxies"]

    def enable(self, name):
        return self.update_route(name, enabled=True)

    def disable(self, name):
        """Stop listening and close every link of the route."""
        return self.update_route(name, enabled=False)

    def reset(self):
        """Every route enabled, with the faults and toxics it was declared
        with (none for routes made through the API)."""
        self.post("/reset")

    # -- toxics --------------------------------------------------------------

    def toxics(self, route):
        return self.get("/proxies/%s/toxics" % _quote(route))

    def toxic(self, route, name):
        return self.get("/proxies/%s/toxics/%s" % (_quote(route), _quote(name)))

    def add_toxic(self, route, type, stream="downstream", toxicity=1.0, name=None, attributes=None):
        """Add a toxic, e.g. add_toxic("car", "latency", attributes={"latency": 200}).
        Its name defaults to "<type>_<stream>"."""
        body = {"type": type, "stream": stream, "toxicity": toxicity, "attributes": dict(attributes or {})}
        if name:
            body["name"] = name
        return self.post("/proxies/%s/toxics" % _quote(route), body)

    def update_toxic(self, route, name, attributes=None, toxicity=None):
        body = {}
        if attributes is not None:
            body["attributes"] = dict(attributes)
        if toxicity is not None:
            body["toxicity"] = toxicity
        return self.post("/proxies/%s/toxics/%s" % (_quote(route), _quote(name)), body)

    def remove_toxic(self, route, name):
        self.delete("/proxies/%s/toxics/%s" % (_quote(route), _quote(name)))

    # -- hil's own endpoints -----------------------------------------------

    def set_faults(self, route, profile):
        """Replace the route's fault profile (docs/faults.md): YAML text, or
        a dict / list with the YAML's structure. Returns the rule count."""
        if isinstance(profile, str):
            path = "/hil/proxies/%s/faults" % _quote(route)
            answer = self.put(path, profile, content_type="application/yaml")
        else:
            if isinstance(profile, (list, tuple)):
                profile = {"rules": list(profile)}
            answer = self.put("/hil/proxies/%s/faults" % _quote(route), profile)
        return answer["rules"] if isinstance(answer, dict) else answer

    def clear_faults(self, route):
        return self.set_faults(route, {"rules": []})

    def faults(self, route):
        """{"rules": N, "yaml": "..."} for the route's current profile."""
        return self.get("/hil/proxies/%s/faults" % _quote(route))

    def links(self, route=None):
        """The links (client connections) of one route, or of every route."""
        if route is None:
            return self.get("/hil/links")
        return self.get("/hil/proxies/%s/links" % _quote(route))

    def stall(self, route, link, duration_ms, direction="both"):
        """Hold every byte of link `link` for `duration_ms`, then let it flow
        (direction: both, to_car, to_client)."""
        body = {"duration_ms": int(duration_ms), "direction": direction}
        self.post("/hil/proxies/%s/links/%d/stall" % (_quote(route), int(link)), body)

    def reset_link(self, route, link):
        """Reset (RST) link `link` on both sides."""
        self.post("/hil/proxies/%s/links/%d/reset" % (_quote(route), int(link)))

    def frames(self, route, limit=50):
        """The last `limit` decoded frames of the route, oldest first."""
        return self.get("/hil/proxies/%s/frames?limit=%d" % (_quote(route), int(limit)))

    def metrics(self):
        """The Prometheus text of /metrics."""
        return self.get("/metrics", raw=True)

    def metric(self, family, **labels):
        """The sum of the samples of `family` whose labels include `labels`
        (0.0 when none), e.g. metric("hil_proxy_frames_total", route="car")."""
        return metric_value(self.metrics(), family, **labels)


def metric_value(text, family, **labels):
    """Sum of the samples of `family` in Prometheus text whose labels include `labels`."""
    total = 0.0
    for line in text.splitlines():
        if not line or line.startswith("#"):
            continue
        name, _, rest = line.partition("{")
        if rest:
            label_text, _, value = rest.rpartition("}")
        else:
            name, _, value = line.partition(" ")
            label_text = ""
        if name.strip() != family:
            continue
        found = _parse_labels(label_text)
        if all(found.get(key) == str(want) for key, want in labels.items()):
            total += float(value.split()[0])
    return total


def _parse_labels(text):
    labels = {}
    i = 0
    while i < len(text):
        eq = text.find("=", i)
        if eq < 0:
            break
        key = text[i:eq].strip().lstrip(",").strip()
        j = eq + 2  # past ="
        value = []
        while j < len(text) and text[j] != '"':
            if text[j] == "\\" and j + 1 < len(text):
                j += 1
                value.append({"n": "\n"}.get(text[j], text[j]))
            else:
                value.append(text[j])
            j += 1
        labels[key] = "".join(value)
        i = j + 1
    return labels


def _retry_after_s(header):
    try:
        return max(0.05, min(float(header), 5.0))
    except (TypeError, ValueError):
        return 1.0


def _error_message(text):
    try:
        answer = json.loads(text)
    except ValueError:
        return text.strip() or "(no message)"
    if isinstance(answer, dict) and "error" in answer:
        return str(answer["error"])
    return text.strip()
