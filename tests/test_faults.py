"""Faults seen from outside the process: signals, killed sweeps, real exit codes.

- SIGKILL of ``rsg sweep``: its worker processes end within a few seconds
  (``app.experiments.jobs._die_with_parent``), and the same command run again resumes with the
  finished jobs kept.
- Ctrl-C (SIGINT) during ``rsg run``: what was simulated is written, marked
  interrupted, exit code 130.
- A few hostile inputs through the real ``python -m app``: exit code 2, one line on
  stderr, no traceback and no NumPy warning.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
SWEEP = ["sweep", "--model", "lipm", "--controllers", "no-step", "--directions", "3",
         "--phases", "0", "--cycle", "1", "--settle", "1", "--tolerance", "20", "--workers",
         "2", "--quiet"]  # fmt: skip


def _rsg(*args: str, **kwargs: object) -> subprocess.Popen:
    env = {**os.environ, "PYTHONUNBUFFERED": "1", "MPLBACKEND": "Agg"}
    return subprocess.Popen(
        [sys.executable, "-m", "app", *args],
        cwd=ROOT,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        **kwargs,  # type: ignore[arg-type]
    )


def _children(pid: int) -> list[int]:
    """Process ids whose parent is ``pid`` (from /proc)."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            fields = stat.rsplit(")", 1)[1].split()
            if int(fields[1]) == pid:
                found.append(int(entry.name))
    return found


def _running(pid: int) -> bool:
    """Whether ``pid`` exists and is not a zombie."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def _wait_for(condition, timeout: float, what: str) -> None:  # noqa: ANN001
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {timeout} s waiting for {what}")
        time.sleep(0.05)


def _records(path: Path) -> list[dict]:
    lines = path.read_text().splitlines() if path.exists() else []
    records = []
    for line in lines:
        try:
            records.append(json.loads(line))
        except json.JSONDecodeError:
            pass  # a line being written
    return records


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc (Linux)")
def test_a_killed_sweep_leaves_no_worker_and_resumes(tmp_path: Path) -> None:
    out = tmp_path / "sweep"
    jobs = out / "jobs.jsonl"
    sweep = _rsg(*SWEEP, "--out", str(out), start_new_session=True)
    workers: list[int] = []
    try:
        _wait_for(lambda: len(_records(jobs)) >= 1, 240, "a first finished job")
        workers = _children(sweep.pid)
        assert workers and all(_running(pid) for pid in workers), workers
        before = _records(jobs)
        assert len(before) < 3, "the sweep ended before it could be killed"
        sweep.kill()  # SIGKILL: nothing in the sweep can react
        sweep.wait(10)
        started = time.monotonic()
        _wait_for(lambda: not any(_running(pid) for pid in workers), 5, "the workers to end")
        print(f"workers {workers} ended {time.monotonic() - started:.2f} s after SIGKILL")
    finally:
        if sweep.poll() is None:
            sweep.kill()
        for pid in workers:  # only if the test failed: do not leave them running
            if _running(pid):
                os.kill(pid, signal.SIGKILL)
    kept = _records(jobs)
    again = _rsg(*SWEEP, "--out", str(out))
    stdout, stderr = again.communicate(timeout=300)
    assert again.returncode == 0, stderr
    assert "Traceback" not in stderr
    records = _records(jobs)
    keys = [r["key"] for r in records]
    assert len(keys) == len(set(keys)) == 3
    assert records[: len(kept)] == kept  # the finished jobs are kept, not run again
    assert "sweep: 3 jobs" in stdout


def test_ctrl_c_writes_what_was_simulated_and_marks_it_interrupted(tmp_path: Path) -> None:
    out = tmp_path / "run"
    run = _rsg("run", "--model", "lipm", "--scenario", "walk", "--duration", "300",
               "--push=250:5,0", "--set", "crossing_margin=0.05", "--no-plots",
               "--out", str(out))  # fmt: skip
    try:
        assert run.stdout is not None
        for _ in range(20):  # "with --set ..." is printed just before the loop starts
            line = run.stdout.readline()
            if line.startswith("with --set") or not line:
                break
        assert line.startswith("with --set"), line
        time.sleep(1.5)
        run.send_signal(signal.SIGINT)
        stdout, stderr = run.communicate(timeout=60)
    finally:
        if run.poll() is None:
            run.kill()
    assert run.returncode == 130, stderr
    assert "Traceback" not in stderr
    assert "INTERRUPTED at t=" in stdout
    summary = json.loads((out / "summary.json").read_text())
    assert summary["interrupted"] is True and summary["recovered"] is False
    assert 0.0 < summary["sim_time"] < 300.0
    rows = np.loadtxt(out / "timeseries.csv", delimiter=",", skiprows=1)
    assert len(rows) == round(summary["sim_time"] / 0.001)
    assert summary["pushes"] == []
    (left,) = summary["pushes_not_applied"]
    assert left["impulse_applied"] == [0.0, 0.0] and "interrupted" in left["reason"]


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["run", "--model", "lipm", "--push=1:1e308,1e308"], "--push impulse=[1e+308, 1e+308]"),
        (["run", "--model", "lipm", "--set", "lqr_zmp_scale=1e-300"], "--set lqr_zmp_scale"),
        (["run", "--model", "lipm", "--out", ""], "--out ''"),
        (["sweep", "--workers", "1000", "--directions", "1", "--phases", "0"], "--workers=1000"),
        (["grid", "--model", "lipm", "--impulses", "1e308"], "impulses=(1e+308,)"),
    ],
)
def test_hostile_input_through_the_real_command(
    args: list[str], fragment: str, tmp_path: Path
) -> None:
    if "--out" not in args:
        args = [*args, "--out", str(tmp_path / "out")]
    process = _rsg(*args)
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == 2, stderr
    lines = [line for line in stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and fragment in lines[0], stderr
    assert "Traceback" not in stderr and "Warning" not in stderr
    assert not (tmp_path / "out").exists()
