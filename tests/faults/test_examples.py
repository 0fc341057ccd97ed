"""The shipped fault examples run through the CLI: ``geardyn stiffness`` for each partial case
file of examples/faults/ and ``geardyn sweep`` over a spall's width (examples are tests)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from .._cli_fork import run_geardyn

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples" / "faults"
CASES = sorted(p.name for p in EXAMPLES.glob("*.toml") if not p.name.startswith("sweep_"))
SMALL = ["--set", "stiffness.centre_distances=3", "--set", "stiffness.nodes_per_segment=6"]


def _run(args, tmp_path, timeout=600):
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(tmp_path / "cache")}
    return run_geardyn([*args], capture_output=True,
                       text=True, env=env, timeout=timeout, cwd=tmp_path)


def test_every_fault_type_has_an_example():
    from geardyn.config import load_case

    kinds = {f.type for name in CASES for f in load_case(EXAMPLES / name).faults}
    assert kinds == {"root_crack", "spall", "breakage", "wear"}
    assert (EXAMPLES / "README.md").is_file()


@pytest.mark.slow
@pytest.mark.parametrize("name", CASES)
def test_example_through_the_cli(tmp_path, name):
    import xarray as xr

    out = tmp_path / "out"
    r = _run(["stiffness", "--config", str(EXAMPLES / name), "--out", str(out), *SMALL],
             tmp_path)
    assert r.returncode == 0, r.stderr
    assert (out / "fig_faults.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with xr.open_dataset(out / "stiffness_healthy.nc") as h, \
            xr.open_dataset(out / "stiffness_faulty.nc") as f:
        kh, kf = h["k_mb"].values, f["k_mb"].values
        # the faulty map is the healthy one repeated over its period, less where the fault is
        reps = kf.shape[1] // kh.shape[1]
        kh = np.tile(kh, reps)
        if name == "wear_archard.toml":  # a gap only (stiffness = false): the same stiffness
            np.testing.assert_array_equal(kf, kh)
            # the Archard profile's largest depth is 20 um; the map samples it on its nodes
            assert 10e-6 < f["fault_gap"].values.max() <= 20e-6 * (1 + 1e-12)
            assert "faults" in f.attrs["parameters"]
            return
        # 30 um of wear thins the tooth by ~0.1 % of its thickness: a loss of ~1e-4
        drop = 1e-5 if name == "wear.toml" else 1e-3
        assert np.all(kf <= kh * (1 + 1e-12)) and np.any(kf < kh * (1 - drop))
        if name == "wear.toml":
            assert np.isclose(f["fault_gap"].values.max(), 30e-6, rtol=1e-12)
        assert "faults" in f.attrs["parameters"]


def test_fe_refused_through_the_cli(tmp_path):
    """Worn-tooth thinning (wear.toml: stiffness = true) is PEM only: a clean refusal."""
    r = _run(["stiffness", "--config", str(EXAMPLES / "wear.toml"), "--method", "fe",
              "--out", str(tmp_path / "o")], tmp_path)
    assert r.returncode == 2
    assert "faults[0].stiffness" in r.stderr


@pytest.mark.slow
def test_sweep_over_spall_width(tmp_path):
    """The example sweep: 4 spall widths, model II dynamics, through ``geardyn sweep``; the
    energy ratio and FM0 of the gear bearing's velocity grow with the width."""
    from geardyn.studies.sweep import open_sweep

    store = tmp_path / "spall.zarr"
    r = _run(["sweep", str(EXAMPLES / "sweep_spall_width.toml"), "--out", str(store)],
             tmp_path, timeout=900)
    assert r.returncode == 0, r.stderr
    ds = open_sweep(store).load()
    assert np.all(ds.status.values == 1)
    np.testing.assert_allclose(ds["faults.0.width"].values, [0, 4e-3, 8e-3, 12e-3])
    for metric in ("v_yg__EnergyRatio", "v_yg__FM0", "v_yg__peak_to_peak"):
        assert np.all(np.diff(ds[metric].values) > 0), (metric, ds[metric].values)


@pytest.mark.slow
def test_sweep_over_crack_depth_with_the_substructured_fe_map(tmp_path):
    """The FE crack-depth sweep (``stiffness.fe.substructure = true``) on a coarser mesh: every
    run ok, the healthy part condensed once for all depths (one superelement in the cache), and
    the energy ratio and FM0 of the gear bearing's velocity grow with the depth."""
    from geardyn.studies.sweep import open_sweep

    store = tmp_path / "depth.zarr"
    r = _run(["sweep", str(EXAMPLES / "sweep_crack_depth_fe.toml"), "--out", str(store),
              "--set", "stiffness.fe.refinement=0.5"], tmp_path, timeout=900)
    assert r.returncode == 0, r.stderr
    ds = open_sweep(store).load()
    assert np.all(ds.status.values == 1)
    np.testing.assert_allclose(ds["crack.depth"].values, np.array([0.5, 1, 2, 3, 4, 5]) * 1e-3)
    for metric in ("v_yg__EnergyRatio", "v_yg__FM0"):
        assert np.all(np.diff(ds[metric].values) > 0), (metric, ds[metric].values)
    fe_entries = [p for p in (tmp_path / "cache" / "fe").glob("*.npz")]
    with_s = []
    for p in fe_entries:
        with np.load(p, allow_pickle=False) as d:
            with_s.append("S" in d.files)
    # one healthy body (the paper's 23/23 pinion and gear share it), one superelement, six
    # cracked bodies
    assert sum(with_s) == 1 and len(fe_entries) == 1 + 1 + 6, (sum(with_s), len(fe_entries))
