"""Replay data of a run: what ``rsg replay`` needs to show the run again in the browser.

Every ``rsg run`` writes ``replay.npz`` next to its results: the controller's state
(CoM, ZMP, window centre, footholds, DCM error, V_u, s~) and, on the full robot, its
configuration (base pose and joint angles) every :data:`RECORD_PERIOD`, plus the
steps, the pushes, the fall and the constants the page draws with (ZMP window,
P_u, gamma_v). No simulation runs in replay. The file is a compressed NumPy archive
(float32 samples; a 20 s G1 run is about 0.4 MB) written to a temporary file and
renamed, so an interrupted run leaves either a complete file or none.

(viser's own ``.viser`` recordings hold the scene only, not the page's plots, and
every file would carry the robot's 5 MB of meshes; ``app`` never imports viser.)
"""

from __future__ import annotations

import json
import os
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from app.runner import TIMESERIES_COLUMNS, ClosedLoop, RunResult
from planner.exceptions import RsgError
from planner.lyapunov import level_set
from planner.types import PlannerOutput, sigma_of

REPLAY_FILE = "replay.npz"
FORMAT_VERSION = 1
RECORD_PERIOD = 0.01  # [s] sampling period of the replay (the page draws at most 40 Hz)
STATE_COLUMNS = (
    "com_x", "com_y", "com_vx", "com_vy", "zmp_x", "zmp_y", "window_x", "window_y",
    "stance_sigma", "stance_x", "stance_y", "previous_x", "previous_y", "next_x", "next_y",
    "dcm_error_x", "dcm_error_y", "lyapunov", "time_since_step",
)  # fmt: skip
ROBOT_BASE_COLUMNS = ("base_x", "base_y", "base_z", "base_qw", "base_qx", "base_qy", "base_qz")
META_FIELDS = {
    "format": int,
    "model": str,
    "robot": str,
    "controller": str,
    "scenario": str,
    "mass": float,
    "com_height": float,
    "omega": float,
    "gamma_v": float,
    "lyapunov_matrix": list,
    "zmp_window_min": list,
    "zmp_window_max": list,
    "joint_names": list,
    "fell": bool,
    "fall_reason": str,
    "sim_time": float,
    "record_period": float,
}


class ReplayError(RsgError):
    """A folder holds no usable replay.

    Attributes:
        path: The folder or file.
        reason: What is wrong.
    """

    def __init__(self, path: Path, reason: str) -> None:
        self.path = path
        self.reason = reason
        super().__init__(f"{path}: {reason}")

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (self.path, self.reason))


