r"""Tooth geometry errors and tip relief: geometry only, a function of tooth and roll length.

What this module describes
--------------------------
Every deviation is a displacement of a flank *along the line of action* (LOA), positive when
material is **missing** (the flank lies behind its nominal involute, as seen by the mating flank),
so that it opens a gap. Eq. 15 of Xue & Howard (2018) becomes, for tooth pair ``j``,

.. math:: p_j = y_p + r_{b1}\theta_p - y_g - r_{b2}\theta_g - e_j, \qquad
          e_j = E_{1,i(j)}(u_1) + E_{2,k(j)}(u_2) + e_{run},

with ``u_1 = s`` and ``u_2 = T_1T_2 - s`` the roll lengths of the contact point on each gear
(``s`` along the LOA from ``T_1``; ``u = r_b phi``, ``phi`` the roll angle) and ``i(j) = n mod z1``,
``k(j) = n mod z2`` the teeth of pair ``n`` (:meth:`geardyn.geometry.GearPair.contact_points`).
Per gear and tooth ``E(u)`` is the sum of

* a single pitch / cumulative pitch deviation: tooth ``i`` displaced by ``P_i cos(alpha)`` along the
  LOA, ``P_i`` the cumulative pitch deviation on the reference circle [m]; the single pitch
  deviations are ``f_pt,i = P_i - P_{i-1}`` (cyclic, so they sum to zero) and the cumulative pitch
  deviation is ``F_p = max P - min P``;
* a profile slope deviation ``f_Halpha,i (xi - 1/2)`` and a profile form deviation
  ``(f_falpha,i / 2) sin(2 pi w xi + psi_i)`` (peak-to-valley ``f_falpha,i`` for ``w >= 1``), with
  ``xi = (u - u_SAP)/(u_tip - u_SAP)`` over the active profile at the design centre distance;
* tip relief ``C_a x^k``, ``x = (u - u_s)/(u_tip - u_s)`` for ``u > u_s`` (``k = 1`` linear,
  ``k = 2`` parabolic; ``u_s = r_b phi_s``, ``phi_s`` the roll angle where relief starts).

Runout (eccentricity ``epsilon`` of a gear's geometric centre, phase ``psi``) gives every pair the
same once-per-revolution ``e_run = epsilon_1 sin(theta_p + psi_1) + epsilon_2 sin(theta_g + psi_2)``
(its component along the LOA), and moves the contact pattern along the LOA by the same amount:
the stiffness map, the load shares and the pairs' roll positions are evaluated at the pinion
angle ``theta - e_run / r_b1`` (a rigid translation of a gear along the LOA slides its involutes'
intersections with the LOA exactly like a rotation ``delta / r_b``). That is the once-per-rev
modulation of ``e`` and of the mesh phase; its sidebands have the closed form of phase
modulation (``J_1(beta)/J_0(beta)`` with ``beta = h z1 epsilon / r_b1`` at mesh harmonic ``h``).

How the dynamics use it
-----------------------
With pair stiffnesses ``k_j = s_j k_mb`` (``s_j`` the map's load share), pairs with
``p + ... - e_j >= 0`` (judged on the free deflection of the step, like eq. 15's contact rule)
carry load and the mesh force is ``N = k_mb f (p - e_bar) + q_mb p'`` with
``f = sum_active s_j`` and ``e_bar = sum_active s_j e_j / f``: with every pair in contact, the
load-sharing-weighted error of the brief. Relief and errors thus also move where contact starts
under load. (Approximation: with a body compliance in series, ``s_j k_mb`` is not exactly each
pair's share of a reduced pair set; damping acts on ``p'`` only.)

ISO 1328-1:2013 tolerances
--------------------------
:func:`iso1328_tolerances` uses formulas (5)-(8) of ISO 1328-1:2013 with the step factor
``sqrt(2)^(A-5)`` and the rounding rules of 5.2.3, as written in two independent public
implementations found with the project's code search (a C# ``Iso1328Tolerance`` class of a
"MechanicalCalculatorWeb" service, search id 59227980784, and a Python ``Iso1328FlankTolerance``
rule, search id 70383590804; their repositories were not shown), which agree term by term; the
standard's own text was **not** read, so the formulas are checked only against those two and by
hand (``tests/modifications/test_tolerances_and_input.py``). The 2013 edition defines flank
tolerance classes 1-11 (BS ISO 1328-1:2013 catalogue abstract, pdfstandards.shop: "Eleven flank
tolerance classes are defined, numbered 1 to 11"), so a class outside 1-11 is refused. ISO's
runout tolerance was not found; runout is given as an amount.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .errors import InputError

__all__ = [
    "iso1328_tolerances",
    "GearDeviations",
    "ToothModifications",
    "draw_pitch_deviations",
    "ISO_CLASSES",
    "N_ROLL",
]

#: Flank tolerance classes of ISO 1328-1:2013.
ISO_CLASSES = (1, 11)
#: Roll-length nodes of each tooth's deviation table.
N_ROLL = 257

_SHAPES = {"linear": 1.0, "parabolic": 2.0}


def _iso_round(v_um: float) -> float:
    """ISO 1328-1:2013 5.2.3 rounding (micrometres): > 10 to 1, 5-10 to 0.5, < 5 to 0.1."""
    if v_um > 10.0:
        return float(math.floor(v_um + 0.5))
    if v_um >= 5.0:
        return float(math.floor(v_um * 2.0 + 0.5) / 2.0)
    return float(math.floor(v_um * 10.0 + 0.5) / 10.0)


def iso1328_tolerances(grade: int, reference_diameter: float, module: float, *,
                       rounded: bool = True, field_name: str = "grade") -> dict[str, float]:
    r"""Flank tolerances of ISO 1328-1:2013 for tolerance class ``grade`` [m].

    ``f_pT = (0.001 d + 0.4 m + 5) S``, ``F_pT = (0.002 d + 0.55 sqrt(d) + 0.7 m + 12) S``,
    ``f_HalphaT = (0.4 m + 0.001 d + 4) S``, ``f_falphaT = (0.55 m + 5) S`` in um with ``d`` and
    ``m`` in mm and ``S = sqrt(2)^(A - 5)`` (formulas 5-8; see the module docstring for what was
    read).

    Parameters
    ----------
    grade : int
        Flank tolerance class ``A``, 1-11.
    reference_diameter, module : float
        ``d = z m`` and the normal module [m].
    rounded : bool
        Apply the rounding rules of 5.2.3.
    field_name : str
        Name used in the error message.

    Returns
    -------
    dict
        ``single_pitch``, ``cumulative_pitch``, ``profile_slope``, ``profile_form`` [m].

    Raises
    ------
    InputError
        A class outside 1-11.
    """
    if isinstance(grade, bool) or not isinstance(grade, int | np.integer) \
            or not ISO_CLASSES[0] <= grade <= ISO_CLASSES[1]:
        raise InputError(field_name, grade, "an ISO 1328-1:2013 flank tolerance class, a whole "
                                            "number from 1 (finest) to 11")
    d, m = reference_diameter * 1e3, module * 1e3
    s = math.sqrt(2.0) ** (int(grade) - 5)
    vals = {"single_pitch": (0.001 * d + 0.4 * m + 5.0) * s,
            "cumulative_pitch": (0.002 * d + 0.55 * math.sqrt(d) + 0.7 * m + 12.0) * s,
            "profile_slope": (0.4 * m + 0.001 * d + 4.0) * s,
            "profile_form": (0.55 * m + 5.0) * s}
    return {k: (_iso_round(v) if rounded else v) * 1e-6 for k, v in vals.items()}


def draw_pitch_deviations(rng: np.random.Generator, teeth: int, single: float,
                          cumulative: float) -> np.ndarray:
    """Cumulative pitch deviations ``P_i`` [m] of ``teeth`` teeth with ``max P - min P`` equal
    to ``cumulative`` [m]: a once-per-revolution sine of random phase (the long-wave part) plus a
    closed random walk of single steps within ``+-single/2`` (the short-wave part); the sine's
    amplitude is found by bisection. ``P`` has zero mean."""
    i = np.arange(teeth)
    steps = rng.uniform(-1.0, 1.0, teeth)
    steps -= steps.mean()
    walk = np.cumsum(steps)
    walk *= 0.5 * single / max(np.max(np.abs(steps)), 1e-300)
    if cumulative <= 0:
        return np.zeros(teeth)
    if np.ptp(walk) > 0.5 * cumulative:
        walk *= 0.5 * cumulative / np.ptp(walk)
    wave = np.sin(2 * np.pi * i / teeth + rng.uniform(0, 2 * np.pi))
    lo, hi = 0.0, cumulative
    while np.ptp(hi * wave + walk) < cumulative:
        hi *= 2.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if np.ptp(mid * wave + walk) < cumulative:
            lo = mid
        else:
            hi = mid
    p = hi * wave + walk
    p *= cumulative / np.ptp(p)  # remove the bisection's last rounding
    return p - p.mean()


@dataclass(frozen=True)
class GearDeviations:
    """Deviations of the flanks of one gear (all lengths in m, along the LOA unless stated).

    Attributes
    ----------
    teeth : int
    base_radius : float
        ``r_b`` [m].
    u_sap, u_tip : float
        Roll lengths of the start of the active profile (design centre distance) and of the tip.
    pitch : ndarray, shape (teeth,)
        Cumulative pitch deviation ``P_i`` on the reference circle [m].
    slope, form, form_phase : ndarray, shape (teeth,)
        Profile slope ``f_Halpha,i`` and form ``f_falpha,i`` [m], form phase ``psi_i`` [rad].
    form_waves : float
        Waves of the form deviation over the active profile [-].
    pressure_angle : float
        ``alpha`` converting pitch deviations to the LOA [rad].
    relief, relief_start, relief_shape
        Tip relief amount ``C_a`` [m], start roll length ``u_s`` [m], ``"linear"`` or
        ``"parabolic"``.
    runout, runout_phase : float
        Eccentricity ``epsilon`` [m] and its phase ``psi`` [rad].
    source : str
        Where the deviations come from (grade and seed, a table, none).
    tolerances : dict
        The ISO tolerances used [m] (empty for tables).
    """

    teeth: int
    base_radius: float
    u_sap: float
    u_tip: float
    pitch: np.ndarray
    slope: np.ndarray
    form: np.ndarray
    form_phase: np.ndarray
    form_waves: float = 2.0
    pressure_angle: float = math.radians(20)
    relief: float = 0.0
    relief_start: float = 0.0
    relief_shape: str = "linear"
    runout: float = 0.0
    runout_phase: float = 0.0
    source: str = "none"
    tolerances: dict = field(default_factory=dict)
    #: Wear faults of the ``faults`` list (:class:`geardyn.faults.Wear`) on this gear's teeth, as
    #: ``(tooth, Wear, r_b [m])``: the deviation ``Wear.deviation(u / r_b)`` at roll length
    #: ``u`` of that tooth, added to its table.
    wear: tuple = ()

    # ------------------------------------------------------------------ tables
    @property
    def u_lo(self) -> float:
        """First roll length of the table [m] (a quarter of the active profile below SAP)."""
        return max(0.0, self.u_sap - 0.25 * (self.u_tip - self.u_sap))

    @property
    def du(self) -> float:
        """Table spacing [m]."""
        return (self.u_tip - self.u_lo) / (N_ROLL - 1)

    @property
    def has_table(self) -> bool:
        """Whether any per-tooth deviation is non-zero."""
        return bool(np.any(self.pitch) or np.any(self.slope) or np.any(self.form)
                    or any(not w[1].is_null() for w in self.wear))

    @property
    def has_relief(self) -> bool:
        return self.relief > 0.0

    def single_pitch(self) -> np.ndarray:
        """Single pitch deviations ``f_pt,i = P_i - P_{i-1}`` [m] (cyclic)."""
        return self.pitch - np.roll(self.pitch, 1)

    def cumulative_pitch(self) -> float:
        """Total cumulative pitch deviation ``F_p = max P - min P`` [m]."""
        return float(np.ptp(self.pitch))

    def table(self) -> np.ndarray:
        """Per-tooth deviation (pitch, slope, form) on ``u_lo + du * arange(N_ROLL)``,
        shape ``(teeth, N_ROLL)`` [m]; constant beyond the ends when interpolated."""
        u = self.u_lo + self.du * np.arange(N_ROLL)
        tab = self.profile_exact(np.arange(self.teeth)[:, None], u[None, :])
        for tooth, fault, rb in self.wear:  # sampled at the nodes: edges ramp over du
            tab[int(tooth) % self.teeth] += fault.deviation(u / rb)
        return tab

    def profile_exact(self, tooth, u) -> np.ndarray:
        """Pitch + slope + form deviation of ``tooth`` at roll length ``u`` [m] (closed form,
        no relief)."""
        tooth = np.asarray(tooth)
        xi = (np.asarray(u, float) - self.u_sap) / (self.u_tip - self.u_sap)
        return (self.pitch[tooth] * math.cos(self.pressure_angle)
                + self.slope[tooth] * (xi - 0.5)
                + 0.5 * self.form[tooth] * np.sin(2 * np.pi * self.form_waves * xi
                                                   + self.form_phase[tooth]))

    def relief_at(self, u) -> np.ndarray:
        """Tip relief at roll length ``u`` [m] (0 below the start)."""
        u = np.asarray(u, float)
        if not self.has_relief:
            return np.zeros(u.shape)
        x = np.clip((u - self.relief_start) / (self.u_tip - self.relief_start), 0.0, None)
        return self.relief * x ** _SHAPES[self.relief_shape]

    def deviation(self, tooth, u) -> np.ndarray:
        """Flank deviation of ``tooth`` at roll length ``u`` as the dynamics see it: the table
        interpolated linearly (``numpy.interp``, constant beyond the ends) plus the relief [m]."""
        tooth, u = np.broadcast_arrays(np.asarray(tooth), np.asarray(u, float))
        out = self.relief_at(u)
        if self.has_table:
            grid = self.u_lo + self.du * np.arange(N_ROLL)
            tab = self.table()
            flat_t, flat_u = tooth.ravel(), u.ravel()
            vals = np.array([np.interp(uu, grid, tab[int(t) % self.teeth])
                             for t, uu in zip(flat_t, flat_u, strict=True)])
            out = out + vals.reshape(u.shape)
        return out


def _zero_gear(pair, which: str) -> GearDeviations:
    g = pair.pinion if which == "pinion" else pair.gear
    op = pair.operating(0.0, check=False)
    u_tip = math.sqrt(g.tip_radius ** 2 - g.base_radius ** 2)
    u_sap = op.s_start if which == "pinion" else op.t1t2 - op.s_end
    z = np.zeros(g.teeth)
    return GearDeviations(teeth=g.teeth, base_radius=g.base_radius, u_sap=u_sap, u_tip=u_tip,
                          pitch=z, slope=z.copy(), form=z.copy(), form_phase=z.copy(),
                          pressure_angle=pair.pinion.pressure_angle)


def _gear_from_config(pair, which: str, cfg, prefix: str) -> GearDeviations:
    base = _zero_gear(pair, which)
    if cfg is None:
        return base
    g = pair.pinion if which == "pinion" else pair.gear
    z = g.teeth
    kw: dict = {}
    tol: dict = {}
    source = []
    if cfg.grade is not None:
        tol = iso1328_tolerances(cfg.grade, g.pitch_radius * 2, g.module,
                                 field_name=f"{prefix}.grade")
        rng = np.random.default_rng([int(cfg.seed), 0 if which == "pinion" else 1])
        frac = cfg.fraction
        kw["pitch"] = draw_pitch_deviations(rng, z, frac * tol["single_pitch"],
                                            frac * tol["cumulative_pitch"])
        kw["slope"] = frac * tol["profile_slope"] * rng.uniform(-1.0, 1.0, z)
        kw["form"] = frac * tol["profile_form"] * rng.uniform(0.0, 1.0, z)
        kw["form_phase"] = rng.uniform(0.0, 2 * np.pi, z)
        source.append(f"ISO 1328-1:2013 class {cfg.grade}, fraction {frac:g}, seed {cfg.seed}")
    for name, key in (("pitch", "cumulative_pitch"), ("slope", "profile_slope"),
                      ("form", "profile_form")):
        table = getattr(cfg, key)
        if table is not None:
            arr = np.asarray(table, float)
            if arr.shape != (z,) or not np.all(np.isfinite(arr)):
                raise InputError(f"{prefix}.{key}", f"{arr.size} values",
                                 f"one finite value per tooth ({z}) [m]")
            if name == "form" and np.any(arr < 0):
                raise InputError(f"{prefix}.{key}", float(arr.min()),
                                 "peak-to-valley values >= 0 [m]")
            kw[name] = arr
            source.append(f"{key} table")
    if cfg.tip_relief > 0:
        phi_tip = base.u_tip / g.base_radius
        if cfg.relief_start is None:
            # default: the highest point of single tooth contact at the design centre distance
            op = pair.operating(0.0, check=False)
            u_s = (op.s_start + pair.base_pitch if which == "pinion"
                   else op.t1t2 - (op.s_end - pair.base_pitch))
        else:
            u_s = cfg.relief_start * g.base_radius
            if not 0.0 <= cfg.relief_start < phi_tip:
                raise InputError(f"{prefix}.relief_start", f"{math.degrees(cfg.relief_start):.6g} deg",
                                 f"a roll angle in [0, {math.degrees(phi_tip):.6g}) deg (the tip "
                                 f"roll angle of the {which})")
        kw.update(relief=float(cfg.tip_relief), relief_start=float(u_s),
                  relief_shape=cfg.relief_shape)
        source.append(f"{cfg.relief_shape} tip relief")
    if cfg.runout > 0:
        kw.update(runout=float(cfg.runout), runout_phase=float(cfg.runout_phase))
        source.append("runout")
    return GearDeviations(**{**base.__dict__, **kw, "form_waves": float(cfg.form_waves),
                             "source": "; ".join(source) or "none", "tolerances": tol})


@dataclass(frozen=True)
class ToothModifications:
    """Deviations of both gears of a pair, and their effect on the mesh (see module docstring).

    Build with :meth:`from_case` (the case's ``[modifications]`` section) or :meth:`none`.
    """

    pair: object
    pinion: GearDeviations
    gear: GearDeviations

    @classmethod
    def none(cls, pair) -> ToothModifications:
        """Perfect involutes."""
        return cls(pair, _zero_gear(pair, "pinion"), _zero_gear(pair, "gear"))

    @classmethod
    def from_case(cls, case) -> ToothModifications:
        """From ``case.modifications`` (absent: perfect involutes).

        Raises
        ------
        InputError
            A class outside 1-11, a table of the wrong length, a relief start off the flank.
        """
        pair = case.gear_pair()
        cfg = getattr(case, "modifications", None)
        if cfg is None:
            out = cls.none(pair)
        else:
            out = cls(pair,
                      _gear_from_config(pair, "pinion", cfg.pinion, "modifications.pinion"),
                      _gear_from_config(pair, "gear", cfg.gear, "modifications.gear"))
        return out._with_wear(case)

    def _with_wear(self, case) -> ToothModifications:
        """Add the ``faults`` list's wear (:class:`geardyn.faults.Wear`, a depth over a roll
        window of one tooth, uniform or by Archard's law: a profile deviation,
        :mod:`geardyn.faults.wear`) to the deviation tables, so the dynamics and the static TE see
        the worn tooth's gap."""
        if not getattr(case, "faults", None):
            return self
        from .faults import Wear, faults_from_case

        wear = [f for f in faults_from_case(case, legacy_crack=False)
                if isinstance(f, Wear) and not f.is_null()]
        if not wear:
            return self
        gears = {"pinion": self.pinion, "gear": self.gear}
        for f in wear:
            g = gears[f.gear]
            entry = (int(f.tooth), f, float(g.base_radius))  # roll length u = r_b * roll
            law = "" if f.law == "uniform" else f", {f.law} profile, largest"
            src = f"wear of tooth {f.tooth} ({f.depth * 1e6:.4g} um{law})"
            gears[f.gear] = replace(g, wear=(*g.wear, entry),
                                    source=src if g.source == "none" else f"{g.source}; {src}")
        return ToothModifications(self.pair, gears["pinion"], gears["gear"])

    @property
    def active(self) -> bool:
        """Whether anything differs from perfect involutes."""
        return any(g.has_table or g.has_relief or g.runout > 0 for g in (self.pinion, self.gear))

    @property
    def has_runout(self) -> bool:
        return self.pinion.runout > 0 or self.gear.runout > 0

    @property
    def hunting_period(self) -> float:
        """Pinion angle after which the tooth pairing repeats, ``lcm(z1, z2) 2 pi / z1`` [rad]."""
        z1, z2 = self.pinion.teeth, self.gear.teeth
        return math.lcm(z1, z2) * 2 * math.pi / z1

    def describe(self) -> str:
        """One line for output attributes."""
        return f"pinion: {self.pinion.source}; gear: {self.gear.source}"

    # ------------------------------------------------------------------ evaluation
    def runout_error(self, theta) -> np.ndarray:
        """``e_run`` [m] at pinion angles ``theta`` [rad] (gear angle ``theta z1/z2``)."""
        th = np.asarray(theta, float)
        r = self.pinion.teeth / self.gear.teeth
        return (self.pinion.runout * np.sin(th + self.pinion.runout_phase)
                + self.gear.runout * np.sin(th * r + self.gear.runout_phase))

    def pair_errors(self, theta, centre_distance_change: float = 0.0) -> dict[str, np.ndarray]:
        """The three load-share slots' pairs at pinion angles ``theta`` [rad].

        Returns
        -------
        dict
            ``theta_eff`` (n,) pinion angle of the contact pattern [rad]; ``pair`` (n, 3);
            ``s`` (n, 3) [m]; ``in_contact`` (n, 3) bool; ``e`` (n, 3) each pair's ``e_j`` [m]
            (runout included); ``runout`` (n,) [m].
        """
        pair = self.pair
        th = np.atleast_1d(np.asarray(theta, float))
        run = self.runout_error(th)
        th_eff = th - run / pair.pinion.base_radius
        op = pair.operating(float(centre_distance_change), check=False)
        pb, rb1 = pair.base_pitch, pair.pinion.base_radius
        s_th = pair.pitch_point_s + rb1 * th_eff
        n_exit = np.floor((s_th - op.s_end) / pb)
        n = (n_exit[:, None] + 1 + np.arange(3)[None, :]).astype(np.int64)
        s = s_th[:, None] - n * pb
        inc = s >= op.s_start - 1e-12
        e = (self.pinion.deviation(np.mod(n, self.pinion.teeth), s)
             + self.gear.deviation(np.mod(n, self.gear.teeth), op.t1t2 - s) + run[:, None])
        return {"theta_eff": th_eff, "pair": n, "s": s, "in_contact": inc, "e": e,
                "runout": run}

    def shares(self, stiffness_map, theta_eff, centre_distance_change, in_contact):
        """Load shares of the slots ``(n, 3)`` from the map (equal shares of the pairs in
        contact when the map has none).

        The map's compiled look-up (:meth:`geardyn.stiffness.StiffnessMap.__call__`). Until
        2026-11-28 this read the map through its pure-NumPy twin
        (:func:`geardyn.stiffness.map.lookup_reference`, the tests' oracle), about 400 times
        slower: 11 of the 16 s (cProfile) of a static TE over 23,000 angles
        (``tests/faults/test_wear_archard.py``). ``tests/modifications/test_static_te.py``
        compares the two.
        """
        th = np.asarray(theta_eff, float)
        if "load_share" in getattr(stiffness_map, "extra", {}):
            dd = float(centre_distance_change)  # (the map broadcasts it over theta)
            return np.stack([np.asarray(stiffness_map(th, dd, "load_share", k), float)
                             for k in range(3)], axis=-1)
        cnt = np.maximum(in_contact.sum(axis=-1, keepdims=True), 1)
        return in_contact / cnt

    def kernel_arrays(self, stiffness_map) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                    np.ndarray, np.ndarray]:
        """``(eip, efp, table_pinion, table_gear, shares)`` for the compiled kernel (see
        :mod:`geardyn.dynamics._kernel`)."""
        from .dynamics import _kernel as K

        pair = self.pair
        op = pair.operating(0.0, check=False)
        eip = np.zeros(K.N_EIP, dtype=np.int64)
        efp = np.zeros(K.N_EFP)
        eip[K.EI_ACTIVE] = int(self.active)
        eip[K.EI_Z1], eip[K.EI_Z2] = self.pinion.teeth, self.gear.teeth
        eip[K.EI_NR] = N_ROLL
        eip[K.EI_TABLE] = int(self.pinion.has_table or self.gear.has_table)
        eip[K.EI_RUNOUT] = int(self.has_runout)
        efp[K.EF_PITCH_S], efp[K.EF_S_END] = pair.pitch_point_s, op.s_end
        efp[K.EF_PB], efp[K.EF_RB1] = pair.base_pitch, pair.pinion.base_radius
        efp[K.EF_U2TIP] = self.gear.u_tip
        efp[K.EF_HPER], efp[K.EF_RATIO] = self.hunting_period, self.pinion.teeth / self.gear.teeth
        for base, g in ((K.EF_GEAR0, self.pinion), (K.EF_GEAR0 + K.EF_PER_GEAR, self.gear)):
            efp[base + K.EG_ULO], efp[base + K.EG_DU] = g.u_lo, g.du
            efp[base + K.EG_RELIEF], efp[base + K.EG_RSTART] = g.relief, g.relief_start
            efp[base + K.EG_RINV] = 1.0 / (g.u_tip - g.relief_start) if g.has_relief else 0.0
            efp[base + K.EG_RPOW] = _SHAPES[g.relief_shape]
            efp[base + K.EG_RUNOUT], efp[base + K.EG_RPHASE] = g.runout, g.runout_phase
        tp = self.pinion.table() if eip[K.EI_TABLE] else np.zeros((1, 2))
        tg = self.gear.table() if eip[K.EI_TABLE] else np.zeros((1, 2))
        if "load_share" in getattr(stiffness_map, "extra", {}) and self.active:
            ls = np.ascontiguousarray(np.moveaxis(np.asarray(stiffness_map.extra["load_share"],
                                                             float), -1, 0))
            eip[K.EI_SHARES] = 1
        else:
            ls = np.zeros((3, 1, 1))
        return eip, efp, np.ascontiguousarray(tp), np.ascontiguousarray(tg), ls
