"""Exception tree of the project.

Every error raised on purpose by this project derives from :class:`RsgError`, so a
caller can catch the project's errors apart from library errors. Exceptions carry
the data that explain them.
"""

from __future__ import annotations

from typing import Any


class RsgError(Exception):
    """Root of the project's exceptions."""


class ParameterError(RsgError, ValueError):
    """A parameter is out of its valid range.

    Attributes:
        field: Name of the offending field.
        value: Value that was given.
        allowed: Human-readable description of what is allowed.
    """

    def __init__(self, field: str, value: Any, allowed: str) -> None:
        self.field = field
        self.value = value
        self.allowed = allowed
        super().__init__(f"{field}={value!r} is not allowed: expected {allowed}")

    def __reduce__(self) -> tuple[Any, ...]:
        # Rebuilt from its data, so it crosses process boundaries (sweep and grid workers).
        return (type(self), (self.field, self.value, self.allowed))


class StepQpError(RsgError):
    """The step-location QP (27) failed in a way its fallback cannot handle.

    Attributes:
        problem: Description of the problem data.
        reason: What went wrong.
    """

    def __init__(self, reason: str, problem: Any = None) -> None:
        self.reason = reason
        self.problem = problem
        super().__init__(reason)

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (self.reason, self.problem))
