"""Progress outside a terminal (a log file, a pipe, a batch job): readable plain lines, one per
5 % of the points and one at the end, never a truncated bar."""

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
