r"""The 6-DOF transverse-torsional model of Xue & Howard (2018), eqs. 9-17 and appendix B.

Degrees of freedom (the paper's order), all in SI units:

.. math:: x = [\theta_m, y_p, \theta_p, y_g, \theta_g, \theta_{out}]^T
          \quad [\mathrm{rad, m, rad, m, rad, rad}]

and the equations of motion ``M x'' + C x' + K x = F`` with

* ``M = diag(I_m, m_p, I_p, m_g, I_g, I_out)``,
* ``K = K0 + h k_mb g g^T`` and ``C = C0 + h q_mb g g^T`` (appendix B), where
  ``g = [0, 1, r_b1, -1, -r_b2, 0]`` is the mesh vector: the mesh deflection along the line of
  action is ``p = g^T x = y_p + r_b1 theta_p - y_g - r_b2 theta_g`` (eq. 15) and the mesh force
  ``N = h (k_mb p + q_mb p')`` (eq. 14) acts on the DOFs as ``-N g``;
* ``K0`` holds the couplings ``k_cp``, ``k_cg`` and the bearings ``k_yp``, ``k_yg``; ``C0`` the
  coupling, bearing and absolute torsional dampings ``q_cp``, ``q_cg``, ``q_yp``, ``q_yg``,
  ``q_stp``, ``q_stg``;
* ``F = [T_in(theta_m'), 0, 0, 0, 0, -T_out(theta_out')]`` (eqs. 9 and 16).

Eq. 13 of the paper writes ``q_stp`` in the gear equation; ``q_stg`` is meant (erratum 3 of
``docs/verification/dynamics.md``); geardyn uses ``q_stg``. ``r_b1``, ``r_b2`` are the *base* radii (the
paper's ``r_p``, ``r_g``; its Table 1 "base radius 129.7 mm" is their sum, erratum 1).

Damping the paper does not give is set from modal damping ratios (the convention of the PHM-BGU
public gear model): coupling ``q_c = 2 zeta sqrt(k_c I_1 I_2 / (I_1 + I_2))`` (the two-inertia
coupling mode), bearing ``q_y = 2 zeta sqrt(k_y m)``, mesh ``q_mb = 2 zeta sqrt(k_rep m_e)`` with
``m_e = I_p I_g / (I_p r_b2^2 + I_g r_b1^2)`` and ``k_rep`` the mean of the stiffness map over one
period at the static operating centre distance (the same for model I and model II, so the two
models differ only in their stiffness).

Load laws (:class:`TorqueLaw`): constant, linear viscous ``c w``, quadratic ``c w |w|``,
tabulated (linear interpolation, constant beyond the ends) and, for the input, an induction motor
(Kloss) curve. When ``case.load.coefficient`` is not given, the output law is calibrated so that
the steady state runs at ``case.load.speed`` (the paper's mean pinion speed 114.14 rad/s):
``T_out(w_g) = N r_b2 - q_stg w_g`` with ``N = (T_in - q_stp w_p) / r_b1``. A given coefficient (or
a table) takes precedence; the steady speed then follows from the torque balance.

References
----------
Xue, S. & Howard, I. (2018). Dynamic modelling of flexibly supported gears using iterative
convergence of tooth mesh stiffness. Mech. Syst. Signal Process. (eqs. 4, 9-17, appendix B).
Chaari, F., Bartelmus, W., Zimroz, R., Fakhfakh, T. & Haddar, M. (2012). Gearbox vibration signal
amplitude and frequency modulation. Shock Vib. 19(4), 635-652 (I_m, I_out, k_cp, k_cg defaults).
Kloss, M. (1910); see e.g. Fitzgerald, Kingsley & Umans, Electric Machinery, 6th ed., ch. 6
(induction motor torque-slip curve ``T = 2 T_b / (s/s_b + s_b/s)``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..geometry import GearPair, check_static_contact

__all__ = [
    "TorqueLaw",
    "DynamicModel",
    "StaticState",
    "static_equilibrium",
    "natural_frequencies",
    "max_time_step",
    "check_time_step",
    "operating_arrays",
    "MIN_STEPS_PER_PERIOD",
    "MODELS",
]

#: The models :func:`geardyn.dynamics.simulate` runs. ``"I"``: ``K(theta)`` at the design centre
#: distance; ``"I-static"``: ``K(theta)`` at the static operating centre distance of eq. 4 (the
#: bearings deflected by the static mesh force), held fixed during the run; ``"II"``:
#: ``K(theta, d(t))`` with the centre distance iterated at every step (the paper's Fig. 7).
MODELS = ("I", "I-static", "II")

#: Fewest time steps per period of the highest natural frequency (and of the mesh) accepted.
#: Average-acceleration Newmark is unconditionally stable, so this is an accuracy limit: its period
#: error is ``(omega dt)^2 / 12``, 3.3 % at 10 steps a period; coarser steps distort the mode the
#: tooth handovers excite most. ``docs/verification/dynamics.md`` recommends 15 or more.
MIN_STEPS_PER_PERIOD = 10

_LAW_CODES = {"constant": 0, "linear": 1, "quadratic": 2, "table": 3, "induction": 4}


# ----------------------------------------------------------------------------- torque laws
@dataclass(frozen=True)
class TorqueLaw:
    r"""A torque-speed law ``T(w)`` [N m] of the input (driving) or output (resisting) rotor.

    Parameters
    ----------
    kind : {"constant", "linear", "quadratic", "table", "induction"}
        ``T = c`` [N m]; ``T = c w`` (c in N m s/rad); ``T = c w |w|`` (c in N m s^2/rad^2);
        linear interpolation in ``(speeds, torques)`` with constant values beyond the ends; or
        the Kloss curve ``T = 2 T_b s s_b / (s^2 + s_b^2)``, ``s = (w_s - w) / w_s``.
    coefficient : float
        ``c`` of the constant, linear and quadratic laws.
    speeds, torques : ndarray, optional
        Table law [rad/s], [N m]; speeds strictly increasing.
    synchronous_speed, breakdown_torque, breakdown_slip : float, optional
        Induction law: ``w_s`` [rad/s], ``T_b`` [N m], ``s_b`` [-].
    """

    kind: str
    coefficient: float = 0.0
    speeds: np.ndarray | None = None
    torques: np.ndarray | None = None
    synchronous_speed: float = 0.0
    breakdown_torque: float = 0.0
    breakdown_slip: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in _LAW_CODES:
            raise InputError("law", self.kind, ", ".join(_LAW_CODES))
        if self.kind == "table":
            w, t = self.speeds, self.torques
            if w is None or t is None or len(w) != len(t) or len(w) < 2 \
                    or np.any(np.diff(w) <= 0):
                raise InputError("table", (w, t), "speeds strictly increasing and torques of the "
                                                  "same length >= 2")
        if self.kind == "induction" and not (self.synchronous_speed > 0
                                             and self.breakdown_torque > 0
                                             and 0 < self.breakdown_slip < 1):
            raise InputError("induction", (self.synchronous_speed, self.breakdown_torque,
                                           self.breakdown_slip),
                             "synchronous speed > 0, breakdown torque > 0, 0 < slip < 1")

    @property
    def code(self) -> int:
        """Integer code of the law in the compiled kernel."""
        return _LAW_CODES[self.kind]

    @property
    def nonlinear(self) -> bool:
        """Whether ``T`` is not affine in ``w`` (the kernel then iterates it within a step)."""
        return self.kind in ("quadratic", "table", "induction")

    def params(self) -> tuple[float, float, float]:
        """The three float parameters the kernel reads (see :func:`_kernel.law_torque`)."""
        if self.kind == "induction":
            return self.synchronous_speed, self.breakdown_torque, self.breakdown_slip
        return self.coefficient, 0.0, 0.0

    def table(self) -> tuple[np.ndarray, np.ndarray]:
        """Table arrays for the kernel (two dummy points for the other laws)."""
        if self.kind == "table":
            return (np.ascontiguousarray(self.speeds, dtype=float),
                    np.ascontiguousarray(self.torques, dtype=float))
        return np.array([0.0, 1.0]), np.array([0.0, 0.0])

    def torque(self, omega):
        """``T(w)`` [N m] for speeds ``w`` [rad/s] (vectorised)."""
        w = np.asarray(omega, dtype=float)
        if self.kind == "constant":
            out = np.full_like(w, self.coefficient)
        elif self.kind == "linear":
            out = self.coefficient * w
        elif self.kind == "quadratic":
            out = self.coefficient * w * np.abs(w)
        elif self.kind == "table":
            out = np.interp(w, self.speeds, self.torques)
        else:
            s = (self.synchronous_speed - w) / self.synchronous_speed
            sb = self.breakdown_slip
            out = 2.0 * self.breakdown_torque * s * sb / (s * s + sb * sb)
        return out if out.ndim else float(out)

    def slope(self, omega: float) -> float:
        """``dT/dw`` [N m s/rad] at ``w`` (the segment slope for a table, right-sided at nodes)."""
        w = float(omega)
        if self.kind == "constant":
            return 0.0
        if self.kind == "linear":
            return self.coefficient
        if self.kind == "quadratic":
            return 2.0 * self.coefficient * abs(w)
        if self.kind == "table":
            sp, tq = np.asarray(self.speeds), np.asarray(self.torques)
            if w < sp[0] or w >= sp[-1]:
                return 0.0
            i = int(np.searchsorted(sp, w, side="right") - 1)
            return float((tq[i + 1] - tq[i]) / (sp[i + 1] - sp[i]))
        ws, tb, sb = self.synchronous_speed, self.breakdown_torque, self.breakdown_slip
        s = (ws - w) / ws
        dtds = 2.0 * tb * sb * (sb * sb - s * s) / (s * s + sb * sb) ** 2
        return -dtds / ws

    def describe(self) -> str:
        """One line for reports and output attributes."""
        if self.kind == "constant":
            return f"constant T = {self.coefficient:.6g} N m"
        if self.kind == "linear":
            return f"linear T = {self.coefficient:.6g} N m s/rad * w"
        if self.kind == "quadratic":
            return f"quadratic T = {self.coefficient:.6g} N m s^2/rad^2 * w|w|"
        if self.kind == "table":
            return f"table of {len(self.speeds)} points, {self.speeds[0]:.6g}..{self.speeds[-1]:.6g} rad/s"
        return (f"induction (Kloss) w_s = {self.synchronous_speed:.6g} rad/s, "
                f"T_b = {self.breakdown_torque:.6g} N m, s_b = {self.breakdown_slip:.6g}")


def _input_law(case) -> TorqueLaw:
    m = case.motor
    if m.law == "induction":
        return TorqueLaw("induction", synchronous_speed=m.synchronous_speed,
                         breakdown_torque=m.breakdown_torque, breakdown_slip=m.breakdown_slip)
    return TorqueLaw("constant", coefficient=m.torque)


# ----------------------------------------------------------------------------- the model
@dataclass(frozen=True)
class DynamicModel:
    r"""Parameters of the 6-DOF model as floats and arrays (SI), built from a case.

    Attributes
    ----------
    pair : GearPair
        Geometry.
    r_b1, r_b2 : float
        Base radii [m].
    M, K0, C0 : ndarray, shape (6, 6)
        Mass [kg, kg m^2], stiffness without the mesh [N/m, N m/rad] and damping without the mesh
        [N s/m, N m s/rad] (appendix B with ``h = 0``; ``C0`` holds ``q_stp`` and ``q_stg``).
    g : ndarray, shape (6,)
        Mesh vector ``[0, 1, r_b1, -1, -r_b2, 0]`` [-, -, m, -, m, -].
    q_mb : float
        Mesh damping [N s/m].
    mesh_damping_ratio : float or None
        The ratio ``q_mb`` was set from (``None`` when the case gives ``q_mb``).
    k_rep : float
        Representative mesh stiffness (mean of the map at the static operating point) [N/m].
    m_e : float
        Equivalent mass of the torsional mesh mode ``I_p I_g / (I_p r_b2^2 + I_g r_b1^2)`` [kg].
    input_law, output_law : TorqueLaw
        ``T_in(w_m)`` and ``T_out(w_out)``.
    speed : float
        Steady (target) mean pinion speed [rad/s].
    ratio : float
        Gear speed over pinion speed, ``r_b1 / r_b2`` (= z1/z2) [-].
    output_calibrated : bool
        Whether the output law's coefficient was calibrated to ``case.load.speed``.
    damping : dict
        Every damping value used, by name (``q_cp``, ``q_cg``, ``q_yp``, ``q_yg``, ``q_stp``,
        ``q_stg``, ``q_mb``) [SI].
    """

    pair: GearPair
    r_b1: float
    r_b2: float
    M: np.ndarray
    K0: np.ndarray
    C0: np.ndarray
    g: np.ndarray
    q_mb: float
    mesh_damping_ratio: float | None
    k_rep: float
    m_e: float
    input_law: TorqueLaw
    output_law: TorqueLaw
    speed: float
    ratio: float
    output_calibrated: bool
    damping: dict = field(default_factory=dict)

    @property
    def gear_speed(self) -> float:
        """Steady gear (and load) speed ``w_p r_b1 / r_b2`` [rad/s]."""
        return self.speed * self.ratio

    @property
    def reference_direction(self) -> np.ndarray:
        """Rigid rotation ``e`` with ``g^T e = 0`` and ``K0 e = 0``: ``[1, 0, 1, 0, r, r]``,
        ``r = r_b1/r_b2``; the reference motion is ``x_ref = w_p t e``."""
        r = self.ratio
        return np.array([1.0, 0.0, 1.0, 0.0, r, r])

    @classmethod
    def from_case(cls, case, stiffness_map) -> DynamicModel:
        """Build the model of ``case``; ``stiffness_map`` gives ``k_rep`` for the mesh damping.

        Raises
        ------
        InputError
            If the load laws admit no steady state, or the calibration is impossible.
        """
        pair = case.gear_pair()
        rb1, rb2 = pair.pinion.base_radius, pair.gear.base_radius
        Im, Io = case.motor.inertia, case.load.inertia
        p, gr = case.pinion, case.gear
        Ip, Ig, mp, mg = p.inertia, gr.inertia, p.mass, gr.mass
        kcp, kcg = case.input_coupling.stiffness, case.output_coupling.stiffness
        kyp, kyg = p.bearing_stiffness, gr.bearing_stiffness

        def coupling_damping(cfg, i1, i2):
            if cfg.damping is not None:
                return cfg.damping
            return 2.0 * cfg.damping_ratio * math.sqrt(cfg.stiffness * i1 * i2 / (i1 + i2))

        def bearing_damping(gc):
            if gc.bearing_damping is not None:
                return gc.bearing_damping
            return 2.0 * gc.bearing_damping_ratio * math.sqrt(gc.bearing_stiffness * gc.mass)

        qcp = coupling_damping(case.input_coupling, Im, Ip)
        qcg = coupling_damping(case.output_coupling, Ig, Io)
        qyp, qyg = bearing_damping(p), bearing_damping(gr)
        qstp, qstg = p.torsional_damping, gr.torsional_damping

        M = np.diag([Im, mp, Ip, mg, Ig, Io]).astype(float)
        K0 = np.zeros((6, 6))
        C0 = np.zeros((6, 6))
        for mat, c_in, c_out, b_p, b_g, s_p, s_g in ((K0, kcp, kcg, kyp, kyg, 0.0, 0.0),
                                                     (C0, qcp, qcg, qyp, qyg, qstp, qstg)):
            mat[0, 0] += c_in
            mat[0, 2] -= c_in
            mat[2, 0] -= c_in
            mat[2, 2] += c_in + s_p
            mat[1, 1] += b_p
            mat[3, 3] += b_g
            mat[4, 4] += c_out + s_g
            mat[4, 5] -= c_out
            mat[5, 4] -= c_out
            mat[5, 5] += c_out
        g = np.array([0.0, 1.0, rb1, -1.0, -rb2, 0.0])
        ratio = rb1 / rb2

        law_in = _input_law(case)
        law_out, speed, calibrated = _output_law_and_speed(case, law_in, rb1, rb2, qstp, qstg)

        # static mesh force and centre distance -> representative mesh stiffness
        n_static = (float(law_in.torque(speed)) - qstp * speed) / rb1
        dd_static = _static_dd(pair, n_static, kyp, kyg)
        k_rep = map_mean(stiffness_map, dd_static)
        m_e = Ip * Ig / (Ip * rb2 ** 2 + Ig * rb1 ** 2)
        if case.mesh.damping is not None:
            q_mb, ratio_mb = case.mesh.damping, None
        else:
            ratio_mb = case.mesh.damping_ratio
            q_mb = 2.0 * ratio_mb * math.sqrt(k_rep * m_e)
        damping = {"q_cp": qcp, "q_cg": qcg, "q_yp": qyp, "q_yg": qyg, "q_stp": qstp,
                   "q_stg": qstg, "q_mb": q_mb}
        return cls(pair=pair, r_b1=rb1, r_b2=rb2, M=M, K0=K0, C0=C0, g=g, q_mb=q_mb,
                   mesh_damping_ratio=ratio_mb, k_rep=k_rep, m_e=m_e, input_law=law_in,
                   output_law=law_out, speed=speed, ratio=ratio, output_calibrated=calibrated,
                   damping=damping)

    def forcing_at_reference(self) -> tuple[np.ndarray, float, float]:
        r"""Constant forcing of the deviation equations and the load-law slopes.

        With ``x = x_ref + z`` (``x_ref = w t e``, a rigid rotation at the steady speed, which
        ``K0`` and ``g`` annihilate), the equations become
        ``M z'' + (C0 + D) z' + K0 z + N g = Q0 + q(z')``, where ``D = diag(-T_in', 0, 0, 0, 0,
        T_out')`` linearises the laws at the reference speeds and ``q`` is the (zero for affine
        laws) remainder.

        Returns
        -------
        Q0 : ndarray, shape (6,)
            ``F(v_ref) - C0 v_ref`` [N m, N].
        d_in, d_out : float
            ``-dT_in/dw`` and ``dT_out/dw`` at the reference speeds [N m s/rad].
        """
        w, wg = self.speed, self.gear_speed
        v_ref = w * self.reference_direction
        F = np.zeros(6)
        F[0] = float(self.input_law.torque(w))
        F[5] = -float(self.output_law.torque(wg))
        Q0 = F - self.C0 @ v_ref
        return Q0, -self.input_law.slope(w), self.output_law.slope(wg)

    def mesh_stiffness_bounds(self, stiffness_map) -> tuple[float, float]:
        """Smallest and largest ``k_mb`` of the map [N/m]."""
        return float(np.min(stiffness_map.k_mb)), float(np.max(stiffness_map.k_mb))


def map_mean(stiffness_map, dd: float, n: int = 4096) -> float:
    """Mean of ``k_mb(theta, dd)`` over the map's period [N/m] (``dd`` clipped to its range)."""
    lo, hi = float(stiffness_map.dd[0]), float(stiffness_map.dd[-1])
    d = min(max(dd, lo), hi)
    th = (np.arange(n) + 0.5) * stiffness_map.period / n
    return float(np.mean(stiffness_map(th, np.full(n, d))))


