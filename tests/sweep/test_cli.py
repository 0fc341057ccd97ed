"""``geardyn sweep`` as a user meets it when something is wrong: one line, exit status 2."""

from __future__ import annotations

import pytest

from .._cli_fork import run_geardyn
from ._procs import env


@pytest.mark.slow
@pytest.mark.parametrize(("args", "words"), [
    (["sweep", "{dir}/bad.toml", "--out", "{dir}/o.zarr"], "axes.crack.depth[1]"),
    (["sweep", "{dir}/good.toml", "--out", "{dir}/o.zarr", "--workers", "2", "--scheduler",
      "tcp://127.0.0.1:1"], "--workers"),
    (["sweep", "{dir}/good.toml", "--out", "{dir}/file.txt"], "not a Zarr store"),
    (["sweep", "{dir}/good.toml", "--out", "{dir}/o.zarr", "--evaluator", "nope"],
     "--evaluator"),
    (["sweep", "{dir}/missing.toml", "--out", "{dir}/o.zarr"], "no such file"),
])
def test_errors_are_one_line_with_status_2(tmp_path, args, words):
    (tmp_path / "bad.toml").write_text('[axes]\ncrack.depth = ["1 mm", "2 kg"]\n')
    (tmp_path / "good.toml").write_text('[axes]\ncrack.depth = ["1 mm"]\n')
    (tmp_path / "file.txt").write_text("not a store")
    r = run_geardyn([*[a.format(dir=tmp_path) for a in args]],
                    capture_output=True, text=True, env=env(), timeout=120, cwd=tmp_path)
    assert r.returncode == 2, r.stdout + r.stderr
    assert words in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "o.zarr").exists()


@pytest.mark.slow
def test_config_and_set_change_the_base_case_and_the_identity(tmp_path):
    """--set overrides reach every run's case, are recorded in the store, and a store made with
    other overrides is not resumed by mistake."""
    import xarray as xr

    (tmp_path / "s.toml").write_text('[axes]\n"motor.torque" = ["80 N m", "120 N m"]\n')
    ev = "tests.sweep._evaluators:OscillatorEvaluator"
    base = ["sweep", str(tmp_path / "s.toml"), "--out", str(tmp_path / "o.zarr"), "--workers",
            "1", "--evaluator", ev]
    r = run_geardyn([*base, "--set", "pinion.mass=0.9 kg"], env=env(), timeout=300, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    ds = xr.open_zarr(tmp_path / "o.zarr")
    assert "--set 'pinion.mass=0.9 kg'" in ds.attrs["sweep_file"]
    r2 = run_geardyn([*base, "--set", "pinion.mass=1.1 kg"], env=env(), timeout=300, cwd=tmp_path)
    assert r2.returncode == 2 and "--force" in r2.stderr
