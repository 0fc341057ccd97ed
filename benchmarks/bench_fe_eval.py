"""FE map evaluation from cached bodies (issue 16, item 1).

The cracked paper map's evaluation (31 centre distances x 1104 boundary-fitted nodes, the bodies
loaded from the user cache, built there first if missing): the default path (candidates once per
centre distance, compiled contact solve, :mod:`geardyn.stiffness.fe._batch`) against the
per-position pure-Python reference (``FEStiffness.evaluate(..., compiled=False)``), measured in
the same run. Target < 2 s. Also reported: the largest relative difference of the two maps over
all nodes and variables (must be <= 1e-9; 0 means bit for bit).
"""

from __future__ import annotations

import os
import time

import numpy as np

import geardyn
from _common import Row


def run(quick: bool = False) -> list[Row]:
    from geardyn.stiffness import centre_distance_grid
    from geardyn.stiffness.fe import FEStiffness
    from geardyn.stiffness.map import StiffnessMap

    case = geardyn.paper_case()
    model = FEStiffness(case, cracked=True)  # fills the cache on first use
    dd = centre_distance_grid(case)
    calls = []
    StiffnessMap.from_function(model.pair, dd[:1],
                               lambda th, d: calls.append(th) or model.evaluate(th, d))
    theta = calls[0]
    grid = dd[::10] if quick else dd
    model.evaluate(theta[:4], float(grid[0]), compiled=True)  # numba compilation / cache load
    out, times = {}, {}
    for compiled in (True, False):
        t0 = time.perf_counter()
        out[compiled] = [model.evaluate(theta, float(d), compiled=compiled) for d in grid]
        times[compiled] = time.perf_counter() - t0
    worst = 0.0
    for a, b in zip(out[True], out[False], strict=True):
        for k in a:
            scale = max(float(np.max(np.abs(b[k]))), 1e-300)
            worst = max(worst, float(np.max(np.abs(a[k] - b[k]))) / scale)
    load = os.getloadavg()[0]
    n = theta.size * grid.size
    return [
        Row(f"FE map evaluation from cached bodies, cracked paper map ({grid.size} dd x "
            f"{theta.size} nodes = {n} positions; load avg {load:.2f})", times[True], "s",
            "per-position pure-Python reference, same run", times[False], "< 2 s",
            bool(times[True] < 2.0)),
        Row("max relative difference, compiled vs reference map (all nodes, all variables)",
            worst, "-", "", None, "<= 1e-9", bool(worst <= 1e-9)),
    ]


if __name__ == "__main__":
    for r in run(quick=False):
        print(r, f"ratio {r.ratio:.3g}" if r.ratio else "")
