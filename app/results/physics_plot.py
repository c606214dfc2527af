"""``physics.png``: the ground's forces and CoP against what the controller asked for.

Drawn from a run's physics log (:mod:`app.backends.physics_log`), one point per physics
step: each foot's measured normal force with its distributed one, the net CoP of the
feet (x and y) with the planned CoP, and each sole's tilt and yaw. Where the plan and the
ground part, the robot is not doing what the stabilizer planned (a swing sole pressing
before the step, a sole rocking on an edge); a loaded sole that tilts is on an edge, and
one whose yaw moves turns on the ground.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from numpy.typing import NDArray  # noqa: E402

from app.backends.physics_log import COLUMNS  # noqa: E402

FEET = ("left", "right")
FOOT_COLOURS = {"left": "tab:blue", "right": "tab:orange"}


def net_cop(column: Mapping[str, NDArray[np.float64]]) -> NDArray[np.float64]:
    """Net CoP (x, y) [m] of the feet on the ground per row, shape (n, 2) (NaN in the air),
    from the physics log's columns by name."""
    total = column["left_fz"] + column["right_fz"]
    total = np.where(total > 0.0, total, np.nan)
    return np.stack(
        [
            sum(column[f"{f}_fz"] * np.nan_to_num(column[f"{f}_cop_{axis}"]) for f in FEET) / total
            for axis in "xy"
        ],
        axis=1,
    )


def plot_physics(rows: NDArray[np.float64], path: Path, title: str = "") -> plt.Figure:
    """Write ``physics.png`` at ``path``; returns the figure (closed)."""
    column = {name: rows[:, i] for i, name in enumerate(COLUMNS)}
    t = column["t"]
    cop = net_cop(column)
    fig, axes = plt.subplots(4, 1, figsize=(10, 10), sharex=True)
    for foot, colour in FOOT_COLOURS.items():
        axes[0].plot(t, column[f"{foot}_fz"], color=colour, lw=1, label=f"{foot}, measured")
        axes[0].plot(
            t, column[f"{foot}_fz_planned"], color=colour, lw=1, ls="--", label=f"{foot}, planned"
        )
    axes[0].set_ylabel("normal force [N]")
    for ax, index, axis in ((axes[1], 0, "x"), (axes[2], 1, "y")):
        ax.plot(t, cop[:, index], color="black", lw=1, label="net CoP, measured")
        ax.plot(t, column[f"planned_cop_{axis}"], color="tab:red", lw=1, ls="--", label="planned")
        ax.set_ylabel(f"CoP {axis} [m]")
    for foot, colour in FOOT_COLOURS.items():
        axes[3].plot(
            t, np.degrees(column[f"{foot}_sole_tilt"]), color=colour, lw=1, label=f"{foot}, tilt"
        )
        axes[3].plot(
            t,
            np.degrees(column[f"{foot}_sole_yaw"]),
            color=colour,
            lw=1,
            ls=":",
            label=f"{foot}, yaw",
        )
    axes[3].set_ylabel("sole angle [deg]")
    axes[3].set_xlabel("t [s]")
    for ax in axes:
        ax.legend(loc="upper right", fontsize=8, ncol=2)
    axes[0].set_title(f"ground against plan, each physics step{': ' + title if title else ''}")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return fig