def _mm(v: float) -> str:
    """A length in mm for messages: four decimals, or 4 significant digits when absurd."""
    x = v * 1e3
    return f"{x:.4f}" if abs(x) < 1e9 else f"{x:.4g}"


def _static_dd(pair: GearPair, mesh_force: float, kyp: float, kyg: float) -> float:
    """Centre distance change [m] with the bearings deflected by the mesh force (eq. 4)."""
    yp, yg = -mesh_force / kyp, mesh_force / kyg
    return math.hypot(pair.base_radius_sum, pair.design_t1t2 + yg - yp) \
        - pair.design_centre_distance


def _output_law_and_speed(case, law_in: TorqueLaw, rb1: float, rb2: float, qstp: float,
                          qstg: float) -> tuple[TorqueLaw, float, bool]:
    """The output law (calibrated when its coefficient is not given) and the steady speed."""
    load = case.load
    ratio = rb1 / rb2

    def output_torque_needed(w: float) -> float:
        n = (float(law_in.torque(w)) - qstp * w) / rb1
        return n * rb2 - qstg * w * ratio

    if load.law == "table":
        law = TorqueLaw("table", speeds=np.asarray(load.table_speeds, float),
                        torques=np.asarray(load.table_torques, float))
        return law, _solve_speed(law_in, law, ratio, qstp, qstg, load.speed, rb1), False
    if load.coefficient is not None:
        law = TorqueLaw(load.law, coefficient=load.coefficient)
        return law, _solve_speed(law_in, law, ratio, qstp, qstg, load.speed, rb1), False
    w = float(load.speed)
    if law_in.kind == "induction":
        s = (law_in.synchronous_speed - w) / law_in.synchronous_speed
        if not 0 < s < law_in.breakdown_slip:
            raise InputError("load.speed", w,
                             f"a speed on the stable branch of the induction motor curve, "
                             f"between {law_in.synchronous_speed * (1 - law_in.breakdown_slip):.6g}"
                             f" and {law_in.synchronous_speed:.6g} rad/s")
    t_out = output_torque_needed(w)
    wg = w * ratio
    if t_out <= 0:
        raise InputError("load.speed", w, "a speed at which the input torque exceeds the "
                                          "absolute torsional damping losses (q_stp, q_stg)")
    coef = {"constant": t_out, "linear": t_out / wg, "quadratic": t_out / (wg * wg)}[load.law]
    return TorqueLaw(load.law, coefficient=coef), w, True


