r"""Tooth faults in the FE mesh stiffness (issue 15, item 3): which fault is done how, and why.

The FE model is plane (2-D per unit face width). What a fault does to it:

* **root crack through the face** (the ``[crack]`` section or a ``root_crack`` of the ``faults``
  list with ``width`` the whole face and ``front = "uniform"``): a slit with duplicated nodes in
  the mesh of the faulty tooth's body (:func:`.mesh.build_body_mesh`), the cracked body of the
  ``[crack]`` model, now one per faulty tooth.
* **tooth breakage**: removed geometry. The faulty tooth is meshed with its involutes ending at
  the radius ``r_a - Delta h`` and a circular arc there (:func:`.mesh.cut_flank`); its flank's
  load points end at the cut (:func:`.solve.load_roll_lengths`). Beyond the cut the contact is
  that of the cut's corner against the mating flank, the unloaded gap computed exactly like the
  tip-corner gap of extended contact (:mod:`.contact`) with the corner at the cut
  (:func:`pinion_corner`, :func:`gear_corner`): so the contact ends early on that tooth and the
  neighbours take over when the deflection closes their gaps.
* **spall**: missing contact over its area. While the contact point on the spalled tooth lies in
  the spall's roll window, the pair has no contact over the spall's width ``b_s``; the rest of
  the face is unchanged. A plane model cannot remove contact over part of the width, so the face
  is cut into **bands** across the width (below); in the band of the spall the pair's contact is
  removed (:data:`REMOVED_GAP`), in the other band it is healthy. The depth does not enter, as in
  the PEM (the flank does not touch the spall's bottom).
* **partial-face crack and breakage over part of the face** (``width`` less than the face, or a
  ``linear`` / ``parabolic`` crack front): bands again, each band a plane model with its own
  crack depth or cut (the crack's ``slices`` equal slices over the cracked width, their depths
  at the slice midpoints as :meth:`geardyn.faults.RootCrack.slice_depths`: each distinct depth
  is one FE body).
* **wear**: a profile deviation along the line of action, recorded in the map as ``fault_gap``
  per load-share slot exactly as the PEM does (:func:`fault_gap`, the same geometry), for the
  dynamics. The contact solve does not see it, as it does not see tooth errors
  (:mod:`geardyn.modifications`), so the map stays the stiffness of the loaded flanks. Wear with
  ``stiffness = true`` (the thinner tooth) is refused: a uniform layer of a few tens of
  micrometres is below the flank element size of the FE mesh.

Bands across the face
---------------------
Each band ``s`` of width ``w_s`` is a plane model of the pair with its own faulty teeth; all the
bands turn with the same pinion hub rotation ``Delta theta`` and share the torque:

.. math:: \sum_s w_s \tau_s = T, \qquad \Delta\theta_s(\tau_s) = \Delta\theta \ \text{for every
          band with}\ \tau_s > 0, \qquad \Delta\theta \le \Delta\theta_{0,s}\ \text{where}\
          \tau_s = 0,

with ``Delta theta_s(tau)`` the rotation of band ``s`` under the torque per unit width ``tau``
(:func:`.contact.solve_compatibility`) and ``Delta theta_{0,s} = min_j g_j / a_j`` the rotation at
which its first pair touches (zero when a pair is on the path). The bands are independent plane
models in parallel: no shear coupling across the face, the assumption of the PEM's slicing
method (:mod:`geardyn.stiffness.pem.partial_crack`) and of the effective-width model of the
spall. :func:`combine_bands` solves it by a secant iteration on the affine law
``tau_s = k_s max(0, Delta theta - Delta theta_{0,s})`` (exact in one step for a band whose
active set does not change and without the load-dependent local Hertz term; a few steps with
it). Faults whose widths would meet at one contact point are placed side by side across the
face (their removed widths add, the PEM's worst case); a crack's slices start at the face end
``z = 0`` where it is deepest.

What is not modelled: a chipped corner whose cut is not parallel to the tip (the cut is at one
radius within its width, as in the PEM); contact on the bottom of a spall; two faulty bodies
whose models load a common tooth (:func:`check_fe_faults` refuses them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ...errors import InputError, NumericalError
from .contact import GEAR_TIP, PINION_TIP, Candidates
from .mesh import CrackGeometry, check_cut, crack_segment

__all__ = ["REMOVED_GAP", "ToothState", "FaceBand", "face_bands", "check_fe_faults",
           "band_candidates", "pinion_corner", "gear_corner", "combine_bands", "fault_gap",
           "body_faults"]

#: Unloaded gap given to a contact that does not exist (a spalled band) [m]: so large that the
#: pair never closes it (the deflections are micrometres), finite so the active-set algebra stays
#: finite.
REMOVED_GAP = 1.0


@dataclass(frozen=True)
class ToothState:
    """What is wrong with one tooth in one band of the face.

    Attributes
    ----------
    crack : CrackGeometry or None
        Root crack of this band.
    cut_radius : float or None
        Radius of a broken tooth's cut [m].
    spalls : tuple of (float, float)
        Roll-angle windows ``(u_a, u_b)`` [rad] where the contact is missing.
    """

    crack: CrackGeometry | None = None
    cut_radius: float | None = None
    spalls: tuple[tuple[float, float], ...] = ()

    @property
    def body(self) -> tuple | None:
        """Key of the faulty FE body this tooth needs (``None``: the healthy body)."""
        if self.crack is None and self.cut_radius is None:
            return None
        return (self.crack, self.cut_radius)


@dataclass(frozen=True)
class FaceBand:
    """One band across the face width: its width and its faulty teeth.

    Attributes
    ----------
    width : float
        Width of the band [m] (bands of the same state summed).
    teeth : tuple of ((str, int), ToothState)
        ``((which, tooth), state)`` of every tooth with a fault in this band.
    """

    width: float
    teeth: tuple[tuple[tuple[str, int], ToothState], ...] = ()

    def state(self) -> dict[tuple[str, int], ToothState]:
        """``(which, tooth) -> ToothState``."""
        return dict(self.teeth)


def _intervals(faults, face_width: float) -> list[tuple[float, float, object]]:
    """``(z0, z1, fault-with-effect)`` of every active fault's part of the face."""
    L = float(face_width)
    out = []
    acc = 0.0  # width-removing faults side by side (their widths add, as in the PEM)
    for f in faults:
        if f.is_null() or f.kind == "wear":
            continue
        if f.kind == "root_crack":
            bc = min(f.cracked_width, L)
            if f.full_width:
                out.append((0.0, L, f, float(f.depth)))
            elif f.front == "uniform":
                out.append((0.0, bc, f, float(f.depth)))
            else:
                n = int(f.slices)
                for i in range(n):
                    z0, z1 = i * bc / n, (i + 1) * bc / n
                    q = float(f.depth_at(np.array([0.5 * (z0 + z1)]))[0])
                    if q > 0:
                        out.append((z0, z1, f, q))
            continue
        b = f.broken_width if f.kind == "breakage" else float(f.width)
        z0, z1 = min(acc, L), min(acc + b, L)
        acc += b
        if z1 > z0:
            out.append((z0, z1, f, None))
    return out


