"""Unitree G1 (29 DoF, rev 1.0) from example-robot-data.

Measured facts: 33.3 kg; each foot touches the ground only through four 5 mm
spheres centred 30 mm below ``*_ankle_roll_link`` at x in {-0.05, 0.12} m and
y in {+-0.025, +-0.03} m (about 17 x 6 cm; the derived URDF puts a box there); four
links have no ``<inertial>`` (the IMU and camera frames), fixed in the derived URDF.
The joints' effort limits (hips 88 N m, knees 139 N m, ankles 35 N m, waist 88/35 N m,
arms 25 N m) are the URDF's.

Choices, each with why (measurements: docs/results.md and the dated notes in
docs/notes/, e.g. 2026-12-02-g1-position-control.md for the planner values chosen
under position control, kept since):

* ``swing_preparation_time`` T_SP = 0.25 s: the earliest step comes 0.35 s after a
  touchdown, soon enough to catch pushes towards the stance side early in its single
  support; with 0.2 s the decision to step comes while V_u rises after each touchdown
  and a pushed G1 takes 2.2x the twin's adjusted steps (chosen on the development
  pushes, docs/notes/2026-12-03-quicker-step.md).
* ``filter_time_constant`` theta = 0.01 s: at 0.05 s the planner's double-support
  pivot overshoots the new sole by up to 8 cm.
* ``step_reaction_time`` 0.2 s: a swing foot needs time to reach a foothold the QP
  has just moved (the planner decides an early step that long before touchdown).
* ``reanchor_time`` 0.2 s: the planner moves its foothold to the measured stance
  sole over 0.2 s rather than in one tick.
* ``touchdown_window`` 0.1 s (the landing rule's window): a step brought forward comes at
  a touchdown up to that early, before a sole that touched early can bounce off while
  the stance foot rolls on its edge (docs/notes/2026-12-06-touchdown-jump.md; Talos,
  whose soles land 40-100 ms early, keeps 0).
* ``step_min``/``step_max`` y -+0.55 m (x [-0.25, 0.35] m): the outward step after a
  crossing step is what catches a push towards the stance side; 0.55 m is the legs'
  lateral reach, the widest stance with flat soles and the CoM midway at c_z
  (``kinematics/reach.py``; the ankle rolls' +-15 deg end it). Development pushes with
  y +-0.4, 0.5, 0.55, 0.6 m: 93, 95, 97, 97 recovered; at 0.6 m the IK had no solution
  in some wide double supports (docs/notes/2026-12-04-lateral-reach.md).
* ``rotational_height`` h_r 0.10 m: as the IK sways the CoM over the feet the body's
  angular momentum follows the CoM velocity (h_r 0.104 m along x, 0.094 m along y,
  ``kinematics/pendulum.py``), so the planner's LIPM is c_z + h_r = 0.76 m tall.
* ``dcm_inset`` 0.02 m and |hdot| <= 5 N m: the planner's row (27c') and the bound
  on its feedback angular momentum rate.
* ``physics_time_step`` 1 ms with 75 solver iterations: the driver's plain PD law
  (``app/backends/joint_motors.py``), explicit at each physics step, chatters on the light
  feet at 2 ms and the walk falls after 18 steps; at 1 ms it walks.
* the motors (``MOTORS``, ``ARMATURE``): unitree_rl_lab's torque-speed curves, friction
  and armatures; the IMU at the URDF's ``imu_in_pelvis``; no foot force sensors.
* ``locked_joints``: the ten distal arm joints are welded at their standing angles
  (the flywheel uses the waist and the shoulders' pitch and roll): 19 actuated
  joints, a physics step 0.58 times as long.
* ``sole_spinning_friction`` 0.01 m: a rubber pad resists turning about the ground
  normal (PyBullet's corner contacts would not).
* the whole-body stabilizer's defaults (``app/stabilizer/config.py``) were chosen on
  G1's development pushes; ``backend_options`` stays empty.
"""

from __future__ import annotations

from robots.description import JointImpedance, MotorModel, RobotDescription, SoleRectangle

_LEG_BEND = {"hip_pitch": -0.35, "knee": 0.7, "ankle_pitch": -0.35}
_ARMS = {"shoulder_pitch": 0.2, "elbow": 0.9}
_SHOULDER_ROLL = 0.2  # [rad], outward (left +, right -)

STANDING_POSTURE = {
    **{
        f"{side}_{joint}_joint": angle
        for side in ("left", "right")
        for joint, angle in _LEG_BEND.items()
    },
    **{
        f"{side}_{joint}_joint": angle
        for side in ("left", "right")
        for joint, angle in _ARMS.items()
    },
    "left_shoulder_roll_joint": _SHOULDER_ROLL,
    "right_shoulder_roll_joint": -_SHOULDER_ROLL,
}

# Unitree's published PD gains (kp [N m/rad], kd [N m s/rad]): legs from unitree_rl_gym,
# legged_gym/envs/g1/g1_config.py; waist and arms from unitree_sdk2,
# example/g1/low_level/g1_ankle_swing_example.cpp.
PUBLISHED_GAINS = {
    "hip": (150.0, 2.0),
    "knee": (300.0, 4.0),
    "ankle": (40.0, 2.0),
    "waist_yaw": (60.0, 1.0),
    "waist": (40.0, 1.0),
    "arm": (40.0, 1.0),
}
# Those gains serve a learned policy that closes its own loop at 50 Hz; tracking the IK
# with a feed-forward here, the joints but the ankles take 5 x kp and 10 x kd (the
# ankles keep theirs: their torque that places the CoP comes from the feed-forward).
STIFFNESS_FACTOR, DAMPING_FACTOR = 5.0, 10.0


