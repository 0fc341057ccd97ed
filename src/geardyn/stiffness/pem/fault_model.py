r"""The PEM mesh stiffness of a pair with any number of tooth faults (:mod:`geardyn.faults`).

Each faulty tooth changes the pair it belongs to in one or two ways:

* its **section** (the beam terms): a root crack through the face (the ``[crack]`` model,
  :mod:`.crack`), through part of the face (slices, :mod:`.partial_crack`), or a worn band with
  ``stiffness = true`` (:mod:`.wear`);
* its **contact width** (:mod:`.spall`): a spall removes ``b_s`` of the contact line while the
  contact point crosses it; a breakage removes the broken width above the cut. With ``L_c`` the
  remaining contact width the pair's stiffness is ``k = (L_c / L) / c_pair``, every term of the
  pair compliance ``c_pair = 1/k_h + sum_i (1/k_b,i + 1/k_s,i + 1/k_a,i + 1/k_f,i)`` being
  proportional to ``1/L`` (effective-width model, :mod:`geardyn.faults.spall`). Two faults of a
  pair that remove width at the same contact point remove the sum of their widths (the worst case,
  their place across the face being unknown).

A worn tooth also records its gap along the line of action (``fault_gap`` per load-share slot,
:mod:`geardyn.faults.wear`). A fault of zero size is left out, so the map is the healthy one.
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import InputError
from .model import N_TABLE, PEMModel
from .partial_crack import SlicedTooth
from .section import ToothSection
from .spall import effective_width_factor, width_lost
from .wear import WornSection


class FaultPEMModel(PEMModel):
    """:class:`PEMModel` with the tooth faults of :mod:`geardyn.faults`.

    Parameters
    ----------
    pair : geardyn.geometry.GearPair
    youngs_modulus, poisson_ratio : float
        ``E`` [Pa], ``nu`` [-].
    faults : sequence of geardyn.faults.RootCrack, Spall, Breakage or Wear
        Validated faults (:func:`geardyn.faults.faults_from_case`).
    model, face_width, n_table, body_torsion, foundation_half_angle
        As :class:`PEMModel`.
    """

    def __init__(self, pair, youngs_modulus: float, poisson_ratio: float, faults=(), *,
                 model: str = "exact", face_width: float | None = None,
                 n_table: int = N_TABLE, body_torsion: bool = False,
                 foundation_half_angle: str | float = "fillet"):
        super().__init__(pair, youngs_modulus, poisson_ratio, None, model=model,
                         face_width=face_width, n_table=n_table, body_torsion=body_torsion,
                         foundation_half_angle=foundation_half_angle)
        self.faults = tuple(faults)
        self.active = tuple(f for f in self.faults if not f.is_null())
        #: (gear, tooth) -> callable roll -> tooth compliance [m/N] (modified sections)
        self.tooth_fn: dict[tuple[str, int], object] = {}
        #: (gear, tooth) -> faults that remove contact width
        self.contact: dict[tuple[str, int], list] = {}
        #: (gear, tooth) -> wear faults (gaps)
        self.wear: dict[tuple[str, int], list] = {}
        for f in self.active:
            key = (f.gear, int(f.tooth))
            g = pair.pinion if f.gear == "pinion" else pair.gear
            if f.tooth >= g.teeth:
                raise InputError(f.field("tooth"), f.tooth,
                                 f"a tooth number in [0, {g.teeth - 1}] of the {f.gear}")
            if f.kind in ("spall", "breakage"):
                self.contact.setdefault(key, []).append(f)
                continue
            if f.kind == "wear":
                self.wear.setdefault(key, []).append(f)
                if not f.stiffness:
                    continue
                section = WornSection(g, f, model=model)
            elif f.full_width:
                try:
                    section = ToothSection(g, f.tooth_crack(), model=model)
                except InputError as exc:
                    raise InputError(f.field("depth"), f.depth, exc.allowed) from None
            else:
                try:
                    sliced = SlicedTooth(self, f)
                except InputError as exc:
                    raise InputError(f.field("depth"), f.depth, exc.allowed) from None
                self.tooth_fn[key] = sliced.compliance
                continue
            if key in self.tooth_fn:
                raise InputError(f.field("type"), f.kind, "one fault that changes the tooth "
                                 f"section per tooth ({f.gear} tooth {f.tooth})")
            skey = ("fault", int(f.tooth))
            self.sections[(f.gear, skey)] = section
            self.tooth_fn[key] = (lambda roll, w=f.gear, k=skey:
                                  self.tooth_compliance(w, roll, k))

    @property
    def period_cycles(self) -> int | None:
        """Mesh cycles of the map's period: ``None`` (one pinion revolution) unless a gear tooth
        is faulty: ``z2`` (one gear revolution), or ``lcm(z1, z2)`` with faults on both."""
        gears = {f.gear for f in self.active}
        z1, z2 = self.pair.pinion.teeth, self.pair.gear.teeth
        if "gear" not in gears:
            return None
        return z2 if "pinion" not in gears else math.lcm(z1, z2)

    def evaluate(self, theta, centre_distance_change: float = 0.0) -> dict[str, np.ndarray]:
        """As :meth:`PEMModel.evaluate`, with the faults; adds ``fault_gap`` [m] (n, 3), the
        worn gap of each slot's pair, when a tooth is worn."""
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
        phi1 = np.where(inc, s / rb1, np.nan)
        phi2 = np.where(inc, (op.t1t2 - s) / rb2, np.nan)
        tooth = {"pinion": np.mod(n, pair.pinion.teeth), "gear": np.mod(n, pair.gear.teeth)}
        roll = {"pinion": phi1, "gear": phi2}
        comp = {}
        lost = np.zeros(s.shape)
        gap = np.zeros(s.shape)
        for which in ("pinion", "gear"):
            c = np.full(s.shape, np.nan)
            c[inc] = self.tooth_compliance(which, roll[which][inc])
            g = pair.pinion if which == "pinion" else pair.gear
            for (w, t), fn in self.tooth_fn.items():
                m = inc & (tooth[which] == t) if w == which else None
                if m is not None and np.any(m):
                    c[m] = fn(roll[which][m])
            for (w, t), fs in self.contact.items():
                m = inc & (tooth[which] == t) if w == which else None
                if m is not None and np.any(m):
                    for f in fs:
                        lost[m] += width_lost(f, g, roll[which][m])
            for (w, t), fs in self.wear.items():
                m = inc & (tooth[which] == t) if w == which else None
                if m is not None and np.any(m):
                    for f in fs:
                        gap[m] += f.deviation(roll[which][m])
            comp[which] = c
        k = np.zeros(s.shape)
        frac = effective_width_factor(self.L, lost)
        k[inc] = frac[inc] / (self.hertz + comp["pinion"][inc] + comp["gear"][inc])
        kmb = k.sum(axis=1)
        share = np.divide(k, kmb[:, None], out=np.zeros_like(k), where=kmb[:, None] > 0)
        if self.body_compliance > 0:
            kmb = np.divide(kmb, 1.0 + kmb * self.body_compliance, out=np.zeros_like(kmb),
                            where=kmb > 0)
        out = {"k_mb": kmb, "load_share": share, "pairs_in_contact": inc.sum(axis=1),
               "pair": n, "pinion_roll": phi1, "gear_roll": phi2}
        if self.wear:
            out["fault_gap"] = np.where(inc, gap, 0.0)
        return out

    def parameters(self) -> dict:
        """The model's parameters with the faults, for provenance."""
        out = super().parameters()
        out["faults"] = [fault_record(f) for f in self.faults]
        return out


def fault_record(f) -> dict:
    """A fault's parameters as plain data (SI units in the key names)."""
    from dataclasses import fields

    rec = {"type": f.kind, "label": f.label, "active": not f.is_null()}
    for fl in fields(f):
        if fl.name in ("label", "shape"):  # an Archard shape is recomputed from the law
            continue
        v = getattr(f, fl.name)
        unit = {"depth": "_m", "width": "_m", "height": "_m", "face_width": "_m",
                "roll_start": "_rad", "roll_length": "_rad", "angle": "_rad"}.get(fl.name, "")
        rec[fl.name + unit] = v
    return rec


def fault_model_from_case(case, faults, *, model: str = "exact") -> FaultPEMModel:
    """The :class:`FaultPEMModel` of a case with the given (validated) faults."""
    return FaultPEMModel(case.gear_pair(), case.material.youngs_modulus,
                         case.material.poisson_ratio, faults, model=model,
                         face_width=case.pair.face_width,
                         body_torsion=case.stiffness.body_torsion,
                         foundation_half_angle=getattr(case.stiffness, "foundation_half_angle",
                                                       "fillet"))