def face_bands(faults, face_width: float, pair) -> list[FaceBand]:
    """The bands across the face of a pair with ``faults`` (module docstring).

    Parameters
    ----------
    faults : sequence of geardyn.faults.RootCrack, Spall, Breakage, Wear
        Validated faults; faults of zero size and wear are left out.
    face_width : float
        ``L`` [m].
    pair : geardyn.geometry.GearPair

    Returns
    -------
    list of FaceBand
        Widths summing to ``L``; one band (``teeth`` empty) without faults. Bands with the
        same faulty teeth are merged, in order of their first appearance from ``z = 0``.
    """
    L = float(face_width)
    parts = _intervals(faults, L)
    cuts = sorted({0.0, L, *[p[0] for p in parts], *[p[1] for p in parts]})
    merged: dict[tuple, float] = {}
    for a, b in zip(cuts[:-1], cuts[1:], strict=True):
        if not b > a:
            continue
        mid = 0.5 * (a + b)
        state: dict[tuple[str, int], ToothState] = {}
        for z0, z1, f, q in parts:
            if not (z0 <= mid < z1):
                continue
            key = (f.gear, int(f.tooth))
            st = state.get(key, ToothState())
            if f.kind == "root_crack":
                st = replace(st, crack=CrackGeometry(depth=q, angle=float(f.angle)))
            elif f.kind == "breakage":
                g = pair.pinion if f.gear == "pinion" else pair.gear
                st = replace(st, cut_radius=float(g.tip_radius - f.height))
            else:
                st = replace(st, spalls=st.spalls + (tuple(map(float, f.window)),))
            state[key] = st
        key = tuple(sorted(state.items()))
        merged[key] = merged.get(key, 0.0) + (b - a)
    return [FaceBand(width=w, teeth=k) for k, w in merged.items()]