def _impedance(joint: str) -> JointImpedance:
    group = next((g for g in ("waist_yaw", "hip", "knee", "ankle", "waist") if g in joint), "arm")
    kp, kd = PUBLISHED_GAINS[group]
    if group == "ankle":
        return JointImpedance(kp, kd)
    return JointImpedance(STIFFNESS_FACTOR * kp, DAMPING_FACTOR * kd)


# G1's motors, from unitree_rl_lab's actuator models (assets/robots/unitree_actuators.py):
# torque-speed curve (Y1, Y2 [N m], X1, X2 [rad/s]), friction (Fs [N m], Fd [N m s/rad])
# and armature [kg m^2], the rotor and gear inertias reflected through the gears (mjlab's
# G1 constants give the same armatures).
MOTORS = {
    "7520-14": MotorModel(71.0, 83.3, 22.63, 35.52, 1.6, 0.16),
    "7520-22": MotorModel(111.0, 131.0, 14.5, 22.7, 2.4, 0.24),
    "5020": MotorModel(24.8, 31.9, 30.86, 40.13, 0.6, 0.06),
    "4010": MotorModel(4.8, 8.6, 15.3, 24.76, 0.6, 0.06),
}
ARMATURE = {"7520-14": 0.01017752, "7520-22": 0.025101925, "5020": 0.003609725, "4010": 0.00425}
_MOTOR = {
    "hip_pitch": "7520-14", "hip_yaw": "7520-14", "waist_yaw": "7520-14",
    "hip_roll": "7520-22", "knee": "7520-22",
    "shoulder_pitch": "5020", "shoulder_roll": "5020", "shoulder_yaw": "5020",
    "elbow": "5020", "wrist_roll": "5020", "wrist_pitch": "4010", "wrist_yaw": "4010",
}  # fmt: skip
# The ankles and the waist's roll and pitch: two 5020 motors through a linkage. Its
# torque-speed curve at the joint is not published: no curve (the URDF's effort limit
# caps the torque), twice a 5020's friction and armature.
_LINKAGE = ("ankle_pitch", "ankle_roll", "waist_roll", "waist_pitch")
_LINKAGE_MOTOR = MotorModel(
    1e3, 1e3, 1e3, 2e3, 2 * MOTORS["5020"].static_friction, 2 * MOTORS["5020"].viscous_friction
)


def _kind(joint: str) -> str:
    return joint.removeprefix("left_").removeprefix("right_").removesuffix("_joint")


def _motor(joint: str) -> MotorModel:
    kind = _kind(joint)
    return _LINKAGE_MOTOR if kind in _LINKAGE else MOTORS[_MOTOR[kind]]


def _armature(joint: str) -> float:
    kind = _kind(joint)
    return 2.0 * ARMATURE["5020"] if kind in _LINKAGE else ARMATURE[_MOTOR[kind]]


# Every joint has gains, the welded ones too (they move with ``--set locked_joints=none``).
_JOINTS = [
    f"{side}_{joint}_joint"
    for side in ("left", "right")
    for joint in ("hip_pitch", "hip_roll", "hip_yaw", "knee", "ankle_pitch", "ankle_roll")
] + [
    "waist_yaw_joint",
    "waist_roll_joint",
    "waist_pitch_joint",
    *(
        f"{side}_{joint}_joint"
        for side in ("left", "right")
        for joint in ("shoulder_pitch", "shoulder_roll", "shoulder_yaw", "elbow")
        + ("wrist_roll", "wrist_pitch", "wrist_yaw")
    ),
]

G1 = RobotDescription(
    name="g1",
    urdf_source="g1_description/urdf/g1_29dof_rev_1_0.urdf",
    base_link="pelvis",
    left_ankle_link="left_ankle_roll_link",
    right_ankle_link="right_ankle_roll_link",
    trunk_link="torso_link",
    sole_offset=(0.0, 0.0, -0.035),
    sole=SoleRectangle(x_min=-0.05, x_max=0.12, half_width=0.025),
    com_height=0.66,
    rotational_height=0.10,
    foot_spacing=0.23,
    standing_posture=STANDING_POSTURE,
    joint_impedance={joint: _impedance(joint) for joint in _JOINTS},
    imu_position=(0.04525, 0.0, -0.08339),  # the URDF's imu_in_pelvis; no foot sensors
    motors={joint: _motor(joint) for joint in _JOINTS},
    motor_armature={joint: _armature(joint) for joint in _JOINTS},
    total_mass=33.3,
    physics_time_step=0.001,
    solver_iterations=75,
    fall_base_height=0.45,
    swing_height=0.06,
    sole_box_collision=True,
    sole_spinning_friction=0.01,
    locked_joints=tuple(
        f"{side}_{joint}_joint"
        for side in ("left", "right")
        for joint in ("shoulder_yaw", "elbow", "wrist_roll", "wrist_pitch", "wrist_yaw")
    ),
    upper_body_joints=(
        "waist_yaw_joint",
        "waist_roll_joint",
        "waist_pitch_joint",
        "left_shoulder_pitch_joint",
        "left_shoulder_roll_joint",
        "right_shoulder_pitch_joint",
        "right_shoulder_roll_joint",
    ),
    step_min=(-0.25, -0.55),
    step_max=(0.35, 0.55),
    swing_preparation_time=0.25,
    angular_momentum_rate_max=5.0,
    filter_time_constant=0.01,
    step_reaction_time=0.2,
    reanchor_time=0.2,
    touchdown_window=0.1,
    dcm_inset=0.02,
)
