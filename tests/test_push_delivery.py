"""Every push listed in summary.json acts with its whole impulse, visibly in the results.

The loop applies, in each control tick, the push impulse of that tick divided by the
tick (:meth:`app.scenarios.Scenario.impulse_between`), so the recorded force
``push_fx, push_fy`` times the tick adds up to each listed impulse, however short the
push; the PyBullet backend applies the tick's force at each physics step, so
``physics.csv`` adds up to the same. A push a fall cuts short is listed apart, with the
impulse it did deliver.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from app.cli import main
from app.scenarios import Scenario, delivered_fraction
from planner.types import Push

pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")

#: (start [s], impulse [N s], duration [s]) on the LIPM's 1 ms tick: ordinary, shorter than
#: a tick (down to the smallest float), straddling a tick boundary, on a boundary, at a
#: time that is not a multiple of the tick in binary, and two overlapping.
PUSHES = [
    (0.3, (6.0, -4.0), 0.1),
    (0.6, (3.0, 2.0), 1e-20),
    (0.8, (-2.0, 5.0), 5e-324),
    (1.0008, (4.0, 4.0), 0.0004),
    (1.2, (-5.0, 1.0), 0.0005),
    (0.1 + 0.2 + 1.1, (2.5, -2.5), 0.0003),
    (1.6, (3.0, 0.0), 0.05),
    (1.62, (0.0, 3.0), 0.05),
]


def _read_csv(path: Path) -> dict[str, np.ndarray]:
    data = np.genfromtxt(path, delimiter=",", names=True)
    return {name: data[name] for name in data.dtype.names}


def _impulse_in(series: dict[str, np.ndarray], dt: float, start: float, end: float):
    """Impulse [N s] of the recorded push force over rows with start <= t < end."""
    rows = (series["t"] >= start - 1e-9) & (series["t"] < end - 1e-9)
    return np.array([series["push_fx"][rows].sum(), series["push_fy"][rows].sum()]) * dt


def test_each_listed_push_acts_with_its_whole_impulse_on_the_lipm(tmp_path: Path) -> None:
    argv = ["run", "--model", "lipm", "--scenario", "walk", "--duration", "2", "--no-plots",
            "--quiet", "--out", str(tmp_path)]  # fmt: skip
    argv += [f"--push={t!r}:{ix!r},{iy!r}:{d!r}" for t, (ix, iy), d in PUSHES]
    assert main(argv) in (0, 1)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["pushes_not_applied"] == []
    listed = sorted((p["t"], tuple(p["impulse"]), p["duration"]) for p in summary["pushes"])
    assert listed == sorted(PUSHES)
    series = _read_csv(tmp_path / "timeseries.csv")
    dt = 0.001
    total = _impulse_in(series, dt, 0.0, 2.0)
    expected = np.sum([impulse for _, impulse, _ in PUSHES], axis=0)
    np.testing.assert_allclose(total, expected, rtol=1e-5, atol=1e-9)
    # Each push on its own (the two overlapping ones together), in its own ticks.
    for t, impulse, duration in PUSHES[:-2]:
        start = np.floor(t / dt) * dt
        found = _impulse_in(series, dt, start, t + duration + dt)
        np.testing.assert_allclose(found, impulse, rtol=1e-5, err_msg=f"{t=} {duration=}")
    both = _impulse_in(series, dt, 1.6, 1.7)
    np.testing.assert_allclose(both, (3.0, 3.0), rtol=1e-5)
    # A push shorter than a tick is the tick's mean force, impulse / tick, in one tick.
    pushed = np.flatnonzero(np.isclose(series["push_fx"], -2.0 / dt, rtol=1e-5))
    assert series["t"][pushed] == pytest.approx([0.8])


def test_the_ticks_split_each_impulse_exactly() -> None:
    """Over consecutive ticks the delivered impulses add up to each push's, for pushes
    of any length and start, the float extremes included."""
    rng = np.random.default_rng(7)
    period = 0.001
    for _ in range(200):
        duration = float(10.0 ** rng.uniform(-320, 0.3))
        start = float(rng.uniform(0.0, 1.0))
        push = Push(start, np.array([1.0, -2.0]), duration)
        scenario = Scenario("s", 3.0, (push,))
        ticks = int(round(3.0 / period))
        total = sum(scenario.impulse_between(k * period, (k + 1) * period) for k in range(ticks))
        np.testing.assert_allclose(total, push.impulse, rtol=1e-12, err_msg=f"{push=}")
        assert delivered_fraction(push, ticks * period) == 1.0


def test_a_push_a_fall_cuts_short_is_listed_with_what_it_delivered(tmp_path: Path) -> None:
    """450 N s over 0.5 s knocks the point mass over before the push ends: it is not
    among the pushes that acted, and the impulse it did deliver is the time series'."""
    argv = ["run", "--model", "lipm", "--scenario", "walk", "--duration", "3", "--push",
            "0.5:450,0:0.5", "--no-plots", "--quiet", "--out", str(tmp_path)]  # fmt: skip
    assert main(argv) == 1
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["fell"] and summary["pushes"] == []
    (cut,) = summary["pushes_not_applied"]
    assert 0.0 < cut["impulse_applied"][0] < 450.0
    assert "ended at t=" in cut["reason"]
    series = _read_csv(tmp_path / "timeseries.csv")
    recorded = _impulse_in(series, 0.001, 0.0, 3.0)
    np.testing.assert_allclose(recorded, cut["impulse_applied"], rtol=1e-5)


def test_pybullet_applies_each_ticks_force_at_every_physics_step(tmp_path: Path) -> None:
    """G1 (10 ms tick, 1 ms physics): a push shorter than a physics step, one shorter
    than a tick and one over several ticks act with their whole impulse in the time
    series and in physics.csv (drawn in physics.png)."""
    pushes = [(0.2, (1.5, 0.0), 1e-6), (0.31, (0.0, 1.0), 0.004), (0.4, (-1.0, 1.0), 0.05)]
    argv = ["run", "--scenario", "walk", "--duration", "0.5", "--physics-log",
            "--quiet", "--out", str(tmp_path)]  # fmt: skip
    argv += [f"--push={t}:{ix},{iy}:{d}" for t, (ix, iy), d in pushes]
    assert main(argv) in (0, 1)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert len(summary["pushes"]) == 3 and summary["pushes_not_applied"] == []
    expected = np.sum([impulse for _, impulse, _ in pushes], axis=0)
    ticks = _read_csv(tmp_path / "timeseries.csv")
    np.testing.assert_allclose(_impulse_in(ticks, 0.01, 0.0, 0.5), expected, rtol=1e-5)
    physics = _read_csv(tmp_path / "physics.csv")
    np.testing.assert_allclose(_impulse_in(physics, 0.001, 0.0, 0.6), expected, rtol=1e-5)
    assert (tmp_path / "physics.png").read_bytes()[:4] == b"\x89PNG"
