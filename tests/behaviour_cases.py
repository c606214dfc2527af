"""Fixed LIPM and G1 runs whose every recorded bit must stay as recorded.

``tests/data/behaviour.npz`` holds their time series and steps as the code produced
them; ``tests/test_behaviour.py`` runs them again in a fresh process and compares
bit for bit, so a refactoring that changes any arithmetic shows. Record again only
when a change of behaviour is meant, and say so in the commit:

    python tests/behaviour_cases.py --record

Each case runs in a child process with CPU-dispatch pinned (tests/kernels.py): OpenBLAS
and numpy pick kernels by CPU, and their sums round differently.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
from kernels import ENVIRONMENT

RECORD = Path(__file__).parent / "data" / "behaviour.npz"
CASES = {
    # (model, robot, built-in scenario or one push as `rsg run --push`, duration [s]):
    # the paper's Fig. 6 on its point mass; G1 pushed forward and sideways in swing.
    "lipm-paper-fig6": ("lipm", None, "paper-fig6", None),
    "g1-push": ("pybullet", "g1", "1.75:6,3:0.1", 3.5),
}


def run_case(name: str) -> dict[str, np.ndarray]:
    """The case's time series (one array per column) and its steps (as JSON text)."""
    from app.runner import TIMESERIES_COLUMNS, run_closed_loop
    from app.scenarios import Scenario, load_scenario, parse_push
    from app.setup.build import build_backend

    model, robot, scenario_name, duration = CASES[name]
    if duration is None:
        scenario = load_scenario(scenario_name)
    else:
        scenario = Scenario(name, duration, (parse_push(scenario_name),))
    backend, config, initial = build_backend(model, robot, "rsg")
    try:
        result = run_closed_loop(backend, config, scenario, initial)
    finally:
        backend.close()
    series = {column: np.asarray(result.column(column)) for column in TIMESERIES_COLUMNS}
    steps = json.dumps([step.event for step in result.steps], default=float)
    return {**series, "steps": np.array(steps)}


def run_in_child(name: str, out: Path) -> dict[str, np.ndarray]:
    """:func:`run_case` in a fresh Python process with the pinned kernels
    (:data:`kernels.ENVIRONMENT`)."""
    env = {**os.environ, **ENVIRONMENT}
    subprocess.run(
        [sys.executable, __file__, "--case", name, "--out", str(out)], check=True, env=env
    )
    with np.load(out) as data:
        return {key: data[key] for key in data.files}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--record", action="store_true", help=f"write {RECORD}")
    parser.add_argument("--case", choices=sorted(CASES), help="run one case (child process)")
    parser.add_argument("--out", type=Path, help="where --case writes its arrays (.npz)")
    args = parser.parse_args()
    if args.case:
        np.savez(args.out, **run_case(args.case))
        return
    if args.record:
        arrays = {}
        for name in CASES:
            result = run_in_child(name, RECORD.with_name(f"{name}.tmp.npz"))
            RECORD.with_name(f"{name}.tmp.npz").unlink()
            arrays |= {f"{name}/{key}": value for key, value in result.items()}
        RECORD.parent.mkdir(exist_ok=True)
        np.savez_compressed(RECORD, **arrays)
        print(f"wrote {RECORD} ({RECORD.stat().st_size} bytes)")


if __name__ == "__main__":
    main()
