"""Polar plot of a sweep's envelope: one curve per controller and the capture bound."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from planner.exceptions import RsgError

COLORS = {"rsg": "tab:red", "fixed-timing": "tab:blue", "no-step": "tab:green",
          "placo-wpg": "tab:purple"}  # fmt: skip


def _closed(angles: list[float], values: list[float]) -> tuple[np.ndarray, np.ndarray]:
    return np.array([*angles, angles[0]]), np.array([*values, values[0]])


def plot_envelope(envelope: dict, path: Path) -> Path:
    """Write the polar plot (one panel per push phase) to ``path``; returns it.

    Raises:
        RsgError: If the file cannot be written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    phases = list(next(iter(envelope["controllers"].values()))["phases"])
    columns = min(len(phases), 4)
    rows = math.ceil(len(phases) / columns)
    fig, axes = plt.subplots(
        rows, columns, subplot_kw={"projection": "polar"},
        figsize=(max(4.2 * columns, 7.0), 4.4 * rows + 0.6),
        squeeze=False,
    )  # fmt: skip
    spec = envelope["spec"]
    for index, phase in enumerate(phases):
        ax = axes[index // columns][index % columns]
        bound_drawn = False
        for controller, data in envelope["controllers"].items():
            rows_ = data["phases"][phase]
            if not rows_:
                continue
            angles = [math.radians(r["direction_deg"]) for r in rows_]
            if not bound_drawn:
                ax.plot(*_closed(angles, [r["bound"] for r in rows_]), "k--", lw=1.5,
                        label="capture bound")  # fmt: skip
                bound_drawn = True
            ax.plot(*_closed(angles, [r["impulse"] for r in rows_]), "o-", ms=3,
                    color=COLORS.get(controller), label=controller)  # fmt: skip
        ax.set_title(f"phase {phase} (s~ = {float(phase):.2f} T*)", fontsize=10)
        ax.set_theta_zero_location("N")  # forward (+x) up, left (+y) to the left
        ax.tick_params(labelsize=7)
    for index in range(len(phases), rows * columns):
        axes[index // columns][index % columns].set_visible(False)
    handles, labels = axes[0][0].get_legend_handles_labels()
    ncol = len(labels) if columns > 1 else min(len(labels), 3)
    fig.legend(handles, labels, loc="lower center", ncol=ncol, fontsize=9)
    fig.suptitle(
        f"Largest recovered impulse [N s] by push direction\n({spec['model']}, "
        f"push {spec['duration']} s, cycle {spec['cycle']}; forward up, left to the left)",
        fontsize=10,
    )
    fig.tight_layout(rect=(0, 0.1 if columns == 1 else 0.06, 1, 0.93))
    try:
        fig.savefig(path, dpi=110)
    except OSError as exc:
        raise RsgError(f"cannot write {path}: {exc}") from exc
    finally:
        plt.close(fig)
    return path
