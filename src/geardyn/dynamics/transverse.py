r"""The transverse model: each gear on x-y bearings, the mesh force along the *operating* line of
action, sliding friction along the teeth; the paper's 6-DOF model is its special case.

Degrees of freedom (SI): ``[theta_m, x_p, y_p, theta_p, x_g, y_g, theta_g, theta_out]``
[rad, m, m, rad, m, m, rad, rad]: the 6-DOF model of :mod:`geardyn.dynamics.model` plus the
displacement ``x`` of each centre perpendicular to the design line of action (eight DOFs; the
issue text's "10 DOF" counts two more than there are). ``y`` is along the design line of action
as in the paper, ``x`` across it, from the pinion's centre towards its base tangent point ``T1``
(the direction ``n`` of ``O1 -> T1`` at the design point; the gear's centre lies at ``+r_sum``
along ``x``).

Geometry of the operating line of action (derived here)
-------------------------------------------------------
With the centre-to-centre vector ``D = (r_sum + x_g - x_p, T1T2 + y_g - y_p)`` (``r_sum =
r_b1 + r_b2``, ``T1T2`` the design length between the tangent points), the line of action is the
internal common tangent of the base circles: its normal ``n`` satisfies ``D . n = r_sum``, so in
the frame ``(n, t)`` turned by ``phi`` from ``(x, y)``

.. math:: D = r_{sum}\, n + \tau\, t, \qquad \tau = \sqrt{d^2 - r_{sum}^2}, \qquad
          \varphi = \operatorname{atan2}(D_y, D_x) - \operatorname{atan2}(\tau, r_{sum}).

``tau`` is the operating ``T1T2`` and ``arccos(r_sum / d)`` the operating pressure angle of the
paper's eq. 6, now following the instantaneous centres. An involute meets the line of action at
the roll length ``r_b (theta - phi)`` from its tangent point (the string unwinds from the turned
tangent point), so the approach of the flanks along the line is

.. math:: p = r_{b1}\theta_p - r_{b2}\theta_g - r_{sum}\varphi - \tau + T1T2

(eq. 15 of the paper when ``x = 0``: then ``phi = 0`` and ``tau = T1T2 + y_g - y_p``). Its
gradient is exact and simple: ``dp/dD = -(r_sum D_perp + tau D) / d^2 = -t``, so by virtual work
the normal force acts along the *turned* line, ``-N t`` on the pinion's centre and ``+N t`` on
the gear's, with the torques ``-N r_b1`` and ``+N r_b2``. To first order ``p`` does not depend on
``x`` (``phi ~ -dx / T1T2`` and ``tau ~ T1T2 + (r_sum/T1T2) dx + dy`` cancel): moving a centre
across the line of action turns the line, it does not load the teeth. The map is read at the
pinion's roll relative to the turned line, ``theta_p - phi``, and (model II) at ``d - d_0``.

Sliding friction (Coulomb, derived here)
----------------------------------------
A pair in contact at roll length ``s`` from ``T1`` (``tau - s`` from ``T2``) slides with the
velocity ``v_s = -omega_p s + omega_g (tau - s)`` of the pinion's flank relative to the gear's
along ``n`` (``omega_g`` positive in the driven direction), zero at the pitch point
``s_pitch = tau r_b1 / r_sum``. The friction ``mu N_k`` opposes it: on the pinion
``-mu N_k sg_k n`` at the contact point, on the gear ``+mu N_k sg_k n``, ``sg_k = sign(s_pitch -
s_k)`` (the sign changes at the pitch point; the position decides it, not the velocity, so that a
slow or stopped gear does not chatter), with the moments ``+mu N_k sg_k s_k`` on the pinion and
``-mu N_k sg_k (tau - s_k)`` on the gear (in the driven direction). ``N_k = w_k N`` shares the
normal load by the map's load shares (equal shares when the map has none). In each time step the
terms are averaged over the step's roll, split where a pair enters or leaves contact or crosses
the pitch point, as the stiffness is (the scheme keeps order 2). Its power is ``-mu N_k |v_s|``
at the steady speeds: it dissipates. When the centres vibrate across the line of action, their
velocity adds to ``v_s``; near the pitch point, where the rolling part is small, the
position-decided sign can then make the friction do positive work (a velocity-decided,
regularised Coulomb law would not; it is not built). The off-line-of-action force
``mu N sum w_k sg_k`` loads the bearings across the line of action, where only this model has a
degree of freedom.

Sources
-------
Xue & Howard (2018) eqs. 4, 6, 9-17 (the 6-DOF model this one contains). The friction model is
the Coulomb law with the kinematic sign change at the pitch point used by the gear-dynamics
literature (Howard, Jia & Wang 2001, MSSP 15(5); Vaishya & Singh 2001, JSV 243(3)); neither paper
could be read here (not found by the search tool), so the formulas above are derived from the
involute kinematics and checked against a hand calculation, an explicit involute construction, the
energy audit and scipy's DOP853 (``tests/dynamics/test_transverse.py``), not against their
equations.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..stiffness.map import MapArrays, StiffnessMap
from . import _kernel as K
from . import _transverse_kernel as T
from .model import DynamicModel, check_time_step, static_equilibrium

__all__ = ["TransverseModel", "line_of_action", "mesh_deflection", "friction_terms",
           "generalised_mesh_force", "simulate_transverse", "DOF_NAMES"]

#: DOF names of the transverse model, in order.
DOF_NAMES = ("theta_m", "x_p", "y_p", "theta_p", "x_g", "y_g", "theta_g", "theta_out")
#: 6-DOF index -> transverse index
_EMBED = np.array([0, 2, 3, 5, 6, 7])


# ----------------------------------------------------------------------------- geometry (NumPy)
def line_of_action(x_p, y_p, x_g, y_g, rsum: float, t1t2: float):
    """Operating centre distance, ``T1T2`` and turn of the line of action.

    Parameters
    ----------
    x_p, y_p, x_g, y_g : float or array_like
        Centre displacements [m] (``x`` across, ``y`` along the design line of action).
    rsum, t1t2 : float
        ``r_b1 + r_b2`` and the design ``T1T2`` [m].

    Returns
    -------
    d, tau, phi : ndarray
        Centre distance [m], operating ``T1T2`` [m], turn of the line of action [rad].
    """
    dx = rsum + np.asarray(x_g, float) - np.asarray(x_p, float)
    dy = t1t2 + np.asarray(y_g, float) - np.asarray(y_p, float)
    d = np.hypot(dx, dy)
    tau = np.sqrt(np.maximum(d * d - rsum * rsum, 0.0))
    phi = np.arctan2(dy, dx) - np.arctan2(tau, rsum)
    return d, tau, phi


def mesh_deflection(theta_p, theta_g, x_p, y_p, x_g, y_g, r_b1: float, r_b2: float,
                    t1t2: float):
    """Exact approach of the flanks along the operating line of action [m] (module text).

    Angles are the deviations from the rigid rotation (or any pair with ``r_b1 theta_p =
    r_b2 theta_g`` at zero approach) [rad]; displacements [m].
    """
    rsum = r_b1 + r_b2
    _, tau, phi = line_of_action(x_p, y_p, x_g, y_g, rsum, t1t2)
    return r_b1 * np.asarray(theta_p, float) - r_b2 * np.asarray(theta_g, float) \
        - rsum * phi - tau + t1t2


def friction_terms(s, shares, tau: float, r_b1: float, r_b2: float, mu: float
                   ) -> tuple[float, float, float]:
    """Friction per unit normal load ``(m_f, A_1, A_2)`` of the pairs at roll lengths ``s``.

    Parameters
    ----------
    s : array_like
        Roll lengths of the pairs in contact from ``T1`` [m].
    shares : array_like
        Their load shares (any positive scale; normalised to sum 1) [-].
    tau : float
        Operating ``T1T2`` [m].
    r_b1, r_b2 : float
        Base radii [m].
    mu : float
        Coefficient of friction [-].

    Returns
    -------
    m_f : float
        ``mu sum w_k sg_k``: the friction force on the gear along ``n`` per unit ``N`` [-],
        ``sg_k = sign(s_pitch - s_k)``.
    A_1, A_2 : float
        ``mu sum w_k sg_k s_k`` and ``mu sum w_k sg_k (tau - s_k)``: friction moments on the
        pinion and (against the driven direction) the gear per unit ``N`` [m].
    """
    s = np.atleast_1d(np.asarray(s, float))
    w = np.atleast_1d(np.asarray(shares, float))
    if mu == 0.0 or s.size == 0 or not w.sum() > 0:
        return 0.0, 0.0, 0.0
    w = w / w.sum()
    sg = np.sign(tau * r_b1 / (r_b1 + r_b2) - s)
    return (float(mu * np.sum(w * sg)), float(mu * np.sum(w * sg * s)),
            float(mu * np.sum(w * sg * (tau - s))))


def generalised_mesh_force(normal_force: float, phi: float, r_b1: float, r_b2: float,
                           m_f: float, a_1: float, a_2: float) -> np.ndarray:
    """Generalised forces of the mesh on ``(x_p, y_p, theta_p, x_g, y_g, theta_g)``.

    ``-N b`` with ``b = g - f`` (module text): the normal force along the turned line of action
    plus the friction across it and its moments [N, N, N m, N, N, N m].
    """
    t = np.array([-math.sin(phi), math.cos(phi)])
    n = np.array([math.cos(phi), math.sin(phi)])
    N = normal_force
    f_p = -N * t - N * m_f * n
    return np.array([f_p[0], f_p[1], -N * r_b1 + N * a_1, -f_p[0], -f_p[1],
                     N * r_b2 - N * a_2])


# ----------------------------------------------------------------------------- the model
@dataclass(frozen=True)
class TransverseModel:
    """The transverse model's matrices (SI), built on the 6-DOF model of the same case.

    Attributes
    ----------
    base : DynamicModel
        The 6-DOF model (laws, damping, speeds, mesh damping).
    M, K0, C0 : ndarray, shape (n, n)
        Mass, stiffness without the mesh and damping without the mesh, ``n = 8`` (``6`` with the
        centres held on the line of action) [SI].
    g0 : ndarray, shape (n,)
        Mesh vector at the design point (``phi = 0``).
    index : dict
        DOF index of ``x_p, y_p, theta_p, x_g, y_g, theta_g, theta_out`` (``-1``: held).
    friction_coefficient : float
        Coulomb coefficient ``mu`` [-].
    x_free : bool
        Whether the centres move across the line of action.
    bearing_x : dict
        ``k_xp, k_xg`` [N/m] and ``q_xp, q_xg`` [N s/m] (empty when ``x`` is held).
    """

    base: DynamicModel
    M: np.ndarray
    K0: np.ndarray
    C0: np.ndarray
    g0: np.ndarray
    index: dict
    friction_coefficient: float
    x_free: bool
    bearing_x: dict

    @property
    def names(self) -> tuple[str, ...]:
        """DOF names in order."""
        if self.x_free:
            return DOF_NAMES
        return ("theta_m", "y_p", "theta_p", "y_g", "theta_g", "theta_out")

    @property
    def reference_direction(self) -> np.ndarray:
        """The rigid rotation ``e`` (``K0 e = 0``, ``g0 e = 0``)."""
        e6 = self.base.reference_direction
        if not self.x_free:
            return e6
        e = np.zeros(8)
        e[_EMBED] = e6
        return e

    @classmethod
    def from_case(cls, case, stiffness_map, *, x_free: bool = True) -> TransverseModel:
        """Build the model of ``case`` (``x_free=False`` holds the centres on the line of action,
        the paper's 6-DOF model with friction torques)."""
        base = DynamicModel.from_case(case, stiffness_map)
        mu = float(case.mesh.friction_coefficient)
        if not x_free:
            idx = {"x_p": -1, "y_p": 1, "theta_p": 2, "x_g": -1, "y_g": 3, "theta_g": 4,
                   "theta_out": 5}
            return cls(base=base, M=base.M.copy(), K0=base.K0.copy(), C0=base.C0.copy(),
                       g0=base.g.copy(), index=idx, friction_coefficient=mu, x_free=False,
                       bearing_x={})
        M = np.zeros((8, 8))
        K0 = np.zeros((8, 8))
        C0 = np.zeros((8, 8))
        M[np.ix_(_EMBED, _EMBED)] = base.M
        K0[np.ix_(_EMBED, _EMBED)] = base.K0
        C0[np.ix_(_EMBED, _EMBED)] = base.C0
        bx = {}
        for name, gc, i in (("p", case.pinion, 1), ("g", case.gear, 4)):
            kx = gc.bearing_stiffness_x if gc.bearing_stiffness_x is not None \
                else gc.bearing_stiffness
            if gc.bearing_damping_x is not None:
                qx = gc.bearing_damping_x
            elif gc.bearing_damping is not None and gc.bearing_stiffness_x is None:
                qx = gc.bearing_damping
            else:
                qx = 2.0 * gc.bearing_damping_ratio * math.sqrt(kx * gc.mass)
            M[i, i] = gc.mass
            K0[i, i] = kx
            C0[i, i] = qx
            bx[f"k_x{name}"], bx[f"q_x{name}"] = float(kx), float(qx)
        g0 = np.zeros(8)
        g0[_EMBED] = base.g
        idx = {"x_p": 1, "y_p": 2, "theta_p": 3, "x_g": 4, "y_g": 5, "theta_g": 6,
               "theta_out": 7}
        return cls(base=base, M=M, K0=K0, C0=C0, g0=g0, index=idx, friction_coefficient=mu,
                   x_free=True, bearing_x=bx)

    def embed(self, z6: np.ndarray) -> np.ndarray:
        """A 6-DOF vector in this model's order (``x = 0``)."""
        if not self.x_free:
            return np.asarray(z6, float).copy()
        z = np.zeros(8)
        z[_EMBED] = z6
        return z


# ----------------------------------------------------------------------------- kernel set-up
@dataclass
class TransverseSetup:
    """Everything :func:`~geardyn.dynamics._transverse_kernel.advance_transverse` needs."""

    model: TransverseModel
    M: np.ndarray
    K0: np.ndarray
    C: np.ndarray
    Q0: np.ndarray
    Sinv: np.ndarray
    SK: np.ndarray
    SC: np.ndarray
    sQ: np.ndarray
    g0: np.ndarray
    u0: np.ndarray
    fp: np.ndarray
    ip: np.ndarray
    tfp: np.ndarray
    tip: np.ndarray
    map_arrays: MapArrays
    shares: np.ndarray
    in_table: tuple
    out_table: tuple
    speed_profile: tuple
    #: the 6-DOF set-up of the same case (time step, laws, map view; the record's metadata)
    base_setup: object = None

    def args(self) -> tuple:
        """The kernel arguments after ``fail``."""
        m = self.map_arrays
        return (self.M, self.K0, self.C, self.Q0, self.Sinv, self.SK, self.SC, self.sQ,
                self.g0, self.u0, self.fp, self.ip, self.tfp, self.tip,
                m.dd0, m.ddd, m.phase_a, m.length_a, m.mesh_angle, m.n_cycles, m.n_seg, m.values,
                self.shares, self.in_table[0], self.in_table[1], self.out_table[0],
                self.out_table[1], *self.speed_profile, *self.base_setup.excitation[:4])

    @property
    def nd(self) -> int:
        """Number of DOFs."""
        return int(self.M.shape[0])


def _refuse_unsupported(case) -> None:
    """Features of the 6-DOF kernel the transverse kernel does not have yet: a clear error."""
    if case.stiffness.method == "fe" and case.stiffness.fe.torques is not None:
        raise InputError("stiffness.fe.torques", list(case.stiffness.fe.torques),
                         "omitted with simulation.dynamics = 'transverse' (maps at several loads "
                         "are read by the 6-DOF kernel only)")
    if case.simulation.integrator != "newmark":
        raise InputError("simulation.integrator", case.simulation.integrator,
                         "'newmark' with simulation.dynamics = 'transverse' (HHT-alpha is "
                         "implemented for the 6-DOF model only)")


def make_transverse_setup(case, tm: TransverseModel, stiffness_map: StiffnessMap, which: str,
                          static) -> TransverseSetup:
    """Kernel arrays of the transverse model of ``case`` (model ``which``) from its static
    state; the time step, tolerances, laws, ripple, drive and the map's view (model I-static)
    are the 6-DOF model's (:func:`geardyn.dynamics.newmark._setup_for_case`)."""
    from .newmark import _setup_for_case

    s6 = _setup_for_case(case, tm.base, stiffness_map, which, static)
    io = tm.index["theta_out"]
    C = tm.C0.copy()
    C[0, 0] = s6.C[0, 0]  # load-law slope and drive gain at the motor
    C[io, io] = s6.C[5, 5]
    Q0 = tm.embed(s6.Q0)
    dt = s6.dt
    beta, gamma = float(s6.fp[K.FP_BETA]), float(s6.fp[K.FP_GAMMA])
    S = tm.M + gamma * dt * C + beta * dt * dt * tm.K0
    Sinv = np.ascontiguousarray(np.linalg.inv(S))
    u0 = Sinv @ tm.g0
    pair = tm.base.pair
    op = pair.operating(0.0, check=False)
    tfp = np.zeros(T.N_TFP)
    tfp[T.TF_RB1], tfp[T.TF_RB2] = tm.base.r_b1, tm.base.r_b2
    tfp[T.TF_MU] = tm.friction_coefficient
    tfp[T.TF_PITCH_S], tfp[T.TF_S_END], tfp[T.TF_PB] = pair.pitch_point_s, op.s_end, \
        pair.base_pitch
    tfp[T.TF_U2TIP] = op.t1t2 - op.s_start
    tfp[T.TF_SIGMA0] = tm.g0 @ u0
    tfp[T.TF_UNORM] = math.sqrt(u0 @ tm.M @ u0)
    tip = np.zeros(T.N_TIP, dtype=np.int64)
    for key, name in ((T.TI_XP, "x_p"), (T.TI_YP, "y_p"), (T.TI_THP, "theta_p"),
                      (T.TI_XG, "x_g"), (T.TI_YG, "y_g"), (T.TI_THG, "theta_g"),
                      (T.TI_OUT, "theta_out")):
        tip[key] = tm.index[name]
    tip[T.TI_XFREE] = int(tm.x_free)
    if "load_share" in getattr(stiffness_map, "extra", {}):
        shares = np.ascontiguousarray(np.moveaxis(np.asarray(stiffness_map.extra["load_share"],
                                                             float), -1, 0))
        tip[T.TI_SHARES] = 1
    else:
        shares = np.zeros((3, 1, 1))
    return TransverseSetup(
        model=tm, M=np.ascontiguousarray(tm.M), K0=np.ascontiguousarray(tm.K0),
        C=np.ascontiguousarray(C), Q0=Q0, Sinv=Sinv, SK=np.ascontiguousarray(Sinv @ tm.K0),
        SC=np.ascontiguousarray(Sinv @ C), sQ=np.ascontiguousarray(Sinv @ Q0),
        g0=np.ascontiguousarray(tm.g0), u0=np.ascontiguousarray(u0), fp=s6.fp.copy(),
        ip=s6.ip.copy(), tfp=tfp, tip=tip, map_arrays=s6.map_arrays, shares=shares,
        in_table=s6.in_table, out_table=s6.out_table, speed_profile=s6.speed_profile,
        base_setup=s6)


def initial_transverse_state(setup: TransverseSetup, z0) -> tuple[np.ndarray, np.ndarray]:
    """State at step 0 with deviations ``z0`` (in the model's order), at rest relative to the
    reference rotation; the acceleration from the equations of motion."""
    from ..stiffness.map import lookup_reference

    tm = setup.model
    nd = setup.nd
    z0 = np.asarray(z0, float)
    idx = tm.index
    fp = setup.fp
    rsum, t1t2 = fp[K.FP_RSUM], fp[K.FP_T1T2]
    xp = z0[idx["x_p"]] if tm.x_free else 0.0
    xg = z0[idx["x_g"]] if tm.x_free else 0.0
    d, tau, phi = (float(v) for v in line_of_action(xp, z0[idx["y_p"]], xg, z0[idx["y_g"]],
                                                    rsum, t1t2))
    if not tm.x_free:
        phi = 0.0
    model2 = setup.ip[K.IP_MODEL] == 2
    dd = d - fp[K.FP_D0] if model2 else 0.0
    th = z0[idx["theta_p"]] - phi
    m = setup.map_arrays
    k0 = float(lookup_reference(np.array(th), np.array(dd), m))
    if np.isnan(k0):
        raise InputError("stiffness_map", f"range [{m.dd0:.6g}, "
                         f"{m.dd0 + m.ddd * (m.values.shape[0] - 1):.6g}] m",
                         f"a map covering the initial centre distance change {dd:.6g} m")
    if tm.x_free:
        p0 = float(mesh_deflection(z0[idx["theta_p"]], z0[idx["theta_g"]], xp, z0[idx["y_p"]],
                                   xg, z0[idx["y_g"]], tm.base.r_b1, tm.base.r_b2, t1t2))
    else:
        p0 = float(setup.g0 @ z0)
    h0 = 0.0 if (setup.ip[K.IP_SEP] and p0 < 0) else 1.0
    ebar = 0.0
    eip, efp, etp, etg, els = setup.base_setup.excitation
    if eip[K.EI_ACTIVE] == 1:  # tooth errors (geardyn.modifications), as the 6-DOF start
        d_e = d if model2 else fp[K.FP_D0]
        th_k, ebar, frac, h0 = K._excite_py(th, z0[idx["theta_p"]] - phi, d_e, rsum, dd, p0,
                                            bool(setup.ip[K.IP_SEP]), eip, efp, etp, etg, els,
                                            m)
        k0 = float(lookup_reference(np.array(th_k), np.array(dd), m)) * frac
        th = th_k
    n0 = h0 * k0 * (p0 - ebar)
    m_f, a_1, a_2 = _friction_at(setup, th, tau, dd)
    gen = generalised_mesh_force(n0, phi, tm.base.r_b1, tm.base.r_b2, m_f, a_1, a_2)
    f = setup.Q0 - setup.K0 @ z0
    for i, name in enumerate(("x_p", "y_p", "theta_p", "x_g", "y_g", "theta_g")):
        if idx[name] >= 0:
            f[idx[name]] += gen[i]
    rip = 0.0
    if fp[K.FP_RIP_AMP] != 0.0 or fp[K.FP_DRIVE_GAIN] != 0.0:
        rip = float(K._input_forcing(fp, 0, *setup.speed_profile))
        f[0] += rip
    a0 = np.linalg.solve(setup.M, f)
    _, _, _, s_sc, n_state = T.state_layout(nd)
    st = np.zeros(n_state)
    st[:nd], st[2 * nd:3 * nd] = z0, a0
    sc = st[s_sc:]
    sc[T.SC_N], sc[T.SC_K], sc[T.SC_H], sc[T.SC_DD] = n0, k0, h0, d - fp[K.FP_D0]
    sc[T.SC_RB], sc[T.SC_RA], sc[T.SC_RIP] = np.nan, np.nan, rip
    sc[T.SC_PHI], sc[T.SC_MF], sc[T.SC_A1], sc[T.SC_A2], sc[T.SC_P] = phi, m_f, a_1, a_2, p0
    sc[T.SC_E] = ebar
    return st, np.array([0, 0], dtype=np.int64)


def _friction_at(setup: TransverseSetup, th: float, tau: float, dd: float):
    from ..stiffness.map import lookup_reference

    tfp = setup.tfp
    mu = float(tfp[T.TF_MU])
    if mu == 0.0:
        return 0.0, 0.0, 0.0
    rb1, pb = tfp[T.TF_RB1], tfp[T.TF_PB]
    s_th = tfp[T.TF_PITCH_S] + rb1 * th
    n_exit = math.floor((s_th - tfp[T.TF_S_END]) / pb)
    s = s_th - (n_exit + 1 + np.arange(3)) * pb
    inc = s >= tau - tfp[T.TF_U2TIP] - 1e-12
    if setup.tip[T.TI_SHARES] == 1:
        m = setup.map_arrays
        sh = np.array([float(lookup_reference(np.array(th), np.array(dd),
                                              m._replace(values=setup.shares[k])))
                       for k in range(3)])
    else:
        sh = np.ones(3)
    return friction_terms(s[inc], sh[inc], tau, rb1, tfp[T.TF_RB2], mu)


def run_transverse_steps(setup: TransverseSetup, st, ist, n_steps: int, *, rec_start: int = 0,
                         decim: int = 1, out=None, j: int = 0, python: bool = False):
    """Advance ``st`` by ``n_steps`` steps with the kernel (or its twin); ``(status, j, fail)``."""
    if out is None:
        out = np.empty((0, T.record_layout(setup.nd)[3]))
    fail = np.full(K.N_FAIL, np.nan)
    if python:
        from ._transverse_twin import advance_transverse_python as fn
    else:
        fn = T.advance_transverse
    status, j = fn(int(n_steps), int(rec_start), int(decim), out, int(j), st, ist, fail,
                   *setup.args())
    return int(status), int(j), fail


# ----------------------------------------------------------------------------- simulate
def simulate_transverse(case, stiffness_map: StiffnessMap | None = None, *,
                        model: str | None = None, x_free: bool = True, cracked: bool = True,
                        progress: Callable[[int, int], None] | None = None, python: bool = False):
    r"""Simulate the transverse model of a case (``simulation.dynamics = "transverse"``).

    Parameters
    ----------
    case : geardyn.config.Case
    stiffness_map : StiffnessMap, optional
        Default ``geardyn.stiffness.build_map(case, cracked=cracked)``.
    model : {"I", "I-static", "II"}, optional
        Where the map is read, as in :func:`geardyn.dynamics.simulate`; the line of action turns
        with the centres in every model.
    x_free : bool
        ``False`` holds the centres on the design line of action (the paper's 6-DOF model, plus
        the friction moments when ``mesh.friction_coefficient > 0``).
    cracked : bool
        Passed to ``build_map`` when no map is given.
    progress : callable, optional
        ``progress(steps_done, steps_total)``.
    python : bool
        Run the pure-Python twin (tests; about 100 times slower).

    Returns
    -------
    xarray.Dataset
        The variables of :func:`geardyn.dynamics.simulate` (``mesh_deflection`` is the exact
        approach along the operating line of action; ``centre_distance_change`` and
        ``pressure_angle`` follow both centre coordinates) plus ``x_p``, ``x_g`` [m], ``v_xp``,
        ``v_xg`` [m/s], ``line_of_action_angle`` [rad], ``friction_force`` [N] (on the gear,
        along the normal ``n``), ``friction_torque_pinion``, ``friction_torque_gear`` [N m] and
        ``friction_power`` [W] (negative: dissipated); attribute ``dynamics = "transverse"``.

    Raises
    ------
    InputError, NumericalError
        As :func:`geardyn.dynamics.simulate`; also HHT or a load family with this model.
    """
    from .newmark import (
        CHUNK_STEPS,
        _start_with_errors,
        case_arithmetic,
        check_arguments,
        check_bounded_work,
        drive_chunks,
        raise_with_partial,
        record_plan,
    )

    which = check_arguments(case, stiffness_map, model)  # a model name in any case
    check_bounded_work(case)
    _refuse_unsupported(case)
    if stiffness_map is None:
        from ..stiffness import build_map

        stiffness_map = build_map(case, cracked=cracked)
    sim = case.simulation
    with case_arithmetic(case):
        tm = TransverseModel.from_case(case, stiffness_map, x_free=x_free)
        check_time_step(tm.base, stiffness_map, sim.dt)
        _check_x_modes(tm, sim.dt)
        static = static_equilibrium(tm.base, stiffness_map, which=which)
        setup = make_transverse_setup(case, tm, stiffness_map, which, static)
    n_settle, decim, count, n_last = record_plan(sim)
    out = np.full((count, T.record_layout(setup.nd)[3]), np.nan)
    st, ist = initial_transverse_state(setup, tm.embed(
        _start_with_errors(setup.base_setup, tm.base, static)))
    rows = [0]

    def step(n: int):
        status, rows[0], fail = run_transverse_steps(setup, st, ist, n, rec_start=n_settle,
                                                     decim=decim, out=out, j=rows[0],
                                                     python=python)
        return status, fail

    def record(complete: bool):
        return transverse_dataset(case, setup, stiffness_map, which, static, out[:rows[0]],
                                  n_settle, decim, complete=complete)

    status, fail = drive_chunks(step, ist, n_last, chunk=CHUNK_STEPS if not python else 2000,
                                progress=progress)
    if status != K.OK:
        raise_with_partial(status, fail, which, static, stiffness_map, record)
    return record(True)


def _check_x_modes(tm: TransverseModel, dt: float) -> None:
    """The x bearing modes need the same resolution as the others (``model.check_time_step``)."""
    from .model import MIN_STEPS_PER_PERIOD

    for name in ("p", "g"):
        k = tm.bearing_x.get(f"k_x{name}")
        if k is None:
            continue
        m = tm.M[1, 1] if name == "p" else tm.M[4, 4]
        f = math.sqrt(k / m) / (2 * math.pi)
        if dt * f * MIN_STEPS_PER_PERIOD > 1.0:
            raise InputError("simulation.dt", dt,
                             f"<= {1.0 / (MIN_STEPS_PER_PERIOD * f):.3g} s: the {name} bearing "
                             f"mode across the line of action ({f:.4g} Hz) needs "
                             f"{MIN_STEPS_PER_PERIOD} steps a period")


def transverse_dataset(case, setup: TransverseSetup, stiffness_map: StiffnessMap, which: str,
                       static, rows: np.ndarray, n_settle: int, decim: int, complete: bool):
    """The record as an :class:`xarray.Dataset`: the 6-DOF record's variables and metadata
    (:func:`geardyn.dynamics.newmark._dataset`) plus the transverse ones."""
    from .newmark import _dataset, owning

    tm = setup.model
    nd = setup.nd
    r_z, r_v, r_sc, _ = T.record_layout(nd)
    idx = tm.index
    six = [0, idx["y_p"], idx["theta_p"], idx["y_g"], idx["theta_g"], idx["theta_out"]]
    rows6 = np.full((rows.shape[0], K.N_REC), np.nan)
    rows6[:, K.R_Z:K.R_Z + 6] = rows[:, [r_z + i for i in six]]
    rows6[:, K.R_V:K.R_V + 6] = rows[:, [r_v + i for i in six]]
    for rk, rt in ((K.R_N, T.RC_N), (K.R_DD, T.RC_DD), (K.R_K, T.RC_K), (K.R_H, T.RC_H),
                   (K.R_IT, T.RC_IT), (K.R_RB, T.RC_RB), (K.R_RA, T.RC_RA)):
        rows6[:, rk] = rows[:, r_sc + rt]
    rows6[:, K.R_E] = rows[:, r_sc + T.RC_E]
    ds = _dataset(case, tm.base, stiffness_map, which, static, setup.base_setup, rows6,
                  n_settle, decim, complete)
    ds["mesh_deflection"] = ("time", rows[:, r_sc + T.RC_P], {
        "units": "m", "long_name": "mesh deflection: approach of the flanks along the operating "
                                   "line of action (transverse model; eq. 15 when x = 0)"})
    t = ds.time
    if tm.x_free:
        for name, i, units, long in (
                ("x_p", idx["x_p"], "m", "pinion centre displacement across the design line "
                                         "of action"),
                ("x_g", idx["x_g"], "m", "gear centre displacement across the design line of "
                                         "action")):
            ds[name] = ("time", rows[:, r_z + i], {"units": units, "long_name": long})
        ds["v_xp"] = ("time", rows[:, r_v + idx["x_p"]], {
            "units": "m/s", "long_name": "pinion centre velocity across the line of action"})
        ds["v_xg"] = ("time", rows[:, r_v + idx["x_g"]], {
            "units": "m/s", "long_name": "gear centre velocity across the line of action"})
    phi = rows[:, r_sc + T.RC_PHI]
    N = rows[:, r_sc + T.RC_N]
    mf, a1, a2 = (rows[:, r_sc + c] for c in (T.RC_MF, T.RC_A1, T.RC_A2))
    ds["line_of_action_angle"] = ("time", phi, {
        "units": "rad", "long_name": "turn phi of the operating line of action from the design "
                                     "one (follows the centres)"})
    ds["friction_force"] = ("time", N * mf, {
        "units": "N", "long_name": "sliding friction force on the gear along the normal n of the "
                                   "line of action (minus on the pinion)"})
    ds["friction_torque_pinion"] = ("time", N * a1, {
        "units": "N m", "long_name": "friction moment on the pinion (positive: in its direction "
                                     "of rotation)"})
    ds["friction_torque_gear"] = ("time", N * a2, {
        "units": "N m", "long_name": "friction moment on the gear against its direction of "
                                     "rotation"})
    n_vec = np.stack([np.cos(phi), np.sin(phi)])
    vx_p = ds["v_xp"].values if tm.x_free else 0.0
    vx_g = ds["v_xg"].values if tm.x_free else 0.0
    vp = np.stack([np.broadcast_to(vx_p, phi.shape), ds["v_yp"].values])
    vg = np.stack([np.broadcast_to(vx_g, phi.shape), ds["v_yg"].values])
    power = N * (mf * ((vg - vp) * n_vec).sum(0) + a1 * ds["omega_p"].values
                 - a2 * ds["omega_g"].values)
    ds["friction_power"] = ("time", power, {
        "units": "W", "long_name": "power of the sliding friction on both gears (negative: "
                                   "dissipated)"})
    ds.attrs.update({
        "title": f"geardyn transverse model {which} simulation of case {case.name!r}",
        "dynamics": "transverse",
        "centres": "x and y free" if tm.x_free else "held on the design line of action (x = 0)",
        "friction_coefficient": float(tm.friction_coefficient),
        "friction_coefficient_units": "1",
        "friction_rule": "Coulomb, mu N_k per pair by the map's load shares (equal without "
                         "them), sign changes at the pitch point, averaged over the step's roll",
    })
    for key, val in tm.bearing_x.items():
        ds.attrs[f"bearing_{key}"] = val
        ds.attrs[f"bearing_{key}_units"] = "N/m" if key.startswith("k") else "N s/m"
    del t
    return owning(ds)
