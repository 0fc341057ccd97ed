"""The load-carrying section of one tooth along its centreline, healthy or cracked.

``"exact"``: the trochoid fillet (Ma, Song, Pang & Wen 2014) and the involute of the generated
outline, integrated from the root chord ``y_0 = r_f cos(theta_f)``. ``"classic"``: the involute from
the base circle plus the root rectangle of half-thickness ``r_b sin(alpha_2)`` (Wan et al. 2014,
Eng. Fail. Anal. 42:157-177), or the involute truncated at the root circle. A crack replaces the
width above its tip by ``h + min(h, limit)`` (Chen & Shao 2011; Mohammed et al. 2013).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from ...errors import GeometryError, InputError
from .crack import ToothCrack, crack_geometry
from .profile import _fillet_xy, _involute_xy

#: Gauss-Legendre points per integration piece (the integrands are analytic on each piece).
N_GAUSS = 24


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

            def gap(t, p=p):
                hh, yy, _ = self._eval(p, np.array([t]))
                return float(hh[0] - cg.limit_x(yy)[0])

            for k in range(ts.size - 1):
                if not ok[k + 1]:
                    continue
                a, fa = ts[k], f[k]
                if not ok[k]:  # the interval straddles the crack tip: scan from the tip up
                    a = self._param_at(p, float(cg.tip[1]))
                    fa = gap(a)
                if fa == 0.0 and ok[k]:  # the limit line meets the flank at a sample
                    out.append(float(y[k]))
                elif fa * f[k + 1] < 0:
                    tc = brentq(gap, a, ts[k + 1], xtol=1e-15, rtol=1e-15)
                    out.append(float(self._eval(p, np.array([tc]))[1][0]))
            if ok[-1] and f[-1] == 0.0:
                out.append(float(y[-1]))
        return sorted({y for y in out if self.y_root < y < self.y_tip - 1e-12})

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
                why = ("a parallel limit line beyond the centreline cuts the tooth off; use "
                       "limit_line='tip' or a shorter crack"
                       if self.crack.limit_line == "parallel" else
                       "this crack's limit line to the tip corner cuts the tooth off; use a "
                       "shorter or shallower crack")
                raise InputError("crack.depth", self.crack.depth,
                                 f"a crack whose limit line leaves material in every section up "
                                 f"to the tip ({why})")

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

