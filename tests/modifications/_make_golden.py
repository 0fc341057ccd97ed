"""Regenerate ``data/golden_records.npz``: model I and II records of a short paper-case run.

The file was written by the code *before* tooth errors existed (commit 917fd3e plus the
step-count guard of ``dynamics/newmark.py``); the test checks that zero errors still reproduce
it bit for bit. Run ``python tests/modifications/_make_golden.py OUT.npz`` only when a deliberate
change of the dynamics makes a new golden file necessary (and say so in the commit).
"""

import sys
import time
import warnings

import numpy as np

import geardyn
from geardyn.dynamics import simulate
from geardyn.stiffness import centre_distance_grid
from geardyn.stiffness.pem import pem_map


def golden_case():
    """The paper case, PEM, 2 ms settling and 6 ms recorded."""
    return geardyn.paper_case({"simulation.settle_time": 0.002, "simulation.record_time": 0.006,
                               "stiffness.method": "pem",
                               # the golden file predates the step-averaged stiffness
                               "simulation.stiffness_window": "point"})


def records() -> dict[str, np.ndarray]:
    """Every data variable and the time of model I and II, keyed ``"I/name"``."""
    case = golden_case()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        smap = pem_map(case, centre_distance_grid(case), cracked=True)
    out = {}
    for which in ("I", "II"):
        ds = simulate(case, smap, model=which)
        for name in ds.data_vars:
            out[f"{which}/{name}"] = ds[name].values
        out[f"{which}/time"] = ds.time.values
    return out


if __name__ == "__main__":
    t0 = time.time()
    rec = records()
    np.savez_compressed(sys.argv[1], **rec)
    print(f"{len(rec)} arrays in {time.time() - t0:.1f} s")
