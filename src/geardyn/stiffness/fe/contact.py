r"""Loaded contact of the gear pair from the bodies' influence coefficients.

For a pinion angle ``theta`` and a centre distance change ``dd`` (backlash closed by turning the
pinion, as in Xue & Howard 2018, section 3, with the gear hub fixed and the torque ``T`` on the
pinion hub) the static problem is

.. math::
   \sum_k C_{jk} F_k + g_j - a_j\,\Delta\theta = w_j \ge 0,\qquad F_j \ge 0,\qquad w_j F_j = 0,
   \qquad \sum_k a_k F_k = T / b,

for the candidate tooth pairs ``j`` (per metre of face width ``b``): ``F_j`` the normal contact
force, ``C = C^{(1)} + C^{(2)} + C^{loc}(F)`` the compliance of the pinion and the gear (FE
influence coefficients under a reference Hertzian patch, :mod:`.solve`) plus the analytical
correction of the local Hertzian deformation to the actual contact width, ``g_j`` the unloaded gap,
``a_j`` the pinion lever arm of the contact force and ``Delta theta`` the rotation of the pinion hub
(the static transmission error). It is the optimality system of the strictly convex quadratic
programme ``min 1/2 F^T C F + g^T F`` subject to ``F >= 0``, ``a^T F = T/b``, solved exactly by an
active-set enumeration (at most five candidates), with a fixed-point iteration on the load-dependent
local term. Then ``K_t = T / Delta theta`` (secant) and ``k_mb = K_t / r_b1^2`` with the *base*
radius (traps T5 and T6 of docs/verification/stiffness.md).

Kinematics and unloaded gaps
----------------------------
Candidate pairs come from :meth:`geardyn.geometry.GearPair.contact_points` (position ``s`` along
the operating line of action, LOA). Inside the theoretical path ``[s_start, s_end]`` the perfect
involutes touch (``g = 0``) at roll lengths ``u_1 = s`` and ``u_2 = T_1T_2 - s`` and the force acts
along the LOA (``a = r_b1``). Beyond it, the tip corner of one gear faces the flank of the other.
Involutes of one base circle are parallel curves whose normal distance is ``r_b`` times their
angular offset, so the gap between the corner ``C`` and the mating flank is exact:

* pinion tip corner (``s > s_end``): ``g = u_2(C) + r_b2 (gamma_C - pi) - (T_1T_2 - s)``, with
  ``u_2(C)`` the length of the tangent from ``C`` to the gear base circle and ``gamma_C`` its
  tangency angle; the gear is loaded at roll ``u_2(C) - g``, the pinion at its tip, along that
  tangent (lever arm about the pinion centre computed exactly);
* gear tip corner (``s < s_start``): the mirror formula with the pinion base circle
  (``a = r_b1``).

So extended contact under load (before the theoretical start, after the theoretical end) appears
when the deflection closes these gaps. The corner load is applied to the FE bodies as the patch at
the tip of the flank, and its local term uses the involute curvatures (a sharp corner has no
Hertzian solution; real tips are rounded).

References
----------
Xue, S. & Howard, I. (2018), Mech. Syst. Signal Process., section 3.
Johnson, K. L. (1985). Contact Mechanics, eq. 5.36 (approach of cylinders in plane strain).
Vedmar, L. (1981). On the design of external involute helical gears. PhD thesis, Lund.
Conry, T. F. & Seireg, A. (1971). A mathematical programming method for design of elastic bodies
in contact. J. Appl. Mech. 38:387-392.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...errors import NumericalError
from .solve import BodyInfluence

if TYPE_CHECKING:
    from scipy.interpolate import CubicSpline, RectBivariateSpline

__all__ = ["Candidates", "candidates", "CandidateGenerator", "BodyCompliance", "solve_compatibility",
           "ContactResult", "PairContactModel"]

PATH, PINION_TIP, GEAR_TIP = 0, 1, 2


@dataclass(frozen=True)
class Candidates:
    """Candidate contacts of the tooth pairs near the mesh at one pinion angle.

    Every field has shape ``(n,)`` for the ``n`` candidates; a block of positions with ``n``
    candidates each (:meth:`CandidateGenerator.block`) has shape ``(positions, n)``.

    Attributes
    ----------
    pair, pinion_tooth, gear_tooth : ndarray of int
        Pair index ``n`` and tooth numbers (see :mod:`geardyn.geometry`).
    s : ndarray
        Position of the pair along the operating LOA [m].
    kind : ndarray of int
        0 on the theoretical path, 1 pinion tip corner (beyond the end), 2 gear tip corner
        (before the start).
    u1, u2 : ndarray
        Roll lengths of the load points on the pinion and the gear flanks [m].
    gap : ndarray
        Unloaded normal gap [m] (0 on the path).
    arm : ndarray
        Lever arm of the contact force about the pinion centre [m].
    radius : ndarray
        Relative radius of curvature ``rho_1 rho_2 / (rho_1 + rho_2)`` for the Hertz width [m].
    """

    pair: np.ndarray
    pinion_tooth: np.ndarray
    gear_tooth: np.ndarray
    s: np.ndarray
    kind: np.ndarray
    u1: np.ndarray
    u2: np.ndarray
    gap: np.ndarray
    arm: np.ndarray
    radius: np.ndarray


def _wrap(a):
    return (np.asarray(a) + math.pi) % (2 * math.pi) - math.pi


def candidates(pair, theta: float, dd: float, margin: float = 0.35) -> Candidates:
    """Candidate contacts, their load points, gaps and lever arms at ``(theta, dd)``.

    Parameters
    ----------
    pair : geardyn.geometry.GearPair
    theta : float
        Pinion angle [rad] (geometry.py convention; backlash closed).
    dd : float
        Centre distance change [m].
    margin : float
        Candidates up to ``margin`` base pitches outside the theoretical path.

    Returns
    -------
    Candidates
    """
    cp = pair.contact_points(theta, dd, margin=margin)
    op = pair.operating(dd, check=False)
    rb1, rb2 = pair.pinion.base_radius, pair.gear.base_radius
    kind, u1, u2, gap, arm, radius = _contact_geometry(
        cp.s, op, rb1, rb2, np.array([rb1 + rb2, op.t1t2]),
        math.sqrt(pair.pinion.tip_radius ** 2 - rb1 ** 2),
        math.sqrt(pair.gear.tip_radius ** 2 - rb2 ** 2))
    return Candidates(pair=cp.pair, pinion_tooth=cp.pinion_tooth, gear_tooth=cp.gear_tooth,
                      s=cp.s, kind=kind, u1=u1, u2=u2, gap=gap, arm=arm, radius=radius)


def _contact_geometry(s, op, rb1, rb2, o2, ua1, ua2):
    """Kind, roll lengths ``u1``, ``u2`` [m], gap [m], lever arm [m] and relative radius of
    curvature [m] of contacts at LOA positions ``s`` [m] (a tip corner in extended contact
    beyond the path: its gap to the mating flank and the contact there)."""
    t1t2 = op.t1t2
    n = s.size
    kind = np.where(s > op.s_end, PINION_TIP, np.where(s < op.s_start, GEAR_TIP, PATH))
    u1 = s.copy()
    u2 = t1t2 - s
    gap = np.zeros(n)
    arm = np.full(n, rb1)
    for k in range(n):
        if kind[k] == PINION_TIP:
            beta = (s[k] - ua1) / rb1
            c = rb1 * np.array([math.cos(beta), math.sin(beta)]) \
                + ua1 * np.array([-math.sin(beta), math.cos(beta)])
            v = c - o2
            r = math.hypot(*v)
            gam = math.atan2(v[1], v[0]) - math.acos(rb2 / r)
            lam = math.sqrt(r * r - rb2 * rb2)
            g = lam + rb2 * float(_wrap(gam - math.pi)) - (t1t2 - s[k])
            gap[k] = g
            u1[k] = ua1
            u2[k] = lam - g
            t2 = o2 + rb2 * np.array([math.cos(gam), math.sin(gam)])
            e = np.array([-math.sin(gam), math.cos(gam)])
            arm[k] = abs(t2[0] * e[1] - t2[1] * e[0])
        elif kind[k] == GEAR_TIP:
            gn = t1t2 - s[k]
            gam = math.pi + (gn - ua2) / rb2
            c = o2 + rb2 * np.array([math.cos(gam), math.sin(gam)]) \
                + ua2 * np.array([-math.sin(gam), math.cos(gam)])
            r = math.hypot(*c)
            beta = math.atan2(c[1], c[0]) - math.acos(rb1 / r)
            lam = math.sqrt(r * r - rb1 * rb1)
            g = lam + rb1 * float(_wrap(beta)) - s[k]
            gap[k] = g
            u1[k] = lam - g
            u2[k] = ua2
    rho1 = np.clip(u1, 1e-9, None)
    rho2 = np.clip(u2, 1e-9, None)
    return kind, u1, u2, gap, arm, rho1 * rho2 / (rho1 + rho2)


class CandidateGenerator:
    """:func:`candidates` at many pinion angles of one centre distance.

    The operating geometry, radii and tip roll lengths are computed once per centre distance
    instead of once per angle; each call repeats the arithmetic of
    :meth:`geardyn.geometry.GearPair.contact_points` and :func:`candidates` operation for
    operation, so the result is bit for bit that of ``candidates(pair, theta, dd, margin)``
    (tests/fe/test_batched_contact.py). :meth:`span` and :meth:`block` do the same for many
    angles at once (the tip-corner geometry compiled, equal to rounding).

    Parameters
    ----------
    pair : geardyn.geometry.GearPair
    dd : float
        Centre distance change [m].
    margin : float
        Candidates up to ``margin`` base pitches outside the theoretical path.
    """

    def __init__(self, pair, dd: float, margin: float = 0.35):
        op = pair.operating(dd, check=False)
        self.op = op
        self.pb = pair.base_pitch
        self.s0 = pair.pitch_point_s
        self.rb1, self.rb2 = pair.pinion.base_radius, pair.gear.base_radius
        self.z1, self.z2 = pair.pinion.teeth, pair.gear.teeth
        self.lo, self.hi = op.s_start - margin * self.pb, op.s_end + margin * self.pb
        self.t1t2 = op.t1t2
        self.o2 = np.array([self.rb1 + self.rb2, op.t1t2])
        self.ua1 = math.sqrt(pair.pinion.tip_radius ** 2 - self.rb1 ** 2)
        self.ua2 = math.sqrt(pair.gear.tip_radius ** 2 - self.rb2 ** 2)

    def pairs(self, theta: float) -> tuple[np.ndarray, np.ndarray]:
        """Pair indices ``n`` and LOA positions ``s`` [m] of the candidates at ``theta`` [rad]."""
        pb = self.pb
        s_theta = self.s0 + self.rb1 * theta
        n = np.arange(math.ceil((s_theta - self.hi) / pb - 1e-12),
                      math.floor((s_theta - self.lo) / pb) + 1)
        s = s_theta - n * pb
        order = np.argsort(s)
        return n[order], s[order]

    def __call__(self, theta: float) -> Candidates:
        """Candidates at pinion angle ``theta`` [rad]."""
        return self.complete(*self.pairs(theta))

    def span(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`pairs` at many angles: ``s_theta`` [m] and the first and last pair index.

        Position ``i`` has the candidates ``n = last[i], last[i] - 1, ..., first[i]`` (in this,
        :meth:`pairs`' order of increasing ``s``) at ``s = s_theta[i] - n p_b``; the same
        floating-point operations as :meth:`pairs`, element by element.
        """
        pb = self.pb
        s_theta = self.s0 + self.rb1 * np.asarray(theta, float)
        first = np.ceil((s_theta - self.hi) / pb - 1e-12).astype(np.int64)
        last = np.floor((s_theta - self.lo) / pb).astype(np.int64)
        return s_theta, first, last

    def block(self, s_theta: np.ndarray, last: np.ndarray, size: int) -> Candidates:
        """Candidates of positions with ``size`` candidates each, from :meth:`span`.

        Returns
        -------
        Candidates
            Every field of shape ``(positions, size)``, row ``i`` equal to
            ``self(theta[i])`` (the geometry of the tip corners computed by the compiled
            :func:`._batch.complete_nb`).
        """
        from ._batch import complete_nb

        n = np.asarray(last, np.int64)[:, None] - np.arange(size, dtype=np.int64)[None, :]
        s = np.asarray(s_theta, float)[:, None] - n * self.pb
        op = self.op
        kind, u1, u2, gap, arm, radius = complete_nb(
            s, float(op.s_start), float(op.s_end), float(self.t1t2), float(self.o2[0]),
            float(self.o2[1]), float(self.rb1), float(self.rb2), float(self.ua1),
            float(self.ua2))
        return Candidates(pair=n, pinion_tooth=np.mod(n, self.z1), gear_tooth=np.mod(n, self.z2),
                          s=s, kind=kind, u1=u1, u2=u2, gap=gap, arm=arm, radius=radius)

    def complete(self, n: np.ndarray, s: np.ndarray) -> Candidates:
        """Candidates of the pairs ``n`` at LOA positions ``s`` [m] (from :meth:`pairs`)."""
        kind, u1, u2, gap, arm, radius = _contact_geometry(
            s, self.op, self.rb1, self.rb2, self.o2, self.ua1, self.ua2)
        return Candidates(pair=n, pinion_tooth=np.mod(n, self.z1), gear_tooth=np.mod(n, self.z2),
                          s=s, kind=kind, u1=u1, u2=u2, gap=gap, arm=arm, radius=radius)


