r"""Analytical mesh stiffness by the potential energy method (PEM), healthy and with a root crack.

Each tooth is a non-uniform cantilever on an elastic gear body. A unit load ``F`` acts at the
contact point along the line of action (LOA); it stores the energies ``U = F^2 / (2 k)`` of

* Hertzian contact (Yang & Lin 1987): :func:`hertz_compliance`,
* bending, shear and axial compression of the tooth (Yang & Lin 1987; Tian 2004; Wu, Zuo & Parey
  2008; Ma, Song, Pang & Wen 2014 for the trochoid fillet): :func:`bending_compliance`,
  :func:`shear_compliance`, :func:`axial_compression_compliance`,
* the fillet-foundation (gear body) deflection (Sainsot, Velex & Duverger 2004):
  :func:`foundation_compliance`,

so that one tooth pair has the stiffness (all compliances in m/N)

.. math:: \frac{1}{k_{pair}} = \frac{1}{k_h} + \sum_{i=1,2}\left(\frac{1}{k_{b,i}}
          + \frac{1}{k_{s,i}} + \frac{1}{k_{a,i}} + \frac{1}{k_{f,i}}\right)

and the mesh stiffness along the LOA is ``k_mb = sum_j k_pair,j`` over the pairs in contact, with
load sharing ratio ``k_pair,j / k_mb`` (equal deflection of every pair, no coupling between the
foundations of adjacent teeth; trap T13 of ``design/stiffness.md``).

The exact tooth
---------------
The tooth section is taken from the rack-generated outline of :class:`geardyn.geometry.Gear`: the
involute above the form circle and the trochoidal fillet below it, down to the root circle at the
half-angle ``theta_f`` (``Gear.root_half_angle``). Integration along the tooth centreline starts
at the root chord ``y_0 = r_f cos(theta_f)``, where the Sainsot foundation takes over. This is
correct whether the root circle lies inside or outside the base circle. ``model="classic"`` gives
the textbook variant instead (involute from the base circle plus the root rectangle of Wan et al.
2014 / Ma et al. 2015 when ``r_f < r_b``, or the involute truncated at ``r_f``), for comparison with
published codes.

With the load point on the involute at roll angle ``phi`` (``phi = s / r_b``, ``s`` the distance
of the contact point from the tangency point along the LOA), the load makes the angle
``alpha_1 = phi - alpha_2`` with the normal to the tooth centreline, and its line crosses the
centreline at ``r_b / cos(alpha_1)`` from the centre. The moment per unit load about the section
at centreline height ``y`` is therefore

.. math:: \hat M(y) = \cos\alpha_1 (y_F - y) - h_F \sin\alpha_1 = r_b - y\cos\alpha_1 ,

and with the section width ``w(y)`` (``2 h(y)`` for a healthy tooth), ``A = w L``,
``I = w^3 L / 12`` and ``G = E / (2 (1 + nu))``:

.. math::
   \frac{1}{k_b} = \int_{y_0}^{y_F} \frac{12 \hat M^2}{E L w^3}\,dy, \quad
   \frac{1}{k_s} = \int_{y_0}^{y_F} \frac{2.4 (1+\nu)\cos^2\alpha_1}{E L w}\,dy, \quad
   \frac{1}{k_a} = \int_{y_0}^{y_F} \frac{\sin^2\alpha_1}{E L w}\,dy .

(For ``w = 2h`` these are the integrands of Tian 2004 and Chen & Shao 2011.) The centre distance
does not enter: it only moves the contact points along the operating LOA (``design/stiffness.md``
section 2.1), so each tooth's compliance is computed once against its roll angle on a fine table
and ``K(theta, d)`` is evaluated from the table for any ``d`` (no closed forms of Tian for
``alpha_1(theta)``, which assume the standard centre distance; trap T7).

The root crack
--------------
:class:`ToothCrack`: a straight crack of length ``depth`` (``q``) on one tooth of the pinion or
the gear. Angle convention (stated explicitly, trap T18): ``angle`` (``upsilon``) is the angle
between the crack and the tooth centreline; the crack runs from its mouth into the tooth and
towards the root, so its tip is ``q sin(upsilon)`` nearer the centreline and ``q cos(upsilon)``
lower than the mouth. The mouth is on the loaded (tension) side, at the fillet point where the
tangent makes 30 deg with the centreline (the critical section of ISO 6336-3, where root cracks
start); :func:`crack_geometry` gives the points so the finite-element route uses the same crack.
Above the crack tip, the material beyond a *limit line* carries no load:

* ``limit_line="parallel"``: the line through the tip parallel to the centreline (Tian 2004;
  Chen & Shao 2011), ``w = h + min(h, h_q)``; the tip must stay on the loaded side of the
  centreline (their "case 1"; the crossing case 2 is not modelled and raises InputError);
* ``limit_line="tip"``: the straight line from the crack tip to the tip corner of the cracked
  flank (Mohammed, Rantatalo & Aidanpaa 2013), which FE favours for large cracks; ``w = h + min(h,
  line(y))``. The tip line is meant to remove *less* material than the parallel one, so when the
  tip corner is nearer the centreline than the crack tip (shallow cracks: ``h_q`` above the tip
  half-thickness; the paper's 5 mm crack on this stubby 23-tooth pinion is such a case) the two
  lines coincide.

The parallel line therefore gives the larger (or equal) loss of stiffness (trap T18). Both keep the
section's moment arm about the tooth centreline (the shift of the neutral axis is neglected, as in
the cited papers). The crack changes neither the Hertz nor the foundation term; a crack tip below
the root chord ``y_0`` acts only through the beam sections above ``y_0``.

References
----------
Yang, D. C. H. & Lin, J. Y. (1987). Hertzian damping, tooth friction and bending elasticity in
gear impact dynamics. J. Mech. Transm. Autom. Des. 109:189-196.
Tian, X. (2004). Dynamic simulation for system response of gearbox including localized gear
faults. MSc thesis, University of Alberta.
Wu, S., Zuo, M. J. & Parey, A. (2008). Simulation of spur gear dynamics and estimation of fault
growth. J. Sound Vib. 317:608-624.
Sainsot, P., Velex, P. & Duverger, O. (2004). Contribution of gear body to tooth deflections - a
new bidimensional analytical formula. J. Mech. Des. 126:748-752.
Chen, Z. & Shao, Y. (2011). Dynamic simulation of spur gear with tooth root crack propagating
along tooth width and crack depth. Eng. Fail. Anal. 18:2149-2164.
Mohammed, O. D., Rantatalo, M. & Aidanpaa, J.-O. (2013). Improved method for calculating the
time-varying mesh stiffness of a spur gear pair with tooth crack. Eng. Fail. Anal. 34:235-251.
Ma, H., Song, R., Pang, X. & Wen, B. (2014). Time-varying mesh stiffness calculation of cracked
spur gears. Eng. Fail. Anal. 44:179-194.
Wan, Z., Cao, H., Zi, Y., He, W. & He, Z. (2014). An improved time-varying mesh stiffness
algorithm and dynamic modeling of gear-rotor system with tooth root crack. Eng. Fail. Anal.
42:157-177.
ISO 6336-3:2019, Calculation of load capacity of spur and helical gears - Part 3: tooth bending
strength (30 deg tangent critical section).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq

from ..errors import GeometryError, InputError
from .map import StiffnessMap

__all__ = [
    "ToothCrack",
    "CrackGeometry",
    "ToothSection",
    "PEMModel",
    "SainsotRangeWarning",
    "hertz_compliance",
    "bending_compliance",
    "shear_compliance",
    "axial_compression_compliance",
    "foundation_compliance",
    "sainsot_coefficients",
    "sainsot_validity",
    "crack_geometry",
    "tooth_compliance",
    "tooth_compliance_quad",
    "pem_map",
    "CITATIONS",
]

CITATIONS = (
    "Yang & Lin 1987, J. Mech. Transm. Autom. Des. 109:189-196 (Hertz, bending, shear, axial)",
    "Tian 2004, MSc thesis, University of Alberta (PEM, parallel crack limit line)",
    "Sainsot, Velex & Duverger 2004, J. Mech. Des. 126:748-752 (fillet foundation)",
    "Ma, Song, Pang & Wen 2014, Eng. Fail. Anal. 44:179-194 (trochoid fillet)",
    "Chen & Shao 2011, Eng. Fail. Anal. 18:2149-2164 (crack, parallel limit line)",
    "Mohammed, Rantatalo & Aidanpaa 2013, Eng. Fail. Anal. 34:235-251 (tip limit line)",
)

#: Gauss-Legendre points per integration piece (the integrands are analytic on each piece).
N_GAUSS = 24
#: Roll-angle points of each tooth's compliance table (per smooth interval).
N_TABLE = 201


class SainsotRangeWarning(UserWarning):
    """The fillet-foundation formula is used outside the range Sainsot et al. (2004) fitted."""


# ---------------------------------------------------------------------------- the crack
@dataclass(frozen=True)
class ToothCrack:
    """A straight root crack on one tooth.

    Parameters
    ----------
    gear : {"pinion", "gear"}
        Which gear carries the cracked tooth.
    tooth : int
        Cracked tooth number (0-based, in mesh order: pair ``n`` holds pinion tooth ``n mod z1``
        and gear tooth ``n mod z2``).
    depth : float
        Crack length ``q`` from the mouth on the fillet to the tip [m].
    angle : float
        Angle ``upsilon`` between the crack and the tooth centreline [rad], in (0, pi/2); the tip
        is ``q sin(upsilon)`` nearer the centreline and ``q cos(upsilon)`` nearer the root than
        the mouth.
    limit_line : {"tip", "parallel"}
        PEM limit line: towards the tooth tip corner (Mohammed et al. 2013) or parallel to the
        centreline (Chen & Shao 2011); see the module docstring.

    Notes
    -----
    The mouth is on the loaded (tension) side at the fillet point with a 30 deg tangent
    (:func:`crack_geometry`).
    """

    gear: Literal["pinion", "gear"] = "pinion"
    tooth: int = 0
    depth: float = 5e-3
    angle: float = math.radians(45)
    limit_line: Literal["tip", "parallel"] = "tip"

    def __post_init__(self) -> None:
        if self.gear not in ("pinion", "gear"):
            raise InputError("crack.gear", self.gear, "'pinion' or 'gear'")
        if isinstance(self.tooth, bool) or int(self.tooth) != self.tooth or self.tooth < 0:
            raise InputError("crack.tooth", self.tooth, "a tooth number >= 0")
        if not (math.isfinite(self.depth) and self.depth > 0):
            raise InputError("crack.depth", self.depth, "a crack length > 0 [m]")
        if not (0 < self.angle < math.pi / 2):
            raise InputError("crack.angle", self.angle, "an angle in (0, pi/2) rad")
        if self.limit_line not in ("tip", "parallel"):
            raise InputError("crack.limit_line", self.limit_line, "'tip' or 'parallel'")

    @classmethod
    def from_config(cls, cfg) -> ToothCrack:
        """From a :class:`geardyn.config.CrackConfig`."""
        return cls(gear=cfg.gear, tooth=int(cfg.tooth), depth=float(cfg.depth),
                   angle=float(cfg.angle), limit_line=cfg.limit_line)


@dataclass(frozen=True)
class CrackGeometry:
    """Where a crack sits in the frame of its tooth (centred on +y, loaded flank at x > 0) [m].

    Attributes
    ----------
    mouth, tip : tuple of float
        ``(x, y)`` of the crack mouth on the fillet and of the crack tip [m].
    limit_end : tuple of float
        Upper end of the limit line: the tip corner of the loaded flank (``"tip"``) or the point
        above the crack tip on the tip circle's height (``"parallel"``) [m].
    mouth_radius : float
        Radius of the mouth point [m].
    """

    mouth: tuple[float, float]
    tip: tuple[float, float]
    limit_end: tuple[float, float]
    mouth_radius: float

    def limit_x(self, y: np.ndarray) -> np.ndarray:
        """Abscissa of the limit line at centreline heights ``y`` [m]."""
        (xt, yt), (xe, ye) = self.tip, self.limit_end
        return xt + (xe - xt) * (np.asarray(y) - yt) / (ye - yt)


# ---------------------------------------------------------------------------- the section
def _fillet_xy(gear, gamma: np.ndarray) -> np.ndarray:
    """Fillet points for the trochoid parameter ``gamma`` in [alpha, pi/2] [m], shape (n, 2).

    ``gamma`` is the angle between the rack-tip normal and the pitch line (Ma et al. 2014);
    ``gamma = alpha`` is the form point, ``gamma = pi/2`` the root circle. Uses the generator of
    :meth:`geardyn.geometry.Gear.outline`, so the section is the same tooth as everywhere else.
    """
    xi_c, a1 = gear._rack_tip_centre()
    gamma = np.asarray(gamma, float)
    phi = (a1 * np.cos(gamma) / np.sin(gamma) + xi_c) / gear.pitch_radius
    return gear._fillet_point(np.atleast_1d(phi))


def _involute_xy(gear, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Half-thickness ``h``, height ``y`` and ``dy/du`` of the involute at roll ``u`` [m]."""
    rb, a2 = gear.base_radius, gear.base_half_angle
    a = a2 - u  # the involute parameter alpha of Tian (2004)
    ca, sa = np.cos(a), np.sin(a)
    return rb * (u * ca + sa), rb * (ca - u * sa), rb * u * ca


