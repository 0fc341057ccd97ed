"""An output that cannot be written is a user error for ``measure``, ``static-te``, ``sweep`` and
``study model-ii`` as for the other commands (tests/cli/test_user_errors.py): one line naming
``--out``, the value and what is allowed, exit status 2, no traceback, before any computation
(nothing cached, nothing written), in bounded time."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

from .._cli_fork import run_geardyn

ROOT = Path(__file__).resolve().parents[2]
SWEEP = ROOT / "examples" / "transverse" / "sweep_friction.toml"
#: /proc refuses new files even to root (a chmod-ed folder would not stop root)
RO = "/proc/geardyn-test"


def run(args, tmp_path, cwd=None):
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(tmp_path / "cache")}
    t0 = time.perf_counter()
    r = run_geardyn(list(args), capture_output=True, text=True, env=env, cwd=cwd or tmp_path,
                    timeout=120)
    return r, time.perf_counter() - t0


def _one_error_line(r, seconds):
    assert r.returncode == 2, r.stdout + r.stderr
    assert "Traceback" not in r.stdout + r.stderr and "internal error" not in r.stderr
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and len(lines[0]) < 500, r.stderr
    assert seconds < 60, seconds  # refused before the map / simulation / cluster
    return lines[0]


def _command(name, out):
    return {"measure": ["measure", "--stiffness", "pem", "--out", out],
            "static-te": ["static-te", "--out", out],
            "sweep": ["sweep", str(SWEEP), "--out", out],
            "study": ["study", "model-ii", "--quick", "--out", out]}[name]


SUFFIX = {"measure": "m.nc", "static-te": "te.nc", "sweep": "s.zarr", "study": "st"}


@pytest.mark.parametrize("name", list(SUFFIX))
def test_unwritable_out_is_refused_first(tmp_path, name):
    out = f"{RO}/{SUFFIX[name]}"
    line = _one_error_line(*run(_command(name, out), tmp_path))
    assert f"--out {out}: got 'cannot write in /proc (" in line, line
    assert line.endswith("allowed: a folder you can write to"), line
    assert not (tmp_path / "cache").exists()  # nothing computed, nothing cached
    assert sorted(p.name for p in tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", list(SUFFIX))
def test_out_below_an_existing_file_is_refused_first(tmp_path, name):
    afile = tmp_path / "afile"
    afile.write_text("keep me")
    out = afile / SUFFIX[name]
    line = _one_error_line(*run(_command(name, str(out)), tmp_path))
    assert f"--out {out}: got '{afile}'" in line and "is a file, not a folder" in line, line
    assert afile.read_text() == "keep me"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]


@pytest.mark.parametrize("name", ["measure", "static-te"])
def test_file_out_that_is_a_folder_is_refused_first(tmp_path, name):
    line = _one_error_line(*run(_command(name, str(tmp_path)), tmp_path))
    assert line.endswith(f"--out {tmp_path}: got 'an existing folder'; allowed: a file path"), line
    assert not (tmp_path / "cache").exists()


def test_study_out_that_is_a_file_is_refused_first(tmp_path):
    afile = tmp_path / "afile"
    afile.write_text("keep me")
    line = _one_error_line(*run(_command("study", str(afile)), tmp_path))
    assert f"--out {afile}: got 'an existing file'" in line, line
    assert afile.read_text() == "keep me"


@pytest.mark.parametrize(("name", "default"), [("measure", "measurement.nc"),
                                               ("static-te", "static_te.nc")])
def test_default_output_in_an_unwritable_folder_names_the_default(tmp_path, name, default):
    r, seconds = run([name], tmp_path, cwd="/proc")
    line = _one_error_line(r, seconds)
    assert f"the default output file {default}: got 'cannot write in /proc" in line, line
    assert line.endswith("allowed: a folder you can write to (choose one with --out)"), line
    assert not (tmp_path / "cache").exists()
