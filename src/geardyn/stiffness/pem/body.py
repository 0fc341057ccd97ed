"""Torsion of a gear body between its bore and its root circle (plane elasticity)."""

from __future__ import annotations

import math


def body_torsion_compliance(gear, youngs_modulus: float, poisson_ratio: float,
                            face_width: float | None = None) -> float:
    r"""Torsional compliance of a gear body between its bore and its root circle [rad/(N m)].

    Axisymmetric torsion of an annulus of thickness ``b`` (exact in plane elasticity): the shear
    stress is :math:`\tau = T / (2 \pi r^2 b)`, so :math:`d\varphi/dr = \tau/(G r)` and

    .. math:: \varphi / T = \frac{1}{4 \pi G b}\left(\frac{1}{r_{int}^2}
              - \frac{1}{r_f^2}\right), \qquad G = \frac{E}{2(1 + \nu)}

    (Timoshenko & Goodier, Theory of Elasticity, 3rd ed., section 33). Along the line of action
    it is a compliance :math:`r_b^2 \varphi/T` [m/N] in series with the mesh.

    Parameters
    ----------
    gear : geardyn.geometry.Gear
    youngs_modulus : float
        ``E`` [Pa].
    poisson_ratio : float
        ``nu`` [-].
    face_width : float, optional
        ``b`` [m]; default the gear's face width.
    """
    b = gear.face_width if face_width is None else face_width
    g = youngs_modulus / (2 * (1 + poisson_ratio))
    return (1 / gear.bore_radius ** 2 - 1 / gear.root_radius ** 2) / (4 * math.pi * g * b)
