"""The explorer in a real browser: ``gearchaos explore`` serves a store, headless Chromium
(Debian's ``chromium``, driven by Playwright) loads the page, clicks points of the diagram and
reads what the page shows from its Bokeh documents; then the server stops cleanly.

Skipped only when no chromium executable is installed (``.ci/run`` installs it the way the
README tells users: ``apt-get install -y chromium``).
"""

from __future__ import annotations

import os
import queue
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any
from urllib.parse import urlparse

import numpy as np
import pytest
import xarray as xr
from bokeh_page import PIXEL_OF

CHROMIUM = next(
    (
        p
        for p in (shutil.which("chromium"), shutil.which("chromium-browser"), "/usr/bin/chromium")
        if p and os.path.exists(p)
    ),
    None,
)
pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(
        CHROMIUM is None, reason="no chromium executable (apt-get install -y chromium)"
    ),
]

#: Chromium flags for a headless run without a GPU, a sandbox or any network of its own.
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
#: Every wait is bounded (milliseconds).
LOAD_MS = 120_000
CLICK_MS = 120_000  # generous: the machine may be shared with other test workers
COMPUTE_MS = 300_000

MODEL = "([name, attr]) => Bokeh.documents[0].get_model_by_name(name)[attr]"
SECTION_SIZE = "() => Bokeh.documents[0].get_model_by_name('poincare-source').data.x.length"
TITLE = "() => Bokeh.documents[0].get_model_by_name('poincare-figure').title.text"


def _start(store: Path) -> dict[str, Any]:
    """``gearchaos explore STORE --port 0 --no-browser`` in its own process, and its URL."""
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "gearchaos",
            "explore",
            str(store),
            "--port",
            "0",
            "--no-browser",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "COLUMNS": "200"},
    )
    lines: queue.Queue[str] = queue.Queue()
    assert proc.stdout is not None
    threading.Thread(target=lambda: [lines.put(ln) for ln in proc.stdout], daemon=True).start()
    url, out = None, []
    deadline = time.monotonic() + LOAD_MS / 1000
    while url is None and time.monotonic() < deadline and proc.poll() is None:
        try:
            line = lines.get(timeout=1)
        except queue.Empty:
            continue
        out.append(line)
        if "http://" in line:
            url = line[line.index("http://") :].split()[0]
    if url is None:
        proc.kill()
        err = proc.stderr.read() if proc.stderr else ""
        pytest.fail(f"the explorer printed no URL: {''.join(out)} {err}")
    return {"proc": proc, "url": url, "lines": lines}


def _stop(server: dict[str, Any]) -> None:
    """SIGTERM (the explorer then ends its worker processes), SIGKILL only if it hangs: a
    killed server left its spawned workers running after the tests."""
    proc = server["proc"]
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=30)


def _open(browser: Any, url: str) -> Any:
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    page.set_default_timeout(LOAD_MS)
    page.goto(url, timeout=LOAD_MS)
    page.wait_for_function(
        "() => window.Bokeh && Bokeh.documents.length > 0 && "
        "Bokeh.documents[0].get_model_by_name('diagram-figure') !== null",
        timeout=LOAD_MS,
    )
    return page


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        yield b
        b.close()


@pytest.fixture(scope="module")
def server(gear_store: Path) -> Iterator[dict[str, Any]]:
    srv = _start(gear_store)
    yield srv
    _stop(srv)


@pytest.fixture
def page(server: dict[str, Any], browser: Any) -> Iterator[Any]:
    """A page of its own for each test (its own Bokeh session, no point selected), so that no
    test sees the point another one left selected."""
    pg = _open(browser, server["url"])
    yield pg
    pg.close()


def _click(page: Any, omega: float, y: float) -> None:
    """Click the diagram at (Ω, X̄) once its view is laid out."""
    page.wait_for_function(
        f"() => ({PIXEL_OF})(['diagram-figure', {omega}, {y}]) !== null", timeout=CLICK_MS
    )
    xy = page.evaluate(PIXEL_OF, ["diagram-figure", omega, y])
    assert xy is not None, "the diagram's view is not on the page"
    page.mouse.click(*xy)


def _stored(gear_store: Path, i: int) -> tuple[np.ndarray, str, float]:
    ds = xr.open_zarr(gear_store).load()
    x = ds.delta_sp.isel(omega=i).sel(planet=1).values
    return x[np.isfinite(x)], str(ds.motion.values[i]), float(ds.omega.values[i])


def test_the_page_loads_with_every_stored_section_value(page: Any, gear_store: Path) -> None:
    ds = xr.open_zarr(gear_store).load()
    n = page.evaluate("() => Bokeh.documents[0].get_model_by_name('diagram-source').data.y.length")
    assert n == int(np.isfinite(ds.delta_sp.values).sum())
    labels = page.evaluate(
        "() => Array.from(Bokeh.documents[0].get_model_by_name('band-source').data.label)"
    )
    assert labels == [str(m) for m in ds.motion.values]


