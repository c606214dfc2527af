"""Landing (:mod:`app.stabilizer.landing`): the sink before the planned landing and the
settle of the new stance sole; and, on G1, what the settle is for: a lower peak ground
force at touchdown."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from app.backends.physics_log import COLUMNS, PhysicsLog
from app.runner import ClosedLoop
from app.scenarios import BUILT_IN
from app.setup.build import build_robot_backend
from app.stabilizer.landing import TOUCHDOWN_SPEED, WINDOW, Landing
from planner.parameters import GRAVITY

DEPTH = 0.005  # [m]
DOUBLE_SUPPORT = 0.1  # [s]


def landing() -> Landing:
    return Landing(DEPTH, DOUBLE_SUPPORT)


def test_the_swing_target_sinks_to_the_depth_by_the_landing_time_and_not_before():
    rule = landing()
    profile = 0.02
    landing_time = 0.3  # [s] after the swing began
    before = [rule.swing_height(profile, t, landing_time - t) for t in (0.3, 0.2, WINDOW + 1e-9)]
    assert before == [profile] * 3
    times = np.linspace(WINDOW, 0.0, 11)
    heights = np.array([rule.swing_height(profile, t, landing_time - t) for t in times])
    assert heights[0] == pytest.approx(profile)
    assert heights[-1] == pytest.approx(profile - DEPTH)
    assert np.all(np.diff(heights) < 0.0)  # going down all the way
    # A touchdown that comes late: the target goes on down at the touchdown speed.
    late = [rule.swing_height(profile, -t, landing_time + t) for t in (0.05, 0.1)]
    expected = [profile - DEPTH - t * TOUCHDOWN_SPEED for t in (0.05, 0.1)]
    assert late == pytest.approx(expected)


def test_a_late_touchdown_sinks_while_the_planner_waits_for_it():
    """While the planner waits for the touchdown it announces the held step at the current
    tick: the time left to the controller's next tick stays at minus one tick, and the
    target still goes on down at the touchdown speed from the planned landing time, until
    a new swing begins."""
    rule = landing()
    profile, tick, landing_time = 0.0, 0.01, 0.3
    rule.swing_height(profile, 0.0, landing_time)
    waiting = np.arange(1, 11) * tick
    heights = [rule.swing_height(profile, -tick, landing_time + t) for t in waiting]
    expected = profile - DEPTH - waiting * TOUCHDOWN_SPEED
    np.testing.assert_allclose(heights, expected)
    rule.start_swing()
    assert rule.swing_height(profile, 0.2, 0.1) == profile  # the next swing starts afresh


def test_the_new_stance_sole_settles_from_the_last_swing_height_to_the_ground():
    rule = landing()
    last = rule.swing_height(0.004, 0.05, 0.25)  # the swing's last target, 1.5 mm up
    assert last != 0.0
    times = np.linspace(0.0, DOUBLE_SUPPORT, 11)
    heights = np.array([rule.stance_height(t) for t in times])
    assert heights[0] == pytest.approx(last)
    assert heights[-1] == pytest.approx(0.0, abs=1e-15)
    np.testing.assert_allclose(np.diff(heights), -last / 10)  # linear
    assert rule.stance_height(2 * DOUBLE_SUPPORT) == 0.0


# ------------------------------------------------------------ on the full robot
def touchdown_peaks(settle: bool, duration: float = 1.7) -> tuple[list[float], bool]:
    """Largest total vertical ground force [-, of m g] per physics step around each
    planned landing (0.15 s before to 0.1 s after) of G1's nominal walk, up to a fall;
    and whether it fell."""
    backend, config, initial = build_robot_backend("g1", "rsg", reality="ideal")
    if not settle:  # the new stance sole's target jumps to the ground at the step
        backend.controller.landing.stance_height = lambda time_since_step: 0.0
    try:
        backend.physics_log = PhysicsLog()
        scenario = dataclasses.replace(BUILT_IN["walk"], duration=duration)
        loop = ClosedLoop(backend, config, scenario, initial)
        steps = []
        fell = False
        for _ in range(round(duration / loop.period)):
            out = loop.tick()
            if out.step is not None:
                steps.append(out.time)
            fell = backend.fall_status().fell
            if fell:
                break
        rows = np.array(backend.physics_log.rows)
        weight = backend.mass * GRAVITY
    finally:
        backend.close()
    column = {name: rows[:, i] for i, name in enumerate(COLUMNS)}
    total = (column["left_fz"] + column["right_fz"]) / weight
    peaks = []
    for time in steps:
        window = (column["t"] > time - 0.15) & (column["t"] < time + 0.1)
        peaks.append(float(total[window].max()))
    return peaks, fell


@pytest.fixture(autouse=True)
def _cache_in_tmp(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("RSG_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.mark.xfail(
    strict=True, reason="honest plant: touchdowns peak at 4.5-6.5 m g; 3 steps in 1.7 s"
)
def test_the_stance_settle_lowers_the_peak_touchdown_force():
    """G1's first landings of the nominal walk: with the new stance sole's target
    settling over the double support, against one that jumps to the ground at the step
    (which kicks the other foot off: about 3 m g, and G1 may fall)."""
    settled, fell = touchdown_peaks(True)
    jumped, _ = touchdown_peaks(False)
    assert not fell and len(settled) == 2
    assert settled[0] < 0.8 * jumped[0], f"{settled=} {jumped=}"
    assert max(settled) < 2.0, settled  # [m g]


@pytest.mark.xfail(strict=True, reason="honest plant: the sole carries nothing at 1.74 s")
def test_a_late_landing_steps_at_the_touchdown():
    """A forward push late in the swing (18 N s at 2.9 s) makes G1's swing foot land
    after the planned step time (3.1 s): the planner's jump waits for the touchdown,
    so at every step the new stance sole carries weight, and none is in the air."""
    from app.stabilizer.controller import CONTACT_LOAD
    from planner.types import Push

    backend, config, initial = build_robot_backend("g1", "rsg", reality="ideal")
    try:
        backend.physics_log = PhysicsLog()
        scenario = dataclasses.replace(
            BUILT_IN["walk"], duration=3.4, pushes=(Push(2.9, (18.0, 0.0), 0.1),)
        )
        loop = ClosedLoop(backend, config, scenario, initial)
        steps = []
        for _ in range(round(scenario.duration / loop.period)):
            out = loop.tick()
            if out.step is not None:
                steps.append((out.time, out.step.foot))
        rows = np.array(backend.physics_log.rows)
        weight = backend.mass * GRAVITY
    finally:
        backend.close()
    column = {name: rows[:, i] for i, name in enumerate(COLUMNS)}
    late = [time for time, _ in steps if time > 3.1 + 1e-9 and time < 3.3]
    assert late, steps  # the step after the push came after its planned time
    for time, foot in steps:
        last = np.flatnonzero(column["t"] <= time + 1e-9)[-1]  # what the tick measured
        assert column[f"{foot}_fz"][last] > CONTACT_LOAD * weight, (time, foot)


def touchdown_dcm_errors(compliance: float, seed: int, duration: float = 10.0) -> np.ndarray:
    """The largest DCM error [m] the planner sees in the 0.15 s after each step but the
    first of G1's nominal walk under the nominal reality drawn from ``seed``."""
    backend, config, initial = build_robot_backend(
        "g1", "rsg", (("landing_compliance", str(compliance)),), seed=seed
    )
    try:
        scenario = dataclasses.replace(BUILT_IN["walk"], duration=duration)
        loop = ClosedLoop(backend, config, scenario, initial)
        steps, errors = [], []
        for _ in range(round(duration / loop.period)):
            out = loop.tick()
            if out.step is not None:
                steps.append(out.time)
            errors.append((out.time, float(np.linalg.norm(out.dcm_error))))
        assert not backend.fall_status().fell
    finally:
        backend.close()
    times, norms = np.array(errors).T
    return np.array([norms[(times >= t) & (times < t + 0.15)].max() for t in steps[1:]])


@pytest.mark.slow
def test_a_compliant_landing_shakes_less_error_into_the_dcm():
    """The legs at landing_compliance of their gains around each touchdown take the
    impact instead of passing it to the body, whose shake the estimate's CoM velocity, and
    so the DCM error, carry (reality seed 6, used for no choice; measured on seed 5:
    median 10 mm against 17 mm with stiff legs)."""
    soft = touchdown_dcm_errors(0.3, seed=6)
    stiff = touchdown_dcm_errors(1.0, seed=6)
    assert len(soft) >= 10 and len(stiff) >= 10
    assert np.median(soft) < 0.75 * np.median(stiff), (soft, stiff)
