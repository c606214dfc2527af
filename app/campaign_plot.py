"""``campaign.png``: each push's outcome by direction (angle) and phase (radius), one
polar panel per controller on the robot and one per twin; marker area grows with the
impulse."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from planner.exceptions import RsgError  # noqa: E402

from .campaign import CampaignSpec, seed_name  # noqa: E402
from .push_outcome import OUTCOMES  # noqa: E402

STYLE = {"recovered": ("o", "#2a9d3a"), "survived": ("^", "#e09f1f"), "fell": ("x", "#c0392b")}


def plot_campaign(spec: CampaignSpec, rows: list[dict], path: Path) -> Path:
    """Polar scatter of ``rows`` (:func:`app.campaign_report.push_rows`); returns ``path``.

    Raises:
        RsgError: If the file cannot be written.
    """
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
    try:
        figure.savefig(path, dpi=110)
    except OSError as exc:
        raise RsgError(f"cannot write {path}: {exc}") from exc
    finally:
        plt.close(figure)
    return path
