"""One push, one run: recovered, survived or fell, and how many steps it took.

Shared by the push grid (:mod:`app.experiments.grid`), the push campaign
(:mod:`app.experiments.campaign`) and the sweep's monotonicity check
(:mod:`app.experiments.monotonicity`):

* ``recovered``: no fall, and the last two steps after the push nominal, each taken
  with V_u below gamma_v (:attr:`app.runner.RunResult.recovered`);
* ``survived``: no fall until the end of the run, but not recovered;
* ``fell``.

Steps after the push (``settle_steps``): the number of touchdowns from the push start
up to the last instant at which V_u >= gamma_v (the time series and each step's
level just before its jump both count, so the step whose jump brings V_u below
gamma_v is included); 0 when V_u stays below gamma_v throughout, ``None`` when it
does not stay below by the end of the run (a fall, or V_u >= gamma_v at the end) or
V_u is not defined (placo-wpg).
"""

from __future__ import annotations

import numpy as np

from app.experiments.sweep import PLACO_WPG, PushExperiment, build_controller
from app.experiments.trial import measured_touchdown
from app.reality import RealityDraw
from app.runner import RunResult
from app.scenarios import Scenario
from app.setup.build import backend_reality
from app.setup.overrides import is_robot_model
from planner.types import Push

OUTCOMES = ("recovered", "survived", "fell")
#: What ``recovered`` means, as written into result files.
RECOVERED_MEANS = (
    "no fall, the last two steps after the push nominal, each taken with V_u < gamma_v"
)


def outcome_of(result: RunResult) -> str:
    """``recovered``, ``survived`` or ``fell`` (see the module's docstring)."""
    if result.recovered:
        return "recovered"
    return "fell" if result.fall.fell else "survived"


def adjusted_steps_after(result: RunResult, start: float) -> int:
    """Adjusted steps that land at or after ``start`` [s]."""
    return sum(bool(s.event["adjusted"]) for s in result.steps if s.event["t"] >= start)


def settle_steps(result: RunResult, start: float) -> int | None:
    """Steps from ``start`` [s] until V_u stays below gamma_v (module docstring)."""
    if result.fall.fell or result.final_lyapunov >= result.lyapunov_threshold:
        return None
    gamma = result.lyapunov_threshold
    time, level = result.column("t"), result.column("lyapunov")
    above = [float(t) for t in time[(time >= start) & (level >= gamma)]]
    above += [s.event["t"] for s in result.steps
              if s.event["t"] >= start and s.event["lyapunov_before"] >= gamma]  # fmt: skip
    if not above:
        return 0
    last = max(above)
    return sum(start <= s.event["t"] <= last for s in result.steps)


class PushRun:
    """``controller`` built on ``spec``'s model and robot, for one run with one push; the
    full robot with ``spec``'s reality drawn from ``seed``.

    Attributes:
        config: The planner configuration (push timing and bounds are read from it
            before :meth:`run`).
        reality: The draw the full robot's backend applies (None on the LIPM).
    """

    def __init__(self, spec: PushExperiment, controller: str, seed: int = 0) -> None:
        self.backend, self.config, self.initial, self.planner = build_controller(
            spec, controller, seed
        )
        self.reality: RealityDraw | None = None
        if is_robot_model(spec.model):
            self.reality = backend_reality(self.backend, spec.reality, seed)

    def touchdown(self, cycle: int) -> float:
        """Time [s] at which step ``cycle`` lands in the unpushed walk
        (:func:`app.experiments.trial.measured_touchdown`); the backend stays open."""
        try:
            return measured_touchdown(self._runner(), self.backend, self.config, self.initial,
                                      cycle, **self._options())  # fmt: skip
        except BaseException:
            self.backend.close()
            raise

    def run(self, push: Push, end_time: float) -> RunResult:
        """Walk until ``end_time`` [s] with ``push`` (the QP (27) solved exactly; a fall
        ends the run early), then release the backend."""
        scenario = Scenario("push", end_time, (push,))
        try:
            return self._runner()(
                self.backend, self.config, scenario, self.initial, qp_solver="exact",
                **self._options(),
            )  # fmt: skip
        finally:
            self.backend.close()

    def _runner(self):  # noqa: ANN202
        from app.runner import run_closed_loop

        return getattr(self.backend, "run_closed_loop", None) or run_closed_loop

    def _options(self) -> dict:
        return {} if self.planner is None else {"planner": self.planner}


def describe(result: RunResult, push: Push, controller: str) -> dict:
    """JSON-ready figures of a run after ``push``: outcome, fall reason, end time [s],
    adjusted steps and steps to settle after the push start, largest and final V_u [-]."""
    defined = controller != PLACO_WPG  # placo-wpg reports V_u = 0: not defined
    return {
        "outcome": outcome_of(result),
        "fall_reason": result.fall.reason,
        "end_time": result.sim_time,
        "adjusted_steps": adjusted_steps_after(result, push.time),
        "settle_steps": settle_steps(result, push.time) if defined else None,
        "max_lyapunov": float(result.max_lyapunov) if defined else None,
        "final_lyapunov": float(result.final_lyapunov) if defined else None,
    }


def stance_offset_after(result: RunResult, push_time: float) -> float | None:
    """Largest lateral (world y) distance [m] between the CoM and the stance sole in
    single support from ``push_time`` on: how far the plan swings the CoM over the
    stance leg (None without such a tick)."""
    time = result.column("t")
    single = result.column("time_since_step") >= result.config.gait.double_support_duration
    after = single & (time >= push_time)
    if not after.any():
        return None
    offset = np.abs(result.column("com_y") - result.column("foot_y"))
    return float(offset[after].max())


def impulse_along(direction_deg: float, magnitude: float) -> np.ndarray:
    """Impulse vector [N s] of ``magnitude`` along ``direction_deg`` (0 forward, 90 left)."""
    angle = np.radians(direction_deg)
    return magnitude * np.array([np.cos(angle), np.sin(angle)])
