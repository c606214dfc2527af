"""Unitree G1 (29 DoF, rev 1.0) from example-robot-data.

Measured facts: 33.3 kg; each foot touches the ground only through four 5 mm
spheres centred 30 mm below ``*_ankle_roll_link`` at x in {-0.05, 0.12} m and
y in {+-0.025, +-0.03} m (about 17 x 6 cm); four links have no ``<inertial>``
(the IMU and camera frames), fixed in the derived URDF.

Walking choices (measured in PyBullet, see ``app/pybullet_backend.py``):

* ``swing_preparation_time`` T_SP = 0.4 s instead of the planner's 0.2 s: a swing
  that must land 0.2 s after lift-off moves the 7 kg legs fast enough that their
  angular momentum rate (up to ~15 N m) shifts the CoP by 4-5 cm, more than the
  whole sole, and every early step then causes the next one (a nominal gait with
  T_SSP = 0.3 s adjusts every step). With the upper body carrying momentum (below),
  over 160 pushes (4-10 N s, 8 directions, 0.1 s, phases 0.25, 0.375, 0.5, 0.5625 and
  0.625: ``rsg grid --controllers rsg --phases 0.25,0.375,0.5,0.5625,0.625 --set
  swing_preparation_time=0.5 --settle 4 --out DIR``, before yaw feedback) T_SP 0.4 s did
  not fall after 104 and recovered 75, 0.5 s 96 and 74. With yaw feedback and 8 s to
  settle, on the 64 at phases 0.5625 and 0.25, 0.4 s is not fallen after 18 and 16 of 32
  (all recovered), 0.5 s after 19 (18) and 14 (14), 0.3 s after 16 (14) and 4 (4).
  Every choice below can be re-measured with ``--set`` the same way.
* ``step_reaction_time`` 0.2 s with ``swing_acceleration`` 20 m/s^2 and
  ``swing_descent_slope`` 0.5: the planner decides an early step 0.2 s before its
  touchdown and aims the QP at the state predicted then; the swing sole reaches the
  moving foothold with bounded accelerations and stays up while it is still far.
  With the paper's instantaneous step the RSG stepped to footholds 5-8 cm from a
  sole still 2 cm up and fell after every 5 N s push at mid single support in 8
  directions (0.1 s pushes at s~ = 0.45 s of the third step, 4 s to settle); with
  these, 5 of 8 directions recover 5 N s and 2 of 8 recover 10 N s. Reaction times
  of 0.15 s and 0.25 s recovered 0 and 2 of 8 at 10 N s. The largest recovered
  impulse per direction is in the README (``rsg sweep``).
* ``swing_land_on_time``: the acceleration bound yields to the landing time, so the
  swing sole is over the foothold when the step is due. With the bound alone the
  re-planning horizon sqrt(6 d / a) shrinks only as the square root of the distance
  d still to go, and a foothold that keeps moving during the reaction time was
  still 4-5 cm away, the sole 2 cm up, at the planner's step: the IK then moved the
  new stance sole there within a tick, it hit the ground at about 2 m/s with 1 kN
  and threw the robot 2 cm into the air for 70 ms (10 N s backward, T_SP 0.3 s,
  traced per physics step). With it, over 160 pushes (4-10 N s, 8 directions, phases
  0.25, 0.375, 0.5, 0.5625 and 0.625: ``rsg grid --controllers rsg --phases ...
  --set swing_land_on_time=false``) rsg does not fall after 82 instead of 70 (14/12,
  12/10, 14/14, 21/19, 21/15 per phase) and recovers 38 as before; nominal walking is
  unchanged (the 20 s walk's V_u peak is 9.67e-4 either way).
* ``foothold_feedback``: at the end of each double support the stance sole is
  measured, and the swing foot is aimed that much the other way. Without it the
  real feet landed a further ~0.8 mm ahead of the planner's footholds at every
  step (2 cm after 30 s), the mean DCM error followed (0.5 -> 5 mm in 25 s) and a
  60 s walk fell at 31 s; with it (before the CoP loops below) the walk went on to
  46 s, the 20 s walk's V_u peak dropped from 0.71 to 0.47 gamma_v, and 10 N s at
  mid single support was survived in 3 of 8 directions instead of 2. (Talos walks
  better without it.)
* ``cop_feedback`` (0, 2) rad/(m s) (``app/pybullet_ankle.py``): in single
  support the stance ankle's targets move the measured CoP onto the CoM plan's,
  laterally only. The lateral CoP error drops from 0.71 to 0.40 cm rms, and the
  walk stops drifting: 180 s with no adjusted step (it fell at 46 s before). A
  forward gain raised the forward error (2: 1.27 -> 1.83 cm rms); a lateral gain of
  5 raised V_u at landings to 1.2 gamma_v. (Talos: V_u 0.52 -> 1.05 gamma_v with it,
  so Talos leaves it off.)
* ``cop_admittance`` 0.3 (``app/pybullet_com_plan.py``): the CoM plan is integrated
  with its CoP moved by 0.3 (planned - measured CoP). Without it, after 8 N s forward
  at mid single support the CoP went bang-bang between heel and toe and every later
  step was adjusted; with it the walk is nominal again after one adjusted step.
  Over 32 pushes (4-10 N s, 8 directions) it survives 19 and recovers 10 (16 and 6
  without; gains 0.2 and 0.5: 16 and 9).
* ``transfer_lift`` 3 mm: at the planner's step the old foot is raised so the new
  foot carries the weight at once, as the planner's reference model assumes
  (landing without it leaves the CoP on the old foot for ~50 ms: 3-4 cm of DCM
  error per step).
* ``momentum_compensation`` 1: the CoM plan accounts for the angular momentum of
  the IK motion itself, keeping the CoP inside the 5 cm wide sole.
* ``filter_time_constant`` theta = 0.01 s instead of the planner's 0.05 s: theta
  also filters the planner's double-support compensation, so its effective pivot
  (ZMP - S hdot / (m g)) lags the moving window and overshoots the new sole by
  |step| theta / T_DSP (8 cm forward-outward at 0.05 s, ~2 cm at 0.01 s), while the
  robot, whose weight moves onto the new foot at the step (``transfer_lift``),
  keeps its CoP on that sole. With 0.01 s: no-step 3.1 s -> 7.3 s, fixed-timing
  3.6 s -> 6.8 s, rsg 5.7 s -> 6.9 s (before the two landing fixes below; with
  them, 0.05 s falls at 4.1 s).
* ``landing_correction`` 1 (``app/pybullet_landing.py``): the planner's foothold at
  its jump is (4.5, 7) mm further than its last announcement; landing on the
  announcement made the feet lag the footholds by 2.3 mm more at every step
  (2.8 cm after 12 steps, e_x -> -1.2 cm). Without it the RSG walk falls at 7.0 s.
* ``upper_body_momentum`` 2 N m s, ``upper_body_return_time`` 0.5 s,
  ``upper_body_cancel`` 0.5 (``kinematics/upper_body.py``): the waist and the
  shoulders (``upper_body_joints``) carry the band-passed part of the RSG's feedback
  hdot and half of the high-passed angular momentum of the legs' swing, as joint
  offsets realised inside the IK. Over the 160 pushes above with T_SP 0.5 s: not
  fallen 96 instead of 82, recovered 74 instead of 38 (``--set upper_body_momentum=0``
  for without); the 20 s walk is unchanged. Measured variants in the README ("The
  upper body carries angular momentum").
* ``yaw_feedback``: at the end of each double support the stance sole's measured
  yaw is compared with the IK's; the IK's swing-sole and CoM targets are turned by the
  difference about the stance foot, and the swing sole turns in the air to land facing
  forward. After pushes G1 turns about the vertical (the stance sole spins when the
  CoP sits on a sole edge or corner, where one or two contact points carry the
  weight: 5 deg within 0.2 s after 10 N s backwards), and without it nothing turned it
  back. Over the 160 pushes above with 8 s to settle (``--settle 8``), not fallen 80
  and recovered 80 with it, 65 and 57 without (``--set yaw_feedback=false``).
* ``reanchor_stance`` with ``reanchor_min`` 5 mm: at the end of each double support a
  stance sole standing more than 5 mm from the planner's foothold is reported to the
  planner (``MeasuredState.stance_sole``), which moves its foothold o_H there, so its
  ZMP window, its DCM error and the IK's stance target refer to the real foot; nearer
  soles are left to ``foothold_feedback``, so nominal walking is unchanged (the 20 s
  walk's time series is identical). After pushes the adjusted steps land 0.7-5 cm off
  their footholds, and the plan then asked for a CoP up to 7.7 cm outside the real
  sole. On the 64 pushes at phases 0.5625 and 0.25 (``rsg grid --phases 0.5625,0.25``,
  8 s to settle) rsg is not fallen after 22 (21 recovered) and 16 (16) of 32, against
  18 (18) and 16 (16) without (``--set reanchor_stance=false``); over the 160 pushes at
  phases 0.25-0.625, 91 (87) against 80 (80). Re-anchoring every sole (``reanchor_min``
  0) gave 89 (80) and raised the walk's V_u peak from 0.67 to 1.52 gamma_v.
* ``reanchor_time`` 0.2 s: the planner's foothold approaches the measured sole as a
  first-order lag instead of jumping there, so the DCM error moves by the landing offset
  (0.7-5 cm after adjusted steps) over 0.2 s instead of in one tick. On the same 64
  pushes, not fallen (recovered) 24 (24) and 21 (20) of 32, against 22 (21) and 16 (16)
  at once; time constants 0.1 s and 0.4 s gave 26 (24) and 20 (19), 24 (24) and 18 (18).
* ``angular_momentum_rate_max`` 5 N m (the description's default is 3 N m): the
  bound on the RSG's feedback hdot per axis, i.e. a CMP shift of up to 1.5 cm on 33 kg
  beyond what the upper body carries; it also scales hdot in the LQR design, so the ZMP
  gain on the DCM error is 1.45 instead of 1.85 (both effects measured together). On the
  64 pushes at phases 0.5625 and 0.25 rsg
  is not fallen after 28 (28 recovered) and 19 (19) of 32 against 24 (24) and 21 (20)
  with 3 N m; 10 N s at mid single support is recovered in 7 of 8 directions against 5
  (4, 4.5, 5.5 and 6 N m: 5, 7, 7 and 5 of 8). The 20 s walk is unchanged (no
  adjusted step, V_u peak 0.35 gamma_v).
* ``sole_spinning_friction`` 0.01 m: PyBullet's box-on-plane contact touches the sole
  at its corners only, and point contacts resist no turn about the ground normal, so a
  sole standing on one corner (the CoP on a sole corner after a push) spins freely: after
  the second ``paper-fig6`` push the stance soles turned by 10-20 deg within one single
  support. A rubber sole touches over an area: torsional friction of 0.01 m per contact
  point (about 2/3 mu a for a patch of radius a = 1.5 cm) models it. On the 64 pushes at
  phases 0.5625 and 0.25 (``rsg grid --controllers rsg --phases 0.5625,0.25``) rsg is
  not fallen after 31 (31 recovered) and 21 (21) of 32 against 28 (28) and 19 (19) with
  point contacts (``--set sole_spinning_friction=0``), and 10 N s at mid single support
  is recovered in all 8 directions against 7; 0.02 m gave 29 (29) and 21 (21), 6 of 8.
  The 20 s walk is unchanged (README, "Torsional friction under the soles").
* ``locked_joints``: the shoulder yaw, elbow and three wrist joints of each arm are
  welded at their standing angles, in the physics URDF and in the IK (19 actuated
  joints instead of 29). The upper body's flywheel uses the waist and the shoulders'
  pitch and roll, so these joints only held their posture, yet each cost the physics a
  degree of freedom and a motor row of its iterative solver, whose work grows with rows
  times degrees of freedom: a 1 ms physics step of G1 standing took 0.58 times as long
  (README, "Locked arm joints"). Behaviour, with
  ``dcm_inset`` (below), against all joints actuated without it: not fallen on the 64
  pushes at phases 0.5625 and 0.25 54 instead of 53, on the 32 late pushes 26 instead of
  21, 10 N s at mid single support 8 of 8 either way; ``--set locked_joints=none``
  actuates them again.
* ``physics_time_step`` 2 ms (500 Hz) with ``solver_iterations`` 75 and position
  gains 0.4 (legs, waist, arms) and 0.2 (ankles), instead of 1 ms with 50 iterations and
  gains 0.1 and 0.05: physics was three quarters of a control tick, and this halves its
  steps. PyBullet's position gain is per step (the servo's time constant is about
  dt / kp, tested on a one-joint arm), so 0.1 at 1 ms and 0.2 at 2 ms hold the same
  10 ms. At 2 ms with 50 iterations, leg gains (ankles at half) of 0.1 fell in
  ``paper-fig6``; on the 64 pushes at phases 0.5625 and 0.25 0.15, 0.2, 0.3, 0.4, 0.5
  and 0.6 were not fallen after 35, 47, 53, 55, 53 and 53 (1 ms defaults: 54). With 0.4
  and 50 iterations 10 N s at mid single support was recovered in 7 of 8 directions;
  with 75 iterations in 8 of 8, and at phases 0.5, 0.5625 and 0.625 in 21 of 24 (1 ms
  defaults: 20; 50 iterations: 19). Not fallen
  (recovered), against the 1 ms defaults: the 64 pushes 32 + 21 = 53 (53) against 54
  (54); the 32 late pushes 26 (25) against 26; ``paper-fig6`` recovered (17 steps, 6
  adjusted); its variants 12 of 17 against 14 (both pushes shifted by 0, +-10, ..., +-60
  ms or scaled by 0.9, 0.95, 1.05 and 1.1); fixed-timing 25 + 21 against 26 + 19 and
  no-step 13 + 11 against 14 + 11 on the 64 pushes; 1 kHz with the same servo time
  constants (``--set physics_time_step=0.001 --set solver_iterations=50``, gains
  halved) 31 + 23 = 54. The 20 s walk: 24 steps, none adjusted, V_u peak 0.66 gamma_v
  (0.34 at 1 ms). The real-time factor: README, "``rsg bench``".
* ``dcm_inset`` 0.02 m (planner row (27c')): a QP step puts the new sole's centre
  line at least 2 cm outside the predicted DCM. With the arms locked, ``paper-fig6``
  fell at 6.6 s without it and is recovered with it (15 steps, 2 adjusted), and so
  are 7 of its 9 variants (recovered: both pushes shifted by 20, 40 or 60 ms either
  way; fell: scaled by 0.9 and by 1.1) against 4 without; the late pushes 26 against
  21 (README, "Pushes late in single support").
* ``landing_clearance`` 2 mm: a swing sole commanded down to the ground touched it
  30-40 ms before the planner's step, took the whole weight at once (up to 940 N,
  toe first) and kicked the DCM by 1.5-2 cm sideways, i.e. above the RSG's
  threshold (~1.1 cm): an adjusted step. The sole now waits 2 mm above the ground
  and the new stance sole is lowered to it over ``transfer_ramp`` after the step.
  Without it the RSG walk falls at 5.2 s; with it (and the two choices above) the
  20 s walk has no adjusted step and V_u stays below 0.7 gamma_v, for rsg,
  fixed-timing and no-step alike (1, 2 and 3 mm all walk the 20 s).
"""

