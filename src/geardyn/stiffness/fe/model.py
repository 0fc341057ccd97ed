r"""The finite-element mesh stiffness of a case: bodies, cache and evaluation of the map.

Pipeline (docs/verification/stiffness.md, section 3): mesh each gear body once (:mod:`.mesh`), factorise
once and compute the flank influence coefficients under Hertzian patches (:mod:`.solve`), cache
them on disk (``.npz``, keyed by a hash of every input), then at each pinion angle and centre
distance solve the small compatibility problem of :mod:`.contact`. Bodies with the same geometry,
material and settings share one cache entry (for the paper's 23/23 pair the healthy pinion and the
gear are one body).

Defaults (all lengths scale with the module ``m``):

* reference Hertz patch half-width ``b_ref = 0.04 m`` (0.24 mm for the paper's m = 6 mm; the
  actual Hertz half-width at 100 N m is 0.1-0.17 mm and is reached by the analytical local term);
* element size in the refined teeth ``mesh_size = 0.08 m``; on their loaded involutes
  ``mesh_size / 8`` (b_ref / 4, P2), in the rest of the body ``3 mesh_size``; ``refinement``
  divides all three;
* 48 load points per flank, ``teeth_in_model`` refined teeth (5), plane strain.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from ...errors import DataFileError, InputError, NumericalError
from ...geometry import Gear
from ...heap import release_free_memory
from .contact import (
    BodyCompliance,
    CandidateGenerator,
    Candidates,
    ContactResult,
    PairContactModel,
    candidates,
    solve_compatibility,
)
from .faults import band_candidates, combine_bands, fault_gap
from .mesh import CrackGeometry, MeshSettings, build_body_mesh
from .solve import (
    BodyInfluence,
    ElasticBody,
    ElasticMaterial,
    influence_matrices,
    load_roll_lengths,
)

__all__ = ["FESettings", "body_influence", "healthy_superelement", "FEStiffness",
           "FORMAT_VERSION", "TANGENT_STEP"]

#: bump when the stored influence data change meaning
FORMAT_VERSION = 2

PATCH_FACTOR = 0.04  # b_ref / m
MESH_FACTOR = 0.08  # default tooth-zone element size / m
FLANK_RATIO = 8.0  # tooth size / flank size
BODY_RATIO = 3.0  # body size / tooth size
#: substructuring: Gamma's arc between bore and root circle (:func:`.substructure.interface_radius`)
SUBSTRUCTURE_FRACTION = 0.5
#: spline points per refined involute/fillet of the body meshes (:func:`.mesh.build_body_mesh`)
SPLINE_POINTS = 150
#: relative torque step h of the tangent stiffness, a central difference at T (1 +/- h) [-]
TANGENT_STEP = 0.05
DEFINITIONS = ("secant", "tangent")


@dataclass(frozen=True)
class FESettings:
    """Numerical settings of the FE mesh stiffness (from ``[stiffness.fe]``).

    Attributes
    ----------
    torque : float
        Pinion torque [N m] (``[stiffness.fe] torque``, by default the case's ``motor.torque``:
        :func:`geardyn.stiffness.fe_torque`).
    plane : {"strain", "stress"}
    flank_size, tooth_size, body_size : float
        Element sizes on the loaded flanks, in the refined teeth and elsewhere [m].
    refined_teeth : int
        ``teeth_in_model``.
    n_points : int
        Load points per flank.
    half_width : float
        Reference Hertz patch half-width ``b_ref`` [m].
    definition : {"secant", "tangent"}
        ``k_mb`` of the map: secant ``T / (dtheta r_b1^2)`` at ``torque``, or tangent
        ``dT / dtheta / r_b1^2`` there (:meth:`FEStiffness.evaluate`).
    tangent_step : float
        Relative torque step ``h`` of the tangent's central difference [-].
    substructure : bool
        Build faulty bodies by substructuring (:func:`body_influence`).
    """

    torque: float
    plane: str
    flank_size: float
    tooth_size: float
    body_size: float
    refined_teeth: int
    n_points: int
    half_width: float
    definition: str = "secant"
    tangent_step: float = TANGENT_STEP
    substructure: bool = False

    @classmethod
    def from_case(cls, case, *, n_points: int = 48) -> FESettings:
        """Settings of a :class:`geardyn.config.Case`."""
        from .. import fe_torque

        fe = case.stiffness.fe
        m = case.pair.module
        tooth = (fe.mesh_size if fe.mesh_size is not None else MESH_FACTOR * m) / fe.refinement
        return cls(torque=fe_torque(case), plane=fe.plane, flank_size=tooth / FLANK_RATIO,
                   tooth_size=tooth, body_size=BODY_RATIO * tooth,
                   refined_teeth=int(fe.teeth_in_model), n_points=int(n_points),
                   half_width=PATCH_FACTOR * m, definition=str(fe.definition),
                   substructure=bool(fe.substructure))

    def mesh_settings(self) -> MeshSettings:
        """The :class:`MeshSettings` of the body meshes."""
        return MeshSettings(flank_size=self.flank_size, tooth_size=self.tooth_size,
                            body_size=self.body_size, refined_teeth=self.refined_teeth)

    def check(self) -> None:
        """Raise :class:`InputError` if the patch is not resolved by the flank mesh, or the
        torque or the stiffness definition is not valid."""
        if not (math.isfinite(self.torque) and self.torque > 0):
            raise InputError("stiffness.fe.torque", self.torque, "a finite torque > 0 [N m]")
        if self.definition not in DEFINITIONS:
            raise InputError("stiffness.fe.definition", self.definition, "'secant' or 'tangent'")
        if not 0 < self.tangent_step < 1:
            raise InputError("tangent_step", self.tangent_step, "a relative step in (0, 1)")
        if self.flank_size > self.half_width:
            raise InputError("stiffness.fe.mesh_size", self.tooth_size,
                             f"a tooth-zone size <= {FLANK_RATIO * self.half_width:.4g} m so that "
                             "the flank elements resolve the reference Hertz patch")


def body_inputs(gear: Gear, material: ElasticMaterial, settings: FESettings,
                crack: CrackGeometry | None, cut_radius: float | None = None) -> dict:
    """Everything a body's influence coefficients depend on (hashed for the cache; a body
    without a cut keeps the key it had before breakage was modelled)."""
    from ..._version import __version__

    g = asdict(gear)
    g.pop("face_width", None)  # 2-D per unit width: the face width enters later
    s = asdict(settings)
    for k in ("torque", "definition", "tangent_step"):  # the bodies are linear: load-free
        s.pop(k)
    substructured = s.pop("substructure") and (crack is not None or cut_radius is not None)
    out = {"geardyn": __version__, "format": FORMAT_VERSION, "gear": g,
           "material": asdict(material), "settings": s,
           "crack": None if crack is None else asdict(crack)}
    if cut_radius is not None:
        out["cut_radius"] = float(cut_radius)
    if substructured:  # another mesh of the body (H + R): another entry
        out["substructure"] = {"fraction": SUBSTRUCTURE_FRACTION, "n_points": SPLINE_POINTS}
    return out


def crack_on_whole_body(H_fault: np.ndarray, H_ref: np.ndarray, healthy: BodyInfluence,
                        load_offsets, read_offsets) -> np.ndarray:
    r"""A cracked body's influence coefficients as the whole-body healthy body plus the crack's
    change computed on the substructured mesh [m^2/N]:

    .. math:: H = H^{whole}_{healthy} + (H^{H+R}_{crack} - H^{H+R}_{healthy}).

    The substructured mesh (``H + R``, with its interface) is another discretisation of the
    body than :func:`.mesh.build_body_mesh`'s: on the coarse test mesh their healthy tooth-0
    compliances differ by 0.6 %. Used directly, that difference would appear as a step of the
    map where the faulty tooth's body takes over, however small the crack; as a change it
    vanishes with the crack, and a crack's change is computed with both terms on one mesh.

    The healthy whole body is loaded on tooth 0 only; its coefficients for a load on tooth ``i``
    read on tooth ``j`` are those of the offset ``j - i`` (every tooth alike, as the healthy pair
    uses them). Offsets outside its refined teeth keep the substructured value.
    """
    H = np.array(H_fault, dtype=float, copy=True)
    for a, i in enumerate(load_offsets):
        for b, j in enumerate(read_offsets):
            if j - i in healthy.read_offsets:
                H[a, b] += healthy.H[0, healthy.read_offsets.index(j - i)] - H_ref[a, b]
    return H


def superelement_inputs(gear: Gear, material: ElasticMaterial, settings: FESettings) -> dict:
    """What the healthy part of a body condensed for substructuring depends on (hashed)."""
    out = body_inputs(gear, material, settings, None)
    out["crack"] = "superelement H"
    out["substructure"] = {"fraction": SUBSTRUCTURE_FRACTION, "n_points": SPLINE_POINTS}
    return out


def healthy_superelement(gear: Gear, material: ElasticMaterial, settings: FESettings, *,
                         cache=None):
    """The healthy part of ``gear``'s body condensed onto the interface below model tooth 0
    (:class:`.substructure.HealthySuperelement`), from the cache or built (about 2.5x a whole
    body's solve, once per gear, material and mesh settings).

    Returns
    -------
    (HealthySuperelement, bool)
        The superelement and whether it came from the cache.
    """
    from ...cache import cache_key, default_cache
    from .substructure import HealthySuperelement

    cache = cache or default_cache()
    key = cache_key(superelement_inputs(gear, material, settings))
    ms = settings.mesh_settings()

    def build():
        se = HealthySuperelement(gear, material, ms, load_roll_lengths(gear, settings.n_points),
                                 settings.half_width, n_points=SPLINE_POINTS,
                                 fraction=SUBSTRUCTURE_FRACTION)
        se.reference()  # the unfaulted glued body, stored with it
        se.inputs_hash = key
        return se

    def load(path):
        se = HealthySuperelement.load(path, gear, material, ms)
        if se.inputs_hash != key:
            raise DataFileError(path, f"holds the superelement of other inputs (inputs_hash "
                                      f"{se.inputs_hash!r}, expected {key!r})")
        return se

    return cache.get_or_build("fe", key, ".npz", build, save=lambda obj, p: obj.save(p),
                              load=load)


def body_influence(gear: Gear, material: ElasticMaterial, settings: FESettings,
                   crack: CrackGeometry | None = None, *, cache=None,
                   progress: Callable[[int, int], None] | None = None,
                   cut_radius: float | None = None) -> tuple[BodyInfluence, bool]:
    """Flank influence coefficients of one body, from the cache or computed.

    ``crack`` and ``cut_radius`` [m] (a broken tooth's cut) make model tooth 0 faulty; a faulty
    body is loaded on every refined tooth. With ``settings.substructure`` a faulty body is the
    cached healthy part of the gear (:func:`healthy_superelement`) glued to a new mesh of the
    faulty tooth's sector (:mod:`.substructure`): a new fault size meshes and solves about a
    seventh of the body. Its mesh differs from :func:`.mesh.build_body_mesh`'s whole-body mesh
    by the discretisation only (``docs/stiffness.md``).

    Returns
    -------
    (BodyInfluence, bool)
        The coefficients and whether they came from the cache.
    """
    from ...cache import cache_key, default_cache

    settings.check()
    cache = cache or default_cache()
    key = cache_key(body_inputs(gear, material, settings, crack, cut_radius))

    def build_substructured() -> BodyInfluence:
        t0 = time.perf_counter()
        se, hit = healthy_superelement(gear, material, settings, cache=cache)
        u0 = None if cut_radius is None else \
            load_roll_lengths(gear, settings.n_points, cut_radius)
        inf, _ = se.influence(crack=crack, cut_radius=cut_radius, u0=u0)
        H = inf.H
        if cut_radius is None:  # a crack: its change on the H + R mesh, on the whole-body mesh
            healthy, _ = body_influence(gear, material, settings, None, cache=cache)
            H = crack_on_whole_body(H, se.reference(), healthy, inf.load_offsets,
                                    inf.read_offsets)
        stats = {**inf.stats, "superelement_cached": float(hit),
                 "crack_as_change": float(cut_radius is None),
                 "t_total": time.perf_counter() - t0}
        return BodyInfluence(u=inf.u, load_offsets=inf.load_offsets,
                             read_offsets=inf.read_offsets, H=H, half_width=inf.half_width,
                             plane_modulus=inf.plane_modulus, stats=stats, inputs_hash=key,
                             u_teeth=inf.u_teeth)

    def build() -> BodyInfluence:
        if settings.substructure and (crack is not None or cut_radius is not None):
            return build_substructured()
        t0 = time.perf_counter()
        mesh = build_body_mesh(gear, settings.mesh_settings(), crack, cut_radius=cut_radius)
        t_mesh = time.perf_counter() - t0
        body = ElasticBody(mesh, material)
        body.factor(release_matrix=True)  # only solved from here: K is not kept (memory)
        u = load_roll_lengths(gear, settings.n_points)
        loads = (0,) if crack is None and cut_radius is None else mesh.offsets
        by = None if cut_radius is None else \
            {0: load_roll_lengths(gear, settings.n_points, cut_radius)}
        inf = influence_matrices(body, u, settings.half_width, load_offsets=loads,
                                 progress=progress, u_by_offset=by)
        # the body's mesh, matrices and factors are freed here: their pages go back to the
        # operating system, not only to this process's allocator (about 60 MB of the paper's
        # pinion, while another process may be factorising its own body; geardyn.heap).
        # Without a garbage collection: one here raised the later peak of a one-process
        # `geardyn run` from 563-567 MB to 590 MB (geardyn.heap.release_free_memory)
        del body
        release_free_memory()
        stats = {**inf.stats, "t_mesh": t_mesh, "t_total": time.perf_counter() - t0}
        return BodyInfluence(u=inf.u, load_offsets=inf.load_offsets,
                             read_offsets=inf.read_offsets, H=inf.H, half_width=inf.half_width,
                             plane_modulus=inf.plane_modulus, stats=stats, inputs_hash=key,
                             u_teeth=inf.u_teeth)

    def load(path) -> BodyInfluence:
        obj = BodyInfluence.load(path)
        if obj.inputs_hash != key:  # content of other inputs under this key: the cache rebuilds
            raise DataFileError(path, f"holds the influence coefficients of other inputs "
                                      f"(inputs_hash {obj.inputs_hash!r}, expected {key!r})")
        return obj

    return cache.get_or_build("fe", key, ".npz", build, save=lambda obj, p: obj.save(p),
                              load=load)


def _crack_of(case, cracked: bool) -> CrackGeometry | None:
    c = case.crack
    if not cracked or c is None or not c.active:
        return None
    return CrackGeometry(depth=float(c.depth), angle=float(c.angle))


def _row(cand: Candidates, q: int) -> Candidates:
    """Position ``q`` of a block of candidates (:meth:`.contact.CandidateGenerator.block`)."""
    return Candidates(**{k: getattr(cand, k)[q] for k in Candidates.__dataclass_fields__})


def _rows(cand: Candidates, q: np.ndarray) -> Candidates:
    """Positions ``q`` of a block of candidates, as a block."""
    return Candidates(**{k: getattr(cand, k)[q] for k in Candidates.__dataclass_fields__})


def solve_batch(*args, **kwargs):
    """:func:`._batch.solve_batch`, imported on the first call: a process that builds FE
    bodies (the second process of :mod:`.background`) does not import numba before its
    factorisations, which are the peak of a run's memory (numba: about 53 MB, 2026-11-27)."""
    from ._batch import solve_batch as compiled

    return compiled(*args, **kwargs)


def solve_compatibility_fast(*args, **kwargs):
    """:func:`._batch.solve_compatibility_fast`, imported on the first call (as
    :func:`solve_batch`)."""
    from ._batch import solve_compatibility_fast as compiled

    return compiled(*args, **kwargs)


class FEStiffness:
    """FE mesh stiffness of a case at any pinion angle and centre distance change.

    Parameters
    ----------
    case : geardyn.config.Case
    cracked : bool
        Include the case's faults: an enabled ``[crack]`` and the ``faults`` list
        (:func:`geardyn.faults.faults_from_case`; what the FE does with each:
        :mod:`.faults`). ``False``: the healthy pair.
    cache : geardyn.cache.Cache, optional
    progress : callable, optional
        ``progress(done, total)`` over the bodies to build.
    n_points : int
        Load points per flank.
    settings : FESettings, optional
        Override the settings derived from the case (studies of the numerical parameters).
    crack : CrackGeometry, optional
        Replaces the geometry of the case's one root crack, e.g. by a grown crack path
        (:func:`geardyn.faults.tooth_growth.crack_at`); the case must have exactly one root
        crack, through the face, and ``cracked`` must be true.
    faulty_first : bool
        Build (or load) the faulty bodies before the healthy ones (what the second process of
        :mod:`.background` does while the first builds the healthy map). Same result.
    """

    def __init__(self, case, *, cracked: bool = True, cache=None,
                 progress: Callable[[int, int], None] | None = None, n_points: int = 48,
                 settings: FESettings | None = None, crack: CrackGeometry | None = None,
                 faulty_first: bool = False):
        names, mat = self._build_bodies(case, cracked, cache, progress, n_points, settings,
                                        crack, faulty_first)
        self._build_contact(names, mat)

    @classmethod
    def bodies_into_cache(cls, case, *, cracked: bool = True, cache=None,
                          progress: Callable[[int, int], None] | None = None,
                          faulty_first: bool = False) -> dict[str, BodyInfluence]:
        """Only the bodies of the map (built, or loaded from ``cache``), without its contact
        model: for a process that fills the cache for another to evaluate the map
        (:mod:`.background`). The bodies are those of ``FEStiffness(case, cracked=cracked)``,
        under the same cache keys. The contact model (splines of every influence line, and
        scipy.interpolate's import) was 0.3-0.5 s of that process's time after its bodies,
        before the work it goes on with (2026-11-28).

        Returns
        -------
        dict of str to BodyInfluence
            The bodies by name (``"pinion"``, ``"gear"``, the faulty ones).
        """
        self = cls.__new__(cls)
        self._build_bodies(case, cracked, cache, progress, 48, None, None, faulty_first)
        return self.influence

    def _build_bodies(self, case, cracked, cache, progress, n_points, settings, crack,
                      faulty_first):
        """The case, its faults and bands, and the bodies (:attr:`influence`); returns the
        faulty bodies' names and the material for :meth:`_build_contact`."""
        from ...faults import faults_from_case
        from .faults import body_faults, check_fe_faults, face_bands

        self.case = case
        self.pair = case.gear_pair()
        self.settings = settings or FESettings.from_case(case, n_points=n_points)
        mat = ElasticMaterial(float(case.material.youngs_modulus),
                              float(case.material.poisson_ratio), self.settings.plane)
        self.material = mat
        self.face_width = float(case.pair.face_width)
        #: the case's faults (validated; zero-size faults kept here, left out of the model)
        self.faults = faults_from_case(case) if cracked else ()
        active = tuple(f for f in self.faults if not f.is_null())
        self.active_faults = active
        check_fe_faults(active, self.pair, self.settings.refined_teeth)
        #: bands across the face (:func:`.faults.face_bands`); one band without faults
        self.bands = face_bands(active, self.face_width, self.pair)
        cracks = [f for f in active if f.kind == "root_crack"]
        #: geometry of the first root crack (the ``[crack]`` section's when enabled)
        self.crack = None if not cracks else CrackGeometry(depth=float(cracks[0].depth),
                                                           angle=float(cracks[0].angle))
        if crack is not None:
            bodies = {st.body for band in self.bands for _k, st in band.teeth
                      if st.body is not None}
            if len(cracks) != 1 or len(bodies) != 1:
                raise InputError("crack", "a crack geometry", "a case with exactly one "
                                 "through-face root crack (and no other faulty body) to replace")
            self.crack = crack
        gears = {"pinion": self.pair.pinion, "gear": self.pair.gear}
        jobs = [("pinion", self.pair.pinion, None, None), ("gear", self.pair.gear, None, None)]
        names: dict[tuple, str] = {}
        for (which, tooth), keys in body_faults(self.bands).items():
            for i, bk in enumerate(sorted(keys, key=repr)):
                name = f"{which}{tooth}" + (f"_{i}" if len(keys) > 1 else "")
                names[(which, tooth, bk)] = name
                jobs.append((name, gears[which], bk[0] if crack is None else crack, bk[1]))
        self.influence: dict[str, BodyInfluence] = {}
        self.from_cache: dict[str, bool] = {}
        order = jobs[2:] + jobs[:2] if faulty_first else jobs
        for k, (name, gear, cr, cut) in enumerate(order):
            inf, hit = body_influence(gear, mat, self.settings, cr, cache=cache,
                                      cut_radius=cut)
            self.influence[name] = inf
            self.from_cache[name] = hit
            if progress is not None:
                progress(k + 1, len(jobs))
        if len(jobs) == 3:  # one faulty body: also under the [crack] model's name
            self.influence["cracked"] = self.influence[jobs[2][0]]
        return names, mat

    def _build_contact(self, names: dict, mat) -> None:
        """The contact models of the bands from the bodies (:class:`BodyCompliance` of each)."""
        teeth = {"pinion": self.pair.pinion.teeth, "gear": self.pair.gear.teeth}
        comp = {"pinion": BodyCompliance(self.influence["pinion"], teeth["pinion"]),
                "gear": BodyCompliance(self.influence["gear"], teeth["gear"])}
        for (which, _tooth, _bk), name in names.items():
            comp[name] = BodyCompliance(self.influence[name], teeth[which])
        kw = {"plane_modulus": (mat.plane_modulus, mat.plane_modulus),
              "half_width": self.settings.half_width}

        def contact_model(bodies, marked):
            return PairContactModel(self.pair, comp["pinion"], comp["gear"], bodies=bodies,
                                    marked=marked, **kw)

        #: one :class:`PairContactModel` per band
        self.band_models = []
        union: dict[tuple[str, int], BodyCompliance] = {}
        faulty: set[tuple[str, int]] = set()
        for band in self.bands:
            bodies, marked = {}, []
            for (which, tooth), st in band.teeth:
                faulty.add((which, tooth))
                if st.body is None:
                    marked.append((which, tooth))
                else:
                    bodies[(which, tooth)] = comp[names[(which, tooth, st.body)]]
                    union.setdefault((which, tooth), bodies[(which, tooth)])
            self.band_models.append(contact_model(bodies, marked))
        #: the band's model (one band), else the model whose faulty teeth are every band's (it
        #: decides which positions involve a fault)
        self.model = self.band_models[0] if len(self.bands) == 1 else \
            contact_model(union, [k for k in faulty if k not in union])
        #: wear faults (recorded as ``fault_gap``)
        self.wear = tuple(f for f in self.active_faults if f.kind == "wear")

    @property
    def period_cycles(self) -> int | None:
        """Mesh cycles of the map's period: ``None`` (one pinion revolution) unless a gear tooth
        is faulty: ``z2`` (one gear revolution), or ``lcm(z1, z2)`` with faults on both (as
        :attr:`geardyn.stiffness.pem.fault_model.FaultPEMModel.period_cycles`)."""
        gears = {f.gear for f in self.active_faults}
        z1, z2 = self.pair.pinion.teeth, self.pair.gear.teeth
        if "gear" not in gears:
            return None
        return z2 if "pinion" not in gears else math.lcm(z1, z2)

    #: :meth:`evaluate` batched over the positions of one centre distance (candidates,
    #: compliances and contact problems each in a few vectorised or compiled calls,
    #: :meth:`_evaluate_batched`); False: the per-position pure-Python reference. Both give the
    #: same map to 1e-9 relative (tests/fe/test_batched_contact.py; 6e-12 measured on the
    #: cracked paper map, from last-bit differences of ``math.hypot`` in the tip-corner gaps).
    compiled: bool = True

    @property
    def torque_per_width(self) -> float:
        """Pinion torque per metre of face width [N m/m]."""
        return self.settings.torque / self.face_width

    def solve(self, theta: float, dd: float):
        """Candidates and :class:`ContactResult` at ``(theta, dd)`` (forces per unit width; with
        several bands across the face the forces are the bands' total over the face divided by
        the face width, the separation that of the first band)."""
        if len(self.bands) == 1:
            cand = candidates(self.pair, theta, dd)
            cb = band_candidates(cand, self.bands[0], self.pair, dd)
            return cb, self.model.solve_candidates(cb, self.torque_per_width)
        cand = candidates(self.pair, theta, dd)
        force, rot = self._solve_bands(cand, dd, compiled=False)
        return cand, ContactResult(force=force, rotation=rot, separation=np.zeros(force.size),
                                   iterations=0)

    def _solve_bands(self, cand: Candidates, dd: float, *, compiled: bool,
                     c0: list[np.ndarray] | None = None, torque: float | None = None
                     ) -> tuple[np.ndarray, float]:
        """Bands across the face in parallel at one position (:func:`.faults.combine_bands`).

        Returns the total contact force of each candidate over the face divided by the face
        width [N/m] and the pinion hub rotation [rad]. ``compiled``: each band's contact problem
        by :func:`._batch.solve_compatibility_fast` (falling back to the reference where it
        fails), else :func:`.contact.solve_compatibility`; ``c0``: the bands' compliance
        matrices if already computed; ``torque``: the pinion torque [N m] (default
        ``settings.torque``).
        """
        torque = self.settings.torque if torque is None else float(torque)
        cbs = [band_candidates(cand, b, self.pair, dd) for b in self.bands]
        if c0 is None:
            c0 = [m.compliance(c) for m, c in zip(self.band_models, cbs, strict=True)]

        def solve(k: int, tau: float):
            m, cb = self.band_models[k], cbs[k]
            if compiled:
                try:
                    res = solve_compatibility_fast(
                        c0[k], cb.gap, cb.arm, tau, cb.radius, plane_modulus=(m.e1, m.e2),
                        half_width=m.half_width, local=m.local_enabled)
                    return res.force, res.rotation
                except NumericalError:
                    pass
            local = (lambda f: m.local_term(cb, f)) if m.local_enabled else None
            res = solve_compatibility(c0[k], cb.gap, cb.arm, tau, local)
            return res.force, res.rotation

        w = np.array([b.width for b in self.bands])
        force, rot, _ = combine_bands(w, [c.gap for c in cbs], [c.arm for c in cbs], solve,
                                      torque)
        return (w[:, None] * force).sum(axis=0) / self.face_width, rot

    def evaluate(self, theta: np.ndarray, dd: float, *, compiled: bool | None = None
                 ) -> dict[str, np.ndarray]:
        """Map variables at pinion angles ``theta`` [rad] and change ``dd`` [m].

        Everything at the settings' torque ``T`` [N m]. ``k_mb`` is the secant
        ``T / (dtheta(T) r_b1^2)`` (``settings.definition = "secant"``, the paper's FEA), or the
        tangent ``dT / dtheta / r_b1^2`` at ``T`` (``"tangent"``): the central difference
        ``2 h T / ((dtheta(T (1 + h)) - dtheta(T (1 - h))) r_b1^2)`` with
        ``h = settings.tangent_step`` (:data:`TANGENT_STEP` = 0.05), from two more evaluations
        at those torques (the incremental stiffness of a small fluctuation of the mesh force
        about its mean). The contact law stiffens with the load (Hertzian local term, gaps
        closing), so the tangent exceeds the secant (tests/fe/test_load_consistent.py).

        ``compiled`` (default :attr:`compiled`): all positions of this centre distance at once
        (:meth:`_evaluate_batched`); ``False`` runs the per-position pure-Python reference
        (:func:`.contact.candidates`, :meth:`PairContactModel.solve_candidates`). Equal to 1e-9
        relative (tests/fe/test_batched_contact.py; at most 6e-12 measured over the cracked
        paper map, benchmarks/bench_fe_eval.py).

        Healthy teeth give the same result in every mesh cycle: a position whose candidates
        involve no tooth of the cracked body reuses the result of the first such position at the
        same phase of the mesh cycle (to 1e-9 of a cycle).

        Returns
        -------
        dict
            ``k_mb`` [N/m]; ``load_share`` (n, 3) [-], slot ``k`` holding pair ``n_exit + 1 + k``
            with ``n_exit = floor((s(theta) - s_end) / p_b)`` the last pair to have passed the
            end of the theoretical path (:attr:`StiffnessMap.slot_tooth`);
            ``load_share_exiting`` [-], the share still carried by pair ``n_exit`` in extended
            contact beyond the theoretical end; ``pairs_in_contact`` [-] (loaded pairs);
            ``transmission_error`` [rad] (pinion hub rotation under the torque).
        """
        theta = np.atleast_1d(np.asarray(theta, float))
        compiled = self.compiled if compiled is None else bool(compiled)
        s = self.settings
        out = self.evaluate_at(theta, dd, s.torque, compiled=compiled)
        if s.definition == "tangent":
            h = s.tangent_step
            hi = self.evaluate_at(theta, dd, s.torque * (1 + h), compiled=compiled)
            lo = self.evaluate_at(theta, dd, s.torque * (1 - h), compiled=compiled)
            rb1 = self.pair.pinion.base_radius
            out["k_mb"] = 2 * h * s.torque / (hi["transmission_error"]
                                              - lo["transmission_error"]) / rb1 ** 2
        return out

    def evaluate_at(self, theta: np.ndarray, dd: float, torque: float, *,
                    compiled: bool | None = None) -> dict[str, np.ndarray]:
        """:meth:`evaluate`'s variables at pinion torque ``torque`` [N m] with the secant
        ``k_mb = torque / (dtheta r_b1^2)`` [N/m], whatever ``settings.definition``."""
        theta = np.atleast_1d(np.asarray(theta, float))
        compiled = self.compiled if compiled is None else bool(compiled)
        torque = float(torque)  # no solution for torque <= 0: NumericalError from the solve
        if compiled:
            return self._evaluate_batched(theta, float(dd), torque)
        tau = torque / self.face_width
        pair = self.pair
        rb1, pb = pair.pinion.base_radius, pair.base_pitch
        tm = pair.mesh_angle
        s_end = pair.operating(dd, check=False).s_end
        n = theta.size
        k_mb = np.empty(n)
        te = np.empty(n)
        share = np.zeros((n, 3))
        exiting = np.zeros(n)
        npair = np.zeros(n)
        memo: dict[int, tuple] = {}  # healthy teeth: the same result in every mesh cycle
        for i, th in enumerate(theta):
            n_exit = math.floor((pair.pitch_point_s + rb1 * th - s_end) / pb)
            key = round(((th - n_exit * tm) % tm) / tm * 1e9)
            cand = candidates(pair, th, dd)
            cyclic = not self.model.involves_crack(cand)
            hit = memo.get(key) if cyclic else None
            if hit is None:
                if cyclic or len(self.bands) == 1:
                    cb = cand if cyclic else band_candidates(cand, self.bands[0], pair, dd)
                    res = self.model.solve_candidates(cb, tau)
                    f, rotation = res.force, res.rotation
                else:
                    f, rotation = self._solve_bands(cand, dd, compiled=False, torque=torque)
                tot = f.sum()
                shares = tuple((int(p - n_exit), float(x / tot))
                               for p, x in zip(cand.pair, f, strict=True))
                hit = (rotation, shares, int(np.sum(f > 1e-9 * tot)))
                if cyclic:
                    memo[key] = hit
            rot, shares, npc = hit
            te[i] = rot
            k_mb[i] = torque / rot / rb1 ** 2
            for r, x in shares:
                if 1 <= r <= 3:
                    share[i, r - 1] = x
                elif r == 0:
                    exiting[i] = x
            npair[i] = npc
        out = {"k_mb": k_mb, "load_share": share, "load_share_exiting": exiting,
               "pairs_in_contact": npair, "transmission_error": te}
        return self._with_gap(out, theta, dd)

    def _with_gap(self, out: dict, theta: np.ndarray, dd: float) -> dict:
        """Add ``fault_gap`` [m] (n, 3) when a tooth is worn (:func:`.faults.fault_gap`)."""
        if self.wear:
            out["fault_gap"] = fault_gap(self.pair, self.wear, theta, dd)
        return out

    def _evaluate_batched(self, theta: np.ndarray, dd: float, torque: float
                          ) -> dict[str, np.ndarray]:
        """:meth:`evaluate_at` of all positions of one centre distance in a few batched calls
        (pinion torque ``torque`` [N m]).

        The reference's arithmetic, reorganised: (1) the candidate pair indices of every
        position (:meth:`.contact.CandidateGenerator.span`) and the mesh-cycle memo decided up
        front (which positions involve the cracked body, which are the first at their phase);
        (2) for the positions to solve, grouped by their number of candidates, the candidate
        geometry (compiled :func:`._batch.complete_nb`), the compliance matrices (one vectorised
        spline call per pair of model teeth, :meth:`.contact.PairContactModel.compliance_batch`)
        and the contact problems (compiled :func:`._batch.solve_batch`); (3) load shares and
        the memo's copies as array operations. A position the compiled solve does not resolve
        (``status != 0``) falls back to :meth:`.contact.PairContactModel.solve_candidates`,
        which solves it or raises :class:`~geardyn.errors.NumericalError`.
        """
        pair = self.pair
        cm = self.model
        rb1, pb = pair.pinion.base_radius, pair.base_pitch
        tm = pair.mesh_angle
        s_end = pair.operating(dd, check=False).s_end
        tau = torque / self.face_width
        npos = theta.size
        gen = CandidateGenerator(pair, dd)
        s_theta, first, last = gen.span(theta)
        count = last - first + 1
        n_exit = np.floor((pair.pitch_point_s + rb1 * theta - s_end) / pb).astype(np.int64)
        key = np.round(((theta - n_exit * tm) % tm) / tm * 1e9).astype(np.int64)
        width = int(count.max()) if npos else 0
        cols = np.arange(width)
        cyclic = ~cm.crack_rows(last[:, None] - cols[None, :], cols[None, :] < count[:, None])
        # the memo: a cyclic position takes the result of the first cyclic one with its key
        src = np.arange(npos)
        cyc = np.nonzero(cyclic)[0]
        if cyc.size:
            _, first_at, inverse = np.unique(key[cyc], return_index=True, return_inverse=True)
            src[cyc] = cyc[first_at][inverse.ravel()]
        solved = np.unique(src)
        rot = np.empty(npos)
        share = np.zeros((npos, 3))
        exiting = np.zeros(npos)
        npair = np.zeros(npos)
        multi = len(self.bands) > 1
        for size in np.unique(count[solved]):
            rows = solved[count[solved] == size]
            cand = gen.block(s_theta[rows], last[rows], int(size))
            if multi:  # the positions on a faulty tooth: bands across the face, one by one
                f = np.zeros((rows.size, int(size)))
                dth = np.zeros(rows.size)
                banded = ~cyclic[rows]
                if banded.any():
                    sub = _rows(cand, np.nonzero(banded)[0])
                    c0s = [m.compliance_batch(band_candidates(sub, b, pair, dd))
                           for m, b in zip(self.band_models, self.bands, strict=True)]
                    for q, r in enumerate(np.nonzero(banded)[0]):
                        f[r], dth[r] = self._solve_bands(_row(sub, q), dd, compiled=True,
                                                         c0=[c[q] for c in c0s], torque=torque)
                plain = np.nonzero(~banded)[0]
                if plain.size:
                    sub = _rows(cand, plain)
                    f[plain], dth[plain] = self._solve_block(sub, tau)
            else:
                cand = band_candidates(cand, self.bands[0], pair, dd)
                f, dth = self._solve_block(cand, tau)
            tot = f.sum(axis=1)
            rel = cand.pair - n_exit[rows][:, None]
            x = f / tot[:, None]
            for k in range(int(size)):
                r = rel[:, k]
                slot = (r >= 1) & (r <= 3)
                share[rows[slot], r[slot] - 1] = x[slot, k]
                ex = r == 0
                exiting[rows[ex]] = x[ex, k]
            rot[rows] = dth
            npair[rows] = np.sum(f > 1e-9 * tot[:, None], axis=1)
        te = rot[src]
        out = {"k_mb": torque / te / rb1 ** 2, "load_share": share[src],
               "load_share_exiting": exiting[src], "pairs_in_contact": npair[src],
               "transmission_error": te}
        return self._with_gap(out, theta, dd)

    def _solve_block(self, cand: Candidates, torque: float) -> tuple[np.ndarray, np.ndarray]:
        """Contact forces [N/m] and rotations [rad] of a block of positions with one band
        (compiled :func:`._batch.solve_batch`, the reference where it fails)."""
        cm = self.model
        c0 = cm.compliance_batch(cand)
        status, f, dth, _, _ = solve_batch(
                c0, cand.gap, cand.arm, torque, cand.radius, plane_modulus=(cm.e1, cm.e2),
                half_width=cm.half_width, local=cm.local_enabled)
        for q in np.nonzero(status)[0]:  # fallback: the pure-Python reference
            res = cm.solve_candidates(_row(cand, int(q)), torque)
            f[q] = res.force
            dth[q] = res.rotation
        return f, dth

    def _parameters(self) -> dict:
        crack = next((f for f in self.active_faults if f.kind == "root_crack"), None)
        out = {"crack": None if crack is None else {
            "gear": crack.gear, "tooth": int(crack.tooth), "depth_m": float(crack.depth),
            "angle_rad": float(crack.angle),
            "mouth": "loaded fillet, 30 deg tangent point (ISO 6336-3)"}}
        if getattr(self.case, "faults", None) and self.faults:
            from ..pem.fault_model import fault_record

            out["faults"] = [fault_record(f) for f in self.faults]
        return out

    def attrs(self) -> dict:
        """Provenance of maps made by this model."""
        s = self.settings
        st = {k: v.stats for k, v in self.influence.items()}
        return {
            "method": "fe",
            "plane": f"plane {s.plane}",
            "face_width_basis": f"2-D results per unit width times face width "
                                f"b = {self.face_width:g} m",
            "torque": s.torque, "torque_units": "N m",
            "stiffness_definition": (
                "secant K_t = T / dtheta at the applied torque (gear hub fixed, torque on the "
                "pinion hub), k_mb = K_t / r_b1^2" if s.definition == "secant" else
                f"tangent K_t = dT / dtheta at the applied torque T (gear hub fixed, torque on "
                f"the pinion hub) by the central difference 2 h T / (dtheta(T (1 + h)) - "
                f"dtheta(T (1 - h))), h = {s.tangent_step:g}, k_mb = K_t / r_b1^2; "
                f"transmission_error and load_share at T"),
            "patch_half_width": s.half_width, "patch_half_width_units": "m",
            "flank_element_size": s.flank_size, "tooth_element_size": s.tooth_size,
            "body_element_size": s.body_size, "element_size_units": "m",
            "teeth_in_model": s.refined_teeth, "load_points_per_flank": s.n_points,
            "elements": "P2 triangles (scikit-fem), whole gear bodies fixed at the bore",
            "dofs": {k: int(v.get("dofs", v.get("dofs_R", 0))) for k, v in st.items()},
            "faulty_bodies": (
                "substructured: the healthy part condensed once onto an interface at mid-rim "
                "below the faulty tooth's sector, the sector meshed with the fault; a crack "
                "enters as its change on that mesh added to the whole-body healthy body "
                "(geardyn.stiffness.fe.model.crack_on_whole_body)" if s.substructure else
                "whole bodies meshed with the fault"),
            "crack": None if self.crack is None else asdict(self.crack),
            "parameters": self._parameters(),
            "cracked": int(bool(self.active_faults)),
            "face_bands": [{"width_m": b.width, "faulty_teeth": [
                f"{w} {t}" for (w, t), _ in b.teeth]} for b in self.bands],
            "case": self.case.name,
            "citations": [
                "Xue & Howard (2018) Mech. Syst. Signal Process., section 3",
                "Johnson (1985) Contact Mechanics, eq. 5.36",
                "Andersson & Vedmar (2003) J. Sound Vib. 260:195-212",
                "Gustafsson & McBain (2020) J. Open Source Softw. 5:2369 (scikit-fem)",
                "Geuzaine & Remacle (2009) Int. J. Numer. Meth. Engng 79:1309-1331 (gmsh)",
            ],
        }