def body_faults(bands: list[FaceBand]) -> dict[tuple[str, int], set]:
    """``(which, tooth) -> {body keys}`` of the faulty bodies the bands need."""
    out: dict[tuple[str, int], set] = {}
    for band in bands:
        for key, st in band.teeth:
            if st.body is not None:
                out.setdefault(key, set()).add(st.body)
    return out


def check_fe_faults(faults, pair, refined_teeth: int) -> None:
    """Raise :class:`InputError` for a fault the FE method cannot model, naming its field.

    * wear with ``stiffness = true`` (the thinner tooth is not meshed; module docstring);
    * a breakage that leaves less than a tenth of the involute above the form circle
      (:func:`.mesh.check_cut`);
    * a crack whose tip leaves the tooth (:func:`.mesh.crack_segment`);
    * two faulty teeth of one gear (crack or breakage) closer than ``teeth_in_model``: each has
      its own body model loaded on ``teeth_in_model`` teeth around it, and two models sharing a
      loaded tooth would each miss the other's fault.
    """
    bodied = []
    for f in faults:
        if f.is_null():
            continue
        g = pair.pinion if f.gear == "pinion" else pair.gear
        if f.kind == "wear" and f.stiffness:
            raise InputError(f.field("stiffness"), True,
                             "false for the FE method (the worn layer, tens of micrometres, is "
                             "not meshed: the FE records wear as the gap fault_gap only), or "
                             "stiffness.method = 'pem'")
        if f.kind == "breakage":
            check_cut(g, g.tip_radius - f.height, f.field("height"))
        if f.kind == "root_crack":
            try:
                crack_segment(g, CrackGeometry(depth=float(f.depth), angle=float(f.angle)))
            except InputError as exc:
                raise InputError(f.field("depth"), f.depth, exc.allowed) from None
        if f.kind in ("root_crack", "breakage"):
            bodied.append(f)
    n = int(refined_teeth)
    for i, f in enumerate(bodied):
        z = (pair.pinion if f.gear == "pinion" else pair.gear).teeth
        for e in bodied[:i]:
            if e.gear != f.gear or e.tooth == f.tooth:
                continue
            d = abs(int(f.tooth) - int(e.tooth)) % z
            d = min(d, z - d)
            if d < n:
                raise InputError(f.field("tooth"), f.tooth,
                                 f"for the FE method a {f.gear} tooth at least "
                                 f"stiffness.fe.teeth_in_model = {n} teeth from tooth {e.tooth} "
                                 f"of {e.label} (each faulty tooth has its own body model loaded "
                                 f"on {n} teeth; two must not share one), or "
                                 "stiffness.method = 'pem'")


def _wrap(a):
    return (np.asarray(a) + math.pi) % (2 * math.pi) - math.pi


def pinion_corner(s, ua, rb1, rb2, t1t2):
    """Unloaded gap of a pinion corner at roll length ``ua`` against the gear flank, for pairs at
    LOA positions ``s > ua`` [m] (the tip-corner formula of :mod:`.contact` with the corner at
    ``ua``: a broken tooth's cut).

    Returns
    -------
    gap, u1, u2, arm : ndarray
        Gap [m], load points on the pinion (``ua``) and the gear [m], pinion lever arm [m].
    """
    s = np.asarray(s, float)
    o2x, o2y = rb1 + rb2, t1t2
    beta = (s - ua) / rb1
    cx = rb1 * np.cos(beta) + ua * (-np.sin(beta))
    cy = rb1 * np.sin(beta) + ua * np.cos(beta)
    vx, vy = cx - o2x, cy - o2y
    r = np.hypot(vx, vy)
    gam = np.arctan2(vy, vx) - np.arccos(rb2 / r)
    lam = np.sqrt(r * r - rb2 * rb2)
    g = lam + rb2 * _wrap(gam - math.pi) - (t1t2 - s)
    t2x = o2x + rb2 * np.cos(gam)
    t2y = o2y + rb2 * np.sin(gam)
    arm = np.abs(t2x * np.cos(gam) + t2y * np.sin(gam))
    return g, np.full(s.shape, float(ua)), lam - g, arm


