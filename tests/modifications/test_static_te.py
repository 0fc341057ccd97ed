"""Static transmission error: relief geometry (unloaded), load / stiffness (loaded), pitch
errors through the TE, and runout sidebands against the closed form of phase modulation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import jv

from geardyn.errors import InputError
from geardyn.modifications import ToothModifications
from geardyn.static_te import solve_approach, static_transmission_error

from ._support import case_with, pem_healthy_map, smooth_map


def _relief_oracle(pair, theta, c_p, phi_p, c_g, phi_g, power):
    """min over the pairs in contact of the two flanks' relief, from
    :meth:`GearPair.contact_points` and the relief formula written out here."""
    out = []
    rb1, rb2 = pair.pinion.base_radius, pair.gear.base_radius
    u1t = math.sqrt(pair.pinion.tip_radius ** 2 - rb1 ** 2)
    u2t = math.sqrt(pair.gear.tip_radius ** 2 - rb2 ** 2)
    for th in theta:
        cp = pair.contact_points(th, 0.0, margin=0.0)
        vals = []
        for s, ok in zip(cp.s, cp.in_contact, strict=True):
            if not ok:
                continue
            u1, u2 = s, pair.operating(0.0).t1t2 - s
            r1 = c_p * max((u1 - rb1 * phi_p) / (u1t - rb1 * phi_p), 0.0) ** power
            r2 = c_g * max((u2 - rb2 * phi_g) / (u2t - rb2 * phi_g), 0.0) ** power
            vals.append(r1 + r2)
        out.append(min(vals))
    return np.array(out)


@pytest.mark.parametrize("shape,power", [("linear", 1), ("parabolic", 2)])
def test_unloaded_te_with_only_tip_relief_equals_the_relief_geometry(shape, power):
    phi_p, phi_g = math.radians(24.0), math.radians(26.0)
    case = case_with(modifications__pinion__tip_relief="20 um",
                     modifications__pinion__relief_start=f"{math.degrees(phi_p)} deg",
                     modifications__pinion__relief_shape=shape,
                     modifications__gear__tip_relief="12 um",
                     modifications__gear__relief_start=f"{math.degrees(phi_g)} deg",
                     modifications__gear__relief_shape=shape)
    mods = ToothModifications.from_case(case)
    pair = mods.pair
    theta = np.linspace(0.0, 2 * pair.mesh_angle, 301)
    ds = static_transmission_error(pem_healthy_map(), 0.0, modifications=mods, theta=theta)
    want = _relief_oracle(pair, theta, 20e-6, phi_p, 12e-6, phi_g, power)
    np.testing.assert_allclose(ds.transmission_error.values * 1e-6, want, rtol=0, atol=1e-12)
    assert want.max() > 1e-6  # the relief is actually seen (double contact near the tips)
    np.testing.assert_allclose(ds.transmission_error_angle.values,
                               want / pair.pinion.base_radius, rtol=0, atol=1e-15)


def test_loaded_te_of_a_perfect_pair_is_load_over_mesh_stiffness():
    smap = pem_healthy_map()
    case = case_with()
    pair = case.gear_pair()
    mods = ToothModifications.none(pair)
    theta = np.linspace(0.0, 2 * pair.mesh_angle, 257)
    ds = static_transmission_error(smap, 100.0, modifications=mods, theta=theta)
    n = 100.0 / pair.pinion.base_radius
    np.testing.assert_allclose(ds.transmission_error.values * 1e-6, n / smap(theta, 0.0),
                               rtol=1e-12)
    # a second method: the PEM's own pair stiffnesses at these angles (no map interpolation)
    from geardyn.stiffness.pem import PEMModel

    k_pem = PEMModel.from_case(case, cracked=False).mesh_stiffness(theta, 0.0)
    np.testing.assert_allclose(ds.transmission_error.values * 1e-6, n / k_pem, rtol=2e-3)


def test_relief_delays_contact_under_light_load():
    """With relief, pairs near the tips touch only under enough load: the double-contact share
    grows with the torque towards the geometric one."""
    case = case_with(modifications__pinion__tip_relief="30 um",
                     modifications__gear__tip_relief="30 um")
    mods = ToothModifications.from_case(case)
    smap = pem_healthy_map()
    geo = mods.pair_errors(np.linspace(0, mods.pair.mesh_angle, 400))["in_contact"].sum(1)
    frac = [np.mean(static_transmission_error(smap, t, modifications=mods, n=400,
                                              theta=np.linspace(0, mods.pair.mesh_angle, 400)
                                              ).loaded_pairs.values == 2)
            for t in (1.0, 100.0, 1e5)]
    assert frac[0] < frac[1] < frac[2] <= np.mean(geo == 2) + 1e-12
    assert frac[2] == pytest.approx(np.mean(geo == 2), abs=0.01)


def test_pitch_errors_seen_in_the_unloaded_te():
    """Only pinion pitch errors: in single contact the unloaded TE is the contacting tooth's
    P_i cos(alpha); that once-per-tooth sequence integrates to the stated F_p cos(alpha)."""
    case = case_with(modifications__pinion__grade=7, modifications__pinion__fraction=1.0)
    mods = ToothModifications.from_case(case)
    mods = ToothModifications(mods.pair, mods.pinion.__class__(**{
        **mods.pinion.__dict__, "slope": 0 * mods.pinion.slope, "form": 0 * mods.pinion.form}),
        mods.gear)
    pair = mods.pair
    op = pair.operating(0.0)
    # pinion angle where tooth i's contact is in the middle of its single-contact zone
    s_mid = 0.5 * (op.s_start + pair.base_pitch + op.s_end - pair.base_pitch)
    i = np.arange(pair.pinion.teeth)
    theta = (s_mid - pair.pitch_point_s + i * pair.base_pitch) / pair.pinion.base_radius
    ds = static_transmission_error(pem_healthy_map(), 0.0, modifications=mods, theta=theta)
    seq = ds.transmission_error.values * 1e-6
    cos_a = math.cos(pair.pinion.pressure_angle)
    np.testing.assert_allclose(seq, mods.pinion.pitch * cos_a, rtol=0, atol=1e-13)
    fpt = np.diff(seq, prepend=seq[-1])
    assert np.ptp(seq[0] + np.concatenate([[0], np.cumsum(fpt[1:])])) == pytest.approx(
        mods.pinion.tolerances["cumulative_pitch"] * cos_a, rel=1e-9)


@pytest.mark.parametrize("eps_p,eps_g,phase_g", [(20e-6, 0.0, 0.0), (15e-6, 10e-6, 1.1)])
def test_runout_sidebands_match_phase_modulation(eps_p, eps_g, phase_g):
    """Runout phase-modulates the mesh: at mesh harmonic h the 1x sidebands of the loaded TE
    have the amplitude ratio J1(beta)/J0(beta) to the carrier, beta = h z1 |a| / r_b1 with
    a = eps_p e^{i psi_p} + eps_g e^{i psi_g} (equal tooth counts) -> beta/2 for small beta."""
    case = case_with(modifications__pinion__runout=eps_p, modifications__pinion__runout_phase=0.4,
                     modifications__gear__runout=eps_g, modifications__gear__runout_phase=phase_g)
    mods = ToothModifications.from_case(case)
    pair = mods.pair
    z1, rb1 = pair.pinion.teeth, pair.pinion.base_radius
    smap = smooth_map(pair)
    n = 23 * 512
    theta = np.arange(n) * 2 * np.pi / n
    te = static_transmission_error(smap, 100.0, modifications=mods, theta=theta)
    spec = np.abs(np.fft.rfft(te.transmission_error.values)) / n
    a = abs(eps_p * np.exp(0.4j) + eps_g * np.exp(1j * phase_g))
    assert 2 * spec[1] * 1e-6 == pytest.approx(a, rel=1e-6)  # the 1x line is the runout itself
    for h in (1, 2, 3):
        beta = h * z1 * a / rb1
        want = jv(1, beta) / jv(0, beta)
        for side in (-1, 1):
            assert spec[h * z1 + side] / spec[h * z1] == pytest.approx(want, rel=1e-4)
        assert want == pytest.approx(beta / 2, rel=beta ** 2)


def test_bad_torque_and_range():
    mods = ToothModifications.none(case_with().gear_pair())
    with pytest.raises(InputError, match="torque"):
        static_transmission_error(pem_healthy_map(), -1.0, modifications=mods)
    with pytest.raises(InputError, match="centre_distance_change"):
        static_transmission_error(pem_healthy_map(), 1.0, modifications=mods,
                                  centre_distance_change=1.0)


def test_solve_approach_piecewise():
    # two pairs, 1e8 N/m each, errors 0 and 10 um: 500 N -> 5 um on one pair; 3000 N -> both
    assert solve_approach(np.array([1e8, 1e8]), np.array([10e-6, 0.0]), 500.0) == \
        pytest.approx((5e-6, 1))
    d, m = solve_approach(np.array([1e8, 1e8]), np.array([10e-6, 0.0]), 3000.0)
    assert m == 2 and d == pytest.approx((3000.0 + 1e8 * 10e-6) / 2e8)


@pytest.mark.slow
def test_quasi_static_simulation_reproduces_the_loaded_static_te():
    """A second method: at 1 rad/s (mesh frequency 3.7 Hz, far below every natural frequency)
    the simulated mesh deflection p(t) of model I with errors, relief and runout equals the
    loaded static TE at the simulated pinion angle (the kernel decides the loaded pairs on the
    step's free deflection; the static solver exactly)."""
    from geardyn.dynamics import simulate

    case = case_with(modifications__pinion__grade=6, modifications__gear__grade=6,
                     modifications__gear__seed=4, modifications__pinion__tip_relief="20 um",
                     modifications__gear__tip_relief="20 um", modifications__pinion__runout="10 um",
                     load__speed=1.0, simulation__settle_time=0.3, simulation__record_time=0.3,
                     simulation__decimation=20)
    smap = pem_healthy_map()
    ds = simulate(case, smap, model="I")
    mods = ToothModifications.from_case(case)
    te = static_transmission_error(smap, case.motor.torque, modifications=mods,
                                   theta=ds.theta_p.values)
    static = te.transmission_error.values * 1e-6
    err = np.abs(ds.mesh_deflection.values - static)
    assert np.ptp(static) > 5e-6
    assert np.median(err) < 1e-8 and np.percentile(err, 95) < 0.01 * np.ptp(static)
    assert err.max() < 0.03 * np.ptp(static)  # transients at the handovers and contact onsets


def test_load_shares_by_the_compiled_lookup_equal_the_numpy_twin():
    """``ToothModifications.shares`` reads the map's load shares through the compiled look-up:
    they equal the pure-NumPy twin (``lookup_reference``, written independently) to 1e-12 at
    angles over two pinion revolutions and three centre distances, and each angle's slots sum
    to one where a pair is in contact. A map without shares gives equal shares."""
    from geardyn.stiffness.map import lookup_reference

    smap = pem_healthy_map()
    mods = ToothModifications.none(smap_pair := case_with().gear_pair())
    th = np.linspace(-0.3, 4 * math.pi, 1501)
    for dd in (smap.dd[0], 0.37 * smap.dd[-1], smap.dd[-1]):
        pe = mods.pair_errors(th, dd)
        got = mods.shares(smap, pe["theta_eff"], dd, pe["in_contact"])
        want = np.stack([lookup_reference(pe["theta_eff"], np.full(th.shape, dd),
                                          smap.arrays("load_share", slot=k))
                         for k in range(3)], axis=-1)
        assert got.shape == (th.size, 3)
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)
        in_contact = pe["in_contact"].any(axis=1)
        np.testing.assert_allclose(got[in_contact].sum(axis=1), 1.0, atol=1e-9)
    plain = smooth_map(smap_pair)
    pe = mods.pair_errors(th[:50], 0.0)
    eq = mods.shares(plain, pe["theta_eff"], 0.0, pe["in_contact"])
    n = pe["in_contact"].sum(axis=1, keepdims=True)
    np.testing.assert_array_equal(eq, pe["in_contact"] / np.maximum(n, 1))

