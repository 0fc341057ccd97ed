"""The FE package imports its model (contact code, compiled kernels, SciPy's LAPACK bindings) on
first use only: a run whose FE maps are cached never loads it."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest


def test_the_background_policy_does_not_import_the_model():
    code = textwrap.dedent("""
        import sys
        import geardyn
        from geardyn.stiffness.fe.background import fe_processes, _faulty_bodies_missing
        from geardyn.cache import Cache
        import tempfile
        with tempfile.TemporaryDirectory() as d:
            case = geardyn.paper_case().with_overrides({"stiffness.method": "fe"})
            missing = _faulty_bodies_missing(case, Cache(d, enabled=True), "fe")
        print(missing, sorted(m for m in sys.modules if m.startswith("geardyn.stiffness.fe")))
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split(None, 1) == [
        "True", "['geardyn.stiffness.fe', 'geardyn.stiffness.fe.background']\n"]


def test_the_model_names_are_still_the_packages():
    import geardyn.stiffness.fe as fe
    from geardyn.stiffness.fe import FESettings, FEStiffness, body_influence, model

    assert (FESettings, FEStiffness, body_influence) == (model.FESettings, model.FEStiffness,
                                                         model.body_influence)
    assert {"FESettings", "FEStiffness", "body_influence", "fe_map"} <= set(dir(fe))
    with pytest.raises(AttributeError, match="no attribute 'FEStiffnes'"):
        fe.FEStiffnes  # noqa: B018 - a typo is an AttributeError, as before


@pytest.mark.slow
def test_building_the_faulty_bodies_imports_neither_numba_nor_matplotlib(tmp_path):
    """What the FE bodies' second process does (:func:`.background._build_faulty_bodies`: the
    cracked pinion, checked and meshed, then the healthy bodies, on a coarse mesh) leaves numba
    and matplotlib unimported: their 53 MB and 13 MB (2026-11-27) would sit beside the
    factorisations, the peak of a run's memory. numba comes later, with the contact problems
    (``solve_batch``) or the kernel's compilation; a crack's inside test is NumPy's."""
    code = textwrap.dedent("""
        import sys
        import geardyn
        from geardyn.cache import Cache
        from geardyn.stiffness.fe.model import FEStiffness
        case = geardyn.paper_case().with_overrides({
            "stiffness.method": "fe", "stiffness.fe.refinement": 0.25})
        fe = FEStiffness(case, cracked=True, faulty_first=True,
                         cache=Cache(sys.argv[1], enabled=True))
        print(len(fe.influence), sorted({"cracked", "pinion", "gear"} & set(fe.influence)),
              [m for m in ("numba", "matplotlib") if m in sys.modules])
    """)
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "cache")],
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    # the healthy pinion and gear, the cracked tooth's body (also under "cracked")
    assert out.stdout.strip() == "4 ['cracked', 'gear', 'pinion'] []", out.stdout