def gear_corner(s, ua, rb1, rb2, t1t2):
    """Unloaded gap of a gear corner at roll length ``ua`` against the pinion flank, for pairs
    with ``T1T2 - s > ua`` [m] (the gear tip-corner formula of :mod:`.contact` with the corner at
    ``ua``).

    Returns
    -------
    gap, u1, u2, arm : ndarray
        As :func:`pinion_corner` (the lever arm is ``r_b1``: the contact normal is tangent to the
        pinion base circle).
    """
    s = np.asarray(s, float)
    o2x, o2y = rb1 + rb2, t1t2
    gn = t1t2 - s
    gam = math.pi + (gn - ua) / rb2
    cx = o2x + rb2 * np.cos(gam) + ua * (-np.sin(gam))
    cy = o2y + rb2 * np.sin(gam) + ua * np.cos(gam)
    r = np.hypot(cx, cy)
    beta = np.arctan2(cy, cx) - np.arccos(rb1 / r)
    lam = np.sqrt(r * r - rb1 * rb1)
    g = lam + rb1 * _wrap(beta) - s
    return g, lam - g, np.full(s.shape, float(ua)), np.full(s.shape, float(rb1))


def band_candidates(cand: Candidates, band: FaceBand, pair, dd: float) -> Candidates:
    """The candidates of one band: a broken tooth's contacts beyond its cut become contacts of
    the cut's corner; a spalled tooth's contacts inside the spall get :data:`REMOVED_GAP`.

    Works on candidates of one position (fields ``(n,)``) or of a block (``(p, n)``); without
    a cut or spall in the band ``cand`` itself is returned.
    """
    if not any(st.cut_radius is not None or st.spalls for _, st in band.teeth):
        return cand
    rb1, rb2 = pair.pinion.base_radius, pair.gear.base_radius
    t1t2 = pair.operating(dd, check=False).t1t2
    d = {k: np.array(getattr(cand, k), copy=True) for k in Candidates.__dataclass_fields__}
    for (which, tooth), st in band.teeth:
        teeth = d["pinion_tooth"] if which == "pinion" else d["gear_tooth"]
        on = teeth == tooth
        if st.cut_radius is not None:
            g = pair.pinion if which == "pinion" else pair.gear
            uc = math.sqrt(st.cut_radius ** 2 - g.base_radius ** 2)
            if which == "pinion":
                m = on & (d["s"] > uc)
                gap, u1, u2, arm = pinion_corner(d["s"][m], uc, rb1, rb2, t1t2)
                kind = PINION_TIP
            else:
                m = on & (t1t2 - d["s"] > uc)
                gap, u1, u2, arm = gear_corner(d["s"][m], uc, rb1, rb2, t1t2)
                kind = GEAR_TIP
            d["gap"][m], d["u1"][m], d["u2"][m], d["arm"][m] = gap, u1, u2, arm
            d["kind"][m] = kind
            rho1 = np.clip(u1, 1e-9, None)
            rho2 = np.clip(u2, 1e-9, None)
            d["radius"][m] = rho1 * rho2 / (rho1 + rho2)
        rb = (pair.pinion if which == "pinion" else pair.gear).base_radius
        for ua, ub in st.spalls:  # the spall's roll window, as Spall.width_lost
            roll = (d["u1"] if which == "pinion" else d["u2"]) / rb
            m = on & (roll >= ua) & (roll <= ub)
            d["gap"][m] = REMOVED_GAP
    return Candidates(**d)


def _first_contact(gap: np.ndarray, arm: np.ndarray) -> float:
    """Rotation at which the first pair of a band touches, ``min g_j / a_j`` [rad]."""
    return float(np.min(np.asarray(gap) / np.asarray(arm)))


def _rotation_for(width, k, theta0, torque) -> float:
    """``Delta theta`` with ``sum_s w_s k_s max(0, Delta theta - theta0_s) = T``."""
    order = np.argsort(theta0)
    num, den = float(torque), 0.0
    for i, s in enumerate(order):
        num += width[s] * k[s] * theta0[s]
        den += width[s] * k[s]
        th = num / den
        if i + 1 == order.size or th <= theta0[order[i + 1]]:
            return th
    raise NumericalError("no rotation carries the torque over the bands")  # pragma: no cover


