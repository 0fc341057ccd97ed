"""Mesh stiffness ``K(theta, d, crack)``: analytical (potential energy) and finite-element methods.

Both methods produce a :class:`StiffnessMap` through :func:`build_map`, which caches maps on disk
keyed by a hash of everything they depend on.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .map import MapArrays, StiffnessMap, lookup_reference

__all__ = ["StiffnessMap", "MapArrays", "lookup", "lookup_reference", "build_map",
           "map_inputs", "centre_distance_grid", "fe_torque", "build_load_family",
           "LoadFamily"]


def centre_distance_grid(case) -> np.ndarray:
    """The centre distance changes of the case's map [m] (``[stiffness]`` section)."""
    s = case.stiffness
    return np.linspace(s.centre_distance_min, s.centre_distance_max, s.centre_distances)


#: Bump when a method's physics or numerics change, so cached maps are rebuilt.
MODEL_VERSIONS = {"pem": "1", "fe": "2"}


def fe_torque(case) -> float:
    """Pinion hub torque the FE map of a case is built at [N m].

    ``[stiffness.fe] torque`` if given, else the case's operating torque ``motor.torque`` (the
    constant law's input torque; the induction law's rated torque), so that the map is the
    secant (or tangent) stiffness at the mean mesh load of the run. The potential-energy map
    does not depend on the load (its Hertz term is Yang & Lin's linearised, load-independent
    form, :func:`geardyn.stiffness.pem.hertz.hertz_compliance`).
    """
    t = case.stiffness.fe.torque
    return float(case.motor.torque if t is None else t)


def map_inputs(case, method: str, cracked: bool) -> dict:
    """Everything a stiffness map depends on, as plain data (hashed for the cache key)."""
    from .._version import __version__

    data = {
        "geardyn": __version__,
        "method": method,
        "model_version": MODEL_VERSIONS[method],
        "pair": case.pair.model_dump(mode="json"),
        "pinion": {k: getattr(case.pinion, k) for k in ("teeth", "profile_shift", "bore_radius")},
        "gear": {k: getattr(case.gear, k) for k in ("teeth", "profile_shift", "bore_radius")},
        "material": {k: getattr(case.material, k) for k in ("youngs_modulus", "poisson_ratio")},
        "grid": {k: getattr(case.stiffness, k) for k in
                 ("centre_distance_min", "centre_distance_max", "centre_distances",
                  "nodes_per_segment")},
        "crack": case.crack.model_dump(mode="json") if (cracked and case.crack is not None
                                                        and case.crack.active) else None,
    }
    if cracked and getattr(case, "faults", None):  # only then: earlier keys stay valid
        data["faults"] = [f.model_dump(mode="json") for f in case.faults]
        data["faults_version"] = "1"
    if method == "fe":
        fe = case.stiffness.fe.model_dump(mode="json")
        fe["torque"] = fe_torque(case)  # the resolved load: omitted = motor.torque
        fe.pop("torques", None)  # a load family is several maps, each keyed by its torque
        if not (cracked and fe.get("substructure")):  # the default keeps earlier keys; a
            fe.pop("substructure", None)              # healthy map has no faulty body
        if fe["definition"] == "secant":  # the default keeps the keys of earlier secant maps
            del fe["definition"]
        else:
            from .fe.model import TANGENT_STEP

            fe["tangent_step"] = TANGENT_STEP
        data["fe"] = fe
    else:
        data["body_torsion"] = case.stiffness.body_torsion
        if case.stiffness.foundation_half_angle != "fillet":  # the default keeps earlier keys
            data["foundation_half_angle"] = case.stiffness.foundation_half_angle
    return data


