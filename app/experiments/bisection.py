"""Bisection of the largest value a monotone predicate accepts (the sweep's search)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field


@dataclass
class Bisection:
    """Result of :func:`bisect_threshold`: largest passing and smallest failing value."""

    passed: float
    failed: float | None
    evaluations: list[tuple[float, bool]] = field(default_factory=list)


def bisect_threshold(
    predicate: Callable[[float], bool], upper: float, tolerance: float
) -> Bisection:
    """Largest x in [0, upper] with ``predicate(x)`` true, for a predicate monotone in x.

    Evaluates ``upper`` first (if it passes, the answer is ``upper`` and ``failed`` is
    None), then 0 (if it fails, the answer is 0), then bisects until the bracket is
    narrower than ``tolerance``.
    """
    result = Bisection(0.0, upper)
    for probe in (upper, 0.0):
        ok = predicate(probe)
        result.evaluations.append((probe, ok))
        if ok and probe == upper:
            return Bisection(upper, None, result.evaluations)
        if not ok and probe == 0.0:
            return Bisection(0.0, 0.0, result.evaluations)
    low, high = 0.0, upper
    while high - low > tolerance:
        middle = 0.5 * (low + high)
        ok = predicate(middle)
        result.evaluations.append((middle, ok))
        low, high = (middle, high) if ok else (low, middle)
    return Bisection(low, high, result.evaluations)
