"""The FE package imports its model (contact code, compiled kernels, SciPy's LAPACK bindings) on
first use only: a run whose FE maps are cached never loads it."""

from __future__ import annotations

import pickle
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
    (``solve_batch``) or the kernel's compilation; a crack's inside test is NumPy's. Since
    2026-11-28 it builds the bodies only (:meth:`FEStiffness.bodies_into_cache`), not the
    contact model: scipy.interpolate stays unimported too, and the bodies are the ones
    ``FEStiffness`` then loads from the cache."""
    code = textwrap.dedent("""
        import sys
        import geardyn
        from geardyn.cache import Cache
        from geardyn.stiffness.fe.model import FEStiffness
        case = geardyn.paper_case().with_overrides({
            "stiffness.method": "fe", "stiffness.fe.refinement": 0.25})
        inf = FEStiffness.bodies_into_cache(case, cracked=True, faulty_first=True,
                                            cache=Cache(sys.argv[1], enabled=True))
        print(len(inf), sorted({"cracked", "pinion", "gear"} & set(inf)),
              [m for m in ("numba", "matplotlib", "scipy.interpolate") if m in sys.modules])
    """)
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "cache")],
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    # the healthy pinion and gear, the cracked tooth's body (also under "cracked")
    assert out.stdout.strip() == "4 ['cracked', 'gear', 'pinion'] []", out.stdout
    # the full model finds every body in that cache, the same arrays
    import numpy as np

    import geardyn
    from geardyn.cache import Cache, record_lookups
    from geardyn.stiffness.fe.model import FEStiffness

    case = geardyn.paper_case().with_overrides({
        "stiffness.method": "fe", "stiffness.fe.refinement": 0.25})
    cache = Cache(tmp_path / "cache", enabled=True)
    with record_lookups() as lookups:
        fe = FEStiffness(case, cracked=True, cache=cache)
    assert [r["hit"] for r in lookups if r["kind"] == "fe"] == [True, True, True]
    again = FEStiffness.bodies_into_cache(case, cracked=True, cache=cache)
    assert set(again) == set(fe.influence) and len(again) == 4
    assert {"cracked", "gear", "pinion"} < set(again)
    for name, body in again.items():
        assert np.array_equal(body.H, fe.influence[name].H)


@pytest.mark.slow
def test_the_first_process_imports_numba_with_the_contact_problems_only(tmp_path, monkeypatch):
    """``geardyn run``'s first process, up to the end of its FE bodies (the command's module,
    its bounded-work check, the FE stage's second-process set-up, the faulty and the healthy
    bodies, here without a second process), leaves numba unimported: it comes with the contact
    problems, after the factorisations. A full run hands the kernel's compilation to the
    bodies' second process by module and name, without asking numba's cache here."""
    code = textwrap.dedent("""
        import os, sys
        import geardyn
        import geardyn.cli.run
        from geardyn.cache import Cache
        from geardyn.run_limits import check_bounded_work
        from geardyn.stiffness.fe.model import FEStiffness
        from geardyn.studies.paper import _faulty_bodies_in_background
        from geardyn.studies.paper_result import StudyResult
        from geardyn.cli import app
        # the command up to its last check before the output folder (a bad second-process
        # setting is refused right after the bounded-work check): exit 2
        os.environ["GEARDYN_FE_PROCESSES"] = "2"
        try:
            app(["run", "--stiffness", "fe", "--out", sys.argv[1]])
        except SystemExit as exc:
            print(exc.code)
        os.environ["GEARDYN_FE_PROCESSES"] = "0"
        case = geardyn.paper_case().with_overrides({
            "stiffness.method": "fe", "stiffness.fe.refinement": 0.25})
        check_bounded_work(case)
        with _faulty_bodies_in_background(case, StudyResult(out=None)) as bodies:
            FEStiffness(case, cracked=False)
        print(bool(bodies), "numba" in sys.modules)
    """)
    env = dict(__import__("os").environ, GEARDYN_FE_PROCESSES="0",
               GEARDYN_CACHE_DIR=str(tmp_path / "cache"))
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "out")],
                         capture_output=True, text=True, timeout=600, env=env)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["2", "False", "False"], out.stdout + out.stderr

    # with a second process allowed, what it is asked to do after its bodies
    from geardyn import paper_case
    from geardyn.stiffness.fe import background
    from geardyn.studies import paper
    from geardyn.studies.paper_result import StudyResult

    seen = {}

    def fake(case, **kw):
        seen.update(kw)
        return __import__("contextlib").nullcontext(None)

    monkeypatch.setattr(background, "faulty_bodies_in_background", fake)
    case = paper_case().with_overrides({"stiffness.method": "fe"})
    paper._faulty_bodies_in_background(case, StudyResult(out=None))
    # the paper's cracked case: a task of geardyn.studies.paper_result (light, as its import
    # in a fresh interpreter checks) that imports the kernel's module when called
    (then,) = seen["then"]
    from geardyn.studies.paper_result import kernels_and_mesh_figure_task

    assert then.func is kernels_and_mesh_figure_task and then.args == (case, True)
    light = subprocess.run([sys.executable, "-c", "import sys, pickle; "
                            f"pickle.loads({pickle.dumps(then)!r}); "
                            "print('numba' in sys.modules, 'matplotlib' in sys.modules)"],
                           capture_output=True, text=True, timeout=300)
    assert light.stdout.split() == ["False", "False"], light.stdout + light.stderr
    # without a crack: the kernel alone, named by module and function
    seen.clear()
    paper._faulty_bodies_in_background(case.with_overrides({"crack.enabled": False}),
                                       StudyResult(out=None))
    (then,) = seen["then"]
    assert (then.__module__, then.__qualname__) == ("geardyn.dynamics.warm", "compile_kernels")
