"""The folder a command writes its results to (``--out``), checked before the work starts.

Policy (docs/input-validation.md):

- ``--out`` is a non-empty path; the folder is created (with its parents) if missing,
  and must then be a folder this process can write a file into (a probe file is
  created and removed: permission bits say nothing when running as root);
- the names the command writes must not exist as anything but files (a folder
  ``grid.png/`` is refused: it cannot be replaced by a file);
- results are never mixed: a folder holding any file an ``rsg`` command writes
  (:data:`RESULT_FILES`) is refused, unless ``--overwrite`` is given, which deletes
  those files (and nothing else) before the work starts. ``rsg sweep``'s own files are
  the exception: a sweep folder is resumed when its specification agrees
  (:mod:`app.experiments.sweep`), and ``--overwrite`` starts it over.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from planner.exceptions import RsgError

#: The files each command writes into its ``--out`` folder.
RESULT_FILES: dict[str, tuple[str, ...]] = {
    "run": (
        "summary.json",
        "timeseries.csv",
        "physics.csv",
        "physics.png",
        "fig6a_top_view.png",
        "fig6b_time_since_step.png",
        "fig6c_dcm_error.png",
    ),
    "sweep": (
        "envelope.json",
        "envelope.csv",
        "envelope.png",
        "monotonicity.json",
        "jobs.jsonl",
        "sweep_spec.json",
    ),
    "monotonicity": ("jobs.jsonl", "sweep_spec.json"),
    "protocol": ("protocol.json", "protocol.csv", "jobs.jsonl", "sweep_spec.json"),
    "pushes": (
        "campaign.json",
        "campaign.csv",
        "campaign.png",
        "jobs.jsonl",
        "campaign_spec.json",
    ),
    "grid": ("grid.json", "grid.csv", "grid.png"),
    "bench": ("bench.json",),
}
MAX_PATH_LENGTH = 4096  # [characters] Linux's PATH_MAX


class ResultFolderError(RsgError):
    """``--out`` cannot take the command's results.

    Attributes:
        path: The folder (or the file in it) at fault.
        problem: What is wrong with it.
        way_out: What the user can do.
    """

    def __init__(self, path: Path | str, problem: str, way_out: str) -> None:
        self.path = path
        self.problem = problem
        self.way_out = way_out
        super().__init__(f"--out {path}: {problem}; {way_out}")

    def __reduce__(self) -> tuple:
        return (type(self), (self.path, self.problem, self.way_out))


def earlier_results(out: Path, keep: tuple[str, ...] = ()) -> list[str]:
    """Names of ``rsg`` result files in ``out``, except ``keep``."""
    names = sorted({name for files in RESULT_FILES.values() for name in files} - set(keep))
    return [name for name in names if os.path.lexists(out / name)]


def prepare_out(
    out: Path, command: str, overwrite: bool = False, resumable: tuple[str, ...] = ()
) -> list[Path]:
    """Check (and create) ``out`` for ``command`` before its work starts.

    Args:
        out: The ``--out`` folder.
        command: A key of :data:`RESULT_FILES`.
        overwrite: Delete an earlier run's result files instead of refusing the folder.
        resumable: Result files that may stay (a resumed sweep's own).

    Returns:
        The files deleted (with ``overwrite``).

    Raises:
        ResultFolderError: ``out`` is not a writable folder, one of the command's
            result names exists as a folder, or (without ``overwrite``) ``out`` holds
            an earlier run's results.
    """
    again = "use another --out"
    try:
        if os.path.lexists(out) and not out.is_dir():
            raise ResultFolderError(out, "exists and is not a folder", again)
        out.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=out, prefix=".rsg-write-test-"):
            pass
    except ResultFolderError:
        raise
    except (OSError, ValueError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise ResultFolderError(
            out, f"is not a folder that can be written ({reason})", again
        ) from exc
    for name in RESULT_FILES[command]:
        path = out / name
        if os.path.lexists(path) and (path.is_symlink() or not path.is_file()):
            raise ResultFolderError(
                path,
                "exists and is not a file, so the result of that name cannot be written",
                f"remove it, or {again}",
            )
    earlier = earlier_results(out, resumable)
    if not earlier:
        return []
    if not overwrite:
        shown = ", ".join(earlier[:4]) + (", ..." if len(earlier) > 4 else "")
        raise ResultFolderError(
            out,
            f"holds the results of an earlier run ({shown})",
            f"{again}, or add --overwrite to delete them first",
        )
    removed = []
    for name in earlier:
        path = out / name
        if path.is_symlink() or not path.is_file():
            raise ResultFolderError(path, "is not a file, so --overwrite cannot delete it",
                                    f"remove it, or {again}")  # fmt: skip
        try:
            path.unlink()
        except OSError as exc:
            raise ResultFolderError(path, f"cannot be deleted ({exc.strerror})", again) from exc
        removed.append(path)
    return removed


def report_files(paths: list[Path]) -> None:
    """Print the files a command wrote, one line each."""
    for path in paths:
        print(f"wrote {path}")
