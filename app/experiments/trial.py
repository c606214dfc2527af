"""One sweep trial: the push timing of a phase, and recovery verdicts from a snapshot."""

from __future__ import annotations

import copy
import math

from app.scenarios import Scenario
from planner.exceptions import RsgError
from planner.parameters import PlannerConfig
from planner.types import Push


def push_timing(config: PlannerConfig, cycle: int, phase: float) -> tuple[float, int, float]:
    """(push start [s], stance sigma, s~ [s]) for ``phase`` of walking cycle ``cycle``."""
    gait = config.gait
    step_time = gait.single_support_duration + (cycle - 1) * gait.step_duration
    sigma = 1 if cycle % 2 == 0 else -1
    since_step = phase * gait.step_duration
    return step_time + since_step, sigma, since_step


def measured_touchdown(runner, backend, config, initial, cycle: int, **options) -> float:  # noqa: ANN001
    """Time [s] at which the walk of ``runner`` (:func:`app.runner.run_closed_loop` or a
    backend's own) on ``backend``, unpushed, is where its nominal step ``cycle`` lands:
    the first touchdown at or after the nominal t_k, on the foot nominal step ``cycle``
    puts down.

    The nominal t_k of :func:`push_timing` is where the reference enters D_S; the loop
    steps at the first tick inside it: at t_k when the ticks fall on it (G1's 10 ms
    ticks: step 4 at 3.1 s), up to a tick later otherwise, and the delays add up. A robot
    that adjusted steps as it started walking (the honest plant's first steps) may have
    taken more steps by then: counting steps would push it during that start, at another
    point of its gait than its twin. A push timed from this touchdown hits the same point
    of the gait on every model, as IHMC's tests trigger on the gait state.

    Raises:
        RsgError: The walk fell or did not land that foot at or after t_k.
    """
    gait = config.gait
    nominal = gait.single_support_duration + (cycle - 1) * gait.step_duration
    foot = initial.swing.foot if cycle % 2 == 1 else initial.stance.foot
    scenario = Scenario("walk", nominal + 2.5 * gait.step_duration)
    result = runner(backend, config, scenario, initial, qp_solver="exact", **options)
    tick = backend.control_period
    for record in result.steps if not result.fall.fell else ():
        event = record.event
        if event["t"] >= nominal - tick - 1e-9 and event["foot"] == foot:
            return float(event["t"])
    raise RsgError(
        f"the unpushed walk took {len(result.steps)} steps by {scenario.duration:g} s "
        f"(fell: {result.fall.reason or 'no'}): no touchdown of the {foot} foot at or after "
        f"{nominal:g} s (step {cycle}) to time the push"
    )


class SettledTrial:
    """Recovery verdicts of one push time, each run from a snapshot taken before the push.

    The walk up to the push is simulated once; each trial deep-copies that loop, adds
    its push and runs on. The verdict is :attr:`RunResult.recovered` of the full run,
    returned early: at a fall (False), or once the push is over and two nominal steps
    have followed it, each taken with V_u < gamma_v (True: from there the undisturbed
    LIPM walks on nominally; a test checks the verdicts are equal).

    Args:
        backend, config, initial: As for :func:`app.runner.run_closed_loop`.
        push_time: Start of the pushes to try [s].
        end_time: Simulated time at which an unsettled run is judged [s].
        qp_solver: ``exact`` or ``proxqp``.
    """

    def __init__(self, backend, config, initial, push_time: float, end_time: float,
                 qp_solver: str = "exact") -> None:  # fmt: skip
        from app.runner import ClosedLoop

        self.end_time = end_time
        loop = ClosedLoop(backend, config, Scenario("sweep", end_time), initial, qp_solver)
        for _ in range(int(math.floor(push_time / loop.period + 1e-9))):
            loop.tick()
        self.loop = copy.deepcopy(loop)  # independent of later uses of ``backend``

    def recovered(self, push: Push) -> bool:
        """Verdict for ``push`` (its time >= the snapshot's)."""
        loop = copy.deepcopy(self.loop)
        loop.add_push(push)
        backend = loop.backend
        push_end = push.time + push.duration
        nominal_in_a_row = 0
        while loop.ticks < int(round(self.end_time / loop.period)):
            out = loop.tick()
            if backend.fall_status().fell:
                return False
            if out.step is not None and out.time >= push_end:
                settled = out.step.lyapunov_before < loop.generator.design.threshold
                nominal_in_a_row = nominal_in_a_row + 1 if settled and not out.step.adjusted else 0
                if nominal_in_a_row >= 2:
                    return True
        return bool(loop.result().recovered)
