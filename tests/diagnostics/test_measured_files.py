"""Measured data as acquisition systems write it, and the mistakes made with it (the third QA
walkthrough, a condition-monitoring engineer with their own files): each test fails on the code
before its fix.

The record: a 23-tooth pinion at 25 rev/s (or a 10 -> 30 rev/s run-up), mesh harmonics 1..3, a
localised fault once per revolution at 90 deg from the tach's leading edge, 20 kHz, 2 s; the
oracle of each file variant is the same record in the plain layout.
"""

from __future__ import annotations

import math
import os
import warnings

import numpy as np
import pytest
import scipy.io
import xarray as xr

from geardyn.diagnostics import DiagnosticsWarning, diagnose, diagnose_file
from geardyn.diagnostics.metrics import CONSTANT_TOLERANCE, condition_metrics, is_constant
from geardyn.errors import DataFileError, InputError

from .._cli_fork import run_geardyn

Z = 23
FS = 20_000.0  # [Hz]
FAST = {"samples_per_rev": 512, "harmonic": 3, "bandwidth": 11}


def _acc(theta: np.ndarray) -> np.ndarray:
    """Housing acceleration [g] against the pinion angle [rad]: mesh harmonics and a fault."""
    x = sum(a * np.cos(k * Z * theta + 0.3 * k) for k, a in enumerate((1.0, 0.5, 0.25), 1))
    ph = np.angle(np.exp(1j * (theta - np.radians(90.0))))
    return x + 1.5 * np.exp(-0.5 * (ph / np.radians(2.0)) ** 2) * np.cos(3 * Z * theta)


def _record(run_up: bool = False, seconds: float = 2.0):
    t = np.arange(int(seconds * FS)) / FS  # [s]
    if run_up:  # 10 -> 30 rev/s
        theta = 2 * np.pi * (10.0 * t + 0.5 * (20.0 / seconds) * t**2) - 0.3
    else:
        theta = 2 * np.pi * 25.0 * t - 0.3
    return t, theta, _acc(theta)


def _pulses(t, theta, *, active_low: bool = False, duration: float = 2e-3):
    """A tach pulse of fixed duration [s] from each whole turn (a one-shot sensor output):
    its leading edge at the turn, its trailing edge ``duration`` later whatever the speed."""
    turns = np.arange(np.ceil(theta[0] / (2 * np.pi)), np.floor(theta[-1] / (2 * np.pi)) + 1)
    starts = np.interp(turns * 2 * np.pi, theta, t)
    high = np.zeros_like(t, dtype=bool)
    for s in starts:
        high |= (t >= s) & (t < s + duration)
    v = np.where(high, 5.0, 0.0)
    v = np.convolve(v, np.ones(3) / 3, mode="same")  # a few samples per edge (band-limited)
    return 5.0 - v if active_low else v


def _metrics(result, name):
    return result.signals[name].metrics


# ------------------------------------------------------------------------------ stuck sensor
def test_a_constant_record_has_no_condition_metrics():
    """A stuck sensor's 0.25 g gave FM4 302, kurtosis 683 (moments of the TSA's round-off)."""
    t, theta, _ = _record()
    with pytest.warns(DiagnosticsWarning, match="constant"):
        r = diagnose({"a": np.full(t.size, 0.25)}, teeth=Z, angle=theta, **FAST)
    s = r.signals["a"]
    m = s.metrics
    assert m.RMS == pytest.approx(0.25, rel=1e-12) and m.CrestFactor == pytest.approx(1.0)
    for name in ("Kurtosis", "FM4", "M6A", "M8A", "FM0", "EnergyRatio", "NA4", "NB4"):
        assert math.isnan(getattr(m, name)), name
    assert math.isnan(s.residual_kurtosis) and math.isnan(s.envelope_kurtosis)
    assert math.isnan(s.statistics.skewness) and math.isnan(s.statistics.crest_factor)


