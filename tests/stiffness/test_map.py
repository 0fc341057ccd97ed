"""The stiffness map shared by every method: compiled lookup, sharp steps, NetCDF, cache, tables."""

from __future__ import annotations

import math
import warnings

import numba
import numpy as np
import pytest
import xarray as xr

import geardyn
import geardyn.stiffness.pem as pem_module
from geardyn.cache import Cache
from geardyn.stiffness import build_map, centre_distance_grid
from geardyn.stiffness.map import StiffnessMap, lookup, lookup_reference
from geardyn.stiffness.pem import PEMModel, SainsotRangeWarning, pem_map
from geardyn.stiffness.plots import fig_crack, fig_load_sharing, fig_stiffness, pair_load_share


@pytest.fixture(scope="module")
def case():
    return geardyn.paper_case().with_overrides({"stiffness.centre_distances": 11,
                                                "stiffness.nodes_per_segment": 12})


@pytest.fixture(scope="module")
def cmap(case):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SainsotRangeWarning)
        return pem_map(case, centre_distance_grid(case), cracked=True)


@numba.njit(cache=False)
def _loop(theta, dd, dd0, ddd, pa, la, tm, nc, ns, vals):
    out = np.empty(theta.size)
    for k in range(theta.size):
        out[k] = lookup(theta[k], dd[k], dd0, ddd, pa, la, tm, nc, ns, vals)
    return out


def test_numba_lookup_matches_numpy_twin(cmap):
    rng = np.random.default_rng(1)
    n = 3000
    th = rng.uniform(-10, 20, n)
    dd = rng.uniform(cmap.dd[0] - 0.2e-3, cmap.dd[-1] + 0.2e-3, n)
    dd[:20] = cmap.dd[rng.integers(0, cmap.dd.size, 20)]  # exactly on grid lines
    for variable in ("k_mb", "pairs_in_contact"):
        arr = cmap.arrays(variable)
        fast = _loop(th, dd, *arr)
        ref = lookup_reference(th, dd, arr)
        outside = (dd < cmap.dd[0]) | (dd > cmap.dd[-1])
        assert np.all(np.isnan(fast[outside])) and np.all(np.isnan(ref[outside]))
        np.testing.assert_allclose(fast[~outside], ref[~outside], rtol=1e-12)
        np.testing.assert_allclose(cmap(th, dd, variable), fast, rtol=0, equal_nan=True)


def test_read_only_angles_use_the_compiled_lookup_of_writable_ones(cmap):
    """numba types a read-only array apart: a read-only theta (or dd) would compile the lookup a
    second time; the map copies it instead, so one signature serves both, with the same values."""
    from geardyn.stiffness._lookup_kernels import _lookup_many

    th = np.linspace(-1.0, 7.0, 50)
    frozen = th.copy()
    frozen.flags.writeable = False
    dd = np.full(th.size, cmap.dd[1])
    writable = cmap(th, dd)
    signatures = list(_lookup_many.signatures)
    np.testing.assert_array_equal(cmap(frozen, dd), writable)
    np.testing.assert_array_equal(cmap(th, np.broadcast_to(cmap.dd[1], th.shape)), writable)
    assert list(_lookup_many.signatures) == signatures
    assert all(a.mutable for sig in signatures for a in sig[:2]), signatures


def test_steps_stay_sharp_off_the_grid(case, cmap):
    """The number of pairs in contact read from the map equals the geometric count at random
    (theta, d) between grid lines. Points within 1e-5 rad of a true handover are skipped: the map
    places the entry handover by linear interpolation in d, off by < 3e-6 rad between lines."""
    pair = case.gear_pair()
    rng = np.random.default_rng(7)
    rb1, pb = pair.pinion.base_radius, pair.base_pitch
    checked = 0
    for _ in range(2000):
        th = rng.uniform(0, 2 * math.pi)
        dd = rng.uniform(cmap.dd[0], cmap.dd[-1])
        op = pair.operating(dd)
        s = pair.pitch_point_s + rb1 * th
        gap = min(abs(((s - op.s_start) / pb + 0.5) % 1 - 0.5),
                  abs(((s - op.s_end) / pb + 0.5) % 1 - 0.5)) * pb / rb1
        if gap < 1e-5:
            continue
        n_geo = int(pair.contact_points(th, dd).in_contact.sum())
        assert cmap(th, dd, "pairs_in_contact") == pytest.approx(n_geo, abs=1e-12)
        checked += 1
    assert checked > 1900


