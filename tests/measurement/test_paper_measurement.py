"""The measurement stage of ``geardyn run`` (:mod:`geardyn.studies.paper_measurement`): the
paper's indicators on a realistic record, and what the healthy pair's indicators become.

Oracles: the sampling distribution of the kurtosis of Gaussian samples (mean 3, standard
deviation ``sqrt(24 / N)`` for ``N`` independent samples; Kendall & Stuart, the large-sample
variance of ``b2``), and the exact kurtosis of a sum of a signal and independent Gaussian noise,
``kurt(x + n) - 3 = (kurt(x) - 3) w^2`` with ``w = var(x) / (var(x) + var(n))`` (expand the
fourth moment; odd moments of the noise vanish).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from geardyn.studies.paper_measurement import (
    DEFAULT_ERRORS,
    INDICATORS,
    VARIANTS,
    detections,
    drivers,
    statements,
)

#: Standard deviation of the sample kurtosis of ``N = 2048`` independent Gaussian samples (one
#: TSA revolution), ``sqrt(24 / N)``. The TSA of band-limited noise has fewer independent
#: samples than points only if the band is narrower than the TSA's: here the noise is white to
#: fs/2 = 25 kHz, beyond the 2048-point TSA's 1024 orders (18.6 kHz), so N = 2048.
SIGMA_KURT = math.sqrt(24 / 2048)


def _healthy_error_record(case, result):
    """The healthy simulation with the stage's tooth errors (from the cache) and its forces."""
    from geardyn.studies.measure import housing_forces
    from geardyn.studies.paper import cached_simulation

    err = case.with_overrides(DEFAULT_ERRORS)
    ds = cached_simulation(err, result.maps["healthy"], "II")
    return ds, housing_forces(err, result.maps["healthy"], ds)


def _fm4_and_difference(case, ds, forces, **chain):
    from geardyn.diagnostics import condition_metrics, tach_pulse_times, tsa
    from geardyn.diagnostics.spectra import difference
    from geardyn.studies.measure import chain_from_config

    cfg = case.measurement.model_copy(update=chain)
    m = chain_from_config(cfg).measure(ds["time"].values, forces, ds["theta_p"].values,
                                       ds["omega_p"].values)
    avg = tsa(m.acc, tach_times=tach_pulse_times(m.tach, fs=m.fs), fs=m.fs).average
    return condition_metrics(avg, teeth=case.pinion.teeth).FM4, difference(
        avg, teeth=case.pinion.teeth)


@pytest.mark.slow
def test_stage_fills_every_variant_and_the_realistic_healthy_indicators_are_finite(
        measured_study):
    """Every variant has every indicator for both states; on the realistic record (class-6
    errors, 20 dB, TSA from the tachometer) the healthy NA4*, energy ratio, FM4 and NA4 are
    finite and positive (on the ideal record NA4* is a ratio to numerical remainder and is
    reported undefined). Measured here: healthy FM4 5.6, NA4* 5.9, ER 0.46."""
    _case, result = measured_study
    m = result.summary["measurement"]
    assert "skipped" not in m
    keys = {k for k, _, _ in INDICATORS}
    for name in VARIANTS:
        for state in ("healthy", "cracked"):
            assert set(m["indicators"][name][state]) == keys
            assert m["records"][f"{name}|{state}"]["revolutions"] >= 14
            assert result.measured_tsa[(name, state)].size == 2048
    h = m["indicators"]["errors+noise"]["healthy"]
    assert all(math.isfinite(v) for v in h.values()), h
    assert h["NA4star"] > 0 and 0 < h["EnergyRatio"] < 10 and h["FM4"] > 0 and h["NA4"] > 0
    # the healthy baseline is its own record: NA4* = m4(r)/m2(r)^2 = NA4 with one record
    assert h["NA4star"] == pytest.approx(h["NA4"], rel=1e-12)
    assert m["undefined"] == {"ideal": ["NA4star", "EnergyRatio cracked / healthy"]}
    assert m["detections"]["ideal"]["NA4star"]["ratio"] is None
    assert m["detections"]["errors+noise"]["NA4star"]["ratio"] > 0
    # the noise variant's additive noise meets the requested 20 dB (before averaging)
    r = m["records"]["noise|healthy"]
    assert 20 * math.log10(r["acc_rms_m_s2"] / r["noise_rms_m_s2"]) == pytest.approx(20, abs=0.1)
    assert statements(m) and all(isinstance(s, str) for s in statements(m))


