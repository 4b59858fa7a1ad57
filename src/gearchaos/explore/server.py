"""The explorer's server: :func:`serve` runs the page of :mod:`.app` on this machine's
loopback only, until Ctrl-C or SIGTERM.

It answers only requests addressed to ``localhost`` or ``127.0.0.1`` (a page of another site
whose name resolves to 127.0.0.1 — DNS rebinding — gets 403, and so does a ``Host`` header
that is no host name with an optional port); one addressed to ``[::1]`` is redirected to
``localhost`` (Panel cannot read an IPv6 host, and Bokeh's websocket check refuses it). Panel's
``/components/<module>/<class>/…`` route, which imports the module named in the URL, answers
only for the classes of the page's own components (:class:`PageClasses`, collected from the
pages served), whose modules are imported already: a URL never imports anything.
"""

from __future__ import annotations

import os
import re
import signal
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import panel as pn

from ..dynamics.curves.file import open_curve
from ..sweep.result import open_result
from .app import Explorer, Workers
from .model import ExploreModel

__all__ = ["LOCAL_HOSTS", "PageClasses", "serve"]


#: The host names a request may address (DNS rebinding: a page of another site whose name
#: resolves to 127.0.0.1 would otherwise reach the explorer from the user's own browser);
#: ``[::1]`` is redirected to ``localhost``.
LOCAL_HOSTS = frozenset({"localhost", "127.0.0.1", "::1"})

#: A ``Host`` header: a name (no colon or bracket) or a bracketed IPv6 address, then an
#: optional port.
_HOST = re.compile(r"(?:(?P<name>[^:\[\]]*)|\[(?P<ipv6>[0-9A-Fa-f:.]*)\])(?::[0-9]{0,5})?")


def _host_name(host: str) -> str | None:
    """``localhost`` of ``localhost:5006``, ``::1`` of ``[::1]:5006``; ``None`` for a header
    that is no host with an optional port (``a:b:c``, ``[::1``)."""
    m = _HOST.fullmatch(host)
    if m is None:
        return None
    return (m.group("name") if m.group("ipv6") is None else m.group("ipv6")).lower()


class PageClasses:
    """The Panel classes of the pages a server shows, as ``(module, class name)``: what
    Panel's ``/components/<module>/<class>/…`` route may serve resources of. A page is held
    while its session lives and its components are looked up at each request, so a component
    it shows later (another store's widgets) counts too, and a closed page's no longer."""

    def __init__(self) -> None:
        self._pages: dict[int, Any] = {}

    def add(self, page: Any) -> Any:
        """Record a page (a Panel viewable) of the session being created; returns it."""
        key = id(page)
        self._pages[key] = page
        if pn.state.curdoc is not None and pn.state.curdoc.session_context is not None:
            pn.state.on_session_destroyed(lambda _context: self._pages.pop(key, None))
        return page

    def allows(self, module: str, name: str) -> bool:
        """Whether a component of a page served is of the class ``module.name`` (its module
        imported already: answering never imports)."""
        if module not in sys.modules:
            return False
        for page in list(self._pages.values()):
            for obj in page.select():
                cls = type(obj)
                if cls.__module__ == module and cls.__name__ == name:
                    return True
        return False


def _guard(server: Any, classes: PageClasses) -> None:
    """Answer 403 to a request for another host name than this machine's loopback or a
    ``Host`` header that is none, redirect one for ``[::1]`` to ``localhost``, and answer 403
    to the components route for a class that no page served uses."""
    import tornado.escape
    import tornado.web

    app = getattr(server, "_tornado", None)
    if app is None:  # pragma: no cover - Bokeh's server layout changed
        raise RuntimeError("cannot guard the explorer's server: Bokeh's layout changed")
    find = app.find_handler
    home = f"http://localhost:{server.port}/"

    class ToLocalhost(tornado.web.RequestHandler):
        """A redirect to the page at ``localhost`` (the path is not carried over: it is
        never echoed into a header)."""

        def prepare(self) -> None:
            self.redirect(home, status=307)

    def guarded(request: Any, **kwargs: Any) -> Any:
        host = _host_name(request.host or "")
        refused = host not in LOCAL_HOSTS
        if request.path.startswith("/components/"):
            # split as Panel does: the unquoted path, by "/"
            parts = tornado.escape.url_unescape(request.path, plus=False).split("/")
            refused = refused or len(parts) < 4 or not classes.allows(parts[2], parts[3])
        if refused:
            return app.get_handler_delegate(request, tornado.web.ErrorHandler, {"status_code": 403})
        if host == "::1":
            return app.get_handler_delegate(request, ToLocalhost)
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
    classes = PageClasses()
    server = pn.serve(
        {
            "/": lambda: classes.add(
                pn.panel(
                    Explorer(store, var=var, planet=planet, workers=workers, boundaries=boundaries)
                )
            )
        },
        port=port,
        address="localhost",
        show=False,
        start=False,
        title=f"gearchaos explore · {Path(store).name}",
        verbose=False,
    )
    _guard(server, classes)
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