def test_map_interpolation_in_d_is_accurate_between_grid_lines(case, cmap):
    """Between grid lines (spacing 0.25 mm here) the map agrees with the direct PEM to < 1 %
    everywhere away from the handovers."""
    pair = case.gear_pair()
    pm = PEMModel.from_case(case)
    rng = np.random.default_rng(5)
    th = rng.uniform(0, 2 * math.pi, 4000)
    for dd in (0.13e-3, 0.61e-3, 1.07e-3):
        exact = pm.mesh_stiffness(th, dd)
        op = pair.operating(dd)
        s = pair.pitch_point_s + pair.pinion.base_radius * th
        far = np.minimum(np.abs(((s - op.s_start) / pair.base_pitch + 0.5) % 1 - 0.5),
                         np.abs(((s - op.s_end) / pair.base_pitch + 0.5) % 1 - 0.5)) > 1e-4
        err = np.abs(cmap(th[far], dd) / exact[far] - 1)
        assert err.max() < 0.01


def test_load_share_slots_sum_to_one(cmap):
    th = np.linspace(0, 2 * math.pi, 5000)
    total = sum(cmap(th, 0.7e-3, "load_share", slot=k) for k in range(3))
    np.testing.assert_allclose(total, 1.0, atol=1e-12)


def test_torsional_uses_base_radius(cmap, case):
    th = np.linspace(0, 1, 11)
    rb1 = case.gear_pair().pinion.base_radius
    np.testing.assert_allclose(cmap.torsional(th, 0.3e-3), cmap(th, 0.3e-3) * rb1 ** 2)


def test_netcdf_round_trip_with_units(cmap, tmp_path):
    path = tmp_path / "map.nc"
    cmap.to_netcdf(path)
    back = StiffnessMap.from_netcdf(path)
    np.testing.assert_array_equal(back.k_mb, cmap.k_mb)
    np.testing.assert_array_equal(back.dd, cmap.dd)
    np.testing.assert_array_equal(back.extra["load_share"], cmap.extra["load_share"])
    np.testing.assert_array_equal(back.slot_tooth, cmap.slot_tooth)
    th = np.linspace(-1, 7, 333)
    np.testing.assert_array_equal(back(th, 0.9e-3), cmap(th, 0.9e-3))
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        assert ds["k_mb"].attrs["units"] == "N/m"
        assert ds["torsional_stiffness"].attrs["units"] == "N m/rad"
        assert ds["centre_distance_change"].attrs["units"] == "m"
        assert ds["theta"].attrs["units"] == "rad"
        assert ds["load_share"].attrs["units"] == "1"
        assert ds.attrs["method"] == "pem"
        assert "Sainsot" in ds.attrs["citations"]
        assert "depth_m" in ds.attrs["parameters"]


