"""The "reality" of a full-robot run: sensor noise, control delay and model errors, drawn
from a profile and a seed.

Profiles (:data:`PROFILES`, default :data:`DEFAULT_PROFILE`):

* ``ideal``: the simulator as the controller's model sees it: no noise, no delay, every
  scale 1, no offset, the description's ground friction;
* ``nominal``: the nominal sensor noise (:data:`NOMINAL_NOISE`) and control delay
  (:data:`NOMINAL_DELAY`) of a G1-class robot, no model error;
* ``randomized``: model errors, delay and a noise level drawn per run, in the ranges of
  humanoid domain randomisation (:data:`LINK_MASS_SCALE` ... :data:`NOISE_SCALE`).

A draw depends only on (profile, seed, names): the same seed gives the same draw, bit for
bit, on any machine and in any worker. The scalar draws come from their own stream,
``numpy.random.default_rng([seed, REALITY_STREAM])``, so they disturb no other random
draw of the run (a push campaign's pushes come from ``default_rng([seed, index])``).
A link's mass factor and a joint's gain factors come from a stream of their own keyed by
the name (:func:`_name_key`), so a factor depends on its name only, not on which other
links or joints the model has (welding a joint does not reshuffle the others).

The sensor noise is Gaussian, independent per sample and per axis, with the standard
deviations of :class:`SensorNoise`; the backend draws those samples from
:meth:`RealityDraw.sample_rng`, a stream of the same seed.

The draw is only data: the backend (:class:`app.backends.pybullet.PyBulletBackend`,
argument ``reality``) applies it. On ``--model lipm`` a profile is accepted and
ignored: the LIPM twin stays ideal.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field, replace

import numpy as np

from planner.exceptions import ParameterError
from robots.description import RobotDescription
from robots.urdf_cache import derived_urdf

PROFILES = ("ideal", "nominal", "randomized")
DEFAULT_PROFILE = "nominal"
#: One line per profile, for ``--help``.
PROFILES_HELP = (
    "ideal (none), nominal (G1-class sensor noise, 2 ms delay), randomized (masses, torso "
    "CoM, friction, gains, delay and noise drawn per run from its seed)"
)

# Streams: the first entropy word after the seed, so that these draws never coincide with
# another stream of the same seed (a campaign's pushes use default_rng([seed, index]) with
# index < 100000).
#: Stream of the scalar draws (torso, CoM, friction, delay, noise level, bias sign).
REALITY_STREAM = 0x5EA117
#: Streams of the per-name factors: link mass, joint stiffness (kp), joint damping (kd).
LINK_MASS_STREAM, STIFFNESS_STREAM, DAMPING_STREAM = 1, 2, 3
#: Stream the backend draws the per-sample sensor noise from (:meth:`RealityDraw.sample_rng`).
SAMPLE_STREAM = 0x5A4D1E

# Nominal sensor noise (standard deviations of Gaussian white noise per sample) and delay.
# Unitree publishes no noise figures for the G1's IMU or joint sensors; where no source is
# given the figure is an engineering estimate, its reasoning on its line.
#: [rad] Joint position: a 14-bit absolute encoder quantises at 2 pi / 16384 = 0.0004 rad;
#: 0.001 rad leaves room for the gear's play (engineering estimate).
NOMINAL_JOINT_POSITION = 0.001
#: [rad/s] Joint velocity: the motor driver's filtered estimate, about 1 % of a swing
#: leg's joint speed (engineering estimate).
NOMINAL_JOINT_VELOCITY = 0.02
#: [N m] Joint torque: unitree_sdk2's ``tau_est`` is estimated from the motor current;
#: current-sensor noise and unmodelled friction, about 0.5 % of a leg motor's peak torque
#: (engineering estimate).
NOMINAL_JOINT_TORQUE = 0.5
#: [rad/s] Gyroscope: a consumer MEMS gyroscope's noise density, 0.014 deg/s/sqrt(Hz)
#: (Bosch BMG160, as listed in Bosch's CISS manual), over the 250 Hz band of 500 Hz
#: samples is 0.0039 rad/s; rounded up (the G1's IMU model is not published).
NOMINAL_GYROSCOPE = 0.005
#: [m/s^2] Accelerometer: 120 ug/sqrt(Hz) (Bosch BMA280, same manual) over 250 Hz is
#: 0.019 m/s^2; 0.05 allows for the structure's vibration while walking (estimate).
NOMINAL_ACCELEROMETER = 0.05
#: [rad] Roll and pitch of the IMU's attitude estimate: 0.3 deg, what a gravity-aided
#: attitude filter holds while walking (engineering estimate).
NOMINAL_ORIENTATION = 0.005
#: [rad/s] Gyroscope yaw bias left after a standstill calibration (the BMG160's
#: uncalibrated zero-rate offset is up to 1 deg/s): 0.0005 rad/s, a yaw integrated from
#: the gyroscope drifts 1.7 deg/min (engineering estimate).
NOMINAL_GYRO_YAW_BIAS = 0.0005
#: [N] Foot force sensors (robots with ankle force-torque sensors, e.g. Talos; G1 has
#: none): 5 N, about 1 % of the load on a foot (engineering estimate).
NOMINAL_FOOT_FORCE = 5.0
#: [s] Control delay: one cycle of the G1's 500 Hz low level (unitree_sdk2's G1
#: low-level examples: ``control_dt_ = 0.002``).
NOMINAL_DELAY = 0.002

# Ranges of the randomized profile, each U(low, high) per run.
#: [-] Factor on each link's mass: mujoco_playground's G1 joystick env
#: (locomotion/g1/randomize.py, "Scale all link masses: *U(0.9, 1.1)"); holosoma's G1
#: locomotion preset uses (0.9, 1.2).
LINK_MASS_SCALE = (0.9, 1.1)
#: [kg] Mass added to the torso link: holosoma (Amazon FAR), G1 locomotion randomisation,
#: ``added_mass_range [-1.0, 3.0]`` on the torso.
TORSO_ADDED_MASS = (-1.0, 3.0)
#: [m] Offset of the torso link's CoM, each axis: holosoma, ``base_com_range`` +-0.05 m
#: on x, y and z (applied to the torso).
COM_OFFSET = (-0.05, 0.05)
#: [-] Ground (and sole) friction coefficient, absolute: mujoco_playground's G1 joystick
#: env ("Floor / foot friction: =U(0.4, 1.0)").
GROUND_FRICTION = (0.4, 1.0)
#: [-] Factor on each joint's kp and on its kd, drawn apart: holosoma, ``kp_range`` and
#: ``kd_range`` [0.9, 1.1].
GAIN_SCALE = (0.9, 1.1)
#: [s] Control delay: holosoma, ``ctrl_delay_step_range [0, 1]`` policy steps of 20 ms
#: (200 Hz simulation, decimation 4), here continuous.
DELAY = (0.0, 0.020)
#: [-] One factor per run on every nominal noise figure (engineering choice: from a
#: noiseless robot to one twice as noisy as the nominal).
NOISE_SCALE = (0.0, 2.0)


@dataclass(frozen=True)
class SensorNoise:
    """Standard deviations of the Gaussian noise on each measurement, per sample and axis.

    Attributes:
        joint_position: [rad] Encoder angle.
        joint_velocity: [rad/s] Joint speed.
        joint_torque: [N m] Joint torque estimate.
        gyroscope: [rad/s] Angular velocity of the IMU.
        accelerometer: [m/s^2] Specific force of the IMU.
        orientation: [rad] Roll and pitch error of the IMU's attitude.
        gyro_yaw_bias: [rad/s] Magnitude of the gyroscope's constant yaw bias; a run's
            signed bias is :attr:`RealityDraw.gyro_yaw_bias` (the yaw integrated from the
            gyroscope drifts at that rate).
        foot_force: [N] Foot force-torque sensors' forces (robots that have them).
    """

    joint_position: float = 0.0
    joint_velocity: float = 0.0
    joint_torque: float = 0.0
    gyroscope: float = 0.0
    accelerometer: float = 0.0
    orientation: float = 0.0
    gyro_yaw_bias: float = 0.0
    foot_force: float = 0.0

    def __post_init__(self) -> None:
        for name, value in asdict(self).items():
            if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0.0):
                raise ParameterError(f"noise.{name}", value, "a finite standard deviation >= 0")

    def scaled(self, factor: float) -> SensorNoise:
        """Every figure times ``factor`` (>= 0)."""
        return SensorNoise(**{name: value * factor for name, value in asdict(self).items()})


#: The nominal sensor noise (module constants above).
NOMINAL_NOISE = SensorNoise(
    joint_position=NOMINAL_JOINT_POSITION,
    joint_velocity=NOMINAL_JOINT_VELOCITY,
    joint_torque=NOMINAL_JOINT_TORQUE,
    gyroscope=NOMINAL_GYROSCOPE,
    accelerometer=NOMINAL_ACCELEROMETER,
    orientation=NOMINAL_ORIENTATION,
    gyro_yaw_bias=NOMINAL_GYRO_YAW_BIAS,
    foot_force=NOMINAL_FOOT_FORCE,
)

#: Units of :meth:`RealityDraw.as_dict`'s fields, written beside them.
UNITS = {
    "delay": "s",
    "torso_added_mass": "kg",
    "com_offset": "m",
    "ground_friction": "-",
    "gyro_yaw_bias": "rad/s",
    "noise": "standard deviations: joint_position rad, joint_velocity rad/s, joint_torque N m, "
    "gyroscope rad/s, accelerometer m/s^2, orientation rad, gyro_yaw_bias rad/s, foot_force N",
    "scales": "factors on the nominal link mass, joint kp (stiffness) and kd (damping)",
}


@dataclass(frozen=True)
class RealityDraw:
    """One run's reality: what the backend applies between the simulator and the
    controller.

    Attributes:
        profile: One of :data:`PROFILES`.
        seed: The seed it was drawn from (>= 0); also seeds :meth:`sample_rng`.
        noise: Standard deviations of the sensor noise.
        noise_scale: [-] Factor of ``noise`` on :data:`NOMINAL_NOISE` (0 on ``ideal``).
        delay: [s] Control delay: commands reach the motors this late.
        gyro_yaw_bias: [rad/s] This run's constant gyroscope yaw bias (signed).
        link_mass_scale: Link name -> factor on its mass [-].
        torso_link: The link ``torso_added_mass`` and ``com_offset`` apply to.
        torso_added_mass: [kg] Mass added to the torso link.
        com_offset: [m] Offset of the torso link's CoM, in its frame (x, y, z).
        ground_friction: [-] Friction coefficient of the ground and soles (absolute).
        stiffness_scale: Joint name -> factor on its kp [-].
        damping_scale: Joint name -> factor on its kd [-].
    """

    profile: str
    seed: int
    noise: SensorNoise = field(default_factory=SensorNoise)
    noise_scale: float = 0.0
    delay: float = 0.0
    gyro_yaw_bias: float = 0.0
    link_mass_scale: dict[str, float] = field(default_factory=dict)
    torso_link: str = ""
    torso_added_mass: float = 0.0
    com_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    ground_friction: float = 1.0
    stiffness_scale: dict[str, float] = field(default_factory=dict)
    damping_scale: dict[str, float] = field(default_factory=dict)

    @property
    def model_error(self) -> bool:
        """The model differs from the description (a scale not 1, an added mass, a CoM
        offset); the ground friction is not counted (``nominal_friction`` of
        :func:`draw_reality` may differ from the description's)."""
        scales = (*self.link_mass_scale.values(), *self.stiffness_scale.values(),
                  *self.damping_scale.values())  # fmt: skip
        return (
            any(s != 1.0 for s in scales)
            or self.torso_added_mass != 0.0
            or any(c != 0.0 for c in self.com_offset)
        )

    def sample_rng(self) -> np.random.Generator:
        """A fresh generator for the per-sample sensor noise of this run: the same
        sequence on every call (a backend re-created or reset with the same draw sees the
        same noise), independent of the draw's own stream."""
        return np.random.default_rng([self.seed, SAMPLE_STREAM])

    def as_dict(self) -> dict:
        """Plain JSON types (for summary.json and the experiments' records)."""
        return {
            "profile": self.profile,
            "seed": int(self.seed),
            "noise": {name: float(value) for name, value in asdict(self.noise).items()},
            "noise_scale": float(self.noise_scale),
            "delay": float(self.delay),
            "gyro_yaw_bias": float(self.gyro_yaw_bias),
            "link_mass_scale": {k: float(v) for k, v in self.link_mass_scale.items()},
            "torso_link": self.torso_link,
            "torso_added_mass": float(self.torso_added_mass),
            "com_offset": [float(c) for c in self.com_offset],
            "ground_friction": float(self.ground_friction),
            "stiffness_scale": {k: float(v) for k, v in self.stiffness_scale.items()},
            "damping_scale": {k: float(v) for k, v in self.damping_scale.items()},
            "units": dict(UNITS),
        }

    def describe(self) -> str:
        """One line for logs."""
        if self.profile == "ideal":
            return "reality ideal: no sensor noise, no control delay, the model as built"
        noise = self.noise
        sensors = (
            f"sensor noise x{self.noise_scale:.2f} of nominal (gyro {noise.gyroscope:.4f} "
            f"rad/s, joints {noise.joint_position:.4f} rad), gyro yaw bias "
            f"{self.gyro_yaw_bias:+.5f} rad/s, control delay {1000 * self.delay:.1f} ms"
        )
        if self.profile == "nominal":
            return f"reality nominal: {sensors}, no model error"
        x, y, z = self.com_offset
        return (
            f"reality randomized (seed {self.seed}): {sensors}, ground friction "
            f"{self.ground_friction:.2f}, {self.torso_link} {self.torso_added_mass:+.2f} kg, "
            f"CoM offset ({x:+.3f}, {y:+.3f}, {z:+.3f}) m, link masses "
            f"{_span(self.link_mass_scale)}, kp {_span(self.stiffness_scale)}, kd "
            f"{_span(self.damping_scale)}"
        )


def _span(scales: Mapping[str, float]) -> str:
    """``x0.91-1.09`` (the smallest and largest factor), ``-`` when empty."""
    if not scales:
        return "-"
    return f"x{min(scales.values()):.2f}-{max(scales.values()):.2f}"


def check_profile(profile: object) -> str:
    """``profile`` if it is one of :data:`PROFILES`.

    Raises:
        ParameterError: Otherwise, naming the field ``reality``.
    """
    if not (isinstance(profile, str) and profile in PROFILES):
        raise ParameterError("reality", profile, f"one of {', '.join(PROFILES)}")
    return profile


def _check_seed(seed: object, name: str = "seed") -> int:
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ParameterError(name, seed, "an integer >= 0")
    return int(seed)


def trial_seed(seed: int, *keys: int) -> int:
    """A seed in [0, 2^63) for the trial ``keys`` (integers >= 0, e.g. a push's index) of
    the experiment seeded ``seed``: deterministic, and different trials draw independent
    realities (``numpy.random.SeedSequence`` mixes the words).

    Raises:
        ParameterError: A negative or non-integer seed or key.
    """
    # The number of keys comes first: SeedSequence pads its entropy with zeros, so
    # (seed) and (seed, 0) would otherwise give the same seed.
    words = [_check_seed(seed), len(keys), *(_check_seed(key, "trial key") for key in keys)]
    state = np.random.SeedSequence(words).generate_state(1, np.uint64)
    return int(state[0] >> np.uint64(1))


def _name_key(name: str) -> int:
    """A stable integer of ``name`` (CRC-32 of its UTF-8 bytes; Python's ``hash`` of a
    string changes between processes)."""
    return zlib.crc32(name.encode("utf-8"))


def _per_name(
    seed: int, stream: int, names: Sequence[str], low: float, high: float
) -> dict[str, float]:
    """name -> U(low, high), each from the generator of (seed, stream, name)."""
    return {
        name: float(
            np.random.default_rng([seed, REALITY_STREAM, stream, _name_key(name)]).uniform(
                low, high
            )
        )
        for name in names
    }


def draw_reality(
    profile: str,
    seed: int,
    link_names: Sequence[str],
    joint_names: Sequence[str],
    torso_link: str,
    nominal_friction: float,
) -> RealityDraw:
    """The reality of one run.

    Args:
        profile: One of :data:`PROFILES`.
        seed: Seed of the draw (>= 0); the same seed gives the same draw, bit for bit.
        link_names: The physics model's links (mass factors are drawn for each).
        joint_names: Its actuated joints (kp and kd factors are drawn for each).
        torso_link: The link that gets the added mass and the CoM offset (one of
            ``link_names``).
        nominal_friction: [-] The description's ground friction, kept by ``ideal`` and
            ``nominal`` (``randomized`` draws an absolute coefficient).

    ``nominal`` keeps the model as built, with :data:`NOMINAL_NOISE`, :data:`NOMINAL_DELAY`
    and a gyroscope yaw bias of +:data:`NOMINAL_GYRO_YAW_BIAS`; ``randomized`` draws a
    bias of the run's noise figure with a random sign.

    Raises:
        ParameterError: An unknown profile (field ``reality``), a negative seed, a torso
            link that is not among ``link_names``, or a friction that is not > 0.
    """
    check_profile(profile)
    seed = _check_seed(seed)
    links, joints = tuple(link_names), tuple(joint_names)
    if torso_link not in links:
        raise ParameterError("torso_link", torso_link, f"one of the links {', '.join(links)}")
    if not (math.isfinite(nominal_friction) and nominal_friction > 0.0):
        raise ParameterError("ground_friction", nominal_friction, "a friction coefficient > 0")
    ideal = RealityDraw(
        profile=profile,
        seed=seed,
        link_mass_scale=dict.fromkeys(links, 1.0),
        torso_link=torso_link,
        ground_friction=float(nominal_friction),
        stiffness_scale=dict.fromkeys(joints, 1.0),
        damping_scale=dict.fromkeys(joints, 1.0),
    )
    if profile == "ideal":
        return ideal
    if profile == "nominal":
        return replace(
            ideal,
            noise=NOMINAL_NOISE,
            noise_scale=1.0,
            delay=NOMINAL_DELAY,
            gyro_yaw_bias=NOMINAL_NOISE.gyro_yaw_bias,
        )
    rng = np.random.default_rng([seed, REALITY_STREAM])
    # Scalars in a fixed order: a new draw is appended at the end, so older ones keep
    # their values.
    torso_added_mass = float(rng.uniform(*TORSO_ADDED_MASS))
    x, y, z = (float(v) for v in rng.uniform(*COM_OFFSET, size=3))
    ground_friction = float(rng.uniform(*GROUND_FRICTION))
    delay = float(rng.uniform(*DELAY))
    noise_scale = float(rng.uniform(*NOISE_SCALE))
    sign = 1.0 if rng.uniform() < 0.5 else -1.0
    noise = NOMINAL_NOISE.scaled(noise_scale)
    return RealityDraw(
        profile=profile,
        seed=seed,
        noise=noise,
        noise_scale=noise_scale,
        delay=delay,
        gyro_yaw_bias=sign * noise.gyro_yaw_bias,
        link_mass_scale=_per_name(seed, LINK_MASS_STREAM, links, *LINK_MASS_SCALE),
        torso_link=torso_link,
        torso_added_mass=torso_added_mass,
        com_offset=(x, y, z),
        ground_friction=ground_friction,
        stiffness_scale=_per_name(seed, STIFFNESS_STREAM, joints, *GAIN_SCALE),
        damping_scale=_per_name(seed, DAMPING_STREAM, joints, *GAIN_SCALE),
    )


def physics_links(description: RobotDescription) -> tuple[str, ...]:
    """The links with mass of ``description``'s physics model, in its URDF's order: those
    of the derived URDF with the locked joints welded and the fixed links merged
    (:func:`robots.urdf_cache.derived_urdf`, ``merged=True``), the bodies PyBullet loads.

    Raises:
        RobotDataError: The robot's URDF is not installed.
    """
    root = ET.parse(derived_urdf(description, merged=True)).getroot()
    return tuple(
        str(link.get("name")) for link in root.iter("link") if link.find("inertial") is not None
    )


def robot_reality(description: RobotDescription, profile: str, seed: int) -> RealityDraw:
    """The reality ``profile`` (:mod:`app.reality`) of ``description`` drawn from ``seed``:
    mass factors over its physics links (:func:`physics_links`), gain factors over its
    actuated joints (those with gains that are not locked), the added mass and CoM
    offset on its trunk link, its ground friction as the nominal one. The same
    description, profile and seed give the same draw, bit for bit.

    Raises:
        ParameterError: An unknown profile (``reality``) or a negative seed.
    """
    locked = set(description.locked_joints)
    joints = [name for name in description.joint_impedance if name not in locked]
    return draw_reality(
        profile,
        seed,
        physics_links(description),
        joints,
        description.trunk_link,
        description.ground_friction,
    )