def _solve_speed(law_in: TorqueLaw, law_out: TorqueLaw, ratio: float, qstp: float, qstg: float,
                 hint: float | None, rb1: float) -> float:
    """Steady pinion speed: the stable root of the torque balance (``f`` falls through zero)."""
    from scipy.optimize import brentq

    def f(w: float) -> float:
        return (float(law_in.torque(w)) - qstp * w
                - ratio * (float(law_out.torque(w * ratio)) + qstg * w * ratio))

    scale = abs(float(law_in.torque(hint if hint else 1.0))) + 1.0
    if law_in.kind == "constant" and law_out.kind == "constant" and qstp == 0 and qstg == 0:
        if abs(f(1.0)) > 1e-12 * scale:
            raise InputError("load.coefficient", law_out.coefficient,
                             f"a constant output torque equal to the transmitted input torque "
                             f"{law_in.coefficient / ratio:.6g} N m (constant laws have no other "
                             "steady state)")
        if hint is None:
            raise InputError("load.speed", None, "a speed (two constant torques balance at any "
                                                 "speed)")
        return float(hint)
    hi = law_in.synchronous_speed * (1 - 1e-9) if law_in.kind == "induction" else 1e5
    grid = np.geomspace(1e-3, hi, 4001)
    vals = np.array([f(w) for w in grid])
    idx = np.nonzero((vals[:-1] > 0) & (vals[1:] <= 0))[0]
    if idx.size == 0:
        raise InputError("load", law_out.describe(),
                         f"a load law that balances the input torque at some pinion speed in "
                         f"(0, {hi:.6g}] rad/s")
    i = idx[-1]
    return float(brentq(f, grid[i], grid[i + 1], xtol=1e-14, rtol=1e-15, maxiter=200))


