r"""Involute spur-gear geometry and the operating centre distance of a flexibly supported pair.

Conventions (used by every other module of geardyn)
----------------------------------------------------
* SI units: lengths in m, angles in rad.
* The frame of Xue & Howard (2018), Fig. 1: the pinion centre at the origin, ``y`` along the
  *nominal* line of action (LOA), ``x`` normal to it. The bearings move the centres along ``y``
  only. Because the LOA is the common tangent of the two base circles and the centres are always
  ``r_b1 + r_b2`` apart in ``x``, the LOA stays the line ``x = r_b1`` for any centre distance; only
  the tangency point ``T2`` of the gear slides along it. Hence

  .. math:: T_1T_2 = (r_{b1} + r_{b2})\tan\alpha' = (r_{b1} + r_{b2})\tan\alpha_w + y_g - y_p

  (the paper's eq. 4), and the pinion's contact positions along the LOA depend on the pinion angle
  only, while the start of contact, ``s_0 = T_1T_2 - \sqrt{r_{a2}^2 - r_{b2}^2}``, moves with the
  centre distance.
* Position along the LOA, ``s``, is measured from ``T1`` (pinion base-circle tangency point).
  The driving pinion engages near its root first, so ``s`` grows with the pinion angle.
* Pinion angle ``theta``: ``theta = 0`` when pinion tooth 0 is at the *design* pitch point. Pair
  ``n`` (pinion tooth ``n mod z1`` with gear tooth ``n mod z2``; teeth numbered in the order they
  enter mesh) is at ``s_n(theta) = r_b1 tan(alpha_w) + r_b1 theta - n p_b``.
  Pinion roll angle of a contact point ``phi_1 = s / r_b1``; gear roll ``phi_2 = (T1T2 - s) / r_b2``.

References
----------
Xue, S. & Howard, I. (2018). Dynamic modelling of flexibly supported gears using iterative
convergence of tooth mesh stiffness. Mech. Syst. Signal Process. (eqs. 1-8).
Litvin, F. L. & Fuentes, A. (2004). Gear Geometry and Applied Theory, 2nd ed., ch. 10.
ISO 21771:2007, Gears - Cylindrical involute gears and gear pairs - Concepts and geometry.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from .errors import GeometryError, InputError

__all__ = [
    "Gear",
    "GearPair",
    "OperatingGeometry",
    "ContactPoints",
    "ToothOutline",
    "inv",
    "inv_inverse",
    "centre_distance_from_displacements",
    "check_static_contact",
]


#: Largest pinion angle magnitude :meth:`GearPair.contact_points` takes [rad] (about 1.6e11
#: revolutions): the pair index ``n`` stays an exact 64-bit integer.
MAX_ANGLE = 1e12


def _real(value, field_name: str, allowed: str | Callable[[], str], *,
          finite: bool = True) -> float:
    """``value`` as a finite float (any float if not ``finite``), or :class:`InputError` naming
    ``field_name``. ``allowed``: the error's text, or a function making it (for a text that
    formats numbers, made only when there is an error: about 1 us of the 18 us a call of
    :meth:`GearPair.operating` took, same-time A/B on 2026-11-28).

    Numbers only (Python or NumPy, 0-d arrays included); a string, ``None``, a bool or an
    array with several values is refused: this module works in SI numbers (unit strings such as
    ``"1 mm"`` are read by case files and the command line, :func:`geardyn.units.to_si`).
    """
    if isinstance(value, float | int) and not isinstance(value, bool):  # np.float64 is a float
        out = float(value)
    elif (isinstance(value, np.generic | np.ndarray) and np.ndim(value) == 0
          and np.asarray(value).dtype.kind in "iuf"):
        out = float(value)
    else:
        raise InputError(field_name, value, allowed() if callable(allowed) else allowed)
    if finite and not math.isfinite(out):
        raise InputError(field_name, value, allowed() if callable(allowed) else allowed)
    return out


def _count(value, field_name: str, minimum: int) -> int:
    """``value`` as an int >= ``minimum`` (Python or NumPy integer, not a bool)."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < minimum:
        raise InputError(field_name, value, f"a whole number >= {minimum}")
    return int(value)


def inv(alpha: float | np.ndarray) -> float | np.ndarray:
    r"""Involute function :math:`\mathrm{inv}\,\alpha = \tan\alpha - \alpha` (alpha in rad)."""
    return np.tan(alpha) - alpha


def inv_inverse(value: float) -> float:
    r"""Solve :math:`\tan\alpha - \alpha = v` for ``alpha`` in [0, pi/2) [rad] (Newton, ~1e-15)."""
    if value < 0:
        raise InputError("involute", value, "a non-negative value")
    # Cheng's starting value, then Newton on f(a) = tan a - a - v, f' = tan^2 a
    a = (3.0 * value) ** (1.0 / 3.0) if value > 0 else 0.0
    a = min(a, 1.5)
    for _ in range(60):
        t = math.tan(a)
        f = t - a - value
        if a == 0.0:
            break
        step = f / (t * t)
        a -= step
        if abs(step) < 1e-16:
            break
    return a


#: The number fields of :class:`Gear` and what they take (checked for their type first, so that
#: a string is refused by name rather than failing in a comparison).
_GEAR_NUMBERS = {
    "module": "a length in m (a number; SI: 0.003 for 3 mm)",
    "pressure_angle": "an angle in rad (a number; 0.3491 for 20 deg)",
    "addendum_coefficient": "a number (in modules)",
    "dedendum_coefficient": "a number (in modules)",
    "profile_shift": "a number (in modules)",
    "face_width": "a length in m (a number; SI: 0.02 for 20 mm)",
    "bore_radius": "a length in m (a number; SI: 0.02 for 20 mm)",
    "tool_tip_radius_coefficient": "a number (in modules) or None",
}


