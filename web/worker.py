"""Background loop threads that can be started once and stopped cleanly: a bare loop
(:class:`Worker`) and a page's drawing loop at a frame rate (:class:`FrameLoop`)."""

from __future__ import annotations

import threading
import time as wallclock
from collections.abc import Callable


class Worker:
    """Runs ``target(stop_event)`` in a daemon thread.

    Args:
        target: The loop; it must return soon after ``stop_event`` is set.
        name: Thread name (shown in debuggers and ``py-spy``).
    """

    def __init__(self, target: Callable[[threading.Event], None], name: str) -> None:
        self._target = target
        self._name = name
        self.stop_event = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self) -> None:
        """Start the thread (idempotent)."""
        if self._thread is None:
            self._thread = threading.Thread(
                target=self._target, args=(self.stop_event,), name=self._name, daemon=True
            )
            self._thread.start()

    def stop(self, timeout: float = 5.0) -> None:
        """Ask the loop to end and wait up to ``timeout`` [s] for it."""
        self.stop_event.set()
        if self._thread is not None:
            self._thread.join(timeout)
            self._thread = None


class FrameLoop:
    """A page's drawing thread: :meth:`_frame` about :attr:`frame_rate` times a second.

    Args:
        frame_rate: Frames per second [Hz] (read when the thread starts).
        name: Thread name.
    """

    def __init__(self, frame_rate: float, name: str) -> None:
        self.frame_rate = frame_rate
        self._worker = Worker(self._run, name)

    def start(self) -> None:
        """Start drawing (idempotent)."""
        self._worker.start()

    def stop(self, timeout: float = 5.0) -> None:
        """Stop drawing."""
        self._worker.stop(timeout)

    def _frame(self, now: float, dt: float) -> bool:
        """One frame at wall time ``now`` [s], ``dt`` [s] after the last counted one;
        True counts it (the next ``dt`` starts here)."""
        raise NotImplementedError

    def _run(self, stop: threading.Event) -> None:
        period = 1.0 / self.frame_rate
        last = wallclock.perf_counter()
        while not stop.is_set():
            start = wallclock.perf_counter()
            if self._frame(start, start - last):
                last = start
            stop.wait(max(0.0, period - (wallclock.perf_counter() - start)))
