"""The numbers and tables of docs/reproduction.md that the calibration wrote: read from the
committed exports of the studies (``paper/calibration-study1.jsonl``, the first study of issue
34, without the load check; ``paper/calibration.jsonl``, the study with it), the confirmation of
the first study's best candidate (``paper/confirmation-study1.json``, by ``paper/confirm.py``),
the confirmation of the load-checked study's best eligible candidates (``paper/confirmation.json``)
and the presets themselves. The peak mesh loads of the first study's best candidates, which it
did not measure, are computed here (:func:`gearchaos.paper.loads.load_factors`, about a second
a gear set). Used by ``docs/make_doc_numbers.py`` as its ``calibration`` source."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
STUDY1 = ROOT / "paper" / "calibration-study1.jsonl"
STUDY2 = ROOT / "paper" / "calibration.jsonl"
CONFIRMATION1 = ROOT / "paper" / "confirmation-study1.json"
CONFIRMATION = ROOT / "paper" / "confirmation.json"


class Markdown(str):
    """A value written between its markers as Markdown, on lines of its own."""


#: Search variable → (column head, scale to the shown unit, format).
SHORT = {
    "torque.input": ("T_D (N·m)", 1.0, "{:.0f}"),
    "transmission_error.amplitude": ("A (µm)", 1e6, "{:.2f}"),
    "stiffness.epsilon_sp": ("ε_sp", 1.0, "{:.3f}"),
    "clearance.characteristic_length": ("b_c (µm)", 1e6, "{:.2f}"),
}


def _teeth(v: dict[str, Any]) -> str:
    return f"{v['geometry.planets']}; {v['teeth.sun']}/{v['teeth.planet']}/{v['teeth.ring']}"


def _variables(v: dict[str, Any]) -> list[str]:
    cells = [_teeth(v)]
    cells += [fmt.format(v[k] * scale) for k, (_, scale, fmt) in SHORT.items()]
    cells.append(str(v["torque.mode"]).replace("constant_", "const. "))
    return cells


VARIABLE_HEAD = ["N; z_s/z_p/z_r", *(h for h, _, _ in SHORT.values()), "load"]


def _table(head: list[str], rows: list[list[str]]) -> Markdown:
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return Markdown("\n".join(lines))


def _rows(path: Path) -> list[dict[str, Any]]:
    return [json.loads(x) for x in path.read_text(encoding="utf-8").splitlines() if x.strip()]


def _load_cells(loads: dict[str, Any]) -> list[str]:
    return [
        f"{loads['max']:.3g} (Ω = {loads['omega']:g})",
        f"{loads['peak_force_N'] / 1e3:.3g}",
        "yes" if loads["plausible"] else "**no**",
    ]


LOAD_HEAD = ["peak load factor", "peak force (kN)", "teeth hold"]


def _loads_of(rec: dict[str, Any]) -> dict[str, Any]:
    from gearchaos.paper.loads import load_factors
    from gearchaos.paper.search_space import build_gearset, candidate_from_record

    parts = rec.get("parts") or {}
    if isinstance(parts.get("loads"), dict):
        return parts["loads"]
    return load_factors(build_gearset(candidate_from_record(rec)))


def _study_table(order: list[dict[str, Any]], n: int) -> Markdown:
    rows = []
    for rank, r in enumerate(order[:n], start=1):
        rows.append([str(rank), str(r["index"]), r["origin"], f"{r['score']:.2f}",
                     f"{r.get('structure', 0.0):.2f}", *_variables(r["variables"]),
                     *_load_cells(_loads_of(r))])  # fmt: skip
    head = ["rank", "trial", "origin", "landmarks", "structure", *VARIABLE_HEAD, *LOAD_HEAD]
    return _table(head, rows)


def _counts_cells(c: dict[str, Any]) -> list[str]:
    lm, cc = c["landmarks"], c["conclusions"]
    return [
        str(lm.get("holds", 0)),
        str(lm.get("holds (constant)", 0)),
        str(lm.get("partly", 0)),
        str(lm.get("does not hold", 0)),
        f"{cc.get('holds', 0)} / {cc.get('partly', 0)} / {cc.get('does not hold', 0)}",
    ]


COUNT_HEAD = ["holds", "holds (constant)", "partly", "not", "conclusions h/p/n"]


def _confirmation_table(conf: dict[str, Any]) -> Markdown:
    """The counts and loads of a ``paper/confirm.py`` summary: each confirmed candidate (the
    winner marked "adopted" where one was adopted from it), then the previous default."""
    rows = []
    for r in conf["confirmed"]:
        tag = f"trial {r['trial']}" + (" (adopted)" if r["trial"] == conf.get("winner") else "")
        rows.append([tag, *_counts_cells(r["counts"]), *_load_cells(r["loads"])])
    p = conf["previous"]
    rows.append([p["preset"], *_counts_cells(p["counts"]), *_load_cells(p["loads"])])
    return _table(["gear set", *COUNT_HEAD, *LOAD_HEAD], rows)


def calibration_values() -> dict[str, str]:
    """Keys ``study1.*`` (the first study: ``trials``, ``enqueued``, ``best.*``, ``top``,
    ``structured`` — trials whose clearances act —, ``broken`` — of those, how many break their
    teeth among the ``top``), ``confirm1`` (the confirmed candidate against the previous
    default), ``study2.*`` (the load-checked study: ``trials``, ``feasible``, ``best.*``,
    ``top``, ``eligible`` and ``eligible-top`` — plausible, with clearances that act),
    ``confirm2.*`` (its confirmation: the table, the winner and its counts against the previous
    default's), ``new.*`` and ``old.*`` (the calibrated values of ``sheng2016`` and
    ``sheng2016-v1``), ``abar.*`` and ``tdbar.*`` (Ā = A/b_c and T̄_D of the previous default,
    the first study's best and the new default)."""
    from gearchaos.gearset import preset
    from gearchaos.model.derived import gearset_info
    from gearchaos.paper.calibrate import adoption_problems, load_problems, ranked
    from gearchaos.paper.search_space import build_gearset, candidate_from_record

    out: dict[str, str] = {}
    s1 = ranked(_rows(STUDY1))
    out["study1.trials"] = str(len(s1))
    out["study1.enqueued"] = str(sum(1 for r in s1 if r["origin"] != "tpe"))
    out["study1.minutes"] = f"{sum(float(r['seconds']) for r in s1) / 60:.0f}"
    best = s1[0]
    out["study1.best.trial"] = str(best["index"])
    out["study1.best.score"] = f"{best['score']:.2f}"
    out["study1.best.structure"] = f"{best.get('structure', 0.0):.2f}"
    prev = next(r for r in s1 if r["origin"] == "default")
    out["study1.previous.score"] = f"{prev['score']:.2f}"
    out["study1.previous.structure"] = f"{prev.get('structure', 0.0):.2f}"
    out["study1.landmarks"] = str(len(best["landmarks"]))
    out["study1.structured"] = str(sum(1 for r in s1 if (r.get("structure") or 0.0) >= 0.9))
    top = s1[:6]
    out["study1.top"] = _study_table(s1, 6)
    out["study1.top-broken"] = str(sum(1 for r in top if not _loads_of(r)["plausible"]))
    out["study1.top-count"] = str(len(top))

    conf = json.loads(CONFIRMATION1.read_text(encoding="utf-8"))
    p = conf["previous"]
    out["confirm1"] = _confirmation_table(conf)
    c = conf["confirmed"][0]
    out["confirm1.trial"] = str(c["trial"])
    out["confirm1.holds"] = str(c["counts"]["landmarks"].get("holds", 0))
    out["confirm1.previous-holds"] = str(p["counts"]["landmarks"].get("holds", 0))
    out["confirm1.force"] = f"{c['loads']['peak_force_N'] / 1e3:.3g}"
    out["confirm1.allowable"] = f"{c['loads']['allowable_force_N'] / 1e3:.3g}"

    s2 = ranked(_rows(STUDY2))
    feasible = [r for r in s2 if not load_problems(r)]
    out["study2.trials"] = str(len(s2))
    out["study2.feasible"] = str(len(feasible))
    out["study2.acting"] = str(sum(1 for r in feasible if (r.get("structure") or 0.0) >= 0.9))
    out["study2.top"] = _study_table(s2, 6)
    if feasible:
        b2 = feasible[0]
        out["study2.best.trial"] = str(b2["index"])
        out["study2.best.score"] = f"{b2['score']:.2f}"
        out["study2.best.structure"] = f"{b2.get('structure', 0.0):.2f}"

    # eligible: plausible in ranges, teeth and loads, and with clearances that act
    eligible = [r for r in s2 if not adoption_problems(r)]
    out["study2.eligible"] = str(len(eligible))
    out["study2.enqueued"] = str(sum(1 for r in s2 if r["origin"] != "tpe"))
    out["study2.minutes"] = f"{sum(float(r['seconds']) for r in s2) / 60:.0f}"
    out["study2.eligible-top"] = _study_table(eligible, 6)

    conf2 = json.loads(CONFIRMATION.read_text(encoding="utf-8"))
    p2 = conf2["previous"]
    out["confirm2"] = _confirmation_table(conf2)
    out["confirm2.count"] = str(len(conf2["confirmed"]))
    win = next(r for r in conf2["confirmed"] if r["trial"] == conf2["winner"])
    wl, pl = win["counts"]["landmarks"], p2["counts"]["landmarks"]
    out["confirm2.winner"] = str(win["trial"])
    out["confirm2.holds"] = str(wl.get("holds", 0))
    out["confirm2.constant"] = str(wl.get("holds (constant)", 0))
    out["confirm2.partly"] = str(wl.get("partly", 0))
    out["confirm2.not"] = str(wl.get("does not hold", 0))
    out["confirm2.previous-holds"] = str(pl.get("holds", 0))
    out["confirm2.previous-constant"] = str(pl.get("holds (constant)", 0))
    out["confirm2.force"] = f"{win['loads']['peak_force_N'] / 1e3:.3g}"
    out["confirm2.minutes"] = f"{win['counts']['seconds'] / 60:.0f}"
    for tag, name in (("new", "sheng2016"), ("old", "sheng2016-v1")):
        g = preset(name)
        out[f"{tag}.torque"] = f"{g.torque.input:.0f}"
        out[f"{tag}.te"] = f"{g.transmission_error.sun_planet * 1e6:.3g}"
        out[f"{tag}.bc"] = f"{g.clearance.characteristic_length * 1e6:.3g}"
        out[f"{tag}.teeth"] = f"{g.teeth.sun}/{g.teeth.planet}/{g.teeth.ring}"
        out[f"{tag}.planets"] = str(g.n_planets)

    for tag, gs in (
        ("old", preset("sheng2016-v1")),
        ("study1", build_gearset(candidate_from_record(best))),
        ("new", preset("sheng2016")),
    ):
        dim = gearset_info(gs)["dimensionless"]
        out[f"abar.{tag}"] = f"{dim['te_sp']:.3g}"
        out[f"tdbar.{tag}"] = f"{dim['torque_input']:.3g}"
    return out
