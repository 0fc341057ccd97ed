"""The FE bodies' sparse solvers: CHOLMOD (cholespy) against SuperLU (issue 16.1, "a sparse
Cholesky only if it measurably helps (SuperLU stays as the fallback)").

The paper's cracked pinion body at the default mesh (about 150,000 DOFs), loaded on every refined
tooth (5 x 48 Hertzian patches, the largest body of a ``geardyn run``), meshed and assembled once
per solver in a fresh process each; then the free-free stiffness factorised and the influence
coefficients solved (:func:`geardyn.stiffness.fe.solve.influence_matrices`) with
``GEARDYN_FE_SOLVER`` set. Rows: factorisation time, solve time, the memory the factorisation
and the solves add to the process (peak resident set sampled every 5 ms, minus the resident set
just before), each against SuperLU in the same run, and the largest difference of the two
solvers' coefficients (target 1e-9 of the largest, the issue's tolerance for solver paths).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from _common import Row

_CHILD = r"""
import json, sys, threading, time
import numpy as np
import geardyn
from geardyn.stiffness.fe.mesh import CrackGeometry, build_body_mesh
from geardyn.stiffness.fe.model import FESettings
from geardyn.stiffness.fe.solve import (ElasticBody, ElasticMaterial, influence_matrices,
                                        load_roll_lengths)

def rss():
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmRSS"):
                return int(line.split()[1]) / 1024

case = geardyn.paper_case()
if sys.argv[3] == "quick":
    case = case.with_overrides({"stiffness.fe.mesh_size": 1.0e-3})
s = FESettings.from_case(case)
gear = case.gear_pair().pinion
crack = CrackGeometry(depth=float(case.crack.depth), angle=float(case.crack.angle))
mesh = build_body_mesh(gear, s.mesh_settings(), crack)
mat = ElasticMaterial(float(case.material.youngs_modulus), float(case.material.poisson_ratio),
                      s.plane)
body = ElasticBody(mesh, mat)
before = rss()
peak = [before]
done = threading.Event()
def sample():
    while not done.is_set():
        peak[0] = max(peak[0], rss())
        done.wait(0.005)
th = threading.Thread(target=sample, daemon=True)
th.start()
t0 = time.perf_counter()
body.factor(release_matrix=True)
t_factor = time.perf_counter() - t0
u = load_roll_lengths(gear, s.n_points)
t0 = time.perf_counter()
inf = influence_matrices(body, u, s.half_width, load_offsets=mesh.offsets)
t_solve = time.perf_counter() - t0
done.set()
th.join()
np.save(sys.argv[2], inf.H)
print(json.dumps({"solver": body.solver, "dofs": body.n_dofs, "loads": int(inf.H.shape[0] * u.size),
                  "t_factor": t_factor, "t_solve": t_solve, "added_mb": peak[0] - before}))
"""


def _child(solver: str, out: Path, quick: bool) -> dict:
    env = dict(os.environ, GEARDYN_FE_SOLVER=solver)
    res = subprocess.run([sys.executable, "-c", _CHILD, solver, str(out),
                          "quick" if quick else "full"], env=env, capture_output=True,
                         text=True, check=False)
    if res.returncode != 0:
        raise RuntimeError(f"the {solver} child failed:\n{res.stderr}")
    return json.loads(res.stdout.strip().splitlines()[-1])


def run(quick: bool = False) -> list[Row]:
    from geardyn.stiffness.fe.factor import available_solvers

    if "cholmod" not in available_solvers():
        print("bench_fe_solver: cholespy is not installed here; only SuperLU, nothing to compare")
        return []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        r = {s: _child(s, tmp / f"{s}.npy", quick) for s in ("superlu", "cholmod")}
        H = {s: np.load(tmp / f"{s}.npy") for s in r}
    diff = float(np.abs(H["cholmod"] - H["superlu"]).max() / np.abs(H["superlu"]).max())
    what = f"cracked pinion, {r['cholmod']['dofs']} DOFs, {r['cholmod']['loads']} loads"
    c, s = r["cholmod"], r["superlu"]
    return [
        Row(f"FE body factorisation, CHOLMOD ({what})", c["t_factor"], "s", "SuperLU",
            s["t_factor"]),
        Row("  its solves (influence coefficients), CHOLMOD", c["t_solve"], "s", "SuperLU",
            s["t_solve"]),
        Row("  factorisation + solves, CHOLMOD", c["t_factor"] + c["t_solve"], "s", "SuperLU",
            s["t_factor"] + s["t_solve"], "faster than SuperLU",
            c["t_factor"] + c["t_solve"] < s["t_factor"] + s["t_solve"]),
        Row("  memory they add to the process, CHOLMOD", c["added_mb"], "MB", "SuperLU",
            s["added_mb"], "less than SuperLU", c["added_mb"] < s["added_mb"]),
        Row("  largest coefficient difference, CHOLMOD vs SuperLU", diff, "of max |H|",
            target="<= 1e-9", met=diff <= 1e-9),
    ]
