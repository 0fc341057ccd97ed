"""A run of the same inputs into a new folder (issue 16): diagnoses, output files and figures
come from the cache, bit for bit what the cold run computed.

Fast tier: the fingerprint of a NetCDF round trip, :class:`Deferred` figure arguments, the
stored diagnosis tree, :meth:`Cache.write_file`. Slow tier: the whole study twice (short
records, PEM maps), the second run into a new folder.
"""

from __future__ import annotations

import dataclasses
import filecmp
import hashlib
import json
import math

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
import xarray as xr  # noqa: E402

from geardyn.cache import Cache, record_lookups  # noqa: E402
from geardyn.studies.paper_cache import (  # noqa: E402
    cached_diagnosis,
    fingerprint,
    load_tree,
    save_tree,
    without_distributions,
)
from geardyn.studies.paper_result import Deferred, FigureStore, _digest  # noqa: E402

CALLS: list = []


def draw(y, *, title="t"):
    CALLS.append(title)
    fig, ax = plt.subplots(figsize=(2, 2))
    ax.plot(np.asarray(y))
    ax.set_title(title)
    return fig


def _key(obj) -> str:
    h = hashlib.sha256()
    _digest(obj, h)
    return h.hexdigest()


# ------------------------------------------------------------------------- fingerprints
def test_a_netcdf_round_trip_keeps_the_fingerprint(tmp_path):
    """The cause of the 6 figures the first warm run redrew: a record's Python float/int
    attributes come back from NetCDF as np.float64/np.int64 (same values)."""
    ds = xr.Dataset({"x": ("t", np.linspace(0.0, 1.0, 7), {"units": "m"})},
                    coords={"t": ("t", np.arange(7.0))},
                    attrs={"dt": 1e-5, "teeth": 23, "model": "II", "complete": 1})
    ds.to_netcdf(tmp_path / "r.nc", engine="h5netcdf")
    with xr.open_dataset(tmp_path / "r.nc", engine="h5netcdf") as back:
        back = back.load()
    assert type(back.attrs["dt"]) is not float and type(back.attrs["teeth"]) is not int
    assert _key(back) == _key(ds)
    # a value or a NumPy type of another precision is another fingerprint
    assert _key(np.float64(0.1)) == _key(0.1)
    assert _key(np.float32(0.5)) != _key(0.5)
    assert _key(np.int32(3)) != _key(3)
    assert _key(0.1) != _key(float(np.nextafter(0.1, 1.0)))


def test_a_deferred_argument_is_computed_only_when_the_figure_is_drawn(tmp_path, monkeypatch):
    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "cache"))
    CALLS.clear()
    computed: list = []

    def values():
        computed.append(1)
        return np.linspace(0.0, 1.0, 20)

    a = FigureStore()
    a.cached("f", draw, Deferred("fp-1", values), title="one")
    assert computed == [1] and CALLS == ["one"]
    b = FigureStore()
    b.cached("f", draw, Deferred("fp-1", values), title="one")  # same fingerprint: cached
    assert computed == [1] and CALLS == ["one"] and b["f"].png == a["f"].png
    FigureStore().cached("f", draw, Deferred("fp-2", values), title="one")  # another value
    assert computed == [1, 1] and CALLS == ["one", "one"]
    d = Deferred("fp-3", values)
    assert d.value() is d.value() and computed == [1, 1, 1]  # computed once
    monkeypatch.setenv("GEARDYN_NO_CACHE", "1")
    FigureStore().cached("f", draw, Deferred("fp-1", values), title="one")
    assert CALLS == ["one", "one", "one"]


def test_a_function_imported_on_call_keeps_the_figure_key(tmp_path, monkeypatch):
    """The study passes some drawing functions by module and name (no import until drawn);
    the figure cache knows them by the same key as the function itself."""
    from geardyn.studies.paper_result import ImportedOnCall

    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "cache"))
    CALLS.clear()
    y = np.arange(4.0)
    lazy = ImportedOnCall(draw.__module__, draw.__qualname__)
    FigureStore().cached("f", draw, y, title="x")
    FigureStore().cached("f", lazy, y, title="x")
    assert CALLS == ["x"]
    FigureStore().cached("f", lazy, y, title="y")  # drawn through the import
    assert CALLS == ["x", "y"]


