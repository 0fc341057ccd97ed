"""FE substructuring benchmark (issue 16, item 2): a new fault without re-solving the healthy body.

* The healthy part ``H`` of the paper's pinion condensed once onto the interface ``Gamma``
  (:class:`geardyn.stiffness.fe.substructure.HealthySuperelement`), default mesh (coarse test mesh
  with ``quick``). No target (paid once per body).
* The influence coefficients of the body with a new crack (and a breakage): only the fault region
  meshed, assembled and factorised. Target < 3 s. Baseline in the same run: the whole cracked body
  meshed (:func:`geardyn.stiffness.fe.mesh.build_body_mesh`) and solved
  (:func:`geardyn.stiffness.fe.solve.influence_matrices`), as the cached map does today.
* Their difference from the full-body solve of the same (glued) mesh, relative to the largest
  coefficient. Target <= 1e-6 (round-off expected: condensation is exact).
* The whole FE map of a new crack size through the library (:func:`geardyn.stiffness.build_map`,
  ``[stiffness.fe] substructure = true``), the healthy bodies and the superelement cached by an
  earlier crack size. Target < 3 s and < 0.12x the cold build of both paper maps; baselines in
  the same run (an empty cache): both maps cold, and a new crack size by the whole-body path.
"""

from __future__ import annotations

import time

import numpy as np

import geardyn
from _common import Row


def run(quick: bool = False) -> list[Row]:
    from geardyn.stiffness.fe.mesh import CrackGeometry, MeshSettings, build_body_mesh
    from geardyn.stiffness.fe.solve import (
        ElasticBody,
        ElasticMaterial,
        influence_matrices,
        load_roll_lengths,
    )
    from geardyn.stiffness.fe.substructure import HealthySuperelement, glue_meshes

    case = geardyn.paper_case()
    g = case.gear_pair().pinion
    mat = ElasticMaterial(float(case.material.youngs_modulus),
                          float(case.material.poisson_ratio))
    m = case.pair.module
    tooth = 0.08 * m * (2.0 if quick else 1.0)
    ms = MeshSettings(flank_size=tooth / 8, tooth_size=tooth, body_size=3 * tooth,
                      refined_teeth=3 if quick else 5)
    n = 24 if quick else 48
    hw = 0.04 * m
    u = load_roll_lengths(g, n)
    label = "coarse" if quick else "default"
    rows = []
    t0 = time.perf_counter()
    se = HealthySuperelement(g, mat, ms, u, hw)
    rows.append(Row(f"substructure: healthy part condensed once ({label} mesh, "
                    f"{se.stats['dofs_H']} DOFs onto {se.stats['gamma_dofs']})",
                    time.perf_counter() - t0, "s"))
    for what, kw in (("5 mm crack", {"crack": CrackGeometry(5e-3, 0.7)}),
                     ("breakage 2 mm", {"cut_radius": g.tip_radius - 2e-3})):
        u0 = load_roll_lengths(g, n, kw["cut_radius"]) if "cut_radius" in kw else None
        by = None if u0 is None else {0: u0}
        t0 = time.perf_counter()
        inf, rmesh = se.influence(u0=u0, **kw)
        t_sub = time.perf_counter() - t0
        t0 = time.perf_counter()
        bm = build_body_mesh(g, ms, kw.get("crack"), cut_radius=kw.get("cut_radius"))
        influence_matrices(ElasticBody(bm, mat), u, hw, load_offsets=bm.offsets, u_by_offset=by)
        t_full = time.perf_counter() - t0
        rows.append(Row(f"substructure: body influence with a new {what} ({label} mesh, "
                        f"{inf.stats['dofs_R']} DOFs in R)", t_sub, "s",
                        "whole body meshed and solved", t_full, "< 3 s", t_sub < 3.0))
        glued = glue_meshes(se.mesh, rmesh)
        ref = influence_matrices(ElasticBody(glued, mat), u, hw, load_offsets=glued.offsets,
                                 u_by_offset=by)
        err = float(np.abs(inf.H - ref.H).max() / np.abs(ref.H).max())
        rows.append(Row(f"substructure: {what}, max |H_sub - H_full| / max |H_full| (glued mesh)",
                        err, "-", target="<= 1e-6", met=err <= 1e-6))
    rows += _map_rows(quick)
    return rows


def _map_rows(quick: bool) -> list[Row]:
    import os
    import tempfile

    from geardyn.cache import Cache
    from geardyn.stiffness import build_map

    over = ["stiffness.method=fe"] + (["stiffness.fe.refinement=0.5"] if quick else [])
    old = os.environ.get("GEARDYN_CACHE_DIR")
    with tempfile.TemporaryDirectory() as tmp:
        os.environ["GEARDYN_CACHE_DIR"] = tmp  # an empty cache for maps and bodies alike

        def timed(extra, cracked=True):
            case = geardyn.paper_case([*over, *extra])
            t0 = time.perf_counter()
            build_map(case, cracked=cracked, cache=Cache())
            return time.perf_counter() - t0

        try:
            t_cold = timed([], cracked=False) + timed([])
            t_whole = timed(['crack.depth="4 mm"'])
            sub = ["stiffness.fe.substructure=true"]
            t_first = timed([*sub, 'crack.depth="3 mm"'])
            t_new = timed([*sub, 'crack.depth="2 mm"'])
        finally:
            if old is None:
                os.environ.pop("GEARDYN_CACHE_DIR", None)
            else:
                os.environ["GEARDYN_CACHE_DIR"] = old
    label = "coarse" if quick else "default"
    return [
        Row(f"FE map, a new crack size, whole-body path, healthy bodies cached ({label} mesh)",
            t_whole, "s", "both paper maps cold (same run)", t_cold),
        Row(f"FE map, the first crack size with substructure (condenses the healthy part once, "
            f"{label} mesh)", t_first, "s", "both paper maps cold (same run)", t_cold),
        Row(f"FE map, a new crack size with substructure, superelement cached ({label} mesh)",
            t_new, "s", "both paper maps cold (same run)", t_cold, "< 3 s and < 0.12x cold",
            t_new < 3.0 and t_new < 0.12 * t_cold),
    ]
