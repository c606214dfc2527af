"""PNG plots of the experiments: the sweep's envelope (``envelope.png``), the push
grid's outcomes (``grid.png``) and the push campaign's pushes (``campaign.png``)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from app.experiments.campaign import CampaignSpec, seed_name
from app.experiments.grid import GridSpec, beyond_bound
from app.experiments.outcome import OUTCOMES
from planner.exceptions import RsgError

COLORS = {"rsg": "tab:red", "fixed-timing": "tab:blue", "no-step": "tab:green",
          "placo-wpg": "tab:purple"}  # fmt: skip
COLOURS = {"recovered": "#2a9d3a", "survived": "#f2c14e", "fell": "#c0392b"}
STYLE = {"recovered": ("o", "#2a9d3a"), "survived": ("^", "#e09f1f"), "fell": ("x", "#c0392b")}


def _pyplot() -> Any:
    """matplotlib's pyplot on the file-only Agg backend (loaded when a plot is drawn)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(figure: Any, path: Path, dpi: int) -> Path:
    """Write ``figure`` to ``path`` and close it; returns ``path``.

    Raises:
        RsgError: If the file cannot be written.
    """
    try:
        figure.savefig(path, dpi=dpi)
    except OSError as exc:
        raise RsgError(f"cannot write {path}: {exc}") from exc
    finally:
        _pyplot().close(figure)
    return path


def _closed(angles: list[float], values: list[float]) -> tuple[np.ndarray, np.ndarray]:
    return np.array([*angles, angles[0]]), np.array([*values, values[0]])


def plot_envelope(envelope: dict, path: Path) -> Path:
    """Write the polar plot (one panel per push phase) to ``path``; returns it.

    Raises:
        RsgError: If the file cannot be written.
    """
    plt = _pyplot()
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
    return save_figure(fig, path, 110)


def plot_grid(spec: GridSpec, records: list[dict], path: Path) -> Path:
    """Impulse (rows) x direction (columns) coloured by outcome, one panel per
    controller (columns) and phase (rows); returns ``path``."""
    from matplotlib.colors import ListedColormap

    plt = _pyplot()
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
    return save_figure(figure, path, 120)


def plot_campaign(spec: CampaignSpec, rows: list[dict], path: Path) -> Path:
    """Polar scatter of ``rows`` (:func:`app.experiments.campaign_report.push_rows`);
    returns ``path``.

    Raises:
        RsgError: If the file cannot be written.
    """
    plt = _pyplot()
    panels = [("runs", c, f"{c} on {spec.model}") for c in spec.controllers]
    if spec.model != "lipm" and rows:
        panels += [("twins", c, f"{c}, LIPM twin") for c in rows[0]["twins"]]
    figure = plt.figure(figsize=(3.6 * len(panels) + 0.4, 4.4))
    impulses = [row["impulse"] for row in rows] or [1.0]
    low, high = min(impulses), max(impulses)
    for number, (kind, controller, title) in enumerate(panels, start=1):
        axis = figure.add_subplot(1, len(panels), number, projection="polar")
        counts = dict.fromkeys(OUTCOMES, 0)
        for outcome in OUTCOMES:
            chosen = [row for row in rows if row[kind][controller]["outcome"] == outcome]
            counts[outcome] = len(chosen)
            marker, colour = STYLE[outcome]
            axis.scatter(
                [math.radians(row["direction_deg"]) for row in chosen],
                [row["phase"] for row in chosen],
                s=[12 + 48 * (row["impulse"] - low) / max(high - low, 1e-9) for row in chosen],
                marker=marker,
                c=colour,
                linewidths=1.2,
            )
        axis.set_ylim(0.0, 1.0)
        axis.set_yticks([0.25, 0.5, 0.75], ["0.25", "0.5", "0.75"], fontsize=7)
        axis.set_title(
            f"{title}\n{counts['recovered']} rec., {counts['survived']} surv., "
            f"{counts['fell']} fell of {len(rows)}",
            fontsize=9,
        )
    handles = [
        plt.Line2D([], [], marker=STYLE[o][0], color=STYLE[o][1], linestyle="none", markersize=7)
        for o in OUTCOMES
    ]
    figure.legend(handles, OUTCOMES, loc="lower center", ncol=3, frameon=False)
    figure.suptitle(
        f"push campaign, seed {seed_name(spec.seed)}: angle = push direction (0 forward, 90 "
        "left), radius = phase, size = impulse",
        fontsize=9,
    )
    figure.tight_layout(rect=(0.0, 0.07, 1.0, 0.95))
    return save_figure(figure, path, 110)
