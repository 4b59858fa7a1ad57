"""benchmarks/bench_first_run.py (issue 35): its command line, the quick-start command it reads
from the README and its per-kernel accounting. No timing here: the benchmark itself is not a
test."""

from __future__ import annotations

import importlib
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


@pytest.fixture
def bench(monkeypatch: pytest.MonkeyPatch) -> ModuleType:
    monkeypatch.syspath_prepend(str(BENCHMARKS))  # it imports child.py from beside it
    return importlib.import_module("bench_first_run")


def test_help_names_every_option() -> None:
    proc = subprocess.run(
        [sys.executable, str(BENCHMARKS / "bench_first_run.py"), "--help"],
        capture_output=True, text=True, timeout=120, check=False,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    for option in ("--repeat", "--src", "--baseline", "--command", "--json", "--kernels"):
        assert option in proc.stdout


def test_arguments_defaults_and_refusals(
    bench: ModuleType, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = bench.parse_args([])
    assert (args.repeat, args.src, args.baseline, args.command) == (3, None, None, None)
    assert bench.parse_args(["-n", "2"]).repeat == 2
    with pytest.raises(SystemExit) as exc:
        bench.parse_args(["-n", "0"])
    assert exc.value.code == 2
    assert "-n/--repeat must be >= 1: got 0" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        bench.parse_args(["--src", str(tmp_path)])  # no gearchaos/__init__.py under it
    assert f"--src must be a directory holding gearchaos/__init__.py: got {tmp_path}" in (
        capsys.readouterr().err
    )


def test_quick_start_command_is_read_from_its_section(bench: ModuleType, tmp_path: Path) -> None:
    readme = tmp_path / "README.md"
    readme.write_text(
        "# x\n\n```bash\ngearchaos info\n```\n\n## Quick start\n\nText.\n\n"
        "```bash\n.venv/bin/gearchaos simulate --set omega=2 -o 'my out/'\n```\n\n"
        "## Next\n\n```bash\ngearchaos sweep\n```\n",
        encoding="utf-8",
    )
    assert bench.quickstart_args(readme) == ["simulate", "--set", "omega=2", "-o", "my out/"]
    readme.write_text("# x\n\n## Install\n\n```bash\ngearchaos info\n```\n", encoding="utf-8")
    with pytest.raises(ValueError, match="no '## Quick start' section"):
        bench.quickstart_args(readme)
    # the project's README: its quick start is a simulation
    assert bench.quickstart_args()[0] == "simulate"


def test_kernel_table_splits_nested_compiles(bench: ModuleType) -> None:
    """An outer kernel compiling 10 s of which 6 s are two nested compiles of another: the
    outer's self time is 4 s, its total 10 s; the nested one has no total (it is not
    outermost); medians over runs."""

    def rec(kernel: str, self_s: float, total_s: float, depth: int) -> dict[str, object]:
        return {"kernel": kernel, "self": self_s, "total": total_s, "depth": depth,
                "self_cpu": self_s / 2, "total_cpu": total_s / 2,
                "self_llvm_cpu": self_s / 4, "failed": False}  # fmt: skip

    run1 = {"compiles": [rec("b", 2.0, 2.0, 1), rec("b", 4.0, 4.0, 1), rec("a", 4.0, 10.0, 0)]}
    run2 = {"compiles": [rec("b", 3.0, 3.0, 1), rec("b", 3.0, 3.0, 1), rec("a", 2.0, 8.0, 0)]}
    run3 = {"compiles": [rec("b", 1.0, 1.0, 1), rec("b", 1.0, 1.0, 1), rec("a", 6.0, 8.0, 0)]}
    table = bench.kernel_table([run1, run2, run3])
    # b: self 6, 6, 2 -> median 6; a: self 4, 2, 6 -> 4, total 10, 8, 8 -> 8
    assert table == [("b", 2, 6.0, 3.0, 1.5, 0.0, 0.0), ("a", 1, 4.0, 2.0, 1.0, 8.0, 4.0)]
