"""PNG plots of a run, reproducing the paper's Fig. 6.

- ``fig6a_top_view.png``: CoM, ZMP, footsteps and footholds from above, with the
  CoM at each push marked;
- ``fig6b_time_since_step.png``: s~(t) = t - s_{j-1};
- ``fig6c_dcm_error.png``: the DCM error e_u in its plane with the Lyapunov level
  sets (gamma_v in bold), and V_u(t) against gamma_v.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402

from app.runner import RunResult  # noqa: E402
from planner.lyapunov import LyapunovDesign  # noqa: E402

ADJUSTED_COLOR = "tab:red"
NOMINAL_COLOR = "tab:green"


def _title(result: RunResult, what: str) -> str:
    return f"{what}: {result.scenario.name}, {result.backend}"


def _push_marks(result: RunResult) -> list[int]:
    t = result.column("t")
    return [int(np.searchsorted(t, p.time)) for p in result.scenario.pushes if p.time <= t[-1]]


def _mark_pushes_and_adjusted_steps(ax: plt.Axes, result: RunResult) -> None:
    """Shade each push's interval and draw a red line at each adjusted step."""
    for push in result.scenario.pushes:
        ax.axvspan(push.time, push.time + push.duration, color="lime", alpha=0.4)
    for step in result.steps:
        if step.event["adjusted"]:
            ax.axvline(step.event["t"], color=ADJUSTED_COLOR, lw=0.8)


def plot_top_view(result: RunResult, path: Path) -> None:
    cons = result.config.constraints
    fig, ax = plt.subplots(figsize=(11, 5))
    wx = np.array([cons.zmp_window_min[0], cons.zmp_window_max[0]])
    wy = np.array([cons.zmp_window_min[1], cons.zmp_window_max[1]])
    positions = [(s.event["position"], s.event["adjusted"]) for s in result.steps]
    first = result.column("foot_x")[0], result.column("foot_y")[0]
    for (x, y), adjusted in [(first, False), *positions]:
        color = ADJUSTED_COLOR if adjusted else NOMINAL_COLOR
        ax.add_patch(
            Rectangle(
                (x + wx[0], y + wy[0]),
                wx[1] - wx[0],
                wy[1] - wy[0],
                fill=False,
                edgecolor=color,
                linewidth=1.2,
            )
        )
        ax.plot(x, y, "o", color="black", markersize=4, markerfacecolor="none")
    ax.plot(result.column("zmp_x"), result.column("zmp_y"), color="tab:orange", lw=1, label="ZMP")
    ax.plot(result.column("com_x"), result.column("com_y"), color="tab:blue", lw=1.5, label="CoM")
    for k in _push_marks(result):
        ax.plot(
            result.column("com_x")[k],
            result.column("com_y")[k],
            "s",
            color="lime",
            markeredgecolor="black",
            markersize=8,
        )
    ax.plot([], [], "s", color="lime", markeredgecolor="black", label="CoM at push")
    ax.plot([], [], color=NOMINAL_COLOR, label="foothold (nominal)")
    ax.plot([], [], color=ADJUSTED_COLOR, label="foothold (adjusted)")
    ax.plot([], [], "o", color="black", markerfacecolor="none", label="step location o_H")
    y_all = np.concatenate([result.column("com_y"), result.column("foot_y")])
    ax.set_ylim(y_all.min() - 0.12, y_all.max() + 0.12)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.28), fontsize=8, ncols=4)
    ax.set_title(_title(result, "(a) top view"))
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_time_since_step(result: RunResult, path: Path) -> None:
    fig, ax = plt.subplots(figsize=(10, 3))
    t = result.column("t")
    ax.plot(t, result.column("time_since_step"), color="tab:blue")
    gait, rsg = result.config.gait, result.config.rsg
    ax.axhline(gait.step_duration, color="gray", ls="--", lw=1, label="T* (nominal)")
    ax.axhline(
        gait.double_support_duration + rsg.swing_preparation_time,
        color="gray",
        ls=":",
        lw=1,
        label="T_DSP + T_SP (earliest)",
    )
    _mark_pushes_and_adjusted_steps(ax, result)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("s~ = t - s_{j-1} [s]")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(_title(result, "(b) time since the previous step (red: adjusted steps)"))
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_dcm_error(result: RunResult, path: Path) -> None:
    gamma = result.lyapunov_threshold
    design = LyapunovDesign(
        gain=np.array(result.extra["feedback_gain"]),
        matrix=np.array(result.extra["lyapunov_matrix"]),
        threshold=gamma,
        state_cost=np.eye(2),
        input_cost=np.eye(4),
    )
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.5), width_ratios=[1, 1.4])
    ex, ey = result.column("dcm_error_x"), result.column("dcm_error_y")
    vmax = max(result.max_lyapunov, 2 * gamma)
    # placo-wpg has no Lyapunov function (a zero P_u): its e_u is drawn alone.
    if np.all(np.linalg.eigvalsh(design.matrix) > 0.0):
        for level in np.geomspace(gamma / 4, vmax, 6):
            pts = design.level_set(level)
            ax.plot(pts[:, 0], pts[:, 1], color="lightgray", lw=0.8)
        pts = design.level_set(gamma)
        ax.plot(pts[:, 0], pts[:, 1], color="black", lw=2, label="V_u = gamma_v")
    ax.plot(ex, ey, color="tab:blue", lw=1, label="e_u(t)")
    for k in _push_marks(result):
        ax.plot(ex[k], ey[k], "s", color="lime", markeredgecolor="black")
    ax.set_aspect("equal")
    ax.set_xlabel("e_u,x [m]")
    ax.set_ylabel("e_u,y [m]")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title("(c) DCM error and Lyapunov level sets")
    t = result.column("t")
    bx.semilogy(t, np.maximum(result.column("lyapunov"), 1e-9), color="tab:blue", label="V_u(t)")
    bx.axhline(gamma, color="black", lw=1.5, label="gamma_v")
    _mark_pushes_and_adjusted_steps(bx, result)
    bx.set_xlabel("t [s]")
    bx.set_ylabel("V_u")
    bx.legend(loc="upper right", fontsize=8)
    bx.set_title("V_u(t) against gamma_v (red: adjusted steps)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_fig6(result: RunResult, out_dir: Path) -> list[Path]:
    """Write the three Fig. 6 panels; returns their paths."""
    paths = [
        out_dir / "fig6a_top_view.png",
        out_dir / "fig6b_time_since_step.png",
        out_dir / "fig6c_dcm_error.png",
    ]
    if len(result.timeseries) == 0:
        return []
    plot_top_view(result, paths[0])
    plot_time_since_step(result, paths[1])
    plot_dcm_error(result, paths[2])
    return paths