@dataclass(frozen=True)
class _Piece:
    kind: str  # "fillet" (parameter gamma), "involute" (roll u) or "rect" (height y)
    t0: float  # parameter at the lower end (smaller y)
    t1: float  # parameter at the upper end
    y0: float
    y1: float


class ToothSection:
    r"""The load-carrying section of one tooth along its centreline, healthy or cracked.

    Parameters
    ----------
    gear : geardyn.geometry.Gear
    crack : ToothCrack, optional
        Crack on this tooth (its ``gear`` and ``tooth`` fields are not used here).
    model : {"exact", "classic"}
        ``"exact"``: trochoid fillet + involute from the generated outline (default).
        ``"classic"``: involute from the base circle plus the root rectangle of half-thickness
        ``r_b sin(alpha_2)`` down to ``r_f cos(alpha_3)`` (Wan et al. 2014), or the involute
        truncated at the root circle when ``r_f >= r_b``.
    n_gauss : int
        Gauss-Legendre points per piece.

    Attributes
    ----------
    y_root : float
        Centreline height where integration starts [m].
    u_min, u_tip : float
        Roll angles of the lowest involute point of the model and of the tip [rad].
    crack_geometry : CrackGeometry or None
    """

    def __init__(self, gear, crack: ToothCrack | None = None, *, model: str = "exact",
                 n_gauss: int = N_GAUSS):
        if model not in ("exact", "classic"):
            raise InputError("model", model, "'exact' or 'classic'")
        self.gear = gear
        self.crack = crack
        self.model = model
        self.n_gauss = int(n_gauss)
        self._xg, self._wg = np.polynomial.legendre.leggauss(self.n_gauss)
        rb, rf = gear.base_radius, gear.root_radius
        a2 = gear.base_half_angle
        self.u_tip = math.sqrt((gear.tip_radius / rb) ** 2 - 1.0)
        if gear.pointed:
            raise GeometryError("teeth", gear.teeth, "teeth that are not pointed (the PEM needs "
                                                     "a tip land)")
        pieces: list[_Piece] = []
        if model == "exact":
            if gear.undercut:
                raise GeometryError("teeth", gear.teeth,
                                    "a tooth without undercut for the PEM (use the FE method)")
            self.u_min = gear.form_roll_length / rb
            g_form, g_root = gear.pressure_angle, math.pi / 2
            y_form = float(_involute_xy(gear, self.u_min)[1])
            y_root = float(_fillet_xy(gear, g_root)[0, 1])
            # the half-thickness must be a function of height along the fillet
            yy = _fillet_xy(gear, np.linspace(g_form, g_root, 400))[:, 1]
            if np.any(np.diff(yy) >= 0):
                raise GeometryError("teeth", gear.teeth,
                                    "a fillet whose height decreases monotonically to the root "
                                    "(this tooth is not a cantilever the PEM can integrate)")
            pieces.append(_Piece("fillet", g_root, g_form, y_root, y_form))
        else:
            if rf < rb:
                self.u_min = 0.0
                a3 = math.asin(rb * math.sin(a2) / rf)
                y_root = rf * math.cos(a3)
                pieces.append(_Piece("rect", y_root, rb * math.cos(a2), y_root,
                                     rb * math.cos(a2)))
            else:
                self.u_min = math.sqrt((rf / rb) ** 2 - 1.0)
                y_root = float(_involute_xy(gear, self.u_min)[1])
        self.y_root = y_root
        y_inv0 = float(_involute_xy(gear, self.u_min)[1])
        self.y_tip = float(_involute_xy(gear, self.u_tip)[1])
        pieces.append(_Piece("involute", self.u_min, self.u_tip, y_inv0, self.y_tip))

        self.crack_geometry = crack_geometry(gear, crack) if crack is not None else None
        if self.crack_geometry is not None:
            pieces = self._split(pieces, self._crack_breaks(pieces))
        self.pieces = tuple(pieces)
        # rolls where the compliance may have a kink (breakpoints on the involute)
        self.roll_breaks = tuple(p.t0 for p in self.pieces
                                 if p.kind == "involute" and p.t0 > self.u_min)
        self._check_width()

    # ------------------------------------------------------------------ geometry
    def half_thickness(self, y: np.ndarray) -> np.ndarray:
        """Half-thickness ``h(y)`` of the (healthy) tooth at centreline heights ``y`` [m]."""
        y = np.atleast_1d(np.asarray(y, float))
        out = np.full(y.shape, np.nan)
        for p in self.pieces:
            m = (y >= p.y0) & (y <= p.y1)
            for k in np.flatnonzero(m):
                t = self._param_at(p, float(y[k]))
                out[k] = self._eval(p, np.array([t]))[0][0]
        return out

    def width(self, y: np.ndarray, h: np.ndarray) -> np.ndarray:
        """Load-carrying width ``w`` at heights ``y`` with half-thickness ``h`` [m]."""
        cg = self.crack_geometry
        if cg is None:
            return 2.0 * h
        lim = cg.limit_x(y)
        return np.where(y >= cg.tip[1], h + np.minimum(h, lim), 2.0 * h)

    def _eval(self, p: _Piece, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``h``, ``y`` and ``dy/dt`` at parameters ``t`` of piece ``p``."""
        if p.kind == "involute":
            return _involute_xy(self.gear, t)
        if p.kind == "rect":
            rb, a2 = self.gear.base_radius, self.gear.base_half_angle
            return np.full_like(t, rb * math.sin(a2)), t, np.ones_like(t)
        # fillet: central difference for dy/dgamma (analytic curve; error ~1e-10 relative)
        shape = t.shape
        t = t.ravel()
        step = 1e-5
        pts = _fillet_xy(self.gear, np.concatenate([t, t + step, t - step]))
        n = t.size
        dy = (pts[n:2 * n, 1] - pts[2 * n:, 1]) / (2 * step)
        return pts[:n, 0].reshape(shape), pts[:n, 1].reshape(shape), dy.reshape(shape)

    def _param_at(self, p: _Piece, y: float) -> float:
        """Parameter of piece ``p`` at height ``y`` (root finding)."""
        if p.kind == "rect":
            return y
        if abs(y - p.y0) <= 1e-15:
            return p.t0
        if abs(y - p.y1) <= 1e-15:
            return p.t1
        return brentq(lambda t: float(self._eval(p, np.array([t]))[1][0]) - y, p.t0, p.t1,
                      xtol=1e-15, rtol=1e-15, maxiter=200)

    def _crack_breaks(self, pieces: list[_Piece]) -> list[float]:
        """Heights where the effective width changes form: the crack tip and where the limit
        line meets the flank."""
        cg = self.crack_geometry
        out = []
        if self.y_root < cg.tip[1] < self.y_tip:
            out.append(cg.tip[1])
        # where h(y) = limit(y) above the crack tip: scan each piece for sign changes
        for p in pieces:
            ts = np.linspace(p.t0, p.t1, 257)
            h, y, _ = self._eval(p, ts)
            f = h - cg.limit_x(y)
            ok = y > cg.tip[1]
            for k in range(ts.size - 1):
                if ok[k] and ok[k + 1] and f[k] * f[k + 1] < 0:
                    tc = brentq(lambda t, p=p: float(
                        self._eval(p, np.array([t]))[0][0]
                        - cg.limit_x(self._eval(p, np.array([t]))[1])[0]),
                        ts[k], ts[k + 1], xtol=1e-15, rtol=1e-15)
                    out.append(float(self._eval(p, np.array([tc]))[1][0]))
        return sorted(y for y in out if self.y_root < y < self.y_tip - 1e-12)

    def _split(self, pieces: list[_Piece], breaks: list[float]) -> list[_Piece]:
        out: list[_Piece] = []
        for p in pieces:
            cuts = [y for y in breaks if p.y0 + 1e-13 < y < p.y1 - 1e-13]
            ys = [p.y0, *cuts, p.y1]
            ts = [p.t0] + [self._param_at(p, y) for y in cuts] + [p.t1]
            out += [_Piece(p.kind, ts[i], ts[i + 1], ys[i], ys[i + 1]) for i in range(len(ys) - 1)]
        return out

    def _check_width(self) -> None:
        cg = self.crack_geometry
        if cg is None:
            return
        for p in self.pieces:
            t = p.t0 + (p.t1 - p.t0) * (self._xg + 1) / 2
            h, y, _ = self._eval(p, t)
            if np.any(self.width(y, h) <= 0):
                raise InputError("crack.depth", self.crack.depth,
                                 "a crack whose limit line leaves material in every section up "
                                 "to the tip (a parallel limit line beyond the centreline cuts "
                                 "the tooth off; use limit_line='tip' or a shorter crack)")

    # ------------------------------------------------------------------ quadrature
    def nodes(self, roll: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Quadrature nodes up to the load point for each roll angle.

        Parameters
        ----------
        roll : ndarray, shape (n,)
            Roll angles ``phi`` of the load points on the involute [rad].

        Returns
        -------
        y, w, wq : ndarray, shape (n, m)
            Heights [m], load-carrying widths [m] and quadrature weights in ``dy`` [m] (zero
            for parts above the load point).
        """
        roll = np.atleast_1d(np.asarray(roll, float))
        ys, ws, wqs = [], [], []
        for p in self.pieces:
            if p.kind == "involute":
                top = np.clip(roll, p.t0, p.t1)[:, None]
            else:
                top = np.full((roll.size, 1), p.t1)
            half = (top - p.t0) / 2
            t = p.t0 + half * (self._xg[None, :] + 1)
            h, y, dy = self._eval(p, t)
            ys.append(y)
            ws.append(self.width(y, h))
            wqs.append(half * self._wg[None, :] * dy)
        return np.hstack(ys), np.hstack(ws), np.hstack(wqs)

    def load_point(self, roll: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Height ``y_F`` [m], half-thickness ``h_F`` [m] and load angle ``alpha_1`` [rad]."""
        roll = np.asarray(roll, float)
        h, y, _ = _involute_xy(self.gear, roll)
        return y, h, roll - self.gear.base_half_angle

    def check_roll(self, roll: np.ndarray) -> None:
        """Raise :class:`GeometryError` if a load point lies off the modelled involute."""
        roll = np.asarray(roll, float)
        if roll.size and (np.min(roll) < self.u_min - 1e-12 or np.max(roll) > self.u_tip + 1e-12):
            raise GeometryError("roll", (float(np.min(roll)), float(np.max(roll))),
                                f"roll angles in [{self.u_min:.6g}, {self.u_tip:.6g}] rad (form "
                                "circle to tip); contact below the form circle is interference")


# ---------------------------------------------------------------------------- energy terms
def hertz_compliance(youngs_modulus: float, poisson_ratio: float, face_width: float) -> float:
    r"""Hertzian contact compliance of a tooth pair, Yang & Lin (1987) [m/N].

    .. math:: \frac{1}{k_h} = \frac{4 (1 - \nu^2)}{\pi E L}

    Constant along the path of contact and independent of the load: Yang & Lin's (1987)
    linearised Hertz energy of two cylinders of the same material (``design/stiffness.md`` 1.1;
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


def bending_compliance(section: ToothSection, roll: np.ndarray, youngs_modulus: float,
                       face_width: float) -> np.ndarray:
    r"""Bending compliance of one tooth, load at roll angle ``roll`` [m/N].

    Yang & Lin (1987); Tian (2004) (involute from the base circle); Ma et al. (2014) for the
    trochoid fillet; Chen & Shao (2011) for the cracked section (``design/stiffness.md`` 1.1):

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


#: Coefficients A..F of L*, M*, P*, Q* (Sainsot, Velex & Duverger 2004; design/stiffness.md 1.3).
SAINSOT_TABLE = {
    "L": (-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045),
    "M": (60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086),
    "P": (-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236),
    "Q": (-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904),
}
#: Range of the Sainsot fit: h_f = r_f / r_int and theta_f [rad].
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


def sainsot_validity(gear, theta_f: float | None = None,
                     bore_radius: float | None = None) -> list[str]:
    """Why the Sainsot formula is extrapolated for this gear, in words (empty if it is not).

    Parameters
    ----------
    gear : geardyn.geometry.Gear
    theta_f, bore_radius : float, optional
        Overrides of the root half-angle [rad] and the bore radius [m].
    """
    theta_f = gear.root_half_angle if theta_f is None else theta_f
    h_f = gear.root_radius / (gear.bore_radius if bore_radius is None else bore_radius)
    out = []
    lo, hi = SAINSOT_RANGE["h_f"]
    if not lo <= h_f <= hi:
        out.append(f"h_f = r_f/r_int = {h_f:.4g} outside the fitted range [{lo}, {hi}] of Sainsot "
                   "et al. (2004)")
    lo, hi = SAINSOT_RANGE["theta_f"]
    if not lo <= theta_f <= hi:
        out.append(f"theta_f = {theta_f:.4g} rad outside the fitted range [{lo}, {hi}] rad of "
                   "Sainsot et al. (2004)")
    return out


def foundation_compliance(gear, roll: np.ndarray, youngs_modulus: float, face_width: float,
                          *, theta_f: float | None = None, bore_radius: float | None = None,
                          warn: bool = False) -> np.ndarray:
    r"""Fillet-foundation (gear body) compliance, Sainsot, Velex & Duverger (2004) [m/N].

    .. math:: \frac{1}{k_f} = \frac{\cos^2\alpha_1}{E L}\left\{L^*\left(\frac{u_f}{S_f}\right)^2
              + M^*\frac{u_f}{S_f} + P^*\left(1 + Q^*\tan^2\alpha_1\right)\right\}

    with ``u_f = r_b / cos(alpha_1) - r_f`` (root circle to where the load line crosses the
    centreline, trap T9), ``S_f = 2 r_f theta_f`` and ``theta_f`` the tooth's half-angle at the
    root circle on the generated outline (``Gear.root_half_angle``, 3.013/z for the ISO 53 rack;
    trap T8), with the gear's own bore (``h_f = r_f / r_int``, trap T11).

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


def tooth_compliance(section: ToothSection, roll: np.ndarray, youngs_modulus: float,
                     poisson_ratio: float, face_width: float, *,
                     terms: bool = False) -> np.ndarray | dict[str, np.ndarray]:
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
        "foundation": foundation_compliance(section.gear, roll, E, L),
    }
    return t if terms else t["bending"] + t["shear"] + t["axial"] + t["foundation"]


def tooth_compliance_quad(section: ToothSection, roll: float, youngs_modulus: float,
                          poisson_ratio: float, face_width: float, *, epsabs: float = 1e-14,
                          epsrel: float = 1e-12) -> float:
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
    found = float(foundation_compliance(section.gear, roll, youngs_modulus, face_width)[0])
    return total / (youngs_modulus * face_width) + found


# ---------------------------------------------------------------------------- crack geometry
def crack_geometry(gear, crack: ToothCrack) -> CrackGeometry:
    """Mouth, tip and limit line of a crack in its tooth's frame (tooth on +y, loaded flank at
    ``x > 0``) [m].

    The mouth is the fillet point whose tangent makes 30 deg with the centreline (ISO 6336-3
    critical section); the crack runs at ``crack.angle`` to the centreline, inwards and towards
    the root, for ``crack.depth``.
    """
    if gear.undercut:
        raise GeometryError("teeth", gear.teeth, "a tooth without undercut for the crack model")
    # tangent angle with the centreline along the fillet: atan(|dx| / |dy|)
    step = 1e-6

    def tangent_angle(g: float) -> float:
        p = _fillet_xy(gear, np.array([g - step, g + step]))
        dx, dy = p[1, 0] - p[0, 0], p[1, 1] - p[0, 1]
        return math.atan2(abs(dx), abs(dy))

    g0, g1 = gear.pressure_angle + 1e-9, math.pi / 2 - 1e-9
    target = math.radians(30)
    if not tangent_angle(g0) < target < tangent_angle(g1):
        raise GeometryError("teeth", gear.teeth, "a fillet that has a 30 deg tangent point")
    g_m = brentq(lambda g: tangent_angle(g) - target, g0, g1, xtol=1e-14)
    xm, ym = (float(v) for v in _fillet_xy(gear, np.array([g_m]))[0])
    q, v = crack.depth, crack.angle
    xt, yt = xm - q * math.sin(v), ym - q * math.cos(v)
    if yt <= gear.bore_radius or abs(xt) >= xm:
        raise InputError("crack.depth", crack.depth,
                         f"a crack that stays inside the tooth body (tip at x = {xt:.4g} m, "
                         f"y = {yt:.4g} m; mouth half-thickness {xm:.4g} m)")
    if crack.limit_line == "parallel" and xt <= 0:
        raise InputError("crack.depth", crack.depth,
                         "a crack whose tip stays on the loaded side of the centreline for the "
                         f"parallel limit line (tip at x = {xt:.4g} m; the crossing case 2 of "
                         "Chen & Shao 2011 is not modelled): use limit_line='tip'")
    u_tip = math.sqrt((gear.tip_radius / gear.base_radius) ** 2 - 1.0)
    h_a, y_a, _ = _involute_xy(gear, u_tip)
    # the tip line never removes more than the parallel line (its purpose, Mohammed et al. 2013):
    # when the tip corner is nearer the centreline than the crack tip, the two lines coincide
    tip_line = crack.limit_line == "tip" and float(h_a) > xt
    end = (float(h_a), float(y_a)) if tip_line else (xt, float(y_a))
    return CrackGeometry(mouth=(xm, ym), tip=(xt, yt), limit_end=end,
                         mouth_radius=math.hypot(xm, ym))


# ---------------------------------------------------------------------------- gear body
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


# ---------------------------------------------------------------------------- the pair
class PEMModel:
    r"""Potential-energy mesh stiffness of a gear pair at any operating centre distance.

    Each tooth's compliance (healthy, and the cracked tooth) is tabulated once against its roll
    angle (cubic splines on ``N_TABLE`` points per smooth interval; relative error ~1e-8); the
    contact points of every pair come from the operating line of action of ``d'``
    (:meth:`geardyn.geometry.GearPair.contact_points` conventions), so ``K(theta, d)`` is exact
    for any ``d``.

    Parameters
    ----------
    pair : geardyn.geometry.GearPair
    youngs_modulus : float
        ``E`` [Pa] (both gears).
    poisson_ratio : float
        ``nu`` [-].
    crack : ToothCrack, optional
    model : {"exact", "classic"}
        Tooth model, see :class:`ToothSection`.
    face_width : float, optional
        ``L`` [m]; default ``pair.pinion.face_width``.
    body_torsion : bool
        Add the elastic torsion of each gear body between its bore and root circle in series
        with the mesh (:func:`body_torsion_compliance`): the torsional stiffness the paper's FEA
        reports is measured hub to hub and contains it (trap T5), while the classic PEM (each
        pair with its own fillet foundation, pairs in parallel) does not. Default off, which is
        the PEM of the literature.
    """

    def __init__(self, pair, youngs_modulus: float, poisson_ratio: float,
                 crack: ToothCrack | None = None, *, model: str = "exact",
                 face_width: float | None = None, n_table: int = N_TABLE,
                 body_torsion: bool = False):
        if not (math.isfinite(youngs_modulus) and youngs_modulus > 0):
            raise InputError("material.youngs_modulus", youngs_modulus, "a modulus > 0 [Pa]")
        if not 0 < poisson_ratio < 0.5:
            raise InputError("material.poisson_ratio", poisson_ratio, "a value in (0, 0.5)")
        self.pair = pair
        self.E = float(youngs_modulus)
        self.nu = float(poisson_ratio)
        self.L = float(pair.pinion.face_width if face_width is None else face_width)
        self.model = model
        self.crack = crack
        self.n_table = int(n_table)
        self.body_torsion = bool(body_torsion)
        # series compliance along the LOA of both bodies' torsion [m/N]
        self.body_compliance = (
            pair.pinion.base_radius ** 2 * body_torsion_compliance(pair.pinion, self.E, self.nu,
                                                                   self.L)
            + pair.gear.base_radius ** 2 * body_torsion_compliance(pair.gear, self.E, self.nu,
                                                                   self.L)
        ) if self.body_torsion else 0.0
        if crack is not None:
            z = pair.pinion.teeth if crack.gear == "pinion" else pair.gear.teeth
            if crack.tooth >= z:
                raise InputError("crack.tooth", crack.tooth,
                                 f"a tooth number in [0, {z - 1}] of the {crack.gear}")
        self.sections = {
            ("pinion", False): ToothSection(pair.pinion, model=model),
            ("gear", False): ToothSection(pair.gear, model=model),
        }
        if crack is not None:
            g = pair.pinion if crack.gear == "pinion" else pair.gear
            self.sections[(crack.gear, True)] = ToothSection(g, crack, model=model)
        self._tables: dict[tuple[str, bool], list[tuple[float, float, CubicSpline]]] = {}

    @classmethod
    def from_case(cls, case, *, cracked: bool = True, model: str = "exact") -> PEMModel:
        """The model of a :class:`geardyn.config.Case` (its crack if ``cracked`` and enabled)."""
        crack = None
        if cracked and case.crack is not None and case.crack.enabled:
            crack = ToothCrack.from_config(case.crack)
        return cls(case.gear_pair(), case.material.youngs_modulus, case.material.poisson_ratio,
                   crack, model=model, face_width=case.pair.face_width,
                   body_torsion=case.stiffness.body_torsion)

    # ---------------------------------------------------------------- per tooth
    @property
    def hertz(self) -> float:
        """``1/k_h`` [m/N]."""
        return hertz_compliance(self.E, self.nu, self.L)

    def tooth_compliance_exact(self, which: str, roll, cracked: bool = False) -> np.ndarray:
        """Tooth compliance by direct quadrature (no table) [m/N]."""
        return tooth_compliance(self.sections[(which, cracked)], roll, self.E, self.nu, self.L)

    def _table(self, which: str, cracked: bool) -> list[tuple[float, float, CubicSpline]]:
        key = (which, cracked)
        if key not in self._tables:
            sec = self.sections[key]
            edges = [sec.u_min, *sec.roll_breaks, sec.u_tip]
            parts = []
            for a, b in zip(edges[:-1], edges[1:], strict=True):
                # Chebyshev-Lobatto spacing: accurate splines near the interval ends
                u = a + (b - a) * (1 - np.cos(np.linspace(0, np.pi, self.n_table))) / 2
                c = tooth_compliance(sec, u, self.E, self.nu, self.L)
                parts.append((a, b, CubicSpline(u, c)))
            self._tables[key] = parts
        return self._tables[key]

    def tooth_compliance(self, which: str, roll, cracked: bool = False) -> np.ndarray:
        """Compliance of a pinion or gear tooth loaded at roll angle ``roll`` [m/N] (table).

        Parameters
        ----------
        which : {"pinion", "gear"}
        roll : array_like
            Roll angle of the load point on that gear [rad].
        cracked : bool
            The cracked tooth (needs a crack on ``which``).
        """
        roll = np.asarray(roll, float)
        sec = self.sections[(which, cracked)]
        sec.check_roll(roll)
        out = np.empty(roll.shape)
        parts = self._table(which, cracked)
        inner = np.array([b for _, b, _ in parts[:-1]])
        idx = np.searchsorted(inner, roll, side="right")
        for k, (_, _, spl) in enumerate(parts):
            m = idx == k
            if np.any(m):
                out[m] = spl(roll[m])
        return out

    def pair_stiffness(self, pinion_roll, gear_roll, *, pinion_cracked=False,
                       gear_cracked=False) -> np.ndarray:
        """Stiffness of one tooth pair along the LOA [N/m] from the two roll angles [rad]."""
        c = (self.hertz + self.tooth_compliance("pinion", pinion_roll, pinion_cracked)
             + self.tooth_compliance("gear", gear_roll, gear_cracked))
        return 1.0 / c

    # ---------------------------------------------------------------- the mesh
    def evaluate(self, theta, centre_distance_change: float = 0.0) -> dict[str, np.ndarray]:
        """Mesh stiffness, load sharing and pairs in contact at pinion angles ``theta``.

        Parameters
        ----------
        theta : array_like
            Pinion angles [rad] (0: pinion tooth 0 at the design pitch point).
        centre_distance_change : float
            ``d' - d`` [m].

        Returns
        -------
        dict
            ``k_mb`` [N/m] (n,); ``load_share`` [-] (n, 3), slot ``k`` holding pair
            ``n_exit + 1 + k`` where ``n_exit = floor((s(theta) - s_end)/p_b)`` is the last pair
            that has left mesh (the slots of :attr:`StiffnessMap.slot_tooth`); ``pair`` (n, 3)
            pair indices of the slots; ``pairs_in_contact`` [-] (n,); ``pinion_roll``,
            ``gear_roll`` (n, 3) [rad] (NaN out of contact).
        """
        pair = self.pair
        theta = np.atleast_1d(np.asarray(theta, float))
        op = pair.operating(float(centre_distance_change))
        if op.contact_ratio >= 3:
            raise InputError("centre_distance_change", centre_distance_change,
                             "a centre distance with contact ratio < 3")
        rb1, rb2, pb = pair.pinion.base_radius, pair.gear.base_radius, pair.base_pitch
        s_theta = pair.pitch_point_s + rb1 * theta
        n_exit = np.floor((s_theta - op.s_end) / pb).astype(np.int64)
        n = n_exit[:, None] + 1 + np.arange(3)[None, :]
        s = s_theta[:, None] - n * pb
        tol = 1e-12
        inc = (s >= op.s_start - tol) & (s <= op.s_end + tol)
        k = np.zeros(s.shape)
        phi1 = np.where(inc, s / rb1, np.nan)
        phi2 = np.where(inc, (op.t1t2 - s) / rb2, np.nan)
        crack = self.crack
        for pc in (False, True):
            for gc in (False, True):
                if (pc or gc) and crack is None:
                    continue
                if pc and crack.gear != "pinion" or gc and crack.gear != "gear":
                    continue
                is_p = (crack is not None and crack.gear == "pinion"
                        and np.mod(n, pair.pinion.teeth) == crack.tooth)
                is_g = (crack is not None and crack.gear == "gear"
                        and np.mod(n, pair.gear.teeth) == crack.tooth)
                m = inc & (is_p == pc) & (is_g == gc)
                if np.any(m):
                    k[m] = self.pair_stiffness(phi1[m], phi2[m], pinion_cracked=pc,
                                               gear_cracked=gc)
        kmb = k.sum(axis=1)
        share = np.divide(k, kmb[:, None], out=np.zeros_like(k), where=kmb[:, None] > 0)
        if self.body_compliance > 0:  # the bodies' torsion in series with all pairs
            kmb = np.divide(kmb, 1.0 + kmb * self.body_compliance, out=np.zeros_like(kmb),
                            where=kmb > 0)
        return {"k_mb": kmb, "load_share": share, "pairs_in_contact": inc.sum(axis=1),
                "pair": n, "pinion_roll": phi1, "gear_roll": phi2}

    def mesh_stiffness(self, theta, centre_distance_change: float = 0.0) -> np.ndarray:
        """Mesh stiffness along the LOA ``k_mb`` [N/m] at pinion angles ``theta`` [rad]."""
        return self.evaluate(theta, centre_distance_change)["k_mb"]

    def torsional_stiffness(self, theta, centre_distance_change: float = 0.0) -> np.ndarray:
        """Combined torsional mesh stiffness ``K_t = k_mb r_b1^2`` [N m/rad] (base radius,
        trap T6)."""
        return self.mesh_stiffness(theta, centre_distance_change) * self.pair.pinion.base_radius ** 2

    def check_range(self, dd: np.ndarray) -> None:
        """Raise :class:`GeometryError` if a centre distance puts contact off the modelled
        involutes (below the form circle) or loses contact (contact ratio < 1)."""
        pair = self.pair
        for d in np.atleast_1d(dd):
            op = pair.operating(float(d))
            rb1, rb2 = pair.pinion.base_radius, pair.gear.base_radius
            if op.s_start / rb1 < self.sections[("pinion", False)].u_min - 1e-12:
                raise GeometryError("centre_distance_change", float(d),
                                    "a centre distance at which the gear tip meets the pinion "
                                    "above its form circle (interference)")
            if (op.t1t2 - op.s_end) / rb2 < self.sections[("gear", False)].u_min - 1e-12:
                raise GeometryError("centre_distance_change", float(d),
                                    "a centre distance at which the pinion tip meets the gear "
                                    "above its form circle (interference)")

    def validity_warnings(self) -> list[str]:
        """Extrapolations of the model for this pair, in words."""
        out = []
        for name, g in (("pinion", self.pair.pinion), ("gear", self.pair.gear)):
            out += [f"{name}: {m}" for m in sainsot_validity(g)]
        return out

    def parameters(self) -> dict:
        """The model's parameters, for provenance."""
        p, g = self.pair.pinion, self.pair.gear
        out = {
            "youngs_modulus_Pa": self.E,
            "poisson_ratio": self.nu,
            "face_width_m": self.L,
            "tooth_model": self.model,
            "pinion_theta_f_rad": p.root_half_angle,
            "gear_theta_f_rad": g.root_half_angle,
            "pinion_bore_radius_m": p.bore_radius,
            "gear_bore_radius_m": g.bore_radius,
            "hertz_compliance_m_per_N": self.hertz,
        }
        if self.crack is not None:
            cg = self.sections[(self.crack.gear, True)].crack_geometry
            out["crack"] = {
                "gear": self.crack.gear, "tooth": int(self.crack.tooth),
                "depth_m": self.crack.depth, "angle_rad": self.crack.angle,
                "angle_convention": "angle between the crack and the tooth centreline; tip "
                                    "depth*sin(angle) nearer the centreline and depth*cos(angle) "
                                    "nearer the root than the mouth",
                "mouth": "fillet point with a 30 deg tangent (ISO 6336-3), loaded side",
                "limit_line": self.crack.limit_line,
                "mouth_xy_m": list(cg.mouth), "tip_xy_m": list(cg.tip),
            }
        return out


# ---------------------------------------------------------------------------- the map
def pem_map(case, dd: np.ndarray, *, cracked: bool,
            progress: Callable[[int, int], None] | None = None,
            model: str = "exact") -> StiffnessMap:
    """The PEM stiffness map of a case on the centre-distance grid ``dd``.

    Called by :func:`geardyn.stiffness.build_map` (which caches it). One pinion revolution
    (``n_cycles = z1``), or one gear revolution (``z2`` cycles) when the crack is on the gear,
    with ``case.stiffness.nodes_per_segment`` nodes per contact zone.

    Parameters
    ----------
    case : geardyn.config.Case
    dd : ndarray
        Centre distance changes ``d' - d`` [m], uniform and increasing.
    cracked : bool
        Include the case's crack (if it has an enabled one).
    progress : callable, optional
        ``progress(done, total)`` after each centre distance.

    Returns
    -------
    StiffnessMap
        ``k_mb`` [N/m] with ``load_share`` (n_d, nodes, 3) and ``pairs_in_contact``.

    Warns
    -----
    SainsotRangeWarning
        If a gear lies outside the fitted range of the foundation formula (recorded in
        ``attrs["warnings"]`` as well).
    """
    pem = PEMModel.from_case(case, cracked=cracked, model=model)
    dd = np.atleast_1d(np.asarray(dd, float))
    pem.check_range(dd)
    notes = pem.validity_warnings()
    for msg in notes:
        warnings.warn(msg, SainsotRangeWarning, stacklevel=2)
    n_cycles = None
    if pem.crack is not None and pem.crack.gear == "gear":
        n_cycles = pem.pair.gear.teeth

    def fn(theta: np.ndarray, d: float) -> dict:
        r = pem.evaluate(theta, d)
        return {"k_mb": r["k_mb"], "load_share": r["load_share"],
                "pairs_in_contact": r["pairs_in_contact"].astype(float)}

    from .. import __version__

    attrs = {
        "method": "pem",
        "title": "mesh stiffness by the potential energy method",
        "citations": list(CITATIONS),
        "parameters": pem.parameters(),
        "cracked": int(pem.crack is not None),
        "warnings": notes,
        "geardyn_version": __version__,
        "case": case.name,
    }
    return StiffnessMap.from_function(pem.pair, dd, fn, n_cycles=n_cycles,
                                      n_seg=case.stiffness.nodes_per_segment, attrs=attrs,
                                      progress=progress)
