"""``rsg bench``: how long the parts of the loop take, per call.

Measured in one process, one after the other:

- ``rsg_tick``: :meth:`ReactiveStepGenerator.update` on ticks without a step (the
  continuous part: error, Lyapunov level, D_T test, filter, preview), on the LIPM
  with the paper's Fig. 6 pushes; ``rsg_step_tick``: the ticks with a step (QP);
- ``qp_proxqp`` / ``qp_exact``: the step QP (27) by qpsolvers/proxqp and by the exact
  box method, on problems sampled around the states the RSG meets (random DCM
  errors, both stance feet); the two solutions are compared (share within 1e-4 m,
  largest difference, and whether the exact one's objective is ever worse);
- ``ik``, ``physics``: one whole-body IK solve and one physics step, timed by
  wrappers put around ``backend.ik.solve`` and ``backend.sim.step`` of a full-robot
  walk on PyBullet or MuJoCo (the backend's files are not touched);
- ``loop``: one control tick of the full-robot closed loop, and its real-time factor.

With several engines (``rsg bench --model pybullet,mujoco``) the robot's figures are
taken for each, one engine after the other in the same process, so their real-time
factors are measured side by side (``by_model``; the first engine's are also at the top
level, as with one).

- ``placo_wpg``: the same walk with the placo-wpg baseline (:mod:`app.baselines.placo_wpg`)
  as the planner: its planner tick (``rsg_tick``/``rsg_step_tick`` keys: ticks
  without/with a step; on the robot, as the baseline exists only there), IK,
  physics and the whole tick, in the same process right after the RSG's walk.
  ``robot_planner_tick`` is the planner's tick on the robot for both.

Each figure is the median and 95th percentile [s] over the calls.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np

from app.backends.lipm import LipmBackend
from app.reality import DEFAULT_PROFILE
from app.runner import ClosedLoop
from app.scenarios import BUILT_IN, Scenario
from app.setup.overrides import Overrides
from planner.lyapunov import design_lyapunov
from planner.parameters import PlannerConfig
from planner.step_generator import ReactiveStepGenerator
from planner.step_qp import build_step_qp, solve_step_qp

QP_AGREEMENT = 1e-4  # [m] proxqp and the exact method "agree" within this


def stats(samples: list[float]) -> dict:
    """Median, 95th percentile, mean [s] and count of ``samples``."""
    if not samples:
        return {"median": None, "p95": None, "mean": None, "count": 0}
    data = np.asarray(samples)
    return {
        "median": float(np.median(data)),
        "mean": float(np.mean(data)),
        "p95": float(np.percentile(data, 95)),
        "count": len(samples),
    }


def timed(function: Callable, sink: list[float]) -> Callable:
    """``function`` that appends its wall time per call [s] to ``sink``."""

    def wrapper(*args: Any, **kwargs: Any) -> Any:
        start = time.perf_counter()
        try:
            return function(*args, **kwargs)
        finally:
            sink.append(time.perf_counter() - start)

    return wrapper


class TimedPlanner:
    """A step planner whose update is timed [s]: ticks without a step in ``flow``, with
    one in ``jump`` (given to :class:`app.runner.ClosedLoop` as its planner)."""

    def __init__(self, planner: Any) -> None:
        self.planner = planner
        self.flow: list[float] = []
        self.jump: list[float] = []

    def reset(self, stance: Any, swing: Any) -> None:
        self.planner.reset(stance, swing)

    def update(self, measured: Any, period: float) -> Any:
        start = time.perf_counter()
        out = self.planner.update(measured, period)
        (self.jump if out.step is not None else self.flow).append(time.perf_counter() - start)
        return out

    def __getattr__(self, name: str) -> Any:
        return getattr(self.planner, name)


def bench_rsg_ticks(duration: float = 12.0) -> dict:
    """Time the RSG's update on the LIPM with the paper-fig6 pushes."""
    config = PlannerConfig()
    scenario = BUILT_IN["paper-fig6"]
    scenario = Scenario(scenario.name, min(duration, scenario.duration), scenario.pushes)
    timed_rsg = TimedPlanner(ReactiveStepGenerator(config, qp_solver="proxqp"))
    loop = ClosedLoop(LipmBackend(config.model), config, scenario, planner=lambda _: timed_rsg)
    for _ in range(int(round(scenario.duration / loop.period))):
        loop.tick()
    flow, jump = timed_rsg.flow, timed_rsg.jump
    return {"rsg_tick": stats(flow), "rsg_step_tick": stats(jump)}


