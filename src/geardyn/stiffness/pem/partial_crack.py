r"""A root crack through part of the face width by the slicing method (Chen & Shao 2011).

The tooth is cut into slices across the face; slice ``i`` has the face-width fraction ``f_i``
and its own crack depth ``q_i`` (:meth:`geardyn.faults.RootCrack.slice_depths`). Each slice is a
cantilever of the full tooth section with its own crack (:class:`ToothSection`), loaded along the
same contact line; the slices deflect together, so their beam stiffnesses add:

.. math:: \frac{1}{k_{beam}} = \left(\sum_i \frac{f_i}{c_{beam}(q_i)}\right)^{-1},
          \qquad c_{beam} = \frac{1}{k_b} + \frac{1}{k_s} + \frac{1}{k_a}

with ``c_beam(q)`` the compliance of a whole-face tooth with a crack ``q`` (each slice of width
``f_i L`` has the compliance ``c_beam(q_i) / f_i``). The fillet foundation stays the whole
tooth's term, in series. This is the slicing of Chen & Shao (2011, Eng. Fail. Anal.
18:2149-2164), which could not be read from this workplace; it is checked here by its limits (one
slice of full width and uniform depth is today's ``[crack]`` tooth to round-off; zero depth is the
healthy tooth) and by convergence in the number of slices (``tests/faults/test_root_crack.py``).
"""

from __future__ import annotations

import numpy as np

from .foundation import foundation_compliance
from .section import ToothSection


class SlicedTooth:
    """Compliance of a tooth with a crack through part of its face width [m/N].

    Parameters
    ----------
    model : geardyn.stiffness.pem.PEMModel
        The pair's model: its sections and compliance tables are extended with one entry per
        slice depth (keys ``(which, ("slice", tooth, k))``).
    crack : geardyn.faults.RootCrack
    """

    def __init__(self, model, crack):
        self.model = model
        self.which = crack.gear
        gear = model.pair.pinion if crack.gear == "pinion" else model.pair.gear
        self.gear = gear
        depths, fractions = crack.slice_depths()
        self.parts: list[tuple[float, object]] = []
        keys: dict[float, object] = {}
        for q, f in zip(depths, fractions, strict=True):
            if f == 0:
                continue
            if q <= 0:
                key = False  # the healthy tooth's table
            elif float(q) in keys:
                key = keys[float(q)]
            else:
                key = ("slice", int(crack.tooth), len(keys))
                keys[float(q)] = key
                model.sections[(self.which, key)] = ToothSection(
                    gear, crack.tooth_crack(float(q)), model=model.model)
            self.parts.append((float(f), key))
        self.section = model.sections[(self.which, False)]

    def compliance(self, roll) -> np.ndarray:
        """Tooth compliance (beam slices in parallel, foundation in series) at roll ``roll``
        [m/N]."""
        m = self.model
        roll = np.asarray(roll, float)
        cf = foundation_compliance(self.gear, roll, m.E, m.L, theta_f=m.theta_f[self.which])
        stiff = np.zeros(roll.shape)
        for f, key in self.parts:
            stiff += f / (m.tooth_compliance(self.which, roll, key) - cf)
        return 1.0 / stiff + cf
