"""What every tooth fault shares: where it is (gear, tooth), its label in the case file and the
active profile of its tooth.

Roll coordinates (used by every fault that sits on the flank): a point of the involute of a gear
with base radius ``r_b`` at roll angle ``u`` [rad] has the roll length ``r_b u`` [m], its distance
from the base-circle tangency point along the line of action (the profile coordinate of ISO
21771 profile charts). The contact point of a pair at distance ``s`` along the line of action lies
at pinion roll ``s / r_b1`` and gear roll ``(t1t2 - s) / r_b2``
(:meth:`geardyn.geometry.GearPair.operating`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InputError

GEARS = ("pinion", "gear")


@dataclass(frozen=True)
class FaultBase:
    """Place of a fault: which gear, which tooth, and how the case file names it.

    Parameters
    ----------
    gear : {"pinion", "gear"}
    tooth : int
        Tooth number, 0-based in mesh order (pair ``n`` holds pinion tooth ``n mod z1`` and gear
        tooth ``n mod z2``), as the ``[crack]`` section.
    label : str
        Name of the entry in error messages, e.g. ``"faults[1]"``.
    """

    gear: str = "pinion"
    tooth: int = 0
    label: str = "fault"

    def field(self, name: str) -> str:
        """Dotted name of a parameter of this entry, e.g. ``"faults[1].length"``."""
        return f"{self.label}.{name}"

    def check_place(self, pair=None) -> None:
        """Raise :class:`InputError` for a bad gear or a tooth out of range of ``pair``."""
        if self.gear not in GEARS:
            raise InputError(self.field("gear"), self.gear, "'pinion' or 'gear'")
        if isinstance(self.tooth, bool) or int(self.tooth) != self.tooth or self.tooth < 0:
            raise InputError(self.field("tooth"), self.tooth, "a tooth number >= 0")
        if pair is not None:
            z = gear_of(pair, self.gear).teeth
            if self.tooth >= z:
                raise InputError(self.field("tooth"), self.tooth,
                                 f"a tooth number in [0, {z - 1}] of the {self.gear} ({z} teeth)")

    def is_null(self) -> bool:  # pragma: no cover - every subclass defines it
        """Whether the fault has zero size (the tooth is healthy)."""
        raise NotImplementedError


def gear_of(pair, which: str):
    """The :class:`geardyn.geometry.Gear` called ``which`` of ``pair``."""
    return pair.pinion if which == "pinion" else pair.gear


def active_roll_range(pair, which: str, centre_distance_change: float = 0.0
                      ) -> tuple[float, float]:
    """Roll angles [rad] of the lowest and highest points of contact of one gear's flank.

    Parameters
    ----------
    pair : geardyn.geometry.GearPair
    which : {"pinion", "gear"}
    centre_distance_change : float
        ``d' - d`` [m]; the nominal centre distance by default.

    Returns
    -------
    tuple of float
        ``(u_low, u_high)`` [rad]: start of active profile and tip.
    """
    op = pair.operating(float(centre_distance_change), check=False)
    if which == "pinion":
        rb = pair.pinion.base_radius
        return op.s_start / rb, op.s_end / rb
    rb = pair.gear.base_radius
    return (op.t1t2 - op.s_end) / rb, (op.t1t2 - op.s_start) / rb


def check_size(value: float, field: str, what: str, *, upper: float | None = None,
               upper_text: str = "") -> float:
    """A finite size >= 0 (zero: no fault), at most ``upper`` when given."""
    if value is None or isinstance(value, bool) or not math.isfinite(float(value)) or value < 0:
        raise InputError(field, value, f"{what} >= 0 (0: no fault)")
    if upper is not None and value > upper:
        raise InputError(field, value, f"{what} in [0, {upper:.6g}]{upper_text}")
    return float(value)
