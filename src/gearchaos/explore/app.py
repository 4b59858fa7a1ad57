"""The explorer's web page (Panel on Bokeh); its server is :mod:`.server`.

One :class:`Explorer` per browser session (or notebook cell) shows a sweep store: the
bifurcation diagram (every stored section value X̄_k against the swept value) with its band of
motion labels, or the regime map of a 2-D sweep. A click on the diagram, the band or the map,
or the slider along the swept axis, selects the nearest swept point and shows at once its
stored Poincaré section, motion label and λ₁; the phase portrait, time histories with the
contact force, spectrum, the recomputed λ₁ and the Floquet multipliers of an nT orbit follow
from a worker process (:mod:`gearchaos.explore.compute`), cached per point, while a spinner
turns. A box zoom followed by *Finer sweep* runs a resumable sweep of the shown range into a
sibling store, which the page then shows. Nothing that computes runs on the server's thread.
"""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing
import os
import threading
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import panel as pn
from bokeh import events
from bokeh.models import ColumnDataSource, HoverTool, Range1d
from bokeh.models.annotations import Span
from bokeh.plotting import figure

from ..analysis.summary import format_exponent
from ..dynamics.curves.file import open_curve
from ..errors import ParameterError
from ..model.loading import named_models
from ..plot.regimes import REGIME_COLOURS
from ..plot.stability import boundary_label
from ..sweep.execute import watch_parent
from ..sweep.result import open_result
from .compute import compute_point, run_zoom
from .model import ExploreModel, Point, parameter_axis_label, parameter_label

__all__ = ["Explorer", "Workers", "explore"]

#: Milliseconds between two looks at the background jobs.
POLL_MS = 250


class Workers:
    """The worker processes of an explorer: one for points, one for finer sweeps (so that a
    long sweep never delays a click), and the cache of computed points, shared by every
    session of a server. Processes start on first use (``spawn``: no forked server state) and
    end with the server, even when it is killed (:func:`~gearchaos.sweep.execute.watch_parent`)."""

    def __init__(self) -> None:
        self._pools: dict[str, cf.ProcessPoolExecutor] = {}
        self._lock = threading.Lock()
        self.cache: dict[tuple[Any, ...], Any] = {}
        self.running: dict[tuple[Any, ...], cf.Future[Any]] = {}

    def submit(self, pool: str, key: tuple[Any, ...], fn: Callable[..., Any], *args: Any) -> Any:
        """The cached result of ``key``, or the future computing it (started once)."""
        with self._lock:
            if key in self.cache:
                return self.cache[key]
            fut = self.running.get(key)
            if fut is None:
                if pool not in self._pools:
                    # the worker starts now, from this thread: the kernel's death signal may
                    # follow it only when it is the main thread (a server's loop)
                    main = threading.current_thread() is threading.main_thread()
                    self._pools[pool] = cf.ProcessPoolExecutor(
                        max_workers=1,
                        mp_context=multiprocessing.get_context("spawn"),
                        initializer=watch_parent,
                        initargs=(os.getpid(), main),
                    )
                fut = self._pools[pool].submit(fn, *args)
                self.running[key] = fut
            return fut

    def collect(self, key: tuple[Any, ...]) -> Any:
        """A finished job's result (cached) or its exception; ``None`` while it runs."""
        with self._lock:
            if key in self.cache:
                return self.cache[key]
            fut = self.running.get(key)
            if fut is None or not fut.done():
                return None
            del self.running[key]
            try:
                out = fut.result()
            except Exception as exc:  # shown on the page, never raised into the server
                return exc
            self.cache[key] = out
            return out

    def shutdown(self) -> None:
        """Stop the worker processes: idle ones end normally, busy ones are terminated at
        once (a running sweep keeps its finished chunks and resumes when asked again)."""
        with self._lock:
            pools, self._pools = self._pools, {}
            running, self.running = list(self.running.values()), {}
        for fut in running:
            fut.cancel()
        busy = any(not fut.done() for fut in running)
        for pool in pools.values():
            if busy:
                for proc in list(getattr(pool, "_processes", {}).values()):
                    if proc.is_alive():
                        proc.terminate()
            pool.shutdown(wait=True, cancel_futures=True)


