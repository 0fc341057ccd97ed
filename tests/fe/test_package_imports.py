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
