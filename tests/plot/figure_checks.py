"""Checks on drawn figures that tests of several figures share: what covers what."""

from __future__ import annotations

from typing import Any

import numpy as np

from gearchaos.plot.placement import EVENT_LABEL_GID


def overlap(a: Any, b: Any, slack: float = 0.5) -> bool:
    """Whether two display boxes (``Bbox``) overlap by more than ``slack`` pixels."""
    return min(a.x1, b.x1) - max(a.x0, b.x0) > slack and min(a.y1, b.y1) - max(a.y0, b.y0) > slack


def legends(fig: Any) -> list[Any]:
    """The figure's legends and those of its axes."""
    found = list(fig.legends)
    for ax in fig.axes:
        if ax.get_legend() is not None:
            found.append(ax.get_legend())
    return found


def draw(fig: Any) -> None:
    """Draw ``fig`` as a saved PNG is drawn (the layout engine places everything then): on an
    Agg canvas, which a ``Figure`` made without pyplot lacks."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)
    fig.canvas.draw()


def assert_legends_clear_of_titles(fig: Any) -> None:
    """No legend of ``fig`` covers its title (``suptitle``) or an axes' title, once drawn."""
    draw(fig)
    titles = [fig._suptitle] if fig._suptitle is not None else []  # the figure's title
    for ax in fig.axes:
        titles += [t for t in (ax.title, ax._left_title, ax._right_title) if t.get_text()]
    assert titles and legends(fig)
    for legend in legends(fig):
        box = legend.get_window_extent()
        for title in titles:
            assert not overlap(box, title.get_window_extent()), (title.get_text(), box)


def curve_enters(box: Any, xy: np.ndarray) -> bool:
    """Whether the display polyline ``xy`` (n × 2; NaN breaks it) enters ``box``: matplotlib's
    own path–rectangle test, independent of the label placement it checks."""
    from matplotlib.path import Path

    xy = np.asarray(xy, dtype=float)
    finite = np.all(np.isfinite(xy), axis=1)
    cuts = np.flatnonzero(~finite)
    for run in np.split(xy, cuts):
        run = run[np.all(np.isfinite(run), axis=1)]
        if len(run) >= 2 and Path(run).intersects_bbox(box, filled=False):
            return True
    return False


def steep_branch(branch: Any, var: str, omega: tuple[float, float], low: float, high: float,
                 kind: str = "grazing") -> Any:  # fmt: skip
    """``branch`` (a continued branch of Ω) made a steep step: Ω spread over ``omega``,
    the section values and the amplitude (max − min) of ``var`` rising from ``low`` to
    ``high`` on a steep ramp in the middle, stable throughout, one event of ``kind`` halfway
    up the ramp — where a name written above its marker sits on the curve."""
    n = branch.sizes["point"]
    lam = np.linspace(*omega, n)
    centre = 0.5 * (omega[0] + omega[1])
    ramp = (lam - centre) / (0.04 * (omega[1] - omega[0])) + 0.5  # 4 % of the range wide
    y = low + (high - low) * np.clip(ramp, 0.0, 1.0)
    events = [v for v in branch.variables if "event" in branch[v].dims]
    out = branch.drop_vars(events).assign_coords(
        omega=("point", lam), arclength=("point", np.arange(n, dtype=float))
    )
    i = int(np.argmin(np.abs(lam - centre)))
    out[var] = (("point", "section"), np.repeat(y[:, None], branch.sizes["section"], axis=1))
    out[f"{var}_min"] = ("point", np.zeros(n))
    out[f"{var}_max"] = ("point", y)
    out["stable"] = ("point", np.ones(n, dtype=np.int8))
    for name, value in (("event_kind", kind), ("event_value", lam[i]), ("event_point", i),
                        ("event_arclength", float(i))):  # fmt: skip
        out[name] = ("event", np.array([value]))
    return out


#: The short names of events written beside their markers.


def labels_on_curves(fig: Any, prefix: str) -> list[str]:
    """The event names of ``fig`` (drawn) whose box a curve with a ``gid`` starting with
    ``prefix`` crosses, or that leave their axes."""
    draw(fig)
    found = []
    for ax in fig.axes:
        for text in ax.texts:
            if text.get_gid() != EVENT_LABEL_GID:  # an event's name, or a crowd's
                continue
            box = text.get_window_extent()
            crossed = any(
                curve_enters(box, ln.get_transform().transform(np.asarray(ln.get_xydata())))
                for ln in ax.lines
                if str(ln.get_gid()).startswith(prefix) and ln.get_linestyle() != "None"
            )
            frame = ax.get_window_extent()
            inside = frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0
            if crossed or not (inside and box.y1 <= frame.y1):
                found.append(text.get_text())
    return found