@pytest.mark.slow
def test_healthy_fm4_is_gaussian_where_noise_dominates_the_difference_signal(measured_study):
    """FM4 is the kurtosis of the difference signal; it is 3 when that signal is Gaussian.

    With the class-6 errors and noise 10x the acceleration RMS (SNR -20 dB, 16 revolutions
    averaged), the noise carries over 95% of the difference signal's variance, so the
    mixture law puts FM4 within 0.03 of 3. Band: each of 8 noise seeds within
    3 +/- 4 sqrt(24/2048) = 3 +/- 0.43, their mean within 3 +/- 4 sqrt(24/2048)/sqrt(8) =
    3 +/- 0.15. Measured on the paper's PEM case: mean 3.06, seed-to-seed STD 0.07."""
    case, result = measured_study
    ds, forces = _healthy_error_record(case, result)
    _, d_err = _fm4_and_difference(case, ds, forces, snr=math.inf, adc_bits=0, tach_jitter=0.0)
    level = 10 * result.summary["measurement"]["records"]["errors|healthy"]["acc_rms_m_s2"]
    fm4 = []
    for seed in range(8):
        f, d = _fm4_and_difference(case, ds, forces, snr=None, noise_level=level, seed=seed)
        w = d_err.var() / d.var()
        assert w < 0.1  # noise-dominated: the errors' share of the variance
        fm4.append(f)
    fm4 = np.array(fm4)
    assert np.all(np.abs(fm4 - 3) < 4 * SIGMA_KURT), fm4
    assert abs(fm4.mean() - 3) < 4 * SIGMA_KURT / math.sqrt(fm4.size), fm4


@pytest.mark.slow
def test_healthy_fm4_with_errors_and_noise_follows_the_gaussian_mixture_law(measured_study):
    """Between the noise-free errors-only record and pure noise, FM4 follows
    ``3 + (FM4_err - 3) w^2`` (module docstring) on average over 8 seeds, within four standard
    errors of the mean (sample STD over seeds / sqrt(8)), at noise 1.5x the acceleration RMS
    (w about 0.7). And the realistic record of the stage (20 dB) lies between 3 and the
    errors-only FM4 (plus the Gaussian sampling band): independent noise can only pull the
    kurtosis towards 3. With class-6 errors FM4 is not near 3 (5.6 measured): each tooth's
    error excites a transient of the 3 kHz housing mode that decays in about 1 ms, under half
    a mesh period (2.4 ms), so the errors' difference signal is intermittent."""
    case, result = measured_study
    m = result.summary["measurement"]["indicators"]
    ds, forces = _healthy_error_record(case, result)
    f_err, d_err = _fm4_and_difference(case, ds, forces, snr=math.inf, adc_bits=0,
                                       tach_jitter=0.0)
    assert f_err == pytest.approx(m["errors"]["healthy"]["FM4"], rel=1e-9)
    level = 1.5 * result.summary["measurement"]["records"]["errors|healthy"]["acc_rms_m_s2"]
    got, want = [], []
    for seed in range(8):
        f, d = _fm4_and_difference(case, ds, forces, snr=None, noise_level=level, seed=seed)
        w = d_err.var() / d.var()
        got.append(f)
        want.append(3 + (f_err - 3) * w * w)
    got, want = np.array(got), np.array(want)
    assert 0.3 < np.mean(want - 3) / (f_err - 3) < 0.8  # a real mixture, neither limit
    se = np.std(got - want, ddof=1) / math.sqrt(got.size)
    assert abs(np.mean(got - want)) < 4 * se + 1e-12, (got, want)
    f_real = m["errors+noise"]["healthy"]["FM4"]
    lo, hi = min(3.0, f_err), max(3.0, f_err)
    assert lo - 4 * SIGMA_KURT < f_real < hi + 4 * SIGMA_KURT


