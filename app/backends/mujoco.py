"""The full-humanoid backend on MuJoCo: PyBullet's backend with the MuJoCo plant.

The controller, the command stream, the drivers' law and the sensors are the same
(:class:`app.backends.pybullet.PyBulletBackend`, :class:`app.backends.plant.Plant`); only
the engine that moves the robot differs (:class:`app.backends.mujoco_robot.MujocoRobot`).
"""

from __future__ import annotations

from app.backends.mujoco_robot import MujocoRobot
from app.backends.plant import Plant
from app.backends.pybullet import PyBulletBackend


class MujocoBackend(PyBulletBackend):
    """A full humanoid in MuJoCo implementing :class:`app.backends.base.Backend`
    (arguments and attributes: :class:`app.backends.pybullet.PyBulletBackend`).

    Attributes:
        name: ``"mujoco"``.
    """

    name = "mujoco"
    plant: type[Plant] = MujocoRobot
