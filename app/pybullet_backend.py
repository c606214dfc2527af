"""Full-humanoid backend: the planner's commands realised on a robot in PyBullet.

Each control tick (``control_period``, several physics steps of the robot's
``physics_time_step``: 2 ms on G1, 1 ms on Talos):

1. CoM plan: a CoM reference state (c_ref, v_ref) is integrated over the tick
   with the LIPM driven by the commanded ZMP and rate of angular momentum; before
   that it is pulled toward the MEASURED state by ``com_reference_blend`` (0:
   open-loop reference, 1: integrate from the measurement). The IK CoM target is
   c_ref (+ optional K_p/K_v corrections and a LIPM look-ahead). Measured on G1:
   integrating from the measurement every tick (blend 1) turns the position
   controller into a pure inverted pendulum: with a constant ZMP command it
   drifts and falls within 1 s; blend 0 stands indefinitely.
2. Feet: the stance sole is put flat at ``command.stance.position``; the swing
   sole follows :class:`SwingFootTrajectory` toward ``command.next_step.position``
   with the planner's timing: touchdown ``touchdown_lead`` before
   ``command.next_step_time`` (absolute [s], re-planned every tick). The
   planner's jump (``command.step``) happens at its planned time: the swing foot
   becomes the stance foot at the step position at once, and the old stance foot
   is raised by ``transfer_lift`` for the rest of the double support.
3. Whole-body IK (placo) -> joint position targets (velocity feed-forward from
   the difference of successive solutions) -> PyBullet POSITION_CONTROL.
4. Physics steps, the push force being applied on the pelvis at every step.
5. Measurement: whole-body CoM and its velocity from the link states.

Why (measured on G1, 33 kg, sole 17 cm x 5 cm, ZMP window +-2 cm laterally):

* Weight transfer. The joints track the IK to < 0.5 deg, so in double support the
  load split between the feet is set by sub-millimetre errors: a foot commanded
  exactly onto the ground touches but carries nothing. Landing at the planner's
  step left the CoP on the old foot for ~50 ms while the plan (``"full"``: the
  planner's hdot compensation puts the effective ZMP on the new foot at the step)
  already decelerated the CoM: 3-4 cm of DCM error per step. Landing earlier
  (``touchdown_lead``) or pressing the landing foot into the ground
  (``touchdown_depth``) loads it BEFORE the step while the plan still has the
  ZMP on the old foot, and makes the robot hop. Raising the old foot by 3 mm
  right after the step (``transfer_lift``) moves the weight at the step, as the
  planner's model assumes: DCM error through the first double support < 1 cm.
* Angular momentum of the motion. The measured CoP is the LIPM's
  c - c''/omega^2 plus S Ldot/(m g), where Ldot is the centroidal angular
  momentum rate of the IK motion itself (``WholeBodyIK.angular_momentum``, the
  legs and the torso: up to 15 N m at swing lift-off, i.e. a 4-5 cm CoP shift,
  predicted by the IK model to within a few mm). With a CoM plan that ignores it
  the CoP leaves the sole and the stance foot rolls over its edge.
  ``momentum_compensation`` integrates the CoM plan with that Ldot and with the
  CoP that keeps the commanded pivot (ZMP - S hdot/(m g)), clipped to the stance
  sole (minus ``cop_margin``): the CoP stays on the sole, and only what the sole
  cannot take moves the CoM away from the planner's LIPM (the planner sees it as
  DCM error and corrects it). The clip also handles the planner's own double
  support: its compensation m g H^-1 r~ is low-pass filtered (theta = 0.05 s),
  so its effective pivot starts at the old foot and overshoots the new sole by
  up to 8 cm at the end of the double support.
* Touchdown timing. The planner detects its jump at the first tick after the
  predicted ``next_step_time`` (nominal steps come every 0.82 s, not 0.8 s), and a
  sole landing with zero vertical speed is within 1 mm of the ground for its last
  ~40 ms. A foot that touches before the jump takes the whole weight at once
  (the stance foot's force drops to 0): 2-3 cm of DCM error at the 2nd and 3rd
  steps of a nominal walk. ``landing_delay`` (one tick) and ``touchdown_speed``
  address it; they help the ``no-step`` walk (3.1 s -> 4.7 s), as does
  ``smooth_swing`` (minimum-jerk swing, smaller Ldot at lift-off: 3.1 s -> 5.2 s),
  but not the RSG (4.0-4.6 s against 5.7 s), so they are off by default.
* Landing. Three measured mechanisms made the walk's DCM error jump at landings,
  each above the RSG's threshold (gamma_v is a DCM error of ~1.1 cm on G1: window
  2 cm / gain 1.85 with the 3 N m hdot bound of then), so each caused adjusted steps
  that stirred new errors:
  (1) the planner's double-support pivot overshoots the new sole by |step| theta /
  T_DSP (theta = 0.05 s: up to 8 cm), which the sole cannot realise: G1 uses
  theta = 0.01 s (``RobotDescription.filter_time_constant``); (2) the feet landed
  on the planner's announced ``next_step`` while its jump puts o_H (4.5, 7) mm
  further, and the offsets added up from step to step (``landing_correction``,
  ``app/pybullet_landing.py``); (3) a sole commanded down to the ground touched
  it 30-40 ms before the step and took the whole weight with an impact (up to
  940 N): ``landing_clearance`` keeps it 2 mm up until the step. With the three,
  the 20 s walk has no adjusted step (max V_u 0.69 gamma_v) for rsg,
  fixed-timing and no-step.
* Foothold drift (``foothold_feedback``). The IK places the swing foot relative
  to the stance foot it believes is on the planner's foothold; a real stance foot
  that landed off it shifts the next landing by as much, and the errors add up
  (G1: ~0.8 mm per step, 2 cm after 30 s, a 60 s walk fell at 31 s). Measuring
  the stance sole at the end of the double support and aiming the swing foot
  against that offset: the 60 s walk lasts 46 s.
* Measured CoP (``cop_feedback``, ``cop_admittance``). Joint position control
  realises the CoM plan's CoP only approximately: laterally it was biased (0.71 cm
  rms, and the 60 s walk still fell at 46 s), and after a push it went bang-bang
  between heel and toe while the plan asked for the middle, which kept the robot in
  a cycle of adjusted steps. Two loops on the CoP measured from the contact forces
  (:meth:`SimulatedRobot.foot_pressure`): the stance ankle's targets move it onto the
  plan's (:mod:`app.pybullet_ankle`; G1: 180 s walk, no adjusted step), and the CoM
  plan gives way to the difference (CoM admittance,
  :func:`app.pybullet_com_plan.cop_admittance_zmp`; G1: one adjusted step after
  8 N s forward, then nominal walking).
* Adjusted steps. With the paper's instantaneous jump the RSG stepped 0.05 s
  after the paper-fig6 push to a foothold 7.8 cm from a swing sole still 1.8 cm up,
  and the IK's hard stance task dragged the foot there within a tick. G1 now uses
  the planner's ``step_reaction_time`` (0.2 s): the touchdown is scheduled when D_T
  fires and the foothold is the QP at the predicted touchdown state; the swing sole
  follows it with a bounded acceleration (``swing_acceleration``) and does not come
  down while still far from it (``swing_descent_slope``); the bound yields to the
  landing time (``swing_land_on_time``), else a foothold still moving late in the
  reaction time left the sole 4-5 cm off and 2 cm up at the step, and the IK slammed
  it down at ~2 m/s (the robot left the ground for 70 ms). Remaining limitation,
  measured: right after an adjusted step the DCM error jumps by 2-5 cm within
  50 ms (landing impact, bounce, CoP on a sole edge), which G1's +-2 cm lateral
  ZMP window cannot absorb, so a second and third adjusted step follow and large
  lateral pushes still topple it (README, "The full robot").
* Swing-sole position feedback (``swing_feedback``, off by default). The IK's model is
  never reset from measurements, and after a push G1's position-controlled joints bend
  under the body's tilt: the real swing sole lagged the IK's by up to 7 cm and landed
  6 cm behind its foothold (10 N s at 135 deg). The option moves the IK's swing target
  against the measured offset (relative to the stance soles, low-passed, bounded at
  5 cm); the real sole then follows its trajectory within 3 cm, but recovery over the
  10 N s pushes was not better (README, "Swing-sole position feedback").
* Swing-sole height and tilt feedback (``swing_level_feedback``, off by default). When
  a push rolls the stance foot onto an edge the whole robot leans, and the swing sole,
  placed by the IK relative to a flat stance foot, comes down early and tilted: after
  the first ``paper-fig6`` push it touched down 30 ms before the step, on an edge,
  with 1.9 kN, and was dragged 4 cm to the re-solved foothold. The option raises the
  IK's swing target by how far the real sole's lowest corner hangs below the IK's and
  tilts it against the real sole's roll and pitch (low-passed like ``swing_feedback``):
  under 40 N toward the swing side the sole then stays within 7 mm of its profile and
  1.5 deg of flat, where it came down 29 mm early and 6.6 deg tilted. On the 64 pushes
  at phases 0.5625 and 0.25 a gain of 0.5 gave 51 not fallen against 47 with point
  contacts under the soles, but 50 against 52 with G1's torsional sole friction, which
  is the default (README, "Swing-sole height and tilt feedback").
"""

