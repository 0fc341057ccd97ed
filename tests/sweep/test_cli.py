"""``geardyn sweep`` as a user meets it when something is wrong: one line, exit status 2."""

from __future__ import annotations

import subprocess

import pytest

from ._procs import GEARDYN, env


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
    r = subprocess.run([*GEARDYN, *[a.format(dir=tmp_path) for a in args]],
                       capture_output=True, text=True, env=env(), timeout=120, cwd=tmp_path)
    assert r.returncode == 2, r.stdout + r.stderr
    assert words in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "o.zarr").exists()