# ----------------------------------------------------------------------------- static state
@dataclass(frozen=True)
class StaticState:
    """Static equilibrium at the steady speed (the start of every simulation).

    Attributes
    ----------
    speed, gear_speed : float
        Pinion and gear speeds [rad/s].
    input_torque, output_torque : float
        ``T_in(w)`` and ``T_out(w_g)`` [N m].
    mesh_force : float
        ``N = (T_in - q_stp w) / r_b1`` [N].
    y_p, y_g : float
        Bearing deflections ``-N/k_yp``, ``N/k_yg`` [m].
    centre_distance_change : float
        ``d' - d`` from eq. 4 [m].
    mesh_stiffness : float
        ``k_mb`` at the start (theta_p = 0, the model's centre distance) [N/m].
    mesh_deflection : float
        ``p = N / k_mb`` [m].
    transmission_error : float
        ``theta_p - (r_b2/r_b1) theta_g`` [rad].
    z : ndarray, shape (6,)
        Deviation from the rigid rotation at ``t = 0`` (the DOFs at ``t = 0``, with
        ``theta_p = 0``) [rad, m].
    """

    speed: float
    gear_speed: float
    input_torque: float
    output_torque: float
    mesh_force: float
    y_p: float
    y_g: float
    centre_distance_change: float
    mesh_stiffness: float
    mesh_deflection: float
    transmission_error: float
    z: np.ndarray