def bench_step_qp(samples: int = 500, seed: int = 0) -> dict:
    """Time proxqp and the exact box method on sampled QPs (27); check they agree."""
    config = PlannerConfig()
    design = design_lyapunov(config.model, config.constraints, config.rsg)
    rng = np.random.default_rng(seed)
    proxqp, exact = [], []
    differences, exact_not_worse = [], True
    for index in range(samples):
        sigma = 1 if index % 2 else -1
        xi1_ref = np.array([rng.uniform(-0.1, 0.1), -sigma * rng.uniform(0.0, 0.1)])
        error = rng.normal(0.0, 0.15, 2)
        xi1 = xi1_ref + rng.normal(0.0, 0.05, 2)
        problem = build_step_qp(
            design.matrix, error, xi1, xi1_ref, sigma, config.constraints, config.rsg
        )
        start = time.perf_counter()
        a = solve_step_qp(problem, "proxqp")
        middle = time.perf_counter()
        b = solve_step_qp(problem, "exact")
        proxqp.append(middle - start)
        exact.append(time.perf_counter() - middle)
        differences.append(float(np.max(np.abs(a.step - b.step))))
        exact_not_worse &= problem.objective(b.step) <= problem.objective(a.step) + 1e-6
    agree = np.asarray(differences) < QP_AGREEMENT
    return {
        "qp_proxqp": stats(proxqp),
        "qp_exact": stats(exact),
        "qp_samples": samples,
        "qp_agree_fraction": float(agree.mean()),
        "qp_max_difference": float(max(differences)),
        "qp_equal": bool(agree.all()),
        "qp_exact_objective_not_worse": bool(exact_not_worse),
    }


def bench_robot(
    robot: str,
    duration: float,
    controller: str = "rsg",
    overrides: Overrides = (),
    reality: str = DEFAULT_PROFILE,
    engine: str = "pybullet",
) -> dict:
    """Time IK, physics and the whole loop of a walk on ``engine`` (``pybullet`` or
    ``mujoco``; it may fall; timed until then).

    With ``controller="placo-wpg"`` the planner is the placo baseline, and its
    ticks are timed too (``rsg_tick``/``rsg_step_tick`` keys: without/with a step).
    ``overrides``: ``--set`` assignments (for example ``locked_joints=none``);
    ``reality``: the robot's reality profile (:mod:`app.reality`), drawn from seed 0.
    """
    factory = None
    if controller == "placo-wpg":
        from app.baselines.placo_wpg import build_placo_wpg_backend

        backend, config, initial, factory = build_placo_wpg_backend(
            robot, overrides, reality=reality, engine=engine
        )
    else:
        from app.setup.build import build_backend

        backend, config, initial = build_backend(
            engine, robot, controller, overrides=overrides, reality=reality
        )
    ik_times: list[float] = []
    physics_times: list[float] = []
    tick_times: list[float] = []
    try:
        # Wrappers around the IK solve and the physics step time them without touching
        # the backend's code.
        ik = backend.controller.ik  # type: ignore[attr-defined]
        ik.solve = timed(ik.solve, ik_times)
        backend.sim.step = timed(backend.sim.step, physics_times)  # type: ignore[attr-defined]
        timed_planner = TimedPlanner(
            ReactiveStepGenerator(config) if factory is None else factory(config)
        )
        loop = ClosedLoop(
            backend, config, Scenario("walk", duration), initial, planner=lambda _: timed_planner
        )
        ik_times.clear()  # the reset's solves are not ticks
        wall = time.perf_counter()
        for _ in range(int(round(duration / loop.period))):
            start = time.perf_counter()
            loop.tick()
            tick_times.append(time.perf_counter() - start)
            if backend.fall_status().fell:
                break
        wall = time.perf_counter() - wall
        sim = loop.ticks * loop.period
        fall = backend.fall_status()
        ticks = max(getattr(backend, "ticks", 1), 1)
        timers = {k: v / ticks for k, v in getattr(backend, "timers", {}).items()}
        motors = len(backend.sim.joint_names)
        physics_time_step = backend.sim.time_step
    finally:
        backend.close()
    flow, jump = timed_planner.flow, timed_planner.jump
    planner_ticks = {"rsg_tick": stats(flow), "rsg_step_tick": stats(jump)}
    return {
        **({} if factory is None else planner_ticks),
        "model": engine,
        "robot_planner_tick": stats(flow + jump),
        "ik": stats(ik_times),
        "physics": stats(physics_times),
        "loop_tick": stats(tick_times),
        "real_time_factor": sim / wall if wall > 0 else None,
        "simulated": sim,
        "fell": fall.fell,
        "fall_reason": fall.reason,
        "backend_timers_mean_per_tick": timers,
        "control_period": loop.period,
        "motors": motors,
        "physics_time_step": physics_time_step,
    }