from __future__ import annotations

import time as clock
from collections import defaultdict
from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from app.backend import FallStatus, InitialCondition
from app.physics_log import PhysicsLog
from app.pybullet_ankle import MIN_LOAD_FRACTION, AnkleCopFeedback
from app.pybullet_com_plan import cop_admittance_zmp, momentum_aware_pivot
from app.pybullet_landing import LandingCorrection
from app.pybullet_robot import GRAVITY, SimulatedRobot
from kinematics.swing_foot import SwingFootTrajectory, SwingTiming
from kinematics.upper_body import UpperBodyFlywheel
from kinematics.whole_body_ik import IkInfeasibleError, WholeBodyIK, sole_pose
from planner.exceptions import ParameterError, RsgError
from planner.hybrid_lipm import integrate_lipm
from planner.parameters import LipmModel, Range
from planner.types import Foot, MeasuredState, PlannerOutput, Vector2, other_foot
from robots import get_robot
from robots.description import RobotDescription
from robots.urdf_cache import locked_angles

INITIAL_VELOCITY_HORIZON = 0.01  # [s] finite difference used to start with a CoM velocity
SWING_FEEDBACK_LIMIT = 0.05  # bound on the swing sole's measured offset [m]
SWING_TILT_LIMIT = 0.2  # bound on the swing sole's measured roll and pitch error [rad]
CONTACT_LOAD_FRACTION = 0.3  # swing-sole load [-, of m g] that counts as a touchdown
CONTACT_WINDOW = 0.08  # [s] before the planned step in which a touchdown switches the stance
DEFAULT_CONTROL_PERIOD = 0.01  # [s]


#: Numeric options of :class:`PyBulletBackend` and the range in which each means
#: something on a humanoid (see the constructor's docstring for what each does).
OPTION_RANGES: dict[str, Range] = {
    # G1 walks 10 s nominally at 4 to 12 ms; it fell at 14, 16 and 20 ms (docs/notes).
    "control_period": Range(0.002, 0.012, "s"),
    "com_lookahead": Range(0.0, 0.5, "s"),
    "com_reference_blend": Range(0.0, 1.0),
    "arrival_lead": Range(0.0, 0.5, "s"),
    "touchdown_lead": Range(0.0, 0.2, "s"),
    "touchdown_depth": Range(0.0, 0.02, "m"),
    "transfer_lift": Range(0.0, 0.02, "m"),
    "transfer_ramp": Range(0.0, 1.0, "s", low_open=True),
    "momentum_compensation": Range(0.0, 1.0),
    "momentum_filter": Range(0.0, 1.0, "s", low_open=True),
    "touchdown_speed": Range(0.0, 0.5, "m/s"),
    "landing_delay": Range(0.0, 0.05, "s"),
    "landing_clearance": Range(0.0, 0.01, "m"),
    "swing_acceleration": Range(0.0, 1000.0, "m/s^2", low_open=True),
    "swing_descent_slope": Range(0.0, 10.0),
    "cop_admittance": Range(0.0, 2.0),
    "upper_body_momentum": Range(0.0, 10.0, "N m s"),
    "upper_body_return_time": Range(0.0, 10.0, "s", low_open=True),
    "upper_body_cancel": Range(0.0, 1.0),
    "reanchor_min": Range(0.0, 0.1, "m"),
    "swing_feedback": Range(0.0, 1.0),
    "swing_feedback_filter": Range(0.0, 1.0, "s", low_open=True),
    "swing_level_feedback": Range(0.0, 1.0),
}
#: Options given as one number or a pair (forward, lateral): the range of each.
PAIR_RANGES: dict[str, tuple[Range, Range]] = {
    "com_tracking_gains": (Range(0.0, 10.0), Range(0.0, 1.0, "s")),
    "landing_correction": (Range(0.0, 1.0), Range(0.0, 1.0)),
    "cop_feedback": (Range(0.0, 50.0, "rad/(m s)"), Range(0.0, 50.0, "rad/(m s)")),
}
OPTION_CHOICES = {
    "plan_angular_momentum": ("full", "feedback", "none"),
    "stance_switch": ("planned", "contact"),
}


