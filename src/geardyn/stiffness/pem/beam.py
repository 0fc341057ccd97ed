"""Bending, shear and axial-compression compliances of one tooth as a non-uniform cantilever.

Yang & Lin (1987); Tian (2004, MSc thesis, University of Alberta); Wu, Zuo & Parey (2008, J. Sound
Vib. 317:608-624) for the involute from the base circle; Ma et al. (2014) for the trochoid fillet;
Chen & Shao (2011) for the cracked section. The integrands are written in the centreline height
``y`` (docs/verification/stiffness.md, section 1).
"""

from __future__ import annotations

import numpy as np

from .section import ToothSection


def bending_compliance(section: ToothSection, roll: np.ndarray, youngs_modulus: float,
                       face_width: float) -> np.ndarray:
    r"""Bending compliance of one tooth, load at roll angle ``roll`` [m/N].

    Yang & Lin (1987); Tian (2004) (involute from the base circle); Ma et al. (2014) for the
    trochoid fillet; Chen & Shao (2011) for the cracked section (``docs/verification/stiffness.md`` 1.1):

    .. math:: \frac{1}{k_b} = \int_{y_0}^{y_F} \frac{12\,(r_b - y\cos\alpha_1)^2}{E L w(y)^3}\,dy

    which for ``w = 2h`` on the involute equals Tian's
    ``int 3{1 + cos a1[(a2 - a) sin a - cos a]}^2 (a2 - a) cos a / (2EL[sin a + (a2 - a) cos a]^3) da``.

    Parameters
    ----------
    section : ToothSection
    roll : array_like
        Roll angle ``phi`` of the load point [rad]; ``alpha_1 = phi - alpha_2``.
    youngs_modulus, face_width : float
        ``E`` [Pa], ``L`` [m].
    """
    roll = np.atleast_1d(np.asarray(roll, float))
    y, w, wq = section.nodes(roll)
    ca = np.cos(roll - section.gear.base_half_angle)[:, None]
    arm = section.gear.base_radius - y * ca
    return np.sum(wq * 12.0 * arm ** 2 / w ** 3, axis=1) / (youngs_modulus * face_width)


def shear_compliance(section: ToothSection, roll: np.ndarray, youngs_modulus: float,
                     poisson_ratio: float, face_width: float) -> np.ndarray:
    r"""Shear compliance of one tooth [m/N], Yang & Lin (1987); Tian (2004):

    .. math:: \frac{1}{k_s} = \int_{y_0}^{y_F} \frac{1.2\cos^2\alpha_1}{G\,w L}\,dy
              = \int_{y_0}^{y_F} \frac{2.4 (1+\nu)\cos^2\alpha_1}{E L w(y)}\,dy

    (shear coefficient 1.2 of a rectangular section, ``G = E / (2(1 + nu))``).

    Parameters
    ----------
    section : ToothSection
    roll : array_like
        Roll angle of the load point [rad].
    youngs_modulus, poisson_ratio, face_width : float
        ``E`` [Pa], ``nu`` [-], ``L`` [m].
    """
    roll = np.atleast_1d(np.asarray(roll, float))
    _, w, wq = section.nodes(roll)
    c2 = np.cos(roll - section.gear.base_half_angle) ** 2
    return 2.4 * (1 + poisson_ratio) * c2 * np.sum(wq / w, axis=1) / (youngs_modulus * face_width)


def axial_compression_compliance(section: ToothSection, roll: np.ndarray, youngs_modulus: float,
                                 face_width: float) -> np.ndarray:
    r"""Axial compression compliance of one tooth [m/N], Yang & Lin (1987); Tian (2004):

    .. math:: \frac{1}{k_a} = \int_{y_0}^{y_F} \frac{\sin^2\alpha_1}{E L w(y)}\,dy

    Parameters
    ----------
    section : ToothSection
    roll : array_like
        Roll angle of the load point [rad].
    youngs_modulus, face_width : float
        ``E`` [Pa], ``L`` [m].
    """
    roll = np.atleast_1d(np.asarray(roll, float))
    _, w, wq = section.nodes(roll)
    s2 = np.sin(roll - section.gear.base_half_angle) ** 2
    return s2 * np.sum(wq / w, axis=1) / (youngs_modulus * face_width)
