"""Foot force difference control (:mod:`app.stabilizer.force_difference`): the sign and
the leak of the loop, and on G1 what it is for: a swing sole that touches the ground
before the planned step carries no weight until the step."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from app.backends.physics_log import COLUMNS, PhysicsLog
from app.runner import ClosedLoop
from app.scenarios import BUILT_IN
from app.setup.build import build_robot_backend
from app.stabilizer.force_difference import (
    LEAK_TIME,
    MAX_DIFFERENCE,
    FootLoads,
    ForceDifferenceControl,
)
from planner.parameters import GRAVITY

ADMITTANCE = 1e-3  # [m/(N s)]
DT = 0.01  # [s]
EARLY = 0.04  # [s] before a planned step, after the swing sole's first contact


def test_the_foot_carrying_more_than_its_share_is_raised_and_the_other_lowered():
    loop = ForceDifferenceControl(ADMITTANCE)
    desired = FootLoads(150.0, 150.0)
    heights = loop.update(FootLoads(250.0, 50.0), desired, True, DT)
    assert heights["left"] > 0.0 > heights["right"]
    assert heights["left"] == pytest.approx(-heights["right"])
    # 200 N of difference error for one tick, less the (zero) leak
    assert heights["left"] - heights["right"] == pytest.approx(ADMITTANCE * 200.0 * DT)
    mirrored = ForceDifferenceControl(ADMITTANCE).update(FootLoads(50.0, 250.0), desired, True, DT)
    assert mirrored["right"] == pytest.approx(heights["left"])


def test_loads_as_distributed_leave_the_heights_alone():
    loop = ForceDifferenceControl(ADMITTANCE)
    for _ in range(50):
        heights = loop.update(FootLoads(200.0, 100.0), FootLoads(200.0, 100.0), True, DT)
    assert heights == {"left": 0.0, "right": 0.0}


def test_in_single_support_the_offset_leaks_back_to_the_planned_heights():
    loop = ForceDifferenceControl(ADMITTANCE)
    for _ in range(10):
        loop.update(FootLoads(300.0, 0.0), FootLoads(0.0, 300.0), True, DT)
    start = loop.difference
    assert start > 0.0
    # The error is still there, but with one foot in the air the loop does not act on it.
    loop.update(FootLoads(300.0, 0.0), FootLoads(0.0, 300.0), False, DT)
    assert loop.difference == pytest.approx(start * (1.0 - DT / LEAK_TIME))
    for _ in range(round(5 * LEAK_TIME / DT)):
        loop.update(FootLoads(300.0, 0.0), FootLoads(0.0, 300.0), False, DT)
    assert abs(loop.difference) < start * math.exp(-4.0)


def test_the_offset_is_bounded():
    loop = ForceDifferenceControl(1.0)
    heights = loop.update(FootLoads(1e4, 0.0), FootLoads(0.0, 0.0), True, DT)
    assert heights["left"] == pytest.approx(0.5 * MAX_DIFFERENCE)


# ------------------------------------------------------------ on the full robot
@pytest.fixture(autouse=True)
def _cache_in_tmp(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("RSG_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def early_load(rate: float, duration: float = 2.6) -> tuple[float, float]:
    """G1's nominal walk with ``force_difference_rate`` = ``rate``: the largest mean
    share of the weight [-] a swing sole carries over the ``EARLY`` before its planned
    step (it touches the ground about 50 ms early), and the largest V_u after the first
    step [gamma_v]."""
    log = PhysicsLog()
    backend, config, initial = build_robot_backend(
        "g1", "rsg", (("force_difference_rate", str(rate)),), physics_log=log
    )
    try:
        scenario = dataclasses.replace(BUILT_IN["walk"], duration=duration)
        loop = ClosedLoop(backend, config, scenario, initial)
        landings = []  # (planned step time, the foot that lands)
        lyapunov = []
        for _ in range(round(duration / loop.period)):
            out = loop.tick()
            if out.step is not None:
                landings.append((out.time, out.stance.foot))
            if out.time > 1.0:
                lyapunov.append(out.lyapunov)
            assert not backend.fall_status().fell
        weight = backend.mass * GRAVITY
    finally:
        backend.close()
    rows = np.array(log.rows)
    column = {name: rows[:, i] for i, name in enumerate(COLUMNS)}
    share = 0.0
    for end, landing_foot in landings:
        window = (column["t"] > end - EARLY) & (column["t"] < end - 1e-9)
        share = max(share, float(column[f"{landing_foot}_fz"][window].mean()) / weight)
    assert len(landings) >= 2
    return share, max(lyapunov) / config.rsg.lyapunov_threshold


def test_an_early_touchdown_carries_no_weight_before_the_step():
    """Without the loop the swing sole, aiming 5 mm below the ground, carries about a
    quarter of the weight over the 40 ms before the step, the CoP leaves the planned
    one and V_u crosses gamma_v after each lift-off (1.7 gamma_v measured); with it the
    sole is raised off its early load and V_u stays below gamma_v (0.7 measured)."""
    with_loop = early_load(0.3)
    without = early_load(0.0)
    assert len({with_loop[0], without[0]}) == 2
    assert without[0] > 0.2, without
    assert with_loop[0] < 0.1, with_loop
    assert with_loop[1] < 1.0 < without[1], (with_loop, without)
