r"""Time integration of model I / I-static / II (Xue & Howard 2018, section 4 and Fig. 7).

:func:`simulate` runs a case: static equilibrium at the steady speed, ``settle_time`` discarded,
``record_time`` recorded every ``decimation``-th step, all inside the compiled kernel of
:mod:`geardyn.dynamics._kernel` called in chunks (progress is reported between chunks; there is
no Python call per step). :func:`make_setup`, :func:`initial_state` and :func:`run_steps` expose
the same kernel for any 6-DOF ``M``, ``K0``, ``C``, ``g`` (the tests use them for single-DOF
oscillators with closed-form solutions).

The algorithm, the stiffness evaluation point, the model II iteration and the tooth separation
rule are described in :mod:`geardyn.dynamics._kernel`.

Model I-static is model I run on the map's ``dd`` axis shifted by the static centre distance
change ``dd_s`` of eq. 4 (:func:`fixed_distance_arrays`): the kernel's model I evaluates that map
at ``dd = 0``, i.e. ``K(theta, dd_s)``, and takes ``d + dd_s`` as the centre distance of the
tooth-error contact geometry. The kernel itself knows only models I and II.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from ..errors import GeardynError, InputError, NumericalError, check_flag
from ..run_limits import check_bounded_work, check_record_size  # noqa: F401 - re-exported
from ..stiffness.map import MapArrays, StiffnessMap
from . import _kernel as K
from .model import (
    MODELS,
    DynamicModel,
    StaticState,
    TorqueLaw,
    check_time_step,
    max_time_step,
    static_equilibrium,
)

__all__ = ["simulate", "integrate", "make_setup", "initial_state", "run_steps", "KernelSetup",
           "fixed_distance_arrays", "CHUNK_STEPS", "CITATIONS"]

#: Steps per kernel call (progress is reported between calls).
CHUNK_STEPS = 20_000

CITATIONS = (
    "Xue & Howard 2018, Mech. Syst. Signal Process., Dynamic modelling of flexibly supported "
    "gears using iterative convergence of tooth mesh stiffness (model, eqs. 4-17, Fig. 7)",
    "Newmark 1959, J. Eng. Mech. Div. ASCE 85(3):67-94 (average acceleration method)",
    "Hilber, Hughes & Taylor 1977, Earthq. Eng. Struct. Dyn. 5:283-292 (HHT-alpha)",
    "Chaari, Bartelmus, Zimroz, Fakhfakh & Haddar 2012, Shock Vib. 19(4):635-652 "
    "(motor/load inertias and coupling stiffness defaults)",
)


@dataclass
class KernelSetup:
    """Everything the kernel needs, as arrays (see :func:`make_setup`)."""

    M: np.ndarray
    K0: np.ndarray
    C: np.ndarray
    Q0: np.ndarray
    Sinv: np.ndarray
    SK: np.ndarray
    SC: np.ndarray
    sQ: np.ndarray
    u: np.ndarray
    g: np.ndarray
    fp: np.ndarray
    ip: np.ndarray
    map_arrays: MapArrays
    in_table: tuple[np.ndarray, np.ndarray]
    out_table: tuple[np.ndarray, np.ndarray]
    #: tooth-error arrays ``(eip, efp, table_pinion, table_gear, shares)``
    #: (:meth:`geardyn.modifications.ToothModifications.kernel_arrays`); default: none
    excitation: tuple = field(default_factory=K.no_excitation)
    #: target speed profile ``(times [s], speeds [rad/s])`` of a speed-controlled drive
    speed_profile: tuple = field(default_factory=lambda: (np.array([0.0, 1.0]), np.zeros(2)))
    #: ``K(theta, d, F)``: ``(forces [N], phase_a, length_a, values)`` of maps at several loads
    #: (:meth:`geardyn.stiffness.LoadFamily.kernel_arrays`); default: the one map
    load_family: tuple = field(default_factory=K.no_family)

    def args(self) -> tuple:
        """The kernel arguments after ``fail``."""
        m = self.map_arrays
        return (self.M, self.K0, self.C, self.Q0, self.Sinv, self.SK, self.SC, self.sQ, self.u,
                self.g, self.fp, self.ip,
                m.dd0, m.ddd, m.phase_a, m.length_a, m.mesh_angle, m.n_cycles, m.n_seg, m.values,
                self.in_table[0], self.in_table[1], self.out_table[0], self.out_table[1],
                *self.excitation, *self.speed_profile, *self.load_family)

    @property
    def dt(self) -> float:
        """Time step [s]."""
        return float(self.fp[K.FP_DT])


def make_setup(M, K0, C, g, Q0, stiffness_map: StiffnessMap | MapArrays, *, dt: float,
               model: str = "I", evaluation: str = "predictor", integrator: str = "newmark",
               hht_alpha: float = 0.0, q_mb: float = 0.0, rsum: float = 1.0, t1t2: float = 0.0,
               d0: float | None = None, tolerance: float = 1e-7, rtol: float = 1e-9,
               max_iterations: int = 50, speed: float = 0.0, p_lim: float = math.inf,
               y_lim: float = math.inf, separation: bool = True,
               input_law: TorqueLaw | None = None, output_law: TorqueLaw | None = None,
               input_speed: float = 0.0, output_speed: float = 0.0,
               excitation: tuple | None = None,
               ripple: tuple[float, float, float] = (0.0, 1.0, 0.0),
               drive: tuple | None = None, stiffness_window: str = "step",
               load_family=None) -> KernelSetup:
    r"""Arrays for the kernel from a general 6-DOF system in deviation coordinates.

    The system is ``M z'' + C z' + K0 z + N g = Q0 + q(z')``, ``N = h (k p + q_mb p')``,
    ``p = g^T z``, with ``k = map(theta, dd)``, ``theta = fmod(n speed dt, period) + z[2]`` and
    ``dd = hypot(rsum, t1t2 + z[3] - z[1]) - d0`` (model II) or 0 (model I).

    Parameters
    ----------
    M, K0, C : array_like, shape (6, 6)
        Mass, stiffness and damping (``C`` includes the load-law linearisation) [SI].
    g : array_like, shape (6,)
        Mesh vector.
    Q0 : array_like, shape (6,)
        Constant forcing [N, N m].
    stiffness_map : StiffnessMap or MapArrays
    dt : float
        Time step [s].
    model : {"I", "II"}
    evaluation : {"predictor", "start"}
    integrator : {"newmark", "hht"}
    hht_alpha : float
        HHT alpha in [-1/3, 0] (``integrator="hht"``).
    q_mb : float
        Mesh damping [N s/m].
    rsum, t1t2, d0 : float
        ``r_b1 + r_b2``, the design ``T1T2`` and the design centre distance [m] (eq. 4); ``d0``
        defaults to ``hypot(rsum, t1t2)``.
    tolerance, rtol, max_iterations
        Model II stopping rules (``|b1 - b2| < tolerance`` [m], relative acceleration update,
        iterations before failing).
    speed : float
        Reference pinion speed [rad/s] (phase of the map angle).
    p_lim, y_lim : float
        Sanity limits on ``|p|`` and ``|z[1]|``, ``|z[3]|`` [m].
    separation : bool
        Eq. 15 (``h = 0`` when the teeth separate); ``False`` keeps ``h = 1``.
    input_law, output_law : TorqueLaw, optional
        Laws whose nonlinear remainder the kernel adds to ``Q0`` (affine laws need none: their
        constant is in ``Q0`` and their slope in ``C``).
    input_speed, output_speed : float
        Reference speeds of DOF 0 and 5 [rad/s] (the laws are linearised there).
    excitation : tuple, optional
        Tooth-error arrays from :meth:`geardyn.modifications.ToothModifications.kernel_arrays`
        (the mesh force becomes ``h (k f (p - e_bar) + q_mb p')``); default none.
    ripple : (float, float, float)
        Input torque ripple ``A sin(n theta_ref + phi)`` added to DOF 0: amplitude ``A`` [N m],
        order ``n`` [-] and phase ``phi`` [rad], locked to the reference angle
        ``theta_ref = speed t`` (0 amplitude: none).
    drive : (gain, w_ref, times, speeds), optional
        Speed-controlled drive: adds ``gain (w_target(t) - w_ref)`` [N m] to DOF 0, with
        ``w_target`` piecewise linear in ``(times [s], speeds [rad/s])``; the drive's slope
        ``-gain`` must already be in ``C[0, 0]``. With it the input torque is
        ``T_in(w_m) + gain (w_target(t) - w_m)``: proportional control without integral action,
        so a steady state differs from a constant target by ``(T_needed(w) - T_in(w)) / gain``
        (``T_needed``: the load and loss torque at the motor), not zero.
    stiffness_window : {"step", "point"}
        ``"step"`` (default): the map averaged over each step's rotation
        (:func:`geardyn.stiffness.map.lookup_box`), so a contact handover inside a step enters
        in proportion to the part of the step after it instead of at the step's end;
        ``"point"``: the map at the evaluation angle (geardyn before 2026-11-25, and the
        paper's flow chart).
    load_family : geardyn.stiffness.LoadFamily, optional
        ``K(theta, d, F)``: the stiffness read from maps at several loads, linear in each
        step's elastic mesh force ``h k (p - e_bar)`` (iterated within the step until the
        stiffness changes by less than ``rtol``); ``stiffness_map`` then serves the static
        state and the tooth-error shares only.
    """
    if model not in ("I", "II"):
        raise InputError("simulation.model", model, "'I' or 'II'")
    if evaluation not in ("predictor", "start"):
        raise InputError("simulation.stiffness_evaluation", evaluation, "'predictor' or 'start'")
    if integrator not in ("newmark", "hht"):
        raise InputError("simulation.integrator", integrator, "'newmark' or 'hht'")
    if stiffness_window not in ("step", "point"):
        raise InputError("simulation.stiffness_window", stiffness_window, "'step' or 'point'")
    al = float(hht_alpha) if integrator == "hht" else 0.0
    if not -1.0 / 3.0 <= al <= 0.0:
        raise InputError("simulation.hht_alpha", hht_alpha, "a value in [-1/3, 0]")
    beta, gamma = (1.0 - al) ** 2 / 4.0, 0.5 - al
    M, K0, C = (np.ascontiguousarray(a, dtype=float) for a in (M, K0, C))
    g, Q0 = np.ascontiguousarray(g, dtype=float), np.ascontiguousarray(Q0, dtype=float)
    S = M + (1.0 + al) * (gamma * dt * C + beta * dt * dt * K0)
    Sinv = np.ascontiguousarray(np.linalg.inv(S))
    u = Sinv @ g
    arrays = stiffness_map.arrays() if isinstance(stiffness_map, StiffnessMap) else stiffness_map
    laws = []
    for law, w in ((input_law, input_speed), (output_law, output_speed)):
        law = law or TorqueLaw("constant", 0.0)
        p0, p1, p2 = law.params()
        laws.append((law, (p0, p1, p2, w, float(law.torque(w)), law.slope(w))))
    fp = np.zeros(K.N_FP)
    fp[K.FP_DT], fp[K.FP_BETA], fp[K.FP_GAMMA], fp[K.FP_ALPHA] = dt, beta, gamma, al
    fp[K.FP_QMB], fp[K.FP_RSUM], fp[K.FP_T1T2] = q_mb, rsum, t1t2
    fp[K.FP_D0] = math.hypot(rsum, t1t2) if d0 is None else d0
    fp[K.FP_TOL], fp[K.FP_RTOL], fp[K.FP_HSTEP] = tolerance, rtol, speed * dt
    fp[K.FP_PLIM], fp[K.FP_YLIM] = p_lim, y_lim
    fp[K.FP_SIGMA] = g @ u
    fp[K.FP_UNORM] = math.sqrt(u @ M @ u)
    fp[K.FP_IN_P0:K.FP_IN_SLOPE + 1] = laws[0][1]
    fp[K.FP_OUT_P0:K.FP_OUT_SLOPE + 1] = laws[1][1]
    fp[K.FP_TSCALE] = max(abs(laws[0][1][4]), abs(laws[1][1][4]), 1e-300)
    fp[K.FP_RIP_AMP], fp[K.FP_RIP_ORDER], fp[K.FP_RIP_PHASE] = ripple
    profile = (np.array([0.0, 1.0]), np.zeros(2))
    if drive is not None:
        fp[K.FP_DRIVE_GAIN], fp[K.FP_WREF] = drive[0], drive[1]
        profile = (np.ascontiguousarray(drive[2], dtype=float),
                   np.ascontiguousarray(drive[3], dtype=float))
    ip = np.zeros(K.N_IP, dtype=np.int64)
    ip[K.IP_MODEL] = 2 if model == "II" else 1
    ip[K.IP_EVAL] = 1 if evaluation == "start" else 0
    ip[K.IP_MAXIT] = int(max_iterations)
    ip[K.IP_SEP] = int(bool(separation))
    ip[K.IP_INLAW], ip[K.IP_OUTLAW] = laws[0][0].code, laws[1][0].code
    ip[K.IP_IN_NL], ip[K.IP_OUT_NL] = int(laws[0][0].nonlinear), int(laws[1][0].nonlinear)
    ip[K.IP_WINDOW] = int(stiffness_window == "step")
    return KernelSetup(M=M, K0=K0, C=C, Q0=Q0, Sinv=Sinv, SK=np.ascontiguousarray(Sinv @ K0),
                       SC=np.ascontiguousarray(Sinv @ C), sQ=np.ascontiguousarray(Sinv @ Q0),
                       u=np.ascontiguousarray(u), g=g, fp=fp, ip=ip, map_arrays=arrays,
                       in_table=laws[0][0].table(), out_table=laws[1][0].table(),
                       excitation=K.no_excitation() if excitation is None else excitation,
                       speed_profile=profile,
                       load_family=K.no_family() if load_family is None
                       else load_family.kernel_arrays())


def _q_remainders(setup: KernelSetup, v: np.ndarray) -> tuple[float, float]:
    fp, ip = setup.fp, setup.ip
    out = []
    for nl, law, base, tab, sign, dz in (
            (ip[K.IP_IN_NL], ip[K.IP_INLAW], K.FP_IN_P0, setup.in_table, 1.0, v[0]),
            (ip[K.IP_OUT_NL], ip[K.IP_OUTLAW], K.FP_OUT_P0, setup.out_table, -1.0, v[5])):
        if not nl:
            out.append(0.0)
            continue
        p0, p1, p2, wref, tref, slope = fp[base:base + 6]
        t = K._law_torque_py(law, p0, p1, p2, tab[0], tab[1], wref + dz)
        out.append(sign * (t - tref - slope * dz))
    return out[0], out[1]


def initial_state(setup: KernelSetup, z0, v0=None, step: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """State arrays for the kernel at step ``step`` with deviations ``z0``, velocities ``v0``.

    The acceleration comes from the equations of motion (zero at a static equilibrium).

    Returns
    -------
    st : ndarray, shape (N_STATE,)
    ist : ndarray of int64, shape (2,)
        ``[step, recorded flag]``.
    """
    from ..stiffness.map import lookup_reference

    z0 = np.asarray(z0, dtype=float)
    v0 = np.zeros(6) if v0 is None else np.asarray(v0, dtype=float)
    fp, ip, g = setup.fp, setup.ip, setup.g
    m = setup.map_arrays
    period = m.n_cycles * m.mesh_angle
    d = math.hypot(fp[K.FP_RSUM], fp[K.FP_T1T2] + z0[3] - z0[1])
    dd = d - fp[K.FP_D0] if ip[K.IP_MODEL] == 2 else 0.0
    theta = np.fmod(step * fp[K.FP_HSTEP], period) + z0[2]
    p0, pd0 = g @ z0, g @ v0
    th_k, ebar, frac, h_err = theta, 0.0, 1.0, None
    eip, efp, etp, etg, els = setup.excitation
    if eip[K.EI_ACTIVE] == 1:  # tooth errors (geardyn.modifications)
        tha = np.fmod(step * fp[K.FP_HSTEP], efp[K.EF_HPER]) + z0[2]
        th_k, ebar, frac, h_err = K._excite_py(theta, tha, d if ip[K.IP_MODEL] == 2 else
                                               fp[K.FP_D0], fp[K.FP_RSUM], dd, p0,
                                               bool(ip[K.IP_SEP]), eip, efp, etp, etg, els, m)
    k0 = float(lookup_reference(np.array(th_k), np.array(dd), m))
    if np.isnan(k0):
        raise InputError("stiffness_map", f"range [{m.dd0:.6g}, "
                         f"{m.dd0 + m.ddd * (m.values.shape[0] - 1):.6g}] m",
                         f"a map covering the initial centre distance change {dd:.6g} m")
    h0 = 0.0 if (ip[K.IP_SEP] and p0 < 0) else 1.0
    if h_err is not None:
        h0, k0 = h_err, k0 * frac
    n0 = h0 * (k0 * (p0 - ebar) + fp[K.FP_QMB] * pd0)
    qin, qout = _q_remainders(setup, v0)
    f = setup.Q0 - setup.C @ v0 - setup.K0 @ z0 - n0 * g
    f[0] += qin
    f[5] += qout
    rip = 0.0
    if fp[K.FP_RIP_AMP] != 0.0 or fp[K.FP_DRIVE_GAIN] != 0.0:  # ripple and drive at this step
        rip = float(K._input_forcing(fp, step, *setup.speed_profile))
        f[0] += rip
    a0 = np.linalg.solve(setup.M, f)
    st = np.zeros(K.N_STATE)
    st[K.S_Z:K.S_Z + 6], st[K.S_V:K.S_V + 6], st[K.S_A:K.S_A + 6] = z0, v0, a0
    st[K.S_N], st[K.S_K], st[K.S_H], st[K.S_DD] = n0, k0, h0, d - fp[K.FP_D0]
    st[K.S_IT], st[K.S_RB], st[K.S_RA] = 0.0, np.nan, np.nan
    st[K.S_QIN], st[K.S_QOUT], st[K.S_E], st[K.S_RIP] = qin, qout, ebar, rip
    st[K.S_FEL] = h0 * k0 * (p0 - ebar)  # elastic mesh force: the load of a K(theta, d, F)
    return st, np.array([step, 0], dtype=np.int64)


def run_steps(setup: KernelSetup, st: np.ndarray, ist: np.ndarray, n_steps: int, *,
              rec_start: int = 0, decim: int = 1, out: np.ndarray | None = None, j: int = 0,
              python: bool = False) -> tuple[int, int, np.ndarray]:
    """Advance ``st`` by ``n_steps`` steps with the compiled kernel (or its Python twin).

    Returns
    -------
    (status, j, fail)
        Status code (0 = success), next free record row, failure information.
    """
    if out is None:
        out = np.empty((0, K.N_REC))
    fail = np.full(K.N_FAIL, np.nan)
    fn = K.advance_python if python else K.advance
    status, j = fn(int(n_steps), int(rec_start), int(decim), out, int(j), st, ist, fail,
                   *setup.args())
    return int(status), int(j), fail


# --------------------------------------------------------------------------- the case
def _setup_for_case(case, dyn: DynamicModel, stiffness_map: StiffnessMap, which: str,
                    static: StaticState, load_family=None) -> KernelSetup:
    sim = case.simulation
    Q0, d_in, d_out = dyn.forcing_at_reference()
    C = dyn.C0.copy()
    C[0, 0] += d_in
    drive = _speed_profile(case, dyn)
    if drive is not None:
        C[0, 0] += drive[0]  # the drive's torque falls with the motor speed
    C[5, 5] += d_out
    pair = dyn.pair
    m_n = pair.module
    p_lim = max(50.0 * abs(static.mesh_deflection), 0.1 * m_n)
    y_lim = max(20.0 * max(abs(static.y_p), abs(static.y_g)), m_n)
    from ..modifications import ToothModifications

    mods = ToothModifications.from_case(case)
    kernel_map: StiffnessMap | MapArrays = stiffness_map
    d0 = pair.design_centre_distance
    if which == "I-static":  # model I on the map seen from the static operating point
        kernel_map = fixed_distance_arrays(stiffness_map, static.centre_distance_change)
        d0 = pair.design_centre_distance + static.centre_distance_change
    return make_setup(
        dyn.M, dyn.K0, C, dyn.g, Q0, kernel_map, dt=sim.dt, model="II" if which == "II" else "I",
        evaluation=sim.stiffness_evaluation, stiffness_window=sim.stiffness_window,
        integrator=sim.integrator, hht_alpha=sim.hht_alpha,
        q_mb=dyn.q_mb, rsum=pair.base_radius_sum, t1t2=pair.design_t1t2,
        d0=d0, tolerance=sim.tolerance, rtol=sim.rtol,
        max_iterations=sim.max_iterations, speed=dyn.speed, p_lim=p_lim, y_lim=y_lim,
        separation=True, input_law=dyn.input_law, output_law=dyn.output_law,
        input_speed=dyn.speed, output_speed=dyn.gear_speed,
        excitation=mods.kernel_arrays(stiffness_map) if mods.active else None,
        ripple=(case.motor.ripple * float(dyn.input_law.torque(dyn.speed)),
                case.motor.ripple_order, case.motor.ripple_phase),
        drive=drive, load_family=_family_view(load_family, which, static))


def _family_view(load_family, which: str, static: StaticState):
    """The family as model ``which`` reads it. The kernel reads every map of the family with
    the ``dd`` origin of the case's map, which model I-static shifts
    (:func:`fixed_distance_arrays`), so only the coverage is checked here."""
    if load_family is not None and which == "I-static":
        dd_shift = float(static.centre_distance_change)
        for m in load_family.maps:
            if not m.covers(dd_shift):
                raise InputError("stiffness_map", f"range [{m.dd[0]:.6g}, {m.dd[-1]:.6g}] m",
                                 f"maps covering the fixed centre distance change "
                                 f"{dd_shift:.6g} m")
    return load_family


def fixed_distance_arrays(stiffness_map: StiffnessMap, centre_distance_change: float
                          ) -> MapArrays:
    """The map's kernel arrays with the ``dd`` axis moved so that ``dd = 0`` reads
    ``K(theta, centre_distance_change)``.

    Only ``dd0`` changes (to ``dd[0] - centre_distance_change``); the node values are shared, so
    model I evaluating this view at ``dd = 0`` interpolates the original map at
    ``centre_distance_change`` (to rounding of ``dd0``). A one-line map is constant in ``dd`` and
    unchanged.

    Parameters
    ----------
    stiffness_map : StiffnessMap
    centre_distance_change : float
        The fixed operating minus design centre distance [m].

    Returns
    -------
    MapArrays

    Raises
    ------
    InputError
        If the map does not cover ``centre_distance_change``.
    """
    if not stiffness_map.covers(centre_distance_change):
        raise InputError("stiffness_map", f"range [{stiffness_map.dd[0]:.6g}, "
                         f"{stiffness_map.dd[-1]:.6g}] m",
                         f"a map covering the fixed centre distance change "
                         f"{centre_distance_change:.6g} m")
    arrays = stiffness_map.arrays()
    return arrays._replace(dd0=arrays.dd0 - float(centre_distance_change))


def _speed_profile(case, dyn: DynamicModel):
    """``(gain, w_ref, times, speeds)`` of the case's speed-controlled drive, or None.

    The drive adds ``gain (w_target(t) - w_m)`` to the input law's torque ``T_in(w_m)``
    (``case.motor.torque`` for the constant law): a proportional controller without integral
    action. In a steady state at a constant target ``w_1`` the motor turns at the speed ``w``
    where ``T_in(w) + gain (w_1 - w)`` equals the torque the load and the losses need, i.e.
    below a target above the starting speed by ``(T_needed(w) - T_in(w)) / gain`` (the paper's
    case ramped to 150 rad/s with gain 5 N m s/rad settles near 144.6 rad/s); a larger gain
    makes the error smaller.

    Raises
    ------
    InputError
        Profile lists of different lengths, fewer than 2 points, times not increasing, speeds
        not positive.
    """
    m = case.motor
    t, w = m.profile_times, m.profile_speeds
    if t is None and w is None:
        return None
    t = np.asarray(t if t is not None else [], float)
    w = np.asarray(w if w is not None else [], float)
    if t.size < 2 or t.size != w.size:
        raise InputError("motor.profile_times", f"{t.size} times and {w.size} speeds",
                         "two lists of the same length >= 2 (profile_times [s], "
                         "profile_speeds [rad/s])")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise InputError("motor.profile_times", t.tolist(), "strictly increasing finite times [s]")
    if not np.all(np.isfinite(w)) or np.any(w <= 0):
        raise InputError("motor.profile_speeds", w.tolist(), "finite target speeds > 0 [rad/s]")
    return float(m.drive_gain), float(dyn.speed), t, w


def _start_with_errors(setup: KernelSetup, dyn: DynamicModel, static: StaticState) -> np.ndarray:
    """The static start ``z`` with tooth errors: the gear (and load) turned back so that the mesh
    deflection is ``N / (k f) + e_bar`` at ``t = 0`` with every pair loaded."""
    from ..stiffness.map import lookup_reference

    z = static.z.copy()
    eip, efp, etp, etg, els = setup.excitation
    if eip[K.EI_ACTIVE] != 1:
        return z
    fp, m = setup.fp, setup.map_arrays
    model2 = setup.ip[K.IP_MODEL] == 2
    d = math.hypot(fp[K.FP_RSUM], fp[K.FP_T1T2] + z[3] - z[1])
    dd = d - fp[K.FP_D0] if model2 else 0.0
    th_k, ebar, frac, _ = K._excite_py(z[2], z[2], d if model2 else fp[K.FP_D0], fp[K.FP_RSUM],
                                       dd, math.inf, False, eip, efp, etp, etg, els, m)
    k = float(lookup_reference(np.array(th_k), np.array(dd), m)) * frac
    shift = (setup.g @ z - (static.mesh_force / k + ebar)) / dyn.r_b2
    z[4] += shift
    z[5] += shift
    return z


def simulate(case, stiffness_map: StiffnessMap | None = None, *, model: str | None = None,
             cracked: bool = True, progress: Callable[[int, int], None] | None = None):
    r"""Simulate model I, I-static or II of a case and return the record as an xarray Dataset.

    Parameters
    ----------
    case : geardyn.config.Case
        Parameters; ``case.simulation`` gives dt, settle and record time, decimation, tolerances,
        the stiffness evaluation point and the integrator.
    stiffness_map : StiffnessMap, optional
        Any map (PEM, FE, a user table). Default:
        ``geardyn.stiffness.build_map(case, cracked=cracked)``.
    model : {"I", "I-static", "II"}, optional
        Default ``case.simulation.model``. Model I: ``K(theta)`` at the design centre distance;
        model I-static: ``K(theta)`` at the static operating centre distance of eq. 4 (the
        bearings deflected by the static mesh force), held fixed; model II: ``K(theta, d(t))``
        iterated each step (the paper's Fig. 7).
    cracked : bool
        Passed to ``build_map`` when no map is given.
    progress : callable, optional
        ``progress(steps_done, steps_total)`` between kernel chunks.

    Returns
    -------
    xarray.Dataset
        Coordinate ``time`` [s]; the DOFs ``theta_m, y_p, theta_p, y_g, theta_g, theta_out``,
        velocities ``omega_m, v_yp, omega_p, v_yg, omega_g, omega_out``,
        ``transmission_error`` (``theta_p - (r_b2/r_b1) theta_g``), ``mesh_force``,
        ``mesh_deflection``, ``centre_distance_change``, ``pressure_angle``, ``contact_ratio``,
        ``contact_ratio_eq8``, ``mesh_stiffness``, ``contact``, ``iterations``,
        ``residual_before``, ``residual_after``; units and provenance in the attributes
        (model I-static adds ``stiffness_centre_distance_change`` [m] and the
        ``stiffness_pressure_angle`` [rad], ``stiffness_contact_ratio`` and
        ``stiffness_contact_ratio_eq8`` there; its ``centre_distance_change`` is, as in model I,
        the geometric ``d(t) - d`` of the bearing motion, not the fixed value).

    Raises
    ------
    InputError
        ``case`` not a :class:`geardyn.config.Case`, ``stiffness_map`` neither a
        :class:`geardyn.stiffness.StiffnessMap` nor None, an unknown model name (any case is
        accepted, as by the CLI's ``--model``), a time step too coarse for the highest natural
        frequency, a map not covering the operating point, load laws without a steady state.
    NumericalError
        Divergence (NaN, runaway deflection), the centre distance leaving the map, or the model II
        iteration not converging. The record up to the failure is attached as ``exc.partial``
        (attribute ``complete = 0``).
    """
    which = check_arguments(case, stiffness_map, model)
    cracked = check_flag(cracked, "cracked")
    if case.simulation.dynamics == "transverse":
        from .transverse import simulate_transverse

        return simulate_transverse(case, stiffness_map, model=which, cracked=cracked,
                                   progress=progress)
    check_model_options(case)  # friction needs the transverse model (also for config validate)
    check_bounded_work(case)  # before any map, matrix or step: refuse runs that would not end
    if stiffness_map is None:
        from ..stiffness import build_map

        stiffness_map = build_map(case, cracked=cracked)
    else:
        _check_family_map(case, stiffness_map, cracked)
    status, fail, static, record = integrate(case, stiffness_map, which, cracked=cracked,
                                             progress=progress)
    if status != K.OK:
        raise_with_partial(status, fail, which, static, stiffness_map, record)
    return record(True)


def integrate(case, stiffness_map: StiffnessMap, which: str, *, cracked: bool = True,
              progress: Callable[[int, int], None] | None = None
              ) -> tuple[int, np.ndarray, StaticState, Callable]:
    """The time steps of :func:`simulate` for checked arguments, without building the record.

    Parameters
    ----------
    case : geardyn.config.Case
        A checked case (:func:`simulate` checks it first).
    stiffness_map : StiffnessMap
    which : {"I", "I-static", "II"}
    cracked : bool
        Which load family (``stiffness.fe.torques``) to build.
    progress : callable, optional
        As for :func:`simulate`.

    Returns
    -------
    status : int
        The kernel's status (:data:`geardyn.dynamics._kernel.OK` when every step ran).
    fail : ndarray
        The kernel's failure details.
    static : StaticState
        The static state the run started from.
    record : callable
        ``record(complete) -> xarray.Dataset``: the record of the steps run (xarray imported
        only when called).
    """
    from ..stiffness import build_load_family

    family = build_load_family(case, cracked=cracked)  # None unless stiffness.fe.torques
    sim = case.simulation
    with case_arithmetic(case):
        dyn = DynamicModel.from_case(case, stiffness_map)
        check_time_step(dyn, stiffness_map, sim.dt)
        static = static_equilibrium(dyn, stiffness_map, which=which)
        setup = _setup_for_case(case, dyn, stiffness_map, which, static, family)
    n_settle, decim, count, n_last = record_plan(sim)
    out = np.full((count, K.N_REC), np.nan)
    st, ist = initial_state(setup, _start_with_errors(setup, dyn, static))
    rows = [0]

    def step(n: int):
        # the first call also records the initial state when nothing is settled
        status, rows[0], fail = run_steps(setup, st, ist, n, rec_start=n_settle, decim=decim,
                                          out=out, j=rows[0])
        return status, fail

    def record(complete: bool):
        return _dataset(case, dyn, stiffness_map, which, static, setup, out[:rows[0]], n_settle,
                        decim, complete=complete)

    status, fail = drive_chunks(step, ist, n_last, progress=progress)
    return status, fail, static, record


def _check_family_map(case, stiffness_map: StiffnessMap, cracked: bool) -> None:
    """Refuse a map other than the case's own for a load-family case: with
    ``stiffness.fe.torques`` the run reads the family's FE maps, built from the case, and a
    given PEM map was silently replaced by them while the record named the PEM map (a user
    audit, 2026-11-27)."""
    if case.stiffness.fe.torques is None or case.stiffness.method != "fe":
        return
    from ..cache import cache_key
    from ..stiffness import map_inputs

    if stiffness_map.attrs.get("inputs_hash") != cache_key(map_inputs(case, "fe", cracked)):
        raise InputError("stiffness_map", f"a {stiffness_map.attrs.get('method', 'user')} map "
                         "of other inputs than the case's",
                         "no map (None) or the case's own FE map: a case with "
                         "stiffness.fe.torques runs on its load family of FE maps, built from "
                         "the case (remove the torques to simulate on another map)")


def check_arguments(case, stiffness_map, model) -> str:
    """Check the arguments of :func:`simulate` and return the model's name as in :data:`MODELS`
    (``model`` matched in any case, as the CLI's ``--model``; None: ``case.simulation.model``).

    Raises
    ------
    InputError
        Naming the argument: ``case`` not a :class:`geardyn.config.Case`, ``stiffness_map``
        neither a :class:`geardyn.stiffness.StiffnessMap` nor None, ``model`` not a model name.
    """
    from ..config import Case

    if not isinstance(case, Case):
        raise InputError("case", case, "a geardyn.config.Case (geardyn.load_case(path) or "
                                       f"geardyn.paper_case()), not {_type_name(case)}")
    if stiffness_map is not None and not isinstance(stiffness_map, StiffnessMap):
        raise InputError("stiffness_map", stiffness_map,
                         "a geardyn.stiffness.StiffnessMap (geardyn.stiffness.build_map(case)), "
                         f"or None to build the case's map; not {_type_name(stiffness_map)}")
    which = case.simulation.model if model is None else model
    if isinstance(which, str):
        for name in MODELS:
            if which.strip().lower() == name.lower():
                return name
    raise InputError("model", which, " or ".join(repr(m) for m in MODELS) + " (any case), or "
                     "None for the case's simulation.model")


def _type_name(value) -> str:
    """``"a <module>.<type>"`` of ``value`` for an error message."""
    t = type(value)
    return f"a {t.__qualname__}" if t.__module__ == "builtins" else \
        f"a {t.__module__}.{t.__qualname__}"


@contextmanager
def case_arithmetic(case):
    """Run the model set-up of ``case``: floating-point overflow, a singular matrix or a value
    error become an :class:`InputError` naming the case's extreme fields."""
    try:
        with np.errstate(over="raise", invalid="raise", divide="raise"):
            yield
    except GeardynError:
        raise
    except (FloatingPointError, OverflowError, ZeroDivisionError, ValueError,
            np.linalg.LinAlgError) as exc:
        fields = _extreme_fields(case)
        raise InputError(", ".join(fields) or "case", "values whose products overflow or are "
                         f"singular ({exc})", "physical magnitudes: the model's matrices and "
                         "static equilibrium must stay finite") from None


def record_plan(sim) -> tuple[int, int, int, int]:
    """``(n_settle, decimation, records, n_last)`` of ``case.simulation`` (refused when the
    record would not fit, :func:`geardyn.run_limits.check_record_size`)."""
    dt = sim.dt
    n_settle = int(round(sim.settle_time / dt))
    n_record = max(1, int(round(sim.record_time / dt)))
    decim = sim.decimation
    count = -(-n_record // decim)
    check_record_size(count, sim)
    return n_settle, decim, count, n_settle + (count - 1) * decim


def drive_chunks(step: Callable[[int], tuple], ist: np.ndarray, n_last: int, *,
                 chunk: int = CHUNK_STEPS,
                 progress: Callable[[int, int], None] | None = None) -> tuple:
    """Call ``step(n) -> (status, fail)`` on chunks of at most ``chunk`` steps until step
    ``n_last`` (the count in ``ist[0]``) or a failure; ``progress(done, n_last)`` between
    chunks. Returns the last ``(status, fail)``."""
    if progress is not None:
        progress(0, n_last)
    while True:
        status, fail = step(min(chunk, n_last - int(ist[0])))
        if progress is not None:
            progress(int(ist[0]), n_last)
        if status != K.OK or int(ist[0]) >= n_last:
            return status, fail


def raise_with_partial(status: int, fail: np.ndarray, which: str, static: StaticState,
                       stiffness_map: StiffnessMap, record: Callable[[bool], object]):
    """Raise the :class:`NumericalError` of a failed run with the record up to the failure
    attached as ``exc.partial`` (attribute ``complete = 0``)."""
    if which == "I-static":  # the kernel's change is from the shifted d0
        fail[5] += static.centre_distance_change
    ds = record(False)
    exc = _numerical_error(status, fail, stiffness_map, which)
    ds.attrs["failure"] = str(exc)
    exc.partial = ds
    raise exc


def _extreme_fields(case) -> list[str]:
    """Dotted keys of the case's numbers that are far outside any physical range."""
    out = []
    data = case.model_dump(mode="python", exclude={"provenance"})

    def walk(node, prefix):
        for k, v in node.items():
            key = f"{prefix}.{k}" if prefix else k
            if isinstance(v, dict):
                walk(v, key)
            elif isinstance(v, float) and v != 0 and not (1e-30 < abs(v) < 1e30):
                out.append(f"{key} = {v:g}")

    walk(data, "")
    return out


def check_model_options(case) -> None:
    """Refuse options the chosen dynamic model does not have (before any map or matrix).

    :func:`simulate` and ``geardyn config validate`` (:mod:`geardyn.case_checks`) call it.
    Friction (``mesh.friction_coefficient > 0``)
    needs ``simulation.dynamics = 'transverse'``; the transverse model refuses HHT-alpha and a
    load family (:func:`geardyn.dynamics.transverse._refuse_unsupported`).

    Raises
    ------
    geardyn.errors.InputError
    """
    if case.simulation.dynamics == "transverse":
        from .transverse import _refuse_unsupported

        _refuse_unsupported(case)
    elif case.mesh.friction_coefficient > 0:
        raise InputError("mesh.friction_coefficient", case.mesh.friction_coefficient,
                         "0 with simulation.dynamics = '6-dof' (friction acts across the line "
                         "of action: set simulation.dynamics = 'transverse')")


def _numerical_error(status: int, fail: np.ndarray, stiffness_map: StiffnessMap,
                     which: str) -> NumericalError:
    msg = f"model {which}: {K.STATUS_TEXT.get(status, f'status {status}')}"
    if status == K.MAP_RANGE:
        msg += (f" (centre distance change {fail[5] * 1e3:.6g} mm; the map covers "
                f"[{stiffness_map.dd[0] * 1e3:.6g}, {stiffness_map.dd[-1] * 1e3:.6g}] mm: widen "
                "stiffness.centre_distance_min/max or check the loads)")
    elif status == K.NOT_CONVERGED:
        msg += " (raise simulation.max_iterations or simulation.tolerance, or reduce dt)"
    else:
        gap = stiffness_map.zero_window(float(fail[5]))
        if status == K.MESH_RUNAWAY and gap > 0:
            # a fault that leaves no pair in contact (a broken tooth taller than the contact
            # ratio allows): dt and the integrator do not help (a user audit, 2026-11-27)
            msg += (f": the stiffness map is zero over {math.degrees(gap):.3g} deg of pinion "
                    f"rotation at {fail[5] * 1e3:.4g} mm (no tooth pair in contact: the fault "
                    "leaves a gap in the mesh) and the pinion ran free there; a smaller fault "
                    "keeps a pair in contact ('geardyn stiffness' shows where K_t is 0)")
        else:
            msg += (" (reduce simulation.dt, check the loads, or use simulation.integrator = "
                    "'hht')")
    state = {name: float(v) for name, v in zip(K.FAIL_NAMES[1:], fail[1:], strict=True)}
    return NumericalError(msg, time=float(fail[0]), state=state)


# --------------------------------------------------------------------------- the record
_VARS = (
    # name, units, long name
    ("theta_m", "rad", "motor rotation angle"),
    ("y_p", "m", "pinion centre displacement along the line of action"),
    ("theta_p", "rad", "pinion rotation angle"),
    ("y_g", "m", "gear centre displacement along the line of action"),
    ("theta_g", "rad", "gear rotation angle"),
    ("theta_out", "rad", "load rotation angle"),
    ("omega_m", "rad/s", "motor angular velocity"),
    ("v_yp", "m/s", "pinion centre velocity along the line of action"),
    ("omega_p", "rad/s", "pinion angular velocity"),
    ("v_yg", "m/s", "gear centre velocity along the line of action"),
    ("omega_g", "rad/s", "gear angular velocity"),
    ("omega_out", "rad/s", "load angular velocity"),
)


#: Units of the damping values of :attr:`DynamicModel.damping` (the record's ``damping``).
_DAMPING_UNITS = {"q_cp": "N m s/rad", "q_cg": "N m s/rad", "q_yp": "N s/m", "q_yg": "N s/m",
                  "q_stp": "N m s/rad", "q_stg": "N m s/rad", "q_mb": "N s/m"}


def _dataset(case, dyn: DynamicModel, stiffness_map: StiffnessMap, which: str,
             static: StaticState, setup: KernelSetup, rows: np.ndarray, n_settle: int,
             decim: int, complete: bool):
    import xarray as xr

    from .._version import __version__
    from ..config import case_to_toml
    from .model import operating_arrays

    dt = setup.dt
    n = n_settle + decim * np.arange(rows.shape[0])
    t = n * dt
    ref = n * setup.fp[K.FP_HSTEP]  # reference pinion angle, integer step count times w dt
    e = dyn.reference_direction
    data: dict[str, tuple] = {}
    for i, (name, units, long) in enumerate(_VARS[:6]):
        val = rows[:, K.R_Z + i] + (ref * e[i] if e[i] != 0 else 0.0)
        data[name] = ("time", val, {"units": units, "long_name": long})
    for i, (name, units, long) in enumerate(_VARS[6:]):
        val = rows[:, K.R_V + i] + dyn.speed * e[i]
        data[name] = ("time", val, {"units": units, "long_name": long})
    z = rows[:, K.R_Z:K.R_Z + 6]
    te = z[:, 2] - dyn.r_b2 / dyn.r_b1 * z[:, 4]
    data["transmission_error"] = ("time", te, {
        "units": "rad", "long_name": "transmission error theta_p - (r_b2/r_b1) theta_g "
                                     "(= theta_p - theta_g for equal gears)"})
    # a sum over the six columns, not ``z @ dyn.g``: OpenBLAS threads a matrix-vector product
    # this long (0.6 ms), and its helper thread then spins on another core for about 0.1 s
    # (0.10-0.11 s of CPU a run of the sweep benchmark's case, 2026-11-27), taking that core
    # from the figure process, the kernel's compiler or a second run; the column sum costs
    # about 1 ms, and rounds the same on every CPU (a BLAS kernel's order depends on it)
    deflection = z[:, 0] * dyn.g[0]
    for i in range(1, 6):
        deflection += z[:, i] * dyn.g[i]
    data["mesh_deflection"] = ("time", deflection, {
        "units": "m", "long_name": "mesh deflection along the line of action p (eq. 15)"})
    data["mesh_force"] = ("time", rows[:, K.R_N], {
        "units": "N", "long_name": "normal mesh force h N (eq. 14)"})
    dd = rows[:, K.R_DD]
    if which == "I-static":
        # the kernel's change is from d0 = d + dd_s; adding d0 back is exact (Sterbenz), so the
        # geometric d(t) - d below rounds exactly as model I's
        dd = (dd + setup.fp[K.FP_D0]) - dyn.pair.design_centre_distance
    op = operating_arrays(dyn.pair, dd)
    data["centre_distance_change"] = ("time", dd, {
        "units": "m", "long_name": "operating minus design centre distance d(t) - d (eq. 4)"})
    data["pressure_angle"] = ("time", op["pressure_angle"], {
        "units": "rad", "long_name": "operating pressure angle (eq. 6)"})
    data["contact_ratio"] = ("time", op["contact_ratio"], {
        "units": "1", "long_name": "operating contact ratio, physical (s_end - s_start)/p_b"})
    data["contact_ratio_eq8"] = ("time", op["contact_ratio_eq8"], {
        "units": "1", "long_name": "operating contact ratio by the paper's eq. 8 "
                                   "(pi m cos alpha' denominator, erratum 2)"})
    data["mesh_stiffness"] = ("time", rows[:, K.R_K], {
        "units": "N/m", "long_name": "mesh stiffness k_mb used in the step"})
    data["contact"] = ("time", rows[:, K.R_H].astype(np.int8), {
        "units": "1", "long_name": "tooth contact h (1 in contact, 0 separated; eq. 15)"})
    data["iterations"] = ("time", rows[:, K.R_IT].astype(np.int32), {
        "units": "1", "long_name": "re-solves in the step after the first: the model II "
                                   "centre distance iteration (paper Fig. 9b), and the load "
                                   "iteration of a nonlinear load law"})
    data["residual_before"] = ("time", rows[:, K.R_RB], {
        "units": "m", "long_name": "|b1 - b2| of the first solve of the step (model II; "
                                   "paper Fig. 9a, red)"})
    data["residual_after"] = ("time", rows[:, K.R_RA], {
        "units": "m", "long_name": "|b1 - b2| of the accepted solve (model II; paper Fig. 9a, "
                                   "black)"})
    tooth_errors = int(setup.excitation[0][K.EI_ACTIVE]) == 1
    if tooth_errors:
        data["mesh_error"] = ("time", rows[:, K.R_E], {
            "units": "m", "long_name": "load-share weighted tooth error e_bar of the loaded pairs "
                                       "along the line of action (eq. 15 with p - e; "
                                       "geardyn.modifications)"})
    sim = case.simulation
    dt_max, f_max, f_mesh = max_time_step(dyn, stiffness_map)
    mattrs = dict(stiffness_map.attrs)
    attrs = {
        "title": f"geardyn model {which} simulation of case {case.name!r}",
        "model": which,
        "pinion_teeth": int(dyn.pair.pinion.teeth),
        "gear_teeth": int(dyn.pair.gear.teeth),
        "dt": float(dt), "dt_units": "s",
        "settle_time": float(n_settle * dt), "settle_time_units": "s",
        "record_time": float(sim.record_time), "record_time_units": "s",
        "decimation": int(decim),
        "integrator": sim.integrator,
        "contact_ratio_formula": sim.contact_ratio_formula,
        "hht_alpha": float(sim.hht_alpha if sim.integrator == "hht" else 0.0),
        "hht_alpha_units": "1",
        "stiffness_evaluation": sim.stiffness_evaluation,
        "stiffness_window": sim.stiffness_window,
        "tolerance": float(sim.tolerance), "tolerance_units": "m",
        "rtol": float(sim.rtol), "rtol_units": "1", "max_iterations": int(sim.max_iterations),
        "target_speed": float(dyn.speed), "target_speed_units": "rad/s",
        "input_law": dyn.input_law.describe(),
        "output_law": dyn.output_law.describe(),
        "output_law_calibrated": int(dyn.output_calibrated),
        "mesh_damping": float(dyn.q_mb), "mesh_damping_units": "N s/m",
        "representative_mesh_stiffness": float(dyn.k_rep),
        "representative_mesh_stiffness_units": "N/m",
        "damping": "; ".join(f"{k} = {v:.6g} {_DAMPING_UNITS.get(k, '(SI)')}"
                             for k, v in dyn.damping.items()),
        "static_mesh_force": float(static.mesh_force), "static_mesh_force_units": "N",
        "static_centre_distance_change": float(static.centre_distance_change),
        "static_centre_distance_change_units": "m",
        "highest_natural_frequency": float(f_max), "highest_natural_frequency_units": "Hz",
        "mesh_frequency": float(f_mesh), "mesh_frequency_units": "Hz",
        "max_time_step": float(dt_max), "max_time_step_units": "s",
        "stiffness_method": str(mattrs.get("method", "")),
        "stiffness_inputs_hash": str(mattrs.get("inputs_hash", "")),
        "stiffness_cracked": int(bool(mattrs.get("cracked", 0))),
        "stiffness_dd_range": f"{stiffness_map.dd[0]:.6g} .. {stiffness_map.dd[-1]:.6g} m",
        "fixed_point_rule": "model II steps whose handover lies between the iterated centre "
                            "distances have no fixed point; they are accepted on the first "
                            "solve's side and keep residual_after >= tolerance",
        "separation_rule": "h = 1 when the free mesh deflection at t_{n+1} is >= 0 (eq. 15)",
        "angles": "total angles; theta_p = 0 at t = 0 with pinion tooth 0 at the design pitch "
                  "point; time counts from the start of the settling phase",
        "case_toml": case_to_toml(case),
        "geardyn_version": __version__,
        "citations": "\n".join(CITATIONS),
        "steps_without_fixed_point": int(np.sum(rows[:, K.R_RA] >= sim.tolerance)),
        "complete": int(complete),
    }
    if which == "I-static":
        dd_s = float(static.centre_distance_change)
        fixed = operating_arrays(dyn.pair, np.array([dd_s]))
        attrs.update({
            "stiffness_centre_distance": "model I-static: K(theta) at the static operating "
                                         "centre distance of eq. 4 (bearings deflected by the "
                                         "static mesh force), held fixed; the variables "
                                         "centre_distance_change, pressure_angle and "
                                         "contact_ratio* stay the geometric values of the "
                                         "bearing motion, as in model I",
            "stiffness_centre_distance_change": dd_s, "stiffness_centre_distance_change_units": "m",
            "stiffness_pressure_angle": float(fixed["pressure_angle"][0]),
            "stiffness_pressure_angle_units": "rad",
            "stiffness_contact_ratio": float(fixed["contact_ratio"][0]),
            "stiffness_contact_ratio_units": "1",
            "stiffness_contact_ratio_eq8": float(fixed["contact_ratio_eq8"][0]),
            "stiffness_contact_ratio_eq8_units": "1",
        })
    if setup.load_family[0].size >= 2:
        forces = setup.load_family[0]
        attrs["stiffness_load_family"] = (
            "K(theta, d, F): maps at mesh forces " + ", ".join(f"{f:.6g}" for f in forces)
            + " N (pinion torques " + ", ".join(f"{t:.6g}" for t in case.stiffness.fe.torques)
            + " N m), read at each step's elastic mesh force, linear between them")
    if setup.fp[K.FP_DRIVE_GAIN] != 0.0:
        tp, wp = setup.speed_profile
        gain = float(setup.fp[K.FP_DRIVE_GAIN])
        attrs["speed_profile"] = (
            f"speed-controlled drive (proportional), gain {gain:.6g} N m s/rad, target "
            + ", ".join(f"{w:.6g} rad/s at {t:.6g} s" for t, w in zip(tp, wp, strict=True))
            + " (linear between, constant beyond the ends)")
        # what was simulated: the input law plus the controller; the target is the profile's
        # (its final speed), not the steady speed of the input law the run starts from
        attrs["input_law"] = (
            f"{dyn.input_law.describe()} + {gain:.6g} N m s/rad x (w_target(t) - w_m): "
            f"proportional speed control without integral action to the speed_profile target "
            f"(final {float(wp[-1]):.6g} rad/s); a steady state misses a constant target by "
            f"w_target - w = (load and loss torque at the motor - T_in(w)) / {gain:.6g} "
            f"N m s/rad")
        attrs["target_speed"] = float(wp[-1])
        attrs["target_speed_meaning"] = (
            f"final target of the speed_profile (from {float(tp[-1]):.6g} s on); the proportional "
            f"drive settles off it (see input_law)")
        attrs["initial_speed"] = float(dyn.speed)
        attrs["initial_speed_units"] = "rad/s"
        attrs["initial_speed_meaning"] = (
            "steady pinion speed of the input and load laws without the drive: the static "
            "equilibrium the run starts from, and the speed of the reference rotation")
    if setup.fp[K.FP_RIP_AMP] != 0.0:
        attrs["input_torque_ripple"] = (
            f"{setup.fp[K.FP_RIP_AMP]:.6g} N m x sin({setup.fp[K.FP_RIP_ORDER]:.6g} theta_ref + "
            f"{setup.fp[K.FP_RIP_PHASE]:.6g} rad), theta_ref = {float(dyn.speed):.6g} rad/s x "
            f"time")
    if tooth_errors:
        from ..modifications import ToothModifications

        attrs["tooth_errors"] = ToothModifications.from_case(case).describe()
    return owning(xr.Dataset(data, coords={"time": ("time", t, {"units": "s",
                                                                "long_name": "time"})},
                             attrs=attrs))


def owning(ds):
    """``ds`` with every variable holding its own array (in place; returned).

    A column of the kernel's record buffer is a view that keeps the whole buffer (every
    recorded quantity) alive as long as the record: the paper's run held 92 MB of such
    buffers (issue 16, peak memory). A variable that is a view gets a copy.
    """
    for name in ds.data_vars:
        var = ds[name].variable
        values = var.values
        if isinstance(values, np.ndarray) and values.base is not None:
            var.values = np.array(values)
    return ds
