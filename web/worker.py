"""A background loop thread that can be started once and stopped cleanly."""

from __future__ import annotations

import threading
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
