"""The live simulation thread of the browser demo, on the fast LIPM backend (and where
the G1 page draws its CoM)."""

from __future__ import annotations

import re
import time

import pytest

from conftest import free_port, output_lines
from web.live import STEP_MARKS, LiveSimulation
from web.push_input import PushInput, paper_presets


def wait_for(condition, timeout: float = 20.0) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.02)
    return False


def test_push_gives_adjusted_step_and_reset_restarts():
    lines: list[str] = []
    live = LiveSimulation("lipm", None, "rsg", "walk", log=lines.append)
    live.start()
    try:
        assert wait_for(lambda: live.snapshot().status.time > 0.3)
        status = live.snapshot().status
        assert status.controller == "rsg" and not status.fell and status.speed >= 0.0
        live.request_push(next(iter(paper_presets(live.snapshot().mass).values())))
        assert wait_for(lambda: any(" adjusted=yes" in line for line in lines))
        push = next(line for line in lines if line.startswith("push "))
        assert re.search(r"t=\d+\.\d+ s impulse=\(8\.00, -6\.00\) N s duration=0\.100 s", push)
        step = next(line for line in lines if "adjusted=yes" in line)
        assert re.match(r"step t=\d+\.\d+ s foot=(left|right) position=\(.+\) m", step)
        assert wait_for(lambda: live.snapshot().adjusted_steps >= 1)  # published after the line
        snap = live.snapshot()
        assert snap.pushes_applied == 1
        assert snap.state is not None and len(snap.state.dcm_error_trail) > 10

        live.set_paused(True)
        assert wait_for(lambda: live.snapshot().status.paused)
        paused_at = live.snapshot().status.time
        time.sleep(0.2)
        assert live.snapshot().status.time == pytest.approx(paused_at)
        live.set_paused(False)

        live.request_reset()
        assert wait_for(lambda: any(line.startswith("reset") for line in lines))
        assert wait_for(lambda: live.snapshot().pushes_applied == 0)
        assert live.snapshot().status.time < paused_at + 1.0
    finally:
        live.stop()


def test_controller_change_and_bad_requests():
    live = LiveSimulation("lipm", None, "rsg", "walk", log=lambda _: None)
    live.start()
    try:
        live.request_controller("no-step")
        assert wait_for(lambda: live.snapshot().status.controller == "no-step")
        with pytest.raises(ValueError, match="controller"):
            live.request_controller("magic")
        with pytest.raises(ValueError, match="slow motion"):
            live.set_slow_motion(3.0)
    finally:
        live.stop()


@pytest.mark.parametrize("signum", ["SIGINT", "SIGTERM"])
def test_demo_stops_cleanly_on_a_signal_even_if_started_with_sigint_ignored(signum):
    """A background job of a non-interactive shell (e.g. CI started with ``&``) inherits
    SIGINT ignored; the demo still stops on SIGINT (and SIGTERM), says so and exits 0
    (before it installed its own SIGINT handler it ran on until killed)."""
    import signal
    import subprocess
    import sys
    from pathlib import Path

    demo = subprocess.Popen(
        [sys.executable, "-m", "app", "demo", "--model", "lipm", "--port", str(free_port())],
        cwd=Path(__file__).resolve().parents[1],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        bufsize=1,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN),
    )
    with output_lines(demo) as lines:
        assert wait_for(lambda: any("open http://" in line for line in lines), 120.0), lines
        demo.send_signal(getattr(signal, signum))
        assert demo.wait(30) == 0
    assert any("rsg demo: stopped" in line for line in lines), lines


def test_a_push_into_a_run_that_is_not_advancing_or_without_impulse_is_refused():
    lines: list[str] = []
    live = LiveSimulation("lipm", None, "rsg", "walk", log=lines.append)
    live.start()
    try:
        preset = next(iter(paper_presets(live.snapshot().mass).values()))
        assert wait_for(lambda: live.snapshot().status.time > 0.2)
        live.set_paused(True)
        assert wait_for(lambda: live.snapshot().status.paused)
        live.request_push(preset)
        assert wait_for(lambda: any("push refused: the run is paused" in line for line in lines))
        live.set_paused(False)
        assert wait_for(lambda: not live.snapshot().status.paused)
        live.request_push(PushInput(preset.direction, 0.0, preset.duration))
        assert wait_for(lambda: any("a push needs an impulse > 0" in line for line in lines))
        assert not any(line.startswith("push t=") for line in lines)
        assert live.snapshot().pushes_applied == 0
        live.request_push(preset)
        assert wait_for(lambda: any(line.startswith("push t=") for line in lines))
        assert wait_for(lambda: live.snapshot().pushes_applied == 1)
    finally:
        live.stop()


def test_the_live_loop_keeps_bounded_memory_however_long_it_runs():
    """No time limit: the loop records no time series, and past pushes are dropped
    (the live thread is driven tick by tick here, 14 s of walking with 7 pushes)."""
    live = LiveSimulation("lipm", None, "rsg", "walk", log=lambda _: None)
    loop = live._require_loop()
    preset = next(iter(paper_presets(live.snapshot().mass).values()))
    small = PushInput(preset.direction, 0.2 * preset.impulse, preset.duration)
    sizes = []
    for second in range(14):
        if second % 2 == 0:
            live.request_push(small)
            live._handle_requests()
        for _ in range(round(1.0 / loop.period)):
            live._tick()
        if second in (10, 13):
            snap = live._make_snapshot()
            assert snap.state is not None
            sizes.append(
                (len(loop.rows), len(loop.steps), len(loop.scenario.pushes),
                 len(snap.state.steps), len(snap.plot_time), len(snap.state.com_trail))
            )  # fmt: skip
    assert live.snapshot().status.error == "" and not loop.backend.fall_status().fell
    assert sizes[0][:3] == sizes[1][:3] == (1, 0, 1), sizes  # no time series, one push
    assert sizes[0][4:] == sizes[1][4:] == (1000, 200), sizes  # plot and trail windows
    assert sizes[1][3] <= STEP_MARKS
    live.stop()


@pytest.mark.usefixtures("cache_in_tmp")
@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_the_g1_page_draws_the_com_where_the_robot_carries_it(engine):
    """The planner's pendulum is taller than G1's CoM (c_z + h_r, robots/g1.py): the
    page still draws the CoM marker at the CoM of the robot it draws, computed from the
    same snapshot's pose, within 2 cm (10 cm higher if drawn at the pendulum), on
    either engine (the status names it)."""
    import numpy as np

    from kinematics.robot_model import RobotModel
    from robots import get_robot
    from web.scene_model import draw_scene

    live = LiveSimulation(engine, "g1", "rsg", "walk", log=lambda _: None)
    live.start()
    try:
        assert wait_for(lambda: live.snapshot().status.time > 1.0, timeout=120.0)
        snap = live.snapshot()
    finally:
        live.stop()
    assert snap.state is not None and snap.robot is not None
    assert snap.status.model == engine and not snap.status.fell
    drawing = draw_scene(snap.state, snap.foot_lower, snap.foot_upper)
    model = RobotModel(get_robot("g1"))
    pose = snap.robot
    w, x, y, z = pose.base_wxyz
    joints = [pose.joints[name] for name in model.joint_names]
    model.update(np.array([*pose.base_position, x, y, z, w, *joints]), np.zeros(model.nv))
    assert abs(drawing.com[2] - model.com[2]) < 0.02, (drawing.com, model.com)
    np.testing.assert_allclose(drawing.com[:2], model.com[:2], atol=0.01)
