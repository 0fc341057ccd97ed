"""Substructuring wired into the FE map (``[stiffness.fe] substructure = true``, issue 16 item 2).

A new crack size reuses the cached healthy superelement and meshes only the faulty tooth's sector;
the crack enters as its change on the substructured mesh added to the whole-body healthy body
(:func:`geardyn.stiffness.fe.model.crack_on_whole_body`).

Oracles:

* the whole-body cracked map (:func:`geardyn.stiffness.fe.mesh.build_body_mesh` remeshed with the
  crack, solved whole): another discretisation, so the two differ by discretisation only. Measured
  on this coarse mesh when written: 0.20 % of the healthy stiffness at most for the 5 mm crack.
  The whole-body path itself moves the map by 0.26 % for a 0.1-0.3 mm crack (its remeshed body),
  so the bound is twice that, 0.5 %;
* the vanishing crack: the map tends to the healthy map as the depth goes to zero (measured
  0.07 % at 0.1 mm, 0.26 % at 0.3 mm, 1.7 % at 1 mm), and the change formula is exact for a zero
  change (an identity checked to round-off);
* a stored and re-read superelement gives the same coefficients bit for bit.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from geardyn.stiffness import map_inputs
from geardyn.stiffness.fe import FEStiffness
from geardyn.stiffness.fe.model import body_influence, crack_on_whole_body, healthy_superelement
from geardyn.stiffness.fe.substructure import HealthySuperelement

from .conftest import coarse_settings

TH = np.linspace(0.0, 2.0 * np.pi, 4000, endpoint=False)  # one pinion revolution [rad]


@pytest.fixture(scope="module")
def sub_settings(paper_case):
    return dataclasses.replace(coarse_settings(paper_case), substructure=True)


@pytest.fixture(scope="module")
def healthy_k(paper_models):
    return paper_models[0].evaluate(TH, 0.0)["k_mb"]


def _k(case, settings, depth=None):
    c = case if depth is None else case.with_overrides({"crack.depth": depth})
    model = FEStiffness(c, cracked=True, settings=settings)
    return model, model.evaluate(TH, 0.0)["k_mb"]


def test_a_new_crack_size_reuses_the_superelement_and_matches_the_whole_body_map(
        paper_case, paper_models, sub_settings, healthy_k):
    first, k_sub = _k(paper_case, sub_settings)
    st = first.influence["cracked"].stats
    assert st["crack_as_change"] == 1.0 and "dofs_R" in st
    k_whole = paper_models[1].evaluate(TH, 0.0)["k_mb"]
    diff = np.abs(k_sub - k_whole).max() / healthy_k.max()
    drop_sub = ((healthy_k - k_sub) / healthy_k).max()
    drop_whole = ((healthy_k - k_whole) / healthy_k).max()
    print(f"5 mm crack: max |sub - whole| / max healthy {diff:.2e}; largest drop "
          f"{drop_sub:.4f} (substructured) vs {drop_whole:.4f} (whole body)")
    assert diff < 5e-3
    assert drop_whole > 0.1 and abs(drop_sub - drop_whole) < 5e-3
    # away from the faulty tooth both use the healthy bodies: identical there
    away = healthy_k == k_whole
    assert away.sum() > TH.size // 2
    np.testing.assert_array_equal(k_sub[away], healthy_k[away])
    # a second size: the superelement (and the healthy bodies) come from the cache
    second, _ = _k(paper_case, sub_settings, 4e-3)
    assert second.influence["cracked"].stats["superelement_cached"] == 1.0
    assert second.from_cache["pinion"] and second.from_cache["gear"]
    faulty = [name for name in second.from_cache if name not in ("pinion", "gear")]
    assert len(faulty) == 1 and not second.from_cache[faulty[0]]
    r, h = second.influence["cracked"].stats["dofs_R"], st["dofs_H"]
    print(f"DOFs: R {r:.0f}, H {h:.0f}")
    assert r < 0.5 * h


def test_a_vanishing_crack_tends_to_the_healthy_map(paper_case, sub_settings, healthy_k):
    devs = []
    for depth in (0.1e-3, 0.3e-3, 1e-3):
        _, k = _k(paper_case, sub_settings, depth)
        devs.append(float((np.abs(k - healthy_k) / healthy_k).max()))
    print("max |k - k_healthy| / k_healthy at 0.1, 0.3, 1 mm:", devs)
    assert devs[0] < 1.5e-3            # measured 0.07 %; the whole-body path gives 0.26 %
    assert devs[0] < devs[1] < devs[2]  # monotone in the depth


def test_the_change_formula_is_exact_for_no_change(paper_case, sub_settings):
    pair = paper_case.gear_pair()
    fe = FEStiffness(paper_case, cracked=False, settings=sub_settings)
    se, _ = healthy_superelement(pair.pinion, fe.material, sub_settings)
    healthy, _ = body_influence(pair.pinion, fe.material, sub_settings, None)
    ref = se.reference()
    offs = tuple(sorted(set(se.offsets) | {0}))
    H = crack_on_whole_body(ref, ref, healthy, offs, offs)
    for a, i in enumerate(offs):
        for b, j in enumerate(offs):
            if j - i in healthy.read_offsets:
                np.testing.assert_allclose(H[a, b], healthy.H[0, healthy.read_offsets.index(j - i)],
                                           rtol=1e-12, atol=0)
            else:
                np.testing.assert_array_equal(H[a, b], ref[a, b])


def test_a_stored_superelement_gives_the_same_coefficients(paper_case, sub_settings, tmp_path):
    pair = paper_case.gear_pair()
    fe = FEStiffness(paper_case, cracked=False, settings=sub_settings)
    se, _ = healthy_superelement(pair.pinion, fe.material, sub_settings)
    se.save(tmp_path / "se.npz")
    back = HealthySuperelement.load(tmp_path / "se.npz", pair.pinion, fe.material,
                                    sub_settings.mesh_settings())
    assert back.mesh is None and back.inputs_hash == se.inputs_hash != ""
    from geardyn.stiffness.fe.mesh import CrackGeometry

    crack = CrackGeometry(depth=2e-3, angle=0.7)
    np.testing.assert_array_equal(back.influence(crack=crack)[0].H,
                                  se.influence(crack=crack)[0].H)
    np.testing.assert_array_equal(back.reference(), se.reference())


def test_the_switch_keys_only_faulty_maps(paper_case):
    on = paper_case.with_overrides({"stiffness.fe.substructure": True})
    assert map_inputs(on, "fe", False) == map_inputs(paper_case, "fe", False)
    assert map_inputs(on, "fe", True) != map_inputs(paper_case, "fe", True)
    assert map_inputs(on, "pem", True) == map_inputs(paper_case, "pem", True)
