"""The scripts in ``examples/`` run as written and say what they promise."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def run_example(name: str, *args: str) -> str:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    done = subprocess.run(
        [sys.executable, str(ROOT / "examples" / name), *args],
        cwd=ROOT, env=env, capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout


def test_fig6_on_the_lipm_adjusts_a_step_and_ends_below_gamma_v():
    out = run_example("fig6_lipm.py")
    assert "adjusted step" in out
    final = float(out.split("final V_u = ")[1].split()[0])
    assert final < 1.0


@pytest.mark.slow
def test_pushing_g1_from_python_reports_a_recovery_with_an_adjusted_step():
    out = run_example("push_g1.py")
    assert "recovered: True" in out
    assert int(out.split(" adjusted:")[0].split(", ")[-1]) >= 1


@pytest.mark.slow
def test_the_small_sweep_stays_under_the_bound(tmp_path):
    out = run_example("small_sweep.py", str(tmp_path))
    rows = [line.split() for line in out.splitlines() if " deg: " in line]
    assert len(rows) == 8
    for row in rows:
        impulse, bound = float(row[3]), float(row[-3])
        assert 0.0 < impulse <= bound + 0.25
    assert (tmp_path / "jobs.jsonl").is_file()
