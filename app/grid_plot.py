"""``grid.png``: the outcome of each push, one panel per controller and phase; a
black dot marks a push above its LIPM capture bound."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402

from .push_grid import OUTCOMES, GridSpec, beyond_bound  # noqa: E402

COLOURS = {"recovered": "#2a9d3a", "survived": "#f2c14e", "fell": "#c0392b"}


def plot_grid(spec: GridSpec, records: list[dict], path: Path) -> Path:
    """Impulse (rows) x direction (columns) coloured by outcome, one panel per
    controller (columns) and phase (rows); returns ``path``."""
    rows, columns = len(spec.phases), len(spec.controllers)
    figure, axes = plt.subplots(
        rows, columns, figsize=(3.4 * columns + 0.6, 3.0 * rows + 0.6), squeeze=False
    )
    directions = spec.directions_deg()
    colormap = ListedColormap([COLOURS[o] for o in OUTCOMES])
    panels = [
        (axes[row, column], controller, phase)
        for row, phase in enumerate(spec.phases)
        for column, controller in enumerate(spec.controllers)
    ]
    for axis, controller, phase in panels:
        matrix = np.full((len(spec.impulses), len(directions)), np.nan)
        beyond = []
        for record in records:
            if record["controller"] == controller and record["phase"] == phase:
                row = spec.impulses.index(record["impulse"])
                column = directions.index(record["direction_deg"])
                matrix[row, column] = OUTCOMES.index(record["outcome"])
                if beyond_bound(record):
                    beyond.append((column, row))
        axis.imshow(matrix, cmap=colormap, vmin=-0.5, vmax=2.5, origin="lower", aspect="auto")
        if beyond:
            xs, ys = zip(*beyond, strict=True)
            axis.plot(xs, ys, "k.", markersize=6)
        not_fallen = int(np.sum(matrix < 2))
        axis.set_title(f"{controller}, phase {phase:g}\nnot fallen {not_fallen}/{matrix.size}")
        axis.set_xticks(range(len(directions)), [f"{d:g}" for d in directions], fontsize=7)
        axis.set_yticks(range(len(spec.impulses)), [f"{i:g}" for i in spec.impulses])
        axis.set_xlabel("push direction [deg] (0 forward, 90 left)")
        axis.set_ylabel("impulse [N s]")
    handles: list = [plt.Rectangle((0, 0), 1, 1, color=COLOURS[o]) for o in OUTCOMES]
    handles.append(plt.Line2D([], [], color="k", marker=".", linestyle="none"))
    labels = [*OUTCOMES, "above the LIPM capture bound"]
    figure.legend(handles, labels, loc="lower center", ncol=4, frameon=False)
    figure.tight_layout(rect=(0.0, 0.6 / (3.0 * rows + 0.6), 1.0, 1.0))
    figure.savefig(path, dpi=120)
    plt.close(figure)
    return path