def test_constant_means_round_off_not_small():
    """The tolerance is the round-off of the values, not their size: a tiny real signal (1e-9
    of its offset, far above 1024 epsilons) keeps its metrics."""
    x = 0.25 + 1e-9 * np.cos(Z * np.linspace(0, 2 * np.pi, 512, endpoint=False))
    assert not is_constant(x)
    assert is_constant(np.full(512, 0.25) + 0.1 * CONSTANT_TOLERANCE * np.sign(np.sin(
        np.arange(512.0))))
    assert is_constant(np.zeros(4)) and is_constant(np.full(4, -1e300))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert math.isfinite(condition_metrics(x, teeth=Z).FM4)


# ------------------------------------------------------------------------------ the tach
def test_an_active_low_tach_by_its_falling_edge():
    """A run-up with an active-low pulse of fixed duration: its rising (trailing) edge sits at
    an angle that moves with the speed and smeared the TSA (mesh amplitude 0.21 of 1); the
    falling (leading) edge gives the active-high record's metrics."""
    t, theta, acc = _record(run_up=True)
    high = diagnose_file_arrays(t, acc, _pulses(t, theta))
    low = diagnose_file_arrays(t, acc, _pulses(t, theta, active_low=True), tach_edge="falling")
    wrong = diagnose_file_arrays(t, acc, _pulses(t, theta, active_low=True))
    for k in ("FM4", "RMS", "NA4"):
        assert getattr(low, k) == pytest.approx(getattr(high, k), rel=2e-3), k
    assert wrong.RMS < 0.9 * high.RMS  # the smeared average the option repairs


def diagnose_file_arrays(t, acc, tach, **kw):
    """:func:`diagnose_file` of a CSV written from the arrays (time, acc [g], tach [V])."""
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "rec.csv")
        np.savetxt(path, np.c_[t, acc, tach], delimiter=",", header="time [s],acc [g],tach [V]",
                   comments="")
        r = diagnose_file(path, signals="acc [g]", time="time [s]", tach="tach [V]",
                          teeth=Z, **FAST, **kw)
    return r.signals["acc [g]"].metrics


def test_the_shaft_speed_is_reported():
    """A forgotten pulses-per-rev doubles the speed shown beside the averaged revolutions."""
    t, theta, acc = _record()
    r = diagnose({"a": acc}, teeth=Z, fs=FS, tach_times=np.arange(0, 2.0, 0.04), **FAST)
    sp = r.settings["shaft_speed_rev_s"]
    assert sp["mean"] == pytest.approx(25.0, rel=1e-12)
    assert sp["min"] == pytest.approx(25.0, rel=1e-9) and sp["max"] == pytest.approx(25.0, rel=1e-9)
    t, theta, acc = _record(run_up=True)
    sp = diagnose({"a": acc}, teeth=Z, angle=theta, time=t, **FAST).settings["shaft_speed_rev_s"]
    assert sp["mean"] == pytest.approx(20.0, rel=2e-3)  # the mean of 10 -> 30 rev/s
    # over whole revolutions: the first averages 10.5 rev/s, the last 29.5
    assert 10.0 < sp["min"] < 11.0 and 29.0 < sp["max"] < 30.0
    # an angle without times has no speed (the TSA needs none)
    assert diagnose({"a": acc}, teeth=Z, angle=theta, **FAST).settings["shaft_speed_rev_s"] is None


def test_chatter_on_a_slow_edge_is_refused_with_what_to_set(tmp_path):
    t, theta, acc = _record()
    tach = _pulses(t, theta, duration=8e-3)
    clean = diagnose_file_arrays(t, acc, tach)
    noisy = tach.copy()
    edges = np.flatnonzero(np.diff((tach > 2.5).astype(int)) == 1)
    noisy[edges + 6] = 0.0  # a dip after each edge: a second crossing 0.3 ms later
    path = tmp_path / "chatter.csv"
    np.savetxt(path, np.c_[t, acc, noisy], delimiter=",", header="time,acc,tach", comments="")
    with pytest.raises(InputError) as exc:
        diagnose_file(path, signals="acc", time="time", tach="tach", teeth=Z, **FAST)
    assert exc.value.field == "tach" and "tach_min_interval" in exc.value.allowed
    fixed = diagnose_file(path, signals="acc", time="time", tach="tach", teeth=Z,
                          tach_min_interval=0.02, **FAST).signals["acc"].metrics
    assert fixed.FM4 == pytest.approx(clean.FM4, rel=1e-3)


