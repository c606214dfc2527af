"""Silence what compiled libraries print on the process's stdout and stderr.

placo (C++) and pybullet (C) write straight to file descriptors 1 and 2, where
Python's ``sys.stdout`` redirection cannot reach: placo's ``HumanoidRobot`` warns
about Sigmaban frames (``left_hip_yaw``, ``head_base``) that only its leg-spacing
and ``camera_look_at`` helpers use, neither used here; pybullet prints its build
time at import and ``argv[0]=`` at connect. :func:`native_output_silenced` points
both descriptors at ``/dev/null`` for the duration of such a call.
"""

from __future__ import annotations

import ctypes
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager

_LIBC = ctypes.CDLL(None)


def _flush_all() -> None:
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (AttributeError, ValueError, OSError):
            pass
    _LIBC.fflush(None)  # C stdio buffers, so their text is not written after restoring


@contextmanager
def native_output_silenced() -> Iterator[None]:
    """Discard what is written to file descriptors 1 and 2 inside the block.

    Python's own output in the block (from any thread) is lost too, so keep the
    block to the one library call; exceptions still propagate.
    """
    _flush_all()
    saved: list[tuple[int, int]] = []
    try:
        with open(os.devnull, "w") as null:
            for fd in (1, 2):
                try:
                    saved.append((fd, os.dup(fd)))
                    os.dup2(null.fileno(), fd)
                except OSError:
                    continue  # descriptor closed: nothing to silence
            yield
    finally:
        _flush_all()
        for fd, copy in saved:
            os.dup2(copy, fd)
            os.close(copy)