def bench_placo_wpg(
    robot: str,
    duration: float,
    overrides: Overrides = (),
    reality: str = DEFAULT_PROFILE,
    engine: str = "pybullet",
) -> dict:
    """The same figures for the placo-wpg baseline (its planner ticks on the robot)."""
    return bench_robot(robot, duration, "placo-wpg", overrides, reality, engine)


def compare_engines(by_model: dict[str, dict]) -> str:
    """One line per figure that differs by engine: the physics step's median [us], the
    whole tick's median [us] and the real-time factor of each engine's walk, side by side."""
    names = list(by_model)
    rows = [
        ("physics step median [us]", lambda r: _us((r.get("physics") or {}).get("median"))),
        ("control tick median [us]", lambda r: _us((r.get("loop_tick") or {}).get("median"))),
        ("real-time factor (rsg)", _rtf),
        ("real-time factor (placo-wpg)", lambda r: _rtf(r.get("placo_wpg") or {})),
        ("fell (rsg)", lambda r: "yes" if r.get("fell") else "no"),
    ]
    lines = [f"| engine | {' | '.join(names)} |", "|---|" + "---|" * len(names)]
    for label, cell in rows:
        lines.append(f"| {label} | {' | '.join(cell(by_model[n]) for n in names)} |")
    return "\n".join(lines)


ROWS = (
    ("rsg_tick", "planner tick without a step (rsg: LIPM; placo-wpg: robot)"),
    ("rsg_step_tick", "planner tick with a step (rsg: LIPM; placo-wpg: robot)"),
    ("robot_planner_tick", "planner tick on the robot (all ticks)"),
    ("qp_proxqp", "step QP, proxqp"),
    ("qp_exact", "step QP, exact box"),
    ("ik", "IK solve"),
    ("physics", "physics step"),
    ("loop_tick", "whole control tick"),
)


def format_bench(report: dict) -> str:
    """Markdown table: median and p95 [us] per part, beside placo-wpg's."""
    other = report.get("placo_wpg") or {}
    lines = [
        "| part | rsg median [us] | rsg p95 [us] | placo-wpg median [us] | placo-wpg p95 [us] |",
        "|---|---|---|---|---|",
    ]
    for key, label in ROWS:
        if key == "physics" and report.get("physics_time_step"):
            label = f"{label} ({1e3 * report['physics_time_step']:g} ms)"
        mine, theirs = report.get(key) or {}, other.get(key) or {}
        lines.append(
            f"| {label} | {_us(mine.get('median'))} | {_us(mine.get('p95'))} | "
            f"{_us(theirs.get('median'))} | {_us(theirs.get('p95'))} |"
        )
    rtf = report.get("real_time_factor")
    lines.append(
        f"| real-time factor (whole loop) | {'-' if rtf is None else f'{rtf:.2f}'} | | "
        f"{_rtf(other)} | |"
    )
    return "\n".join(lines)


def _us(value: float | None) -> str:
    return "-" if value is None else f"{1e6 * value:.1f}"


def _rtf(other: dict) -> str:
    value = other.get("real_time_factor")
    return "-" if value is None else f"{value:.2f}"


def tick_breakdown(report: dict) -> str:
    """One line: the mean time per control tick of each part of the robot loop [ms]."""
    timers = report["backend_timers_mean_per_tick"]
    ik = report["ik"]["mean"] or 0.0
    parts = {
        "physics and motors": timers.get("physics", 0.0),
        "measurement and estimation": timers.get("estimation", 0.0),
        "RSG": report["robot_planner_tick"]["mean"] or 0.0,
        "stabilizer, swing foot, feed-forward": max(timers.get("control", 0.0) - ik, 0.0),
        "IK": ik,
    }
    listed = ", ".join(f"{name} {1e3 * value:.2f} ms" for name, value in parts.items())
    return (
        f"mean per {1e3 * report['control_period']:.0f} ms tick on the robot: {listed}; "
        f"total {1e3 * sum(parts.values()):.2f} ms; real-time factor "
        f"{report['real_time_factor']:.2f}"
    )