def _table(e, n, b, i=1.0):
    row = {k: 1.0 for k, _, _ in INDICATORS}
    return {"ideal": {"healthy": {**row, "FM4": i}, "cracked": {**row, "FM4": i}},
            "errors": {"healthy": {**row, "FM4": e}, "cracked": {**row, "FM4": e}},
            "noise": {"healthy": {**row, "FM4": n}, "cracked": {**row, "FM4": 2 * n}},
            "errors+noise": {"healthy": {**row, "FM4": b}, "cracked": {**row, "FM4": b}}}


def test_drivers_and_detections_are_computed_from_the_variants():
    ind = _table(e=5.5, n=3.0, b=5.4)
    d = drivers(ind)
    assert d["healthy"]["FM4"]["driver"] == "errors"
    assert d["healthy"]["FM0"]["driver"] == "neither"  # 1.0 everywhere
    assert drivers(_table(e=6.0, n=3.1, b=3.2))["healthy"]["FM4"]["driver"] == "noise"
    det = detections(ind)
    assert det["noise"]["FM4"] == {"ratio": 2.0, "detected": True}
    assert det["errors"]["FM4"] == {"ratio": 1.0, "detected": False}
    undefined = {"ideal": ["NA4star", "EnergyRatio cracked / healthy"]}
    assert detections(ind, undefined)["ideal"]["NA4star"]["ratio"] is None
    assert drivers(ind, undefined)["healthy"]["NA4star"]["ideal"] is None
    text = statements({"drivers": d, "detections": det})
    assert any("FM4" in t and "errors" in t for t in text)
    assert any(t.startswith("Crack seen (cracked / healthy > 1.5) on noise only by 1 of")
               for t in text)
    # a fault that is not a crack is named as a fault (the data keep the key "cracked")
    text = statements({"drivers": d, "detections": det}, ("faulty", "fault"))
    assert any(t.startswith("Fault seen (faulty / healthy > 1.5) on noise only by 1 of")
               for t in text)
    assert any(t.startswith("Faulty pair, realistic record: ") for t in text)
    assert not any("crack" in t.lower() for t in text)


@pytest.mark.slow
def test_healthy_fm4_against_housing_damping(measured_study):
    """The realistic record re-measured with every housing mode's damping ratio set to each of
    HOUSING_DAMPING (``housing_damping_sweep``).

    Oracles: at the case's own damping ratio (5 %) the sweep repeats the main 'errors + noise'
    variant (same forces, chain and noise seed) and must give its FM4, NA4* and energy ratio
    bit for bit; the decay time over the mesh period is ``1 / (zeta 2 pi f) / (2 pi /
    (omega z))``. The physics the issue asked about ("FM4 near 3 for a healthy gear with random
    errors and noise"): with the paper case's tooth errors the healthy FM4 rises with the
    housing damping, because a damped mode leaves each mesh's unequal transient isolated and
    impulsive while a lightly damped one lets successive transients overlap. Measured when
    written (single 3 kHz mode, PEM, CLI with 17 revolutions): 2.6, 3.1, 4.2, 6.6, 7.6 at
    0.5, 1, 2, 5, 10 %; the test asserts the rise (end to end) and that FM4 is within 0.5 of 3
    somewhere in the physically usual 0.5-2 % range, and not at 5 % and 10 %.
    """
    from geardyn.studies.paper_measurement import HOUSING_DAMPING, housing_statements

    case, result = measured_study
    m = result.summary["measurement"]
    hd = m["housing_damping"]
    assert hd["damping_ratios"] == list(HOUSING_DAMPING)
    own = hd["case_damping_ratios"]
    assert own == [0.05]
    i = HOUSING_DAMPING.index(own[0])
    for state in ("healthy", "cracked"):
        for k in ("FM4", "NA4star", "EnergyRatio"):
            assert hd[state][k][i] == m["indicators"]["errors+noise"][state][k], (state, k)
    f = hd["mode_frequencies_Hz"][0]
    for zeta, r in zip(HOUSING_DAMPING, hd["decay_over_mesh_period"], strict=True):
        assert r == pytest.approx(1 / (zeta * 2 * math.pi * f) / hd["mesh_period_s"], rel=1e-12)
    fm = hd["healthy"]["FM4"]
    print("healthy FM4 over housing damping", dict(zip(HOUSING_DAMPING, fm, strict=True)))
    assert fm[-1] > fm[0] + 2 and fm[HOUSING_DAMPING.index(0.05)] > fm[0]
    near = [z for z, v in zip(HOUSING_DAMPING, fm, strict=True) if abs(v - 3) <= 0.5]
    assert near and all(z <= 0.02 for z in near), near
    text = " ".join(housing_statements(hd))
    assert "within 0.5 of 3" in text and all(f"{100 * z:g}%" in text for z in near)