# ---------------------------------------------------------------------- stored diagnoses
def _synthetic_inputs(n_rev: int = 6, n: int = 256, z: int = 23) -> dict:
    """A gear-like signal over ``n_rev`` revolutions: mesh harmonics plus a once-per-rev
    impulse (a crack), sampled on an uneven angle grid."""
    rng = np.random.default_rng(5)
    m = n_rev * n * 3
    angle = np.cumsum(np.full(m, 2 * np.pi / (3 * n)) * (1 + 0.01 * rng.standard_normal(m)))
    mesh = np.cos(z * angle) + 0.3 * np.cos(2 * z * angle + 0.4)
    crack = np.exp(-((np.mod(angle, 2 * np.pi) - 3.0) / 0.05) ** 2)
    sigs = {"v_yg": 1e-3 * (mesh + 0.5 * crack), "omega_p": 100 + mesh - crack,
            "transmission_error": 0.05 + 1e-4 * mesh}
    return dict(signals=sigs, teeth=z, angle=angle, time=angle / 100.0, samples_per_rev=n,
                harmonic=2, bandwidth=5, residual_preset="paper",
                units={"v_yg": "m/s", "omega_p": "rad/s", "transmission_error": "rad"},
                source="synthetic")


def _same_tree(a, b, path="") -> None:
    """Equal value for value and type for type (arrays: dtype, shape, bytes)."""
    assert type(a) is type(b), (path, type(a), type(b))
    if isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes(), path
    elif isinstance(a, np.generic):
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes(), path
    elif isinstance(a, float):
        assert (math.isnan(a) and math.isnan(b)) or (a == b and math.copysign(1, a)
                                                      == math.copysign(1, b)), path
    elif dataclasses.is_dataclass(a):
        for f in dataclasses.fields(a):
            _same_tree(getattr(a, f.name), getattr(b, f.name), f"{path}.{f.name}")
    elif isinstance(a, dict):
        assert list(a) == list(b), path
        for k in a:
            _same_tree(a[k], b[k], f"{path}[{k!r}]")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _same_tree(x, y, f"{path}[{i}]")
    else:
        assert a == b, path


def test_a_stored_diagnosis_reads_back_bit_for_bit(tmp_path):
    from geardyn.diagnostics import diagnose

    full = diagnose(**_synthetic_inputs())
    diag = without_distributions(full)
    sd = diag.signals["v_yg"]
    assert sd.pwvd_tsa.distribution.shape == (0, 0)
    assert full.signals["v_yg"].pwvd_tsa.distribution.size > 0
    save_tree(diag, tmp_path / "d.npz")
    back = load_tree(tmp_path / "d.npz")
    _same_tree(diag, back)
    assert back.to_dict() == diag.to_dict()
    # the special floats and containers too
    odd = {"nan": float("nan"), "inf": -math.inf, "neg0": -0.0, "t": (1, "a", None, True),
           "l": [np.float32(1.5), np.int64(7), np.bool_(True)], 3: np.zeros((0, 0)),
           "c": np.array([1 + 2j])}
    save_tree(odd, tmp_path / "o.npz")
    _same_tree(odd, load_tree(tmp_path / "o.npz"))


def test_a_stored_tree_naming_another_class_is_refused(tmp_path):
    """No pickles and no classes outside geardyn.diagnostics: a tampered tree is an error (the
    cache then rebuilds the entry), not code that runs."""
    tree = {"dataclass": "subprocess:CompletedProcess", "fields": {"args": "x", "returncode": 0,
                                                                    "stdout": None,
                                                                    "stderr": None}}
    text = json.dumps(tree).encode()
    with open(tmp_path / "bad.npz", "wb") as fh:
        np.savez(fh, __tree__=np.frombuffer(text, dtype=np.uint8))
    with pytest.raises(ValueError, match="subprocess:CompletedProcess"):
        load_tree(tmp_path / "bad.npz")


