"""Compliance of one tooth on its body: the beam terms plus the Sainsot foundation [m/N]."""

from __future__ import annotations

import math

import numpy as np

from .foundation import foundation_compliance
from .section import ToothSection


def tooth_compliance(section: ToothSection, roll: np.ndarray, youngs_modulus: float,
                     poisson_ratio: float, face_width: float, *,
                     terms: bool = False, theta_f: float | None = None
                     ) -> np.ndarray | dict[str, np.ndarray]:
    """Compliance of one tooth on its body, ``1/k_b + 1/k_s + 1/k_a + 1/k_f`` [m/N].

    Parameters
    ----------
    section : ToothSection
    roll : array_like
        Roll angle of the load point [rad].
    youngs_modulus, poisson_ratio, face_width : float
        ``E`` [Pa], ``nu`` [-], ``L`` [m].
    terms : bool
        Return a dict of the four terms (``bending``, ``shear``, ``axial``, ``foundation``)
        instead of their sum.
    theta_f : float, optional
        Root half-angle of the foundation term [rad]; default ``Gear.root_half_angle``.
    """
    roll = np.atleast_1d(np.asarray(roll, float))
    section.check_roll(roll)
    E, nu, L = youngs_modulus, poisson_ratio, face_width
    y, w, wq = section.nodes(roll)
    a1 = roll - section.gear.base_half_angle
    arm = section.gear.base_radius - y * np.cos(a1)[:, None]
    jw = np.sum(wq / w, axis=1)
    t = {
        "bending": np.sum(wq * 12.0 * arm ** 2 / w ** 3, axis=1) / (E * L),
        "shear": 2.4 * (1 + nu) * np.cos(a1) ** 2 * jw / (E * L),
        "axial": np.sin(a1) ** 2 * jw / (E * L),
        "foundation": foundation_compliance(section.gear, roll, E, L, theta_f=theta_f),
    }
    return t if terms else t["bending"] + t["shear"] + t["axial"] + t["foundation"]


def tooth_compliance_quad(section: ToothSection, roll: float, youngs_modulus: float,
                          poisson_ratio: float, face_width: float, *, epsabs: float = 1e-14,
                          epsrel: float = 1e-12, theta_f: float | None = None) -> float:
    """The tooth compliance of :func:`tooth_compliance` by adaptive ``scipy.integrate.quad`` on
    each piece, from scratch (reference for tests and the benchmark's baseline) [m/N].

    The integrals are in units of 1/m (compliance times ``E L``), so ``epsabs`` is absolute.
    """
    from scipy.integrate import quad

    roll = float(roll)
    a1 = roll - section.gear.base_half_angle
    ca, sa = math.cos(a1), math.sin(a1)
    rb = section.gear.base_radius
    nu = poisson_ratio
    total = 0.0
    for p in section.pieces:
        top = min(max(roll, p.t0), p.t1) if p.kind == "involute" else p.t1
        if top == p.t0:
            continue

        def f(t, p=p):
            h, y, dy = section._eval(p, np.array([t]))
            w = float(section.width(y, h)[0])
            y0, dy0 = float(y[0]), float(dy[0])
            return (12.0 * (rb - y0 * ca) ** 2 / w ** 3
                    + (2.4 * (1 + nu) * ca ** 2 + sa ** 2) / w) * dy0

        total += quad(f, p.t0, top, epsabs=epsabs, epsrel=epsrel, limit=200)[0]
    found = float(foundation_compliance(section.gear, roll, youngs_modulus, face_width,
                                        theta_f=theta_f)[0])
    return total / (youngs_modulus * face_width) + found
