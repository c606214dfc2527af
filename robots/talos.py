"""PAL Robotics Talos (``talos_reduced.urdf``, 32 joints) from example-robot-data.

Measured facts: 90.27 kg (URDF, PyBullet and placo agree); every link has an
``<inertial>``. The foot's collision mesh has its flat bottom 0.107 m below
``leg_*_6_link`` (where the URDF's own ``*_sole_link`` is), spanning x in
[-0.108, 0.097] m and y in [-0.062, 0.062] m: the sole rectangle is 20 x 12 cm and,
as on G1, the derived URDF replaces the mesh by a box under it. The standing posture
is talos.srdf's ``half_sitting`` (legs and arms; torso and head at 0): CoM 0.877 m
above the soles, 0.870 m standing on them in PyBullet, so c_z = 0.87 m. Hips are
0.17 m apart. Joint torque limits are the URDF efforts (knee 300 N m).

Walking: the paper's gait (L_x 0.1 m, L_y 0.2 m, T_DSP 0.1 s, T_SSP 0.7 s), T_SP 0.5 s,
theta 0.01 s and a step reaction time of 0.2 s as on G1; 1 ms physics. Step bounds: y in
[-0.83, 0.83] m, as on G1 the legs' lateral reach (the widest stance with flat soles, the
CoM midway at c_z and the knees bent by the IK's margin, ``kinematics/reach.py``; 0.875 m
with straight knees; development pushes with y +-0.53, 0.66, 0.79, 0.87 m: 87, 88, 90, 90
recovered, docs/notes/2026-12-04-lateral-reach.md); x in [-0.33, 0.46] m, G1's in units of the CoM
height (the LIPM's length scale, 0.87/0.66 = 1.32; docs/notes/2026-12-03-talos-reach.md,
docs/notes/2026-12-04-lateral-reach.md). The planner's LIPM is c_z + h_r = 0.985 m tall:
as the IK sways the CoM over the feet the body's angular momentum follows the CoM
velocity with h_r 0.121 m along x, 0.119 m along y (``kinematics/pendulum.py``; the 0.115 m
used was measured along y while the IK still moved the arms, within 1 cm of both). The
whole-body stabilizer's defaults, chosen on G1, are used (its joint gains follow from
each joint's effort limit) but one: its net force is the LIPM's m g
(``height_frequency`` 0): G1's CoM height loop lowered its development grid
(docs/notes/2026-12-06-height-loop.md). Talos lists no upper-body joints, so it has no
flywheel and the whole hdot goes to the CoP (a flywheel of the torso and the shoulders did
no better on the development pushes, and worse taking back the legs' momentum;
docs/notes/2026-12-03-talos-reach.md).
"""

from __future__ import annotations

from robots.description import JointImpedance, RobotDescription, SoleRectangle

# Half-sitting posture of talos.srdf (legs and arms; torso and head at 0). Leg joints
# 1-6: hip yaw, hip roll, hip pitch, knee, ankle pitch, ankle roll; the right arm's
# joints 1 and 2 (yaw, roll) are mirrored.
_LEG_BEND = {"3": -0.411354, "4": 0.859395, "5": -0.448041}
_ARM = {"1": 0.25847, "2": 0.173046, "4": -0.525366, "7": 0.1}
_ARM_MIRRORED = {"1", "2"}

STANDING_POSTURE = {
    **{
        f"leg_{side}_{joint}_joint": angle
        for side in ("left", "right")
        for joint, angle in _LEG_BEND.items()
    },
    **{f"arm_left_{joint}_joint": angle for joint, angle in _ARM.items()},
    **{
        f"arm_right_{joint}_joint": (-angle if joint in _ARM_MIRRORED else angle)
        for joint, angle in _ARM.items()
    },
}

# The URDF's effort limits [N m]. No PD gains are published for Talos: each joint uses
# its whole effort at 0.1 rad of error, with kd = 0.025 s x kp, and the ankles (joints 5
# and 6, whose CoP-placing torque comes from the feed-forward) at 1 rad, kd = 0.05 s x kp.
_LEG_EFFORTS = {"1": 100.0, "2": 160.0, "3": 160.0, "4": 300.0, "5": 160.0, "6": 100.0}
_ARM_EFFORTS = {"1": 44.64, "2": 22.32, "3": 17.86, "4": 17.86, "5": 3.0, "6": 6.6, "7": 6.6}
_EFFORTS = {
    **{f"leg_{s}_{j}_joint": e for s in ("left", "right") for j, e in _LEG_EFFORTS.items()},
    **{f"arm_{s}_{j}_joint": e for s in ("left", "right") for j, e in _ARM_EFFORTS.items()},
    "torso_1_joint": 78.0,
    "torso_2_joint": 78.0,
    "gripper_left_joint": 1.0,
    "gripper_right_joint": 1.0,
    "head_1_joint": 8.0,
    "head_2_joint": 4.0,
}


# talos.srdf's rotor parameters (pinocchio.loadRotorParameters): every motor a rotor of
# 1e-5 kg m^2 behind a 100:1 gear, an armature of 1e-5 x 100^2 = 0.1 kg m^2.
ARMATURE = 1e-5 * 100.0**2  # [kg m^2]
_GEARED = [j for j in _EFFORTS if j.startswith(("leg_", "arm_", "torso_", "head_"))]


def _impedance(joint: str, effort: float) -> JointImpedance:
    ankle = joint.startswith("leg_") and joint.endswith(("_5_joint", "_6_joint"))
    angle, damping_time = (1.0, 0.05) if ankle else (0.1, 0.025)
    return JointImpedance(effort / angle, damping_time * effort / angle)


TALOS = RobotDescription(
    name="talos",
    urdf_source="talos_data/robots/talos_reduced.urdf",
    base_link="base_link",
    left_ankle_link="leg_left_6_link",
    right_ankle_link="leg_right_6_link",
    trunk_link="torso_2_link",
    sole_offset=(0.0, 0.0, -0.107),
    sole=SoleRectangle(x_min=-0.105, x_max=0.095, half_width=0.06),
    com_height=0.87,
    rotational_height=0.115,
    foot_spacing=0.17,
    standing_posture=STANDING_POSTURE,
    joint_impedance={joint: _impedance(joint, effort) for joint, effort in _EFFORTS.items()},
    total_mass=90.27,
    foot_force_sensors=True,  # six-axis force-torque sensors at the ankles
    motor_armature={joint: ARMATURE for joint in _GEARED},
    fall_base_height=0.6,
    swing_height=0.06,
    sole_box_collision=True,
    step_min=(-0.33, -0.83),  # x: G1's x 0.87 / 0.66; y: the legs' reach
    step_max=(0.46, 0.83),
    swing_preparation_time=0.5,
    filter_time_constant=0.01,
    step_reaction_time=0.2,
    backend_options={"height_frequency": 0.0},
)
