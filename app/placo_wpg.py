"""The ``placo-wpg`` baseline: placo's walk pattern generator with ``update_supports``.

NOT BUILT YET. ``AVAILABLE`` is False and ``rsg sweep`` refuses ``placo-wpg`` with a
message saying so; ``rsg bench`` leaves its column empty.

What it is meant to be (placo 0.10.2, ``placo.pyi``): the baseline a placo user would
pick, driving the same G1 through the same IK (:class:`kinematics.whole_body_ik.
WholeBodyIK`) and the same PyBullet backend as the RSG:

- a ``placo.HumanoidParameters`` filled from the robot description: single/double
  support durations (T_SSP, T_DSP), ``walk_com_height`` = c_z, ``feet_spacing`` =
  L_y, ``foot_length``/``foot_width`` and ``zmp_margin`` from the sole, and the step
  limits ``walk_max_dx_forward``/``walk_max_dx_backward``/``walk_max_dy`` from
  u_d^M, u_d^m; a ``placo.HumanoidRobot`` on the derived URDF
  (:func:`robots.urdf_cache.derived_urdf`) for ``WalkPatternGenerator(robot, params)``;
- footsteps from ``FootstepsPlannerRepetitive.configure(L_x, 0, 0, n)`` and
  ``make_supports``, planned once with ``plan(supports, com_world, t0)``;
- every control tick: ``supports = wpg.update_supports(t, supports, measured_dcm)``
  (its QP on the current swing's duration and target, fed the measured DCM), then
  ``replan(supports, trajectory, t)`` when ``can_replan_supports``; the tick's
  command is read from the trajectory: ``get_p_world_ZMP(t)`` as the ZMP, the
  support side and the footholds from ``get_support``/``get_next_support`` (their
  ``footstep_frame`` positions), and the support's end time as
  ``PlannerOutput.extra["planned_step_time"]`` for the swing foot;
- packed into :class:`planner.types.PlannerOutput` (hdot = 0, ``step`` set at the
  tick where the support side changes) by an object with the generator's
  ``reset``/``update``/``design`` interface, swapped into
  :class:`app.runner.ClosedLoop` in place of the RSG, so the PyBullet backend runs
  it unchanged; recovery on the full robot is "no fall" for every controller.
"""

from __future__ import annotations

from planner.exceptions import RsgError

AVAILABLE = False
REASON = (
    "placo-wpg is not built yet (see app/placo_wpg.py for its design); "
    "sweep rsg, fixed-timing and no-step on --model pybullet meanwhile"
)


def build_placo_wpg_backend(robot: str):  # noqa: ANN201
    """The PyBullet backend driven by the placo-wpg baseline (not built yet).

    Raises:
        RsgError: Always, with :data:`REASON`.
    """
    raise RsgError(REASON)