def test_a_column_of_pulse_times_needs_tach_times(tmp_path):
    t, theta, acc = _record()
    times = np.full(t.size, np.nan)
    times[:50] = np.arange(50) * 0.04
    path = tmp_path / "p.csv"
    np.savetxt(path, np.c_[t, acc, times], delimiter=",", header="time,acc,pt", comments="")
    with pytest.raises(InputError) as exc:
        diagnose_file(path, signals="acc", time="time", tach="pt", teeth=Z, **FAST)
    assert "pulse times" in exc.value.allowed and "tach_column_is_pulse_times" in exc.value.allowed
    r = diagnose_file(path, signals="acc", time="time", tach="pt", teeth=Z,
                      tach_column_is_pulse_times=True, **FAST)
    assert r.settings["shaft_speed_rev_s"]["mean"] == pytest.approx(25.0, rel=1e-12)


# ------------------------------------------------------------------------------ file layouts
def _plain(tmp_path):
    t, theta, acc = _record()
    tach = _pulses(t, theta)
    path = tmp_path / "plain.csv"
    np.savetxt(path, np.c_[t, acc, tach], delimiter=",", header="time [s],acc [g],tach [V]",
               comments="", fmt="%.10g")
    ref = diagnose_file(path, signals="acc [g]", time="time [s]", tach="tach [V]", teeth=Z,
                        **FAST)
    return t, acc, tach, ref.signals["acc [g]"]


def test_european_csv_with_decimal_commas(tmp_path):
    t, acc, tach, ref = _plain(tmp_path)
    rows = [";".join(f"{v:.10g}".replace(".", ",") for v in row) for row in np.c_[t, acc, tach]]
    for name, head in (("euro.csv", ["Zeit [s];Beschl. [g];Tacho [V]"]), ("nohdr.csv", [])):
        path = tmp_path / name
        path.write_text("\n".join(head + rows) + "\n")
        cols = ("Zeit [s]", "Beschl. [g]", "Tacho [V]") if head else (0, 1, 2)
        r = diagnose_file(path, time=cols[0], signals=cols[1], tach=cols[2], teeth=Z, **FAST)
        got = next(iter(r.signals.values()))
        assert got.metrics == ref.metrics, name


def test_a_preamble_not_marked_as_comments_is_named(tmp_path):
    _plain(tmp_path)
    text = (tmp_path / "plain.csv").read_text()
    path = tmp_path / "pre.csv"
    path.write_text("Recorder: ACME DAQ\nSample rate: 20000 Hz\n\n" + text)
    with pytest.raises(DataFileError, match="must start with '#'"):
        diagnose_file(path, signals="acc [g]", time="time [s]", tach="tach [V]", teeth=Z, **FAST)


def test_the_sample_rate_under_its_usual_names(tmp_path):
    """Fs, sampleRate in a struct, "# fs = 20 kHz": each is the file's rate."""
    t, acc, tach, ref = _plain(tmp_path)
    scipy.io.savemat(tmp_path / "row.mat", {"acc": acc[None, :], "tach": tach[None, :],
                                            "Fs": FS})
    scipy.io.savemat(tmp_path / "struct.mat", {"data": {"acc": acc[:, None],
                                                        "tach": tach[:, None],
                                                        "sampleRate": FS}})
    np.savetxt(tmp_path / "khz.csv", np.c_[acc, tach], delimiter=",", header="acc,tach",
               comments="", fmt="%.10g")
    (tmp_path / "khz.csv").write_text("# fs = 20 kHz\n" + (tmp_path / "khz.csv").read_text())
    for name, sig, tc in (("row.mat", "acc", "tach"), ("struct.mat", "data.acc", "data.tach"),
                          ("khz.csv", "acc", "tach")):
        r = diagnose_file(tmp_path / name, signals=sig, tach=tc, teeth=Z, **FAST)
        assert r.signals[sig].metrics.FM4 == pytest.approx(ref.metrics.FM4, rel=1e-6), name
        with pytest.raises(InputError, match="own sample rate"):  # and a contradiction refused
            diagnose_file(tmp_path / name, signals=sig, tach=tc, teeth=Z, fs=10_000.0, **FAST)


