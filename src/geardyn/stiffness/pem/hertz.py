"""Hertzian contact compliance of a tooth pair (Yang & Lin 1987, J. Mech. Transm. Autom. Des.
109:189-196)."""

from __future__ import annotations

import math


def hertz_compliance(youngs_modulus: float, poisson_ratio: float, face_width: float) -> float:
    r"""Hertzian contact compliance of a tooth pair, Yang & Lin (1987) [m/N].

    .. math:: \frac{1}{k_h} = \frac{4 (1 - \nu^2)}{\pi E L}

    Constant along the path of contact and independent of the load: Yang & Lin's (1987)
    linearised Hertz energy of two cylinders of the same material (``docs/verification/stiffness.md`` 1.1;
    equation numbers of the cited papers were not re-read and are not quoted).

    Parameters
    ----------
    youngs_modulus : float
        ``E`` [Pa].
    poisson_ratio : float
        ``nu`` [-].
    face_width : float
        ``L`` [m].
    """
    return 4.0 * (1.0 - poisson_ratio ** 2) / (math.pi * youngs_modulus * face_width)
