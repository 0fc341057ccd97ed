"""Tooth breakage: the tip of one tooth missing, over the whole face or part of it.

Geometry. The tooth is cut at the radius ``r_a - Delta h`` (``Delta h`` the height lost,
measured radially from the tip circle) over a width ``b_t`` of the face (default: the whole face).
The involute above the cut, roll angles ``u > u_c = sqrt((r_a - Delta h)^2 / r_b^2 - 1)``, is gone
there, so the contact ends early on that part of the face: above ``u_c`` the pair carries its load
on ``L - b_t`` (nothing when the whole face is broken).

What the PEM does with it (:mod:`geardyn.stiffness.pem.spall`, the same contact-width machinery
as a spall): below ``u_c`` the tooth is unchanged, since every beam term of the potential energy
method integrates only the sections below the load point, so the material above it stores no
energy; above ``u_c`` the pair's terms use the remaining width ``L - b_t``. The public PHM-BGU gear
model (``calcKeq.m``, read) does the same for a tooth breakage over the whole face: it sets the
pair stiffness to zero at the profile points above ``tip - tipLoss``. Chaari et al. (2008) treat
breakage with the effective-width idea as well; that paper could not be read here. A chipped
corner (a cut that is not parallel to the tip) is not modelled.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .base import FaultBase, check_size, gear_of


@dataclass(frozen=True)
class Breakage(FaultBase):
    """Part of one tooth's tip missing.

    Parameters
    ----------
    gear, tooth, label
        See :class:`geardyn.faults.base.FaultBase`.
    height : float
        Height lost, radially from the tip circle [m] (0: no breakage).
    width : float or None
        Part of the face width broken [m]; ``None``: the whole face.
    face_width : float
        Face width ``L`` of the tooth [m] (for ``width=None``).
    """

    height: float = 0.0
    width: float | None = None
    face_width: float = 0.0

    kind = "breakage"

    @property
    def broken_width(self) -> float:
        """Width across the face that is broken [m]."""
        return self.face_width if self.width is None else float(self.width)

    def is_null(self) -> bool:
        return self.height == 0 or self.broken_width == 0

    def cut_roll(self, gear) -> float:
        """Roll angle ``u_c`` of the cut on the involute [rad] (0 if the cut is below the base
        circle: no involute left)."""
        r = gear.tip_radius - self.height
        return math.sqrt(max((r / gear.base_radius) ** 2 - 1.0, 0.0))

    def width_lost(self, gear, roll) -> np.ndarray:
        """Contact width missing at roll ``roll`` of the tooth [m]."""
        roll = np.asarray(roll, float)
        if self.is_null():
            return np.zeros(roll.shape)
        return np.where(roll > self.cut_roll(gear), self.broken_width, 0.0)

    def validate(self, pair, face_width: float) -> None:
        """Raise :class:`InputError` for a breakage deeper than the tooth or wider than the
        face."""
        self.check_place(pair)
        g = gear_of(pair, self.gear)
        whole = g.tip_radius - g.root_radius
        check_size(self.height, self.field("height"), "a height lost [m]")
        if self.height >= whole:
            raise InputError(self.field("height"), self.height,
                             f"a height lost below the whole tooth height r_a - r_f = "
                             f"{whole:.4g} m")
        if self.width is not None:
            check_size(self.width, self.field("width"), "a broken width [m]",
                       upper=face_width, upper_text=" m (the face width)")