def test_units_from_the_file(tmp_path):
    """A column named with its unit, a NetCDF variable's units, geardyn measure's "# units:"."""
    t, acc, tach, ref = _plain(tmp_path)
    assert ref.unit == "g"
    ds = xr.Dataset({"acc": ("time", acc, {"units": "m/s^2"}), "tach": ("time", tach)},
                    coords={"time": ("time", t, {"units": "s"})})
    ds.to_netcdf(tmp_path / "daq.nc", engine="h5netcdf")
    r = diagnose_file(tmp_path / "daq.nc", signals="acc", tach="tach", time="time", teeth=Z,
                      **FAST)
    assert r.signals["acc"].unit == "m/s^2"
    # without --time the message points at the time coordinate it holds
    with pytest.raises(InputError, match="its column 'time'"):
        diagnose_file(tmp_path / "daq.nc", signals="acc", tach="tach", teeth=Z, **FAST)


def _as_dict(metrics) -> dict:
    from dataclasses import asdict

    return asdict(metrics)


def test_time_and_angle_columns_in_the_units_they_state(tmp_path):
    """A time column "time [ms]" was read as seconds (a shaft 1000 times slower, nothing said)
    and "angle [deg]" as radians without --angle-unit (a user audit, 2026-11-27). The oracle:
    the same record in s and rad, diagnosed the same to round-off; a contradicting
    --angle-unit and a unit that is no time are refused; a matrix column's index is not its
    unit."""
    t, theta, acc = _record()
    tach = _pulses(t, theta)
    _, _, _, ref = _plain(tmp_path)
    ms = tmp_path / "ms.csv"
    np.savetxt(ms, np.c_[t * 1e3, acc, tach], delimiter=",", comments="", fmt="%.12g",
               header="time [ms],acc [g],tach [V]")
    r = diagnose_file(ms, signals="acc [g]", time="time [ms]", tach="tach [V]", teeth=Z, **FAST)
    assert _as_dict(r.signals["acc [g]"].metrics) == pytest.approx(_as_dict(ref.metrics),
                                                                   rel=1e-7, nan_ok=True)
    assert r.settings["shaft_speed_rev_s"]["mean"] == pytest.approx(25.0, rel=1e-4)
    deg = tmp_path / "deg.csv"
    np.savetxt(deg, np.c_[t, acc, np.degrees(theta)], delimiter=",", comments="", fmt="%.15g",
               header="time [s],acc [g],angle [deg]")
    rad = tmp_path / "rad.csv"
    np.savetxt(rad, np.c_[t, acc, theta], delimiter=",", comments="", fmt="%.15g",
               header="time [s],acc [g],angle")
    by_deg = diagnose_file(deg, signals="acc [g]", time="time [s]", angle="angle [deg]",
                           teeth=Z, **FAST).signals["acc [g]"]
    by_rad = diagnose_file(rad, signals="acc [g]", time="time [s]", angle="angle", teeth=Z,
                           **FAST).signals["acc [g]"]
    assert _as_dict(by_deg.metrics) == pytest.approx(_as_dict(by_rad.metrics), rel=1e-7,
                                                     nan_ok=True)
    with pytest.raises(InputError) as err:
        diagnose_file(deg, signals="acc [g]", time="time [s]", angle="angle [deg]",
                      angle_unit="rad", teeth=Z, **FAST)
    assert err.value.field == "angle_unit" and "'angle [deg]' states, deg" in err.value.allowed
    bad = tmp_path / "bad.csv"
    np.savetxt(bad, np.c_[t, acc, tach], delimiter=",", comments="", fmt="%.10g",
               header="time [V],acc [g],tach [V]")
    with pytest.raises(InputError, match="in 'V'") as err:
        diagnose_file(bad, signals="acc [g]", time="time [V]", tach="tach [V]", teeth=Z, **FAST)
    assert err.value.field == "time"
    mat = tmp_path / "counts.mat"
    scipy.io.savemat(mat, {"data": np.c_[np.round(acc * 1000), tach].astype(np.int16),
                           "fs": FS})
    r = diagnose_file(mat, signals=0, tach=1, teeth=Z, **FAST)
    assert [s.unit for s in r.signals.values()] == [""]  # not "0"


