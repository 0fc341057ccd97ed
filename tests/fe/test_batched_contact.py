"""The compiled FE map evaluation equals the per-position pure-Python reference (issue 16).

Oracle: :meth:`FEStiffness.evaluate` with ``compiled=False`` (today's per-position path:
``candidates`` + ``PairContactModel.solve_candidates`` + ``solve_compatibility``), a second
implementation of the same arithmetic. Tolerance 1e-9 relative (the issue's figure); on this
machine the two agree bit for bit.
"""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.stiffness.fe._batch import solve_compatibility_fast, subset_table
from geardyn.stiffness.fe.contact import CandidateGenerator, candidates, solve_compatibility

from .conftest import coarse_settings  # noqa: F401  (the coarse models come from conftest)

KEYS = ("k_mb", "load_share", "load_share_exiting", "pairs_in_contact", "transmission_error")


def _theta_cycle(model, n=181, centre=0):
    """Five mesh cycles around pair ``centre`` at the pitch point (``theta = centre * mesh
    angle``), so every handover and the extended contact are met."""
    tm = model.pair.mesh_angle
    return np.linspace((centre - 2.6) * tm, (centre + 2.6) * tm, n)


@pytest.mark.parametrize("which", [0, 1], ids=["healthy", "cracked"])
def test_compiled_evaluation_equals_reference(paper_models, which):
    model = paper_models[which]
    # around the cracked pinion tooth (pair n meets the pitch point at theta = n * mesh angle):
    # positions on the cracked body and on the healthy bodies, with the handovers between them
    tooth = model.model.crack_tooth
    theta = _theta_cycle(model, 365, tooth)
    if which:
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
