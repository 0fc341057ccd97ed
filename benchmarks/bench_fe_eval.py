"""FE map evaluation from cached bodies (issue 16, item 1).

The cracked paper map's evaluation (31 centre distances x 1104 boundary-fitted nodes, the bodies
loaded from the user cache, built there first if missing): the default path
(``FEStiffness.evaluate``, all positions of a centre distance batched: candidates, compliance
matrices and contact problems in a few vectorised or compiled calls,
:mod:`geardyn.stiffness.fe._batch`) against the per-position pure-Python reference
(``FEStiffness.evaluate(..., compiled=False)``), measured in the same run. Target < 2 s (23.5 s
originally). The default path is timed as the best of three runs (it is short, and the machine
may be shared), the reference once. Also reported: the largest relative difference of the two
maps over all nodes and variables (must be <= 1e-9; 0 means bit for bit), and the machine with
the 1-minute load average before and after the timing.
"""

from __future__ import annotations

import sys
import time

import numpy as np

import geardyn
from _common import Row, machine
from _common import load_average as _load


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
    load0 = _load()
    out, times = {}, {}
    for compiled, repeat in ((True, 3), (False, 1)):
        best = float("inf")
        for _ in range(repeat):
            t0 = time.perf_counter()
            out[compiled] = [model.evaluate(theta, float(d), compiled=compiled) for d in grid]
            best = min(best, time.perf_counter() - t0)
        times[compiled] = best
    load1 = _load()
    worst = 0.0
    for a, b in zip(out[True], out[False], strict=True):
        for k in a:
            scale = max(float(np.max(np.abs(b[k]))), 1e-300)
            worst = max(worst, float(np.max(np.abs(a[k] - b[k]))) / scale)
    n = theta.size * grid.size
    return [
        Row(f"FE map evaluation from cached bodies, cracked paper map ({grid.size} dd x "
            f"{theta.size} nodes = {n} positions), batched, best of 3", times[True], "s",
            "per-position pure-Python reference, same run", times[False], "< 2 s",
            bool(times[True] < 2.0)),
        Row("max relative difference, batched vs reference map (all nodes, all variables)",
            worst, "-", "", None, "<= 1e-9", bool(worst <= 1e-9)),
        Row(f"machine: {machine()}; 1-min load average before the timing (baseline column) "
            "and after it", load1, "load", "before", load0, "", None),
    ]


if __name__ == "__main__":  # python benchmarks/bench_fe_eval.py [--quick]
    for row in run(quick="--quick" in sys.argv):
        base = "" if row.baseline_value is None else \
            f"; {row.baseline}: {row.baseline_value:.4g} {row.unit}"
        ratio = "" if row.ratio is None or row.unit in ("load", "-") else \
            f"; ratio {row.ratio:.3g}x"
        met = "" if row.met is None else f"; target {row.target}: {'met' if row.met else 'NOT met'}"
        print(f"{row.name}: {row.value:.4g} {row.unit}{base}{ratio}{met}")
