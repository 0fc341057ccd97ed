"""The batched FE map evaluation equals the per-position pure-Python reference (issue 16).

Oracle: :meth:`FEStiffness.evaluate` with ``compiled=False`` (the per-position path:
``candidates`` + ``PairContactModel.solve_candidates`` + ``solve_compatibility``), a second
implementation of the same arithmetic. Tolerance 1e-9 relative (the issue's figure). Measured
when written: the compliance matrices are equal bit for bit, the tip-corner geometry differs in
the last bit where numba's ``math.hypot`` (the C library's) and Python's own differ, and the maps
by at most 6e-12 relative over the cracked paper map (benchmarks/bench_fe_eval.py).
"""

from __future__ import annotations

import copy
import dataclasses

import numpy as np
import pytest

import geardyn.stiffness.fe.model as fe_model
from geardyn.errors import NumericalError
from geardyn.stiffness.fe import FEStiffness
from geardyn.stiffness.fe._batch import solve_compatibility_fast, subset_table
from geardyn.stiffness.fe.contact import CandidateGenerator, candidates, solve_compatibility

from .conftest import coarse_settings

KEYS = ("k_mb", "load_share", "load_share_exiting", "pairs_in_contact", "transmission_error")


def _theta_cycle(model, n=181, centre=0):
    """Five mesh cycles around pair ``centre`` at the pitch point (``theta = centre * mesh
    angle``), so every handover and the extended contact are met."""
    tm = model.pair.mesh_angle
    return np.linspace((centre - 2.6) * tm, (centre + 2.6) * tm, n)


@pytest.mark.parametrize("which", [0, 1], ids=["healthy", "cracked"])
def test_compiled_evaluation_equals_reference(paper_models, which):
    _check_against_reference(paper_models[which])


@pytest.fixture(scope="module")
def gear_cracked_model(paper_case, paper_models):
    """The crack on gear tooth 7 (the 23/23 pair's bodies are shared with the pinion crack's)."""
    case = paper_case.with_overrides({"crack.gear": "gear", "crack.tooth": 7})
    return FEStiffness(case, cracked=True, settings=coarse_settings(case))


def test_compiled_evaluation_equals_reference_crack_on_gear(gear_cracked_model):
    assert gear_cracked_model.model.crack_gear == "gear"
    _check_against_reference(gear_cracked_model)


def _check_against_reference(model):
    # around the cracked pinion tooth (pair n meets the pitch point at theta = n * mesh angle):
    # positions on the cracked body and on the healthy bodies, with the handovers between them
    tooth = model.model.crack_tooth  # pair n meets pinion tooth n mod z1, gear tooth n mod z2
    theta = _theta_cycle(model, 365, tooth)
    if model.crack is not None:
        assert model.model.cracked is not None and tooth != 0
        inv = [model.model.involves_crack(candidates(model.pair, th, 0.0)) for th in theta]
        assert any(inv) and not all(inv)
    for dd in (0.0, 0.5e-3):
        fast = model.evaluate(theta, dd, compiled=True)
        ref = model.evaluate(theta, dd, compiled=False)
        for k in KEYS:
            scale = np.max(np.abs(ref[k]))
            np.testing.assert_allclose(fast[k], ref[k], rtol=0, atol=1e-9 * scale, err_msg=k)
        # the cycle includes extended contact (a share carried beyond the theoretical end) and
        # both one- and two-pair zones, i.e. the handovers
        assert np.any(ref["load_share_exiting"] > 0)
        assert set(np.unique(ref["pairs_in_contact"])) >= {1.0, 2.0}


def test_candidate_generator_is_bitwise_candidates(paper_models):
    pair = paper_models[0].pair
    tm = pair.mesh_angle
    for dd in (0.0, 0.5e-3):
        gen = CandidateGenerator(pair, dd)
        kinds = set()
        for th in np.linspace(-1.3 * tm, 1.3 * tm, 97):
            a, b = gen(th), candidates(pair, th, dd)
            for f in ("pair", "pinion_tooth", "gear_tooth", "s", "kind", "u1", "u2", "gap",
                      "arm", "radius"):
                assert np.array_equal(getattr(a, f), getattr(b, f)), f
            kinds |= set(b.kind.tolist())
        assert kinds == {0, 1, 2}  # path, pinion tip corner, gear tip corner all met


