r"""ISO 6336-1 (method B) single stiffness ``c'`` and mesh stiffness ``c_gamma_alpha``.

A reference for the level of any mesh stiffness computed by geardyn (or by a user). ISO gives one
number per pair, not a curve against the pinion angle, and depends on the centre distance only
through the contact ratio (trap T16 of ``docs/verification/stiffness.md``).

.. math::
   q' = C_1 + \frac{C_2}{z_{n1}} + \frac{C_3}{z_{n2}} + C_4 x_1 + \frac{C_5 x_1}{z_{n1}}
        + C_6 x_2 + \frac{C_7 x_2}{z_{n2}} + C_8 x_1^2 + C_9 x_2^2 \quad [\mathrm{mm\,\mu m/N}]

   c'_{th} = 1/q', \qquad c' = c'_{th}\, C_M C_R C_B \cos\beta\, \xi
   \qquad c_{\gamma\alpha} = c' (0.75\,\varepsilon_\alpha + 0.25)

with ``C_M = 0.8`` (measured against theoretical), the rim factor ``C_R`` (1 for solid discs),
the basic rack factor ``C_B = [1 + 0.5(1.2 - h_fP/m)][1 - 0.02(20 deg - alpha_P)]`` and the
material ratio ``xi = E / E_st`` with ``E = 2 E_1 E_2/(E_1 + E_2)`` and ``E_st = 206 GPa``.
Note that ``x_2^2`` goes with ``C_9`` (trap T15: one open code multiplies ``C_9`` by ``x_1^2``) and
that ``c_gamma_alpha`` is not ``c_gamma_alpha + c_gamma_beta``.

Units: geardyn returns stiffness per unit face width in SI, N/m per m = N/m^2; the standard's
unit is N/(mm um) = 1e9 N/m^2 (:data:`N_PER_MM_UM`). Multiply by the face width for N/m.

References
----------
ISO 6336-1:2006/2019, Calculation of load capacity of spur and helical gears - Part 1: Basic
principles, introduction and general influence factors (tooth stiffness parameters c' and
c_gamma_alpha; the formulas as collected in docs/verification/stiffness.md 4.3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InputError

__all__ = ["IsoStiffness", "iso_single_stiffness", "iso_mesh_stiffness", "iso_stiffness",
           "rim_factor", "Q_COEFFICIENTS", "N_PER_MM_UM", "E_STEEL"]

#: C1..C9 of the q' formula [mm um / N] (ISO 6336-1, method B).
Q_COEFFICIENTS = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529,
                  0.00182)
#: 1 N/(mm um) in N/m^2.
N_PER_MM_UM = 1e9
#: Reference modulus of steel in ISO 6336-1 [Pa].
E_STEEL = 206e9
#: Correction of the theoretical to the measured stiffness.
C_M = 0.8


@dataclass(frozen=True)
class IsoStiffness:
    """ISO 6336-1 stiffness of one pair, per unit face width.

    Attributes
    ----------
    q_prime : float
        Minimum flexibility of a tooth pair ``q'`` [m^2/N] (mm um/N times 1e-9).
    c_theoretical : float
        ``c'_th = 1/q'`` [N/m^2].
    c_single : float
        Single stiffness ``c'`` [N/m^2].
    c_mesh : float
        Mesh stiffness ``c_gamma_alpha`` [N/m^2].
    contact_ratio : float
        Transverse contact ratio used [-].
    """

    q_prime: float
    c_theoretical: float
    c_single: float
    c_mesh: float
    contact_ratio: float


def rim_factor(rim_width: float, face_width: float, rim_thickness: float, module: float) -> float:
    r"""Gear blank factor ``C_R = 1 + ln(b_s/b) / (5 exp(s_R/(5 m)))`` (ISO 6336-1) [-].

    For solid discs ``C_R = 1``. Valid for ``0.2 <= b_s/b <= 1.2`` and ``s_R/m >= 1``.

    Parameters
    ----------
    rim_width : float
        Web thickness ``b_s`` [m].
    face_width : float
        ``b`` [m].
    rim_thickness : float
        Rim thickness ``s_R`` [m].
    module : float
        ``m`` [m].
    """
    ratio = rim_width / face_width
    if not 0.2 <= ratio <= 1.2:
        raise InputError("rim_width", rim_width, f"b_s/b in [0.2, 1.2] (got {ratio:.4g})")
    if rim_thickness / module < 1:
        raise InputError("rim_thickness", rim_thickness, "s_R >= m")
    return 1.0 + math.log(ratio) / (5.0 * math.exp(rim_thickness / (5.0 * module)))


def iso_single_stiffness(z1: float, z2: float, x1: float = 0.0, x2: float = 0.0, *,
                         youngs_modulus: float | tuple[float, float] = E_STEEL,
                         rim: float = 1.0, dedendum_coefficient: float = 1.25,
                         pressure_angle: float = math.radians(20), helix_angle: float = 0.0,
                         line_load: float | None = None) -> IsoStiffness:
    r"""Single stiffness ``c'`` of a spur or helical pair (ISO 6336-1 method B) [N/m^2].

    Parameters
    ----------
    z1, z2 : float
        Numbers of teeth (virtual numbers ``z/cos^3(beta_b...)`` for helical gears) [-].
    x1, x2 : float
        Profile shift coefficients [-].
    youngs_modulus : float or (float, float)
        ``E`` of both gears or ``(E_1, E_2)`` [Pa]; ``c'`` scales with
        ``(2 E_1 E_2/(E_1 + E_2)) / 206 GPa``.
    rim : float
        Gear blank factor ``C_R`` [-] (:func:`rim_factor`; 1 for solid discs).
    dedendum_coefficient : float
        Dedendum of the basic rack ``h_fP / m`` [-] (1.25 for ISO 53).
    pressure_angle : float
        Pressure angle of the basic rack ``alpha_P`` [rad].
    helix_angle : float
        ``beta`` [rad].
    line_load : float, optional
        ``F_t K_A / b`` [N/m]; below 1e5 N/m (100 N/mm) ``c'`` is multiplied by
        ``(F_t K_A/b / 100 N/mm)^0.25`` (the standard's low-load rule, as we recall it).

    Returns
    -------
    IsoStiffness
        With ``c_mesh`` and ``contact_ratio`` left NaN (see :func:`iso_mesh_stiffness`).
    """
    for name, z in (("z1", z1), ("z2", z2)):
        if not z >= 5:
            raise InputError(name, z, "a number of teeth >= 5")
    c = Q_COEFFICIENTS
    q = (c[0] + c[1] / z1 + c[2] / z2 + c[3] * x1 + c[4] * x1 / z1 + c[5] * x2 + c[6] * x2 / z2
         + c[7] * x1 ** 2 + c[8] * x2 ** 2)  # mm um / N
    c_th = 1.0 / q  # N / (mm um)
    if isinstance(youngs_modulus, tuple):
        e1, e2 = youngs_modulus
        e = 2 * e1 * e2 / (e1 + e2)
    else:
        e = float(youngs_modulus)
    c_b = ((1 + 0.5 * (1.2 - dedendum_coefficient))
           * (1 - 0.02 * (20.0 - math.degrees(pressure_angle))))
    c1 = c_th * C_M * rim * c_b * math.cos(helix_angle) * e / E_STEEL
    if line_load is not None and line_load < 1e5:
        c1 *= (line_load / 1e5) ** 0.25
    return IsoStiffness(q_prime=q * 1e-9, c_theoretical=c_th * N_PER_MM_UM,
                        c_single=c1 * N_PER_MM_UM, c_mesh=math.nan, contact_ratio=math.nan)


def iso_mesh_stiffness(c_single: float, contact_ratio: float, *,
                       low_contact_ratio_reduction: bool = True) -> float:
    r"""Mesh stiffness ``c_gamma_alpha = c' (0.75 eps_alpha + 0.25)`` [same unit as ``c_single``].

    ISO 6336-1 allows up to 10 % less for spur gears with ``eps_alpha < 1.2``; with
    ``low_contact_ratio_reduction`` the full 10 % is applied.

    Parameters
    ----------
    c_single : float
        ``c'`` [N/m^2].
    contact_ratio : float
        Transverse contact ratio ``eps_alpha`` [-].
    """
    if not contact_ratio > 0:
        raise InputError("contact_ratio", contact_ratio, "a contact ratio > 0")
    out = c_single * (0.75 * contact_ratio + 0.25)
    if low_contact_ratio_reduction and contact_ratio < 1.2:
        out *= 0.9
    return out


def iso_stiffness(pair, youngs_modulus: float | tuple[float, float] = E_STEEL,
                  centre_distance_change: float = 0.0, **kwargs) -> IsoStiffness:
    """ISO 6336-1 ``c'`` and ``c_gamma_alpha`` of a :class:`geardyn.geometry.GearPair` [N/m^2].

    The contact ratio is the physical one at ``d + centre_distance_change`` [m]; further keyword
    arguments go to :func:`iso_single_stiffness`.
    """
    p, g = pair.pinion, pair.gear
    single = iso_single_stiffness(p.teeth, g.teeth, p.profile_shift, g.profile_shift,
                                  youngs_modulus=youngs_modulus,
                                  dedendum_coefficient=p.dedendum_coefficient,
                                  pressure_angle=p.pressure_angle, **kwargs)
    eps = pair.operating(centre_distance_change).contact_ratio
    return IsoStiffness(q_prime=single.q_prime, c_theoretical=single.c_theoretical,
                        c_single=single.c_single,
                        c_mesh=iso_mesh_stiffness(single.c_single, eps), contact_ratio=eps)