def check_backend_options(description: RobotDescription, options: Mapping[str, object]) -> None:
    """Check the backend ``options`` (keyword arguments of :class:`PyBulletBackend`) for
    ``description``, without loading anything: each number in its range, each word
    among its choices, each flag a bool, and the control period a whole multiple of the
    robot's physics step.

    Raises:
        ParameterError: Naming the option, its value and what is allowed.
    """
    for name, value in options.items():
        if name == "cop_margin" or (value is None and name == "swing_acceleration"):
            continue  # cop_margin: against the sole, below
        if name in OPTION_RANGES:
            OPTION_RANGES[name].check(name, value)
        elif name in PAIR_RANGES:
            ranges = PAIR_RANGES[name]
            pair = (value, value) if isinstance(value, int | float) else value
            parts: tuple = tuple(pair) if isinstance(pair, tuple | list) else ()
            if len(parts) != 2 or not all(
                r.contains(v) for r, v in zip(ranges, parts, strict=True)
            ):
                allowed = " and ".join(r.describe().removeprefix("a number ") for r in ranges)
                raise ParameterError(name, value, f"one number or a pair a,b: {allowed}")
        elif name in OPTION_CHOICES:
            if value not in OPTION_CHOICES[name]:
                raise ParameterError(name, value, " or ".join(OPTION_CHOICES[name]))
        elif not isinstance(value, bool):
            raise ParameterError(name, value, "true or false")
    physics_step = description.physics_time_step
    control_period = float(options.get("control_period", DEFAULT_CONTROL_PERIOD))  # type: ignore[arg-type]
    substeps = round(control_period / physics_step)
    if substeps < 1 or abs(substeps * physics_step - control_period) > 1e-9:
        raise ParameterError(
            "control_period/physics_time_step",
            (control_period, physics_step),
            "a control period that is a whole multiple of the physics step [s]",
        )
    cop_margin = options.get("cop_margin", 0.01)
    half_width = description.sole.half_width
    if not (isinstance(cop_margin, int | float) and 0.0 <= cop_margin < half_width):
        raise ParameterError("cop_margin", cop_margin, f"a number in [0, {half_width:g}) m")
    momentum = options.get("upper_body_momentum", 0.0)
    if momentum and not description.upper_body_joints:  # type: ignore[truthy-bool]
        raise ParameterError(
            "upper_body_momentum",
            momentum,
            f"0 for {description.name}, whose description lists no upper_body_joints",
        )


