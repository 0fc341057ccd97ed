"""StiffnessMap (stiffness/map.py): the grid check of ``__post_init__`` for two grid lines, and
the storage/evaluation wrappers (``to_dataset``, ``from_dataset``, ``to_netcdf``/``from_netcdf``,
``arrays``, ``__call__``) on a hand-made map whose every array is unequal and non-symmetric.

Written against survivors of the mutation run of ``stiffness/map.py`` (docs/mutation.md, issue
20): ``__post_init__`` 23 and 28 (a decreasing or repeated pair of grid lines, a constant grid)
and the wrappers, which the earlier tests only exercised with symmetric data (equal grid lines,
one extra variable). Oracles: the arrays the map was built from (a round trip must give them
back bit for bit, with the dimensions and units of the documented layout) and the NumPy twin
:func:`lookup_reference` called on :class:`MapArrays` assembled here by hand.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from geardyn.errors import DataFileError, InputError
from geardyn.stiffness.map import MapArrays, StiffnessMap, lookup_reference

N_CYC, N_SEG, N_D = 3, 4, 3
NODES = N_CYC * 2 * N_SEG
MESH = 0.27          # rad, deliberately not 2 pi / n_cycles
RB = 0.0514          # m


def _base(**over):
    rng = np.random.default_rng(11)
    kw = dict(dd=np.array([-2e-4, 1e-4, 4e-4]), phase_a=np.array([0.031, 0.044, 0.052]),
              length_a=np.array([0.101, 0.093, 0.088]), mesh_angle=MESH, n_cycles=N_CYC,
              n_seg=N_SEG, k_mb=rng.uniform(5e7, 2e8, (N_D, NODES)), base_radius=RB)
    kw.update(over)
    return kw


@pytest.fixture(scope="module")
def rich():
    """Three grid lines, every array different along every axis; all extra layouts."""
    rng = np.random.default_rng(5)
    share = rng.uniform(0.0, 1.0, (N_D, NODES, 3))
    share /= share.sum(axis=-1, keepdims=True)
    extra = {"load_share": share,
             "pairs_in_contact": rng.integers(1, 3, (N_D, NODES)).astype(float),
             "transmission_error": rng.normal(0.0, 1e-5, (N_D, NODES)),
             "load_share_exiting": rng.uniform(0.0, 0.1, (N_D, NODES)),
             "custom": rng.normal(size=(N_D, NODES, 2, 5))}
    attrs = {"method": "hand-made", "parameters": {"a": 1, "b": [1, 2]}, "flags": [3, 4],
             "pair": (5, 6), "cracked": True, "note": None, "scale": 2.5, "count": 7}
    return StiffnessMap(**_base(), extra=extra,
                        slot_tooth=np.array([[0, 1, 2], [1, 2, 0], [2, 0, 1]]), attrs=attrs)


def _arrays_by_hand(m, values):
    return MapArrays(float(m.dd[0]), float(m.dd[1] - m.dd[0]) if m.dd.size > 1 else 0.0,
                     np.asarray(m.phase_a, float), np.asarray(m.length_a, float),
                     float(m.mesh_angle), int(m.n_cycles), int(m.n_seg),
                     np.asarray(values, float))


# ------------------------------------------------------------------ __post_init__
@pytest.mark.parametrize("dd", [[1e-4, 0.0], [3e-4, 3e-4], [0.0, 0.0, 0.0], [2e-4, 2e-4, 2e-4],
                                [0.0, 1e-4, 1e-4]])
def test_two_or_more_grid_lines_must_increase(dd):
    """A decreasing or repeated pair of grid lines (mutant 23 skipped the check for two
    lines) and a constant grid (mutant 28 accepted a zero step) are refused in full."""
    dd = np.array(dd)
    kw = _base(dd=dd, phase_a=np.full(dd.size, 0.03), length_a=np.full(dd.size, 0.1),
               k_mb=np.full((dd.size, NODES), 1e8))
    with pytest.raises(InputError) as exc:
        StiffnessMap(**kw)
    assert exc.value.field == "dd" and exc.value.value is dd
    assert exc.value.allowed == "uniformly spaced, increasing values"


def test_grid_uniformity_tolerance():
    """Spacings equal to 1e-9 of the first step (+1e-15 m) are accepted, a spacing error of
    1e-11 m on 1e-4 m steps (1e-7 relative) is refused."""
    ok = np.array([0.0, 1e-4, 2e-4 + 5e-14])
    StiffnessMap(**_base(dd=ok))
    bad = np.array([0.0, 1e-4, 2e-4 + 1e-11])
    with pytest.raises(InputError) as exc:
        StiffnessMap(**_base(dd=bad))
    assert (exc.value.field, exc.value.allowed) == ("dd", "uniformly spaced, increasing values")
    one = StiffnessMap(**_base(dd=np.array([7e-5]), phase_a=np.array([0.03]),
                               length_a=np.array([0.1]), k_mb=np.full((1, NODES), 1e8)))
    assert one.dd.tolist() == [7e-5]


# ------------------------------------------------------------------ arrays and __call__
def test_arrays_pick_variable_slot_and_grid(rich):
    a = rich.arrays()
    assert a.dd0 == -2e-4 and a.ddd == pytest.approx(3e-4, rel=1e-12)
    assert a.mesh_angle == MESH and a.n_cycles == N_CYC and a.n_seg == N_SEG
    for got, want in ((a.phase_a, rich.phase_a), (a.length_a, rich.length_a),
                      (a.values, rich.k_mb)):
        np.testing.assert_array_equal(got, want)
        assert got.flags.c_contiguous and got.dtype == np.float64
    for k in range(3):
        np.testing.assert_array_equal(rich.arrays("load_share", slot=k).values,
                                      rich.extra["load_share"][..., k])
    np.testing.assert_array_equal(rich.arrays("transmission_error").values,
                                  rich.extra["transmission_error"])
    for name, slot in (("load_share", None), ("custom", 1)):
        with pytest.raises(InputError) as exc:
            rich.arrays(name, slot=slot)
        assert (exc.value.field, exc.value.value, exc.value.allowed) == (
            "variable", name, "a variable with one value per node")
    single = StiffnessMap(**_base(dd=np.array([5e-5]), phase_a=np.array([0.04]),
                                  length_a=np.array([0.09]), k_mb=np.full((1, NODES), 3e7)))
    s = single.arrays()
    assert (s.dd0, s.ddd) == (5e-5, 0.0)


def test_call_broadcasts_and_matches_the_reference_lookup(rich):
    """``map(theta, dd)`` for every variable and slot against :func:`lookup_reference` on
    arrays assembled by hand: scalars give a float, arrays broadcast, NaN off the range."""
    rng = np.random.default_rng(2)
    th = rng.uniform(-0.5, 2.0, (7, 1))
    dd = np.array([[-2e-4, -1.1e-4, 0.0, 1e-4, 3.9e-4, 4e-4]])
    tb, db = np.broadcast_arrays(th, dd)
    cases = [("k_mb", None, rich.k_mb)] + [("load_share", k, rich.extra["load_share"][..., k])
                                            for k in range(3)]
    cases.append(("transmission_error", None, rich.extra["transmission_error"]))
    for name, slot, vals in cases:
        want = lookup_reference(tb, db, _arrays_by_hand(rich, vals))
        got = rich(th, dd, name, slot) if slot is not None else rich(th, dd, variable=name)
        assert got.shape == (7, 6)
        np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-13 * np.abs(vals).max())
    x = rich(0.123, 2e-4)
    assert isinstance(x, float)
    assert x == pytest.approx(float(lookup_reference(np.array(0.123), np.array(2e-4),
                                                     _arrays_by_hand(rich, rich.k_mb))),
                              rel=1e-13)
    assert np.isnan(rich(0.1, 4.1e-4)) and np.isnan(rich(0.1, -2.1e-4))
    np.testing.assert_allclose(rich.torsional(th, dd), rich(th, dd) * RB ** 2, rtol=1e-15)
    # dd defaults to 0
    assert rich(0.2) == rich(0.2, 0.0)


# ------------------------------------------------------------------ dataset and NetCDF
def test_dataset_layout_of_every_variable(rich):
    ds = rich.to_dataset()
    dims2 = ("centre_distance_change", "node")
    assert ds["load_share"].dims == dims2 + ("slot",)
    assert ds["load_share"].attrs == {"units": "1",
                                      "long_name": "load sharing ratio of the slot's tooth pair"}
    assert ds["pairs_in_contact"].dims == dims2
    assert ds["pairs_in_contact"].attrs == {"units": "1",
                                            "long_name": "number of tooth pairs in contact"}
    assert ds["transmission_error"].attrs == {
        "units": "rad", "long_name": "static transmission error (pinion angle)"}
    assert ds["load_share_exiting"].attrs == {
        "units": "1", "long_name": "load sharing ratio of the pair past the end of the "
                                  "theoretical path (extended contact, FE)"}
    assert ds["custom"].dims == dims2 + ("custom_dim2", "custom_dim3")
    assert ds["custom"].attrs == {"units": "", "long_name": "custom"}
    assert ds["slot_tooth"].dims == ("cycle", "slot")
    assert ds["slot_tooth"].attrs == {"units": "1", "long_name": "pinion tooth of each load-share slot"}
    np.testing.assert_array_equal(ds["slot_tooth"].values, rich.slot_tooth)
    for name, v in rich.extra.items():
        np.testing.assert_array_equal(ds[name].values, v)
    np.testing.assert_array_equal(ds["phase_a"].values, rich.phase_a)
    np.testing.assert_array_equal(ds["length_a"].values, rich.length_a)
    np.testing.assert_array_equal(ds["centre_distance_change"].values, rich.dd)
    np.testing.assert_array_equal(ds["node"].values, np.arange(NODES))
    # both are dimension coordinates (indexes): selection by value works
    assert ds["centre_distance_change"].dims == ("centre_distance_change",)
    assert ds["node"].dims == ("node",)
    assert set(ds.indexes) == {"centre_distance_change", "node"}
    assert float(ds["phase_a"].sel(centre_distance_change=1e-4)) == rich.phase_a[1]
    assert ds["node"].attrs == {"units": "1", "long_name": "boundary-fitted node index"}
    np.testing.assert_array_equal(ds["theta"].values, rich.node_theta())
    np.testing.assert_array_equal(ds["torsional_stiffness"].values, rich.k_mb * RB ** 2)
    # attributes: containers, booleans and None as JSON text, numbers and strings as they are
    a = ds.attrs
    assert json.loads(a["parameters"]) == {"a": 1, "b": [1, 2]}
    assert a["flags"] == "[3, 4]" and a["pair"] == "[5, 6]"
    assert a["cracked"] == "true" and a["note"] == "null"
    assert a["scale"] == 2.5 and a["count"] == 7 and a["method"] == "hand-made"
    assert (a["mesh_angle"], a["n_cycles"], a["n_seg"], a["base_radius"]) == (MESH, N_CYC,
                                                                               N_SEG, RB)
    assert a["mesh_angle_units"] == "rad" and a["base_radius_units"] == "m"
    assert a["geardyn_object"] == "StiffnessMap"


def _assert_same_map(back, m):
    for name in ("dd", "phase_a", "length_a", "k_mb", "slot_tooth"):
        got, want = getattr(back, name), getattr(m, name)
        np.testing.assert_array_equal(got, want)
        assert got.shape == want.shape, name
    assert (back.mesh_angle, back.n_cycles, back.n_seg, back.base_radius) == (
        m.mesh_angle, m.n_cycles, m.n_seg, m.base_radius)
    assert type(back.mesh_angle) is float and type(back.base_radius) is float
    assert type(back.n_cycles) is int and type(back.n_seg) is int
    assert back.dd.dtype == back.k_mb.dtype == back.phase_a.dtype == np.float64
    assert sorted(back.extra) == sorted(m.extra)
    for name, v in m.extra.items():
        np.testing.assert_array_equal(back.extra[name], v)
        assert back.extra[name].shape == v.shape
    rng = np.random.default_rng(9)
    th = rng.uniform(-1.0, 1.0, 50)
    d = rng.uniform(-2e-4, 4e-4, 50)
    np.testing.assert_array_equal(back(th, d), m(th, d))
    for k in range(3):
        np.testing.assert_array_equal(back(th, d, "load_share", k), m(th, d, "load_share", k))


def test_dataset_round_trip_in_memory(rich):
    back = StiffnessMap.from_dataset(rich.to_dataset())
    _assert_same_map(back, rich)
    reserved = {"mesh_angle", "mesh_angle_units", "n_cycles", "n_seg", "base_radius",
                "base_radius_units", "geardyn_object"}
    assert not reserved & set(back.attrs)
    assert back.attrs["method"] == "hand-made" and back.attrs["scale"] == 2.5
    assert json.loads(back.attrs["parameters"]) == {"a": 1, "b": [1, 2]}
    assert "torsional_stiffness" not in back.extra and "k_mb" not in back.extra
    assert "phase_a" not in back.extra and "slot_tooth" not in back.extra
    # no slot table: none comes back
    plain = StiffnessMap(**_base())
    again = StiffnessMap.from_dataset(plain.to_dataset())
    assert again.slot_tooth is None and again.extra == {}


def test_netcdf_round_trip_of_the_rich_map(rich, tmp_path):
    path = tmp_path / "rich.nc"
    rich.to_netcdf(path)
    back = StiffnessMap.from_netcdf(path)
    _assert_same_map(back, rich)
    assert back.attrs["method"] == "hand-made" and back.attrs["cracked"] == "true"


def test_from_netcdf_requires_the_map_variables(rich, tmp_path):
    """A file without ``length_a`` (or ``phase_a``, ``k_mb``) is refused by name."""
    for drop in ("length_a", "phase_a", "k_mb"):
        path = tmp_path / f"no_{drop}.nc"
        rich.to_dataset().drop_vars(drop).to_netcdf(path, engine="h5netcdf")
        with pytest.raises(DataFileError) as exc:
            StiffnessMap.from_netcdf(path)
        assert exc.value.problem == f"lacks the variable(s) {drop}"
    with pytest.raises(DataFileError) as exc:
        StiffnessMap.from_netcdf(tmp_path / "missing.nc")
    assert exc.value.problem == "no such file"


def test_from_dataset_returns_float64_from_narrower_storage(rich):
    """A dataset written by another tool with float32 / integer variables: the map holds
    float64 (SI float64 inside), with the stored values."""
    ds = rich.to_dataset()
    for name in ("phase_a", "length_a"):
        ds[name] = ds[name].astype(np.float32)
    ds = ds.assign_coords(centre_distance_change=ds["centre_distance_change"].astype(np.float32))
    ds["k_mb"] = (ds["k_mb"].dims, np.round(rich.k_mb).astype(np.int64), ds["k_mb"].attrs)
    back = StiffnessMap.from_dataset(ds)
    for name in ("dd", "phase_a", "length_a", "k_mb"):
        got = getattr(back, name)
        assert got.dtype == np.float64, name
    np.testing.assert_array_equal(back.k_mb, np.round(rich.k_mb))
    np.testing.assert_array_equal(back.phase_a, rich.phase_a.astype(np.float32))
    np.testing.assert_array_equal(back.dd, rich.dd.astype(np.float32))