def static_equilibrium(model: DynamicModel, stiffness_map, *, which: str = "II",
                       theta0: float = 0.0) -> StaticState:
    r"""Static equilibrium at the steady speed, so a simulation starts without start-up impacts.

    ``T_cp = T_in(w)``, ``N = (T_cp - q_stp w)/r_b1``, ``y_p = -N/k_yp``, ``y_g = N/k_yg``,
    ``p = N/k_mb(theta0, dd)`` (``dd`` from eq. 4 for models II and I-static, 0 for model I),
    ``theta_m - theta_p = T_cp/k_cp``, ``theta_g - theta_out = T_cg/k_cg`` with
    ``T_cg = N r_b2 - q_stg w_g`` (``docs/verification/dynamics.md``).

    Parameters
    ----------
    model : DynamicModel
    stiffness_map : StiffnessMap
    which : {"I", "I-static", "II"}
        Model I evaluates the stiffness at the design centre distance (``dd = 0``); model
        I-static and model II at the static operating centre distance of eq. 4.
    theta0 : float
        Pinion angle at ``t = 0`` [rad].

    Raises
    ------
    InputError
        If ``which`` is not one of :data:`MODELS`, the mesh is not loaded (``N <= 0``) or the
        map does not cover the centre distance; for models I-static and II also (a
        ``GeometryError`` naming the softer bearing) if the bearings' static deflection leaves
        the teeth out of contact (:func:`geardyn.geometry.check_static_contact`).
    """
    if which not in MODELS:
        raise InputError("model", which, ", ".join(repr(m) for m in MODELS))
    w = model.speed
    t_in = float(model.input_law.torque(w))
    q = model.damping
    n = (t_in - q["q_stp"] * w) / model.r_b1
    if not n > 0:
        raise InputError("motor.torque", t_in, "a torque that loads the mesh (mesh force > 0)")
    kyp, kyg = model.K0[1, 1], model.K0[3, 3]
    yp, yg = -n / kyp, n / kyg
    dd = _static_dd(model.pair, n, kyp, kyg)
    dd_eval = 0.0 if which == "I" else dd
    if which != "I":  # model I reads the map at the design centre distance whatever dd is
        check_static_contact(model.pair, dd, n, kyp, kyg,
                             fields=("pinion.bearing_stiffness", "gear.bearing_stiffness"))
    if not stiffness_map.covers(dd_eval):
        raise InputError("stiffness.centre_distance_max" if dd_eval > stiffness_map.dd[-1]
                         else "stiffness.centre_distance_min",
                         f"map range [{stiffness_map.dd[0] * 1e3:.4g}, "
                         f"{stiffness_map.dd[-1] * 1e3:.4g}] mm",
                         f"a stiffness map covering the static centre distance change "
                         f"{_mm(dd_eval)} mm of model {which}")
    k0 = float(stiffness_map(theta0, dd_eval))
    if not k0 > 0:
        raise InputError("stiffness_map", k0, "a positive mesh stiffness at the start")
    p0 = n / k0
    t_cg = n * model.r_b2 - q["q_stg"] * model.gear_speed
    kcp, kcg = -model.K0[0, 2], -model.K0[4, 5]
    theta_p = theta0
    theta_g = (yp - yg + model.r_b1 * theta_p - p0) / model.r_b2
    z = np.array([theta_p + t_in / kcp, yp, theta_p, yg, theta_g, theta_g - t_cg / kcg])
    t_out = float(model.output_law.torque(model.gear_speed))
    return StaticState(speed=w, gear_speed=model.gear_speed, input_torque=t_in,
                       output_torque=t_out, mesh_force=n, y_p=yp, y_g=yg,
                       centre_distance_change=dd, mesh_stiffness=k0, mesh_deflection=p0,
                       transmission_error=theta_p - model.r_b2 / model.r_b1 * theta_g, z=z)