def build_map(case, *, method: str | None = None, cracked: bool = True,
              progress: Callable[[int, int], None] | None = None, cache=None,
              ) -> StiffnessMap:
    """The stiffness map of a case, from the cache or computed.

    Parameters
    ----------
    case : geardyn.config.Case
    method : {"pem", "fe"}, optional
        Any case; default: ``case.stiffness.method``.
    cracked : bool
        Include the case's crack (if it has an enabled one) and its ``faults`` list; ``False``
        gives the healthy map. The FE method refuses the faults it does not model, naming the
        field (:func:`geardyn.faults.check_method`, :mod:`geardyn.stiffness.fe.faults`).
    progress : callable, optional
        ``progress(done, total)``.
    cache : geardyn.cache.Cache, optional
        Default: :func:`geardyn.cache.default_cache`.

    Returns
    -------
    StiffnessMap
        ``k_mb`` [N/m] on the case's centre-distance grid over one period: one pinion
        revolution, or one gear revolution for a crack on the gear (``StiffnessMap.period``).
    """
    from ..cache import cache_key, default_cache
    from ..config import Case
    from ..errors import InputError
    from ..io import to_netcdf

    if not isinstance(case, Case):
        raise InputError("case", case, "a geardyn.config.Case (geardyn.load_case(path) or "
                                       "geardyn.paper_case())")
    from ..errors import check_flag

    cracked = check_flag(cracked, "cracked")
    if method is None:
        method = case.stiffness.method
    elif isinstance(method, str) and method.strip().lower() in MODEL_VERSIONS:
        method = method.strip().lower()  # any case, as simulate's model and the CLI's options
    else:
        raise InputError("method", method, "'pem' or 'fe' (any case), or None for the case's "
                                           "stiffness.method")
    if cracked:  # a method that cannot model a fault of the case says so (geardyn.faults)
        from ..faults import check_method

        check_method(case, method)
    cache = cache or default_cache()
    inputs = map_inputs(case, method, cracked)
    key = cache_key(inputs)
    dd = centre_distance_grid(case)

    def build() -> StiffnessMap:
        if method == "pem":
            from .pem import pem_map as make
        else:
            from .fe import fe_map as make
        m = make(case, dd, cracked=cracked, progress=progress)
        m = StiffnessMap(**{**m.__dict__, "attrs": {**dict(m.attrs), "inputs_hash": key}})
        # as stored (list attributes as JSON text), so a fresh map equals a cached one
        return StiffnessMap.from_dataset(m.to_dataset())

    from ..errors import GeometryError

    try:
        m, _ = cache.get_or_build("stiffness", key, ".nc", build,
                                  save=lambda obj, path: to_netcdf(obj.to_dataset(), path),
                                  load=lambda path: load_cached_map(path, key))
    except GeometryError as exc:
        if exc.field != "centre_distance_change" or exc.value is None:
            raise
        raise _grid_error(case, dd, exc) from None
    return m


def _grid_error(case, dd, exc):
    """A map grid point the pair cannot run at (interference: a tip below the other gear's form
    circle), named as the case's field with the change that would do (the check names the
    model's own argument, ``centre_distance_change``)."""
    from ..errors import GeometryError

    bad = float(exc.value)
    pair = case.gear_pair()

    def interferes(d: float) -> bool:
        return any(c.startswith("interference") for c in pair.checks(d))

    hint = ""
    if bad <= float(dd[0]) + 1e-15 and not interferes(float(dd[-1])):
        lo, hi = bad, float(dd[-1])  # interferes at lo, not at hi
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if interferes(mid) else (lo, mid)
        up = math.ceil(hi * 1e5) / 1e5  # [m], rounded up to 0.01 mm
        hint = (f"; this pair interferes below {hi * 1e3:.4f} mm: --set "
                f"stiffness.centre_distance_min=\"{up * 1e3:g} mm\"")
    # closer centres interfere, farther ones lose the contact ratio: the end to move
    field = ("stiffness.centre_distance_max" if "contact ratio" in str(exc.allowed)
             else "stiffness.centre_distance_min")
    return GeometryError(field, f"{bad * 1e3:g} mm", f"{exc.allowed}{hint}")


def load_cached_map(path, key: str) -> StiffnessMap:
    """Read a cached map and check that it was built for ``key`` (its ``inputs_hash``).

    Raises
    ------
    DataFileError
        The file is unreadable, or records other inputs (e.g. a cracked map copied over the
        healthy map's entry): the cache then rebuilds the entry.
    """
    from ..errors import DataFileError

    m = StiffnessMap.from_netcdf(path)
    stored = m.attrs.get("inputs_hash")
    if stored != key:
        raise DataFileError(path, f"holds the map of other inputs (inputs_hash {stored!r}, "
                                  f"expected {key!r})")
    return m


