"""Shared helpers of the tooth-error tests: cases and small maps."""

from __future__ import annotations

import functools
import warnings

import numpy as np

import geardyn
from geardyn.stiffness import StiffnessMap, centre_distance_grid


def case_with(**over):
    """The paper's case (PEM, short times) with dotted overrides (``__`` for ``.``)."""
    base = {"simulation.settle_time": 0.0, "simulation.record_time": 0.003,
            "stiffness.method": "pem"}
    base.update({k.replace("__", "."): v for k, v in over.items()})
    return geardyn.paper_case(base)


@functools.lru_cache(maxsize=2)
def pem_healthy_map(n_d: int = 6) -> StiffnessMap:
    """The paper pair's healthy PEM map on a coarse centre-distance grid (with load shares)."""
    from geardyn.stiffness.pem import pem_map

    case = case_with(**{"stiffness.centre_distances": n_d})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return pem_map(case, centre_distance_grid(case), cracked=False)


def smooth_map(pair, k0=1.1e8, k1=2.0e7, k2=5.0e6) -> StiffnessMap:
    """A smooth, mesh-periodic map without load shares:
    ``k0 + k1 cos(z1 theta) + k2 cos(2 z1 theta + 0.3)`` on a fine boundary-fitted grid."""
    z1 = pair.pinion.teeth
    th = np.linspace(0.0, 2 * np.pi / z1, 512, endpoint=False)
    k = k0 + k1 * np.cos(z1 * th) + k2 * np.cos(2 * z1 * th + 0.3)
    return StiffnessMap.from_table(pair, th, k, n_seg=256)
