"""Uniform wear of one tooth's loaded flank: material removed to a depth over a band of the
profile, as a profile deviation.

Geometry. Over the roll window ``[u_a, u_b]`` (default: the whole active profile at the nominal
centre distance) a layer of uniform depth ``delta`` is removed normal to the involute. The normal
of an involute is the line of action, so the worn flank lies ``delta`` behind the perfect one
along the line of action: a profile deviation ``e(u) = delta`` on the window, 0 elsewhere,
positive where material is missing (the sign convention of :mod:`geardyn.modifications`).

What it does:

* the **excitation / separation**: the worn tooth pair must close the gap ``e`` before it carries
  load. The PEM and FE maps record the gap of each load-share slot (``fault_gap`` [m], extra
  variable of the map); the dynamics and the static TE take it from
  :class:`geardyn.modifications.ToothModifications`, which adds ``e(u)`` to the worn tooth's
  deviation table (sampled on its nodes: the window's edges ramp over one node spacing), so the
  worn pair closes the gap before it carries load (``tests/faults/test_wear_dynamics.py``: the
  static TE rises by exactly ``delta`` in single contact);
* optionally (``stiffness = true``) the **stiffness**: the tooth is thinner. At a section of
  the worn band the half-thickness on the loaded side is smaller by ``delta / cos(alpha_1)``
  (the flank normal makes the angle ``alpha_1 = u - alpha_2`` with the tooth's transverse axis),
  so the section width is ``w = 2 h - delta / cos(alpha_1)`` (:mod:`geardyn.stiffness.pem.wear`;
  first order in ``delta``, the shift of the neutral axis neglected as for the crack).

No published wear-stiffness formula was read for this; the section change is plain geometry and
is checked in ``tests/faults/test_wear.py`` against an independent quadrature (scipy ``quad``) of
the same beam integrals. Wear laws over time (Archard, sliding distance) are not modelled.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .base import FaultBase, active_roll_range, check_size, gear_of
from .spall import involute_half_thickness


@dataclass(frozen=True)
class Wear(FaultBase):
    """Uniform wear of one tooth's loaded flank.

    Parameters
    ----------
    gear, tooth, label
        See :class:`geardyn.faults.base.FaultBase`.
    depth : float
        Depth removed normal to the flank [m] (0: no wear).
    roll_start, roll_length : float
        Worn roll window [rad].
    stiffness : bool
        Also model the thinner tooth in the PEM stiffness.
    """

    depth: float = 0.0
    roll_start: float = 0.0
    roll_length: float = 0.0
    stiffness: bool = False

    kind = "wear"

    @property
    def window(self) -> tuple[float, float]:
        """Worn roll window ``(u_a, u_b)`` [rad]."""
        return self.roll_start, self.roll_start + self.roll_length

    def is_null(self) -> bool:
        return self.depth == 0 or self.roll_length == 0

    def deviation(self, roll) -> np.ndarray:
        """Profile deviation along the line of action at roll ``roll`` [m] (material
        missing)."""
        roll = np.asarray(roll, float)
        a, b = self.window
        return np.where((roll >= a) & (roll <= b), self.depth, 0.0)

    def thickness_loss(self, gear, roll) -> np.ndarray:
        """Loss of section width at the involute point of roll ``roll`` [m]:
        ``delta / cos(u - alpha_2)`` on the window, 0 elsewhere."""
        roll = np.asarray(roll, float)
        return self.deviation(roll) / np.cos(roll - gear.base_half_angle)

    def validate(self, pair, face_width: float) -> None:
        """Raise :class:`InputError` for a window off the active profile or a depth the tooth
        cannot lose."""
        self.check_place(pair)
        check_size(self.depth, self.field("depth"), "a wear depth [m]")
        check_size(self.roll_length, self.field("length"), "a worn length")
        g = gear_of(pair, self.gear)
        lo, hi = active_roll_range(pair, self.gear)
        a, b = self.window
        rb = g.base_radius
        if not (lo - 1e-12 <= a and b <= hi + 1e-12):
            raise InputError(self.field("start"), f"roll {a:.6g} to {b:.6g} rad",
                             f"a worn band inside the active profile of the {self.gear}: roll "
                             f"[{lo:.6g}, {hi:.6g}] rad, roll length [{lo * rb * 1e3:.4g}, "
                             f"{hi * rb * 1e3:.4g}] mm")
        if self.is_null():
            return
        u = np.linspace(a, b, 65)
        spare = 2 * involute_half_thickness(g, u) - np.asarray(self.thickness_loss(g, u))
        if np.min(spare) <= 0.5 * 2 * float(np.min(involute_half_thickness(g, u))):
            raise InputError(self.field("depth"), self.depth,
                             "a wear depth below half the local tooth thickness")
