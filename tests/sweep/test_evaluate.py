"""One sweep run: simulation + diagnostics, checked against the public pipeline.

The sweep computes the diagnostics without the PWVDs (most of ``diagnose``'s cost); the oracle is
``geardyn.diagnostics.diagnose(...).to_dict()`` on the same signals, and
``geardyn.dynamics.simulate`` + ``summary`` for the record's summary.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn import paper_case
from geardyn.diagnostics import diagnose
from geardyn.studies.sweep import GeardynEvaluator, diagnostic_features, evaluate_run
from geardyn.studies.sweep.evaluate import _METRICS, _STATISTICS, _cached_map, _stiffness_map
from geardyn.studies.sweep.spec import StoreSpec

#: Short runs on a coarse map (about 2.5 revolutions recorded).
SHORT = {"simulation.record_time": 0.15, "simulation.settle_time": 0.02,
         "stiffness.centre_distances": 6, "stiffness.nodes_per_segment": 6}


def check_against_diagnose(features: dict, d: dict) -> None:
    for name, sd in d["signals"].items():
        for f, _, _ in _STATISTICS:
            assert features[f"{name}__{f}"] == pytest.approx(sd["statistics"][f], rel=1e-12,
                                                             abs=1e-300), (name, f)
        for f, _ in _METRICS:
            assert features[f"{name}__{f}"] == pytest.approx(
                sd["condition_metrics"][f], rel=1e-12), (name, f)
        for mine, theirs in [("residual_kurtosis", "residual"),
                             ("envelope_kurtosis", "envelope"),
                             ("am_kurtosis", "amplitude_modulation"),
                             ("pm_kurtosis", "phase_modulation")]:
            assert features[f"{name}__{mine}"] == pytest.approx(sd["kurtosis"][theirs],
                                                                rel=1e-12), (name, mine)
        mh = features[f"{name}__mesh_harmonic_rms"]
        for k, v in enumerate(mh, start=1):
            assert v == pytest.approx(sd["mesh_harmonics_rms"][str(23 * k)]["rms"], rel=1e-12)
        assert features["n_averages"] == sd["n_averages"]


def test_features_equal_the_diagnostics_pipeline():
    rng = np.random.default_rng(1)
    n = 40_000
    angle = np.linspace(0.0, 12 * 2 * np.pi, n) + 0.01 * np.sin(np.linspace(0, 30, n))
    mesh = np.sin(23 * angle) + 0.3 * np.sin(46 * angle + 0.4)
    fault = np.exp(-((np.mod(angle, 2 * np.pi) - 3.0) / 0.05) ** 2)
    signals = {"a": mesh + 0.5 * fault + 0.05 * rng.standard_normal(n),
               "b": 2.0 + mesh * (1 + 0.2 * fault) + 0.05 * rng.standard_normal(n)}
    feats = diagnostic_features(signals, angle, teeth=23, samples_per_rev=1024)
    check_against_diagnose(feats, diagnose(signals, teeth=23, angle=angle,
                                           samples_per_rev=1024).to_dict())


@pytest.mark.slow
def test_evaluate_run_end_to_end():
    from geardyn.dynamics import simulate, summary
    from geardyn.stiffness import build_map

    # the PEM map: what is tested is evaluate_run against diagnose on the same record; the FE
    # map through a sweep is run by tests/faults/test_examples.py (crack-depth sweep)
    case = paper_case({**SHORT, "stiffness.method": "pem"})
    feats = evaluate_run(case)
    ds = simulate(case, build_map(case, cracked=True))
    sig = {s: ds[s].values for s in ("v_yg", "omega_p", "transmission_error")}
    d = case.diagnostics
    check_against_diagnose(feats, diagnose(sig, teeth=23, angle=ds.theta_p.values,
                                           samples_per_rev=d.samples_per_rev,
                                           harmonic=d.harmonic, bandwidth=d.bandwidth,
                                           residual_preset=d.residual_preset).to_dict())
    s = summary(ds)
    assert feats["sim__mean_centre_distance_change"] == s["mean_centre_distance_change_m"]
    assert feats["sim__mean_pressure_angle"] == pytest.approx(
        math.radians(s["mean_pressure_angle_deg"]), rel=1e-14)
    assert feats["sim__mean_pinion_speed"] == s["mean_pinion_speed_rad_s"]
    # every declared output is returned with its shape, and nothing undeclared
    outs = GeardynEvaluator().outputs(case)
    assert {o.name for o in outs} == set(feats)
    for o in outs:
        assert np.shape(feats[o.name]) == o.shape, o.name


def test_map_memo_by_inputs_and_seeded_noise():
    case = paper_case({**SHORT, "stiffness.method": "pem"})  # the memo is tested, not the FE
    _cached_map.cache_clear()
    m1 = _stiffness_map(case)
    assert _stiffness_map(case.with_overrides({"motor.torque": 80.0})) is m1  # same inputs
    deeper = _stiffness_map(case.with_overrides({"crack.depth": 0.002}))
    assert deeper is not m1 and deeper.attrs["inputs_hash"] != m1.attrs["inputs_hash"]
    info = _cached_map.cache_info()
    assert (info.hits, info.misses, info.currsize, info.maxsize) == (1, 2, 2, 32)
    noisy = StoreSpec(noise_snr_db=20.0, tsa=True)
    a = evaluate_run(case, noisy, seed=5)
    b = evaluate_run(case, noisy, seed=5)
    c = evaluate_run(case, noisy, seed=6)
    clean = evaluate_run(case, StoreSpec(tsa=True))
    np.testing.assert_array_equal(a["v_yg__tsa"], b["v_yg__tsa"])
    assert not np.array_equal(a["v_yg__tsa"], c["v_yg__tsa"])
    # 20 dB of white noise averaged over the revolutions: a small, non-zero change of the TSA
    rel = np.std(a["v_yg__tsa"] - clean["v_yg__tsa"]) / np.std(clean["v_yg__tsa"])
    assert 0.005 < rel < 0.1