class ReplayRecorder:
    """Samples the closed loop for a replay; pass it as ``on_tick`` to
    :func:`app.runner.run_closed_loop`.

    Each sample holds the tick's measured CoM state and planner output; the robot's
    configuration is the one after the tick (one control period later).

    Args:
        period: Sampling period [s] (rounded to whole control ticks).
    """

    def __init__(self, period: float = RECORD_PERIOD) -> None:
        self.period = period
        self._times: list[float] = []
        self._states: list[list[float]] = []
        self._robot: list[np.ndarray] = []
        self.joint_names: list[str] = []

    def __call__(self, loop: ClosedLoop, out: PlannerOutput) -> None:
        every = max(1, round(self.period / loop.period))
        last = loop.backend.fall_status().fell
        if (loop.ticks - 1) % every and not last:
            return
        row = loop.rows[loop.ticks - 1]  # the tick's time series: the state it planned from
        com = row[[TIMESERIES_COLUMNS.index(name) for name in ("com_x", "com_y")]]
        velocity = row[[TIMESERIES_COLUMNS.index(name) for name in ("com_vx", "com_vy")]]
        self._times.append(float(out.time))
        self._states.append(
            [
                *com,
                *velocity,
                *out.zmp,
                *out.window_center,
                sigma_of(out.stance.foot),
                *out.stance.position,
                *out.previous_stance.position,
                *out.next_step.position,
                *out.dcm_error,
                out.lyapunov,
                out.time_since_step,
            ]  # fmt: skip
        )
        configuration = getattr(loop.backend, "robot_configuration", None)
        if configuration is not None:
            position, quaternion_xyzw, joints = configuration()
            if not self.joint_names:
                self.joint_names = sorted(joints)
            x, y, z, w = (float(v) for v in quaternion_xyzw)
            angles = [joints[name] for name in self.joint_names]
            self._robot.append(np.array([*position, w, x, y, z, *angles], dtype=np.float32))

    def __len__(self) -> int:
        return len(self._times)

    def write(self, result: RunResult, controller: str, robot: str | None, out_dir: Path) -> Path:
        """Write ``replay.npz`` of ``result`` into ``out_dir`` atomically; returns its path.

        Raises:
            RsgError: The folder cannot be written.
        """
        constraints = result.config.constraints
        meta = {
            "format": FORMAT_VERSION,
            "model": result.backend,
            "robot": robot or "",
            "controller": controller,
            "scenario": result.scenario.name,
            "mass": float(result.mass),
            "com_height": float(result.com_height),
            "omega": float(result.config.model.omega),
            "gamma_v": float(result.lyapunov_threshold),
            "lyapunov_matrix": np.asarray(result.extra["lyapunov_matrix"], float).tolist(),
            "zmp_window_min": [float(v) for v in constraints.zmp_window_min],
            "zmp_window_max": [float(v) for v in constraints.zmp_window_max],
            "joint_names": list(self.joint_names),
            "fell": bool(result.fall.fell),
            "fall_reason": result.fall.reason,
            "sim_time": float(result.sim_time),
            "record_period": float(self.period),
        }
        steps = np.array(
            [
                [s.event["t"], sigma_of(s.event["foot"]), *s.event["position"], s.event["adjusted"]]
                for s in result.steps
            ],
            dtype=np.float64,
        ).reshape(-1, 5)
        pushes = np.array(
            [[p.time, *np.asarray(p.impulse, float), p.duration] for p in result.scenario.pushes],
            dtype=np.float64,
        ).reshape(-1, 4)
        arrays: dict[str, Any] = {
            "meta": np.array(json.dumps(meta)),
            "time": np.array(self._times, dtype=np.float64),
            "state": np.array(self._states, dtype=np.float32).reshape(-1, len(STATE_COLUMNS)),
            "steps": steps,
            "pushes": pushes,
        }
        if self._robot:
            arrays["robot"] = np.stack(self._robot)
        target = out_dir / REPLAY_FILE
        try:
            out_dir.mkdir(parents=True, exist_ok=True)
            temporary = out_dir / f".{REPLAY_FILE}.{os.getpid()}.tmp"
            try:
                with temporary.open("wb") as handle:
                    np.savez_compressed(handle, **arrays)
                os.replace(temporary, target)
            finally:
                temporary.unlink(missing_ok=True)
        except OSError as exc:
            raise RsgError(f"cannot write the replay to {target}: {exc}") from exc
        return target


@dataclass(frozen=True)
class ReplayData:
    """A run loaded for replay (see :class:`ReplayRecorder` for what is sampled).

    Attributes:
        meta: Run constants (model, robot, controller, gamma_v, P_u, ZMP window, fall, ...).
        time: Sample times [s], increasing, shape (n,).
        state: Controller state, shape (n, len(STATE_COLUMNS)) [m, s, V_u units].
        robot: Base position [m], base quaternion (w, x, y, z) and joint angles [rad]
            (``meta["joint_names"]``), shape (n, 7 + joints), or None on the LIPM.
        steps: Steps: time [s], foot sigma (+1 left), position x, y [m], adjusted, shape (m, 5).
        pushes: Pushes: start [s], impulse x, y [N s], duration [s], shape (p, 4).
    """

    meta: dict
    time: np.ndarray
    state: np.ndarray
    robot: np.ndarray | None
    steps: np.ndarray
    pushes: np.ndarray

    def column(self, name: str) -> np.ndarray:
        """One column of :attr:`state`."""
        return self.state[:, STATE_COLUMNS.index(name)]

    @property
    def duration(self) -> float:
        """Time of the last sample [s]."""
        return float(self.time[-1])

    def index_at(self, time: float) -> int:
        """Index of the last sample at or before ``time`` [s] (the first before the start)."""
        index = int(np.searchsorted(self.time, time + 1e-9, side="right")) - 1  # float times
        return min(max(index, 0), len(self.time) - 1)

    def impulse_at(self, time: float) -> np.ndarray | None:
        """Total impulse [N s] of the pushes acting at ``time`` [s], or None."""
        acting = [p for p in self.pushes if p[0] <= time < p[0] + p[3]]
        return np.sum([p[1:3] for p in acting], axis=0) if acting else None

    def level_set(self, level: float, count: int = 100) -> np.ndarray:
        """Points e_u on {V_u = level}, shape (count, 2) [m] (from P_u)."""
        return level_set(np.asarray(self.meta["lyapunov_matrix"], float), level, count)


