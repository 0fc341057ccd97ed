"""FE meshing and stiffness maps from several threads of one process (issue 19, item 0).

gmsh keeps one global model per process and is not thread-safe; a Dask worker with several threads
(``dask worker``'s default) used to crash the whole process with a segmentation fault. Oracle: the
same bodies and maps built serially, compared bit for bit.
"""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from geardyn.cache import Cache
from geardyn.stiffness import build_map
from geardyn.stiffness.fe.mesh import CrackGeometry, MeshSettings, build_body_mesh

#: FE meshes and maps built twice (serial and threaded): the slow tier
pytestmark = pytest.mark.slow
MESH = MeshSettings(flank_size=0.1e-3, tooth_size=1e-3, body_size=3e-3, refined_teeth=3)
CRACK = CrackGeometry(depth=5e-3, angle=math.radians(45))

#: a small, coarse FE map of the paper case (the mesh size enters through the case)
SMALL_MAP = {"stiffness.centre_distances": 2, "stiffness.nodes_per_segment": 4,
             "stiffness.centre_distance_min": "0 mm", "stiffness.centre_distance_max": "1 mm",
             "stiffness.fe.mesh_size": "1.9 mm", "stiffness.fe.teeth_in_model": 3,
             "crack.depth": "3 mm"}


def _same_mesh(a, b) -> None:
    np.testing.assert_array_equal(a.p, b.p)
    np.testing.assert_array_equal(a.t, b.t)
    assert a.edges.keys() == b.edges.keys()
    for k in a.edges:
        np.testing.assert_array_equal(a.edges[k], b.edges[k])


def test_meshes_in_threads_equal_serial(paper_case):
    gear = paper_case.gear_pair().pinion
    jobs = [None, CRACK, None, CRACK]
    serial = [build_body_mesh(gear, MESH, c) for c in jobs[:2]]
    with ThreadPoolExecutor(max_workers=4) as pool:
        threaded = list(pool.map(lambda c: build_body_mesh(gear, MESH, c), jobs))
    for k, m in enumerate(threaded):
        _same_mesh(m, serial[k % 2])


def test_fe_maps_in_threads_equal_serial(paper_case, tmp_path):
    case = paper_case.with_overrides(SMALL_MAP)
    # no cache: every build meshes and solves its bodies itself, so the threads really overlap
    off = Cache(tmp_path, enabled=False)
    serial = [build_map(case, method="fe", cracked=c, cache=off) for c in (False, True)]
    with ThreadPoolExecutor(max_workers=2) as pool:
        threaded = list(pool.map(lambda c: build_map(case, method="fe", cracked=c, cache=off),
                                 (False, True)))
    for a, b in zip(threaded, serial, strict=True):
        np.testing.assert_array_equal(a.k_mb, b.k_mb)
        np.testing.assert_array_equal(a.dd, b.dd)
        assert a.extra.keys() == b.extra.keys()
        for k in a.extra:
            np.testing.assert_array_equal(a.extra[k], b.extra[k])
    assert not np.array_equal(serial[0].k_mb, serial[1].k_mb)  # the crack is in the second map
