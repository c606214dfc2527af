"""The reactive step generator: the hybrid tracking controller (17) of Section V-B.

Why one long module: the flow, the jump sets and the output map all read and write
the controller's state nu; split, each part would reach into the others' state.

State nu = (zeta, o_H, r_H^dagger, s~, V_u^dagger):

- flow  F_nu = ((u^_c* - zeta) / theta, 0, 0, 1, 0),
        u^_c* = sat(K_u e_u + (0, m g H^-1 r~_H)),
- jump  G_nu = (zeta, o_H + u_d, r_H, 0, V_u(e_u - u_d + 2 xi1*)),
- output H_nu = (zeta, u_d^QP) if V_u >= gamma_v else (zeta, 2 xi1*),

with r~_H = -(o_H - r_H^dagger)(T_DSP - s~)/T_DSP in the DSP and 0 after it, and the
jump set D = D_T U D_S (14):

- D_S = {sign(xi2y*) xi1y* >= L_y/2} (the reference reaches its nominal jump),
- D_T = {s~ >= T_DSP + T_SP} n (D_T,1 U D_T,2),
  D_T,1 = {V_u >= gamma_v and V_u - V_u^dagger >= -gamma_v + mu_1},
  D_T,2 = {sigma xi1y - w_y >= 0} (the CoM crosses the outer edge of the stance
  foot; sign convention as in :mod:`planner.step_qp`).

Departures and extensions, one line each (why, flag and measurement:
``docs/extensions.md``; the extensions are off under ``--paper-rules``):

- the double-support compensation m g H^-1 r~_H is added to hdot after the saturation
  of K_u e_u (inside it, it saturates in every double support of nominal walking);
- D_S is also gated by s~ >= T_DSP + T_SP (no step before a real swing foot is ready);
- ``push_hold_time``: D_T,1 waits, at most that long, while the DCM shows a push
  (f c_z / (m g) = p_cmd - p from two ticks' DCMs), so the QP sees the whole push;
- ``step_reaction_time`` Delta: D_T is evaluated Delta ahead and schedules the
  touchdown at min(max(s~ + Delta, T_DSP + T_SP), s~_nom), the QP solved at the state
  predicted then; the decision is kept;
- ``qp_at_timing_jump``: H_nu takes the QP's step for a timing jump even below gamma_v;
- ``announced_foothold``: a nominal jump (D_S) steps onto the foothold announced at the
  tick before, where the swing foot was sent, as a scheduled timing jump does;
- a backend's swing contact (``MeasuredState.swing_contact``: a due jump waits for the
  swing sole to touch down, its foothold kept; ``touchdown_window``: a timing jump
  scheduled before the reference's own jump comes at the touchdown if the sole lands
  within that window before its time) and stance sole
  (``MeasuredState.stance_sole``: o_H follows it, over ``reanchor_time``).

Controllers in the same framework (``PlannerConfig.controller``): ``rsg``, all of the
above; ``fixed-timing``, D_S alone with locations from the QP when V_u >= gamma_v;
``no-step``, D_S alone and u_d = 2 xi1* always (feedback through the ZMP and the
angular momentum only).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .hybrid_lipm import H_INVERSE, H_MATRIX, dcm, flow_autonomous, integrate_lipm
from .lyapunov import LyapunovDesign, design_lyapunov
from .parameters import PlannerConfig
from .reference_model import NominalOrbit, ReferenceModel
from .step_qp import build_step_qp, solve_step_qp
from .types import Foot, Foothold, MeasuredState, PlannerOutput, StepEvent, sigma_of


def _foot_of(sigma: int) -> Foot:
    return "left" if sigma > 0 else "right"


@dataclass(frozen=True)
class HeldStep:
    """A jump that is due while the swing sole is still in the air: it comes at the
    touchdown, onto ``foothold`` [m] (where the swing foot was sent); ``nominal`` and
    ``from_qp`` say how it was decided."""

    foothold: np.ndarray
    nominal: bool
    from_qp: bool


class ReactiveStepGenerator:
    """Hybrid tracking controller (17) with the reference model (13).

    Args:
        config: Parameters; ``config.controller`` selects the variant.
        qp_solver: Solver for the QP (27) at a step: ``"proxqp"`` or ``"exact"``.
    """

    def __init__(self, config: PlannerConfig, qp_solver: str = "proxqp") -> None:
        self.config = config
        self.qp_solver = qp_solver
        self.model = config.model
        self.omega = config.model.omega
        self.design: LyapunovDesign = design_lyapunov(config.model, config.constraints, config.rsg)
        self.orbit = NominalOrbit(self.omega, config.gait)
        self._input_min = config.constraints.input_min()
        self._input_max = config.constraints.input_max()
        self._filter_gain = 0.0
        self._filter_period = -1.0
        self.reference = ReferenceModel(self.orbit, 1)
        self.reset(Foothold("left", np.zeros(2)), Foothold("right", np.zeros(2)))

    # ------------------------------------------------------------------ setup
    def reset(
        self, stance: Foothold, previous: Foothold, time_since_step: float | None = None
    ) -> None:
        """Start on the nominal orbit with ``stance`` just stepped on.

        Args:
            stance: Current stance foot o_H and sigma.
            previous: The other foot (r_H^dagger, the window start in the DSP).
            time_since_step: s~ at the start [s]; default T_DSP (start of the SSP).
        """
        gait = self.config.gait
        s0 = gait.double_support_duration if time_since_step is None else time_since_step
        self.sigma = sigma_of(stance.foot)
        self.stance = np.asarray(stance.position, dtype=float).copy()
        self.previous = np.asarray(previous.position, dtype=float).copy()
        self.window_start = self.previous.copy()  # r_H^dagger
        self.time_since_step = float(s0)  # s~
        self.lyapunov_at_step = 0.0  # V_u^dagger
        self.filter_state = np.zeros(4)  # zeta = filtered sat(K_u e_u) = (p~, hdot_fb)
        self.compensation_state = np.zeros(2)  # filtered m g H^-1 r~_H [N m]
        self.scheduled_step: float | None = None  # s~ of a decided timing jump
        # The last output's next step [m], whether the QP (27) placed it, and whether it
        # was a scheduled timing jump's: where the swing foot was sent.
        self.announced: tuple[np.ndarray, bool, bool] | None = None
        self.held_step: HeldStep | None = None  # a due jump waiting for the touchdown
        self.reference = ReferenceModel(self.orbit, self.sigma, s0)
        self._last_dcm: np.ndarray | None = None  # measured DCM at the last tick (world)
        self._last_cmp = np.zeros(2)  # effective CMP commanded over the last period
        self._last_period = 0.0
        self.push_estimate = np.zeros(2)  # f c_z / (m g): CMP shift by the push [m]
        self.push_duration = 0.0  # time the estimate has been above the threshold [s]
        self._reanchor_target: np.ndarray | None = None  # measured stance sole [m]
        self._swing_lifted = False  # the swing sole was seen off the ground this swing

    def initial_com_state(self) -> tuple[np.ndarray, np.ndarray]:
        """CoM position and velocity [m], [m/s] of the reference at the current state."""
        return self.stance + self.reference.xi1, self.reference.xi2.copy()

    # -------------------------------------------------------------- helpers
    def window_offset(self) -> np.ndarray:
        """r~_H = r_H - o_H [m]: non-zero only in the DSP."""
        t_dsp = self.config.gait.double_support_duration
        s = self.time_since_step
        if s >= t_dsp:
            return np.zeros(2)
        return -(self.stance - self.window_start) * (t_dsp - s) / t_dsp

    def dcm_error(self, xi: np.ndarray) -> np.ndarray:
        """e_u (18) [m]."""
        return dcm(self.omega, xi) - self.reference.dcm()

    @property
    def earliest_step(self) -> float:
        """T_DSP + T_SP, the earliest s~ at which the swing foot can land [s]."""
        return self.config.gait.double_support_duration + self.config.rsg.swing_preparation_time

    def _in_double_support(self) -> bool:
        return self.time_since_step < self.config.gait.double_support_duration

    def _ready_to_step(self, lead: float = 0.0) -> bool:
        """s~ + ``lead`` >= T_DSP + T_SP."""
        return self.time_since_step + lead >= self.earliest_step - 1e-9

    def _estimate_push(self, dcm_world: np.ndarray) -> None:
        """Update the push estimate from the DCM measured now and at the last tick.

        Over one period with constant inputs, (1) gives xi(t + T) = p + (xi(t) - p)
        e^(omega T) with p the effective CMP, p = p_cmd - f c_z / (m g) (p_cmd the
        commanded ZMP shifted by the commanded hdot). Solving for p from the two
        measured DCMs gives f c_z / (m g) = p_cmd - p, exact on the LIPM.
        """
        if self._last_dcm is not None and self._last_period > 0.0:
            growth = math.exp(self.omega * self._last_period)
            cmp_measured = (dcm_world - growth * self._last_dcm) / (1.0 - growth)
            self.push_estimate = self._last_cmp - cmp_measured
            pushed = np.linalg.norm(self.push_estimate) >= self.config.rsg.push_cmp_threshold
            self.push_duration = self.push_duration + self._last_period if pushed else 0.0
        self._last_dcm = dcm_world.copy()

    def holding_for_push(self) -> bool:
        """Whether D_T,1 is held back: a push is under way, for less than T_hold."""
        hold = self.config.rsg.push_hold_time
        return hold > 0.0 and 0.0 < self.push_duration < hold

    def _timing_jump(self, xi1: np.ndarray, level: float) -> bool:
        """D_T, evaluated ``step_reaction_time`` ahead (only for ``rsg``)."""
        lead = self.config.rsg.step_reaction_time
        if not self.config.adjusts_timing or not self._ready_to_step(lead):
            return False
        gamma, mu1 = self.design.threshold, self.config.rsg.step_decrease_margin
        d_t1 = level >= gamma and level - self.lyapunov_at_step >= -gamma + mu1
        d_t1 = d_t1 and not self.holding_for_push()
        d_t2 = self.sigma * xi1[1] - self.config.constraints.half_width >= 0.0
        return bool(d_t1 or d_t2)

    def _timing_jump_delay(self, nominal_wait: float | None = None) -> float:
        """Time [s] from now to the touchdown of a timing jump decided now.

        ``step_reaction_time`` from now and not before s~ = T_DSP + T_SP, but never
        later than the reference's own (gated) step: a timing jump brings a step
        forward, it does not postpone one that is due sooner.
        """
        reaction = self.config.rsg.step_reaction_time
        delay = max(self.earliest_step - self.time_since_step, reaction, 0.0)
        wait = self._nominal_wait() if nominal_wait is None else nominal_wait
        return min(delay, wait)

    def _schedule(self, xi1: np.ndarray, level: float, touchdown: bool) -> bool:
        """Decide a timing jump (D_T) if none is scheduled; True when it is due now, or
        when the swing sole has just landed within ``touchdown_window`` of it and the
        jump brings the step forward (a nominal step's time is the reference's jump,
        so it waits for it)."""
        if self.scheduled_step is None and self._timing_jump(xi1, level):
            self.scheduled_step = self.time_since_step + self._timing_jump_delay()
        due = self.scheduled_step
        if due is None:
            return False
        left = due - self.time_since_step
        window = self.config.rsg.touchdown_window
        if touchdown and left <= window + 1e-9 and left < self._nominal_wait() - 1e-9:
            return True
        return left <= 1e-9

    def predict(self, xi: np.ndarray, delay: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """State, DCM error and xi1* predicted ``delay`` [s] ahead, before any jump.

        The LIPM flows under the current (filtered) input, the reference freely (13a).
        """
        if delay <= 0.0:
            return xi, self.dcm_error(xi), self.reference.xi1.copy()
        zmp = self.filter_state[:2] + self.window_offset()
        hdot = self.filter_state[2:] + self.compensation_state
        com, velocity = integrate_lipm(self.model, xi[:2], xi[2:], zmp, hdot, np.zeros(2), delay)
        predicted = np.concatenate([com, velocity])
        reference = flow_autonomous(self.omega, self.reference.state, delay)
        error = dcm(self.omega, predicted) - dcm(self.omega, reference)
        return predicted, error, reference[:2].copy()

    def _step_location(
        self,
        xi: np.ndarray,
        error: np.ndarray,
        level: float,
        solver: str,
        reference_xi1: np.ndarray | None = None,
    ) -> tuple[np.ndarray, bool, bool]:
        """u_d of the output map H_nu; returns (u_d, from_qp, qp_feasible).

        The QP is used while V_u >= gamma_v, and for a scheduled timing jump with
        ``qp_at_timing_jump`` (the paper's H_nu: 2 xi1* below gamma_v); ``xi`` is the
        state (c_H - o_H, cdot_H) at the step and ``reference_xi1`` xi1* then (default:
        now).
        """
        timing_jump = self.scheduled_step is not None and self.config.rsg.qp_at_timing_jump
        use_qp = level >= self.design.threshold or timing_jump
        if self.config.adjusts_location and use_qp:
            problem = build_step_qp(
                self.design.matrix,
                error,
                xi[:2],
                self.reference.xi1 if reference_xi1 is None else reference_xi1,
                self.sigma,
                self.config.constraints,
                self.config.rsg,
                dcm=dcm(self.omega, xi),
            )
            solution = solve_step_qp(problem, solver)
            return solution.step, True, solution.feasible
        return self.reference.nominal_step(), False, True

    def _jump_step(
        self, timing: bool, xi: np.ndarray, error: np.ndarray, level: float
    ) -> tuple[np.ndarray, bool, bool]:
        """u_d of a jump due now; returns (u_d, from_qp, qp_feasible)."""
        if self.announced is not None:
            # The swing foot was sent to the foothold announced last tick: it lands there
            # (a nominal step's sole is on the ground by now).
            foothold, from_qp, scheduled = self.announced
            if timing and scheduled:
                return foothold - self.stance, True, True
            if not timing and self.config.rsg.announced_foothold:
                return foothold - self.stance, from_qp, True
        return self._step_location(xi, error, level, self.qp_solver)

    def _nominal_wait(self) -> float:
        """Time [s] until the gated D_S: the reference's jump, not before s~ = T_DSP + T_SP."""
        ready = self.earliest_step - self.time_since_step
        wait = max(self.reference.time_to_nominal_jump(), ready, 0.0)
        return wait if math.isfinite(wait) else max(ready, 0.0)

    def _preview(
        self,
        xi: np.ndarray,
        nominal_wait: float | None = None,
        error: np.ndarray | None = None,
    ) -> tuple[np.ndarray, bool]:
        """Where the next step would land [m], re-planned at each tick, and whether the
        QP (27) places it.

        With a jump held for the touchdown it is that jump's foothold; with a timing
        jump scheduled it is the QP (27) at the state predicted at its touchdown; with
        V_u >= gamma_v the QP at the state predicted when the step is expected
        (:meth:`predicted_step_time`; at the current state without
        ``preview_at_touchdown``); otherwise the nominal step 2 xi1* at the reference's
        next (gated) nominal jump.

        Args:
            xi: (c_H - o_H, cdot_H) now.
            nominal_wait: Time to the gated D_S [s], if already known.
            error: e_u of ``xi``, if already known [m].
        """
        if self.held_step is not None:
            return self.held_step.foothold.copy(), self.held_step.from_qp
        error = self.dcm_error(xi) if error is None else error
        level = self.design.level(error)
        wait = self._nominal_wait() if nominal_wait is None else nominal_wait
        scheduled = self.scheduled_step is not None
        if self.config.adjusts_location and (scheduled or level >= self.design.threshold):
            # H_nu at the state predicted at the touchdown (now without preview_at_touchdown)
            delay = 0.0
            if self.scheduled_step is not None:
                delay = self.scheduled_step - self.time_since_step
            elif self.config.rsg.preview_at_touchdown:
                delay = self._timing_jump_delay(wait) if self.config.adjusts_timing else wait
            predicted, predicted_error, reference_xi1 = self.predict(xi, delay)
            step, from_qp, _ = self._step_location(
                predicted, predicted_error, level, "exact", reference_xi1
            )
            return self.stance + step, from_qp
        future = flow_autonomous(self.omega, self.reference.state, wait)
        return self.stance + 2.0 * future[:2], False

    def predicted_step_time(
        self, time: float, level: float, nominal_wait: float | None = None
    ) -> float:
        """When the next step is expected [s], re-planned at each tick.

        A scheduled timing jump comes at its scheduled time. While V_u >= gamma_v
        and timing adjustment is on, D_T,1 fires as soon as the swing foot can land
        (s~ = T_DSP + T_SP, and ``step_reaction_time`` from now) or now if that is
        past, and not after the reference's step; otherwise the step comes when the
        reference reaches D_S.
        """
        if self.held_step is not None:
            return time
        if self.scheduled_step is not None:
            return time + max(self.scheduled_step - self.time_since_step, 0.0)
        if self.config.adjusts_timing and level >= self.design.threshold:
            return time + self._timing_jump_delay(nominal_wait)
        return time + (self._nominal_wait() if nominal_wait is None else nominal_wait)

    # ------------------------------------------------------------ one tick
    def update(self, measured: MeasuredState, period: float) -> PlannerOutput:
        """Run one control tick: jump if (chi, eta) is in D, then flow for ``period``.

        Args:
            measured: CoM position and velocity at this tick.
            period: Control period [s] over which the output is applied.

        Returns:
            The command for the next ``period`` and what the planner knows now.
        """
        com = np.asarray(measured.com_position, dtype=float)
        if measured.stance_sole is not None and not self._in_double_support():
            self._reanchor_target = np.asarray(measured.stance_sole, dtype=float).copy()
        if self._reanchor_target is not None:
            self._reanchor(self._reanchor_target, period)
        xi = np.concatenate([com - self.stance, np.asarray(measured.com_velocity, dtype=float)])
        self._estimate_push(com + xi[2:] / self.omega)
        error = self.dcm_error(xi)
        level = self.design.level(error)

        step_event: StepEvent | None = None
        qp_infeasible = False
        if measured.swing_contact is False:
            self._swing_lifted = True
        touchdown = bool(measured.swing_contact) and self._swing_lifted
        timing = self._schedule(xi[:2], level, touchdown)
        # A scheduled timing jump keeps its time: the swing foot is on its way there.
        nominal = (
            self.scheduled_step is None
            and self._ready_to_step()
            and self.reference.in_nominal_jump_set()
        )
        if self.held_step is None and (timing or nominal):
            u_d, from_qp, feasible = self._jump_step(timing, xi, error, level)
            qp_infeasible = not feasible
            if measured.swing_contact is False:
                # A late landing: the jump waits for the touchdown, onto this foothold.
                self.held_step = HeldStep(self.stance + u_d, nominal and not timing, from_qp)
        elif self.held_step is not None and measured.swing_contact is not False:
            held, self.held_step = self.held_step, None
            nominal, timing = held.nominal, not held.nominal
            u_d, from_qp = held.foothold - self.stance, held.from_qp
        if self.held_step is not None:
            timing = nominal = False
        if timing or nominal:
            window_now = self.stance + self.window_offset()
            self.lyapunov_at_step = self.design.level(error - u_d + 2.0 * self.reference.xi1)
            self._reanchor_target = None
            self.previous = self.stance.copy()
            self.stance = self.stance + u_d
            self.sigma = -self.sigma
            self.window_start = window_now
            self.time_since_step = 0.0
            self.scheduled_step = None
            self._swing_lifted = False
            self.reference.jump()
            step_event = StepEvent(
                time=measured.time,
                foot=_foot_of(self.sigma),
                position=self.stance.copy(),
                timing_adjusted=bool(timing and not nominal),
                location_adjusted=from_qp,
                lyapunov_before=level,
                lyapunov_after=self.lyapunov_at_step,
            )
            xi = np.concatenate([com - self.stance, xi[2:]])
            error = self.dcm_error(xi)
            level = self.design.level(error)

        nominal_wait = self._nominal_wait()
        window_offset = self.window_offset()
        zmp_offset = self.filter_state[:2].copy()
        angular_momentum_rate = self.filter_state[2:] + self.compensation_state
        next_step, next_from_qp = self._preview(xi, nominal_wait, error)
        output = PlannerOutput(
            time=measured.time,
            zmp=self.stance + zmp_offset + window_offset,
            zmp_offset=zmp_offset,
            window_center=self.stance + window_offset,
            angular_momentum_rate=angular_momentum_rate,
            angular_momentum_rate_feedback=self.filter_state[2:].copy(),
            stance=Foothold(_foot_of(self.sigma), self.stance.copy()),
            previous_stance=Foothold(_foot_of(-self.sigma), self.previous.copy()),
            next_step=Foothold(_foot_of(-self.sigma), next_step),
            next_step_time=self.predicted_step_time(measured.time, level, nominal_wait),
            time_since_step=self.time_since_step,
            double_support=self._in_double_support(),
            dcm_error=error,
            lyapunov=level,
            lyapunov_at_step=self.lyapunov_at_step,
            com_reference=self.stance + self.reference.xi1,
            step=step_event,
            qp_infeasible=qp_infeasible,
        )
        self._last_cmp = output.zmp - H_MATRIX @ angular_momentum_rate / (
            self.model.mass * self.model.gravity
        )
        self._last_period = period
        # The swing foot is sent to the announced foothold: the next step lands there.
        scheduled = self.scheduled_step is not None
        self.announced = (output.next_step.position.copy(), next_from_qp, scheduled)
        self._flow(error, window_offset, period)
        return output

    def _reanchor(self, target: np.ndarray, period: float) -> None:
        """Move o_H towards the measured stance sole ``target`` (``reanchor_time``: at
        once if 0); the re-anchoring ends when o_H is there."""
        ramp = self.config.rsg.reanchor_time
        fraction = 1.0 if ramp <= 0.0 else min(period / ramp, 1.0)
        self.stance = self.stance + fraction * (target - self.stance)
        if fraction >= 1.0 or float(np.linalg.norm(target - self.stance)) < 1e-4:
            self.stance = target.copy()
            self._reanchor_target = None

    def _flow(self, error: np.ndarray, window_offset: np.ndarray, period: float) -> None:
        """Flow of nu and of the reference model over ``period`` [s]."""
        compensation = self.model.mass * self.model.gravity * (H_INVERSE @ window_offset)
        target = np.clip(self.design.gain @ error, self._input_min, self._input_max)
        if period != self._filter_period:
            self._filter_period = period
            self._filter_gain = 1.0 - math.exp(-period / self.config.rsg.filter_time_constant)
        self.filter_state += self._filter_gain * (target - self.filter_state)
        self.compensation_state += self._filter_gain * (compensation - self.compensation_state)
        self.time_since_step += period
        self.reference.flow(period)
