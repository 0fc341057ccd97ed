"""The measurement study on a simulated run (PEM map, 1 s record): tachometer TSA against the
exact-angle TSA, the TSA noise floor against 1/sqrt(revolutions), the files against each other
and ``diagnose_file`` reading them like measured data."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from geardyn.config import paper_case
from geardyn.diagnostics import tach_pulse_times, tsa
from geardyn.studies.measure import measure

pytestmark = pytest.mark.slow

FAST = ['stiffness.method="pem"', "stiffness.centre_distances=6", "stiffness.nodes_per_segment=8",
        "simulation.settle_time=0.1"]


@pytest.fixture(scope="module")
def run():
    case = paper_case([*FAST, "simulation.record_time=1.0", "measurement.snr=10.0",
                       "measurement.tach_jitter=0.0", "measurement.seed=11"])
    return measure(case)


def test_record_layout_and_provenance(run):
    ds = run.record
    m = run.measured
    assert ds.sizes["time"] == 50_000 and ds.attrs["fs"] == 50_000.0
    assert ds["acc"].attrs["units"] == "m/s^2" and ds["acc_g"].attrs["units"] == "g"
    assert ds["tach"].attrs["units"] == "V"
    np.testing.assert_allclose(ds["acc_g"].values * 9.80665, ds["acc"].values, rtol=1e-15)
    assert ds.attrs["noise_seed"] == 11 and "measurement" in ds.attrs["case_toml"]
    assert ds.attrs["stiffness_method"] == "pem" and ds.attrs["clipped_samples"] == 0
    # the requested SNR holds on this 1 s record too (before the 24-bit ADC)
    assert 10 * np.log10(np.var(m.acc_clean) / np.var(m.noise)) == pytest.approx(10.0, abs=0.1)
    # and the ADC adds only its quantisation (step 2 * 50 g / 2^24)
    q = 2 * 50 * 9.80665 / 2 ** 24
    assert np.max(np.abs(m.acc - (m.acc_clean + m.noise))) <= q / 2 + 1e-15


def test_tach_tsa_agrees_with_exact_angle_tsa(run):
    """Noise-free channel, once-per-rev tachometer without jitter: the TSA through the pulse
    spline against the TSA on the simulated pinion angle over the same 14 revolutions.
    Measured: RMS difference 0.43 % and largest difference 3.7 % of the TSA's standard
    deviation; the pulse times themselves are recovered from the sampled channel to 1e-12 s."""
    m = run.measured
    tp = tach_pulse_times(m.tach, fs=m.fs)
    np.testing.assert_allclose(tp, m.pulse_times, atol=1e-12)
    n_rev = tp.size - 4
    exact = tsa(m.acc_clean, angle=run.exact_angle(), skip_revolutions=1, n_revolutions=n_rev)
    tach = tsa(m.acc_clean, tach_times=tp, fs=m.fs, skip_revolutions=1, n_revolutions=n_rev)
    assert exact.n_averages == tach.n_averages == n_rev >= 12
    d = exact.average - tach.average
    scale = np.std(exact.average)
    assert np.std(d) < 0.01 * scale
    assert np.max(np.abs(d)) < 0.05 * scale


def test_tsa_noise_floor_falls_as_one_over_sqrt_revolutions(run):
    m = run.measured
    tp = tach_pulse_times(m.tach, fs=m.fs)
    revs = np.array([1, 2, 4, 8, 16])
    floor = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # one revolution: "no averaging" warning
        for r in revs:
            floor.append(np.std(tsa(m.noise, tach_times=tp, fs=m.fs, n_revolutions=int(r),
                                    min_revolutions=1).average))
    slope = np.polyfit(np.log(revs), np.log(floor), 1)[0]
    assert slope == pytest.approx(-0.5, abs=0.05)


def test_files_read_like_measured_data(run, tmp_path):
    from geardyn.diagnostics import diagnose_file
    from geardyn.measurement.record import write_csv, write_mat, write_netcdf

    ds = run.record
    paths = {s: tmp_path / f"m.{s}" for s in ("nc", "csv", "mat")}
    write_netcdf(ds, paths["nc"])
    write_csv(ds, paths["csv"])
    write_mat(ds, paths["mat"])
    opts = {"signals": ["acc"], "tach": "tach", "teeth": 23, "samples_per_rev": 1024}
    res = {s: diagnose_file(p, fs=50_000.0 if s == "csv" else None, **opts)
           for s, p in paths.items()}
    d_nc = res["nc"].to_dict()["signals"]["acc"]
    assert d_nc["n_averages"] >= 16
    for s in ("csv", "mat"):
        d = res[s].to_dict()["signals"]["acc"]
        assert d["n_averages"] == d_nc["n_averages"]
        assert d["kurtosis"]["tsa"] == pytest.approx(d_nc["kurtosis"]["tsa"], rel=1e-9)


def test_indicators_are_finite_and_sensible_on_the_measured_signal(run):
    """Through the housing path and 20 dB of noise the healthy pair's indicators are those of
    a Gaussian difference signal (FM4 and NA4 near 3, small energy ratio); the 5 mm crack
    raises FM4 and NA4 far above. Measured on 1 s (17 revolutions): healthy at 20 dB FM4 3.17,
    NA4 3.12, ER 0.019; cracked at 10 dB FM4 14.5, NA4 17.0, ER 0.114. No tooth errors here
    (those are geardyn.modifications'), so the healthy difference signal is mostly noise."""
    from geardyn.diagnostics import condition_metrics

    healthy = measure(paper_case([*FAST, "simulation.record_time=1.0"]), cracked=False)
    out = {}
    for name, r in (("healthy", healthy), ("cracked", run)):
        m = r.measured
        avg = tsa(m.acc, tach_times=tach_pulse_times(m.tach, fs=m.fs), fs=m.fs).average
        out[name] = condition_metrics(avg, teeth=23)
    h, c = out["healthy"], out["cracked"]
    assert 2.5 < h.FM4 < 3.6 and 2.5 < h.NA4 < 3.6 and 0 < h.EnergyRatio < 0.05
    assert c.FM4 > 6 and c.NA4 > 6 and c.EnergyRatio > 2 * h.EnergyRatio