@dataclass(frozen=True)
class Gear:
    r"""One involute spur gear cut by a standard basic rack (ISO 53 shape).

    Parameters
    ----------
    teeth : int
        Number of teeth ``z`` (>= 5).
    module : float
        Module ``m`` [m].
    pressure_angle : float
        Pressure angle of the basic rack ``alpha`` [rad], in (0, 35 deg].
    addendum_coefficient : float
        Addendum of the gear ``h_a* `` (in modules) [-]. Default 1.
    dedendum_coefficient : float
        Dedendum ``h_f*`` = addendum of the cutting rack (in modules) [-]. Default 1.25.
    tool_tip_radius_coefficient : float or None
        Tip radius of the rack ``rho*`` (in modules) [-]. ``None`` gives the largest radius that
        keeps the straight rack flank down to depth ``h_a* m``,
        ``(h_f* - h_a*) / (1 - sin alpha)`` (0.38 for 1/1.25 at 20 deg, ISO 53 profile A).
    profile_shift : float
        Profile shift coefficient ``x`` [-]. Default 0.
    face_width : float
        Face width ``b`` [m].
    bore_radius : float
        Radius of the bore (hub) ``r_int`` [m]; used by the fillet-foundation stiffness and the FE
        model, which fixes the bore.
    """

    teeth: int
    module: float
    pressure_angle: float
    addendum_coefficient: float = 1.0
    dedendum_coefficient: float = 1.25
    tool_tip_radius_coefficient: float | None = None
    profile_shift: float = 0.0
    face_width: float = 0.02
    bore_radius: float = 0.02

    def __post_init__(self) -> None:
        if isinstance(self.teeth, bool) or not isinstance(self.teeth, int | np.integer) \
                or self.teeth < 5:
            raise InputError("teeth", self.teeth, "a whole number of teeth >= 5")
        for name, what in _GEAR_NUMBERS.items():
            v = getattr(self, name)
            if v is None and name == "tool_tip_radius_coefficient":
                continue
            if isinstance(v, bool) or not isinstance(v, float | int | np.integer | np.floating):
                raise InputError(name, v, what)
        for name in ("module", "face_width", "bore_radius"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise InputError(name, v, "a finite length > 0 [m]")
        if not (0 < self.pressure_angle <= math.radians(35)):
            raise InputError("pressure_angle", self.pressure_angle,
                             "a pressure angle in (0, 35 deg], given in rad (0.3491 = 20 deg)")
        if not (0 < self.addendum_coefficient <= 2):
            raise InputError("addendum_coefficient", self.addendum_coefficient, "a value in (0, 2]")
        if not (self.addendum_coefficient <= self.dedendum_coefficient <= 3):
            raise InputError("dedendum_coefficient", self.dedendum_coefficient,
                             f"a value in [addendum_coefficient = {self.addendum_coefficient}, 3]")
        if not (-1.5 <= self.profile_shift <= 1.5):
            raise InputError("profile_shift", self.profile_shift, "a value in [-1.5, 1.5]")
        rho = self.tool_tip_radius
        if not (0 <= rho <= self.rho_max + 1e-12 * self.module):
            raise InputError("tool_tip_radius_coefficient", self.tool_tip_radius_coefficient,
                             f"a value in [0, {self.rho_max / self.module:.4f}] (larger radii "
                             "cut into the active flank)")
        if self.bore_radius >= self.root_radius:
            raise InputError("bore_radius", self.bore_radius,
                             f"a radius below the root radius {self.root_radius:.6g} m")

    # ------------------------------------------------------------------ radii
    @property
    def pitch_radius(self) -> float:
        """Reference (pitch) radius ``r = z m / 2`` [m]."""
        return self.teeth * self.module / 2

    @property
    def base_radius(self) -> float:
        """Base radius ``r_b = r cos(alpha)`` [m]."""
        return self.pitch_radius * math.cos(self.pressure_angle)

    @property
    def tip_radius(self) -> float:
        """Tip (addendum) radius ``r_a = r + (h_a* + x) m`` [m]."""
        return self.pitch_radius + (self.addendum_coefficient + self.profile_shift) * self.module

    @property
    def root_radius(self) -> float:
        """Root radius ``r_f = r - (h_f* - x) m`` [m]."""
        return self.pitch_radius - (self.dedendum_coefficient - self.profile_shift) * self.module

    @property
    def base_pitch(self) -> float:
        """Base pitch ``p_b = pi m cos(alpha) = 2 pi r_b / z`` [m]."""
        return math.pi * self.module * math.cos(self.pressure_angle)

    @property
    def rho_max(self) -> float:
        """Largest rack tip radius that keeps the straight flank down to depth ``h_a* m``,
        ``(h_f* - h_a*) m / (1 - sin alpha)`` [m]."""
        c = self.dedendum_coefficient - self.addendum_coefficient
        return c * self.module / (1 - math.sin(self.pressure_angle))

    @property
    def tool_tip_radius(self) -> float:
        """Tip radius of the generating rack ``rho`` [m]."""
        if self.tool_tip_radius_coefficient is None:
            return self.rho_max
        return self.tool_tip_radius_coefficient * self.module

    @property
    def pitch_thickness(self) -> float:
        """Tooth thickness on the reference circle ``s = m (pi/2 + 2 x tan alpha)`` [m]."""
        return self.module * (math.pi / 2 + 2 * self.profile_shift * math.tan(self.pressure_angle))

    @property
    def base_half_angle(self) -> float:
        r"""Half-tooth angle on the base circle :math:`\alpha_2 = s/(2r) + \mathrm{inv}\,\alpha` [rad]."""
        return self.pitch_thickness / (2 * self.pitch_radius) + float(inv(self.pressure_angle))

    @property
    def _flank_generating_depth(self) -> float:
        """Depth below the generating pitch line where the rack's straight flank ends [m]."""
        rho = self.tool_tip_radius
        a = self.pressure_angle
        return (self.dedendum_coefficient - self.profile_shift) * self.module - rho * (1 - math.sin(a))

    @property
    def form_roll_length(self) -> float:
        r"""Roll length (distance from the base tangency point) of the lowest involute point [m].

        :math:`r\sin\alpha - h_g/\sin\alpha`, with ``h_g`` the depth at which the rack flank ends.
        Negative means the rack undercuts the tooth.
        """
        a = self.pressure_angle
        return self.pitch_radius * math.sin(a) - self._flank_generating_depth / math.sin(a)

    @property
    def undercut(self) -> bool:
        """True if the generating rack undercuts the involute (the flank starts below r_b)."""
        return self.form_roll_length < 0

    @property
    def form_radius(self) -> float:
        """Radius where the trochoid fillet meets the involute (the form circle) [m]."""
        u = max(self.form_roll_length, 0.0)
        return math.hypot(self.base_radius, u)

    def thickness_at(self, radius: float) -> float:
        r"""Arc tooth thickness at a radius on the involute [m]:
        :math:`s_y = 2 r_y(\alpha_2 - \mathrm{inv}\,\alpha_y)`, :math:`\cos\alpha_y = r_b/r_y`."""
        allowed = f"a radius >= the base radius {self.base_radius:.6g} m"
        radius = _real(radius, "radius", f"a finite {allowed[2:]}")
        if radius < self.base_radius:
            raise InputError("radius", radius, allowed)
        ay = math.acos(self.base_radius / radius)
        return 2 * radius * (self.base_half_angle - float(inv(ay)))

    @property
    def tip_thickness(self) -> float:
        """Arc tooth thickness at the tip circle [m]; <= 0 means a pointed tooth."""
        return self.thickness_at(self.tip_radius)

    @property
    def pointed(self) -> bool:
        """True if the involute flanks meet below the tip circle."""
        return self.tip_thickness <= 0

    @property
    def root_half_angle(self) -> float:
        r"""Half-angle of the tooth at the root circle, :math:`\theta_f` [rad].

        The angle between the tooth centreline and the point where the trochoid fillet reaches the
        root circle, measured on the actual generated outline (used by the Sainsot et al. 2004
        foundation term: ``S_f = 2 r_f theta_f``). For h_a* = 1, h_f* = 1.25 and rho* = 0.38
        this is 3.013/z.
        """
        pts = self.outline(n_involute=4, n_fillet=400).fillet
        # the fillet's last point lies on the root circle at the tooth-space centre or where the
        # rack tip line begins; theta measured from the centreline (y axis)
        x, y = pts[-1]
        return math.atan2(x, y)

    # ------------------------------------------------------------------ outline
    def outline(self, n_involute: int = 60, n_fillet: int = 60) -> ToothOutline:
        r"""Rack-generated outline of one tooth's right flank (the tooth centred on +y).

        The involute runs from the form radius to the tip; the fillet is the envelope of the rack
        tip circle (radius ``rho``) rolled on the generating pitch circle, a trochoid offset, from
        the form radius down to the root circle. Tooth 0 is centred on the +y axis; the left flank
        is the mirror image ``x -> -x``.

        Parameters
        ----------
        n_involute, n_fillet : int
            Number of points on each part (>= 2).

        Returns
        -------
        ToothOutline
            Points in m.
        """
        n_involute = _count(n_involute, "n_involute", 2)
        n_fillet = _count(n_fillet, "n_fillet", 2)
        rb, ra = self.base_radius, self.tip_radius
        a2 = self.base_half_angle
        u0 = max(self.form_roll_length, 0.0) / rb  # roll parameter at the form circle
        u1 = math.sqrt((ra / rb) ** 2 - 1.0)
        if self.pointed:
            # stop the involute where it meets the centreline: inv(alpha_y) = a2
            ay = inv_inverse(a2)
            u1 = math.tan(ay)
        u = np.linspace(u0, u1, n_involute)
        rad = rb * np.sqrt(1 + u * u)
        psi = a2 - (u - np.arctan(u))  # polar angle from the +y axis toward +x
        involute = np.column_stack([rad * np.sin(psi), rad * np.cos(psi)])
        fillet = self._fillet(n_fillet)
        return ToothOutline(involute=involute, fillet=fillet, gear=self)

    def _rack_tip_centre(self) -> tuple[float, float]:
        """Rack tip-circle centre: abscissa ``xi_c`` from the tooth centreline and depth ``a1``
        below the generating pitch line [m] (``b1`` and ``a1`` of Ma et al. 2014, with shift)."""
        m, a, rho = self.module, self.pressure_angle, self.tool_tip_radius
        x = self.profile_shift
        a1 = (self.dedendum_coefficient - x) * m - rho
        w = m * (math.pi / 4 - x * math.tan(a)) - a1 * math.tan(a)  # rack half-width at depth a1
        e = w - rho / math.cos(a)  # offset of the tip-circle centre from the rack tooth axis
        return math.pi * m / 2 - e, a1

    def _fillet_point(self, phi: np.ndarray) -> np.ndarray:
        """Envelope point of the rack tip circle for gear roll angles ``phi`` [m].

        The rack rolls on the generating pitch circle (radius r); at roll ``phi`` its pitch line
        touches the circle at ``P = r (sin phi, cos phi)``. The tip-circle centre ``C`` sits at rack
        abscissa ``xi_c`` and depth ``a1``. The normal of an enveloping contact passes through the
        instantaneous centre ``P``, so the fillet point is on line ``P C``, on the far side of ``C``:
        ``F = C - rho (P - C)/|P - C|`` (distance ``a1/sin(gamma) + rho`` from P).
        """
        r, rho = self.pitch_radius, self.tool_tip_radius
        xi_c, a1 = self._rack_tip_centre()
        s, c = np.sin(phi), np.cos(phi)
        d = xi_c - r * phi
        # P + d t + a1 n with t = (cos, -sin), n = -(sin, cos)
        cx = r * s + d * c - a1 * s
        cy = r * c - d * s - a1 * c
        vx, vy = r * s - cx, r * c - cy
        norm = np.hypot(vx, vy)
        return np.column_stack([cx - rho * vx / norm, cy - rho * vy / norm])

    def _fillet(self, n: int) -> np.ndarray:
        """Fillet points from the form circle (first) down to the root circle (last) [m].

        With ``gamma`` the angle between line ``P C`` and the pitch line, the rack roll is
        ``r phi = a1 / tan(gamma) + xi_c`` for ``gamma`` in ``[alpha, pi/2]``: ``gamma = alpha``
        is where the straight rack flank takes over (the form point, joining the involute with a
        common tangent) and ``gamma = pi/2`` is the root circle (Ma, Song, Pang & Wen 2014).
        """
        r, a = self.pitch_radius, self.pressure_angle
        xi_c, a1 = self._rack_tip_centre()
        gamma = np.linspace(a, math.pi / 2, n)
        phis = (a1 / np.tan(gamma) + xi_c) / r
        phis[-1] = xi_c / r
        return self._fillet_point(phis)


@dataclass(frozen=True)
class ToothOutline:
    """Points of one tooth's right flank; the tooth is centred on the +y axis [m].

    Attributes
    ----------
    involute : ndarray, shape (n, 2)
        Involute points from the form circle (first) to the tip (last) [m].
    fillet : ndarray, shape (k, 2)
        Fillet points from the form circle (first) to the root circle (last) [m].
    gear : Gear
        The gear the outline belongs to.
    """

    involute: np.ndarray
    fillet: np.ndarray
    gear: Gear

    def right_flank(self) -> np.ndarray:
        """Root-to-tip points of the right flank (fillet then involute) [m], shape (n, 2)."""
        return np.vstack([self.fillet[::-1], self.involute[1:]])

    def closed_tooth(self) -> np.ndarray:
        """One tooth from the left root point to the right root point over the tip [m].

        The tip circle arc is sampled between the two flank tips.
        """
        right = self.right_flank()
        left = right[::-1] * np.array([-1.0, 1.0])
        ra = self.gear.tip_radius
        x0 = right[-1, 0]
        half = math.asin(min(max(x0 / ra, -1.0), 1.0))
        ang = np.linspace(-half, half, 9)[1:-1]
        tip = np.column_stack([ra * np.sin(ang), ra * np.cos(ang)])
        return np.vstack([left, tip, right])


@dataclass(frozen=True)
class ContactPoints:
    """Where the tooth pairs meet on the operating line of action for one pinion angle.

    All arrays have one entry per candidate pair (pairs whose contact point lies within one base
    pitch of the contact interval), ordered by position along the LOA.

    Attributes
    ----------
    pair : ndarray of int
        Pair index ``n`` (pinion tooth ``n mod z1`` with gear tooth ``n mod z2``).
    pinion_tooth, gear_tooth : ndarray of int
        Tooth numbers.
    s : ndarray
        Position along the LOA from T1 [m].
    pinion_roll, gear_roll : ndarray
        Roll angles ``phi_1 = s/r_b1`` and ``phi_2 = (T1T2 - s)/r_b2`` [rad].
    pinion_radius, gear_radius : ndarray
        Radii of the contact point on each gear [m].
    in_contact : ndarray of bool
        Whether the point lies within the theoretical contact interval ``[s0, s1]``.
    """

    pair: np.ndarray
    pinion_tooth: np.ndarray
    gear_tooth: np.ndarray
    s: np.ndarray
    pinion_roll: np.ndarray
    gear_roll: np.ndarray
    pinion_radius: np.ndarray
    gear_radius: np.ndarray
    in_contact: np.ndarray


@dataclass(frozen=True)
class OperatingGeometry:
    """The pair at one operating centre distance (eqs. 6 and 8 of Xue & Howard 2018).

    Attributes
    ----------
    centre_distance : float
        Operating centre distance ``d'`` [m].
    centre_distance_change : float
        ``d' - d`` from the design (zero-backlash) centre distance [m].
    pressure_angle : float
        Operating pressure angle ``alpha' = arccos((r_b1 + r_b2)/d')`` [rad] (eq. 6).
    t1t2 : float
        Length of the LOA between the tangency points ``(r_b1 + r_b2) tan alpha'`` [m].
    s_start, s_end : float
        Contact interval along the LOA from T1 [m]: start (gear tip) and end (pinion tip).
    contact_ratio : float
        Physical transverse contact ratio ``(s_end - s_start)/p_b`` with the invariant base pitch.
    contact_ratio_eq8 : float
        The paper's eq. 8, which divides by ``pi m cos(alpha')`` instead of the base pitch
        (erratum 2); reproduces the paper's "1.43" at +1.07 mm.
    normal_backlash : float
        Normal backlash ``j_n = 2 (r_b1 + r_b2)(inv alpha' - inv alpha_w)`` [m].
    circumferential_backlash : float
        Transverse backlash on the operating pitch circle ``j_t = j_n / cos alpha'`` [m].
    closing_rotation : float
        Pinion rotation that closes the backlash with the gear held ``j_n / r_b1`` [rad].
    base_pitch : float
        Base pitch ``p_b = pi m cos(alpha)`` [m], the same for every centre distance (the
        divisor of ``contact_ratio``; not shown in the repr).
    """

    centre_distance: float
    centre_distance_change: float
    pressure_angle: float
    t1t2: float
    s_start: float
    s_end: float
    contact_ratio: float
    contact_ratio_eq8: float
    normal_backlash: float
    circumferential_backlash: float
    closing_rotation: float
    base_pitch: float = field(repr=False)

    @property
    def single_contact_fraction(self) -> float:
        """Fraction of a mesh period with the lower number of pairs in contact: ``ceil(e) - e``."""
        e = self.contact_ratio
        return math.ceil(e) - e if e % 1 else 1.0

    @property
    def double_contact_fraction(self) -> float:
        """Fraction of a mesh period with the higher number of pairs in contact: ``e - floor(e)``."""
        return 1.0 - self.single_contact_fraction if self.contact_ratio % 1 else 0.0

    def contact_ratio_by(self, formula: str) -> float:
        """The contact ratio by ``"physical"`` (default in geardyn) or ``"paper_eq8"``."""
        if formula == "physical":
            return self.contact_ratio
        if formula == "paper_eq8":
            return self.contact_ratio_eq8
        raise InputError("contact_ratio_formula", formula, "'physical' or 'paper_eq8'")


class GearPair:
    """A pinion (driver) and gear in mesh, with the geometry of any operating centre distance.

    Parameters
    ----------
    pinion, gear : Gear
        Same module and pressure angle. The pinion drives.

    Notes
    -----
    The design centre distance is the zero-backlash one,
    ``d = (r_b1 + r_b2)/cos(alpha_w)`` with
    ``inv alpha_w = inv alpha + 2 tan(alpha)(x1 + x2)/(z1 + z2)``; for unshifted gears it is the
    standard ``m (z1 + z2)/2`` (the paper's 138 mm) and ``alpha_w = alpha`` (eqs. 3 and 5).
    """

    def __init__(self, pinion: Gear, gear: Gear):
        for name, g in (("pinion", pinion), ("gear", gear)):
            if not isinstance(g, Gear):
                raise InputError(name, g, "a geardyn.geometry.Gear")
        if not math.isclose(pinion.module, gear.module, rel_tol=1e-12):
            raise InputError("gear.module", gear.module, f"the pinion's module {pinion.module} m")
        if not math.isclose(pinion.pressure_angle, gear.pressure_angle, rel_tol=1e-12):
            raise InputError("gear.pressure_angle", gear.pressure_angle,
                             f"the pinion's pressure angle {pinion.pressure_angle} rad")
        self.pinion = pinion
        self.gear = gear

    def __repr__(self) -> str:
        return (f"GearPair(z={self.pinion.teeth}/{self.gear.teeth}, m={self.pinion.module * 1e3:g} mm, "
                f"alpha={math.degrees(self.pinion.pressure_angle):g} deg)")

    # ---------------------------------------------------------------- design values
    @property
    def module(self) -> float:
        """Module [m]."""
        return self.pinion.module

    @property
    def base_pitch(self) -> float:
        """Base pitch [m] (identical for both gears and for any centre distance)."""
        return self.pinion.base_pitch

    @property
    def ratio(self) -> float:
        """Gear ratio ``z2 / z1`` [-]."""
        return self.gear.teeth / self.pinion.teeth

    @property
    def base_radius_sum(self) -> float:
        """``r_b1 + r_b2`` [m] (the paper's Table 1 '129.7 mm', erratum 1)."""
        return self.pinion.base_radius + self.gear.base_radius

    @cached_property
    def working_pressure_angle(self) -> float:
        """Zero-backlash (design) pressure angle ``alpha_w`` [rad]."""
        a = self.pinion.pressure_angle
        z1, z2 = self.pinion.teeth, self.gear.teeth
        x1, x2 = self.pinion.profile_shift, self.gear.profile_shift
        return inv_inverse(float(inv(a)) + 2 * math.tan(a) * (x1 + x2) / (z1 + z2))

    @cached_property
    def design_centre_distance(self) -> float:
        """Design (zero-backlash) centre distance ``d`` [m] (eq. 3)."""
        return self.base_radius_sum / math.cos(self.working_pressure_angle)

    @property
    def design_t1t2(self) -> float:
        """LOA length between tangency points at the design centre distance [m]."""
        return self.base_radius_sum * math.tan(self.working_pressure_angle)

    @property
    def pitch_point_s(self) -> float:
        """Design pitch point along the LOA from T1, ``r_b1 tan alpha_w`` [m]: pinion tooth 0
        is here at ``theta = 0``."""
        return self.pinion.base_radius * math.tan(self.working_pressure_angle)

    @property
    def mesh_angle(self) -> float:
        """Pinion angle of one mesh period ``2 pi / z1`` [rad]."""
        return 2 * math.pi / self.pinion.teeth

    # ---------------------------------------------------------------- operation
    def operating(self, centre_distance_change: float = 0.0, *, check: bool = True
                  ) -> OperatingGeometry:
        """Geometry at the operating centre distance ``d' = d + centre_distance_change``.

        Parameters
        ----------
        centre_distance_change : float
            ``d' - d`` [m], a finite number (SI; a unit string such as ``"1 mm"`` is refused).
        check : bool
            Raise :class:`GeometryError` if the contact ratio is below 1 (the pair cannot keep
            contact) or the centre distance is below the base-radius sum.

        Returns
        -------
        OperatingGeometry
        """
        rsum, d0, s_end, gear_tip_roll, pb, inv_w = self._operating_constants
        dd = _real(centre_distance_change, "centre_distance_change",
                   lambda: f"a number > {rsum - d0:.6g} [m] (SI: 0.001 for 1 mm)", finite=False)
        d = d0 + dd
        if not math.isfinite(dd) or d <= rsum:
            raise GeometryError("centre_distance_change", dd,
                                f"a change > {rsum - d0:.6g} m "
                                "(the operating centre distance must exceed r_b1 + r_b2)")
        alpha_op = math.acos(rsum / d)
        t1t2 = rsum * math.tan(alpha_op)
        s_start = t1t2 - gear_tip_roll
        eps = (s_end - s_start) / pb
        # eq. 8 of the paper, with its cos(alpha') in the denominator (erratum 2)
        eps8 = (s_end + gear_tip_roll - d * math.sin(alpha_op)) / (
            math.pi * self.module * math.cos(alpha_op))
        jn = 2 * rsum * (float(inv(alpha_op)) - inv_w)
        p = self.pinion
        op = OperatingGeometry(
            centre_distance=d,
            centre_distance_change=dd,
            pressure_angle=alpha_op,
            t1t2=t1t2,
            s_start=s_start,
            s_end=s_end,
            contact_ratio=eps,
            contact_ratio_eq8=eps8,
            normal_backlash=jn,
            circumferential_backlash=jn / math.cos(alpha_op),
            closing_rotation=jn / p.base_radius,
            base_pitch=pb,
        )
        if check and eps < 1.0:
            raise GeometryError(
                "centre_distance_change", dd,
                f"a centre distance change that keeps the contact ratio >= 1 (it is {eps:.4f} "
                f"at {d * 1e3:.4f} mm; the largest allowed change is "
                f"{self.max_centre_distance_change() * 1e3:.4f} mm)")
        return op

    @cached_property
    def _operating_constants(self) -> tuple[float, float, float, float, float, float]:
        r"""What :meth:`operating` needs of the pair at any centre distance: ``r_b1 + r_b2``,
        the design centre distance, the pinion's and the gear's tip roll lengths
        :math:`\sqrt{r_a^2 - r_b^2}`, the base pitch [m] and ``inv alpha_w`` [rad], computed
        once (each call computed them again from the gears' properties: about half of its
        time, 2026-11-28)."""
        p, g = self.pinion, self.gear
        return (self.base_radius_sum, self.design_centre_distance,
                math.sqrt(p.tip_radius ** 2 - p.base_radius ** 2),
                math.sqrt(g.tip_radius ** 2 - g.base_radius ** 2), self.base_pitch,
                float(inv(self.working_pressure_angle)))

    def max_centre_distance_change(self) -> float:
        """Largest ``d' - d`` with contact ratio >= 1 [m]."""
        p, g = self.pinion, self.gear
        # s_end - s_start = p_b  ->  t1t2 = s_end + sqrt(ra2^2 - rb2^2) - p_b
        t = (math.sqrt(p.tip_radius ** 2 - p.base_radius ** 2)
             + math.sqrt(g.tip_radius ** 2 - g.base_radius ** 2) - self.base_pitch)
        return math.hypot(self.base_radius_sum, t) - self.design_centre_distance

    def min_centre_distance_change(self) -> float:
        """Smallest ``d' - d`` with a normal backlash >= 0 [m]: the change giving zero backlash.

        ``j_n = 2 (r_b1 + r_b2)(inv alpha' - inv alpha_w) = 0`` solved for ``d'``; with the
        design centre distance the zero-backlash one, this is 0 (up to rounding). Closer centres
        would make the teeth interpenetrate. :meth:`operating` does not refuse them: stiffness
        maps evaluate the mesh below the design centre distance on purpose (the default grid
        starts at -0.5 mm); front ends that take a user's operating point check against this.
        """
        alpha0 = inv_inverse(float(inv(self.working_pressure_angle)))
        return self.base_radius_sum / math.cos(alpha0) - self.design_centre_distance

    def contact_points(self, theta: float, centre_distance_change: float = 0.0,
                       *, margin: float = 1.0) -> ContactPoints:
        """Contact points of the pairs near the mesh at pinion angle ``theta``.

        Parameters
        ----------
        theta : float
            Pinion angle [rad] (0: pinion tooth 0 at the design pitch point), finite, of
            magnitude <= :data:`MAX_ANGLE`.
        centre_distance_change : float
            ``d' - d`` [m].
        margin : float
            Also return candidate pairs up to ``margin`` (finite, >= 0) base pitches outside the
            contact interval (for extended-contact searches), flagged ``in_contact = False``.

        Returns
        -------
        ContactPoints
        """
        theta = _real(theta, "theta",
                      lambda: f"a finite pinion angle of magnitude <= {MAX_ANGLE:g} [rad]")
        if abs(theta) > MAX_ANGLE:
            raise InputError("theta", theta, f"a finite pinion angle of magnitude <= "
                                             f"{MAX_ANGLE:g} [rad]")
        margin = _real(margin, "margin", "a finite number of base pitches >= 0")
        if margin < 0:
            raise InputError("margin", margin, "a finite number of base pitches >= 0")
        op = self.operating(centre_distance_change, check=False)
        pb = self.base_pitch
        s_theta = self.pitch_point_s + self.pinion.base_radius * theta
        lo, hi = op.s_start - margin * pb, op.s_end + margin * pb
        # s_n = s_theta - n pb in [lo, hi]  ->  n in [(s_theta - hi)/pb, (s_theta - lo)/pb]
        n = np.arange(math.ceil((s_theta - hi) / pb - 1e-12), math.floor((s_theta - lo) / pb) + 1)
        s = s_theta - n * pb
        order = np.argsort(s)
        n, s = n[order], s[order]
        rb1, rb2 = self.pinion.base_radius, self.gear.base_radius
        tol = 1e-12
        return ContactPoints(
            pair=n,
            pinion_tooth=np.mod(n, self.pinion.teeth),
            gear_tooth=np.mod(n, self.gear.teeth),
            s=s,
            pinion_roll=s / rb1,
            gear_roll=(op.t1t2 - s) / rb2,
            pinion_radius=np.hypot(rb1, s),
            gear_radius=np.hypot(rb2, op.t1t2 - s),
            in_contact=(s >= op.s_start - tol) & (s <= op.s_end + tol),
        )

    def checks(self, centre_distance_change: float = 0.0) -> list[str]:
        """Problems of the pair at ``d + centre_distance_change``, in words (empty if none).

        Reports undercut, pointed teeth, a tip land thinner than 0.2 m, contact below the form
        circle (tip interference with the fillet) and a contact ratio below 1.
        """
        out = []
        for name, g in (("pinion", self.pinion), ("gear", self.gear)):
            if g.undercut:
                out.append(f"{name}: undercut by the generating rack (z = {g.teeth}, "
                           f"x = {g.profile_shift}); the involute starts below the base circle")
            if g.pointed:
                out.append(f"{name}: pointed teeth (flanks meet below the tip circle)")
            elif g.tip_thickness < 0.2 * g.module:
                out.append(f"{name}: thin tip land {g.tip_thickness * 1e3:.3f} mm (< 0.2 m)")
        op = self.operating(centre_distance_change, check=False)
        if op.contact_ratio < 1:
            out.append(f"contact ratio {op.contact_ratio:.4f} < 1: the teeth lose contact")
        u1 = math.sqrt(max(self.pinion.form_radius ** 2 - self.pinion.base_radius ** 2, 0.0))
        u2 = math.sqrt(max(self.gear.form_radius ** 2 - self.gear.base_radius ** 2, 0.0))
        if op.s_start < u1 - 1e-12:
            out.append("interference: the gear tip meets the pinion below its form circle "
                       f"(start of contact at roll length {op.s_start * 1e3:.4f} mm < "
                       f"{u1 * 1e3:.4f} mm)")
        if op.t1t2 - op.s_end < u2 - 1e-12:
            out.append("interference: the pinion tip meets the gear below its form circle")
        return out


def centre_distance_from_displacements(pair: GearPair, y_p: float | np.ndarray,
                                       y_g: float | np.ndarray) -> float | np.ndarray:
    r"""Operating centre distance from the bearing displacements along the LOA (eq. 4).

    .. math:: d' = \sqrt{(r_{b1} + r_{b2})^2 + [(r_{b1} + r_{b2})\tan\alpha_w + y_g - y_p]^2}

    Parameters
    ----------
    pair : GearPair
    y_p, y_g : float or array_like
        Pinion and gear centre displacements along the nominal LOA [m], finite numbers (SI).

    Returns
    -------
    float or ndarray
        ``d'`` [m]; equals the design centre distance for zero displacements. An array when
        ``y_p`` or ``y_g`` is an array (or a list or tuple).

    Raises
    ------
    InputError
        ``pair`` not a :class:`GearPair`; a displacement that is not a finite number (or an
        array of them).
    """
    if not isinstance(pair, GearPair):
        raise InputError("pair", pair, "a geardyn.geometry.GearPair")
    rsum = pair.base_radius_sum
    if isinstance(y_p, np.ndarray | list | tuple) or isinstance(y_g, np.ndarray | list | tuple):
        yp, yg = _displacements(y_p, "y_p"), _displacements(y_g, "y_g")
        return np.hypot(rsum, pair.design_t1t2 + yg - yp)
    allowed = "a finite displacement [m] (a number, or an array of them)"
    return math.hypot(rsum, pair.design_t1t2 + _real(y_g, "y_g", allowed)
                      - _real(y_p, "y_p", allowed))


def _displacements(value, field_name: str) -> np.ndarray:
    """``value`` as a float array of finite displacements [m], or :class:`InputError`."""
    allowed = "a finite displacement [m] (a number, or an array of them)"
    arr = np.asarray(value) if isinstance(value, np.ndarray | list | tuple) else None
    if arr is None:
        return np.asarray(_real(value, field_name, allowed))
    if arr.dtype.kind not in "iuf":
        raise InputError(field_name, value, allowed)
    arr = arr.astype(float, copy=False)
    if not np.all(np.isfinite(arr)):
        raise InputError(field_name, "an array with non-finite entries", allowed)
    return arr


def static_operating_point(pair: GearPair, torque: float, pinion_bearing_stiffness: float,
                           gear_bearing_stiffness: float, *,
                           fields: tuple[str, str] = ("pinion_bearing_stiffness",
                                                      "gear_bearing_stiffness")
                           ) -> OperatingGeometry:
    r"""Operating geometry under a static torque on rigid teeth and flexible bearings.

    The mesh force along the LOA is ``N = T / r_b1``; it pushes the pinion to ``y_p = -N/k_yp``
    and the gear to ``y_g = +N/k_yg`` (eqs. 10 and 12 at rest), and eq. 4 gives ``d'``.
    For the paper's case: N = 1542.3 N, d' - d = 1.0852 mm.

    Parameters
    ----------
    pair : GearPair
    torque : float
        Input torque on the pinion [N m].
    pinion_bearing_stiffness, gear_bearing_stiffness : float
        Bearing stiffnesses along the LOA [N/m], finite and > 0.
    fields : (str, str)
        Their names in an error (:func:`check_static_contact`).

    Raises
    ------
    GeometryError
        If the bearings' deflection leaves the teeth out of contact.
    """
    if not isinstance(pair, GearPair):
        raise InputError("pair", pair, "a geardyn.geometry.GearPair")
    torque = _real(torque, "torque", "a finite torque [N m]")
    for name, k in (("pinion_bearing_stiffness", pinion_bearing_stiffness),
                    ("gear_bearing_stiffness", gear_bearing_stiffness)):
        if not _real(k, name, "a finite stiffness > 0 [N/m]") > 0:
            raise InputError(name, k, "a finite stiffness > 0 [N/m]")
    n = torque / pair.pinion.base_radius
    d = centre_distance_from_displacements(pair, -n / pinion_bearing_stiffness,
                                           n / gear_bearing_stiffness)
    dd = float(d) - pair.design_centre_distance
    check_static_contact(pair, dd, n, pinion_bearing_stiffness, gear_bearing_stiffness,
                         fields=fields)
    return pair.operating(dd)


def check_static_contact(pair: GearPair, centre_distance_change: float, mesh_force: float,
                         pinion_bearing_stiffness: float, gear_bearing_stiffness: float, *,
                         fields: tuple[str, str] = ("pinion_bearing_stiffness",
                                                    "gear_bearing_stiffness")) -> None:
    """Refuse bearings so soft that the static mesh force pushes the teeth out of contact.

    The static centre distance change of eq. 4 beyond
    :meth:`GearPair.max_centre_distance_change` leaves a contact ratio below 1 (beyond it the
    teeth separate): the error names the softer bearing, the change and the limit, instead of
    a centre distance the user never gave.

    Parameters
    ----------
    pair : GearPair
    centre_distance_change : float
        Static ``d' - d`` [m] under ``mesh_force``.
    mesh_force : float
        Static mesh force along the line of action [N].
    pinion_bearing_stiffness, gear_bearing_stiffness : float
        Bearing stiffnesses along the LOA [N/m].
    fields : (str, str)
        The names of the two stiffnesses in the error (the case's ``pinion.bearing_stiffness``
        where a case gave them).

    Raises
    ------
    GeometryError
        If the change exceeds the largest with contact ratio >= 1.
    """
    dd_max = pair.max_centre_distance_change()
    if centre_distance_change <= dd_max:
        return
    soft = 0 if pinion_bearing_stiffness <= gear_bearing_stiffness else 1
    k = (pinion_bearing_stiffness, gear_bearing_stiffness)
    raise GeometryError(
        fields[soft], k[soft],
        f"bearings stiff enough to keep the teeth in contact [N/m]: under the static mesh force "
        f"{mesh_force:.5g} N, {fields[0]} {k[0]:.4g} N/m and {fields[1]} {k[1]:.4g} N/m move "
        f"the centres {centre_distance_change * 1e3:.5g} mm apart, beyond the largest change "
        f"with contact ratio >= 1, {dd_max * 1e3:.4f} mm (stiffer bearings or a lower torque)")


def geometry_summary(pair: GearPair, centre_distance_change: float = 0.0) -> dict:
    """A JSON-ready summary of the pair at ``d + centre_distance_change`` [m].

    Keys carry their unit as a suffix (``_m``, ``_deg``); everything else is dimensionless.
    """
    op = pair.operating(centre_distance_change)

    def gear_dict(g: Gear) -> dict:
        return {
            "teeth": int(g.teeth),
            "module_m": g.module,
            "pressure_angle_deg": math.degrees(g.pressure_angle),
            "profile_shift": g.profile_shift,
            "pitch_radius_m": g.pitch_radius,
            "base_radius_m": g.base_radius,
            "tip_radius_m": g.tip_radius,
            "root_radius_m": g.root_radius,
            "form_radius_m": g.form_radius,
            "tool_tip_radius_m": g.tool_tip_radius,
            "tip_thickness_m": g.tip_thickness,
            "root_half_angle_rad": g.root_half_angle,
            "face_width_m": g.face_width,
            "bore_radius_m": g.bore_radius,
        }

    return {
        "pinion": gear_dict(pair.pinion),
        "gear": gear_dict(pair.gear),
        "base_pitch_m": pair.base_pitch,
        "design_centre_distance_m": pair.design_centre_distance,
        "design_pressure_angle_deg": math.degrees(pair.working_pressure_angle),
        "operating": {
            "centre_distance_m": op.centre_distance,
            "centre_distance_change_m": op.centre_distance_change,
            "pressure_angle_deg": math.degrees(op.pressure_angle),
            "contact_ratio": {"physical": op.contact_ratio, "paper_eq8": op.contact_ratio_eq8},
            "single_contact_fraction": op.single_contact_fraction,
            "double_contact_fraction": op.double_contact_fraction,
            "contact_start_m": op.s_start,
            "contact_end_m": op.s_end,
            "t1t2_m": op.t1t2,
            "normal_backlash_m": op.normal_backlash,
            "circumferential_backlash_m": op.circumferential_backlash,
            "backlash_closing_rotation_rad": op.closing_rotation,
        },
        "max_centre_distance_change_m": pair.max_centre_distance_change(),
        "checks": pair.checks(centre_distance_change),
    }
