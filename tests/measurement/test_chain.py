"""The measurement chain on synthetic inputs, against closed forms and a second method.

Oracles: the closed-form FRF of a single mode (amplitude and phase of a steady sine), a
time-domain integration of the mode's equation (scipy DOP853), the exact every-r-th sample for
integer decimation, the requested SNR, the ideal signal through an identity chain, the exact
pulse times of a shaft with a known angle law.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from geardyn.errors import InputError
from geardyn.measurement import (
    G_N,
    MeasurementChain,
    ModalPath,
    Mode,
    Sensor,
    Tachometer,
    pulse_times,
    pulse_train,
)
from geardyn.measurement.sensor import quantise, sample_at

FS_IN = 100_000.0


def _inputs(duration, f0=2870.3, amp=(1.0, 0.0)):
    t = np.arange(int(round(duration * FS_IN))) / FS_IN
    x = np.vstack([a * np.sin(2 * np.pi * f0 * t) for a in amp])
    w = 114.14
    return t, x, w * t, np.full_like(t, w)


@pytest.mark.parametrize("f0", [417.8, 2870.3, 3000.0, 7123.4])
def test_single_mode_sine_matches_closed_form_frf(f0):
    """Steady response to a sine = |H| sin(wt + arg H) with the closed-form accelerance
    H = g (-w^2)/(w_k^2 - w^2 + 2 j zeta w_k w)."""
    fk, zeta, g = 3000.0, 0.05, 0.1
    chain = MeasurementChain(ModalPath.single(fk, zeta, [g, 0.0]), Sensor(fs=50_000.0))
    t, x, a, w = _inputs(0.15, f0)
    m = chain.measure(t, x, a, w)
    wk, wf = 2 * np.pi * fk, 2 * np.pi * f0
    h = g * (-wf ** 2) / (wk ** 2 - wf ** 2 + 2j * zeta * wk * wf)
    ts = m.start_time + m.time
    # amplitude and phase by least squares on sin/cos, compared with the closed form
    # (the chain's record has zero mean: the accelerance is 0 at DC and the record is treated
    # as periodic, so a sine over a fractional number of cycles differs by its window mean)
    basis = np.column_stack([np.sin(wf * ts), np.cos(wf * ts), np.ones_like(ts)])
    (s, c, dc), *_ = np.linalg.lstsq(basis, m.acc, rcond=None)
    # measured: amplitude within 2e-12 relative, phase within 1e-12 rad, every sample within
    # 1.3e-10 |H| (the start-up taper's left-over decays below 1e-8 of the path gain g)
    tol = 1e-9 * abs(h)
    assert math.hypot(s, c) == pytest.approx(abs(h), abs=tol)
    assert math.atan2(c, s) == pytest.approx(np.angle(h), abs=1e-9)
    ref = abs(h) * np.sin(wf * ts + np.angle(h))
    assert np.max(np.abs(m.acc - dc - ref)) < 1e-8 * abs(h) and abs(dc) < tol


@pytest.mark.slow
def test_single_mode_matches_time_domain_integration():
    """Second method: q'' + 2 zeta w_k q' + w_k^2 q = g F(t), a = q'' by DOP853, for a
    multi-tone force that starts at rest (zero force and zero state before t = 0)."""
    fk, zeta, g = 3000.0, 0.05, 0.1
    chain = MeasurementChain(ModalPath.single(fk, zeta, [g, 0.0]), Sensor(fs=FS_IN))
    wk = 2 * np.pi * fk
    lead = chain.lead_in()
    n = int(round((0.06 + lead + chain.tail()) * FS_IN)) + 10
    t = np.arange(n) / FS_IN

    def force(tt):
        s = tt - lead  # silent before `lead`, smooth start (sin^2 ramp over 2 ms)
        ramp = np.where(s <= 0, 0.0, np.where(s < 2e-3, np.sin(np.pi * s / 4e-3) ** 2, 1.0))
        return ramp * (np.sin(2 * np.pi * 418 * s) + 0.5 * np.sin(2 * np.pi * 2500 * s + 1.0))

    def rhs(tt, y):
        return [y[1], g * force(tt) - 2 * zeta * wk * y[1] - wk * wk * y[0]]

    x = np.vstack([force(t), np.zeros_like(t)])
    m = chain.measure(t, x, 114.0 * t, np.full_like(t, 114.0))
    ts = m.start_time + m.time
    sol = solve_ivp(rhs, (0.0, ts[-1]), [0.0, 0.0], method="DOP853", t_eval=ts, rtol=1e-11,
                    atol=1e-14, max_step=2e-5)
    acc = g * force(ts) - 2 * zeta * wk * sol.y[1] - wk * wk * sol.y[0]
    assert np.max(np.abs(m.acc - acc)) < 1e-6 * np.max(np.abs(acc))


def test_two_bearings_superpose_with_their_gains():
    path = ModalPath((Mode(3000.0, 0.05, (0.05, 0.1)), Mode(5200.0, 0.03, (0.02, -0.04))))
    chain = MeasurementChain(path, Sensor(fs=FS_IN))
    t, x, a, w = _inputs(0.2, 1234.5, amp=(1.0, 0.0))
    m1 = chain.measure(t, x, a, w)
    m2 = chain.measure(t, x[::-1], a, w)
    m12 = chain.measure(t, x + x[::-1], a, w)
    np.testing.assert_allclose(m12.acc, m1.acc + m2.acc, atol=1e-12)
    h = path.frf([1234.5])[:, 0]
    ts = m1.start_time + m1.time
    wf = 2 * np.pi * 1234.5
    np.testing.assert_allclose(m2.acc, abs(h[1]) * np.sin(wf * ts + np.angle(h[1])), atol=1e-7)


def test_identity_chain_reproduces_the_ideal_signal():
    """A rigid-body path (f = 0, A = g) with a flat sensor, no filter, no ADC and no noise
    returns g1 F1 + g2 F2: bit for bit for unit gains (applied sample by sample), and to
    within 1e-11 through the FFT path (forced here by a filter far above the band); zero noise
    adds exactly nothing."""
    rng = np.random.default_rng(3)
    t = np.arange(5000) / FS_IN
    x = rng.standard_normal((2, t.size)) * 100.0
    a, w = 100.0 * t, np.full_like(t, 100.0)
    unit = MeasurementChain(ModalPath.single(0.0, 0.0, [1.0, 0.0]), Sensor(fs=FS_IN))
    assert unit.is_static() and unit.lead_in() == 0.0 and unit.tail() == 0.0
    m = unit.measure(t, x, a, w)
    assert np.array_equal(m.acc, x[0]) and np.array_equal(m.acc, m.acc_clean)
    assert not np.any(m.noise)
    path = ModalPath.single(0.0, 0.0, [1.0, 0.5])
    ideal = x[0] + 0.5 * x[1]
    m = MeasurementChain(path, Sensor(fs=FS_IN)).measure(t, x, a, w)
    np.testing.assert_allclose(m.acc, ideal, rtol=0, atol=1e-15 * np.max(np.abs(ideal)))
    m2 = MeasurementChain(path, Sensor(fs=FS_IN / 2)).measure(t, x, a, w)
    assert np.array_equal(m2.acc, m.acc[::2])
    # the FFT path: an order-64 filter at 0.49 fs passes the random input except near Nyquist;
    # a band-limited input (sum of tones below 10 kHz) comes through (measured within 2e-12)
    tones = sum(np.sin(2 * np.pi * f * t + k) for k, f in enumerate((417.8, 1234.0, 9000.0)))
    xb = np.vstack([tones, 0.3 * tones])
    fft_chain = MeasurementChain(path, Sensor(fs=FS_IN, antialias_cutoff=0.49 * FS_IN,
                                              antialias_order=64))
    assert not fft_chain.is_static()
    mf = fft_chain.measure(t, xb, a, w)
    j0 = round(mf.start_time * FS_IN)
    ideal_b = (xb[0] + 0.5 * xb[1])[j0:j0 + mf.acc.size]
    np.testing.assert_allclose(mf.acc, ideal_b, rtol=0, atol=1e-11 * np.max(np.abs(ideal_b)))


def test_sample_at_folds_like_sampling():
    rng = np.random.default_rng(0)
    x = rng.standard_normal(3000)
    spec = np.fft.rfft(x)
    np.testing.assert_allclose(sample_at(spec, 3000, 1000), x[::3], atol=1e-13)
    # a band-limited tone at a non-integer ratio: exact samples of the tone
    n = 2000
    t = np.arange(n) / n
    tone = np.cos(2 * np.pi * 37 * t + 0.4)
    y = sample_at(np.fft.rfft(tone), n, 1280)
    np.testing.assert_allclose(y, np.cos(2 * np.pi * 37 * np.arange(1280) / 1280 + 0.4),
                               atol=1e-12)
    # a tone above the new Nyquist aliases: 700 cycles sampled 1000 times -> 300 cycles
    tone = np.cos(2 * np.pi * 700 * t)
    y = sample_at(np.fft.rfft(tone), n, 1000)
    np.testing.assert_allclose(y, np.cos(2 * np.pi * 300 * np.arange(1000) / 1000), atol=1e-12)


def test_requested_snr_is_met_on_a_long_record():
    chain = MeasurementChain(ModalPath.single(3000.0, 0.05, [0.1, 0.05]),
                             Sensor(fs=50_000.0, snr=20.0, antialias_cutoff=20_000.0), seed=7)
    rng = np.random.default_rng(1)
    t = np.arange(int(2.0 * FS_IN)) / FS_IN
    x = 100.0 * rng.standard_normal((2, t.size))
    m = chain.measure(t, x, 100.0 * t, np.full_like(t, 100.0))
    assert m.acc.size > 90_000
    snr = 10 * np.log10(np.var(m.acc_clean) / np.var(m.acc - m.acc_clean))
    assert snr == pytest.approx(20.0, abs=0.1)
    # the same seed gives the same noise; another seed another one
    again = chain.measure(t, x, 100.0 * t, np.full_like(t, 100.0))
    assert np.array_equal(again.acc, m.acc)
    other = MeasurementChain(chain.path, chain.sensor, seed=8).measure(
        t, x, 100.0 * t, np.full_like(t, 100.0))
    assert not np.array_equal(other.acc, m.acc)


def test_noise_level_and_adc():
    q_bits, fs_range = 12, 10.0
    xq, clipped = quantise(np.array([0.0, 0.0024, 0.0025, 9.99, 10.0, -10.0, -10.01, 50.0]),
                           q_bits, fs_range)
    q = 2 * fs_range / 2 ** q_bits
    assert q == pytest.approx(0.0048828125)
    np.testing.assert_allclose(xq[:3], [0.0, 0.0, q])
    assert xq[4] == pytest.approx(fs_range - q) and xq[5] == -fs_range
    assert clipped.tolist() == [False, False, False, False, True, False, True, True]
    # quantisation noise of a busy signal has variance q^2/12
    rng = np.random.default_rng(2)
    x = rng.uniform(-5, 5, 200_000)
    e = quantise(x, q_bits, fs_range)[0] - x
    assert np.var(e) == pytest.approx(q * q / 12, rel=0.02)


def test_bad_inputs_name_their_field():
    path = ModalPath.single(3000.0, 0.05, [0.1, 0.05])
    with pytest.raises(InputError, match=r"measurement\.fs.*twice the highest"):
        MeasurementChain(path, Sensor(fs=5_000.0))
    with pytest.raises(InputError, match=r"measurement\.snr.*>= 0"):
        Sensor(snr=-3.0)
    with pytest.raises(InputError, match=r"measurement\.antialias_cutoff"):
        Sensor(fs=50_000.0, antialias_cutoff=30_000.0)
    with pytest.raises(InputError, match=r"measurement\.mode_damping_ratios"):
        Mode(3000.0, 0.0, (1.0, 1.0))
    with pytest.raises(InputError, match=r"measurement\.fs.*at most"):
        t = np.arange(1000) / FS_IN
        MeasurementChain(path, Sensor(fs=200_000.0)).measure(
            t, np.zeros((2, t.size)), t, np.ones_like(t))
    with pytest.raises(InputError, match=r"measurement\.tach_jitter"):
        Tachometer(jitter=-1e-6)


def test_pulse_times_of_a_known_angle_law():
    """theta(t) = w t + eps sin(W t): pulse k at theta = 2 pi k, found by Newton on the closed
    form as the oracle; the Hermite inversion errs by O(dt^4)."""
    w, eps, big_w = 114.14, 0.02, 2 * np.pi * 417.8
    t = np.arange(0, 0.5, 1e-5)
    th = w * t + eps * np.sin(big_w * t)
    om = w + eps * big_w * np.cos(big_w * t)
    tp = pulse_times(t, th, om, pulses_per_rev=4, offset=0.1)
    levels = 0.1 + 2 * np.pi / 4 * np.arange(tp.size)
    ref = levels / w
    for _ in range(50):
        ref = ref - (w * ref + eps * np.sin(big_w * ref) - levels) / (w + eps * big_w
                                                                      * np.cos(big_w * ref))
    assert tp.size == int((th[-1] - 0.1) // (np.pi / 2)) + 1
    assert np.max(np.abs(tp - ref)) < 1e-11


def test_pulse_train_edges_are_found_exactly():
    from geardyn.diagnostics import tach_pulse_times

    fs = 50_000.0
    tp = np.cumsum(np.full(20, 0.0550123)) + 0.0123457
    v = pulse_train(tp, int(1.2 * fs), fs, amplitude=5.0)
    assert v.min() == 0.0 and v.max() == 5.0
    found = tach_pulse_times(v, fs=fs)
    np.testing.assert_allclose(found, tp[tp < 1.2 - 3 / fs], atol=1e-12)


def test_acc_in_g():
    assert G_N == 9.80665


def test_accelerometer_resonance_and_antialias_filter_on_sines():
    """Rigid path (A = 1) into an accelerometer with a 20 kHz resonance (zeta 0.02) and an
    order-4 anti-alias filter at 30 kHz, no resampling: a sine comes out scaled by
    |H_acc H_aa| and shifted by arg H_acc (the filter has zero phase), the closed forms
    w_n^2 / (w_n^2 - w^2 + 2 j zeta w_n w) and 1 / sqrt(1 + (f/f_c)^8)."""
    sensor = Sensor(fs=FS_IN, resonance=20_000.0, resonance_damping=0.02,
                    antialias_cutoff=30_000.0, antialias_order=4)
    chain = MeasurementChain(ModalPath.single(0.0, 0.0, [1.0, 0.0]), sensor)
    for f0 in (1000.0, 15_000.0, 20_000.0, 31_234.5):
        t, x, a, w = _inputs(0.08, f0)
        m = chain.measure(t, x, a, w)
        wn, wf = 2 * np.pi * 20_000.0, 2 * np.pi * f0
        h = wn ** 2 / (wn ** 2 - wf ** 2 + 2j * 0.02 * wn * wf) / math.sqrt(
            1 + (f0 / 30_000.0) ** 8)
        ts = m.start_time + m.time
        ref = abs(h) * np.sin(wf * ts + np.angle(h))
        assert np.max(np.abs(m.acc - ref)) < 1e-8 * abs(h)
    assert abs(h) < 1.0 < abs(chain.sensor.frf(np.array([20_000.0]))[0])


def test_noise_level_and_tach_jitter_statistics():
    """A stated noise RMS and a stated trigger jitter come out with those standard deviations
    (the sampling spread of a standard deviation of N values is about 1/sqrt(2N): 0.3 % for
    50 000 noise samples, 1 % for about 4500 pulses; tolerances 3 % and 10 %)."""
    path = ModalPath.single(0.0, 0.0, [1e-3, 0.0])
    chain = MeasurementChain(path, Sensor(fs=FS_IN, noise_level=0.05),
                             Tachometer(pulses_per_rev=500, jitter=2e-6), seed=5)
    t = np.arange(50_000) / FS_IN
    w = 114.14
    m = chain.measure(t, np.vstack([np.sin(900 * t), 0 * t]), w * t, np.full_like(t, w))
    assert np.std(m.noise) == pytest.approx(0.05, rel=0.03)
    exact = pulse_times(t, w * t, np.full_like(t, w), pulses_per_rev=500)
    exact = exact[(exact >= 3e-5) & (exact < t[-1] - 3e-5)]
    assert m.pulse_times.size == exact.size > 400
    assert np.std(m.pulse_times - exact) == pytest.approx(2e-6, rel=0.1)


def test_frf_table_reproduces_the_modal_path_it_tabulates(tmp_path):
    """A measured-FRF path: the single mode's accelerance tabulated every 0.5 Hz to 50 kHz and
    written to CSV gives the modal path's output to the linear-interpolation error
    (h^2/8 |H''|; measured 6e-7 of the largest sample)."""
    from geardyn.measurement import FRFTable

    path = ModalPath.single(3000.0, 0.05, [0.1, 0.05])
    f = np.arange(0.0, 50_000.5, 0.5)
    h = path.frf(f)
    csv = tmp_path / "frf.csv"
    cols = np.column_stack([f, h[0].real, h[0].imag, h[1].real, h[1].imag])
    np.savetxt(csv, cols, delimiter=",", header="frequency,re_p,im_p,re_g,im_g", comments="")
    table = FRFTable.from_csv(csv, settling=path.settling_time())
    assert table.n_inputs == 2 and table.highest_frequency == 50_000.0
    rng = np.random.default_rng(4)
    t = np.arange(30_000) / FS_IN
    x = rng.standard_normal((2, t.size)) * 100.0
    ref = MeasurementChain(path, Sensor(fs=50_000.0)).measure(t, x, 100 * t, 100 + 0 * t)
    got = MeasurementChain(table, Sensor(fs=50_000.0)).measure(t, x, 100 * t, 100 + 0 * t)
    assert got.acc.size == ref.acc.size
    assert np.max(np.abs(got.acc - ref.acc)) < 1e-5 * np.max(np.abs(ref.acc))
    with pytest.raises(InputError, match="frf_table"):
        FRFTable(np.array([0.0, 10.0, 5.0]), np.ones((2, 3)))
