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
* ``physics_time_step`` 2 ms with 75 solver iterations: the motors' stable PD law
  (``app/backends/joint_motors.py``) is stable at this step; 1 ms doubles the physics' cost.
* ``locked_joints``: the ten distal arm joints are welded at their standing angles
  (the flywheel uses the waist and the shoulders' pitch and roll): 19 actuated
  joints, a physics step 0.58 times as long.
* ``sole_spinning_friction`` 0.01 m: a rubber pad resists turning about the ground
  normal (PyBullet's corner contacts would not).
* the whole-body stabilizer's defaults (``app/stabilizer/config.py``) were chosen on
  G1's development pushes; ``backend_options`` stays empty.
"""

from __future__ import annotations

from robots.description import JointImpedance, RobotDescription, SoleRectangle

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
    total_mass=33.3,
    physics_time_step=0.002,
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