class Explorer(pn.viewable.Viewer):
    """The explorer of one sweep store (a Panel viewable: display it in a notebook or serve
    it). Build it with :func:`explore`."""

    def __init__(
        self,
        store: str | os.PathLike[str],
        *,
        var: str | None = None,
        planet: int = 1,
        workers: Workers | None = None,
        boundaries: Sequence[str | os.PathLike[str]] = (),
        **params: Any,
    ):
        super().__init__(**params)
        self.root = str(store)
        self.boundaries = [open_curve(b) for b in boundaries]
        self.planet = planet
        self.workers = workers if workers is not None else Workers()
        self.model = ExploreModel(open_result(store), var=var, planet=planet, store=self.root)
        if self.boundaries and not self.model.is_map:
            raise ParameterError(
                "boundary curves are drawn over the regime map of a 2-D sweep: "
                f"{Path(self.root).name} sweeps one parameter"
            )
        self.var = self.model.var
        self.point: Point | None = None
        self.x_range: Any = None
        self.y_range: Any = None
        self._zoom_key: tuple[Any, ...] | None = None
        self._syncing = False
        self.store_select = pn.widgets.Select(
            label="store", options=[self.root], value=self.root, width=420
        )
        self.store_select.param.watch(lambda e: self._open(e.new), "value")
        self.info = pn.pane.Markdown("", sizing_mode="stretch_width")
        self.computed = pn.pane.Markdown("", sizing_mode="stretch_width")
        self.figure_png = pn.pane.PNG(None, width=880)
        self.spinner = pn.indicators.LoadingSpinner(value=False, size=28)
        self.busy = pn.pane.Markdown("", margin=(0, 10))
        self.zoom_note = pn.pane.Markdown("")
        self.zoom_points = pn.widgets.IntInput(label="points", value=100, start=2, width=100)
        self.zoom_button = pn.widgets.Button(
            label="Finer sweep of the shown range", color="primary"
        )
        self.zoom_button.on_click(lambda _e: self._zoom())
        self.body = pn.Column(sizing_mode="stretch_width")
        self._show()
        self._poller = pn.state.add_periodic_callback(self._poll, period=POLL_MS, start=True)

    def __panel__(self) -> Any:
        header = pn.pane.Markdown(f"## gearchaos explore · {Path(self.root).name}", margin=(0, 10))
        zoom = pn.Row(self.zoom_points, self.zoom_button, self.zoom_note)
        return pn.Column(header, self.store_select, self.body, zoom, sizing_mode="stretch_width")

    # ------------------------------------------------------------------ building the page
    def _open(self, path: str, select: Mapping[str, Any] | None = None) -> None:
        self.model = ExploreModel(
            open_result(path), var=self.var, planet=self.planet, select=select, store=path
        )
        self.point = None
        self._show()

    def _show(self) -> None:
        m = self.model
        self.zoom_points.value = int(m.axis(m.vary[0]).size)
        self.main = self._map_figure() if m.is_map else self._diagram_figures()
        self.poincare_src = ColumnDataSource({"x": [], "y": []}, name="poincare-source")
        self.poincare = figure(
            name="poincare-figure",
            width=440,
            height=400,
            title="click the diagram to see a point",
            tools="pan,wheel_zoom,box_zoom,reset,save",
            x_range=Range1d(start=0.0, end=1.0),
            y_range=Range1d(start=0.0, end=1.0),
        )
        self.poincare.scatter("x", "y", source=self.poincare_src, size=6, color="#d62728")
        self.sliders = [self._slider(i, name) for i, name in enumerate(m.vary)]
        selects = []
        if m.family:
            fam = pn.widgets.Select(
                label=parameter_label(m.family),
                options=m.family_values(),
                value=float(m.selection[m.family]),
            )
            family = m.family
            fam.param.watch(lambda e: self._reselect(family, e.new), "value")
            selects.append(fam)
        if m.directions:
            dirs = pn.widgets.Select(
                label="branch", options=list(m.directions), value=m.selection["direction"]
            )
            dirs.param.watch(lambda e: self._reselect("direction", e.new), "value")
            selects.append(dirs)
        fractions = ", ".join(f"{k} {100 * v:.3g} %" for k, v in m.regime_fractions().items())
        summary = pn.pane.Markdown(
            f"**{' × '.join(f'{parameter_label(n)}: {m.axis(n).size} points' for n in m.vary)}**"
            f" · motions: {fractions}",
            sizing_mode="stretch_width",
        )
        self.body[:] = [
            summary,
            pn.Row(*selects, *self.sliders),
            pn.Row(
                pn.pane.Bokeh(self.main),
                pn.Column(pn.pane.Bokeh(self.poincare), self.info),
            ),
            pn.Row(self.spinner, self.busy),
            self.computed,
            self.figure_png,
        ]

    def _slider(self, axis: int, name: str) -> Any:
        values = self.model.axis(name)
        options = {f"{v:.6g}": i for i, v in enumerate(values)}
        if len(options) < values.size:  # values equal at 6 digits: label by index too
            options = {f"{v:.6g} (#{i})": i for i, v in enumerate(values)}
        slider = pn.widgets.DiscreteSlider(
            label=parameter_label(name), options=options, value=0, width=420
        )

        def moved(event: Any) -> None:
            if self._syncing:
                return
            if self.point is not None:
                index = list(self._vary_index(self.point))
            else:
                index = [0] * len(self.model.vary)
            index[axis] = int(event.new)
            self.select(self.model.point(*index))

        slider.param.watch(moved, "value")
        return slider

    def _reselect(self, dim: str, value: Any) -> None:
        select = dict(self.model.selection)
        select[dim] = value
        self._open(self.model.store or self.root, select)

    def _diagram_figures(self) -> Any:
        m = self.model
        name = m.vary[0]
        xs = m.axis(name)
        pad = 0.02 * (xs.max() - xs.min()) if xs.size > 1 else 0.5
        x_range = Range1d(start=float(xs.min() - pad), end=float(xs.max() + pad))
        data = m.diagram()
        fig = figure(
            name="diagram-figure",
            height=420,
            width=760,
            x_range=x_range,
            title="bifurcation diagram: stored section values (click a point)",
            tools="pan,box_zoom,wheel_zoom,reset,save",
            x_axis_label=parameter_axis_label(name),
            y_axis_label=m.var_label(),
        )
        src = ColumnDataSource(
            {"x": data["x"], "y": data["y"], "i": data["i"]}, name="diagram-source"
        )
        fig.scatter("x", "y", source=src, size=2, color="black", alpha=0.5)
        self.marker = Span(location=None, dimension="height", line_color="#d62728", line_width=2)
        fig.add_layout(self.marker)
        fig.on_event(events.Tap, self._tapped)
        fig.on_event(events.DoubleTap, self._tapped)
        fig.xaxis.axis_label_text_font_size = "13px"
        fig.yaxis.axis_label_text_font_size = "13px"
        band = figure(
            name="band-figure",
            height=110,
            width=760,
            x_range=x_range,
            y_range=Range1d(start=0.0, end=1.0),
            tools="",
            toolbar_location=None,
            title="motion (stored labels)",
            x_axis_label=parameter_axis_label(name),
        )
        band.yaxis.visible = False
        b = m.band()
        bsrc = ColumnDataSource({**b, "y": [0.5] * len(b["x"])}, name="band-source")
        cells = band.rect("x", "y", "width", 1, source=bsrc, fill_color="colour", line_color=None)
        band.add_tools(
            HoverTool(renderers=[cells], tooltips=[(name, "@x{0.0000}"), ("motion", "@label")])
        )
        band.on_event(events.Tap, self._tapped)
        band.on_event(events.DoubleTap, self._tapped)
        self._legend(fig, b["label"])
        self.x_range = x_range
        return _stack(fig, band)

    def _map_figure(self) -> Any:
        m = self.model
        b = m.band()
        fig = figure(
            name="map-figure",
            height=480,
            width=760,
            title="regime map: stored motion labels (click a cell)",
            tools="pan,box_zoom,wheel_zoom,reset,save",
            x_axis_label=parameter_axis_label(m.vary[0]),
            y_axis_label=parameter_axis_label(m.vary[1]),
        )
        src = ColumnDataSource(b, name="map-source")
        cells = fig.rect(
            "x", "y", "width", "height", source=src, fill_color="colour", line_color=None
        )
        fig.add_tools(
            HoverTool(
                renderers=[cells],
                tooltips=[("motion", "@label"), ("", "(@x{0.0000}, @y{0.0000})")],
            )
        )
        self.marker_src = ColumnDataSource({"x": [], "y": []})
        fig.scatter(
            "x", "y", source=self.marker_src, size=14, marker="x", color="black", line_width=3
        )
        fig.on_event(events.Tap, self._tapped)
        fig.on_event(events.DoubleTap, self._tapped)
        self._legend(fig, b["label"])
        self._boundaries(fig, m.vary[0], m.vary[1])
        self.x_range = fig.x_range
        self.y_range = fig.y_range
        return fig

    def _boundaries(self, fig: Any, xname: str, yname: str) -> None:
        """The boundary curves given (:func:`gearchaos.boundary_curve`) over the map, in the
        map's axes, each named by its kind in the legend."""
        for k, cv in enumerate(self.boundaries):
            names = (str(cv.attrs["parameter"]), str(cv.attrs["parameter2"]))
            if set(names) != {xname, yname}:
                raise ParameterError(
                    f"boundary curve {k + 1} varies {names[0]} and {names[1]}, the map "
                    f"{xname} and {yname}: give curves of the map's two parameters"
                )
            colour = BOUNDARY_COLOURS[k % len(BOUNDARY_COLOURS)]
            fig.line(
                np.asarray(cv[xname].values, dtype=float),
                np.asarray(cv[yname].values, dtype=float),
                line_width=3,
                color=colour,
                legend_label=boundary_label(cv),
                name=f"boundary-{k}",
            )

    @staticmethod
    def _legend(fig: Any, labels: list[str]) -> None:
        present = [c for c in REGIME_COLOURS if c in set(labels)]
        for c in present:
            fig.scatter(
                [np.nan],
                [np.nan],
                marker="square",
                size=10,
                color=REGIME_COLOURS[c],
                legend_label=c,
            )
        fig.legend.orientation = "horizontal"
        fig.legend.location = "top_left"
        fig.legend.click_policy = "none"
        fig.legend.label_text_font_size = "11px"
        fig.add_layout(fig.legend[0], "above")

    # ------------------------------------------------------------------ selecting a point
    def _tapped(self, event: Any) -> None:
        """A click selects the nearest point. Bokeh reports a click that follows another
        within its double-tap interval as a DoubleTap, not a Tap, so both select: a quick
        second click on another point must not be dropped."""
        try:
            y = event.y if self.model.is_map else None
            self.select(self.model.nearest(event.x, y))
        except ParameterError:
            return

    def _vary_index(self, point: Point) -> tuple[int, ...]:
        lead = self.model.full.lead_dims
        return tuple(point.index[lead.index(n)] for n in self.model.vary)

    def select(self, point: Point) -> None:
        """Show ``point``: its stored section, label and λ₁ now, its computed views when the
        worker has them."""
        m = self.model
        self.point = point
        x, y, xl, yl = m.section(point)
        self.poincare_src.data = {"x": x, "y": y}
        ranges: tuple[Any, Any] = (self.poincare.x_range, self.poincare.y_range)
        for rng, v in zip(ranges, (x, y), strict=True):
            rng.start, rng.end = readable_range(v)
        label = m.label(point)
        title: Any = self.poincare.title
        title.text = f"{point.title()} · {label} · {x.size} stored section points"
        self.poincare.xaxis.axis_label = xl
        self.poincare.yaxis.axis_label = yl
        lle = m.lle(point)
        evidence = m.evidence(point)
        self.info.object = (
            f"**{point.title()}**  \nmotion (stored): **{label}**"
            f"{f' ({evidence})' if evidence else ''}  \n"
            f"λ₁ (stored): {format_exponent(lle, m.lle_error(point))} per unit τ  \n"
            f"status: {m.status(point)} · {x.size} section points"
        )
        vidx = self._vary_index(point)
        if m.is_map:
            self.marker_src.data = {"x": [point.values[m.vary[0]]], "y": [point.values[m.vary[1]]]}
        else:
            self.marker.location = point.values[m.vary[0]]
        for slider, i in zip(self.sliders, vidx, strict=True):
            if slider.value != i:
                self._syncing = True
                try:
                    slider.value = i
                finally:
                    self._syncing = False
        self._request(point)

    def _point_key(self, point: Point) -> tuple[Any, ...]:
        values = tuple(sorted(point.values.items()))
        return ("point", self.model.store, values, point.direction, self.var, self.planet)

    def _request(self, point: Point) -> None:
        try:  # what the store was computed on: a gear set or a model it can build again
            target = self.model.full.base_target
        except ParameterError as exc:  # a model of the user's own that was not named
            self.computed.object = f"*(cannot recompute this point: {exc})*"
            return
        if target is None:
            self.computed.object = (
                "*(this store records no model to build again: nothing to recompute)*"
            )
            return
        values = {k: v for k, v in point.values.items()}
        key = self._point_key(point)
        self.workers.submit(
            "point", key, compute_point, self.model.store, values, self.var, self.planet, 10.0,
            named_models(),
        )  # fmt: skip
        self._poll()

    def _poll(self) -> None:
        """Show finished background jobs (runs every :data:`POLL_MS` on the server)."""
        busy = []
        if self.point is not None:
            out = self.workers.collect(self._point_key(self.point))
            if out is None:
                if self._point_key(self.point) in self.workers.running:
                    busy.append(f"computing {self.point.title()} …")
            elif isinstance(out, Exception):
                self.computed.object = f"**could not compute this point:** {out}"
                self.figure_png.object = None
            elif self.computed.object != (text := _computed_text(out)):
                self.computed.object = text
                self.figure_png.object = out["png"] or None
        if self._zoom_key is not None:
            out = self.workers.collect(self._zoom_key)
            if out is None:
                busy.append("finer sweep running (resumable) …")
            else:
                self._zoom_key = None
                if isinstance(out, Exception):
                    self.zoom_note.object = f"**finer sweep failed:** {out}"
                else:
                    self.zoom_note.object = f"finer sweep written to `{out}`"
                    self.store_select.options = [*self.store_select.options, out]
                    self.store_select.value = out
        self.spinner.value = bool(busy)
        self.busy.object = " · ".join(busy)

    # ------------------------------------------------------------------ finer sweeps
    def _zoom(self) -> None:
        m = self.model
        if self._zoom_key is not None:
            return
        ranges: list[Any] = [self.x_range] + ([self.y_range] if m.is_map else [])
        axes: dict[str, tuple[float, float, int]] = {}
        for name, r in zip(m.vary, ranges, strict=True):
            v = m.axis(name)
            lo = max(float(r.start), float(v.min())) if r.start is not None else float(v.min())
            hi = min(float(r.end), float(v.max())) if r.end is not None else float(v.max())
            if not hi > lo:
                self.zoom_note.object = f"the shown range of {name} holds no swept values"
                return
            axes[name] = (lo, hi, int(self.zoom_points.value or 2))
        self._zoom_key = ("zoom", m.store, tuple(sorted(axes.items())))
        self.zoom_note.object = ", ".join(
            f"{k} {lo:.6g} … {hi:.6g}" for k, (lo, hi, _) in axes.items()
        )
        self.workers.submit("zoom", self._zoom_key, run_zoom, m.store, axes, named_models())