class LoadFamily:
    """Stiffness maps of one case at several mesh loads: ``K(theta, d, F)``.

    Attributes
    ----------
    forces : ndarray
        Mesh forces along the line of action the maps were built at, ``T / r_b1`` [N],
        increasing.
    torques : ndarray
        The pinion torques [N m].
    maps : list of StiffnessMap
    """

    def __init__(self, torques, maps, r_b1: float):
        self.torques = np.asarray(torques, float)
        self.forces = self.torques / float(r_b1)
        self.maps = list(maps)
        first = self.maps[0].arrays()
        for m in self.maps[1:]:
            a = m.arrays()
            if (a.values.shape != first.values.shape or a.dd0 != first.dd0 or a.ddd != first.ddd
                    or a.n_seg != first.n_seg or a.n_cycles != first.n_cycles
                    or a.mesh_angle != first.mesh_angle):
                from ..errors import InputError

                raise InputError("stiffness.fe.torques", self.torques.tolist(),
                                 "maps on one grid (the same case grid for every torque)")

    def kernel_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(forces, phase_a, length_a, values)`` stacked over the loads, for the kernel."""
        arr = [m.arrays() for m in self.maps]
        return (np.ascontiguousarray(self.forces),
                np.ascontiguousarray(np.stack([a.phase_a for a in arr])),
                np.ascontiguousarray(np.stack([a.length_a for a in arr])),
                np.ascontiguousarray(np.stack([a.values for a in arr])))

    def at(self, theta, dd: float, force: float) -> np.ndarray:
        """``K(theta, dd, force)`` [N/m]: linear in the force between the maps, constant
        beyond the ends."""
        th = np.atleast_1d(np.asarray(theta, float))
        ks = np.stack([np.asarray(m(th, np.full(th.shape, dd)), float) for m in self.maps])
        return np.array([np.interp(force, self.forces, ks[:, i]) for i in range(th.size)])


def build_load_family(case, *, cracked: bool = True,
                      progress: Callable[[int, int], None] | None = None, cache=None
                      ) -> LoadFamily | None:
    """The FE maps of ``case`` at ``stiffness.fe.torques`` (each from the cache or computed), or
    ``None`` when the case asks for one map (no ``torques``, or the PEM method, whose map does
    not depend on the load).

    With secant maps ``K_s(F) = F / delta(F)``, reading the stiffness at the elastic mesh force
    of each step, ``F = K_s(F) p``, is the FE's nonlinear static force-deflection law
    ``delta(F)`` (linear in ``F`` between the loads): a conservative force of ``p``.

    Raises
    ------
    InputError
        The operating torque (``stiffness.fe.torque`` or ``motor.torque``) outside the torques.
    """
    from ..errors import InputError

    torques = case.stiffness.fe.torques
    if torques is None or case.stiffness.method != "fe":
        return None
    if case.stiffness.fe.definition != "secant":
        raise InputError("stiffness.fe.definition", case.stiffness.fe.definition,
                         "'secant' with stiffness.fe.torques: the dynamics read F = K_s(F) p, "
                         "the nonlinear force law of secant maps (a tangent map linearises "
                         "about one load)")
    t_op = fe_torque(case)
    if not torques[0] <= t_op <= torques[-1]:
        raise InputError("stiffness.fe.torques", list(torques),
                         f"torques bracketing the operating torque {t_op:.6g} N m")
    maps = []
    for i, t in enumerate(torques):
        sub = case.with_overrides({"stiffness.fe.torque": float(t)})
        maps.append(build_map(sub, method="fe", cracked=cracked, cache=cache))
        if progress is not None:
            progress(i + 1, len(torques))
    return LoadFamily(torques, maps, case.gear_pair().pinion.base_radius)


def __getattr__(name: str):
    """:func:`~.map.lookup`, a compiled function, imported on first use: importing this
    package (e.g. to build FE bodies) does not import numba (:mod:`._lookup_kernels`)."""
    if name == "lookup":
        from ._lookup_kernels import lookup

        return lookup
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
