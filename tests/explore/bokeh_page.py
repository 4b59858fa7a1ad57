"""JavaScript that browser tests and the docs' screenshot script evaluate in an explorer page."""

from __future__ import annotations

#: The page position of data coordinates (x, y) of a named Bokeh figure (null until laid out).
PIXEL_OF = """([name, x, y]) => {
  const model = Bokeh.documents[0].get_model_by_name(name);
  function find(v) {
    if (v.model === model) return v;
    for (const c of (v.child_views ?? [])) { const r = find(c); if (r) return r; }
    return null;
  }
  let view = null;
  for (const root of Object.values(Bokeh.index)) { view = find(root); if (view) break; }
  if (view === null) return null;
  const box = view.canvas_view.el.getBoundingClientRect();
  return [box.left + view.frame.x_scale.compute(x), box.top + view.frame.y_scale.compute(y)];
}"""
