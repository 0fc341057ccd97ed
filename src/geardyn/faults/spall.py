"""A rectangular spall (pit) on the flank of one tooth: parameters, validation and the contact it
removes.

Geometry. The spall covers the roll window ``[u_a, u_a + du]`` of its tooth's loaded involute
(roll angle ``u``, or roll length ``r_b u`` along the line of action, :mod:`geardyn.faults.base`)
over a width ``b_s`` across the face, to a depth ``d_s`` below the flank. While the contact line
crosses the window, the material of the spall is missing, so the contact line is shorter by
``b_s``: the tooth pair carries its load on ``L - b_s`` of the face width ``L``.

What the PEM does with it (:mod:`geardyn.stiffness.pem.spall`): the effective-width model, every
energy term of the pair (Hertz, bending, shear, axial compression, fillet foundation) with ``L``
replaced by ``L - b_s`` while the contact point lies inside the window. Sources: Chaari, Baccar,
Abbes & Haddar (2008, Eur. J. Mech. A/Solids 27:691-705) introduced this model for spalls; the
paper itself could not be read from this workplace. What was read is the public PHM-BGU gear
model (MATLAB, Ben-Gurion University 2023; files ``calcKeq.m`` and ``calcInvBendingStiff.m``),
which for a partial-face fault computes the Hertz and fillet-foundation terms with the tooth
width minus the defect width and the mating tooth's bending with that reduced contact width. The
depth does not enter the effective-width model (the flank is assumed not to touch the bottom of
the spall, i.e. ``d_s`` larger than the static approach of the pair, a few micrometres); it is
validated against the tooth thickness.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .base import FaultBase, active_roll_range, check_size, gear_of


def involute_half_thickness(gear, u) -> np.ndarray:
    """Half-thickness of a tooth at the involute point of roll ``u`` [m] (Tian's parameter
    ``alpha = alpha_2 - u``: ``h = r_b (u cos(alpha) + sin(alpha))``)."""
    a = gear.base_half_angle - np.asarray(u, float)
    return gear.base_radius * (np.asarray(u, float) * np.cos(a) + np.sin(a))


@dataclass(frozen=True)
class Spall(FaultBase):
    """A rectangular spall on the loaded flank of one tooth.

    Parameters
    ----------
    gear, tooth, label
        See :class:`geardyn.faults.base.FaultBase`.
    roll_start : float
        Roll angle of the spall's lower edge on the involute [rad].
    roll_length : float
        Roll-angle extent of the spall along the profile [rad] (0: no spall).
    width : float
        Extent across the face width [m] (0: no spall).
    depth : float
        Depth below the flank [m].
    """

    roll_start: float = 0.0
    roll_length: float = 0.0
    width: float = 0.0
    depth: float = 0.0

    kind = "spall"

    @property
    def window(self) -> tuple[float, float]:
        """Roll window ``(u_a, u_b)`` of the spall [rad]."""
        return self.roll_start, self.roll_start + self.roll_length

    def is_null(self) -> bool:
        return self.roll_length == 0 or self.width == 0 or self.depth == 0

    def width_lost(self, roll) -> np.ndarray:
        """Contact width missing when the contact point is at roll ``roll`` [m]."""
        roll = np.asarray(roll, float)
        if self.is_null():
            return np.zeros(roll.shape)
        a, b = self.window
        return np.where((roll >= a) & (roll <= b), self.width, 0.0)

    def validate(self, pair, face_width: float) -> None:
        """Raise :class:`InputError` naming the field for a spall off the active profile,
        wider than the face or deeper than the tooth."""
        self.check_place(pair)
        check_size(self.roll_length, self.field("length"), "a spall length")
        check_size(self.width, self.field("width"), "a spall width [m]", upper=face_width,
                   upper_text=" m (the face width)")
        check_size(self.depth, self.field("depth"), "a spall depth [m]")
        g = gear_of(pair, self.gear)
        lo, hi = active_roll_range(pair, self.gear)
        a, b = self.window
        rb = g.base_radius
        if not (math.isfinite(a) and lo - 1e-12 <= a and b <= hi + 1e-12):
            raise InputError(self.field("start"), f"roll {a:.6g} to {b:.6g} rad "
                             f"(roll length {a * rb * 1e3:.4g} to {b * rb * 1e3:.4g} mm)",
                             f"a spall inside the active profile of the {self.gear}: roll "
                             f"[{lo:.6g}, {hi:.6g}] rad, roll length [{lo * rb * 1e3:.4g}, "
                             f"{hi * rb * 1e3:.4g}] mm at the nominal centre distance")
        h_min = float(np.min(involute_half_thickness(g, np.array([a, b]))))
        if self.depth >= 2 * h_min:
            raise InputError(self.field("depth"), self.depth,
                             f"a spall depth below the tooth thickness over the spall "
                             f"({2 * h_min:.4g} m)")