def readable_range(v: np.ndarray, rel: float = 1e-3) -> tuple[float, float]:
    """Axis limits around values ``v``: their span padded by 5 %, and at least ``rel`` of their
    magnitude wide, so that a section of nearly equal points (a 1T orbit) reads as one point
    with short tick labels rather than as a cloud at the ninth digit."""
    v = np.asarray(v, dtype=np.float64)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return 0.0, 1.0
    lo, hi = float(v.min()), float(v.max())
    mid, half = 0.5 * (lo + hi), 0.55 * (hi - lo)
    half = max(half, 0.5 * rel * max(abs(mid), 1.0))
    return mid - half, mid + half


def _stack(*figs: Any) -> Any:
    from bokeh.layouts import column

    return column(*figs)


def _computed_text(out: Mapping[str, Any]) -> str:
    from ..dynamics.verdict.evidence import evidence_words

    summary = out.get("summary") or {}
    lle = format_exponent(out.get("lle"), summary.get("lle_error"))
    lines = [
        f"**computed at {', '.join(f'{k} = {v:.6g}' for k, v in out['values'].items())}**: "
        f"motion **{out['motion']}** "
        f"(decided by {evidence_words(summary.get('evidence', 'record'))}), "
        f"λ₁ = {lle} per unit τ, "
        f"{out['distinct']} distinct section points, status {out['status']} "
        "(simulated from rest with the store's protocol)"
    ]
    mu = out.get("multipliers")
    if mu:
        shown = ", ".join(f"{abs(complex(r, i)):.4f}" for r, i in mu[:4])
        lines.append(f"{out['orbit_note']}: Floquet multipliers |μ| = {shown}, …")
    elif out.get("orbit_note"):
        lines.append(out["orbit_note"])
    return "  \n".join(lines)


