"""Snapshots of a recorded run (:class:`app.results.replay.ReplayData`) at any time: the replay
page draws them exactly as the live demo draws its own (:mod:`web.page`).

Pure NumPy: no simulation runs, no viser.
"""

from __future__ import annotations

import numpy as np

from app.results.replay import ROBOT_BASE_COLUMNS, STATE_COLUMNS, ReplayData

from .scene_model import ControllerState, StepMark
from .snapshot import (
    DCM_ERROR_TRAIL_TIME,
    PLOT_TIME,
    STEP_MARKS,
    TRAIL_TIME,
    PageStatus,
    RobotPose,
    Snapshot,
    sole_corners,
)

_COLUMN = {name: index for index, name in enumerate(STATE_COLUMNS)}


def _foot(sigma: float) -> str:
    return "left" if sigma > 0 else "right"


def _window(replay: ReplayData, time: float, length: float) -> slice:
    """Samples in (time - length, time]."""
    end = replay.index_at(time) + 1
    start = int(np.searchsorted(replay.time, time - length + 1e-9, side="right"))
    return slice(min(start, end - 1), end)


def snapshot_at(replay: ReplayData, time: float, serial: int = 0, paused: bool = True) -> Snapshot:
    """What the page shows at ``time`` [s] of the recorded run.

    Args:
        replay: The recorded run.
        time: Replay time [s] (clipped to the recording).
        serial: The snapshot's serial number.
        paused: The replay is paused (for the status).
    """
    meta = replay.meta
    index = replay.index_at(time)
    time = float(replay.time[index])
    row = dict(zip(STATE_COLUMNS, replay.state[index], strict=True))
    com_height = float(meta["com_height"])
    stance_foot = _foot(row["stance_sigma"])
    next_foot = "right" if stance_foot == "left" else "left"
    previous_foot = next_foot
    taken = replay.steps[replay.steps[:, 0] <= time + 1e-9]
    steps = tuple(
        StepMark(float(t), _foot(sigma), np.array([x, y]), bool(adjusted))  # type: ignore[arg-type]
        for t, sigma, x, y, adjusted in taken[-STEP_MARKS:]
    )
    trail = _window(replay, time, TRAIL_TIME)
    com = replay.state[trail][:, [_COLUMN["com_x"], _COLUMN["com_y"]]]
    velocity = replay.state[trail][:, [_COLUMN["com_vx"], _COLUMN["com_vy"]]]
    omega = float(meta["omega"])
    error_trail = _window(replay, time, DCM_ERROR_TRAIL_TIME)
    fell = bool(meta["fell"]) and index == len(replay.time) - 1
    window_min = np.array(meta["zmp_window_min"], float)
    window_max = np.array(meta["zmp_window_max"], float)
    state = ControllerState(
        time=time,
        com=np.array([row["com_x"], row["com_y"]]),
        com_velocity=np.array([row["com_vx"], row["com_vy"]]),
        com_height=com_height,
        omega=omega,
        zmp=np.array([row["zmp_x"], row["zmp_y"]]),
        window_center=np.array([row["window_x"], row["window_y"]]),
        window_min=window_min,
        window_max=window_max,
        stance_foot=stance_foot,  # type: ignore[arg-type]
        stance=np.array([row["stance_x"], row["stance_y"]]),
        previous_foot=previous_foot,  # type: ignore[arg-type]
        previous=np.array([row["previous_x"], row["previous_y"]]),
        next_foot=next_foot,  # type: ignore[arg-type]
        next_step=np.array([row["next_x"], row["next_y"]]),
        steps=steps,
        dcm_error=np.array([row["dcm_error_x"], row["dcm_error_y"]]),
        lyapunov=float(row["lyapunov"]),
        threshold=float(meta["gamma_v"]),
        time_since_step=float(row["time_since_step"]),
        push_impulse=replay.impulse_at(time),
        fell=fell,
        fall_reason=str(meta["fall_reason"]) if fell else "",
        com_trail=com,
        zmp_trail=replay.state[trail][:, [_COLUMN["zmp_x"], _COLUMN["zmp_y"]]],
        dcm_trail=com + velocity / omega,
        dcm_error_trail=replay.state[error_trail][
            :, [_COLUMN["dcm_error_x"], _COLUMN["dcm_error_y"]]
        ],
    )
    plot = _window(replay, time, PLOT_TIME)
    foot_lower, foot_upper = sole_corners(window_min, window_max)
    applied = int(np.sum(replay.pushes[:, 0] <= time + 1e-9))
    return Snapshot(
        serial=serial,
        state=state,
        robot=_robot_pose(replay, index),
        status=PageStatus(
            time=time,
            model=str(meta["model"]),
            robot=str(meta["robot"]),
            controller=str(meta["controller"]),
            paused=paused,
            fell=fell,
            fall_reason=state.fall_reason,
        ),
        plot_time=replay.time[plot],
        plot_lyapunov=replay.state[plot][:, _COLUMN["lyapunov"]],
        plot_time_since_step=replay.state[plot][:, _COLUMN["time_since_step"]],
        level_set=replay.level_set,
        foot_lower=foot_lower,
        foot_upper=foot_upper,
        mass=float(meta["mass"]),
        pushes_applied=applied,
        adjusted_steps=int(np.sum(taken[:, 4] > 0.5)),
        last_push=replay.pushes[applied - 1, 1:3] if applied else None,
    )


def _robot_pose(replay: ReplayData, index: int) -> RobotPose | None:
    if replay.robot is None:
        return None
    values = replay.robot[index].astype(np.float64)
    base = len(ROBOT_BASE_COLUMNS)
    joints = dict(zip(replay.meta["joint_names"], values[base:].tolist(), strict=True))
    return RobotPose(values[:3], values[3:7] / np.linalg.norm(values[3:7]), joints)
