"""``pem_map`` (stiffness/pem/mesh_map.py): every argument reaches the model, the provenance
record in full, progress reports and the caller's line in the range warning.

Written against the mutants that survived the first mutation run of
``stiffness/pem/mesh_map.py`` (docs/mutation.md, issue 20 item 6). Oracle: the direct
:class:`PEMModel` evaluated at the map's nodes (the map is only a tabulation of it).
"""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest

import geardyn
from geardyn.stiffness.pem import CITATIONS, PEMModel, SainsotRangeWarning, pem_map


@pytest.fixture(scope="module")
def small():
    return geardyn.paper_case().with_overrides({"stiffness.nodes_per_segment": 4})


def _nodes_match(m, model, dd):
    th = m.node_theta()
    for i, d in enumerate(dd):
        np.testing.assert_allclose(m.k_mb[i], model.mesh_stiffness(th[i], d), rtol=1e-13)


def test_healthy_map_of_a_cracked_case(small):
    dd = np.array([0.0, 1e-3])
    m = pem_map(small, dd, cracked=False)
    assert m.attrs["cracked"] == 0 and "crack" not in m.attrs["parameters"]
    _nodes_match(m, PEMModel.from_case(small, cracked=False), dd)
    mc = pem_map(small, dd[:1], cracked=True)
    assert mc.attrs["cracked"] == 1 and mc.attrs["parameters"]["crack"]["tooth"] == 11
    assert np.min(mc.k_mb[0] / m.k_mb[0]) < 0.99          # the crack is in the cracked map only


def test_classic_tooth_model_reaches_the_map(small):
    dd = np.array([0.0])
    m = pem_map(small, dd, cracked=False, model="classic")
    assert m.attrs["parameters"]["tooth_model"] == "classic"
    classic = PEMModel.from_case(small, cracked=False, model="classic")
    _nodes_match(m, classic, dd)
    exact = PEMModel.from_case(small, cracked=False)
    assert np.max(np.abs(m.k_mb[0] / exact.mesh_stiffness(m.node_theta()[0]) - 1)) > 1e-3


def test_provenance_record_in_full_and_progress(small):
    calls = []
    m = pem_map(small, [0.0, 5e-4, 1e-3], cracked=True,
                progress=lambda done, total: calls.append((done, total)))
    assert calls == [(1, 3), (2, 3), (3, 3)]
    a = m.attrs
    assert set(a) == {"method", "title", "citations", "parameters", "cracked", "warnings",
                      "notes", "geardyn_version", "case"}
    assert a["method"] == "pem"
    assert a["title"] == "mesh stiffness by the potential energy method"
    assert a["citations"] == list(CITATIONS) and len(a["citations"]) == 6
    assert a["cracked"] == 1 and a["warnings"] == []
    assert a["geardyn_version"] == geardyn.__version__
    assert a["case"] == small.name
    assert a["parameters"] == PEMModel.from_case(small).parameters()


def test_range_warning_points_at_the_caller(small):
    tiny = small.with_overrides({"pinion.bore_radius": "8 mm"})
    with pytest.warns(SainsotRangeWarning) as rec:
        mt = pem_map(tiny, [0.0], cracked=False)
    msgs = [str(w.message) for w in rec]
    assert msgs == mt.attrs["warnings"] and msgs[0].startswith("pinion: h_f = ")
    assert all(m.startswith("pinion: ") for m in msgs)    # the gear keeps its 20 mm bore
    # mutmut's trampoline adds a stack frame, so the caller's line is checked outside mutmut only
    if "MUTANT_UNDER_TEST" not in os.environ:
        assert rec[0].filename == __file__
    with warnings.catch_warnings():
        warnings.simplefilter("error", SainsotRangeWarning)
        pem_map(small, [0.0], cracked=False)               # inside the fit: no warning
