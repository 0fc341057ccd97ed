"""Shared pieces of the benchmark suite.

Each ``benchmarks/bench_<subsystem>.py`` defines ``run(quick: bool) -> list[Row]``. A row reports one
measured figure, the baseline measured *in the same run* (a straightforward implementation of the
same computation), their ratio, and the project's target, so a reader sees at once whether the
target is met on this machine.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class Row:
    """One benchmark figure.

    Attributes
    ----------
    name : str
        What was measured.
    value : float
        The measured figure, in ``unit``.
    unit : str
        Unit of ``value`` (e.g. ``"s"``, ``"us/step"``, ``"lookups/s"``).
    baseline : str
        What the baseline is (empty if there is none).
    baseline_value : float or None
        The baseline's figure in the same unit, measured in the same run.
    target : str
        The target in words, e.g. ``"< 2 s"``.
    met : bool or None
        Whether the target is met (``None`` if there is no target).
    """

    name: str
    value: float
    unit: str
    baseline: str = ""
    baseline_value: float | None = None
    target: str = ""
    met: bool | None = None

    @property
    def ratio(self) -> float | None:
        """Speed-up of the measured figure over the baseline (> 1 means faster / better)."""
        if self.baseline_value is None or self.value == 0:
            return None
        # for rates (per second) larger is better; for times smaller is better
        if self.unit.endswith("/s") or self.unit.startswith("runs/"):
            return self.value / self.baseline_value
        return self.baseline_value / self.value


def best_time(fn: Callable[[], object], repeat: int = 3, number: int = 1) -> float:
    """Best wall-clock time of ``number`` calls of ``fn`` over ``repeat`` trials [s per call]."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        best = min(best, (time.perf_counter() - t0) / number)
    return best