def test_build_map_caches_and_rebuilds_a_corrupt_entry(case, tmp_path, monkeypatch):
    calls = []
    real = pem_module.pem_map

    def counting(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(pem_module, "pem_map", counting)
    cache = Cache(root=tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SainsotRangeWarning)
        m1 = build_map(case, method="pem", cracked=True, cache=cache)
        assert len(calls) == 1
        m2 = build_map(case, method="pem", cracked=True, cache=cache)
        assert len(calls) == 1  # loaded from the cache
        np.testing.assert_array_equal(m1.k_mb, m2.k_mb)
        assert m2.attrs["inputs_hash"] == m1.attrs["inputs_hash"]
        # healthy and cracked maps are different entries
        build_map(case, method="pem", cracked=False, cache=cache)
        assert len(calls) == 2
        # corrupt the cracked entry: detected by its checksum and rebuilt
        entry = cache.path("stiffness", m1.attrs["inputs_hash"], ".nc")
        data = bytearray(entry.read_bytes())
        data[len(data) // 2] ^= 0xFF
        entry.write_bytes(bytes(data))
        m3 = build_map(case, method="pem", cracked=True, cache=cache)
        assert len(calls) == 3
        np.testing.assert_array_equal(m3.k_mb, m1.k_mb)
        # a changed input is a different key
        build_map(case.with_overrides({"crack.depth": "3 mm"}), method="pem", cracked=True,
                  cache=cache)
        assert len(calls) == 4


def test_from_table_of_a_user_curve(case):
    """A user's table over one mesh cycle, repeated over a revolution; the map reproduces it
    away from the steps, and several rows interpolate in d."""
    pair = case.gear_pair()
    pm = PEMModel.from_case(case, cracked=False)
    tm = pair.mesh_angle
    th = np.linspace(0, tm, 720, endpoint=False)
    rows = np.stack([pm.mesh_stiffness(th, d) for d in (0.0, 1e-3)])
    m = StiffnessMap.from_table(pair, th, rows, dd=[0.0, 1e-3], n_seg=256,
                                attrs={"source": "test"})
    assert m.attrs["method"] == "table" and m.n_cycles == pair.pinion.teeth
    probe = np.linspace(0, tm, 97, endpoint=False) + 0.3 * (th[1] - th[0])
    for i, d in enumerate((0.0, 1e-3)):
        ref = np.interp(probe, th, rows[i], period=tm)
        op = pair.operating(d)
        s = pair.pitch_point_s + pair.pinion.base_radius * probe
        far = np.minimum(np.abs(((s - op.s_start) / pair.base_pitch + 0.5) % 1 - 0.5),
                         np.abs(((s - op.s_end) / pair.base_pitch + 0.5) % 1 - 0.5)) > 0.01
        for shift in (0, 5, 22):  # the same curve every mesh cycle
            np.testing.assert_allclose(m(probe[far] + shift * tm, d), ref[far], rtol=2e-4)
    # one row: constant in d
    m1 = StiffnessMap.from_table(pair, th, rows[0])
    assert m1(0.1, 0.0) == m1(0.1, 5e-3)
    with pytest.raises(geardyn.InputError):
        StiffnessMap.from_table(pair, th[:100], rows[0][:100])


def test_pair_load_share_follows_one_pair(case, cmap):
    """The share of the pair holding a pinion tooth, read from the map's slots, equals the PEM's
    share of that pair (zero out of mesh)."""
    pm = PEMModel.from_case(case)
    th = np.linspace(2.0, 3.5, 701)
    for tooth in (0, 11):
        for dd in (0.0, 0.55e-3):
            r = pm.evaluate(th, dd)
            ref = np.where(np.mod(r["pair"], 23) == tooth, r["load_share"], 0.0).sum(axis=1)
            got = pair_load_share(cmap, th, dd, tooth)
            op = case.gear_pair().operating(dd)
            s = case.gear_pair().pitch_point_s + case.gear_pair().pinion.base_radius * th
            pb = case.gear_pair().base_pitch
            far = np.minimum(np.abs(((s - op.s_start) / pb + 0.5) % 1 - 0.5),
                             np.abs(((s - op.s_end) / pb + 0.5) % 1 - 0.5)) > 1e-3
            np.testing.assert_allclose(got[far], ref[far], atol=2e-3)


def test_figures_are_method_agnostic(case, cmap):
    """The figure functions take any map: a PEM map or a user's table (no load sharing)."""
    from matplotlib.figure import Figure

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SainsotRangeWarning)
        healthy = pem_map(case, centre_distance_grid(case), cracked=False)
    for fig in (fig_stiffness(healthy), fig_load_sharing(healthy), fig_crack(healthy, cmap)):
        assert isinstance(fig, Figure)
        ax = fig.axes[0]
        assert "[deg]" in ax.get_xlabel() and "[" in ax.get_ylabel()
        assert len(ax.get_lines()) >= 3
    def legend_labels(fig):  # on the axes, or under them (figure legend, off the data)
        leg = fig.axes[0].get_legend() or fig.legends[0]
        return [t.get_text() for t in leg.get_texts()]

    labels = legend_labels(fig_stiffness(healthy))
    assert [lab.split()[0] for lab in labels] == ["K00", "K05", "K10"]
    labels = legend_labels(fig_crack(healthy, cmap))
    assert [lab.split()[0] for lab in labels] == ["K00", "KC005", "KC105"]
    pair = case.gear_pair()
    th = np.linspace(0, pair.mesh_angle, 200, endpoint=False)
    table = StiffnessMap.from_table(pair, th, 1e8 + 1e7 * np.sin(th * 23))
    assert isinstance(fig_stiffness(table, dds=(0.0,)), Figure)
    with pytest.raises(geardyn.InputError):
        fig_load_sharing(table)