@pytest.mark.slow
def test_housing_damping_needs_two_revolutions_after_the_lead_in(measured_study):
    """A record long enough for a damping ratio's lead-in and tail but leaving one whole
    revolution after them is not averaged (a one-revolution TSA is no average, and not what the
    other ratios compute): that ratio is not computed, with the reason, and no warning reaches
    the user (``geardyn run --quick`` printed "TSA over only 1 whole revolution(s)" out of
    context). Oracle: the case's lead-in ``L(zeta)`` (the chain's own) and revolution period
    decide which ratios keep at least 2 revolutions in ``T - 2 L``; those are computed."""
    from geardyn.studies.measure import chain_from_config
    from geardyn.studies.paper import cached_simulation
    from geardyn.studies.paper_measurement import HOUSING_DAMPING, housing_damping_sweep

    case, result = measured_study
    err = case.with_overrides(DEFAULT_ERRORS)
    shaft = "p" if chain_from_config(case.measurement).tach.shaft == "pinion" else "g"
    records = {}
    for state in ("healthy", "cracked"):
        ds = cached_simulation(err, result.maps[state], "II")
        t = ds["time"].values
        t_rev = 2 * math.pi / float(np.mean(ds[f"omega_{shaft}"].values))
        records[state] = (err, ds.isel(time=np.flatnonzero(t <= t[0] + 0.3)), result.maps[state])
    freqs = case.measurement.mode_frequencies
    span = {}
    for zeta in HOUSING_DAMPING:
        chain = chain_from_config(case.measurement.model_copy(
            update={"mode_damping_ratios": [zeta] * len(freqs)}))
        # revolutions left after the lead-in and tail, before the pulses' phase is counted
        span[zeta] = (0.3 - chain.lead_in() - chain.tail()) / t_rev
    one = [z for z in HOUSING_DAMPING if 1 < span[z] < 2]
    assert one, span  # the record length makes at least one ratio a one-revolution case
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        hd = housing_damping_sweep(err, records, case.pinion.teeth)
    for z in HOUSING_DAMPING:
        fm = hd["healthy"]["FM4"][HOUSING_DAMPING.index(z)]
        if span[z] >= 3:  # two whole revolutions whatever the pulse phase
            assert math.isfinite(fm), (z, hd.get("not_computed"))
        if span[z] < 2:
            assert math.isnan(fm) and f"{z:g}" in hd["not_computed"], (z, hd)
    assert any("whole revolution" in hd["not_computed"][f"{z:g}"] for z in one)


def test_housing_statements_follow_the_numbers():
    from geardyn.studies.paper_measurement import housing_statements

    hd = {"damping_ratios": [0.01, 0.05], "case_damping_ratios": [0.05],
          "decay_over_mesh_period": [2.2, 0.44], "healthy": {"FM4": [3.2, 6.6]},
          "mode_frequencies_Hz": [3000.0]}
    (text,) = housing_statements(hd)
    assert "1%: 3.2" in text and "5%: 6.6" in text and "at 1% (decay 2.2 mesh periods)" in text
    hd["healthy"]["FM4"] = [4.0, 6.6]
    assert "not within 0.5 of 3" in housing_statements(hd)[0]
    # a damping not computed (record too short) is NaN, stored in the cached JSON as null
    hd["healthy"]["FM4"] = [None, 3.2]
    hd["not_computed"] = {"0.01": "too short"}
    (text,) = housing_statements(hd)
    # one word for it, in the sentence and in the report's table (NOT_COMPUTED)
    assert "1%: not computed" in text and "Not computed at 1%" in text and "at 5%" in text
    assert "undefined" not in text
    # "not within 0.5 of 3" says why 3 matters
    hd["healthy"]["FM4"] = [None, 4.0]
    (text,) = housing_statements(hd)
    assert "not within 0.5 of 3, the value of a Gaussian difference signal, at any" in text
    assert housing_statements({"skipped": "an FRF table"}) == [
        "Housing damping not varied: an FRF table."]
    assert housing_statements(None) == []
