"""What the full-robot side needs to know about one biped.

A :class:`RobotDescription` gathers every robot-specific constant (URDF source,
link names, sole geometry, nominal posture, joint gains, fall thresholds) so that
the whole-body IK and the PyBullet backend stay robot-agnostic. Frames: the sole
frame of a foot has its origin on the ground below the ankle, x forward, z up.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

from planner.exceptions import ParameterError
from planner.parameters import CORNER_RANGE, RANGES

#: Fields handed to the planner (app.setup.robot_config.planner_config_for), checked with the
#: planner's ranges so that an error names the description field.
PLANNER_FIELDS = (
    "stride_length",
    "step_width",
    "double_support_duration",
    "single_support_duration",
    "angular_momentum_rate_max",
    "lqr_dcm_error_scale",
    "swing_preparation_time",
    "filter_time_constant",
    "step_reaction_time",
    "reanchor_time",
    "touchdown_window",
)


@dataclass(frozen=True)
class JointImpedance:
    """A joint motor's PD gains (the G1 low level's kp and kd).

    Attributes:
        stiffness: kp [N m/rad], > 0.
        damping: kd [N m s/rad], >= 0.
    """

    stiffness: float
    damping: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.stiffness) and 0.0 < self.stiffness <= 1e5):
            raise ParameterError("stiffness", self.stiffness, "a number in (0, 1e5] N m/rad")
        if not (math.isfinite(self.damping) and 0.0 <= self.damping <= 1e3):
            raise ParameterError("damping", self.damping, "a number in [0, 1e3] N m s/rad")


@dataclass(frozen=True)
class MotorModel:
    """One motor's limits and friction, as the joint sees them.

    Attributes:
        peak_torque: Torque limit [N m] below ``full_torque_speed`` (Y1).
        braking_torque: Limit [N m] of a torque against the motion (Y2).
        full_torque_speed: Speed [rad/s] up to which ``peak_torque`` is available (X1).
        no_load_speed: Speed [rad/s] at which the torque limit reaches zero (X2).
        static_friction: Coulomb friction [N m] (Fs).
        viscous_friction: Viscous friction [N m s/rad] (Fd).
    """

    peak_torque: float
    braking_torque: float
    full_torque_speed: float
    no_load_speed: float
    static_friction: float = 0.0
    viscous_friction: float = 0.0

    def __post_init__(self) -> None:
        for name in ("peak_torque", "braking_torque", "full_torque_speed", "no_load_speed"):
            if not getattr(self, name) > 0.0:
                raise ParameterError(name, getattr(self, name), "a number > 0")
        if not self.no_load_speed > self.full_torque_speed:
            raise ParameterError(
                "no_load_speed", self.no_load_speed, f"> full_torque_speed {self.full_torque_speed}"
            )
        for name in ("static_friction", "viscous_friction"):
            if not getattr(self, name) >= 0.0:
                raise ParameterError(name, getattr(self, name), "a number >= 0")


def _check_physics_time_step(value: float) -> None:
    """Raise a ParameterError naming ``physics_time_step`` unless 0.5 ms <= value <= 5 ms."""
    if not (isinstance(value, float) and 0.0005 <= value <= 0.005):
        raise ParameterError("physics_time_step", value, "a number in [0.0005, 0.005] s")


@dataclass(frozen=True)
class SoleRectangle:
    """Contact rectangle of a sole, in the sole frame.

    Attributes:
        x_min: Rear edge [m] (negative: behind the ankle).
        x_max: Front edge [m].
        half_width: Half of the lateral extent, symmetric about the ankle [m].
    """

    x_min: float
    x_max: float
    half_width: float

    def __post_init__(self) -> None:
        if not self.x_min < 0.0 < self.x_max:
            raise ParameterError("sole.x_min/x_max", (self.x_min, self.x_max), "x_min < 0 < x_max")
        if not self.half_width > 0.0:
            raise ParameterError("sole.half_width", self.half_width, "> 0 m")


@dataclass(frozen=True)
class RobotDescription:
    """Robot-specific constants of a biped from example-robot-data.

    Attributes:
        name: Registry name (``"g1"``).
        urdf_source: URDF path relative to example-robot-data's ``robots/`` share
            folder (``"g1_description/urdf/g1_29dof_rev_1_0.urdf"``).
        base_link: Floating-base link of the URDF (the pelvis).
        left_ankle_link: Link carrying the left sole.
        right_ankle_link: Link carrying the right sole.
        trunk_link: Link whose orientation is kept upright (torso).
        sole_offset: Position of the sole frame origin in the ankle link frame [m],
            3 values; the sole frame has the ankle link's orientation.
        sole: Sole contact rectangle (bounds the planner's ZMP window).
        com_height: Nominal CoM height above the ground while walking [m].
        rotational_height: h_r, the body's centroidal angular momentum per unit
            of CoM velocity over its mass [m] (L = m h_r H cdot as the CoM sways over
            the feet); the planner's pendulum is c_z + h_r tall.
        foot_spacing: Nominal lateral distance between the two ankles [m].
        standing_posture: Joint name -> angle [rad] of the nominal posture; joints
            not listed are at 0 rad.
        joint_impedance: Joint name -> its motor's PD gains, for every actuated
            joint that is not locked.
        total_mass: Mass from the URDF [kg] (checked against PyBullet in the tests).
        fall_base_height: Pelvis height [m] under which the robot counts as fallen.
        fall_tilt: Pelvis tilt from vertical [rad] over which it counts as fallen.
        swing_height: Apex height of the swing sole above the ground [m].
        ground_friction: Lateral friction coefficient of the ground and soles [-].
        sole_spinning_friction: PyBullet's torsional friction of the soles [m]: each
            contact point resists a turn about the ground normal with up to this
            times its normal force (a contact patch of radius a gives about
            2/3 mu a); 0: point contacts, which resist no turn.
        stride_length: Nominal L_x of the planner's gait [m].
        step_width: Nominal L_y [m].
        double_support_duration: Nominal T_DSP [s].
        single_support_duration: Nominal T_SSP [s].
        step_min: Lower bound u_d^m of a step (x, y) [m] (leg reach).
        step_max: Upper bound u_d^M of a step (x, y) [m].
        angular_momentum_rate_max: Bound on the feedback hdot [N m].
        lqr_dcm_error_scale: DCM error scale e_max of the LQR (Bryson) [m].
        swing_preparation_time: T_SP, time the swing foot needs after the double
            support before it can land [s] (bounds how early the planner may step).
        filter_time_constant: theta, the planner's low-pass filter on its
            continuous input and double-support compensation [s].
        step_reaction_time: Time [s] the swing foot needs between the planner's
            decision to step early and the touchdown
            (``RsgParameters.step_reaction_time``).
        reanchor_time: Time constant [s] with which the planner moves its foothold
            to a measured stance sole (``RsgParameters.reanchor_time``; backend
            option ``reanchor_stance``); 0: at once.
        touchdown_window: How long [s] before a scheduled timing jump's time a
            measured touchdown of the swing sole brings the jump forward
            (``RsgParameters.touchdown_window``); 0: the jump keeps its time.
        dcm_inset: The planner's row (27c') [m] (``RsgParameters.dcm_inset``): a QP
            step puts the new sole's centre line at least this far outside the
            predicted DCM; None: (27c) as printed.
        physics_time_step: PyBullet's fixed time step [s], in [0.0005, 0.005];
            the control period must be a multiple of it.
        solver_iterations: Iterations of PyBullet's contact and joint-motor
            solver per physics step (its cost grows with them; 1 to 200).
        sole_box_collision: Replace the foot's collision shapes by a box spanning
            the sole rectangle in the derived URDF.
        upper_body_joints: Joints that turn the torso and the arms, used to carry
            the planner's angular momentum (the stabilizer's flywheel).
        locked_joints: Joints welded at their standing angle, in the physics URDF
            (:func:`robots.urdf_merge.lock_joints`: fewer degrees of freedom and
            motor rows, so a cheaper physics step) and in the IK (masked); neither
            actuated nor measured. Not the upper-body or leg joints the controller
            moves.
        imu_position: Where the pelvis IMU is, in the base link's frame [m] (its
            axes are the base link's).
        foot_force_sensors: Whether the ankles carry force-torque sensors.
        motors: Joint name -> its motor's torque-speed curve and friction
            (:class:`MotorModel`); joints not listed: the effort limit, no friction.
        motor_armature: Joint name -> its motor's armature, the rotor inertia reflected
            through the gear [kg m^2] (:mod:`robots.rotor_inertia`); joints not listed
            have none.
        backend_options: This robot's whole-body stabilizer options
            (:class:`app.stabilizer.config.StabilizerConfig`) and ``control_period``
            [s], where they differ from the defaults.
    """

    name: str
    urdf_source: str
    base_link: str
    left_ankle_link: str
    right_ankle_link: str
    trunk_link: str
    sole_offset: tuple[float, float, float]
    sole: SoleRectangle
    com_height: float
    foot_spacing: float
    standing_posture: Mapping[str, float]
    joint_impedance: Mapping[str, JointImpedance]
    total_mass: float
    rotational_height: float = 0.0
    fall_base_height: float = 0.4
    fall_tilt: float = math.radians(45.0)
    swing_height: float = 0.06
    ground_friction: float = 1.0
    sole_spinning_friction: float = 0.0
    stride_length: float = 0.1
    step_width: float = 0.2
    double_support_duration: float = 0.1
    single_support_duration: float = 0.7
    step_min: tuple[float, float] = (-0.25, -0.4)
    step_max: tuple[float, float] = (0.35, 0.4)
    angular_momentum_rate_max: float = 3.0
    lqr_dcm_error_scale: float = 0.03
    swing_preparation_time: float = 0.2
    filter_time_constant: float = 0.05
    step_reaction_time: float = 0.0
    reanchor_time: float = 0.0
    touchdown_window: float = 0.0
    dcm_inset: float | None = None
    physics_time_step: float = 0.001
    solver_iterations: int = 50
    sole_box_collision: bool = False
    upper_body_joints: tuple[str, ...] = ()
    locked_joints: tuple[str, ...] = ()
    imu_position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    foot_force_sensors: bool = False
    motors: Mapping[str, MotorModel] = field(default_factory=dict)
    motor_armature: Mapping[str, float] = field(default_factory=dict)
    backend_options: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not self.name or not self.name.isidentifier():
            raise ParameterError("name", self.name, "a non-empty identifier")
        if not self.urdf_source.endswith(".urdf") or self.urdf_source.startswith("/"):
            raise ParameterError("urdf_source", self.urdf_source, "a relative path to a .urdf")
        links = (self.base_link, self.left_ankle_link, self.right_ankle_link, self.trunk_link)
        if any(not link for link in links) or self.left_ankle_link == self.right_ankle_link:
            raise ParameterError("links", links, "non-empty names, distinct ankle links")
        if len(self.sole_offset) != 3 or not self.sole_offset[2] < 0.0:
            raise ParameterError("sole_offset", self.sole_offset, "(x, y, z<0) [m]")
        if not 0.2 <= self.com_height <= 2.0:
            raise ParameterError("com_height", self.com_height, "0.2 m <= c_z <= 2 m")
        if not 0.0 <= self.rotational_height <= 0.5:
            raise ParameterError("rotational_height", self.rotational_height, "0 <= h_r <= 0.5 m")
        if not 0.0 < self.foot_spacing < 1.0:
            raise ParameterError("foot_spacing", self.foot_spacing, "0 < L_y < 1 m")
        if not self.total_mass > 0.0:
            raise ParameterError("total_mass", self.total_mass, "> 0 kg")
        if not 0.0 < self.fall_base_height < 2.0:
            raise ParameterError("fall_base_height", self.fall_base_height, "0 < h < 2 m")
        if not 0.0 < self.fall_tilt < math.pi / 2:
            raise ParameterError("fall_tilt", self.fall_tilt, "0 < tilt < pi/2 rad")
        if not 0.0 < self.swing_height < 0.3:
            raise ParameterError("swing_height", self.swing_height, "0 < h < 0.3 m")
        if not 0.0 < self.ground_friction <= 10.0:
            raise ParameterError("ground_friction", self.ground_friction, "a number in (0, 10]")
        if not 0.0 <= self.sole_spinning_friction <= 0.1:
            raise ParameterError(
                "sole_spinning_friction", self.sole_spinning_friction, "in [0, 0.1] m"
            )
        _check_physics_time_step(self.physics_time_step)
        iterations = self.solver_iterations
        if type(iterations) is not int or not 1 <= iterations <= 200:  # not a bool either
            raise ParameterError(
                "solver_iterations", self.solver_iterations, "an integer from 1 to 200"
            )
        for joint, angle in self.standing_posture.items():
            if not math.isfinite(angle):
                raise ParameterError(f"standing_posture[{joint}]", angle, "a finite angle [rad]")
        for name in PLANNER_FIELDS:
            RANGES[name].check(name, getattr(self, name))
        for name in ("step_min", "step_max"):
            pair = getattr(self, name)
            if len(pair) != 2 or not all(CORNER_RANGE.contains(v) for v in pair):
                raise ParameterError(name, pair, "two numbers (x, y), each in [-2, 2] m")
        if self.dcm_inset is not None and not RANGES["dcm_inset"].contains(self.dcm_inset):
            raise ParameterError("dcm_inset", self.dcm_inset, "none or a number in [-0.1, 0.1] m")
        locked = tuple(self.locked_joints)
        named = all(isinstance(name, str) and name for name in locked)
        if not named or len(set(locked)) != len(locked):
            raise ParameterError("locked_joints", self.locked_joints, "distinct joint names")
        moved = sorted(set(locked) & set(self.upper_body_joints))
        if moved:
            raise ParameterError("locked_joints", moved, "joints that are not in upper_body_joints")
        object.__setattr__(self, "locked_joints", locked)
        # Freeze the mappings so the description stays immutable and hashable-safe.
        object.__setattr__(self, "standing_posture", MappingProxyType(dict(self.standing_posture)))
        object.__setattr__(self, "backend_options", MappingProxyType(dict(self.backend_options)))
        object.__setattr__(self, "joint_impedance", MappingProxyType(dict(self.joint_impedance)))
        object.__setattr__(self, "motors", MappingProxyType(dict(self.motors)))
        object.__setattr__(self, "motor_armature", MappingProxyType(dict(self.motor_armature)))

    @property
    def pendulum_height(self) -> float:
        """c_z + h_r, the height of the planner's pendulum [m]."""
        return self.com_height + self.rotational_height

    def ankle_link(self, foot: str) -> str:
        """Ankle link name of ``foot`` (``"left"`` or ``"right"``)."""
        if foot == "left":
            return self.left_ankle_link
        if foot == "right":
            return self.right_ankle_link
        raise ParameterError("foot", foot, "'left' or 'right'")