class BodyCompliance:
    """Interpolated influence coefficients of one body between any two load points.

    Parameters
    ----------
    influence : BodyInfluence
        Healthy body (loaded on tooth 0 only; cyclic symmetry gives the other teeth) or faulty
        body (loaded on every refined tooth; model tooth 0 faulty: cracked, broken or both).
    teeth : int
        Number of teeth of the gear.
    """

    def __init__(self, influence: BodyInfluence, teeth: int):
        # imported here: the FE bodies' second process imports this module (through .model)
        # but evaluates no map; scipy.interpolate took 0.3-0.6 s of its start (2026-11-28)
        from scipy.interpolate import CubicSpline, RectBivariateSpline

        self.inf = influence
        self.z = teeth
        u = influence.u
        self.u_min, self.u_max = float(u[0]), float(u[-1])
        self.cyclic = influence.load_offsets == (0,)
        ro = influence.read_offsets
        #: roll-length range of the points of each model tooth [m] (a broken tooth's is shorter)
        self.bounds = {j: (float(influence.grid(j)[0]), float(influence.grid(j)[-1]))
                       for j in ro}
        self._self: dict[int, CubicSpline] = {}
        self._cross: dict[tuple[int, int], RectBivariateSpline] = {}
        for a, i in enumerate(influence.load_offsets):
            b = ro.index(i)
            self._self[i] = CubicSpline(influence.grid(i), np.diag(influence.H[a, b]))
            for b, j in enumerate(ro):
                if j != i:
                    self._cross[(i, j)] = RectBivariateSpline(influence.grid(j),
                                                              influence.grid(i),
                                                              influence.H[a, b])

    def covers(self, offset: int) -> bool:
        """Whether model tooth ``offset`` is loaded in this body's model (faulty bodies)."""
        return offset in self.inf.load_offsets

    def _clip(self, offset: int, u):
        lo, hi = self.bounds.get(offset, (self.u_min, self.u_max))
        return np.clip(u, lo, hi)

    def batch(self, load: np.ndarray, u_load: np.ndarray, read: np.ndarray,
              u_read: np.ndarray) -> np.ndarray:
        """:meth:`__call__` element by element on arrays of one shape [m^2/N].

        Entries sharing a spline are evaluated in one vectorised call of it (the same spline
        arithmetic as the scalar call; equal bit for bit, tests/fe/test_batched_contact.py).
        """
        load = np.asarray(load, np.int64)
        read = np.asarray(read, np.int64)
        u_load = np.asarray(u_load, float)
        u_read = np.asarray(u_read, float)
        if self.cyclic:
            read, load = read - load, np.zeros_like(load)
        out = np.zeros(u_load.shape)
        if out.size == 0:
            return out
        base = int(max(np.max(np.abs(load)), np.max(np.abs(read)))) + 1
        code = (load + base) * (2 * base + 1) + (read + base)
        for c in np.unique(code):
            sel = code == c
            i, j = int(c // (2 * base + 1) - base), int(c % (2 * base + 1) - base)
            ul = self._clip(i, u_load[sel])
            if i == j:
                out[sel] = self._self[i](ul)
            else:
                f = self._cross.get((i, j))
                if f is not None:
                    out[sel] = f.ev(self._clip(j, u_read[sel]), ul)
        return out

    def __call__(self, load: int, u_load: float, read: int, u_read: float) -> float:
        """Compliance [m^2/N]: displacement at ``u_read`` on model tooth ``read`` per unit load at
        ``u_load`` on model tooth ``load`` (0 if the teeth are farther apart than the model)."""
        if self.cyclic:
            read, load = read - load, 0
        lo, hi = self.bounds.get(load, (self.u_min, self.u_max))
        ul = min(max(u_load, lo), hi)
        if read == load:
            return float(self._self[load](ul))
        f = self._cross.get((load, read))
        if f is None:
            return 0.0
        lo, hi = self.bounds.get(read, (self.u_min, self.u_max))
        ur = min(max(u_read, lo), hi)
        return float(f(ur, ul)[0, 0])


@dataclass(frozen=True)
class ContactResult:
    """Loaded contact at one position (per metre of face width).

    Attributes
    ----------
    force : ndarray
        Normal contact force of each candidate per unit width [N/m].
    rotation : float
        Pinion hub rotation ``Delta theta`` under the torque [rad] (static transmission error).
    separation : ndarray
        Loaded gap of each candidate [m] (0 where in contact).
    iterations : int
        Fixed-point iterations of the local Hertz term.
    """

    force: np.ndarray
    rotation: float
    separation: np.ndarray
    iterations: int


def _qp(c: np.ndarray, g: np.ndarray, a: np.ndarray, torque: float,
        first: np.ndarray | None = None) -> tuple[np.ndarray, float, np.ndarray]:
    """Exact active-set enumeration of ``min 1/2 F'CF + g'F, F >= 0, a'F = torque``."""
    n = g.size
    scale_f = torque / a.max()
    orders: list[tuple[int, ...]] = []
    if first is not None and first.any():
        orders.append(tuple(np.nonzero(first)[0]))
    for m in range(1, n + 1):
        orders += [s for s in itertools.combinations(range(n), m) if s not in orders]
    best = None
    for sset in orders:
        idx = np.asarray(sset)
        k = idx.size
        mat = np.zeros((k + 1, k + 1))
        mat[:k, :k] = c[np.ix_(idx, idx)]
        mat[:k, k] = -a[idx]
        mat[k, :k] = a[idx]
        rhs = np.concatenate([-g[idx], [torque]])
        try:
            sol = np.linalg.solve(mat, rhs)
        except np.linalg.LinAlgError:
            continue
        f = np.zeros(n)
        f[idx] = sol[:k]
        dth = sol[k]
        if np.any(f < -1e-10 * scale_f):
            continue
        w = c @ f + g - dth * a
        tol = 1e-9 * max(dth * a.max(), 1e-30)
        if np.any(np.delete(w, idx) < -tol):
            continue
        f = np.clip(f, 0.0, None)
        w[idx] = 0.0
        best = (f, float(dth), np.clip(w, 0.0, None))
        break
    if best is None:
        raise NumericalError("no solution of the contact compatibility problem",
                             state={"candidates": n})
    return best


def solve_compatibility(c0: np.ndarray, gap: np.ndarray, arm: np.ndarray, torque: float,
                        local=None, *, tol: float = 1e-10, max_iter: int = 60) -> ContactResult:
    """Contact forces and hub rotation from compliances, gaps and lever arms.

    Parameters
    ----------
    c0 : ndarray, shape (n, n)
        Compliance matrix at the reference patch width [m^2/N] (per unit width, symmetric).
    gap : ndarray, shape (n,)
        Unloaded gaps [m].
    arm : ndarray, shape (n,)
        Pinion lever arms [m].
    torque : float
        Pinion torque per unit width [N m/m].
    local : callable, optional
        ``local(F) -> (n,)`` extra diagonal compliance of the local contact at forces ``F``
        [m^2/N]; solved by fixed-point iteration on the secant compliance.

    Returns
    -------
    ContactResult
    """
    gap = np.asarray(gap, float)
    arm = np.asarray(arm, float)
    first = gap <= 0
    f, dth, w = _qp(c0, gap, arm, torque, first)
    it = 0
    if local is not None:
        for k in range(1, max_iter + 1):
            it = k
            c = c0 + np.diag(local(f))
            f_new, dth_new, w = _qp(c, gap, arm, torque, f > 0)
            done = abs(dth_new - dth) <= tol * abs(dth_new) and \
                np.max(np.abs(f_new - f)) <= tol * 1e3 * np.max(f_new)
            f, dth = f_new, dth_new
            if done:
                break
        else:
            raise NumericalError("local contact iteration did not converge",
                                 state={"rotation": dth})
    return ContactResult(force=f, rotation=dth, separation=w, iterations=it)


class PairContactModel:
    """The gear pair's compliance and loaded contact at any ``(theta, dd)``.

    Parameters
    ----------
    pair : geardyn.geometry.GearPair
    pinion, gear : BodyCompliance
        Healthy bodies.
    bodies : dict, optional
        Faulty bodies: ``(which, tooth) -> BodyCompliance`` whose model tooth 0 is tooth
        ``tooth`` (mesh order) of ``which`` (``"pinion"`` or ``"gear"``). The coefficient between
        two teeth both loaded in a faulty body's model comes from that body, any other from the
        healthy body (so two faulty bodies of one gear must not load a common tooth:
        :func:`geardyn.stiffness.fe.faults.check_fe_faults`).
    cracked : BodyCompliance, optional
        One faulty body (the ``[crack]`` model), the same as ``bodies={(crack_gear,
        crack_tooth): cracked}``.
    crack_gear : {"pinion", "gear"}
    crack_tooth : int
        Cracked tooth number (mesh order).
    plane_modulus : (float, float)
        Plane moduli of the pinion and the gear [Pa].
    half_width : float
        Reference patch half-width of the influence coefficients [m].
    marked : iterable of (str, int), optional
        Teeth with a fault but no faulty body (a spall): positions involving them are not
        repeated from another mesh cycle (:meth:`fault_rows`).
    """

    def __init__(self, pair, pinion: BodyCompliance, gear: BodyCompliance, *,
                 cracked: BodyCompliance | None = None, crack_gear: str = "pinion",
                 crack_tooth: int = 0, plane_modulus: tuple[float, float],
                 half_width: float, local: bool = True, bodies: dict | None = None,
                 marked=()):
        self.pair = pair
        self.pinion = pinion
        self.gear = gear
        bodies = dict(bodies or {})
        if cracked is not None:
            bodies[(crack_gear, int(crack_tooth))] = cracked
        self.bodies: dict[tuple[str, int], BodyCompliance] = {
            (w, int(t)): b for (w, t), b in bodies.items()}
        first = next(iter(self.bodies.items()), None)
        #: the first faulty body, its gear and tooth (``None``, "pinion", 0 without one)
        self.cracked = None if first is None else first[1]
        self.crack_gear = "pinion" if first is None else first[0][0]
        self.crack_tooth = 0 if first is None else first[0][1]
        self.marked = frozenset((w, int(t)) for w, t in marked)
        self.e1, self.e2 = plane_modulus
        self.half_width = half_width
        self.estar = 1.0 / (1.0 / self.e1 + 1.0 / self.e2)
        self.local_enabled = local

    # model tooth of a real tooth: pinion teeth follow each other clockwise in the body model
    # (model offsets run counter-clockwise), gear teeth counter-clockwise.
    def _wrap(self, d: int, z: int) -> int:
        return int((d + z // 2) % z - z // 2)

    def _teeth(self, which: str) -> int:
        return self.pair.pinion.teeth if which == "pinion" else self.pair.gear.teeth

    def _own(self, which: str) -> list[tuple[int, BodyCompliance]]:
        return [(t, b) for (w, t), b in self.bodies.items() if w == which]

    def model_offset(self, which: str, tooth: int, ref: int | None = None) -> int:
        """Model tooth of a real tooth relative to tooth ``ref`` (default: the first faulty
        tooth of that gear, else tooth 0). Pinion teeth follow each other clockwise in the body
        model (whose offsets run counter-clockwise), gear teeth counter-clockwise."""
        z = self._teeth(which)
        sign = -1 if which == "pinion" else 1
        if ref is None:
            own = self._own(which)
            ref = own[0][0] if own else 0
        return sign * self._wrap(int(tooth) - ref, z)

    def involves_crack(self, cand: Candidates) -> bool:
        """Whether any candidate tooth is loaded in a faulty body's model or marked."""
        return bool(self.teeth_involve_crack(cand.pinion_tooth, "pinion")
                    or self.teeth_involve_crack(cand.gear_tooth, "gear"))

    def teeth_involve_crack(self, teeth, which: str | None = None) -> bool:
        """Whether any of these teeth of ``which`` (default: the first faulty body's gear) is
        loaded in a faulty body's model or marked."""
        which = self.crack_gear if which is None else which
        for t in teeth:
            if (which, int(t)) in self.marked:
                return True
            for ref, body in self._own(which):
                if body.covers(self.model_offset(which, int(t), ref)):
                    return True
        return False

    def _side(self, which: str, teeth: np.ndarray, u: np.ndarray) -> np.ndarray:
        n = teeth.size
        out = np.zeros((n, n))
        healthy = self.pinion if which == "pinion" else self.gear
        own = self._own(which)
        z = self._teeth(which)
        m = [self.model_offset(which, int(t), 0) for t in teeth]
        for j in range(n):
            for k in range(n):
                for ref, body in own:
                    mj = self.model_offset(which, int(teeth[j]), ref)
                    mk = self.model_offset(which, int(teeth[k]), ref)
                    if body.covers(mk) and body.covers(mj):
                        out[j, k] = body(mk, u[k], mj, u[j])
                        break
                else:
                    out[j, k] = healthy(0, u[k], self._wrap(m[j] - m[k], z), u[j])
        # Maxwell-Betti: the patch-to-point coefficients are symmetric up to discretisation
        return 0.5 * (out + out.T)

    def _side_batch(self, which: str, teeth: np.ndarray, u: np.ndarray) -> np.ndarray:
        z = self._teeth(which)
        sign = -1 if which == "pinion" else 1
        healthy = self.pinion if which == "pinion" else self.gear
        teeth = np.asarray(teeth, np.int64)
        npos, n = teeth.shape
        shape = (npos, n, n)
        uk = np.broadcast_to(u[:, None, :], shape)
        uj = np.broadcast_to(u[:, :, None], shape)
        out = np.zeros(shape)
        done = np.zeros(shape, bool)
        for ref, body in self._own(which):
            m = sign * ((teeth - ref + z // 2) % z - z // 2)
            mk = np.broadcast_to(m[:, None, :], shape)  # load on candidate k (column)
            mj = np.broadcast_to(m[:, :, None], shape)  # read on candidate j (row)
            cov = np.isin(m, body.inf.load_offsets)
            use = cov[:, None, :] & cov[:, :, None] & ~done
            if use.any():
                out[use] = body.batch(mk[use], uk[use], mj[use], uj[use])
                done |= use
        m = sign * ((teeth + z // 2) % z - z // 2)
        mk = np.broadcast_to(m[:, None, :], shape)
        mj = np.broadcast_to(m[:, :, None], shape)
        rest = ~done
        rel = (mj[rest] - mk[rest] + z // 2) % z - z // 2
        out[rest] = healthy.batch(np.zeros_like(rel), uk[rest], rel, uj[rest])
        return 0.5 * (out + np.swapaxes(out, 1, 2))

    def compliance_batch(self, cand: Candidates) -> np.ndarray:
        """:meth:`compliance` of a block of positions (every field of ``cand`` of shape
        ``(positions, n)``, e.g. from :meth:`CandidateGenerator.block`), shape
        ``(positions, n, n)`` [m^2/N per m]; each matrix equal bit for bit to
        :meth:`compliance` of that row."""
        return self._side_batch("pinion", cand.pinion_tooth, cand.u1) + \
            self._side_batch("gear", cand.gear_tooth, cand.u2)

    def crack_rows(self, pair_index: np.ndarray, valid: np.ndarray) -> np.ndarray:
        """:meth:`involves_crack` of many positions: pair indices ``n`` (positions, k) of which
        ``valid`` entries are candidates -> bool (positions,)."""
        out = np.zeros(pair_index.shape[0], bool)
        for which in ("pinion", "gear"):
            z = self._teeth(which)
            sign = -1 if which == "pinion" else 1
            teeth = np.mod(pair_index, z)
            for ref, body in self._own(which):
                m = sign * ((teeth - ref + z // 2) % z - z // 2)
                out |= np.any(np.isin(m, body.inf.load_offsets) & valid, axis=1)
            for w, t in self.marked:
                if w == which:
                    out |= np.any((teeth == t) & valid, axis=1)
        return out

    def compliance(self, cand: Candidates) -> np.ndarray:
        """Compliance matrix of the candidates at the reference patch width [m^2/N per m]."""
        return self._side("pinion", cand.pinion_tooth, cand.u1) + \
            self._side("gear", cand.gear_tooth, cand.u2)

    def local_term(self, cand: Candidates, force_per_width: np.ndarray) -> np.ndarray:
        """Analytical change of the contact approach from the reference patch to the actual Hertz
        width, per unit force [m^2/N]: ``-(2/pi)(1/E1' + 1/E2') ln(b/b_ref)`` with
        ``b = sqrt(4 F' R / (pi E*))`` (Johnson 1985, eq. 5.36)."""
        f = np.maximum(np.asarray(force_per_width, float), 1e-9)
        b = np.sqrt(4 * f * cand.radius / (math.pi * self.estar))
        return -(2 / math.pi) * (1 / self.e1 + 1 / self.e2) * np.log(b / self.half_width)

    def solve_candidates(self, cand: Candidates, torque_per_width: float) -> ContactResult:
        """Loaded contact of given candidates for the pinion torque per unit width [N m/m]."""
        c0 = self.compliance(cand)
        local = (lambda f: self.local_term(cand, f)) if self.local_enabled else None
        return solve_compatibility(c0, cand.gap, cand.arm, torque_per_width, local)

    def solve(self, theta: float, dd: float, torque_per_width: float,
              margin: float = 0.35) -> tuple[Candidates, ContactResult]:
        """Candidates and loaded contact at ``(theta, dd)`` for the pinion torque per unit width
        [N m/m]."""
        cand = candidates(self.pair, theta, dd, margin=margin)
        return cand, self.solve_candidates(cand, torque_per_width)
