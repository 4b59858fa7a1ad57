"""Progress outside a terminal (a log file, a pipe, a batch job): readable plain lines, at most
one per 5 % of the points and per 10 s, and one at the end, never a truncated bar."""

from __future__ import annotations

import re

import pytest

import gearchaos as gc


def test_progress_outside_a_terminal_is_plain_lines(capsys: pytest.CaptureFixture[str]) -> None:
    system = gc.backlash_oscillator(1.0, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.5)
    gc.bifurcation(
        system,
        {"omega": "0.6:1.2:40"},
        observe=("x", "x_dot"),
        transient_periods=5,
        periods=4,
        progress=True,
    )
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.startswith("sweep")]
    assert lines, err
    pattern = re.compile(
        r"^sweep( \(.*\))?: (\d+) of 40 points \((\d+) %\) · [\d.]+ points/s · failed (\d+) · "
        r"elapsed \d\d:\d\d:\d\d · ETA (\d\d:\d\d:\d\d|–)$"
    )
    done = []
    for ln in lines:
        m = pattern.match(ln)
        assert m, f"not a plain progress line: {ln!r}"
        done.append(int(m.group(2)))
        assert int(m.group(3)) == round(100 * int(m.group(2)) / 40)
    assert done == sorted(done) and done[-1] == 40
    assert len(lines) <= 21  # at most one line per 5 % (and the last)
    assert "━" not in err  # no bar characters in a log


def test_a_short_sweep_in_a_log_writes_one_line(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    # issue 24: outside a terminal a 100-point sweep printed about 20 lines; lines are now
    # also at least EVERY seconds apart (set very long here: only the final line remains)
    from gearchaos.sweep.progress import _Bar

    monkeypatch.setattr(_Bar, "EVERY", 1e9)
    system = gc.backlash_oscillator(1.0, zeta=0.05, b=1.0, f_mean=0.1, f_alt=0.5)
    gc.bifurcation(system, {"omega": "0.6:1.2:100"}, transient_periods=2, periods=2)
    lines = [ln for ln in capsys.readouterr().err.splitlines() if ln.startswith("sweep")]
    assert len(lines) == 1 and " 100 of 100 points (100 %)" in lines[0]
