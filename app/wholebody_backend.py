"""Full-humanoid backend with torque-controlled joints (development version)."""

from __future__ import annotations

import time as clock
from collections import defaultdict

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from kinematics.swing_foot import SwingTiming
from kinematics.whole_body_ik import sole_pose
from planner.exceptions import ParameterError
from planner.types import MeasuredState, PlannerOutput, Vector2
from robots import get_robot
from robots.description import RobotDescription
from robots.urdf_cache import locked_angles

from .backend import FallStatus, InitialCondition
from .pybullet_robot import SimulatedRobot
from .stabilizer.controller import ControllerOptions, WholeBodyController

INITIAL_VELOCITY_HORIZON = 0.01  # [s]


class WholeBodyBackend:
    name = "pybullet"

    def __init__(
        self,
        robot: str | RobotDescription = "g1",
        control_period: float = 0.01,
        timing: SwingTiming | None = None,
        options: ControllerOptions | None = None,
        **_: object,
    ) -> None:
        self.description = robot if isinstance(robot, RobotDescription) else get_robot(robot)
        self._locked_angles = locked_angles(self.description)
        physics_step = self.description.physics_time_step
        substeps = round(control_period / physics_step)
        if substeps < 1 or abs(substeps * physics_step - control_period) > 1e-9:
            raise ParameterError(
                "control_period/physics_time_step",
                (control_period, physics_step),
                "a control period that is a whole multiple of the physics step [s]",
            )
        self.control_period = control_period
        self._substeps = substeps
        self.sim = SimulatedRobot(self.description, torque_control=True)
        self.mass = self.sim.mass
        self.com_height = self.description.com_height
        self.options = options or ControllerOptions()
        self._timing = timing or SwingTiming()
        self.controller = WholeBodyController(
            self.description, self._timing, control_period, self.options
        )
        self.timers: dict[str, float] = defaultdict(float)
        self.ticks = 0
        self.physics_log = None
        self._measured: MeasuredState | None = None

    @property
    def timing(self) -> SwingTiming:
        return self._timing

    @timing.setter
    def timing(self, value: SwingTiming) -> None:
        self._timing = value
        self.controller.timing = value
        self.controller.swing.timing = value

    @property
    def swing(self):  # noqa: ANN201 (build_robot_backend sets swing.timing)
        return self.controller.swing

    def reset(self, initial: InitialCondition) -> MeasuredState:
        controller = self.controller
        stance = initial.stance.foot
        soles = {
            stance: sole_pose(np.array([*initial.stance.position, 0.0])),
            initial.swing.foot: sole_pose(np.array([*initial.swing.position, 0.0])),
        }
        com_xy = np.asarray(initial.com_position, float)
        com_velocity = np.asarray(initial.com_velocity, float)
        ik = controller.ik
        q0 = ik.reset(soles["left"], soles["right"], com_xy)
        base0 = np.asarray(ik.robot.get_T_world_fbase(), float).copy()
        base_velocity = np.zeros(3)
        base_angular_velocity = np.zeros(3)
        joint_velocity = np.zeros_like(q0)
        if np.any(com_velocity):
            h = INITIAL_VELOCITY_HORIZON
            q1 = ik.solve(com_xy + h * com_velocity, soles["left"], soles["right"], "both", h)
            base1 = np.asarray(ik.robot.get_T_world_fbase(), float)
            base_velocity = (base1[:3, 3] - base0[:3, 3]) / h
            base_angular_velocity = Rotation.from_matrix(base1[:3, :3] @ base0[:3, :3].T).as_rotvec() / h
            joint_velocity = (q1 - q0) / h
        target = controller.reset(soles[stance], soles[initial.swing.foot], stance, com_xy)
        names = ik.joint_names
        self.sim.set_configuration(
            base0[:3, 3],
            Rotation.from_matrix(base0[:3, :3]).as_quat(),
            dict(zip(names, q0, strict=True)),
            base_velocity,
            base_angular_velocity,
            dict(zip(names, joint_velocity, strict=True)),
        )
        self.sim.time = 0.0
        self.sim.set_motor_target(target)
        self.timers.clear()
        self.ticks = 0
        measurement = self.sim.measure()
        self._measurement = measurement
        controller.state = controller.estimator.update(measurement, stance)
        controller._stance_sole_report = None
        controller._report_touchdown = None
        self._measured = controller.planner_state()
        return self._measured

    def step(self, command: PlannerOutput, push_force: Vector2) -> MeasuredState:
        start = clock.perf_counter()
        measurement = self._measurement
        joint_command = self.controller.tick(measurement, command)
        controlled = clock.perf_counter()
        force = np.array([push_force[0], push_force[1], 0.0]) if any(push_force) else None
        self.sim.actuate(
            joint_command, measurement, self._substeps, self.controller.expected_contact_force, force
        )
        stepped = clock.perf_counter()
        self._measurement = self.sim.measure()
        self._measured = self.controller.observe(self._measurement, command.stance.foot)
        self.timers["control"] += controlled - start
        self.timers["physics"] += stepped - controlled
        self.ticks += 1
        return self._measured

    def fall_status(self) -> FallStatus:
        if self.controller.ik_failure is not None:
            return FallStatus(True, self.controller.ik_failure)
        position, quaternion = self.sim.base_pose()
        if position[2] < self.description.fall_base_height:
            return FallStatus(True, f"pelvis height {position[2]:.3f} m")
        x, y = quaternion[0], quaternion[1]
        tilt = float(np.arccos(np.clip(1.0 - 2.0 * (x * x + y * y), -1.0, 1.0)))
        if tilt > self.description.fall_tilt:
            return FallStatus(True, f"pelvis tilt {np.degrees(tilt):.0f} deg")
        others = self.sim.ground_contacts() - set(self.sim.foot_links.values())
        if others:
            names = sorted(self.sim.link_name(link) for link in others)
            return FallStatus(True, f"ground contact of {', '.join(names)}")
        return FallStatus(False)

    @property
    def planned_cop(self) -> NDArray[np.float64]:
        return self.controller.planned_cop

    def foot_pressure(self):  # noqa: ANN201
        return self.sim.foot_pressure()

    def feet_in_contact(self) -> set[str]:
        return self.sim.feet_in_contact()

    def robot_configuration(self):  # noqa: ANN201
        position, quaternion = self.sim.base_pose()
        return position, quaternion, {**self._locked_angles, **self.sim.joint_angles()}

    def sole_positions(self) -> dict[str, NDArray[np.float64]]:
        return {foot: self.sim.sole_position(foot) for foot in ("left", "right")}

    def timing_report(self) -> dict[str, float]:
        ticks = max(self.ticks, 1)
        report = {key: value / ticks for key, value in self.timers.items()}
        report["total"] = sum(report.values())
        return report

    def close(self) -> None:
        self.sim.close()