# ----------------------------------------------------------------------------- frequencies
def natural_frequencies(model: DynamicModel, k_mb: float) -> np.ndarray:
    """Undamped natural frequencies [Hz] of the linearised model with mesh stiffness ``k_mb``
    [N/m] (``K = K0 + k_mb g g^T``), ascending; the rigid-body mode gives 0."""
    from scipy.linalg import eigh

    lam = eigh(model.K0 + k_mb * np.outer(model.g, model.g), model.M, eigvals_only=True)
    return np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi)


def max_time_step(model: DynamicModel, stiffness_map) -> tuple[float, float, float]:
    """Largest accepted time step [s], with the highest natural frequency and the mesh frequency
    [Hz] it is based on (:data:`MIN_STEPS_PER_PERIOD` steps a period of either)."""
    f_max = float(natural_frequencies(model, float(np.max(stiffness_map.k_mb)))[-1])
    f_mesh = model.speed * model.pair.pinion.teeth / (2 * np.pi)
    f = max(f_max, f_mesh)
    return 1.0 / (MIN_STEPS_PER_PERIOD * f), f_max, f_mesh


def check_time_step(model: DynamicModel, stiffness_map, dt: float) -> None:
    """Refuse a time step with fewer than :data:`MIN_STEPS_PER_PERIOD` steps per period of the
    highest natural frequency (largest mesh stiffness of the map) or of the mesh.

    Raises
    ------
    InputError
        On ``simulation.dt``, naming the largest acceptable step.
    """
    dt_max, f_max, f_mesh = max_time_step(model, stiffness_map)
    if not (math.isfinite(dt) and 0 < dt <= dt_max * (1 + 1e-12)):
        raise InputError("simulation.dt", dt,
                         f"a time step <= {dt_max:.4g} s: at least {MIN_STEPS_PER_PERIOD} steps "
                         f"per period of the highest natural frequency {f_max:.5g} Hz (largest "
                         f"mesh stiffness {np.max(stiffness_map.k_mb):.4g} N/m) and of the mesh "
                         f"frequency {f_mesh:.5g} Hz; 15 or more is recommended")