def load_replay(folder: Path) -> ReplayData:
    """The replay of the run in ``folder``.

    Raises:
        ReplayError: The folder is missing, holds no ``replay.npz``, or the file is
            not a complete replay of this format.
    """
    if not folder.exists():
        raise ReplayError(folder, "no such folder")
    if not folder.is_dir():
        raise ReplayError(folder, "not a folder (give the --out folder of rsg run)")
    path = folder / REPLAY_FILE
    if not path.is_file():
        raise ReplayError(
            folder, f"no {REPLAY_FILE}: not a run folder written by rsg run (give its --out)"
        )
    try:
        with np.load(path, allow_pickle=False) as archive:
            arrays = {name: archive[name] for name in archive.files}
        meta = json.loads(str(arrays["meta"]))
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
        raise ReplayError(path, f"not a readable replay ({exc})") from None
    return _checked(path, meta, arrays)


def _checked(path: Path, meta: Any, arrays: dict[str, np.ndarray]) -> ReplayData:
    if not isinstance(meta, dict):
        raise ReplayError(path, "its metadata is not a JSON object")
    if meta.get("format") != FORMAT_VERSION:
        raise ReplayError(
            path, f"replay format {meta.get('format')!r}, this rsg reads {FORMAT_VERSION}"
        )
    for name, kind in META_FIELDS.items():
        value = meta.get(name)
        if not isinstance(value, kind) and not (kind is float and isinstance(value, int)):
            raise ReplayError(path, f"metadata {name}={value!r}: expected {kind.__name__}")
    missing = [name for name in ("time", "state", "steps", "pushes") if name not in arrays]
    if missing:
        raise ReplayError(path, f"missing arrays {missing}")
    time, state = arrays["time"], arrays["state"]
    count = len(time)
    if time.ndim != 1 or count < 1 or not np.all(np.isfinite(time)) or np.any(np.diff(time) < 0):
        raise ReplayError(path, "sample times are not an increasing series of numbers")
    if state.shape != (count, len(STATE_COLUMNS)) or not np.all(np.isfinite(state)):
        raise ReplayError(path, f"state has shape {state.shape}, expected ({count}, 19)")
    robot = arrays.get("robot")
    if robot is not None:
        width = len(ROBOT_BASE_COLUMNS) + len(meta["joint_names"])
        if robot.shape != (count, width) or not np.all(np.isfinite(robot)):
            raise ReplayError(path, f"robot has shape {robot.shape}, expected ({count}, {width})")
    steps, pushes = arrays["steps"], arrays["pushes"]
    if steps.ndim != 2 or steps.shape[1] != 5 or pushes.ndim != 2 or pushes.shape[1] != 4:
        raise ReplayError(path, "steps or pushes have the wrong shape")
    matrix = np.asarray(meta["lyapunov_matrix"], dtype=float)
    if matrix.shape != (2, 2) or not np.all(np.linalg.eigvalsh(matrix) > 0.0):
        raise ReplayError(path, "lyapunov_matrix is not a 2x2 positive definite matrix")
    return ReplayData(meta, time, state.astype(np.float64), robot, steps, pushes)
