"""The explorer's server serves only what a page needs (issue 33).

Panel's ``/components/<module>/<class>/…`` route imports the module named in the URL. It was
limited to the ``panel`` and ``bokeh`` packages, but not to their resources:
``GET /components/panel.tests.conftest/pytest/_css/a`` made the server import a test module
(and pytest with it), and ``/components/bokeh.sampledata.iris/…`` answered 500 with a traceback
in the server's log. It now answers only for the classes of the components of the pages it
serves, whose modules are imported already. ``Host: [::1]`` answered 500 (Panel cannot parse an
IPv6 host); it is now redirected to ``localhost``, and no ``Host`` header gets a 500.

One server runs for the module (``gearchaos explore --port 0 --no-browser`` in its own
process, with an audit hook that reports every import of a test or sample-data module on
stderr). Each case sends one request and waits for the server's access-log line of it (the
readiness signal), then reads what the server logged meanwhile: no import by URL, no
traceback. The server is stopped with SIGTERM at the end.
"""

from __future__ import annotations

import http.client
import os
import queue
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from typing import Any
from urllib.parse import urlparse

import pytest

#: Seconds any wait may take (a loaded CI machine).
BOUND = 120.0

#: The CLI with an audit hook that reports imports of modules no page needs.
SCRIPT = """
import sys

def report(event, args):
    if event == "import" and str(args[0]).startswith(("panel.tests", "bokeh.sampledata")):
        print(f"IMPORTED {args[0]}", file=sys.stderr, flush=True)

sys.addaudithook(report)
from gearchaos.cli import app
app(sys.argv[1:], prog_name="gearchaos")
"""


class Server:
    """The explorer's process, its URL and the lines it logs."""

    def __init__(self, store: str) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-c", SCRIPT, "explore", store, "--port", "0", "--no-browser"],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
            env={**os.environ, "COLUMNS": "200"},
        )  # fmt: skip
        self.out: queue.Queue[str] = queue.Queue()
        self.log: list[str] = []
        self.probes = 0
        self._lock = threading.Lock()
        assert self.proc.stdout is not None and self.proc.stderr is not None
        threading.Thread(target=self._read_out, daemon=True).start()
        threading.Thread(target=self._read_log, daemon=True).start()
        self.url = self._wait_url()
        self.port = urlparse(self.url).port

    def _read_out(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.out.put(line)

    def _read_log(self) -> None:
        assert self.proc.stderr is not None
        for line in self.proc.stderr:
            with self._lock:
                self.log.append(line)

    def _wait_url(self) -> str:
        deadline = time.monotonic() + BOUND
        while time.monotonic() < deadline and self.proc.poll() is None:
            try:
                line = self.out.get(timeout=1)
            except queue.Empty:
                continue
            if "http://" in line:
                return line[line.index("http://") :].split()[0]
        self.stop()
        pytest.fail(f"the explorer printed no URL: {''.join(self.log)}")

    def _request(self, path: str, host: str) -> tuple[int, dict[str, str]]:
        conn = http.client.HTTPConnection("localhost", self.port, timeout=BOUND)
        try:
            conn.request("GET", path, headers={"Host": host})
            r = conn.getresponse()
            r.read()
            return r.status, {k.lower(): v for k, v in r.getheaders()}
        finally:
            conn.close()

    def get(self, path: str, host: str) -> tuple[int, dict[str, str], list[str]]:
        """(status, headers, the server's log lines of this request). The lines are complete
        once the access-log line of a probe sent after it appears: the server answers and logs
        one request after the other."""
        with self._lock:
            start = len(self.log)
        status, headers = self._request(path, host)
        self.probes += 1
        probe = f"/components/probe{self.probes}/x/_css/a"
        self._request(probe, f"localhost:{self.port}")
        deadline = time.monotonic() + BOUND
        while time.monotonic() < deadline:
            with self._lock:
                lines = self.log[start:]
            done = [i for i, ln in enumerate(lines) if f"GET {probe} " in ln]
            if done:
                return status, headers, lines[: done[0]]
            time.sleep(0.05)
        pytest.fail(f"the server logged no line of {probe} in {BOUND} s")

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout=BOUND)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(timeout=BOUND)


@pytest.fixture(scope="module")
def server(gear_store: Any) -> Iterator[Server]:
    srv = Server(str(gear_store))
    try:
        yield srv
    finally:
        srv.stop()


def _clean(lines: list[str]) -> None:
    text = "".join(lines)
    assert "IMPORTED" not in text, f"a module was imported by URL:\n{text}"
    assert "Traceback" not in text and "Uncaught exception" not in text, text


@pytest.mark.parametrize(
    "path",
    [
        "/components/panel.tests.conftest/pytest/_css/a",
        "/components/bokeh.sampledata.iris/flowers/_css/a",
        "/components/panel.tests/conftest/_css/a",
        "/components/panel%2Etests.conftest/pytest/_css/a",
        "/components/this/Zen/_css/x.css",
        "/components/panel.layout.base/NoSuchClass/_css/a",
        "/components/panel.layout.base",
    ],
)
def test_a_component_no_page_uses_is_refused_without_an_import(server: Server, path: str) -> None:
    status, _, lines = server.get(path, f"localhost:{server.port}")
    assert status == 403, (status, lines)
    _clean(lines)


def test_a_component_the_page_uses_reaches_panel(server: Server) -> None:
    local = f"localhost:{server.port}"
    status, _, lines = server.get("/", local)  # a page: its components are known
    assert status == 200
    status, _, lines = server.get("/components/panel.layout.base/Column/_css/a", local)
    assert status == 404, (status, lines)  # Panel's answer: Column lists no such resource
    _clean(lines)


@pytest.mark.parametrize("suffix", ["", ":{port}"])
def test_the_ipv6_loopback_is_redirected_to_localhost(server: Server, suffix: str) -> None:
    status, headers, lines = server.get("/", "[::1]" + suffix.format(port=server.port))
    assert status == 307, (status, lines)
    assert headers["location"] == f"http://localhost:{server.port}/"
    _clean(lines)


@pytest.mark.parametrize("host", ["localhost:{port}", "127.0.0.1:{port}", "LOCALHOST", "localhost"])
def test_the_loopback_names_get_the_page(server: Server, host: str) -> None:
    status, _, lines = server.get("/", host.format(port=server.port))
    assert status == 200, (status, lines)
    _clean(lines)


@pytest.mark.parametrize(
    "host",
    ["[", "[::1", "]", "[::1]x", "[::2]", "[::1]:abc", "a:b:c", "localhost:abc", "localhost:1:2",
     "localhost:123456", "evil.example", "127.0.0.1.nip.io:{port}", "[::ffff:127.0.0.1]", "",
     " ", "localhost.", "xn--80ak6aa92e.com", "l\xf3calhost"],
)  # fmt: skip
def test_no_host_header_gets_a_server_error(server: Server, host: str) -> None:
    status, _, lines = server.get("/", host.format(port=server.port))
    assert status in (400, 403), (status, lines)
    _clean(lines)