def test_cached_diagnosis_computes_once_and_is_rebuilt_when_damaged(tmp_path, monkeypatch):
    import geardyn.diagnostics as gd

    cache = Cache(tmp_path / "cache", enabled=True)
    inputs = _synthetic_inputs()
    d1, full = cached_diagnosis(inputs, cache=cache)
    # computed here, without the distributions (not computed at all: what dropping them from
    # the whole diagnosis leaves, to the last bit of every other result)
    assert full is not None and full.signals["omega_p"].pwvd_residual.distribution.shape == (0, 0)
    whole = gd.diagnose(**inputs)
    assert whole.signals["omega_p"].pwvd_residual.distribution.size > 0
    _same_tree(d1, without_distributions(whole))
    assert fingerprint(d1) == fingerprint(without_distributions(whole))
    calls = []
    real = gd.diagnose
    monkeypatch.setattr(gd, "diagnose", lambda **kw: calls.append(1) or real(**kw))
    d2, full2 = cached_diagnosis(inputs, cache=cache)
    assert full2 is None and calls == []
    _same_tree(d1, d2)
    assert fingerprint(d2) == fingerprint(without_distributions(whole))
    # other inputs (one sample changed in its last digit): another entry
    other = {**inputs, "signals": {**inputs["signals"]}}
    other["signals"]["v_yg"] = inputs["signals"]["v_yg"].copy()
    other["signals"]["v_yg"][10] *= 1 + 2**-52
    cached_diagnosis(other, cache=cache)
    assert calls == [1]
    # a damaged entry fails its checksum and is computed again
    entry = next((tmp_path / "cache" / "diagnosis").glob("*.npz"))
    entry.write_bytes(entry.read_bytes()[:-10])
    for _ in range(2):
        cached_diagnosis(inputs, cache=cache)
        cached_diagnosis(other, cache=cache)
    assert calls == [1, 1]


# --------------------------------------------------------------------------- output files
def test_write_file_copies_the_bytes_of_an_earlier_write(tmp_path):
    cache = Cache(tmp_path / "cache", enabled=True)
    writes = []

    def write(path):
        writes.append(path)
        path.write_bytes(b"payload " * 1000)

    assert cache.write_file("output", "k1", tmp_path / "a" / "x.nc", write) is False
    assert cache.write_file("output", "k1", tmp_path / "b" / "x.nc", write) is True
    assert len(writes) == 1 and writes[0] != tmp_path / "a" / "x.nc"  # written into the cache
    assert filecmp.cmp(tmp_path / "a" / "x.nc", tmp_path / "b" / "x.nc", shallow=False)
    entry = cache.path("output", "k1", ".nc")
    assert entry.is_file() and json.loads(entry.with_name("k1.nc.sha256").read_text())["key"] \
        == "k1"
    # a damaged entry is written again, never copied
    entry.write_bytes(b"garbage")
    assert cache.write_file("output", "k1", tmp_path / "c" / "x.nc", write) is False
    assert len(writes) == 2 and (tmp_path / "c" / "x.nc").read_bytes() == b"payload " * 1000
    # no temporary files left beside the targets
    assert sorted(p.name for p in (tmp_path / "c").iterdir()) == ["x.nc"]
    # without the cache: written in place, nothing stored
    off = Cache(tmp_path / "off", enabled=False)
    assert off.write_file("output", "k1", tmp_path / "d" / "x.nc", write) is False
    assert (tmp_path / "d" / "x.nc").read_bytes() == b"payload " * 1000
    assert not (tmp_path / "off").exists()


# ------------------------------------------------------------------------- the whole run
SETS = ["simulation.record_time=0.2 s", "simulation.settle_time=0.05 s",
        "stiffness.centre_distances=11", "diagnostics.samples_per_rev=1024"]


def _counts(lookups: list[dict]) -> dict:
    out: dict = {}
    for r in lookups:
        c = out.setdefault(r["kind"], {"hits": 0, "built": 0})
        c["hits" if r["hit"] else "built"] += 1
    return out


def _h5_equal(a, b, path=""):
    import h5py

    assert sorted(a) == sorted(b), path
    for k in a:
        if isinstance(a[k], h5py.Group):
            _h5_equal(a[k], b[k], f"{path}/{k}")
        else:
            x, y = np.asarray(a[k][()]), np.asarray(b[k][()])
            assert x.dtype == y.dtype and x.shape == y.shape, f"{path}/{k}"
            if x.dtype.hasobject:  # strings
                assert x.tolist() == y.tolist(), f"{path}/{k}"
            else:
                assert x.tobytes() == y.tobytes(), f"{path}/{k}"
    assert sorted(a.attrs) == sorted(b.attrs), path
    for k in a.attrs:
        if k != "summary_json":  # holds the run times
            assert np.array_equal(np.asarray(a.attrs[k]), np.asarray(b.attrs[k])), (path, k)


