"""The explorer's server: :func:`serve` runs the page of :mod:`.app` on this machine's
loopback only, until Ctrl-C or SIGTERM.

It answers only requests addressed to ``localhost``, ``127.0.0.1`` or ``[::1]`` (a page of
another site whose name resolves to 127.0.0.1 — DNS rebinding — gets 403), and Panel's
``/components/<module>/…`` route, which imports the module named in the URL, only for the
modules the page uses (``panel``, ``bokeh``).
"""

from __future__ import annotations

import os
import signal
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import panel as pn

from ..dynamics.curve_file import open_curve
from ..sweep.result import open_result
from .app import Explorer, Workers
from .model import ExploreModel

__all__ = ["COMPONENT_MODULES", "LOCAL_HOSTS", "serve"]


#: The host names a request may address (DNS rebinding: a page of another site whose name
#: resolves to 127.0.0.1 would otherwise reach the explorer from the user's own browser).
LOCAL_HOSTS = frozenset({"localhost", "127.0.0.1", "::1"})
#: The modules Panel's ``/components/<module>/…`` route may import (it imports the one named
#: in the URL): those of the page's own components.
COMPONENT_MODULES = ("panel", "bokeh")


def _host_name(host: str) -> str:
    """``localhost`` of ``localhost:5006``, ``::1`` of ``[::1]:5006``."""
    if host.startswith("["):
        return host[1 : host.find("]")] if "]" in host else host
    return host.rsplit(":", 1)[0] if host.count(":") == 1 else host


def _guard(server: Any) -> None:
    """Answer 403 to a request for another host name than this machine's loopback, and to
    the components route for a module the page does not use."""
    import tornado.web

    app = getattr(server, "_tornado", None)
    if app is None:  # pragma: no cover - Bokeh's server layout changed
        raise RuntimeError("cannot guard the explorer's server: Bokeh's layout changed")
    find = app.find_handler

    def guarded(request: Any, **kwargs: Any) -> Any:
        refused = _host_name(request.host or "").lower() not in LOCAL_HOSTS
        if request.path.startswith("/components/"):
            module = request.path.split("/")[2] if request.path.count("/") >= 2 else ""
            refused = refused or module.split(".")[0] not in COMPONENT_MODULES
        if refused:
            return app.get_handler_delegate(request, tornado.web.ErrorHandler, {"status_code": 403})
        return find(request, **kwargs)

    app.find_handler = guarded


def serve(
    store: str | os.PathLike[str],
    *,
    port: int = 0,
    show: bool = True,
    var: str | None = None,
    planet: int = 1,
    ready: Callable[[str], None] | None = None,
    boundaries: Sequence[str | os.PathLike[str]] = (),
) -> None:
    """Serve the explorer of ``store`` on ``localhost:port`` (0: a free port) until Ctrl-C or
    SIGTERM; ``ready(url)`` is called once it listens. Returns after a clean stop: the server
    closed and the worker processes ended."""
    open_result(store)  # a bad store fails here, before anything listens
    ExploreModel(open_result(store), var=var, planet=planet)
    for path in boundaries:  # a bad curve file fails here, before anything listens
        open_curve(path)
    workers = Workers()
    server = pn.serve(
        {
            "/": lambda: Explorer(
                store, var=var, planet=planet, workers=workers, boundaries=boundaries
            )
        },
        port=port,
        address="localhost",
        show=False,
        start=False,
        title=f"gearchaos explore · {Path(store).name}",
        verbose=False,
    )
    _guard(server)
    url = f"http://localhost:{server.port}/"
    loop = server.io_loop

    # Ctrl-C and SIGTERM stop the loop through asyncio's own signal handling (Tornado's
    # add_callback_from_signal is deprecated); the handlers before are put back after
    signals = (signal.SIGINT, signal.SIGTERM)
    old = {s: signal.getsignal(s) for s in signals}
    for s in signals:
        loop.asyncio_loop.add_signal_handler(s, loop.stop)
    try:
        server.start()
        if ready is not None:
            ready(url)
        if show:
            loop.add_callback(lambda: server.show("/"))
        loop.start()
    finally:
        for s, h in old.items():
            loop.asyncio_loop.remove_signal_handler(s)
            signal.signal(s, h)
        server.stop()
        workers.shutdown()
        sys.stdout.flush()
