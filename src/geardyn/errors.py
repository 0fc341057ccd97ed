"""Exceptions raised by geardyn.

Every error a user can cause names the offending field (a dotted config key or a function
argument), the value that was given and what is allowed, so the command-line tool can print one
clear line and exit with status 2 instead of showing a traceback.
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "GeardynError",
    "InputError",
    "GeometryError",
    "NumericalError",
    "DataFileError",
]


class GeardynError(Exception):
    """Base class of every error geardyn raises on purpose."""


class InputError(GeardynError, ValueError):
    """A parameter, argument or file entry is invalid.

    Parameters
    ----------
    field : str
        Dotted name of the offending input, e.g. ``"pinion.teeth"`` or ``"dt"``.
    value : Any
        The value that was given.
    allowed : str
        What would have been accepted, in words, e.g. ``"an integer >= 5"``.
    """

    def __init__(self, field: str, value: Any, allowed: str):
        self.field = field
        self.value = value
        self.allowed = allowed
        super().__init__(f"{field}: got {value!r}; allowed: {allowed}")


class GeometryError(InputError):
    """A gear pair cannot work as given (interference, contact ratio below 1, pointed teeth...)."""


class NumericalError(GeardynError, RuntimeError):
    """A computation failed numerically (divergence, NaN, runaway separation).

    Parameters
    ----------
    message : str
        What went wrong.
    time : float, optional
        Simulated time of the failure [s].
    state : dict, optional
        Named state values at the failure, reported with the message.
    """

    def __init__(self, message: str, time: float | None = None, state: dict | None = None):
        self.time = time
        self.state = dict(state or {})
        parts = [message]
        if time is not None:
            parts.append(f"at t = {time:.6g} s")
        if self.state:
            parts.append(
                "state: " + ", ".join(f"{k} = {v:.6g}" if isinstance(v, float) else f"{k} = {v}"
                                      for k, v in self.state.items())
            )
        super().__init__("; ".join(parts))


class DataFileError(GeardynError, OSError):
    """An input file is missing, unreadable, truncated or not of the expected format."""

    def __init__(self, path: Any, problem: str):
        self.path = str(path)
        self.problem = problem
        super().__init__(f"{self.path}: {problem}")
