"""``geardyn sweep`` exits 1 when a run of the store failed, after the store and the summary are
written (a script can tell); a resume without ``--retry-failed`` keeps the failed runs (not
computed again) and still exits 1; a sweep without failures exits 0."""

from __future__ import annotations

import re

import numpy as np
import pytest

from geardyn.studies.sweep import STATUS_FAILED, STATUS_OK, open_sweep, verify_store

from .._cli_fork import run_geardyn
from ._procs import env

EV = "tests.sweep._evaluators:FAST"


def sweep(args, tmp_path):
    e = {**env(), "GEARDYN_CACHE_DIR": str(tmp_path / "cache")}
    return run_geardyn(["sweep", *map(str, args), "--workers", "1"], capture_output=True,
                       text=True, env=e, timeout=300, cwd=tmp_path)


def _last_line(text):
    return [ln for ln in text.splitlines() if ln.strip()][-1]


def _computed(r):
    return int(re.search(r"(\d+) computed now", r.stdout).group(1))


@pytest.mark.slow
def test_a_sweep_whose_runs_all_fail_exits_1_and_a_resume_too(tmp_path):
    """The QA's sweep: cracks deeper than the tooth, through geardyn's own evaluator."""
    f = tmp_path / "deep.toml"
    f.write_text('name = "deep"\n[set]\nstiffness.method = "pem"\n'
                 '[axes]\ncrack.depth = ["60 mm", "50 mm"]\n')
    out = tmp_path / "deep.zarr"
    r = sweep([f, "--out", out], tmp_path)
    assert r.returncode == 1, r.stdout + r.stderr
    assert "Traceback" not in r.stdout + r.stderr
    assert "ok 0, failed 2, pending 0" in r.stdout and _computed(r) == 2
    # one cause, one line (the two differ only in their numbers), with the first's numbers
    assert "2 failed (numbers of the first): crack.depth: got 0.06" in r.stderr, r.stderr
    assert _last_line(r.stderr) == (f"2 of 2 runs failed (their errors are in the store: {out}, "
                                    "variable 'error')")
    # everything was written before the exit: a whole store recording both failures
    assert verify_store(out).ok
    ds = open_sweep(out).load()
    np.testing.assert_array_equal(ds.status.values, [STATUS_FAILED, STATUS_FAILED])
    assert str(ds.error.values[0]).startswith("crack.depth: got 0.06")

    again = sweep([f, "--out", out], tmp_path)  # resumed: the failed runs are not retried
    assert again.returncode == 1, again.stdout + again.stderr
    assert "resumed" in again.stdout and _computed(again) == 0
    assert "ok 0, failed 2, pending 0" in again.stdout
    assert _last_line(again.stderr).startswith("2 of 2 runs failed")


@pytest.mark.slow
def test_some_failed_runs_exit_1_and_retry_failed_computes_them_again(tmp_path):
    # the 70 mm bore is larger than the root radius: that run fails in the geometry
    f = tmp_path / "bores.toml"
    f.write_text('name = "bores"\n[axes]\npinion.bore_radius = ["20 mm", "70 mm"]\n'
                 '[link]\ngear.bore_radius = "pinion.bore_radius"\n')
    out = tmp_path / "bores.zarr"
    args = [f, "--out", out, "--evaluator", EV]
    r = sweep(args, tmp_path)
    assert r.returncode == 1, r.stdout + r.stderr
    assert "ok 1, failed 1, pending 0" in r.stdout
    assert _last_line(r.stderr).startswith(f"1 of 2 runs failed (their errors are in the "
                                           f"store: {out}")
    np.testing.assert_array_equal(open_sweep(out).status.values, [STATUS_OK, STATUS_FAILED])

    resumed = sweep(args, tmp_path)
    assert resumed.returncode == 1 and _computed(resumed) == 0, resumed.stdout + resumed.stderr
    retried = sweep([*args, "--retry-failed"], tmp_path)  # computed again, fails again
    assert retried.returncode == 1 and _computed(retried) == 1, retried.stdout + retried.stderr
    assert "ok 1, failed 1, pending 0" in retried.stdout


@pytest.mark.slow
def test_a_sweep_without_failures_exits_0(tmp_path):
    f = tmp_path / "ok.toml"
    f.write_text('name = "ok"\n[axes]\nmotor.torque = ["80 N m", "120 N m"]\n')
    out = tmp_path / "ok.zarr"
    r = sweep([f, "--out", out, "--evaluator", EV], tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "ok 2, failed 0, pending 0" in r.stdout and "runs failed" not in r.stderr
    again = sweep([f, "--out", out, "--evaluator", EV], tmp_path)
    assert again.returncode == 0 and _computed(again) == 0, again.stdout + again.stderr


def test_the_help_states_the_exit_status():
    r = run_geardyn(["sweep", "--help"], capture_output=True, text=True, timeout=120,
                    env={**env(), "COLUMNS": "200"})
    assert r.returncode == 0, r.stderr
    text = " ".join(r.stdout.split())
    assert "Exit status 1 if any run of the store failed" in text, text