from __future__ import annotations

from robots.description import JointGains, RobotDescription, SoleRectangle

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

_LEG_GAINS = JointGains(position_gain=0.4, velocity_gain=1.0, max_force=139.0)
_ANKLE_GAINS = JointGains(position_gain=0.2, velocity_gain=1.0, max_force=50.0)
_ARM_GAINS = JointGains(position_gain=0.4, velocity_gain=1.0, max_force=25.0)

JOINT_GAINS = {
    **{
        f"{side}_{joint}_joint": _LEG_GAINS
        for side in ("left", "right")
        for joint in ("hip_pitch", "hip_roll", "hip_yaw", "knee")
    },
    **{
        f"{side}_{joint}_joint": _ANKLE_GAINS
        for side in ("left", "right")
        for joint in ("ankle_pitch", "ankle_roll")
    },
    **{
        f"{side}_{joint}_joint": _ARM_GAINS
        for side in ("left", "right")
        for joint in (
            "shoulder_pitch",
            "shoulder_roll",
            "shoulder_yaw",
            "elbow",
            "wrist_roll",
            "wrist_pitch",
            "wrist_yaw",
        )
    },
}

#: PyBullet backend options tuned on G1 (reasons in the module docstring); Talos
#: walks with them unchanged.
WALKING_OPTIONS = {
    "com_reference_blend": 0.05,
    "com_tracking_gains": (1.0, 0.0),
    "transfer_lift": 0.003,
    "momentum_compensation": 1.0,
    "momentum_filter": 0.05,
    "cop_margin": 0.0,
    "landing_correction": 1.0,
    "landing_clearance": 0.002,
    "swing_acceleration": 20.0,
    "swing_descent_slope": 0.5,
}

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
    foot_spacing=0.23,
    standing_posture=STANDING_POSTURE,
    joint_gains=JOINT_GAINS,
    default_gains=JointGains(position_gain=0.4, velocity_gain=1.0, max_force=88.0),
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
    swing_preparation_time=0.4,
    angular_momentum_rate_max=5.0,
    filter_time_constant=0.01,
    step_reaction_time=0.2,
    reanchor_time=0.2,
    dcm_inset=0.02,
    backend_options={
        **WALKING_OPTIONS,
        "foothold_feedback": True,
        "cop_feedback": (0.0, 2.0),
        "cop_admittance": 0.3,
        "swing_land_on_time": True,
        "upper_body_momentum": 2.0,
        "upper_body_return_time": 0.5,
        "upper_body_cancel": 0.5,
        "yaw_feedback": True,
        "reanchor_stance": True,
        "reanchor_min": 0.005,
    },
)
