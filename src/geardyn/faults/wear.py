r"""Wear of one tooth's loaded flank: material removed to a depth over a band of the
profile, as a profile deviation.

Geometry. Over the roll window ``[u_a, u_b]`` (default: the whole active profile at the nominal
centre distance) a layer of uniform depth ``delta`` is removed normal to the involute. The normal
of an involute is the line of action, so the worn flank lies ``delta`` behind the perfect one
along the line of action: a profile deviation ``e(u) = delta`` on the window, 0 elsewhere,
positive where material is missing (the sign convention of :mod:`geardyn.modifications`).

What it does:

* the **excitation / separation**: the worn tooth pair must close the gap ``e`` before it carries
  load. The PEM and FE maps record the gap of each load-share slot (``fault_gap`` [m], extra
  variable of the map); the dynamics and the static TE take it from
  :class:`geardyn.modifications.ToothModifications`, which adds ``e(u)`` to the worn tooth's
  deviation table (sampled on its nodes: the window's edges ramp over one node spacing), so the
  worn pair closes the gap before it carries load (``tests/faults/test_wear_dynamics.py``: the
  static TE rises by exactly ``delta`` in single contact);
* optionally (``stiffness = true``) the **stiffness**: the tooth is thinner. At a section of
  the worn band the half-thickness on the loaded side is smaller by ``delta / cos(alpha_1)``
  (the flank normal makes the angle ``alpha_1 = u - alpha_2`` with the tooth's transverse axis),
  so the section width is ``w = 2 h - delta / cos(alpha_1)`` (:mod:`geardyn.stiffness.pem.wear`;
  first order in ``delta``, the shift of the neutral axis neglected as for the crack).

No published wear-stiffness formula was read for this; the section change is plain geometry and
is checked in ``tests/faults/test_wear.py`` against an independent quadrature (scipy ``quad``) of
the same beam integrals.

Depth along the profile (``law``). ``"uniform"``: ``delta`` everywhere on the window.
``"archard"``: the profile of mild sliding wear, Archard's law ``dh = k p ds`` (wear depth
proportional to contact pressure times sliding distance) integrated over one passage of the
Hertz band across a flank point. While the band (half-width ``a``) passes the point at the
point's own rolling speed ``v_self``, the surfaces slide by ``|v_self - v_mate|`` per unit time,
so the point slides ``|1 - v_mate / v_self|`` per unit of band travel and

.. math:: h_{pass}(u) = k \left|1 - \frac{v_{mate}}{v_{self}}\right| \int p\, dx
          = k\, \frac{W(u)}{b} \left|1 - \frac{v_{mate}}{v_{self}}\right|,

since the Hertz pressure integrates to the load per unit face width ``W / b`` whatever ``a``.
With ``omega_self r_b,self = omega_mate r_b,mate`` the speed ratio is ``v_mate / v_self =
(r_b,self rho_mate) / (r_b,mate rho_self)``, the ``rho`` the involutes' radii of curvature at the
contact point (``rho_self = r_b,self u``, ``rho_mate = T1T2 - rho_self``, nominal centre
distance). ``W(u)`` is the idealised load sharing of rigid teeth: the full load where one pair
is in contact, half where two are. After ``N`` passes the depth is ``N h_pass``; geardyn takes
the largest depth ``delta`` and keeps the shape (zero at the pitch point, largest at the root of
the flank): ``e(u) = delta f(u) / max f`` with ``f = W |1 - v_mate / v_self|``, so ``k N`` need
not be known (:func:`archard_scale` gives ``delta`` from ``k``, ``N`` and the load). The
profile is fixed geometry: it neither changes the load sharing it was computed from (no wear
iteration) nor follows the centre distance.

Archard's law is the usual model of mild gear wear (Flodin, *Wear of spur and helical gears*,
KTH doctoral thesis 2000, abstract read: "a modified Archard's equation"); the passage integral
above is derived here and checked in ``tests/faults/test_wear_archard.py`` against a direct
integration of the Hertz pressure over the band with the sliding speed of two explicitly turned
involutes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .base import FaultBase, active_roll_range, check_size, gear_of
from .spall import involute_half_thickness


@dataclass(frozen=True)
class Wear(FaultBase):
    """Uniform wear of one tooth's loaded flank.

    Parameters
    ----------
    gear, tooth, label
        See :class:`geardyn.faults.base.FaultBase`.
    depth : float
        Depth removed normal to the flank [m] (0: no wear).
    roll_start, roll_length : float
        Worn roll window [rad].
    stiffness : bool
        Also model the thinner tooth in the PEM stiffness.
    law : {"uniform", "archard"}
        Depth along the profile (module docstring); ``depth`` is the largest depth.
    shape : tuple
        ``"archard"``: ``(roll, f)`` from :func:`archard_shape` (set by
        :func:`geardyn.faults.faults_from_case`).
    """

    depth: float = 0.0
    roll_start: float = 0.0
    roll_length: float = 0.0
    stiffness: bool = False
    law: str = "uniform"
    #: ``"archard"``: the unnormalised shape ``f`` sampled on the window, ``(roll [rad], f)``
    shape: tuple = ()

    kind = "wear"

    @property
    def window(self) -> tuple[float, float]:
        """Worn roll window ``(u_a, u_b)`` [rad]."""
        return self.roll_start, self.roll_start + self.roll_length

    def is_null(self) -> bool:
        return self.depth == 0 or self.roll_length == 0

    def deviation(self, roll) -> np.ndarray:
        """Profile deviation along the line of action at roll ``roll`` [m] (material
        missing)."""
        roll = np.asarray(roll, float)
        a, b = self.window
        inside = (roll >= a) & (roll <= b)
        if self.law == "uniform":
            return np.where(inside, self.depth, 0.0)
        u, f = (np.asarray(v, float) for v in self.shape)
        return np.where(inside, self.depth * np.interp(roll, u, f) / f.max(), 0.0)

    def thickness_loss(self, gear, roll) -> np.ndarray:
        """Loss of section width at the involute point of roll ``roll`` [m]:
        ``delta / cos(u - alpha_2)`` on the window, 0 elsewhere."""
        roll = np.asarray(roll, float)
        return self.deviation(roll) / np.cos(roll - gear.base_half_angle)

    def validate(self, pair, face_width: float) -> None:
        """Raise :class:`InputError` for a window off the active profile or a depth the tooth
        cannot lose."""
        self.check_place(pair)
        check_size(self.depth, self.field("depth"), "a wear depth [m]")
        check_size(self.roll_length, self.field("length"), "a worn length")
        g = gear_of(pair, self.gear)
        lo, hi = active_roll_range(pair, self.gear)
        a, b = self.window
        rb = g.base_radius
        if not (lo - 1e-12 <= a and b <= hi + 1e-12):
            raise InputError(self.field("start"), f"roll {a:.6g} to {b:.6g} rad",
                             f"a worn band inside the active profile of the {self.gear}: roll "
                             f"[{lo:.6g}, {hi:.6g}] rad, roll length [{lo * rb * 1e3:.4g}, "
                             f"{hi * rb * 1e3:.4g}] mm")
        if self.is_null():
            return
        u = np.linspace(a, b, 65)
        spare = 2 * involute_half_thickness(g, u) - np.asarray(self.thickness_loss(g, u))
        if np.min(spare) <= 0.5 * 2 * float(np.min(involute_half_thickness(g, u))):
            raise InputError(self.field("depth"), self.depth,
                             "a wear depth below half the local tooth thickness")


#: Roll samples of an Archard profile over its window [-]
ARCHARD_SAMPLES = 801


def sliding_factor(pair, which: str, roll) -> np.ndarray:
    """``|1 - v_mate / v_self|`` at the contact point of ``which``'s flank at roll ``roll``
    [rad] (nominal centre distance) [-]: the distance slid per unit of Hertz-band travel."""
    op = pair.operating(0.0, check=False)
    self_g, mate = (pair.pinion, pair.gear) if which == "pinion" else (pair.gear, pair.pinion)
    rho = self_g.base_radius * np.asarray(roll, float)
    rho_mate = op.t1t2 - rho
    return np.abs(1.0 - self_g.base_radius * rho_mate / (mate.base_radius * rho))


def rigid_load_share(pair, which: str, roll) -> np.ndarray:
    """Idealised share of the load of the pair touching ``which``'s flank at roll ``roll``
    [rad] [-]: 1 over the number of pairs in contact (rigid teeth, nominal centre distance);
    the neighbours lie one base pitch either side on the line of action."""
    op = pair.operating(0.0, check=False)
    rb = gear_of(pair, which).base_radius
    u = np.asarray(roll, float)
    s = rb * u if which == "pinion" else op.t1t2 - rb * u  # pinion roll length from T1 [m]
    pb, tol = pair.base_pitch, 1e-12
    pairs = 1 + (s + pb <= op.s_end + tol).astype(int) + (s - pb >= op.s_start - tol).astype(int)
    return 1.0 / pairs


def archard_shape(pair, which: str, window: tuple[float, float]) -> tuple:
    """``(roll [rad], f [-])`` on :data:`ARCHARD_SAMPLES` points of ``window``: the Archard
    depth per passage over ``k W_total / b`` (module docstring)."""
    u = np.linspace(window[0], window[1], ARCHARD_SAMPLES)
    f = rigid_load_share(pair, which, u) * sliding_factor(pair, which, u)
    return tuple(float(x) for x in u), tuple(float(x) for x in f)


def archard_scale(pair, which: str, *, wear_coefficient: float, cycles: float,
                  torque: float, face_width: float) -> float:
    """Largest Archard depth [m] after ``cycles`` meshes of one tooth: ``k N (W / b) max f``
    with ``W = torque / r_b1`` the total normal load [N] (pinion torque [N m]),
    ``wear_coefficient`` ``k`` [m^2/N] (dimensional wear coefficient, depth per pressure and
    sliding distance) and ``face_width`` ``b`` [m]."""
    for name, v in (("wear_coefficient", wear_coefficient), ("cycles", cycles),
                    ("torque", torque), ("face_width", face_width)):
        if not (np.isfinite(v) and v >= 0):
            raise InputError(name, v, "a finite value >= 0")
    lo, hi = active_roll_range(pair, which)
    _, f = archard_shape(pair, which, (lo, hi))
    w = torque / pair.pinion.base_radius
    return float(wear_coefficient * cycles * w / face_width * max(f))
