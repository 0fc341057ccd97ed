"""Exceptions raised by geardyn.

Every error a user can cause names the offending field (a dotted config key or a function
argument), the value that was given and what is allowed, so the command-line tool can print one
clear line and exit with status 2 instead of showing a traceback.
"""

from __future__ import annotations

import re
from typing import Any

#: Longest rendering of a value, a field name and an "allowed" text in a message [characters]:
#: a 16 MB input is never echoed whole, and a message stays one line under ~500 characters.
MAX_VALUE_CHARS = 100
MAX_FIELD_CHARS = 100
MAX_ALLOWED_CHARS = 300

_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f]+")


class _NotGiven:
    """The value of an option or argument the user left out (``--out: got nothing``)."""

    def __repr__(self) -> str:
        return "nothing"


#: Value of an :class:`InputError` for a required option that was not given (its message reads
#: ``--out: got nothing; ...``, not Python's ``None``).
NOT_GIVEN: Any = _NotGiven()


def check_flag(value: Any, field: str) -> bool:
    """``value`` as a bool if it is one (Python's or NumPy's), else :class:`InputError` naming
    ``field``: a string such as ``"no"`` is not taken for True."""
    t = type(value)
    if isinstance(value, bool) or (t.__module__ == "numpy" and t.__name__ in ("bool", "bool_")):
        return bool(value)
    raise InputError(field, value, "True or False")


def _clip(text: str, limit: int) -> str:
    """One line of at most ``limit`` characters (control characters shown as one space)."""
    text = _CONTROL.sub(" ", text)
    return text if len(text) <= limit else text[: limit - 1] + "…"


def short_repr(value: Any, limit: int = MAX_VALUE_CHARS) -> str:
    """``repr(value)`` cut to ``limit`` characters with an ellipsis and the full length.

    Safe for huge inputs: a long string is cut before ``repr``; an integer too long for
    ``repr`` (Python's 4300-digit limit) is described by its size.
    """
    if isinstance(value, str | bytes) and len(value) > limit:
        return repr(value[: limit // 2]) + f"… ({len(value)} characters)"
    if type(value).__module__ == "numpy" and hasattr(value, "item") and getattr(
            value, "ndim", 1) == 0:  # a NumPy scalar as the number it holds, not np.float64(...)
        value = value.item()
    try:
        text = repr(value)
    except ValueError:  # int too long to convert
        return f"<integer of about {int(value.bit_length() * 0.30103) + 1} digits>"
    if len(text) > limit:
        return text[: limit - 1] + f"… ({len(text)} characters)"
    return text


__all__ = [
    "NOT_GIVEN",
    "GeardynError",
    "InputError",
    "GeometryError",
    "NumericalError",
    "DataFileError",
    "short_repr",
    "check_flag",
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
        super().__init__(f"{_clip(str(field), MAX_FIELD_CHARS)}: got {short_repr(value)}; "
                         f"allowed: {_clip(str(allowed), MAX_ALLOWED_CHARS)}")


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
        super().__init__(f"{_clip(self.path, MAX_FIELD_CHARS)}: {_clip(str(problem), MAX_ALLOWED_CHARS)}")
