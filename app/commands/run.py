"""``rsg run``: one scenario, headless, results to a folder."""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from app.commands.arguments import (
    add_command,
    add_model_and_robot,
    add_out_arguments,
    add_paper_rules,
    add_set_argument,
    push_argument,
    simulated_seconds,
)
from app.results.folder import prepare_out
from app.results.replay import ReplayRecorder
from app.results.run_files import write_results
from app.runner import RunResult, run_closed_loop
from app.scenarios import BUILT_IN, describe_push, load_scenario
from app.setup.build import backend_reality, build_backend, resolve_robot
from app.setup.overrides import ROBOT_MODELS, check_overrides, is_robot_model
from planner.exceptions import ParameterError
from planner.parameters import CONTROLLERS
from planner.types import Push
from robots import DEFAULT_ROBOT


class ProgressBar:
    """A one-line progress bar on stderr (silent when stderr is not a terminal)."""

    def __init__(self, label: str, enabled: bool = True) -> None:
        self.label = label
        self.enabled = enabled and sys.stderr.isatty()
        self.last = -1

    def __call__(self, fraction: float) -> None:
        if not self.enabled:
            return
        percent = int(100 * fraction)
        if percent != self.last:
            self.last = percent
            bar = "#" * (percent // 4)
            sys.stderr.write(f"\r{self.label} [{bar:<25}] {percent:3d}%")
            if percent >= 100:
                sys.stderr.write("\n")
            sys.stderr.flush()


HELP = "simulate one scenario headless and write summary, time series and plots"
DESCRIPTION = (
    "Simulate one scenario with a step controller in the loop, headless, and "
    "write summary.json, timeseries.csv and the paper's Fig. 6 plots to --out."
)
EPILOG = """\
examples:
  rsg run --scenario walk --duration 20 --out results/g1-walk       # G1 in PyBullet
  rsg run --model lipm --scenario paper-fig6 --out results/fig6
  rsg run --model lipm --controller no-step --scenario walk --push 3:0,25 --out results/side
  rsg run --model lipm --scenario my_pushes.toml --out results/mine
  rsg run --model pybullet --controller placo-wpg --scenario walk --duration 4 --out results/wpg
  rsg run --reality randomized --reality-seed 3 --scenario walk --out results/g1-real3
  rsg run --model mujoco --robot talos --scenario paper-fig6 --out results/talos-mujoco

outputs in --out (a folder with an earlier run's results is refused without --overwrite):
  summary.json     verdict (recovered, fell, interrupted), steps, pushes, Lyapunov levels,
                   the reality profile and, on the full robot, its draw
  timeseries.csv   CoM, ZMP, hdot, stance foot, DCM error, V_u, s~, push force (SI units)
  fig6*.png        the paper's Fig. 6: top view, time since step, DCM error
  replay.npz       the run for the browser: rsg replay FOLDER
  physics.csv      with --physics-log: every physics step, the ground against the plan
  physics.png      with --physics-log: the feet's forces and CoP against the plan, the
                   soles' tilt and yaw

exit code: 0 recovered, 1 not recovered, 2 bad input, 130 interrupted (Ctrl-C: what was
simulated is written, summary.json says "interrupted": true)
"""

#: Exit code of a run stopped by Ctrl-C (128 + SIGINT, the shells' convention).
EXIT_INTERRUPTED = 130


def verdict(result: RunResult) -> str:
    """One line saying what happened."""
    adjusted = sum(s.event["adjusted"] for s in result.steps)
    head = "RECOVERED" if result.recovered else ("FELL" if result.fall.fell else "NOT RECOVERED")
    if result.interrupted:
        head = f"INTERRUPTED at t={result.sim_time:.3f} s (results so far written)"
    why = f" ({result.fall.reason})" if result.fall.fell else ""
    return (
        f"{head}{why}: {len(result.steps)} steps ({adjusted} adjusted), "
        f"V_u final {result.final_lyapunov:.2e} / max {result.max_lyapunov:.2e} "
        f"(gamma_v {result.lyapunov_threshold:g}), constraint violations "
        f"{result.constraint_violations}, QP infeasible {result.qp_infeasible}, "
        f"{result.sim_time:.1f} s simulated in {result.wall_time:.1f} s"
    )


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Add ``rsg run`` to the subcommands."""
    p = add_command(sub, "run", HELP, DESCRIPTION, EPILOG)
    add_model_and_robot(p, "pybullet", reality_seed=True)
    p.add_argument(
        "--controller",
        choices=(*CONTROLLERS, "placo-wpg"),
        default="rsg",
        help="rsg: step time and location adjusted; fixed-timing: location only; "
        "no-step: nominal steps; placo-wpg: placo's WalkPatternGenerator with "
        "update_supports (a full-robot model only) (default: rsg)",
    )
    p.add_argument(
        "--scenario",
        default="paper-fig6",
        help=f"built-in ({', '.join(BUILT_IN)}) or a .toml file (default: paper-fig6)",
    )
    p.add_argument(
        "--push",
        type=push_argument,
        action="append",
        default=[],
        metavar="T:IX,IY[:D]",
        help="add a push: start time [s], impulse [N s], duration [s] (default 0.1); repeatable",
    )
    p.add_argument(
        "--duration",
        type=simulated_seconds,
        default=None,
        help="simulated time [s] (default: the scenario's)",
    )
    add_out_arguments(p)
    add_paper_rules(p)
    add_set_argument(p)
    p.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    p.add_argument(
        "--physics-log",
        action="store_true",
        help="also write physics.csv: CoM, foot forces and CoPs, soles (position, tilt, "
        "yaw), and the controller's planned CoP, foot forces and sole targets at every "
        "physics step (--model pybullet or mujoco; touchdowns and impacts), and physics.png: the "
        "feet's forces and CoP against the plan, the soles' tilt and yaw",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def run(args: argparse.Namespace) -> int:
    """Run ``args.scenario``; returns 0 if recovered, 1 if not, 130 if interrupted.

    Everything is checked before the backend is built: the scenario and pushes
    (:mod:`app.scenarios`), the overrides (:func:`app.setup.overrides.check_overrides`), that
    the scenario fits the loop's tick, and the ``--out`` folder
    (:func:`app.results.folder.prepare_out`).
    """
    scenario = load_scenario(args.scenario)
    left_out: list[Push] = []
    if args.duration is not None:  # shortens the scenario: its later pushes are left out
        left_out = [p for p in scenario.pushes if p.time >= args.duration]
        kept = tuple(p for p in scenario.pushes if p.time < args.duration)
        scenario = replace(scenario, duration=args.duration, pushes=kept)
    scenario = scenario.with_pushes(args.push)  # each must end before the run does
    planner = None
    overrides = tuple(args.overrides)
    robot = resolve_robot(args.model, args.robot)
    wpg = args.controller == "placo-wpg"
    if wpg and not is_robot_model(args.model):
        raise ParameterError(
            "--controller",
            "placo-wpg",
            f"--model {' or '.join(ROBOT_MODELS)} with placo-wpg (it drives the full robot's "
            "IK), or one of "
            f"{', '.join(CONTROLLERS)} on --model {args.model}",
        )
    if wpg and args.paper_rules:
        raise ParameterError(
            "--paper-rules", True, "no --paper-rules with placo-wpg (they are rules of the RSG)"
        )
    if args.physics_log and args.model not in ROBOT_MODELS:
        raise ParameterError(
            "--model",
            args.model,
            f"{' or '.join(ROBOT_MODELS)} with --physics-log (the LIPM has no physics steps)",
        )
    settings = check_overrides(
        overrides, args.model, robot, "rsg" if wpg else args.controller, args.paper_rules
    )
    scenario.check_fits(settings.control_period)
    scenario.scaled_to(settings.mass)  # the impulses' bound, with the nominal mass
    for path in prepare_out(args.out, "run", args.overwrite):
        print(f"deleted {path} (--overwrite)")
    for push in left_out:
        print(f"left out: {describe_push(push)} of {scenario.name} starts after --duration")
    physics_log = None
    if args.physics_log:
        from app.backends.physics_log import PhysicsLog

        physics_log = PhysicsLog()
    if wpg:
        from app.baselines.placo_wpg import build_placo_wpg_backend

        backend, config, initial, planner = build_placo_wpg_backend(
            robot or DEFAULT_ROBOT,
            overrides,
            physics_log,
            args.reality,
            args.reality_seed,
            engine=args.model,
        )
    else:
        backend, config, initial = build_backend(
            args.model,
            robot,
            args.controller,
            args.paper_rules,
            overrides,
            physics_log,
            args.reality,
            args.reality_seed,
        )
    if overrides:
        print("with " + " ".join(f"--set {name}={value}" for name, value in overrides))
    recorder = ReplayRecorder()
    try:
        reality = backend_reality(backend, args.reality, args.reality_seed)
        if reality is not None:
            print(reality.describe())
        elif args.reality != "ideal":
            print(f"reality {args.reality}: ignored on --model lipm (the LIPM stays ideal)")
        scaled, factor = scenario.scaled_to(backend.mass)
        if factor != 1.0:
            print(
                f"impulses scaled by {factor:.3f} (robot mass {backend.mass:.1f} kg / "
                f"{scenario.reference_mass:.1f} kg) so the velocity change matches"
            )
        bar = ProgressBar(f"{args.model}/{args.controller}/{scenario.name}", not args.quiet)
        result = run_closed_loop(
            backend,
            config,
            scaled,
            initial,
            progress=bar,
            planner=planner,
            interruptible=True,
            on_tick=recorder,
        )
        if result.interrupted and bar.enabled:
            sys.stderr.write("\n")  # end the bar's line
        result.impulse_scale = factor
        result.extra["pushes_left_out"] = [
            Push(p.time, np.asarray(p.impulse, dtype=float) * factor, p.duration) for p in left_out
        ]
        if robot is not None:
            result.extra["robot"] = robot
        result.extra["reality"] = args.reality
        result.extra["reality_seed"] = args.reality_seed
        if reality is not None:
            result.extra["reality_draw"] = reality.as_dict()
        description = getattr(backend, "description", None)
        if args.model in ROBOT_MODELS and description is not None:
            # The physics model: these joints are welded at their standing angles.
            result.extra["locked_joints"] = list(description.locked_joints)
        if overrides:
            result.extra["overrides"] = dict(overrides)
    finally:
        backend.close()
    out: Path = args.out
    summary = write_results(result, args.controller, out, plots=not args.no_plots)
    for name in ("summary.json", "timeseries.csv"):
        print(f"wrote {out / name}")
    if physics_log is not None:
        print(f"wrote {physics_log.write(out / 'physics.csv')}")
        if not args.no_plots and physics_log.rows:
            from app.results.physics_plot import plot_physics

            plot_physics(np.array(physics_log.rows), out / "physics.png", scenario.name)
            print(f"wrote {out / 'physics.png'}")
    if not args.no_plots and len(result.timeseries) >= 2:
        print(f"wrote {out}/fig6a_top_view.png, fig6b_time_since_step.png, fig6c_dcm_error.png")
    print(f"wrote {recorder.write(result, args.controller, robot, out)} (rsg replay {out})")
    print(verdict(result))
    if result.interrupted:
        return EXIT_INTERRUPTED
    return 0 if summary["recovered"] else 1