def _names_omega(omega: float) -> str:
    """JavaScript: the point view's title names Ω = omega, followed by its rpm (``, n_s = …``)
    or the label (`` · …``) — not a longer number that starts with the same digits."""
    head = f"Ω = {omega:.6g}"
    either = f"t.startsWith('{head},') || t.startsWith('{head} ')"
    return f"() => {{ const t = ({TITLE})(); return {either}; }}"


def _shows(omega: float, size: int) -> str:
    """JavaScript: the point view shows the point Ω = omega with ``size`` section points."""
    return f"() => ({_names_omega(omega)})() && ({SECTION_SIZE})() === {size}"


def test_a_click_shows_the_points_label_and_stored_section(page: Any, gear_store: Path) -> None:
    x, label, omega = _stored(gear_store, 2)
    _click(page, omega + 0.01, float(np.median(x)))  # near, not on, the swept value
    # the point view names the clicked Ω: its section size alone (16 points at every Ω of this
    # store) held already for the point a click before had selected, and the title read then
    # was that point's
    page.wait_for_function(_shows(omega, x.size), timeout=CLICK_MS)
    title = page.evaluate(TITLE)
    assert f"Ω = {omega:.6g}" in title and f"· {label} ·" in title
    shown = page.evaluate(
        "() => Array.from(Bokeh.documents[0].get_model_by_name('poincare-source').data.x)"
    )
    np.testing.assert_array_equal(np.asarray(shown), x)
    page.get_by_text(f"motion (stored): {label}").wait_for(timeout=CLICK_MS)
    page.screenshot(path=str(gear_store.parent / "explorer-click.png"), full_page=True)


def test_a_second_click_replaces_the_point(page: Any, gear_store: Path) -> None:
    first, _, omega1 = _stored(gear_store, 1)
    _click(page, omega1, float(np.median(first)))
    page.wait_for_function(_names_omega(omega1), timeout=CLICK_MS)
    x, label, omega = _stored(gear_store, 6)
    _click(page, omega - 0.01, float(np.median(x)))
    page.wait_for_function(_names_omega(omega), timeout=CLICK_MS)
    assert f"· {label} · {x.size} stored section points" in page.evaluate(TITLE)
    shown = page.evaluate(
        "() => Array.from(Bokeh.documents[0].get_model_by_name('poincare-source').data.x)"
    )
    np.testing.assert_array_equal(np.asarray(shown), x)


def test_the_point_is_computed_in_the_background(page: Any, gear_store: Path) -> None:
    """The worker's views of the selected point arrive (motion, λ₁, figure) while the page
    stays live."""
    x, _, omega = _stored(gear_store, 4)
    _click(page, omega, float(np.median(x)))
    page.get_by_text(f"computed at omega = {omega:.6g}").wait_for(timeout=COMPUTE_MS)
    page.locator("img").first.wait_for(timeout=CLICK_MS)
    page.screenshot(path=str(gear_store.parent / "explorer-computed.png"), full_page=True)


def test_the_server_stops_cleanly(gear_store: Path, browser: Any) -> None:
    """SIGTERM (as Ctrl-C) with a page open: exit code 0, ``explorer stopped``, port closed."""
    server = _start(gear_store)
    try:
        port = urlparse(server["url"]).port
        pg = _open(browser, server["url"])
        proc = server["proc"]
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=60) == 0
        pg.close()
        rest = []
        while not server["lines"].empty():
            rest.append(server["lines"].get())
        assert "explorer stopped" in "".join(rest)
        with socket.socket() as s:
            assert s.connect_ex(("localhost", port)) != 0, "the port still accepts connections"
    finally:
        _stop(server)


def _get(url: str, path: str, host: str) -> tuple[int, str]:
    import http.client

    u = urlparse(url)
    conn = http.client.HTTPConnection(u.hostname or "localhost", u.port, timeout=30)
    try:
        conn.request("GET", path, headers={"Host": host})
        r = conn.getresponse()
        return r.status, r.read().decode("utf-8", "replace")
    finally:
        conn.close()


def test_the_server_answers_only_its_own_host_names(server: dict[str, Any]) -> None:
    # issue 23: any Host: header was served (DNS rebinding), and /components/<module>/ imported
    # any installed module (`this` printed the Zen of Python in the server log)
    port = urlparse(server["url"]).port
    for host in (f"localhost:{port}", f"127.0.0.1:{port}"):
        assert _get(server["url"], "/", host)[0] == 200, host
    for host in (f"evil.example:{port}", "attacker.test", f"127.0.0.1.nip.io:{port}"):
        assert _get(server["url"], "/", host)[0] == 403, host
    status, _ = _get(server["url"], "/components/this/Zen/_css/x.css", f"localhost:{port}")
    assert status == 403
    time.sleep(0.5)
    seen = []
    while not server["lines"].empty():
        seen.append(server["lines"].get_nowait())
    assert not any("Beautiful is better than ugly" in line for line in seen)