def test_compiled_solve_equals_reference_solve(paper_models):
    """Single contact problems, including ones with open extended-contact candidates."""
    model = paper_models[1]
    cm = model.model
    tm = model.pair.mesh_angle
    for th in np.linspace((cm.crack_tooth - 1) * tm, (cm.crack_tooth + 1) * tm, 23):
        cand = candidates(model.pair, th, 0.0)
        ref = cm.solve_candidates(cand, model.torque_per_width)
        fast = solve_compatibility_fast(cm.compliance(cand), cand.gap, cand.arm,
                                        model.torque_per_width, cand.radius,
                                        plane_modulus=(cm.e1, cm.e2), half_width=cm.half_width)
        assert fast.rotation == pytest.approx(ref.rotation, rel=1e-9, abs=0)
        np.testing.assert_allclose(fast.force, ref.force, rtol=0,
                                   atol=1e-9 * ref.force.max())
        assert fast.iterations == ref.iterations
    # without the local term: the same as solve_compatibility(local=None)
    cand = candidates(model.pair, 0.1 * tm, 0.0)
    c0 = cm.compliance(cand)
    ref = solve_compatibility(c0, cand.gap, cand.arm, model.torque_per_width)
    fast = solve_compatibility_fast(c0, cand.gap, cand.arm, model.torque_per_width, cand.radius,
                                    plane_modulus=(cm.e1, cm.e2), half_width=cm.half_width,
                                    local=False)
    assert fast.rotation == pytest.approx(ref.rotation, rel=1e-9, abs=0)


def test_subset_order_is_the_reference_enumeration():
    t = subset_table(3)
    assert t.astype(int).tolist() == [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0], [1, 0, 1],
                                      [0, 1, 1], [1, 1, 1]]


def test_reference_path_is_reachable(paper_models, monkeypatch):
    """``compiled=False`` really runs the pure-Python solve (and the default does not)."""
    import geardyn.stiffness.fe.contact as contact

    model = paper_models[0]
    calls = []
    orig = contact.solve_compatibility

    def spy(*a, **k):
        calls.append(1)
        return orig(*a, **k)

    monkeypatch.setattr(contact, "solve_compatibility", spy)
    theta = _theta_cycle(model, 9)
    model.evaluate(theta, 0.0, compiled=True)
    assert not calls
    model.evaluate(theta, 0.0, compiled=False)
    assert calls


def test_candidate_block_equals_candidates(paper_models):
    """:meth:`CandidateGenerator.block` (compiled tip-corner geometry) against
    :func:`candidates` position by position: integers exact, lengths to rounding (64 ulp of the
    line of action's length; numba's and Python's ``math.hypot`` may differ in the last bit)."""
    pair = paper_models[0].pair
    tm = pair.mesh_angle
    theta = np.linspace(-1.3 * tm, 1.3 * tm, 97)
    for dd in (0.0, 0.5e-3):
        gen = CandidateGenerator(pair, dd)
        s_theta, first, last = gen.span(theta)
        count = last - first + 1
        tol = 64 * np.finfo(float).eps * gen.t1t2
        kinds = set()
        for size in np.unique(count):
            rows = np.nonzero(count == size)[0]
            blk = gen.block(s_theta[rows], last[rows], int(size))
            for q, i in enumerate(rows):
                ref = candidates(pair, theta[i], dd)
                for f in ("pair", "pinion_tooth", "gear_tooth", "kind"):
                    assert np.array_equal(getattr(blk, f)[q], getattr(ref, f)), f
                for f in ("s", "u1", "u2", "gap", "arm", "radius"):
                    np.testing.assert_allclose(getattr(blk, f)[q], getattr(ref, f), rtol=0,
                                               atol=tol, err_msg=f)
                kinds |= set(ref.kind.tolist())
        assert kinds == {0, 1, 2}
        assert set(count.tolist()) == {2, 3}


@pytest.mark.parametrize("which", [0, 1], ids=["healthy", "cracked"])
def test_compliance_batch_is_bitwise_compliance(paper_models, which):
    """The vectorised spline evaluations give the scalar ones' matrices bit for bit, on the
    cracked body, the healthy bodies and across the handover between them."""
    model = paper_models[which]
    cm = model.model
    theta = _theta_cycle(model, 97, cm.crack_tooth)
    gen = CandidateGenerator(model.pair, 0.0)
    s_theta, first, last = gen.span(theta)
    count = last - first + 1
    on_crack = 0
    for size in np.unique(count):
        rows = np.nonzero(count == size)[0]
        blk = gen.block(s_theta[rows], last[rows], int(size))
        c = cm.compliance_batch(blk)
        for q, i in enumerate(rows):
            cand = gen(theta[i])  # the reference geometry; the block's own u for the matrix
            row = fe_model._row(blk, q)
            assert np.array_equal(row.pair, cand.pair)
            assert np.array_equal(c[q], cm.compliance(row))
            on_crack += cm.involves_crack(cand)
    assert (on_crack > 0) == bool(which)


