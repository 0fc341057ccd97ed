"""Measured-data handling against closed forms and hand-made records, written against the
mutants that survived a mutation run of the measured-file code (constant records, the shaft
speed, the tooth-count warning, tach chatter, decimal commas, sample-rate names, units).

Each oracle is independent of the code under test: the documented tolerance in machine
epsilons, a speed from pulse times chosen by hand, amplitudes of cosines of known orders, a few
numbers typed into a text file.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from geardyn.diagnostics import (
    DiagnosticsWarning,
    condition_metrics,
    diagnose,
    kurtosis,
    load_measurement,
    read_table,
)
from geardyn.diagnostics.io import is_rate_key, stored_rate, unit_in_name
from geardyn.diagnostics.metrics import is_constant
from geardyn.errors import DataFileError, InputError

Z = 23
FS = 20_000.0  # [Hz]
EPS = float(np.finfo(np.float64).eps)
N_REV = 512
TH = 2 * np.pi * np.arange(N_REV) / N_REV  # one revolution [rad]


# ------------------------------------------------------------------------------ constant
def test_constant_is_1024_epsilons_of_the_largest_magnitude():
    """The documented bound, in numbers: 500 epsilons of variation is round-off, 4000 are a
    signal (whatever the tolerance constant is set to)."""
    wiggle = np.sign(np.sin(np.arange(N_REV) + 0.5))  # +-1
    assert is_constant(0.25 * (1.0 + 500 * EPS * wiggle))
    assert not is_constant(0.25 * (1.0 + 4000 * EPS * wiggle))
    # relative, not absolute: a signal of 1e-12 units is a signal
    tiny = 1e-12 * np.cos(Z * TH)
    assert not is_constant(tiny)
    # and its metrics are those of the same signal in larger units (scale invariance)
    big = condition_metrics(np.cos(Z * TH) + 0.3 * np.cos(5 * TH), teeth=Z)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        small = condition_metrics(1e-12 * (np.cos(Z * TH) + 0.3 * np.cos(5 * TH)), teeth=Z)
    assert small.FM4 == pytest.approx(big.FM4, rel=1e-9)
    assert small.Kurtosis == pytest.approx(big.Kurtosis, rel=1e-9)


def test_kurtosis_of_a_constant_to_round_off_is_nan():
    """The variance of 0.25 plus one ulp here and there is positive, its kurtosis a number of
    the round-off: NaN, warned."""
    x = np.full(N_REV, 0.25)
    x[::3] += 0.25 * EPS  # one ulp of 0.25 on a third of the samples
    assert np.var(x) > 0
    with pytest.warns(DiagnosticsWarning, match="constant"):
        assert math.isnan(kurtosis(x))


def test_a_negative_constant_has_a_positive_rms_and_crest_factor_one():
    """RMS of -0.25 g is 0.25 g (not its mean), its crest factor max|x|/RMS is 1."""
    with pytest.warns(DiagnosticsWarning, match="constant"):
        m = condition_metrics(np.full(64, -0.25), teeth=Z)
    assert m.RMS == pytest.approx(0.25, rel=1e-15)
    assert m.CrestFactor == pytest.approx(1.0, rel=1e-15)
    assert math.isnan(m.FM4) and math.isnan(m.NA4)


# ------------------------------------------------------------------------------ shaft speed
def test_the_shaft_speed_counts_pulses_per_revolution():
    """Two unevenly placed pulses per revolution (19 ms then 21 ms apart) at 25 rev/s: every
    revolution is 40 ms, so min = max = mean = 25 rev/s; pulse to pulse would read 47.6..52.6
    (or, as one pulse per revolution, 23.8..26.3)."""
    gaps = np.tile([0.019, 0.021], 50)
    tach = np.r_[0.0, np.cumsum(gaps)]  # 101 pulses, 50 revolutions, 2 s
    acc = np.cos(Z * 2 * np.pi * 25.0 * np.arange(int(2.0 * FS)) / FS)
    r = diagnose({"a": acc}, teeth=Z, fs=FS, tach_times=tach, pulses_per_rev=2,
                 samples_per_rev=256, harmonic=1, bandwidth=11)
    sp = r.settings["shaft_speed_rev_s"]
    assert sp["mean"] == pytest.approx(25.0, rel=1e-12)
    assert sp["min"] == pytest.approx(25.0, rel=1e-9)
    assert sp["max"] == pytest.approx(25.0, rel=1e-9)


def test_the_shaft_speed_of_an_angle_over_its_first_and_last_whole_revolutions():
    """A run-up at 10 + 10 t rev/s: the angle has turned 10 t + 5 t^2 times at t, so whole turn
    k is reached at t_k = (sqrt(100 + 20 k) - 10) / 10; 2 s hold 39 whole turns. The slowest
    revolution is the first, 1 / t_1; the fastest the last, 1 / (t_39 - t_38)."""
    t = np.arange(int(2.0 * FS)) / FS
    theta = 2 * np.pi * (10.0 * t + 5.0 * t**2) + 0.7
    acc = np.cos(Z * theta)
    sp = diagnose({"a": acc}, teeth=Z, angle=theta, time=t, samples_per_rev=256, harmonic=1,
                  bandwidth=11).settings["shaft_speed_rev_s"]
    t_k = (np.sqrt(100.0 + 20.0 * np.arange(40)) - 10.0) / 10.0
    assert sp["min"] == pytest.approx(1.0 / t_k[1], rel=1e-6)
    assert sp["max"] == pytest.approx(1.0 / (t_k[39] - t_k[38]), rel=1e-6)
    assert sp["mean"] == pytest.approx((10.0 * t[-1] + 5.0 * t[-1] ** 2) / t[-1], rel=1e-12)


# ------------------------------------------------------------------------------ tooth count
def _diagnose_orders(orders: dict[int, float], **options):
    """diagnose of one revolution-periodic signal, 8 revolutions of 512 samples, given as
    order -> amplitude (cosines); the warnings it gives."""
    theta = np.tile(TH, 8) + 2 * np.pi * np.repeat(np.arange(8), N_REV)
    x = sum(a * np.cos(k * theta + 0.2 * k) for k, a in orders.items())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        diagnose({"a": x}, teeth=Z, angle=theta, samples_per_rev=N_REV, harmonic=1,
                 bandwidth=11, **options)
    return [str(w.message) for w in caught if "strongest order" in str(w.message)]


def test_teeth_the_record_states_are_not_doubted(tmp_path):
    """A worn flank's gap put order 6 far above the mesh order of a geardyn simulation, and
    diagnose asked whether the pinion has 23 teeth, which the record states (a user audit,
    2026-11-27): no doubt where the file states the teeth (doubt_teeth=False)."""
    import xarray as xr

    from geardyn.diagnostics import diagnose_file

    mesh = {Z: 1.0, 2 * Z: 0.5}
    assert _diagnose_orders({**mesh, 6: 5.0}, doubt_teeth=False) == []
    assert len(_diagnose_orders({**mesh, 6: 5.0})) == 1
    theta = np.tile(TH, 8) + 2 * np.pi * np.repeat(np.arange(8), N_REV)
    x = sum(a * np.cos(k * theta + 0.2 * k) for k, a in {**mesh, 6: 5.0}.items())
    t = np.arange(theta.size) / 5000.0
    ds = xr.Dataset({"theta_p": ("time", theta), "v_yg": ("time", x),
                     "omega_p": ("time", np.gradient(theta, t)),
                     "transmission_error": ("time", 1e-4 * x)}, coords={"time": t},
                    attrs={"model": "II", "pinion_teeth": Z})
    ds.to_netcdf(tmp_path / "sim.nc", engine="h5netcdf")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        diagnose_file(tmp_path / "sim.nc", signals="v_yg", samples_per_rev=N_REV, harmonic=1,
                      bandwidth=11)
    assert not [w for w in caught if "strongest order" in str(w.message)]


def test_the_tooth_count_warning_needs_three_times_the_mesh_harmonics():
    """Order 5 at 2.5 times the mesh order's amplitude: a shaft order, no doubt about the teeth;
    at 3.5 times: warned, naming order 5. Runout (orders 1 and 2, ten times the mesh) never
    counts: the search starts at order 3."""
    mesh = {Z: 1.0, 2 * Z: 0.5}
    assert _diagnose_orders({**mesh, 5: 2.5}) == []
    assert _diagnose_orders({**mesh, 1: 10.0, 2: 5.0}) == []
    got = _diagnose_orders({**mesh, 5: 3.5})
    assert len(got) == 1 and "strongest order is 5, not a multiple of the mesh order 23" in got[0]
    assert "(3.5 times its largest mesh harmonic)" in got[0]


def test_a_constant_record_does_not_doubt_the_tooth_count():
    """The spectrum of a stuck sensor's TSA is round-off: its strongest order means nothing.
    (0.3 is not a binary fraction: its TSA varies by about 1e-17, and the strongest order of
    that round-off, 208 here, is some 4 times its largest mesh harmonic.)"""
    theta = np.tile(TH, 8) + 2 * np.pi * np.repeat(np.arange(8), N_REV)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        diagnose({"a": np.full(theta.size, 0.3)}, teeth=Z, angle=theta,
                 samples_per_rev=N_REV, harmonic=1, bandwidth=11)
    assert not [w for w in caught if "strongest order" in str(w.message)]


# ------------------------------------------------------------------------------ tach chatter
def _pulse_train(extra_at: tuple[float, ...] = (), spikes: int = 0):
    """A 25 rev/s tach (8 ms pulses, 5 V, 2 s at 20 kHz, a sample part-way up each edge) with,
    after each pulse's rising edge, a one-sample drop to 0 V at each delay in ``extra_at`` [s]
    (each adds a rising edge), and
    ``spikes`` pulses followed by a one-sample 5 V spike 12 ms after the edge."""
    t = np.arange(int(2.0 * FS)) / FS
    starts = np.arange(0.01, 2.0 - 0.04, 0.04)
    v = np.zeros_like(t)
    for s in starts:
        v[(t >= s) & (t < s + 8e-3)] = 5.0
    edges = np.flatnonzero(np.diff(v) > 0) + 1
    v[edges] = 3.0  # part-way up: an edge the sampling resolves
    for d in extra_at:
        k = edges + int(round(d * FS))
        v[k], v[k + 1] = 0.0, 3.0
    v[edges[:spikes] + int(round(12e-3 * FS))] = 5.0
    return t, v


def _csv(path, t, tach):
    acc = np.cos(Z * 2 * np.pi * 25.0 * t)
    np.savetxt(path, np.c_[t, acc, tach], delimiter=",", header="time,acc,tach", comments="",
               fmt="%.10g")
    return path


def test_chatter_of_two_extra_edges_per_pulse_is_refused(tmp_path):
    """Two dips on each pulse (0.3 ms and 0.6 ms after its edge): three edges per pulse, two
    short gaps side by side, each shorter than half its longer neighbour."""
    t, v = _pulse_train(extra_at=(3e-4, 6e-4))
    path = _csv(tmp_path / "c.csv", t, v)
    with pytest.raises(InputError) as exc:
        load_measurement(path, signal="acc", time="time", tach="tach")
    assert exc.value.field == "tach"
    # 49 pulses of 3 edges; each pulse's 2 short gaps, but the record's first and last short
    # gap, whose only neighbour is the other short one, are not counted
    assert exc.value.value == "147 pulses, 96 too soon"
    m = load_measurement(path, signal="acc", time="time", tach="tach", tach_min_interval=0.02)
    assert m.tach_times.size == 49


def test_a_glitch_at_0_3_of_the_interval_is_refused(tmp_path):
    """A spike 12 ms after the edge of a 40 ms pulse interval: gaps 12 and 28 ms, 12 < 0.5 * 28
    (and < 0.5 * 40): one pulse too soon per glitch."""
    t, v = _pulse_train(spikes=3)
    path = _csv(tmp_path / "g.csv", t, v)
    with pytest.raises(InputError) as exc:
        load_measurement(path, signal="acc", time="time", tach="tach")
    assert exc.value.value == "52 pulses, 3 too soon"
    # a clean train of the same pulses passes
    t, v = _pulse_train()
    m = load_measurement(_csv(tmp_path / "ok.csv", t, v), signal="acc", time="time", tach="tach")
    assert np.diff(m.tach_times) == pytest.approx(np.full(48, 0.04), abs=1.5 / FS)


def test_the_tach_options_are_named_as_the_caller_gave_them(tmp_path):
    """load_measurement's tach_threshold, tach_min_interval and tach_edge, not the names of
    tach_pulse_times underneath (threshold, min_interval, edge)."""
    t, v = _pulse_train()
    path = _csv(tmp_path / "p.csv", t, v)
    for key, value, allowed in (("tach_threshold", 99.0, "a level between the tach minimum 0 "
                                                         "and maximum 5"),
                                ("tach_min_interval", -1.0, "a positive time in s"),
                                ("tach_edge", "both", "'rising' or 'falling'")):
        with pytest.raises(InputError) as exc:
            load_measurement(path, signal="acc", time="time", tach="tach", **{key: value})
        assert (exc.value.field, exc.value.value, exc.value.allowed) == (key, value, allowed)


def test_only_increasing_values_padded_with_nan_look_like_pulse_times(tmp_path):
    """A pulse train with a lost sample (NaN) is a pulse train with a NaN, not a list of pulse
    times; a column that increases without NaN (the time column given as the tach) has one
    crossing of its mid-range, not a list of pulse times either."""
    t, v = _pulse_train()
    v[1000] = np.nan
    with pytest.raises(InputError) as exc:
        load_measurement(_csv(tmp_path / "nan.csv", t, v), signal="acc", time="time",
                         tach="tach")
    assert exc.value.field == "tach" and exc.value.value == "non-finite value nan at index 1000"
    assert "pulse times" not in exc.value.allowed
    t, v = _pulse_train()
    with pytest.raises(InputError) as exc:
        load_measurement(_csv(tmp_path / "ok.csv", t, v), signal="acc", time="time", tach="time")
    assert exc.value.field == "tach" and "at least 2 pulses (found 1 " in exc.value.allowed
    assert "pulse times" not in exc.value.allowed


def test_a_time_column_named_t_is_pointed_at(tmp_path):
    """No rate and no time given: the message names a column "t [s]" as the time to give."""
    t, v = _pulse_train()
    path = tmp_path / "t.csv"
    np.savetxt(path, np.c_[t, np.cos(t), v], delimiter=",", header="t [s],acc,tach",
               comments="")
    with pytest.raises(InputError) as exc:
        load_measurement(path, signal="acc", tach="tach")
    assert exc.value.field == "fs/time"
    assert exc.value.allowed.endswith("stores no sample rate (its column 't [s]' for time?)")


# ------------------------------------------------------------------------------ text files
def test_decimal_commas_when_the_first_row_is_whole_numbers(tmp_path):
    """The first data row of a run often reads 0;0;0: the commas further down are still
    decimal commas."""
    path = tmp_path / "euro.csv"
    path.write_text("Zeit [s];Beschl. [g];Tacho [V]\n0;0;0\n0,5;1,25;5\n1;-2,5;0\n1,5;3;5\n")
    tab = read_table(path)
    assert list(tab.columns["Zeit [s]"]) == [0.0, 0.5, 1.0, 1.5]
    assert list(tab.columns["Beschl. [g]"]) == [0.0, 1.25, -2.5, 3.0]


def test_a_preamble_line_with_as_many_fields_is_named(tmp_path):
    """A preamble of three comma-separated fields is read as the header; the real header is
    then the first data row, non-numeric: the message says what a preamble needs. A
    non-numeric value further down is a corrupt value, nothing about a preamble."""
    path = tmp_path / "pre.csv"
    path.write_text("Device,ACME DAQ,v2\ntime,acc,tach\n0,1,2\n1,2,3\n")
    with pytest.raises(DataFileError, match=r"line 2: non-numeric value .*; lines before the "
                                            r"column names .* must start with '#'"):
        read_table(path)
    path.write_text("time,acc,tach\n0,1,2\n1,x,3\n")
    with pytest.raises(DataFileError, match="line 3: non-numeric value") as exc:
        read_table(path)
    assert "must start with '#'" not in str(exc.value)


def _square(k: int) -> float:
    """Sample k of a 0/5 V square wave of period 20 samples, one sample part-way up each edge."""
    return min(5.0, 2.5 * (k % 20)) if k % 20 < 10 else 0.0


def test_a_sample_rate_named_with_an_underscore_and_a_unit(tmp_path):
    """"# sample_rate = 51.2 kHz": the file's rate, 51200 Hz."""
    assert is_rate_key("sample_rate") and is_rate_key("Sampling_Frequency")
    assert not is_rate_key("sample") and not is_rate_key("rate")
    path = tmp_path / "r.csv"
    path.write_text("# sample_rate = 51.2 kHz\nacc,tach\n" + "".join(
        f"{math.cos(k):.6f},{_square(k)}\n" for k in range(200)))
    tab = read_table(path)
    assert tab.scalars["sample_rate"] == pytest.approx(51200.0, rel=1e-15)
    m = load_measurement(path, signal="acc", tach="tach")
    assert m.fs == pytest.approx(51200.0, rel=1e-15)


def test_fs_is_the_rate_when_a_file_names_two():
    """``fs`` first, whatever the order of the entries; else the first rate-like name."""
    assert stored_rate({"sampleRate": 1000.0, "fs": 2000.0}) == ("fs", 2000.0)
    assert stored_rate({"gain": 3.0, "Fs": 500.0, "srate": 7.0}) == ("Fs", 500.0)
    assert stored_rate({"gain": 3.0}) is None


def test_a_unit_in_parentheses(tmp_path):
    """"acc (g)" is g, as "acc [g]" is; a bracket mid-name is no unit."""
    assert unit_in_name("force (N)") == "N" and unit_in_name("acc [m/s^2]") == "m/s^2"
    assert unit_in_name("acc [g] raw") == ""
    path = tmp_path / "u.csv"
    path.write_text("acc (g),tach\n" + "".join(
        f"{math.cos(k):.6f},{_square(k)}\n" for k in range(200)))
    m = load_measurement(path, signal="acc (g)", tach="tach", fs=FS)
    assert m.units == {"acc (g)": "g"}