def combine_bands(width, gaps, arms, solve, torque: float, *, tol: float = 1e-10,
                  max_iter: int = 100) -> tuple[np.ndarray, float, np.ndarray]:
    """Bands across the face in parallel under one pinion torque (module docstring).

    Parameters
    ----------
    width : sequence of float
        Band widths ``w_s`` [m].
    gaps, arms : sequence of ndarray
        Unloaded gaps [m] and pinion lever arms [m] of each band's candidates.
    solve : callable
        ``solve(s, tau) -> (force, rotation)``: band ``s`` under the torque per unit width
        ``tau`` [N m/m]; forces per unit width [N/m], rotation [rad].
    torque : float
        Pinion torque ``T`` [N m].
    tol : float
        Relative agreement of the bands' rotations [-].

    Returns
    -------
    force : ndarray, shape (bands, n)
        Contact forces per unit width of each band [N/m] (zero in a band carrying no torque).
    rotation : float
        Pinion hub rotation ``Delta theta`` [rad].
    tau : ndarray
        Torque per unit width of each band [N m/m].
    """
    w = np.asarray(width, float)
    nb = w.size
    if all(np.all(np.asarray(g) >= 0.5 * REMOVED_GAP) for g in gaps):
        raise NumericalError("no contact left in any band across the face",
                             state={"bands": nb})
    th0 = np.array([_first_contact(g, a) for g, a in zip(gaps, arms, strict=True)])
    never = np.array([np.all(np.asarray(g) >= 0.5 * REMOVED_GAP) for g in gaps])
    n = np.asarray(gaps[0]).size
    force = np.zeros((nb, n))
    rot = np.full(nb, np.nan)
    k = np.zeros(nb)
    tau = np.where(never, 0.0, torque / w[~never].sum())
    for s in np.nonzero(~never)[0]:
        force[s], rot[s] = solve(int(s), float(tau[s]))
        k[s] = tau[s] / (rot[s] - th0[s])
    use = ~never
    for _ in range(max_iter):
        th = _rotation_for(w[use], k[use], th0[use], torque)
        tau = np.zeros(nb)
        tau[use] = k[use] * np.maximum(th - th0[use], 0.0)
        ok = True
        for s in np.nonzero(use)[0]:
            if tau[s] > 0:
                force[s], rot[s] = solve(int(s), float(tau[s]))
                k[s] = tau[s] / (rot[s] - th0[s])
                ok &= abs(rot[s] - th) <= tol * abs(th)
            else:
                force[s] = 0.0
        if ok:
            return force, float(th), tau
    raise NumericalError("the bands across the face did not reach one rotation",
                         state={"rotation": float(th), "band_rotations": rot.tolist()})


def fault_gap(pair, faults, theta, dd: float) -> np.ndarray:
    """Worn gap of each load-share slot's pair [m], shape ``(n, 3)``: the PEM's ``fault_gap``
    (:meth:`geardyn.stiffness.pem.fault_model.FaultPEMModel.evaluate`), the same geometry.

    Slot ``k`` holds pair ``n_exit + 1 + k`` (:attr:`geardyn.stiffness.StiffnessMap.slot_tooth`);
    a pair off the theoretical path has no gap.
    """
    theta = np.atleast_1d(np.asarray(theta, float))
    op = pair.operating(float(dd), check=False)
    rb1, rb2, pb = pair.pinion.base_radius, pair.gear.base_radius, pair.base_pitch
    s_theta = pair.pitch_point_s + rb1 * theta
    n_exit = np.floor((s_theta - op.s_end) / pb).astype(np.int64)
    n = n_exit[:, None] + 1 + np.arange(3)[None, :]
    s = s_theta[:, None] - n * pb
    tol = 1e-12
    inc = (s >= op.s_start - tol) & (s <= op.s_end + tol)
    roll = {"pinion": np.where(inc, s / rb1, np.nan),
            "gear": np.where(inc, (op.t1t2 - s) / rb2, np.nan)}
    tooth = {"pinion": np.mod(n, pair.pinion.teeth), "gear": np.mod(n, pair.gear.teeth)}
    gap = np.zeros(s.shape)
    for f in faults:
        if f.kind != "wear" or f.is_null():
            continue
        m = inc & (tooth[f.gear] == f.tooth)
        if np.any(m):
            gap[m] += f.deviation(roll[f.gear][m])
    return np.where(inc, gap, 0.0)