def test_fallback_to_reference_gives_the_same_map(paper_models, monkeypatch):
    """Positions the compiled solve reports unsolved are re-solved by the pure-Python reference
    (forced here on every third solved position): the map is unchanged to 1e-9 and the
    reference ran exactly on those positions."""
    model = paper_models[1]
    theta = _theta_cycle(model, 121, model.model.crack_tooth)
    real = fe_model.solve_batch
    forced = []

    def flaky(c0, *a, **k):
        status, f, dth, w, it = real(c0, *a, **k)
        status = status.copy()
        status[::3] = 1
        f[::3] = -1.0  # garbage the fallback must overwrite
        dth[::3] = np.nan
        forced.append(int(np.count_nonzero(status)))
        return status, f, dth, w, it

    calls = []
    orig = model.model.solve_candidates

    def spy(cand, torque):
        calls.append(cand.pair.copy())
        return orig(cand, torque)

    monkeypatch.setattr(fe_model, "solve_batch", flaky)
    monkeypatch.setattr(model.model, "solve_candidates", spy)
    got = model.evaluate(theta, 0.0, compiled=True)
    assert len(calls) == sum(forced) > 0
    monkeypatch.undo()
    ref = model.evaluate(theta, 0.0, compiled=False)
    for k in KEYS:
        np.testing.assert_allclose(got[k], ref[k], rtol=0, atol=1e-9 * np.max(np.abs(ref[k])),
                                   err_msg=k)


def test_fallback_raises_where_the_reference_fails(paper_models):
    """A problem without solution (a negative torque: ``a'F = T < 0`` with ``F >= 0`` and
    ``a > 0``): the compiled solve reports it, the fallback reference raises."""
    model = copy.copy(paper_models[0])
    model.settings = dataclasses.replace(model.settings, torque=-model.settings.torque)
    with pytest.raises(NumericalError, match="no solution"):
        model.evaluate(_theta_cycle(model, 5), 0.0, compiled=True)
    with pytest.raises(NumericalError, match="no solution"):
        model.evaluate(_theta_cycle(model, 5), 0.0, compiled=False)


def test_singular_active_set_is_skipped_like_the_reference():
    """Two identical candidates: the KKT matrix of the pair of them is exactly singular; both
    solvers skip it and load the first alone (closed form ``F = T / a``, ``dtheta = C T / a^2``)."""
    c = np.full((2, 2), 2e-9)
    g = np.zeros(2)
    a = np.full(2, 0.05)
    torque = 100.0
    ref = solve_compatibility(c, g, a, torque)
    fast = solve_compatibility_fast(c, g, a, torque, np.full(2, 0.01), plane_modulus=(7e10, 7e10),
                                    half_width=2e-4, local=False)
    assert np.array_equal(fast.force, ref.force)
    assert fast.rotation == ref.rotation
    assert ref.force.tolist() == [torque / 0.05, 0.0]
    assert ref.rotation == pytest.approx(2e-9 * torque / 0.05 ** 2, rel=1e-12)


@pytest.mark.slow
def test_contact_kernels_compile_no_array_routine(tmp_path):
    """The compiled contact routines allocate nothing (their callers pass outputs and
    workspace, ``_batch._workspace``): compiled from a fresh numba cache, the completion, the
    batch and the single solve compile geardyn's functions, once each, and numba's ``max``, but
    none of numba's array routines (``np.zeros``, ``np.empty``, ``np.ascontiguousarray``...,
    each compiled once per array type: 1.0-1.7 s of the first run's compilation before they
    went, module docstring). Fails on the allocating version (19 array routines)."""
    import os
    import subprocess
    import sys
    import textwrap

    code = textwrap.dedent("""
        import numpy as np
        from numba.core import event
        compiled = []
        class Listener(event.Listener):
            def on_start(self, ev):
                pass
            def on_end(self, ev):
                f = ev.data["dispatcher"].py_func
                compiled.append(f"{f.__module__}:{f.__qualname__}")
        event.register("numba:compile", Listener())
        from geardyn.stiffness.fe import _batch
        rng = np.random.default_rng(1)
        _batch.complete_nb(rng.random((5, 3)) * 0.03, 0.005, 0.025, 0.03, 0.1, 0.02, 0.03,
                           0.05, 0.006, 0.008)
        c0 = np.stack([np.eye(3) * 1e-10] * 4)
        gap, arm, rad = np.zeros((4, 3)), np.full((4, 3), 0.02), np.full((4, 3), 0.01)
        _batch.solve_batch(c0, gap, arm, 100.0, rad, plane_modulus=(2.2e11, 2.2e11),
                           half_width=1e-4)
        _batch.solve_compatibility_fast(c0[0], gap[0], arm[0], 100.0, rad[0],
                                        plane_modulus=(2.2e11, 2.2e11), half_width=1e-4)
        print("\\n".join(compiled))
    """)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    r = subprocess.run([sys.executable, "-c", code], env=env, text=True, capture_output=True,
                       timeout=300)
    assert r.returncode == 0, r.stderr
    compiled = r.stdout.split()
    ours = [c.split(":")[1] for c in compiled if c.startswith("geardyn.stiffness.fe._batch:")]
    assert sorted(ours) == sorted(["_wrap_angle", "_complete_nb", "_gesv", "_try", "_qp_nb",
                                   "_solve_nb", "_solve_batch_nb"]), compiled
    others = [c for c in compiled if not c.startswith("geardyn.stiffness.fe._batch:")]
    assert others and all(c == "numba.cpython.builtins:ol_max.<locals>.impl" for c in others), \
        others