@pytest.mark.slow
def test_a_warm_run_into_a_new_folder_recomputes_nothing(tmp_path, monkeypatch):
    """The second run diagnoses nothing, draws no figure and encodes no output file, and
    everything it writes equals the cold run's bit for bit (the run times apart)."""
    import h5py

    import geardyn.diagnostics as gd
    from geardyn.config import paper_case
    from geardyn.studies.paper import run_paper_study

    monkeypatch.setenv("GEARDYN_CACHE_DIR", str(tmp_path / "cache"))
    case = paper_case(SETS)
    with record_lookups() as cold:
        a = run_paper_study(case, tmp_path / "a", quick=True, stiffness="pem")
    cold = _counts(cold)
    assert cold["diagnosis"] == {"hits": 0, "built": 6}  # models I, I-static, II x 2 states
    # the output files: the run records, the two maps and results.nc (since 2026-11-28: one
    # entry, each run's own summary set on its copy)
    assert cold["figure"]["hits"] == 0 and cold["output"] == {"hits": 0, "built": 10}
    assert cold["map values"] == {"hits": 0, "built": 1}

    def no_diagnosis(**_kw):
        raise AssertionError("a warm run diagnosed a record")

    monkeypatch.setattr(gd, "diagnose", no_diagnosis)
    with record_lookups() as warm:
        b = run_paper_study(case, tmp_path / "b", quick=True, stiffness="pem")
    warm = _counts(warm)
    assert warm["figure"] == {"hits": cold["figure"]["built"], "built": 0}
    assert warm["diagnosis"] == {"hits": 6, "built": 0}
    assert warm["output"] == {"hits": 10, "built": 0}
    assert warm["map values"] == {"hits": 1, "built": 0}
    assert all(v["built"] == 0 for v in warm.values()), warm

    # the results: summaries, diagnoses, figures and files, bit for bit
    sa, sb = (json.loads((r.out / "summary.json").read_text()) for r in (a, b))
    for s in (sa, sb):
        s.pop("run_time_s")
        s.pop("output_size_bytes")  # results.nc holds the summary, with its run times
    assert sa == sb
    assert sorted(a.diagnoses) == sorted(b.diagnoses)
    for k in a.diagnoses:
        _same_tree(a.diagnoses[k], b.diagnoses[k], str(k))
    assert sorted(a.figures) == sorted(b.figures)
    assert all(a.figures[k].png == b.figures[k].png for k in a.figures)
    files = sorted(p.relative_to(a.out) for p in a.out.rglob("*") if p.is_file()
                   and p.name not in ("summary.json", "results.nc", "report.html"))
    assert any(p.parts[0] == "runs" for p in files) and any(p.parts[0] == "figures"
                                                            for p in files)
    for p in files:
        assert filecmp.cmp(a.out / p, b.out / p, shallow=False), p
    with h5py.File(a.out / "results.nc") as fa, h5py.File(b.out / "results.nc") as fb:
        _h5_equal(fa, fb)
    # each copy holds its own run's summary (its stage times), readable by xarray
    for r, s in ((a, sa), (b, sb)):
        with xr.open_dataset(r.out / "results.nc") as ds:
            own = json.loads(ds.attrs["summary_json"])
        times = json.loads((r.out / "summary.json").read_text())["run_time_s"]
        assert own.pop("run_time_s") == {k: times[k] for k in times
                                         if k not in ("report", "total")}
        # (results.nc is written as the report stage starts: "complete" and "stages" are
        # the summary's then)
        assert own.pop("stages") == s["stages"][:-1] and s["stages"][-1] == "report"
        assert own.pop("complete") is False and s["complete"] is True
        assert own == {k: v for k, v in s.items() if k in own} and len(own) >= len(s) - 3

    # the cached numbers read off the maps are the maps' own (computed directly here)
    from geardyn.stiffness.plots import crack_angle

    h, c = b.maps["healthy"], b.maps["cracked"]
    dd_op = sb["crack_angle_in_stiffness_at_mm"] * 1e-3
    assert sb["crack_angle_in_stiffness_deg"] == math.degrees(crack_angle(h, c, dd_op))
    assert b.crack_angle_rad == crack_angle(h, c, 0.0)
    th = np.linspace(0.0, h.period, 4096, endpoint=False)
    assert sb["mean_mesh_stiffness_N_per_m"] == {
        f"{dd * 1e3:+.1f}mm": float(np.mean(h(th, dd))) for dd in (0.0, 0.5e-3, 1.0e-3)
        if h.covers(dd)}
