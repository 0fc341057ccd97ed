r"""The section of a worn tooth for the PEM beam terms (:mod:`geardyn.faults.wear`).

Uniform wear of depth ``delta`` normal to the loaded flank over the roll window ``[u_a, u_b]``
thins the sections of that band: at the involute point of roll ``u`` (height ``y``,
half-thickness ``h``) the load-carrying width becomes

.. math:: w = 2 h - \frac{\delta}{\cos\alpha_1}, \qquad \alpha_1 = u - \alpha_2 ,

since the flank normal (the line of action) makes the angle ``alpha_1`` with the tooth's
transverse axis. The roll of a section's involute point follows from its radius,
``u = sqrt((h^2 + y^2) / r_b^2 - 1)``. Geometry only; no published wear-stiffness formula was
read for this (see :mod:`geardyn.faults.wear`).
"""

from __future__ import annotations

import numpy as np

from .profile import _involute_xy
from .section import N_GAUSS, ToothSection


class WornSection(ToothSection):
    """A :class:`ToothSection` with a worn band on its loaded flank.

    Parameters
    ----------
    gear : geardyn.geometry.Gear
    wear : geardyn.faults.Wear
    model : {"exact", "classic"}
    n_gauss : int
    """

    def __init__(self, gear, wear, *, model: str = "exact", n_gauss: int = N_GAUSS):
        self.wear = wear
        super().__init__(gear, None, model=model, n_gauss=n_gauss)
        ys = [float(_involute_xy(gear, u)[1]) for u in wear.window]
        self.pieces = tuple(self._split(list(self.pieces), ys))
        self.roll_breaks = tuple(p.t0 for p in self.pieces
                                 if p.kind == "involute" and p.t0 > self.u_min)

    def width(self, y: np.ndarray, h: np.ndarray) -> np.ndarray:
        """Load-carrying width: ``2 h`` less the worn thickness on the band [m]."""
        rb = self.gear.base_radius
        u = np.sqrt(np.maximum((np.asarray(h) ** 2 + np.asarray(y) ** 2) / rb ** 2 - 1.0, 0.0))
        return 2.0 * np.asarray(h) - self.wear.thickness_loss(self.gear, u)