#: Line colours of boundary curves over a regime map (none of the regime colours).
BOUNDARY_COLOURS = ("black", "#7f00ff", "#8b4513", "#ff1493")


def explore(
    store: str | os.PathLike[str],
    *,
    var: str | None = None,
    planet: int = 1,
    boundaries: Sequence[str | os.PathLike[str]] = (),
) -> Explorer:
    """The explorer of a sweep store, as a Panel app (display it in a notebook, or serve it).

    Shows the bifurcation diagram — every stored section value X̄_k of ``var`` (default
    X̄_sp1 = δ_sp1/b_c) against the swept parameter, with the band of motion labels — or the
    regime map of a 2-D sweep. Clicking (or moving the slider) selects the nearest swept
    point: its stored Poincaré section (X̄_k, X̄′_k), label and λ₁ at once; the phase portrait,
    time histories of X̄ and of the mesh's contact force, the spectrum with the mesh harmonics
    h f_m labelled, the recomputed motion and λ₁ and, for an nT orbit, its Floquet
    multipliers μ, computed in a worker process and cached per point.

    Parameters
    ----------
    store
        Path of a sweep store (:func:`gearchaos.bifurcation`, ``gearchaos bifurcation``).
    var, planet
        The section variable drawn (default: the store's first observed one) and its planet.
    boundaries
        Boundary-curve files (:func:`gearchaos.boundary_curve`, ``gearchaos boundary``) of the
        map's two parameters, drawn over the regime map of a 2-D sweep.

    Returns
    -------
    Explorer
        A Panel viewable.

    Raises
    ------
    ParameterError, StoreError
        For a missing, damaged or foreign store, as ``gearchaos plot``.
    """
    return Explorer(store, var=var, planet=planet, boundaries=boundaries)