# ------------------------------------------------------------------------------ teeth
def test_a_tooth_count_the_spectrum_contradicts_is_warned():
    t, theta, acc = _record()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        diagnose({"a": acc}, teeth=Z, angle=theta, **FAST)
    with pytest.warns(DiagnosticsWarning, match="strongest order is 23, not a multiple of the "
                                                "mesh order 31"):
        diagnose({"a": acc}, teeth=31, angle=theta, samples_per_rev=512, harmonic=1,
                 bandwidth=11)


# ------------------------------------------------------------------------------ the CLI
@pytest.mark.slow
def test_cli_names_with_brackets_speed_and_tach_options(tmp_path):
    """A column "acc [/s]" was read as a rich closing tag: internal error after metrics.json."""
    t, theta, acc = _record(run_up=True)
    path = tmp_path / "rec.csv"
    np.savetxt(path, np.c_[t, acc, _pulses(t, theta, active_low=True)], delimiter=",",
               header="time [s],acc [/s],tach [V]", comments="")
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(tmp_path / "cache")}
    r = run_geardyn(["diagnose", str(path), "--time", "time [s]", "--signal", "acc [/s]",
                     "--tach", "tach [V]", "--tach-edge", "falling", "--no-figures",
                     "--set", "diagnostics.samples_per_rev=512", "-o", str(tmp_path / "o")],
                    capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "acc [/s]: " in r.stdout and "revolutions averaged at 10" in r.stdout, r.stdout
    assert "rev/s (" in r.stdout and "rpm)" in r.stdout
    r = run_geardyn(["diagnose", str(path), "--time", "time [s]", "--signal", "acc [/s]",
                     "--angle", "time [s]", "--tach-edge", "falling", "-o", str(tmp_path / "x")],
                    capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 2 and "--tach-edge" in r.stderr and "Traceback" not in r.stderr


def test_decimal_commas_after_whole_number_rows_and_commas_in_names(tmp_path):
    """Mutation pass: decimal commas were looked for in the first five data rows only (a
    recorder's pre-trigger zeros hid them), and the header's commas became points."""
    from geardyn.diagnostics.io import read_table

    path = tmp_path / "late.csv"
    path.write_text("Zeit [s];Beschl. [g]\n" + "0;0\n" * 5 + "0,00005;0,125\n0,0001;-0,25\n")
    t = read_table(path)
    assert list(t.columns["Beschl. [g]"]) == [0.0] * 5 + [0.125, -0.25]
    path.write_text("Zeit [s];Kraft, axial [N]\n0,0;1,5\n0,1;2,5\n")
    t = read_table(path)
    assert t.names == ["Zeit [s]", "Kraft, axial [N]"]
    assert list(t.columns["Kraft, axial [N]"]) == [1.5, 2.5]


def test_a_missing_tach_pulse_is_named_as_such(tmp_path):
    """One pulse of a regular train missing: it was refused as "2 too soon" with advice to set
    --tach-min-interval, which did not help (a user audit, 2026-11-27). Chatter keeps its own
    message (tests/diagnostics/test_mutants_measured.py)."""
    from geardyn.diagnostics.loading import load_measurement

    t, theta, acc = _record()
    tach = _pulses(t, theta)
    turn = np.floor((theta + 0.3) / (2 * np.pi) + 1e-9)
    tach[turn == 20] = 0.0  # the 20th revolution's pulse is lost
    path = tmp_path / "miss.csv"
    np.savetxt(path, np.c_[t, acc, tach], delimiter=",", header="time,acc,tach", comments="",
               fmt="%.10g")
    with pytest.raises(InputError) as err:
        load_measurement(path, signal="acc", time="time", tach="tach")
    assert err.value.field == "tach"
    assert err.value.value.endswith("pulses, 1 interval(s) with a pulse missing")
    assert "2 times the regular interval: about 1 pulse missed" in err.value.allowed
    # the last pulse before the gap: turn 19 at theta = 2 pi 19, t = (19 + 0.3 / (2 pi)) / 25
    before = float(err.value.allowed.split("after the pulse at t = ")[1].split(" s")[0])
    assert before == pytest.approx((19 + 0.3 / (2 * np.pi)) / 25.0, abs=1e-4)
