r"""Fillet-foundation (gear body) compliance of Sainsot, Velex & Duverger (2004).

.. math:: \frac{1}{k_f} = \frac{\cos^2\alpha_1}{E L}\left\{L^*\left(\frac{u_f}{S_f}\right)^2
          + M^*\frac{u_f}{S_f} + P^*\left(1 + Q^*\tan^2\alpha_1\right)\right\}

with ``X* = A/theta_f^2 + B h_f^2 + C h_f/theta_f + D/theta_f + E h_f + F`` for each of ``L*, M*,
P*, Q*``, ``h_f = r_f / r_int`` and ``S_f = 2 r_f theta_f``.

Sources actually read: the paper itself could not be reached from this workplace. The formula and
the coefficient table are those of two independent public implementations that cite it, which
agree digit for digit: ROSS (``petrobras/ross``, ``ross/gear_element.py``,
``GearElementTVMS._inv_kf``) and the PHM-BGU gear model (``calcInvFilletFoundationStiff.m``, which
defines ``theta_f`` as the angle between the tooth centreline and the profile point on the root
circle and ``u`` as the distance from the root circle to where the load line crosses the
centreline). The test ``tests/stiffness/test_pem_oracles.py`` re-evaluates the formula from this
transcription.

The root half-angle ``theta_f`` (:func:`root_half_angle`)
--------------------------------------------------------
The literature uses three definitions; ``stiffness.foundation_half_angle`` picks one:

* ``"fillet"`` (default): the half-angle of the generated tooth where its trochoid fillet reaches
  the root circle, measured on geardyn's outline (``Gear.root_half_angle``). For an ISO 53 rack
  (h_a* = 1, c* = 0.25, rho* = 0.38) and x = 0 it is
  ``[pi/2 + 2 tan(alpha)(h_a* + c* - rho*) + 2 rho*/cos(alpha)]/z = 3.013/z``; it is the
  definition PHM-BGU measures on its own profile (``atan`` of the root point).
* ``"ross"``: ROSS's closed form ``[pi/2 + 2 tan(alpha)(h_a* - rho*) + 2 rho*/cos(alpha)]/z``
  (2.831/z for the same rack, no profile shift), which puts the gear addendum where the rack
  addendum ``h_a* + c*`` belongs (trap T8 of docs/verification/stiffness.md); reproduces ROSS.
* ``"alpha3"``: ``alpha_3 = arcsin(r_b sin(alpha_2) / r_f)``, the root-rectangle angle of Wan et
  al. (2014) and of the codes that model the root below the base circle as a rectangle
  (0.0877 rad for the paper's 23-tooth gear).
* a number: that angle [rad].

On the paper's 23-tooth gears the three give 0.1310, 0.1231 and 0.0877 rad, and the PEM mesh
stiffness ``-2.1 %`` (``"ross"``) and ``-16 %`` (``"alpha3"``) from ``"fillet"``.

The range of the fit
--------------------
ROSS warns when a fitted coefficient ``X*`` leaves the interval spanned by its tabulated values
(``L* in [6.82, 6.94]``, ``M* in [1.08, 3.29]``, ``P* in [2.56, 13.47]``, ``Q* in [0.141, 0.62]``);
that live check is what :func:`sainsot_validity` reports as a :class:`SainsotRangeWarning`,
together with ``h_f in [1.4, 7]``. Both ``h_f in [1.4, 7]`` and ``theta_f in [0.01, 0.12]`` rad
appear only in one commented-out line of the ROSS code, with no source; neither could be checked
against the paper. geardyn keeps the ``h_f`` box as a warning (the bore is the user's choice and
the fit depends strongly on it, trap T11), but no longer warns for the ``theta_f`` box: every
rack-generated definition except ``alpha3`` puts any gear with fewer than about 25 teeth outside
it (the paper's 23-tooth gears, the 19-tooth pinion of Tian 2004 and Wu et al. 2008), while the
fitted coefficients of those gears stay inside ROSS's envelope. :func:`sainsot_validity` still
returns it as a note with ``notes=True``, and the stiffness map records it in
``attrs["notes"]``.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from ...errors import InputError


class SainsotRangeWarning(UserWarning):
    """The fillet-foundation formula is used outside the range Sainsot et al. (2004) fitted."""


#: Choices of the root half-angle, see :func:`root_half_angle`.
HALF_ANGLE_CHOICES = ("fillet", "ross", "alpha3")


def root_half_angle(gear, choice: str | float = "fillet") -> float:
    """The root half-angle ``theta_f`` of the Sainsot term for one gear [rad].

    Parameters
    ----------
    gear : geardyn.geometry.Gear
    choice : {"fillet", "ross", "alpha3"} or float
        Definition (module docstring) or an angle in rad, in (0, pi/z).

    Returns
    -------
    float
        ``theta_f`` [rad].
    """
    if isinstance(choice, str):
        key = choice.strip().lower()
        if key == "fillet":
            return gear.root_half_angle
        if key == "ross":
            a = gear.pressure_angle
            rho = gear.tool_tip_radius / gear.module
            return (math.pi / 2 + 2 * math.tan(a) * (gear.addendum_coefficient - rho)
                    + 2 * rho / math.cos(a)) / gear.teeth
        if key == "alpha3":
            if gear.root_radius >= gear.base_radius:
                raise InputError("stiffness.foundation_half_angle", choice,
                                 "'fillet', 'ross' or an angle: alpha3 (the root rectangle of Wan "
                                 f"et al.) needs a root circle below the base circle ({gear.teeth} "
                                 "teeth have none)")
            return math.asin(gear.base_radius * math.sin(gear.base_half_angle) / gear.root_radius)
        raise InputError("stiffness.foundation_half_angle", choice,
                         "'fillet', 'ross', 'alpha3' or an angle in rad")
    value = float(choice)
    if not (math.isfinite(value) and 0 < value < math.pi / gear.teeth):
        raise InputError("stiffness.foundation_half_angle", choice,
                         f"an angle in (0, pi/z) = (0, {math.pi / gear.teeth:.4g}) rad")
    return value


#: Envelope of the fitted coefficients X* (ROSS ``_inv_kf``): outside it the fit is extrapolated.
SAINSOT_COEFFICIENT_RANGE = {"L": (6.82, 6.94), "M": (1.08, 3.29), "P": (2.56, 13.47),
                             "Q": (0.141, 0.62)}


#: Coefficients A..F of L*, M*, P*, Q* (Sainsot, Velex & Duverger 2004; docs/verification/stiffness.md 1.3).
SAINSOT_TABLE = {
    "L": (-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045),
    "M": (60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086),
    "P": (-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236),
    "Q": (-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904),
}
#: Range of h_f = r_f / r_int (a warning) and the unsourced theta_f box [rad] (a note only).
SAINSOT_RANGE = {"h_f": (1.4, 7.0), "theta_f": (0.01, 0.12)}


def sainsot_coefficients(h_f: float, theta_f: float) -> dict[str, float]:
    r"""``L*, M*, P*, Q*`` of Sainsot et al. (2004):
    ``X* = A/theta_f^2 + B h_f^2 + C h_f/theta_f + D/theta_f + E h_f + F``.

    Parameters
    ----------
    h_f : float
        ``r_f / r_int``, root radius over bore radius [-].
    theta_f : float
        Half-angle of the tooth at the root circle [rad].
    """
    out = {}
    for name, (a, b, c, d, e, f) in SAINSOT_TABLE.items():
        out[name] = (a / theta_f ** 2 + b * h_f ** 2 + c * h_f / theta_f + d / theta_f + e * h_f
                     + f)
    return out


def sainsot_validity(gear, theta_f: float | None = None, bore_radius: float | None = None,
                     *, notes: bool = False) -> list[str]:
    """Why the Sainsot formula is extrapolated for this gear, in words (empty if it is not).

    Reports ``h_f = r_f / r_int`` outside ``[1.4, 7]`` and fitted coefficients ``X*`` outside
    the envelope of :data:`SAINSOT_COEFFICIENT_RANGE` (the check ROSS applies). With ``notes``,
    also ``theta_f`` outside the unsourced box ``[0.01, 0.12]`` rad (module docstring).

    Parameters
    ----------
    gear : geardyn.geometry.Gear
    theta_f, bore_radius : float, optional
        Overrides of the root half-angle [rad] and the bore radius [m].
    notes : bool
        Include the informational ``theta_f`` note.
    """
    theta_f = gear.root_half_angle if theta_f is None else theta_f
    h_f = gear.root_radius / (gear.bore_radius if bore_radius is None else bore_radius)
    out = []
    lo, hi = SAINSOT_RANGE["h_f"]
    if not lo <= h_f <= hi:
        out.append(f"h_f = r_f/r_int = {h_f:.4g} outside the fitted range [{lo}, {hi}] of Sainsot "
                   "et al. (2004)")
    for name, value in sainsot_coefficients(h_f, theta_f).items():
        lo, hi = SAINSOT_COEFFICIENT_RANGE[name]
        if not lo <= value <= hi:
            out.append(f"{name}* = {value:.4g} outside the range [{lo}, {hi}] of the fitted "
                       f"coefficients of Sainsot et al. (2004) (h_f = {h_f:.4g}, theta_f = "
                       f"{theta_f:.4g} rad)")
    lo, hi = SAINSOT_RANGE["theta_f"]
    if notes and not lo <= theta_f <= hi:
        out.append(f"theta_f = {theta_f:.4g} rad outside [{lo}, {hi}] rad, a bound of unknown "
                   "source (a commented-out line of the ROSS code); the fitted coefficients stay "
                   "in their range")
    return out


def foundation_compliance(gear, roll: np.ndarray, youngs_modulus: float, face_width: float,
                          *, theta_f: float | None = None, bore_radius: float | None = None,
                          warn: bool = False) -> np.ndarray:
    r"""Fillet-foundation (gear body) compliance, Sainsot, Velex & Duverger (2004) [m/N].

    .. math:: \frac{1}{k_f} = \frac{\cos^2\alpha_1}{E L}\left\{L^*\left(\frac{u_f}{S_f}\right)^2
              + M^*\frac{u_f}{S_f} + P^*\left(1 + Q^*\tan^2\alpha_1\right)\right\}

    with ``u_f = r_b / cos(alpha_1) - r_f`` (root circle to where the load line crosses the
    centreline, trap T9), ``S_f = 2 r_f theta_f`` and ``theta_f`` the root half-angle (default
    the generated outline's, ``Gear.root_half_angle``, 3.013/z for the ISO 53 rack; trap T8;
    :func:`root_half_angle` gives the other definitions), with the gear's own bore
    (``h_f = r_f / r_int``, trap T11).

    Parameters
    ----------
    gear : geardyn.geometry.Gear
    roll : array_like
        Roll angle of the load point [rad].
    youngs_modulus, face_width : float
        ``E`` [Pa], ``L`` [m].
    theta_f : float, optional
        Override of the root half-angle [rad] (e.g. ``alpha_3`` to reproduce Wan-type codes).
    bore_radius : float, optional
        Override of the bore radius [m]; default ``gear.bore_radius``.
    warn : bool
        Emit :class:`SainsotRangeWarning` outside the fitted range.
    """
    roll = np.atleast_1d(np.asarray(roll, float))
    theta_f = gear.root_half_angle if theta_f is None else float(theta_f)
    r_int = gear.bore_radius if bore_radius is None else float(bore_radius)
    rf = gear.root_radius
    if warn:
        for msg in sainsot_validity(gear, theta_f, r_int):
            warnings.warn(msg, SainsotRangeWarning, stacklevel=2)
    c = sainsot_coefficients(rf / r_int, theta_f)
    a1 = roll - gear.base_half_angle
    uf = gear.base_radius / np.cos(a1) - rf
    sf = 2.0 * rf * theta_f
    x = uf / sf
    return (np.cos(a1) ** 2 / (youngs_modulus * face_width)
            * (c["L"] * x ** 2 + c["M"] * x + c["P"] * (1.0 + c["Q"] * np.tan(a1) ** 2)))
