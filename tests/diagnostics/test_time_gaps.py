"""A record with a gap in its time column is refused (with a tachometer or an angle column), naming the gap (a
user audit of 2026-11-27: 200 samples cut out of a 25.6 kHz CSV were interpolated over, and the
TSA showed a dip of seven times the signal's amplitude at a wrong angle, without a word). One
dropped sample, a DAQ's timestamp jitter and a run-up from standstill still pass."""

from __future__ import annotations

import numpy as np
import pytest

from geardyn.diagnostics import tsa
from geardyn.errors import InputError

FS = 25_600.0
T = np.arange(int(FS)) / FS  # 1 s
ANGLE = 2 * np.pi * 18.17 * T
X = np.sin(23 * ANGLE)
TACH = np.arange(19) / 18.17  # one pulse a revolution [s]


def _cut(first: int, count: int):
    keep = np.ones(T.size, bool)
    keep[first:first + count] = False
    return T[keep], X[keep], ANGLE[keep]


def test_a_gap_is_refused_with_its_time_and_size():
    t, x, a = _cut(12_800, 200)
    with pytest.raises(InputError) as err:  # time and tachometer pulses
        tsa(x, time=t, tach_times=TACH, samples_per_rev=512)
    e = err.value
    assert e.field == "time"
    # the gap: 201 steps of 1/FS in one, after the sample at 12799/FS
    assert e.value == f"a gap of {201 / FS:.4g} s after time = {12_799 / FS:.6g} s"
    assert "about 200 samples are missing" in e.allowed
    with pytest.raises(InputError) as err:  # the exact angle, with its sample times
        tsa(x, angle=a, time=t, samples_per_rev=512)
    assert err.value.field == "time" and err.value.value == e.value


def test_two_gaps_are_counted():
    t, x, a = _cut(5_000, 50)
    keep = np.ones(t.size, bool)
    keep[15_000:15_010] = False
    with pytest.raises(InputError, match="2 gaps in all"):
        tsa(x[keep], time=t[keep], tach_times=TACH, samples_per_rev=512)


def test_one_dropped_sample_and_jitter_pass():
    t, x, a = _cut(12_800, 1)  # a step of two sample intervals
    assert tsa(x, time=t, tach_times=TACH, samples_per_rev=512).n_averages >= 17
    assert tsa(x, angle=a, time=t, samples_per_rev=512).n_averages >= 17
    jitter = np.random.default_rng(0).uniform(-0.2, 0.2, T.size) / FS  # +/- 20 % of a step
    assert tsa(X, time=T + jitter, tach_times=TACH, samples_per_rev=512).n_averages >= 17
    run_up = 2 * np.pi * 30.0 * T**2  # from standstill to 60 rev/s in 1 s
    assert tsa(np.sin(23 * run_up), angle=run_up, time=T, samples_per_rev=512).n_averages >= 10


@pytest.mark.parametrize("fs", [-1e5, 0, float("nan"), "x", True])
def test_a_bad_rate_beside_an_angle_is_refused(fs):
    """With an angle, ``fs`` only times the record: a string failed deep in numpy, a negative
    rate passed and the speed vanished silently (a user audit, 2026-11-27)."""
    with pytest.raises(InputError) as err:
        tsa_input = {"v": X[:4096]}
        from geardyn.diagnostics import diagnose

        diagnose(tsa_input, teeth=23, angle=ANGLE[:4096], fs=fs, samples_per_rev=256)
    assert err.value.field == "fs"


def test_a_rate_with_a_unit_beside_an_angle_times_the_record():
    from geardyn.diagnostics import diagnose

    a = diagnose({"v": X}, teeth=23, angle=ANGLE, fs="25.6 kHz", samples_per_rev=256)
    b = diagnose({"v": X}, teeth=23, angle=ANGLE, fs=FS, samples_per_rev=256)
    assert a.settings["shaft_speed_rev_s"] == b.settings["shaft_speed_rev_s"]
    assert a.settings["shaft_speed_rev_s"]["mean"] == pytest.approx(18.17, rel=1e-9)
