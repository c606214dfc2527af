"""PAL Robotics Talos (``talos_reduced.urdf``, 32 joints) from example-robot-data.

Measured facts: 90.27 kg (URDF, PyBullet and placo agree); every link has an
``<inertial>``. The foot's collision mesh (``ankle_X_collision.stl``) has its flat
bottom 0.107 m below ``leg_*_6_link`` (where the URDF's own ``*_sole_link`` is),
spanning x in [-0.108, 0.097] m and y in [-0.062, 0.062] m: the sole rectangle is
20 x 12 cm and, as on G1, the derived URDF replaces the mesh by a box under it.
The standing posture is talos.srdf's ``half_sitting`` (legs and arms; torso and
head at 0): CoM 0.877 m above the soles, 0.870 m standing on them in PyBullet,
so c_z = 0.87 m. Hips are 0.17 m apart. Joint torque limits are the URDF efforts
(knee 300 N m), PyBullet gains those of G1 (kp 0.1, kd 1.0): with constant
commands it stands 5 s (CoM moves < 0.1 mm), and walking the leg joints track the
IK to < 0.16 deg.

Walking: the paper's gait (L_x 0.1 m, L_y 0.2 m, T_DSP 0.1 s, T_SSP 0.7 s) and
every other choice of ``robots/g1.py`` unchanged (T_SP 0.5 s, theta 0.01 s,
step reaction time 0.2 s and the same ``backend_options``); no controller change.
Measured with ``rsg run --robot talos --scenario walk --duration 20``: 20 s, 25
steps (CLI count), none adjusted, V_u at most 0.52 gamma_v; ``fixed-timing`` and ``no-step``
walk the 20 s too. Landing errors (measured sole vs. the planner's step at the end
of its double support, as in ``tests/test_pybullet_walk.py``) grow by ~0.5 mm per
step, in +x and +y for both feet: 4.7 mm after 10 s, 12 mm after 20 s. Where
they come from, measured over 10 s runs (max landing error):

* ``landing_clearance`` 2 mm (G1's): 4.7 mm. 0 mm: 0.7 mm at 10 s, but the 20 s
  walk falls at 16.1 s; 1 mm: 5.9 mm at 20 s, V_u up to 3.2 gamma_v; 4 mm: 7.3 mm
  at 10 s. The stance foot does not slide (< 0.02 mm mid to end of stance) and the
  feet yaw by < 0.2 deg: the offset is made at the touchdown, and grows with the
  clearance.
* ``transfer_lift`` 6 mm: 2.5 mm at 10 s, 9.3 mm at 20 s, V_u up to 0.82 gamma_v;
  0 mm: 4.6 mm at 10 s.
* ``landing_correction`` has nothing to learn on Talos (the planner's foothold at
  its jump equals its last announcement to 1e-14 m); 0: 4.5 mm at 10 s.
* ``momentum_compensation`` 0: 9 adjusted steps in 10 s and 3.3 cm of landing error.

(These comparisons ran with a 20 x 12 cm sole centred 5 mm further forward; the
final sole gives 11.9 mm after 20 s against 12.2 mm.)
"""

from __future__ import annotations

from robots.description import JointGains, RobotDescription, SoleRectangle
from robots.g1 import WALKING_OPTIONS

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

_LEG_EFFORTS = {"1": 100.0, "2": 160.0, "3": 160.0, "4": 300.0, "5": 160.0, "6": 100.0}
_ARM_EFFORTS = {"1": 44.64, "2": 22.32, "3": 17.86, "4": 17.86, "5": 3.0, "6": 6.6, "7": 6.6}

JOINT_GAINS = {
    **{
        f"leg_{side}_{joint}_joint": JointGains(0.1, 1.0, effort)
        for side in ("left", "right")
        for joint, effort in _LEG_EFFORTS.items()
    },
    **{
        f"arm_{side}_{joint}_joint": JointGains(0.1, 1.0, effort)
        for side in ("left", "right")
        for joint, effort in _ARM_EFFORTS.items()
    },
    "torso_1_joint": JointGains(0.1, 1.0, 78.0),
    "torso_2_joint": JointGains(0.1, 1.0, 78.0),
}

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
    foot_spacing=0.17,
    standing_posture=STANDING_POSTURE,
    joint_gains=JOINT_GAINS,
    default_gains=JointGains(position_gain=0.1, velocity_gain=1.0, max_force=10.0),
    total_mass=90.27,
    fall_base_height=0.6,
    swing_height=0.06,
    sole_box_collision=True,
    swing_preparation_time=0.5,
    filter_time_constant=0.01,
    step_reaction_time=0.2,
    backend_options=dict(WALKING_OPTIONS),  # G1's, unchanged
)