# ----------------------------------------------------------------------------- geometry
def operating_arrays(pair: GearPair, dd) -> dict[str, np.ndarray]:
    """Operating pressure angle and contact ratios for centre distance changes ``dd`` [m].

    Vectorised eqs. 6 and 8 (the same formulas as :meth:`GearPair.operating`):
    ``alpha' = arccos((r_b1 + r_b2)/d')``, physical contact ratio ``(s_end - s_start)/p_b`` with
    ``s_start = T1T2 - sqrt(r_a2^2 - r_b2^2)``, and the paper's eq. 8 (``pi m cos alpha'`` in the
    denominator, erratum 2).

    Returns
    -------
    dict
        ``pressure_angle`` [rad], ``contact_ratio`` [-], ``contact_ratio_eq8`` [-].
    """
    d = pair.design_centre_distance + np.asarray(dd, float)
    rsum = pair.base_radius_sum
    with np.errstate(invalid="ignore"):
        alpha = np.arccos(rsum / d)
        t1t2 = np.sqrt(d * d - rsum * rsum)
    p, g = pair.pinion, pair.gear
    u1 = math.sqrt(p.tip_radius ** 2 - p.base_radius ** 2)
    u2 = math.sqrt(g.tip_radius ** 2 - g.base_radius ** 2)
    eps = (u1 - (t1t2 - u2)) / pair.base_pitch
    eps8 = (u1 + u2 - d * np.sin(alpha)) / (math.pi * pair.module * np.cos(alpha))
    return {"pressure_angle": alpha, "contact_ratio": eps, "contact_ratio_eq8": eps8}
