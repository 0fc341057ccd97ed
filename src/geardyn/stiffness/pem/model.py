"""The PEM mesh stiffness of a gear pair at any operating centre distance (assembly of the terms).

One tooth pair: ``1/k_pair = 1/k_h + sum_i (1/k_b,i + 1/k_s,i + 1/k_a,i + 1/k_f,i)`` (Yang & Lin
1987; Tian 2004); the mesh: ``k_mb = sum_j k_pair,j`` over the pairs in contact on the operating
line of action (docs/verification/stiffness.md, sections 1 and 2).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.interpolate import CubicSpline

from ...errors import GeometryError, InputError
from .body import body_torsion_compliance
from .crack import ToothCrack
from .foundation import root_half_angle, sainsot_validity
from .hertz import hertz_compliance
from .section import ToothSection
from .tooth import tooth_compliance

#: Roll-angle points of each tooth's compliance table (per smooth interval).
N_TABLE = 201


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
    foundation_half_angle : {"fillet", "ross", "alpha3"} or float
        Root half-angle ``theta_f`` of the Sainsot foundation term of both gears
        (:func:`geardyn.stiffness.pem.foundation.root_half_angle`): the generated outline's
        (default), ROSS's closed form, Wan et al.'s ``alpha_3``, or an angle [rad].
    """

    def __init__(self, pair, youngs_modulus: float, poisson_ratio: float,
                 crack: ToothCrack | None = None, *, model: str = "exact",
                 face_width: float | None = None, n_table: int = N_TABLE,
                 body_torsion: bool = False, foundation_half_angle: str | float = "fillet"):
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
        self.foundation_half_angle = foundation_half_angle
        #: theta_f of the foundation term of each gear [rad]
        self.theta_f = {"pinion": root_half_angle(pair.pinion, foundation_half_angle),
                        "gear": root_half_angle(pair.gear, foundation_half_angle)}
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
        if cracked and case.crack is not None and case.crack.active:
            crack = ToothCrack.from_config(case.crack)
        return cls(case.gear_pair(), case.material.youngs_modulus, case.material.poisson_ratio,
                   crack, model=model, face_width=case.pair.face_width,
                   body_torsion=case.stiffness.body_torsion,
                   foundation_half_angle=getattr(case.stiffness, "foundation_half_angle", "fillet"))

    # ---------------------------------------------------------------- per tooth
    @property
    def hertz(self) -> float:
        """``1/k_h`` [m/N]."""
        return hertz_compliance(self.E, self.nu, self.L)

    def tooth_compliance_exact(self, which: str, roll, cracked: bool = False) -> np.ndarray:
        """Tooth compliance by direct quadrature (no table) [m/N]."""
        return tooth_compliance(self.sections[(which, cracked)], roll, self.E, self.nu, self.L,
                                theta_f=self.theta_f[which])

    def _table(self, which: str, cracked: bool) -> list[tuple[float, float, CubicSpline]]:
        key = (which, cracked)
        if key not in self._tables:
            sec = self.sections[key]
            edges = [sec.u_min, *sec.roll_breaks, sec.u_tip]
            parts = []
            for a, b in zip(edges[:-1], edges[1:], strict=True):
                # Chebyshev-Lobatto spacing: accurate splines near the interval ends
                u = a + (b - a) * (1 - np.cos(np.linspace(0, np.pi, self.n_table))) / 2
                c = tooth_compliance(sec, u, self.E, self.nu, self.L, theta_f=self.theta_f[which])
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

    def validity_warnings(self, *, notes: bool = False) -> list[str]:
        """Extrapolations of the model for this pair, in words (with ``notes``, also the
        informational ones of :func:`sainsot_validity`)."""
        out = []
        for name, g in (("pinion", self.pair.pinion), ("gear", self.pair.gear)):
            out += [f"{name}: {m}" for m in sainsot_validity(g, self.theta_f[name], notes=notes)]
        return out

    def parameters(self) -> dict:
        """The model's parameters, for provenance."""
        p, g = self.pair.pinion, self.pair.gear
        out = {
            "youngs_modulus_Pa": self.E,
            "poisson_ratio": self.nu,
            "face_width_m": self.L,
            "tooth_model": self.model,
            "foundation_half_angle": str(self.foundation_half_angle),
            "pinion_theta_f_rad": self.theta_f["pinion"],
            "gear_theta_f_rad": self.theta_f["gear"],
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

