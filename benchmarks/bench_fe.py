"""FE mesh stiffness benchmarks (issue 4).

* One gear body's influence matrices at the default mesh, cold (gmsh mesh, P2 assembly, one
  SuperLU factorisation, 48 Hertzian patch loads, readouts). Target < 60 s. Baseline in the same
  run: the same loads without reusing the factorisation (a fresh sparse direct solve per load;
  two timed, scaled to 48).
* The paper's whole map cold: dd = 0, 0.5, 1.0 mm x healthy/cracked x 1104 boundary-fitted nodes
  per revolution (23 cycles x 2 zones x 24), bodies and maps built from an empty cache. Target
  < 180 s. Baseline: a direct two-body FE contact solve per position (:mod:`.direct`; the bodies'
  factorisations reused, node-to-segment contact with Lagrange multipliers), a few positions
  timed and scaled to the map's positions.
* The same maps from the cache. Target < 1 s.
* Mesh convergence: pitch-point (single contact) and mid double-contact stiffness at the default
  mesh against every element size halved. Target < 1 % change.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import tempfile
import time

import numpy as np

import geardyn
from _common import Row
from geardyn.cache import Cache


@contextlib.contextmanager
def _cache_dir(path):
    old = os.environ.get("GEARDYN_CACHE_DIR")
    os.environ["GEARDYN_CACHE_DIR"] = str(path)
    try:
        yield Cache(path)
    finally:
        if old is None:
            os.environ.pop("GEARDYN_CACHE_DIR", None)
        else:
            os.environ["GEARDYN_CACHE_DIR"] = old


def run(quick: bool = False) -> list[Row]:
    from scipy.sparse.linalg import spsolve

    from geardyn.stiffness import build_map
    from geardyn.stiffness.fe import FESettings, FEStiffness, body_influence, fe_map
    from geardyn.stiffness.fe.direct import direct_contact
    from geardyn.stiffness.fe.mesh import build_body_mesh
    from geardyn.stiffness.fe.solve import ElasticBody, ElasticMaterial, load_roll_lengths

    rows: list[Row] = []
    case = geardyn.paper_case().with_overrides({
        "stiffness.centre_distance_min": 0.0, "stiffness.centre_distance_max": 1.0e-3,
        "stiffness.centre_distances": 3,
        "stiffness.nodes_per_segment": 8 if quick else 24})
    if quick:
        case = case.with_overrides({"stiffness.fe.mesh_size": 1.0e-3})
    settings = FESettings.from_case(case)
    pair = case.gear_pair()
    mat = ElasticMaterial(case.material.youngs_modulus, case.material.poisson_ratio,
                          settings.plane)

    with tempfile.TemporaryDirectory() as tmp:
        # ---- 1. one body, cold
        with _cache_dir(os.path.join(tmp, "one")) as cache:
            t0 = time.perf_counter()
            inf, _ = body_influence(pair.pinion, mat, settings, cache=cache)
            t_body = time.perf_counter() - t0
        # baseline: no factorisation reuse
        body = ElasticBody(build_body_mesh(pair.pinion, settings.mesh_settings()), mat)
        u = load_roll_lengths(pair.pinion, settings.n_points)
        loads = body.patch_loads(0, u[:2], settings.half_width)
        kff = body.K[body.free][:, body.free].tocsc()
        t0 = time.perf_counter()
        for k in range(2):
            spsolve(kff, loads[body.free, k])
        t_base = (time.perf_counter() - t0) / 2 * settings.n_points + inf.stats["t_mesh"] \
            + inf.stats["t_assemble"]
        rows.append(Row(f"FE influence matrices, one body ({int(inf.stats['dofs'])} P2 dofs, "
                        f"{settings.n_points} patch loads), cold", t_body, "s",
                        "fresh sparse solve per load (scaled)", t_base, "< 60 s", t_body < 60))

        # ---- 2. the paper's whole map, cold
        with _cache_dir(os.path.join(tmp, "map")) as cache:
            t0 = time.perf_counter()
            mh = build_map(case, method="fe", cracked=False, cache=cache)
            mc = build_map(case, method="fe", cracked=True, cache=cache)
            t_cold = time.perf_counter() - t0
            n_pos = mh.k_mb.size + mc.k_mb.size

            # ---- 3. from the cache
            t0 = time.perf_counter()
            build_map(case, method="fe", cracked=False, cache=cache)
            build_map(case, method="fe", cracked=True, cache=cache)
            t_hot = time.perf_counter() - t0
            # re-evaluated from the cached bodies (no map cache)
            t0 = time.perf_counter()
            dd = np.asarray(mh.dd)
            fe_map(case, dd, cracked=False, cache=cache)
            fe_map(case, dd, cracked=True, cache=cache)
            t_bodies = time.perf_counter() - t0

        # baseline: direct two-body contact solves at a few positions, scaled
        b1 = ElasticBody(build_body_mesh(pair.pinion, settings.mesh_settings()), mat)
        b1.factor()
        model = FEStiffness(case, cracked=False, cache=Cache(os.path.join(tmp, "map")))
        tm = pair.mesh_angle
        pos = (0.0, 0.5) if quick else (0.0, 0.3, 0.5)
        t0 = time.perf_counter()
        for f in pos:
            direct_contact(b1, b1, pair, f * tm, 0.5e-3, model.torque_per_width)
        t_direct = (time.perf_counter() - t0) / len(pos)
        rows.append(Row(f"paper's FE map cold: 3 dd x healthy/cracked x "
                        f"{mh.k_mb.shape[1]} nodes ({n_pos} positions, bodies + maps)", t_cold,
                        "s", "direct two-body contact FE per position (scaled)",
                        t_direct * n_pos, "< 180 s", t_cold < 180))
        rows.append(Row("the same maps from the cache", t_hot, "s", "cold build", t_cold,
                        "< 1 s", t_hot < 1.0))
        rows.append(Row("the same maps re-evaluated from the cached bodies (no map cache)",
                        t_bodies, "s", "cold build", t_cold, "", None))

        # ---- 4. mesh convergence
        steel = case.with_overrides({"material.youngs_modulus": 206e9,
                                     "material.poisson_ratio": 0.3})
        th = np.array([0.0, 0.5 * tm])
        base = FESettings.from_case(steel)
        fine = dataclasses.replace(base, flank_size=base.flank_size / 2,
                                   tooth_size=base.tooth_size / 2, body_size=base.body_size / 2)
        k = []
        for s in (base, fine):
            m = FEStiffness(steel, cracked=False, settings=s,
                            cache=Cache(os.path.join(tmp, "conv")))
            k.append(m.evaluate(th, 0.0)["k_mb"])
        change = np.abs(k[1] / k[0] - 1) * 100
        rows.append(Row(f"pitch-point k_mb change, default -> 2x refined (steel; "
                        f"{k[0][0] / steel.pair.face_width / 1e9:.3f} -> "
                        f"{k[1][0] / steel.pair.face_width / 1e9:.3f} N/(mm um))",
                        float(change[0]), "%", "", None, "< 1 %", bool(change[0] < 1)))
        rows.append(Row("mid double-contact k_mb change, default -> 2x refined", float(change[1]),
                        "%", "", None, "< 1 %", bool(change[1] < 1)))
    return rows


if __name__ == "__main__":
    for r in run(quick=False):
        print(r, f"ratio {r.ratio:.3g}" if r.ratio else "")
