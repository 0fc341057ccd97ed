"""The root crack of the PEM: parameters and where the crack sits in its tooth.

Angle convention (stated explicitly, trap T18 of docs/verification/stiffness.md): ``angle``
(``upsilon``) is the angle between the crack and the tooth centreline; the crack runs from its
mouth into the tooth and towards the root, so its tip is ``q sin(upsilon)`` nearer the centreline
and ``q cos(upsilon)`` lower than the mouth. The mouth is on the loaded (tension) side at the
fillet point whose tangent makes 30 deg with the centreline (the critical section of ISO 6336-3).
Limit lines: parallel to the centreline (Tian 2004; Chen & Shao 2011, Eng. Fail. Anal.
18:2149-2164) or from the crack tip to the tip corner (Mohammed, Rantatalo & Aidanpaa 2013, Eng.
Fail. Anal. 34:235-251); see :mod:`geardyn.stiffness.pem`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.optimize import brentq

from ...errors import GeometryError, InputError
from .profile import _fillet_xy, _involute_xy


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