class PyBulletBackend:
    """A full humanoid in PyBullet implementing :class:`app.backend.Backend`.

    Attributes:
        name: ``"pybullet"``.
        mass: Total mass measured in PyBullet [kg].
        com_height: Nominal CoM height [m] (the planner's c_z).
        control_period: Duration of one :meth:`step` [s].
        timing: The planner's step timing used by the swing foot.
    """

    name = "pybullet"

    def __init__(
        self,
        robot: str | RobotDescription = "g1",
        control_period: float = DEFAULT_CONTROL_PERIOD,
        timing: SwingTiming | None = None,
        com_lookahead: float = 0.0,
        com_reference_blend: float = 0.0,
        com_tracking_gains: tuple[float, float] = (0.0, 0.0),
        arrival_lead: float = 0.1,
        use_angular_momentum: bool = False,
        interpolate_targets: bool = True,
        touchdown_lead: float = 0.0,
        touchdown_depth: float = 0.0,
        plan_angular_momentum: str = "full",
        transfer_lift: float = 0.0,
        transfer_ramp: float = 0.02,
        momentum_compensation: float = 0.0,
        momentum_filter: float = 0.02,
        cop_margin: float = 0.01,
        touchdown_speed: float = 0.0,
        landing_delay: float = 0.0,
        smooth_swing: bool = False,
        landing_correction: float | tuple[float, float] = 0.0,
        landing_clearance: float = 0.0,
        swing_acceleration: float | None = None,
        swing_descent_slope: float = 0.0,
        swing_land_on_time: bool = False,
        foothold_feedback: bool = False,
        cop_feedback: float | tuple[float, float] = 0.0,
        cop_admittance: float = 0.0,
        stance_switch: str = "planned",
        upper_body_momentum: float = 0.0,
        upper_body_return_time: float = 0.5,
        upper_body_cancel: float = 0.0,
        yaw_feedback: bool = False,
        reanchor_stance: bool = False,
        reanchor_min: float = 0.0,
        swing_feedback: float = 0.0,
        swing_feedback_filter: float = 0.03,
        swing_level_feedback: float = 0.0,
    ) -> None:
        """Load the robot.

        Args:
            robot: Registry name or description of the robot.
            control_period: Control period [s], a multiple of the robot's physics step.
            timing: Step timing of the planner (T_DSP, T_SP, nominal step time).
            com_lookahead: Extra horizon [s] by which the IK CoM target leads the
                CoM reference (compensates the position-control lag).
            com_reference_blend: Fraction [-] of the gap between the CoM reference
                and the measured CoM state closed at each tick (0: open-loop
                reference, 1: integrate from the measurement).
            com_tracking_gains: (K_p [-], K_v [s]): the IK CoM target is the
                reference plus K_p (reference - measured position) plus
                K_v (reference - measured velocity).
            arrival_lead: Time before touchdown at which the swing foot is above
                its target [s].
            use_angular_momentum: Add the IK's centroidal angular momentum task with
                a zero target (the upper body damps the legs' angular momentum).
                The commanded hdot enters only the CoM plan (as the CMP shift);
                it is not realised by an upper-body motion.
            interpolate_targets: Interpolate the joint targets linearly over the
                physics steps of a tick (else hold the tick's final target).
            touchdown_lead: The swing foot lands this long before the planner's
                step time [s].
            touchdown_depth: Once down, the swing sole target is this far below the
                ground [m], so the foot is loaded before it becomes the stance foot.
            plan_angular_momentum: Which hdot enters the CoM plan: ``"full"`` (the
                planner's hdot, with its double-support compensation: the plan's
                effective ZMP jumps to the new foot at the step), ``"feedback"``
                (without it: the plan's ZMP moves along the moving window from the
                old foot to the new one over T_DSP, as the feet can realise) or
                ``"none"``.
            transfer_lift: After the planner's step, the old stance foot is raised
                this far [m] (ramped over ``transfer_ramp`` [s]) for the rest of
                the double support, so the weight moves onto the new foot at once.
            transfer_ramp: Duration of that ramp [s].
            momentum_compensation: Fraction [-] of the IK motion's own centroidal
                angular momentum rate taken into the CoM plan (see the module notes).
            momentum_filter: Time constant of the low-pass filter on that rate [s].
            touchdown_speed: Vertical speed of the swing sole at touchdown [m/s]
                (a foot landing at zero speed skims the ground, within 1 mm, for
                its last ~40 ms).
            smooth_swing: Minimum-jerk horizontal swing (zero acceleration at
                lift-off) instead of the cubic.
            landing_delay: Time the touchdown this long after the planner's
                predicted step time [s] (its jump comes one control tick after it).
            cop_margin: Distance [m] kept between the CoP the CoM plan asks for and
                the edges of the stance sole when ``momentum_compensation`` > 0.
            landing_correction: Gain [-] (or per axis: forward, outward) of
                :class:`app.pybullet_landing.LandingCorrection`: the swing foot
                aims where the planner's jump will put o_H.
            landing_clearance: The swing sole never goes below this height [m];
                at the step the new stance sole target is lowered from it to the
                ground over ``transfer_ramp`` (a foot commanded onto the ground
                touches it early, see the module notes).
            swing_acceleration: Bound on the swing sole's horizontal
                acceleration when its target moves [m/s^2] (None: unbounded).
            swing_descent_slope: The swing sole stays at least this many metres
                up per metre still to go horizontally [-].
            swing_land_on_time: The acceleration bound yields to the landing time:
                the swing sole is above the foothold when the step is due.
            foothold_feedback: At the end of each double support, measure how far
                the stance sole stands from the planner's foothold and aim the swing
                foot that much the other way, so landing errors do not add up.
            cop_feedback: Gains (forward, lateral) [rad / (m s)] of
                :class:`app.pybullet_ankle.AnkleCopFeedback`: in single support the
                stance ankle's targets move the measured CoP onto the CoM plan's.
            cop_admittance: Gain A [-] of the CoM admittance
                (:func:`app.pybullet_com_plan.cop_admittance_zmp`): the CoM plan is
                integrated with its CoP moved by A (planned - measured CoP).
            stance_switch: ``"planned"``: the stance switches at the planner's jump
                (its planned step time); ``"contact"``: also when the swing sole
                carries :data:`CONTACT_LOAD_FRACTION` of the weight within
                :data:`CONTACT_WINDOW` of the planned step, the measured state then
                reports the sole's position as ``touchdown`` and the planner jumps
                onto it at once.
            upper_body_momentum: h_max [N m s]: the torso and the arms carry the
                band-passed part of the planner's feedback hdot, up to this much
                angular momentum (:class:`kinematics.upper_body.UpperBodyFlywheel`
                on the description's ``upper_body_joints``); 0: off, all of hdot
                is realised by the CoP as a CMP shift of the CoM plan.
            upper_body_return_time: T_r of that band-pass, and the time constant
                of the upper body's return to its posture [s].
            upper_body_cancel: Fraction [0, 1] of the high-passed angular momentum
                of the IK motion (the legs' swing) the upper body takes back.
            yaw_feedback: At the end of each double support, measure the stance
                sole's yaw against the IK's: the IK's targets (swing sole and CoM)
                are rotated by the difference about the stance foot, and the swing
                sole is turned so that it lands facing forward.
            reanchor_stance: At the end of each double support the measured stance
                sole goes to the planner (``MeasuredState.stance_sole``), which moves
                its stance foothold there; ``foothold_feedback`` then has nothing
                left to correct.
            reanchor_min: Only a sole standing further than this from the planner's
                foothold re-anchors it [m]; a nearer one is left to
                ``foothold_feedback``.
            swing_feedback: Gain [0, 1] of the swing sole's position feedback: in
                single support the IK's swing sole target moves against the measured
                offset of the real swing sole from the IK's (both relative to their
                stance soles), so the real foot, not the IK's, lands on the foothold.
            swing_feedback_filter: Time constant of the low-pass filter on that
                offset [s] (and on ``swing_level_feedback``'s).
            swing_level_feedback: Gain [0, 1] of the swing sole's height and tilt
                feedback: in single support the IK's swing sole target is raised by
                how far the real sole's lowest corner hangs below the IK's, and
                tilted against the real sole's roll and pitch relative to the IK's,
                so the real foot hovers at the swing profile's height and lands flat
                when the body leans (after a push the stance foot rolls onto an edge
                and the swing foot comes down early).
        """
        options = {k: v for k, v in locals().items() if k not in ("self", "robot", "timing")}
        self.description = robot if isinstance(robot, RobotDescription) else get_robot(robot)
        check_backend_options(self.description, options)
        # Welded in the physics: not measured, shown at the angle they are welded at.
        self._locked_angles = locked_angles(self.description)
        self.control_period = control_period
        self._substeps = round(control_period / self.description.physics_time_step)
        self.com_lookahead = com_lookahead
        self.com_reference_blend = com_reference_blend
        self.com_tracking_gains = com_tracking_gains
        self.interpolate_targets = interpolate_targets
        self.touchdown_lead = touchdown_lead
        self.plan_angular_momentum = plan_angular_momentum
        self.touchdown_depth = touchdown_depth
        self.transfer_lift = transfer_lift
        self.transfer_ramp = transfer_ramp
        self.momentum_compensation = momentum_compensation
        self.momentum_filter = momentum_filter
        self.cop_margin = cop_margin
        self._ik_momentum: NDArray[np.float64] | None = None
        self._ik_momentum_rate = np.zeros(2)
        self.landing = LandingCorrection(landing_correction)
        self.foothold_feedback = foothold_feedback
        self._stance_offset = np.zeros(2)  # measured stance sole - o_H [m]
        self.yaw_feedback = yaw_feedback
        self.reanchor_stance = reanchor_stance
        self.reanchor_min = reanchor_min
        self._report_stance = False
        self.swing_feedback = swing_feedback
        self.swing_feedback_filter = swing_feedback_filter
        self._swing_offset = np.zeros(2)  # real - IK swing sole, relative to stance [m]
        self.swing_level_feedback = swing_level_feedback
        self._swing_sag = 0.0  # IK - real lowest swing sole corner height [m]
        self._swing_tilt = np.zeros(2)  # real - IK swing sole roll, pitch [rad]
        self._frame_yaw = 0.0  # measured stance yaw - the IK's [rad]
        self._ik_yaw = {"left": 0.0, "right": 0.0}  # soles' yaw in the IK [rad]
        self.ankle = AnkleCopFeedback(cop_feedback)
        self.cop_admittance = cop_admittance
        self.stance_switch = stance_switch
        self._last_command: PlannerOutput | None = None
        #: Set to a :class:`app.physics_log.PhysicsLog` to record every physics step.
        self.physics_log: PhysicsLog | None = None
        self._plan_cop = np.zeros(2)  # CoP of the CoM plan over the last tick [m]
        self._pressure: dict[str, tuple[NDArray[np.float64], float]] = {}
        self.landing_clearance = landing_clearance
        self._com_reference = np.zeros(2)
        self._com_velocity_reference = np.zeros(2)
        self.timing = timing or SwingTiming()
        self.sim = SimulatedRobot(self.description)
        sole = self.description.sole
        self._sole_corners = np.array(  # in the sole frame [m], shape (4, 3)
            [
                [x, y, 0.0]
                for x in (sole.x_min, sole.x_max)
                for y in (-sole.half_width, sole.half_width)
            ]
        )
        self.ik = WholeBodyIK(
            self.description,
            use_angular_momentum=use_angular_momentum,
            upper_body=upper_body_momentum > 0.0,
        )
        self._ik_to_sim = [self.ik.joint_names.index(name) for name in self.sim.joint_names]
        self._ankle_joints = {foot: self._ankle_joint_names(foot) for foot in ("left", "right")}
        self._ankle_sim_index = {
            foot: [self.sim.joint_names.index(name) for name in names]
            for foot, names in self._ankle_joints.items()
        }
        self.flywheel: UpperBodyFlywheel | None = None
        if upper_body_momentum > 0.0:
            self.flywheel = UpperBodyFlywheel(
                self.ik.robot,
                self.ik.upper_body_joints,
                self.ik.upper_body_posture,
                return_time=upper_body_return_time,
                max_momentum=upper_body_momentum,
                cancel=upper_body_cancel,
            )
        self.mass = self.sim.mass
        self.com_height = self.description.com_height
        self._lipm = LipmModel(mass=self.mass, com_height=self.com_height)
        self.swing = SwingFootTrajectory(
            self.timing,
            apex_height=self.description.swing_height,
            arrival_lead=arrival_lead,
            touchdown_speed=touchdown_speed,
            smooth_horizontal=smooth_swing,
            max_acceleration=swing_acceleration,
            descent_slope=swing_descent_slope,
            land_on_time=swing_land_on_time,
        )
        self.landing_delay = landing_delay

        self.timers: dict[str, float] = defaultdict(float)
        self.ticks = 0
        self._stance: Foot = "left"
        self._joint_targets = np.zeros(len(self.sim.joint_names))
        self._measured: MeasuredState | None = None
        self._ik_failure: str | None = None

    # ------------------------------------------------------------------ reset
    def reset(self, initial: InitialCondition) -> MeasuredState:
        """Stand on both feet at the initial footholds with the initial CoM state."""
        if initial.stance.foot == initial.swing.foot:
            raise ParameterError("initial.swing.foot", initial.swing.foot, "the non-stance foot")
        soles: dict[str, NDArray[np.float64]] = {
            initial.stance.foot: _ground_pose(initial.stance.position),
            initial.swing.foot: _ground_pose(initial.swing.position),
        }
        com_xy = np.asarray(initial.com_position, float)
        com_velocity = np.asarray(initial.com_velocity, float)
        base0, q0 = self._ik_reset(soles, com_xy)
        base_velocity = np.zeros(3)
        base_angular_velocity = np.zeros(3)
        joint_velocity = np.zeros_like(q0)
        if np.any(com_velocity):
            h = INITIAL_VELOCITY_HORIZON
            q1 = self.ik.solve(com_xy + h * com_velocity, soles["left"], soles["right"], "both", h)
            base1 = self.ik.robot.get_T_world_fbase()
            base_velocity = (base1[:3, 3] - base0[:3, 3]) / h
            base_angular_velocity = (
                Rotation.from_matrix(base1[:3, :3] @ base0[:3, :3].T).as_rotvec() / h
            )
            joint_velocity = (q1 - q0) / h
            self._ik_reset(soles, com_xy)
        quaternion = Rotation.from_matrix(base0[:3, :3]).as_quat()
        self.sim.set_configuration(
            base0[:3, 3],
            quaternion,
            dict(zip(self.ik.joint_names, q0, strict=True)),
            base_velocity,
            base_angular_velocity,
            dict(zip(self.ik.joint_names, joint_velocity, strict=True)),
        )
        self.sim.time = 0.0
        self._joint_targets = q0[self._ik_to_sim]
        self.sim.set_joint_targets(self._joint_targets, joint_velocity[self._ik_to_sim])
        self._stance = initial.stance.foot
        self.swing.start(np.asarray(initial.swing.position, float))
        self.timers.clear()
        self.ticks = 0
        self._last_command = None
        self._measured = self._measure()
        self._com_reference = com_xy.copy()
        self._com_velocity_reference = com_velocity.copy()
        self._ik_momentum = None
        self._ik_momentum_rate = np.zeros(2)
        self.landing.reset()
        self._ik_failure = None
        self._stance_offset = np.zeros(2)
        self._frame_yaw = 0.0
        self._swing_offset = np.zeros(2)
        self._swing_sag = 0.0
        self._swing_tilt = np.zeros(2)
        self._ik_yaw = {"left": 0.0, "right": 0.0}
        self.ankle.reset()
        if self.flywheel is not None:
            self.flywheel.reset()
        self._plan_cop = np.asarray(initial.com_position, float).copy()
        return self._measured

    def _ik_reset(
        self, soles: Mapping[str, NDArray[np.float64]], com_xy: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        q = self.ik.reset(soles["left"], soles["right"], com_xy)
        return np.asarray(self.ik.robot.get_T_world_fbase(), float).copy(), q

    # ------------------------------------------------------------------- step
    def step(self, command: PlannerOutput, push_force: Vector2) -> MeasuredState:
        """Realise ``command`` for one control period with ``push_force`` [N] on the pelvis."""
        if self._measured is None:
            raise ParameterError("backend", "not reset", "reset() before step()")
        start = clock.perf_counter()
        dt = self.control_period
        stance: Foot = command.stance.foot
        swing_foot = other_foot(stance)
        if stance != self._stance:
            # The planner stepped: the old stance foot lifts off from where it stood.
            self.swing.start(np.asarray(command.previous_stance.position, float))
            self._stance = stance
            self._swing_offset = np.zeros(2)
            self._swing_sag = 0.0
            self._swing_tilt = np.zeros(2)
        com_target = self._advance_com_reference(command)
        foothold = np.asarray(command.stance.position, float)
        if self.yaw_feedback:
            com_target = foothold + _rotate(com_target - foothold, -self._frame_yaw)
        time_since_step = command.time_since_step + dt
        # Optional touchdown before the planner's step (``touchdown_lead``); G1
        # uses 0 and unloads the old foot after the step instead (transfer_lift).
        # The planner detects its jump at the first tick after the predicted step
        # time (measured: one tick after ``next_step_time`` in nominal walking), so
        # the foot is timed to touch down then and not earlier: a foot that
        # touches before the jump takes the whole weight while the plan still
        # has the ZMP on the stance foot (2-3 cm of DCM error).
        landing = (
            command.next_step_time
            - (command.time - command.time_since_step)
            + self.landing_delay
            - self.touchdown_lead
        )
        self._last_command = command
        self.landing.observe(command)
        target = self.landing.target(command)
        end = self.timing.double_support
        if command.time_since_step <= end < time_since_step:
            if self.foothold_feedback or self.reanchor_stance:
                offset = self.sim.sole_position(stance)[:2] - foothold
                far = self.reanchor_stance and float(np.linalg.norm(offset)) > self.reanchor_min
                # A far sole re-anchors the planner; a near one is left to the foothold
                # feedback (re-anchoring every step moved the walk's DCM error by the
                # landing's few mm: V_u peak 1.52 gamma_v instead of 0.67).
                self._report_stance = far
                self._stance_offset = offset if self.foothold_feedback and not far else np.zeros(2)
            if self.yaw_feedback:
                self._frame_yaw = _wrap(self.sim.sole_yaw(stance) - self._ik_yaw[stance])
        if self.foothold_feedback:
            target = target - self._stance_offset
        if self.yaw_feedback:
            target = foothold + _rotate(target - foothold, -self._frame_yaw)
            if time_since_step > end:  # in the air: turn to land facing forward
                turn = _wrap(-self._frame_yaw - self._ik_yaw[swing_foot])
                self._ik_yaw[swing_foot] += float(np.clip(turn, -YAW_RATE * dt, YAW_RATE * dt))
        swing_position = self.swing.update(time_since_step, target, dt, landing)
        if self.swing_feedback > 0.0 and time_since_step > end:
            swing_position[:2] -= self.swing_feedback * self._update_swing_offset(stance)
        swing_position[2] = max(swing_position[2] - self._press_depth(swing_position), -0.01)
        swing_position[2] = max(swing_position[2], self.landing_clearance)
        if self.transfer_lift > 0.0 and time_since_step < self.timing.double_support + 0.1:
            # The old stance foot leaves the ground at the step: the new one takes
            # the weight at once (kept until the swing profile rises above it).
            # Measured: keeping both feet down until the plan's pivot reaches the
            # new sole leaves the CoP on the old foot (4-5 cm of DCM error).
            lift = self.transfer_lift * min(time_since_step / self.transfer_ramp, 1.0)
            swing_position[2] = max(swing_position[2], lift)
        swing_sole = sole_pose(swing_position, self._ik_yaw[swing_foot])
        if self.swing_level_feedback > 0.0 and time_since_step > end:
            sag, tilt = self._update_swing_level(swing_foot)
            swing_sole[2, 3] += self.swing_level_feedback * sag
            swing_sole[:3, :3] = (
                Rotation.from_rotvec([*(-self.swing_level_feedback * tilt), 0.0]).as_matrix()
                @ swing_sole[:3, :3]
            )
        soles = {
            stance: sole_pose(
                np.array([*command.stance.position, self._settle(time_since_step)]),
                self._ik_yaw[stance],
            ),
            swing_foot: swing_sole,
        }

        support = "both" if command.double_support else stance
        planned = clock.perf_counter()
        offsets = self._upper_body_offsets(command)
        try:
            q = self.ik.solve(
                com_target, soles["left"], soles["right"], support, dt, upper_body_offsets=offsets
            )
            q = q[self._ik_to_sim]
        except IkInfeasibleError as error:
            # Measured only while falling (feet and CoM far apart): hold the last
            # targets and report the fall instead of ending the run with an error.
            self._ik_failure = f"whole-body IK infeasible at t = {command.time:.2f} s"
            self._ik_failure += f" ({error.reason})"
            q = self._joint_targets
        # Rate of the IK motion's own centroidal angular momentum (low-pass).
        momentum = self.ik.angular_momentum[:2].copy()
        previous_momentum = momentum if self._ik_momentum is None else self._ik_momentum
        rate = (momentum - previous_momentum) / dt
        self._ik_momentum = momentum
        self._ik_momentum_rate += min(dt / self.momentum_filter, 1.0) * (
            rate - self._ik_momentum_rate
        )
        if self.ankle.enabled:
            q = self._with_ankle_offsets(command, q)
        solved = clock.perf_counter()
        previous = self._joint_targets
        velocity = (q - previous) / dt
        self._joint_targets = q
        self._run_physics(previous, q, velocity, push_force)
        stepped = clock.perf_counter()
        self._measured = self._measure()
        measured_at = clock.perf_counter()
        self.timers["planning"] += planned - start
        self.timers["ik"] += solved - planned
        self.timers["physics"] += stepped - solved
        self.timers["estimation"] += measured_at - stepped
        self.ticks += 1
        return self._measured

    def _run_physics(
        self,
        previous: NDArray[np.float64],
        q: NDArray[np.float64],
        velocity: NDArray[np.float64],
        push_force: Vector2,
    ) -> None:
        """The physics steps of one tick: joint targets from ``previous`` to ``q`` [rad].

        With ``interpolate_targets`` the position target moves linearly to ``q``
        over the steps (velocity target ``velocity`` [rad/s]); else ``q`` is set
        once. ``push_force`` [N] acts on the pelvis at every step.
        """
        force = (
            np.array([push_force[0], push_force[1], 0.0], dtype=float) if any(push_force) else None
        )
        change = q - previous
        for substep in range(1, self._substeps + 1):
            if self.interpolate_targets or substep == 1:
                fraction = substep / self._substeps if self.interpolate_targets else 1.0
                self.sim.set_joint_targets(previous + fraction * change, velocity)
            self.sim.step(force)
            if self.physics_log is not None:
                self.physics_log.record(self.sim, force)

    def _update_swing_offset(self, stance: Foot) -> NDArray[np.float64]:
        """Low-passed offset [m] of the real swing sole from the IK's, each relative
        to its stance sole (horizontal), after the last physics step."""
        swing = other_foot(stance)
        real = self.sim.sole_position(swing)[:2] - self.sim.sole_position(stance)[:2]
        ik = self.ik.sole_world(swing)[:2, 3] - self.ik.sole_world(stance)[:2, 3]
        alpha = min(self.control_period / self.swing_feedback_filter, 1.0)
        self._swing_offset += alpha * (real - ik - self._swing_offset)
        size = float(np.linalg.norm(self._swing_offset))
        if size > SWING_FEEDBACK_LIMIT:
            self._swing_offset *= SWING_FEEDBACK_LIMIT / size
        return self._swing_offset

    def _update_swing_level(self, swing: Foot) -> tuple[float, NDArray[np.float64]]:
        """Low-passed sag [m] of the real swing sole's lowest corner below the IK's,
        and the real sole's roll and pitch [rad] relative to the IK's (world axes)."""
        origin, rotation = self.sim.sole_frame(swing)
        ik = self.ik.sole_world(swing)
        corners = self._sole_corners
        ik_lowest = ik[2, 3] + np.min(ik[2, :3] @ corners.T)
        sag = float(ik_lowest - origin[2] - np.min(rotation[2] @ corners.T))
        error = Rotation.from_matrix(rotation @ ik[:3, :3].T).as_rotvec()[:2]
        alpha = min(self.control_period / self.swing_feedback_filter, 1.0)
        self._swing_sag += alpha * (sag - self._swing_sag)
        self._swing_tilt += alpha * (error - self._swing_tilt)
        limit = SWING_FEEDBACK_LIMIT
        self._swing_sag = float(np.clip(self._swing_sag, -limit, limit))
        np.clip(self._swing_tilt, -SWING_TILT_LIMIT, SWING_TILT_LIMIT, out=self._swing_tilt)
        return self._swing_sag, self._swing_tilt

    def _settle(self, time_since_step: float) -> float:
        """Height [m] of the new stance sole target: ``landing_clearance`` ramped to 0."""
        return self.landing_clearance * max(0.0, 1.0 - time_since_step / self.transfer_ramp)

    def _press_depth(self, swing_position: NDArray[np.float64]) -> float:
        """How far below the ground the landed swing sole is commanded [m]."""
        return self.touchdown_depth if swing_position[2] <= 1e-4 else 0.0

    def _advance_com_reference(self, command: PlannerOutput) -> NDArray[np.float64]:
        """Blend the CoM reference toward the measurement, integrate it, return the IK target."""
        measured = self._measured
        if measured is None:
            raise RsgError("the PyBullet backend must be reset before it steps")
        position_error = self._com_reference - measured.com_position
        velocity_error = self._com_velocity_reference - measured.com_velocity
        correction = (
            self.com_tracking_gains[0] * position_error
            + self.com_tracking_gains[1] * velocity_error
        )
        blend = self.com_reference_blend
        self._com_reference = self._com_reference - blend * position_error
        self._com_velocity_reference = self._com_velocity_reference - blend * velocity_error
        hdot = {
            "full": command.angular_momentum_rate,
            "feedback": command.angular_momentum_rate_feedback,
            "none": np.zeros(2),
        }[self.plan_angular_momentum]
        zmp = np.asarray(command.zmp, float)
        if self.momentum_compensation > 0.0:
            zmp, hdot = self._momentum_aware_pivot(command, zmp, hdot)
        planned_before, self._plan_cop = self._plan_cop, zmp
        if self.cop_admittance > 0.0:
            zmp = cop_admittance_zmp(zmp, planned_before, self._measured_cop(), self.cop_admittance)
        self._com_reference, self._com_velocity_reference = integrate_lipm(
            self._lipm,
            self._com_reference,
            self._com_velocity_reference,
            zmp,
            hdot,
            np.zeros(2),
            self.control_period,
        )
        if self.com_lookahead == 0.0:
            return self._com_reference + correction
        target, _ = integrate_lipm(
            self._lipm,
            self._com_reference,
            self._com_velocity_reference,
            zmp,
            hdot,
            np.zeros(2),
            self.com_lookahead,
        )
        return target + correction

    def _momentum_aware_pivot(
        self, command: PlannerOutput, zmp: NDArray[np.float64], hdot: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """ZMP and hdot of the CoM plan given the IK motion's own angular momentum rate."""
        return momentum_aware_pivot(
            zmp,
            hdot,
            self.momentum_compensation * self._ik_momentum_rate,
            self.mass,
            command,
            self.description.sole,
            self.cop_margin,
            ramped_double_support=self.plan_angular_momentum != "full",
        )

    def _upper_body_offsets(self, command: PlannerOutput) -> NDArray[np.float64] | None:
        """Upper-body joint offsets [rad] that carry the planner's hdot (None: off).

        The rest of the motion is the IK's last motion less the upper body's part.
        """
        if self.flywheel is None:
            return None
        rest = self.ik.angular_momentum[:2] - self.flywheel.momentum
        return self.flywheel.follow_rate(
            command.angular_momentum_rate_feedback, self.control_period, rest
        )

    def _ankle_joint_names(self, foot: str) -> list[str]:
        """The two joints above ``foot``'s ankle link, nearest first (roll, pitch on G1)."""
        model = self.ik.robot.model
        first = model.frames[model.getFrameId(self.description.ankle_link(foot))].parentJoint
        return [model.names[first], model.names[model.parents[first]]]

    def _with_ankle_offsets(
        self, command: PlannerOutput, q: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """Joint targets ``q`` (simulator order) plus the ankle CoP feedback's offsets."""
        stance = command.stance.foot
        single_support = not command.double_support
        axes = []
        if single_support:  # the offsets only decay in double support
            robot = self.ik.robot
            jacobian = robot.frame_jacobian(self.description.ankle_link(stance), "world")
            axes = [
                jacobian[3:6, robot.get_joint_v_offset(name)] for name in self._ankle_joints[stance]
            ]
        offsets = self.ankle.update(
            self.control_period,
            stance,
            single_support,
            self._plan_cop,
            self._pressure.get(stance),
            axes,
            self.mass * GRAVITY,
        )
        q = q.copy()
        for foot, offset in offsets.items():
            q[self._ankle_sim_index[foot]] += offset
        return q

    def _measured_cop(self) -> NDArray[np.float64] | None:
        """CoP of both feet [m] at the end of the last tick (None: hardly loaded)."""
        total = sum(force for _, force in self._pressure.values())
        if total < MIN_LOAD_FRACTION * self.mass * GRAVITY:
            return None
        moment = np.sum([cop * force for cop, force in self._pressure.values()], axis=0)
        return np.asarray(moment / total, dtype=float)

    def _measure(self) -> MeasuredState:
        if self.ankle.enabled or self.cop_admittance > 0.0 or self.stance_switch == "contact":
            self._pressure = self.sim.foot_pressure()
        com, com_velocity = self.sim.com_state()
        stance_sole = None
        if self._report_stance and self._last_command is not None:
            stance_sole = self.sim.sole_position(self._last_command.stance.foot, False)[:2].copy()
            self._report_stance = False
        return MeasuredState(
            self.sim.time, com[:2].copy(), com_velocity[:2].copy(), self._touchdown(), stance_sole
        )

    def _touchdown(self) -> NDArray[np.float64] | None:
        """Where the swing sole touched down [m] (``stance_switch="contact"``), else None."""
        command = self._last_command
        if self.stance_switch != "contact" or command is None or command.double_support:
            return None
        swing = other_foot(command.stance.foot)
        load = self._pressure.get(swing)
        if load is None or load[1] < CONTACT_LOAD_FRACTION * self.mass * GRAVITY:
            return None
        if not 0.0 < command.next_step_time - self.sim.time <= CONTACT_WINDOW:
            return None
        return np.asarray(self.sim.sole_position(swing)[:2], dtype=float)

    # ---------------------------------------------------------------- queries
    def fall_status(self) -> FallStatus:
        """Fallen if the pelvis is low or tilted, a non-foot body touches the ground, or
        the whole-body IK had no solution."""
        if self._ik_failure is not None:
            return FallStatus(True, self._ik_failure)
        position, quaternion = self.sim.base_pose()
        if position[2] < self.description.fall_base_height:
            return FallStatus(True, f"pelvis height {position[2]:.3f} m")
        tilt = _tilt(quaternion)
        if tilt > self.description.fall_tilt:
            return FallStatus(True, f"pelvis tilt {np.degrees(tilt):.0f} deg")
        others = self.sim.ground_contacts() - set(self.sim.foot_links.values())
        if others:
            names = sorted(self.sim.link_name(link) for link in others)
            return FallStatus(True, f"ground contact of {', '.join(names)}")
        return FallStatus(False)

    @property
    def planned_cop(self) -> NDArray[np.float64]:
        """CoP [m] the CoM plan assumed over the last tick, shape (2,)."""
        return self._plan_cop

    def foot_pressure(self) -> dict[str, tuple[NDArray[np.float64], float]]:
        """Foot -> (measured CoP [m], normal force [N]) of the feet on the ground."""
        return self.sim.foot_pressure()

    def feet_in_contact(self) -> set[str]:
        """Feet touching the ground."""
        return self.sim.feet_in_contact()

    def robot_configuration(self) -> tuple[NDArray[np.float64], NDArray[np.float64], dict]:
        """URDF base position [m], quaternion (x, y, z, w) and joint angles [rad]
        (the description's locked joints at their standing angle)."""
        position, quaternion = self.sim.base_pose()
        return position, quaternion, {**self._locked_angles, **self.sim.joint_angles()}

    def sole_positions(self) -> dict[str, NDArray[np.float64]]:
        """Measured sole origin of each foot in the world [m], shape (3,)."""
        return {foot: self.sim.sole_position(foot) for foot in ("left", "right")}

    def timing_report(self) -> dict[str, float]:
        """Mean wall time per tick of each part [s] (planning, ik, physics, estimation)."""
        ticks = max(self.ticks, 1)
        report = {key: value / ticks for key, value in self.timers.items()}
        report["total"] = sum(report.values())
        return report

    def close(self) -> None:
        """Release the PyBullet client."""
        self.sim.close()


def _tilt(quaternion_xyzw: NDArray[np.float64]) -> float:
    """Angle [rad] between the body z axis of a unit quaternion (x, y, z, w) and the vertical.

    The z component of the rotated z axis is 1 - 2 (x^2 + y^2) (called every tick
    by the fall check: 12 us less than building the rotation matrix with scipy).
    """
    x, y = quaternion_xyzw[0], quaternion_xyzw[1]
    return float(np.arccos(np.clip(1.0 - 2.0 * (x * x + y * y), -1.0, 1.0)))


def _ground_pose(position_xy: NDArray[np.float64]) -> NDArray[np.float64]:
    """Flat sole pose on the ground at ``position_xy`` [m]."""
    return sole_pose(np.array([position_xy[0], position_xy[1], 0.0]))


YAW_RATE = 2.0  # turning rate of the swing sole with ``yaw_feedback`` [rad/s]


def _rotate(vector: NDArray[np.float64], angle: float) -> NDArray[np.float64]:
    """``vector`` (2,) turned by ``angle`` [rad] about z."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([c * vector[0] - s * vector[1], s * vector[0] + c * vector[1]])


def _wrap(angle: float) -> float:
    """``angle`` [rad] in (-pi, pi]."""
    return float(np.arctan2(np.sin(angle), np.cos(angle)))
