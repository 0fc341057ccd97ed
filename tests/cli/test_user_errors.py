"""User errors as user errors (issue 19, items 3 and 4, CLI side): a bad output path or a run
that would not end is refused before any work, with exit 2 and one line under 500 characters,
no traceback; the library refuses the same runs."""

from __future__ import annotations

import os
import sys

import pytest

from .._cli_fork import run_geardyn

GEARDYN = [sys.executable, "-m", "geardyn"]
PEM = ["--set", "stiffness.method=pem", "--set", "stiffness.centre_distances=6",
       "--set", "stiffness.nodes_per_segment=8"]


def run(*args, tmp_path, cwd=None):
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(tmp_path / "cache")}
    return run_geardyn(list(args), capture_output=True, text=True, env=env,
                       cwd=cwd, timeout=300)


def _one_error_line(r):
    assert r.returncode == 2, r.stdout + r.stderr
    assert "Traceback" not in r.stdout + r.stderr
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and len(lines[0]) < 500, r.stderr
    return lines[0]


def _csv(path):
    import numpy as np

    t = np.linspace(0, 1, 4000, endpoint=False)
    np.savetxt(path, np.column_stack([t, 113 * t, np.cos(23 * 113 * t)]), delimiter=",",
               header="t,angle,acc", comments="")


def _args(command, out, tmp_path):
    if command == "diagnose":
        _csv(tmp_path / "m.csv")
        return ["diagnose", str(tmp_path / "m.csv"), "--time", "t", "--angle", "angle",
                "--out", str(out)]
    return [command, "--out", str(out), *PEM]


@pytest.mark.slow
@pytest.mark.parametrize("command", ["run", "stiffness", "simulate", "diagnose"])
def test_out_that_is_an_existing_file_is_refused_first(tmp_path, command):
    out = tmp_path / "a-file"
    out.write_text("keep me")
    line = _one_error_line(run(*_args(command, out, tmp_path), tmp_path=tmp_path))
    assert f"--out {out}" in line and "an existing file" in line
    assert out.read_text() == "keep me"
    assert not (tmp_path / "cache").exists()  # nothing computed, nothing cached


def test_simulate_out_that_is_a_folder_is_refused_first(tmp_path):
    line = _one_error_line(run("simulate", "--out", str(tmp_path), *PEM, tmp_path=tmp_path))
    assert "--out" in line and "an existing folder" in line
    assert not (tmp_path / "cache").exists()


@pytest.mark.slow
@pytest.mark.parametrize("command", ["run", "stiffness", "simulate", "diagnose"])
def test_unwritable_out_is_refused_first(tmp_path, command):
    # /proc refuses new files even to root; a chmod-ed folder would not stop root
    out = "/proc/geardyn-test/out" + (".nc" if command == "simulate" else "")
    line = _one_error_line(run(*_args(command, out, tmp_path), tmp_path=tmp_path))
    assert "--out /proc/geardyn-test/out" in line and "cannot write" in line
    assert not (tmp_path / "cache").exists()


def test_out_below_a_file_is_refused_first(tmp_path):
    (tmp_path / "f").write_text("")
    line = _one_error_line(run("stiffness", "--out", str(tmp_path / "f" / "sub"), *PEM,
                               tmp_path=tmp_path))
    assert "is a file, not a folder" in line


@pytest.mark.slow
@pytest.mark.parametrize("override", [
    ["--set", "simulation.settle_time=1e6 s"],
    ["--set", "simulation.dt=1e-12 s", "--set", "simulation.decimation=1000000"],
    ["--set", "simulation.dt=1e-20 s", "--set", "simulation.settle_time=1e20 s"],
])
@pytest.mark.parametrize("command", ["simulate", "run"])
def test_runs_that_would_not_end_are_refused_first(tmp_path, command, override):
    out = tmp_path / ("s.nc" if command == "simulate" else "r")
    line = _one_error_line(run(command, "--out", str(out), *PEM, *override, tmp_path=tmp_path))
    assert "time steps" in line and "simulation.max_steps = 100,000,000 steps" in line
    assert "raise simulation.max_steps" in line
    assert not out.exists() and not (tmp_path / "cache").exists()


def test_library_refuses_before_building_anything(monkeypatch):
    """``simulate()`` checks the step count before it builds a map or a matrix; the limit is a
    case field that a user can raise."""
    import geardyn.stiffness
    from geardyn.config import paper_case
    from geardyn.dynamics import simulate
    from geardyn.dynamics.newmark import check_bounded_work
    from geardyn.errors import InputError

    def no_map(*a, **k):  # pragma: no cover - reached only if the check came too late
        raise AssertionError("a map was built before the step count was checked")

    monkeypatch.setattr(geardyn.stiffness, "build_map", no_map)
    huge = paper_case({"simulation.settle_time": "1e6 s"})
    with pytest.raises(InputError, match=r"got .100,000,100,000 time steps"):  # (1e6 + 1) / 1e-5
        simulate(huge)
    raised = paper_case({"simulation.settle_time": "1e6 s", "simulation.max_steps": 1e12,
                         "simulation.decimation": 100000})
    # (1e6 s + 1 s) / 1e-5 s, an independent count of the same steps
    assert check_bounded_work(raised) == round((1e6 + 1.0) / 1e-5)
    assert check_bounded_work(paper_case()) == round((0.5 + 1.0) / 1e-5)


def test_long_error_messages_are_cut_to_one_line(tmp_path):
    bad = "x" * 20000
    line = _one_error_line(run("geometry", "--set", f"pinion.teeth={bad}", tmp_path=tmp_path))
    assert "pinion.teeth" in line


def test_a_step_count_just_over_the_limit_is_not_rounded_onto_it():
    """1,000.5 s at 10 us is 100,050,000 steps, over the 1e8 limit: both numbers whole, so they
    differ on screen (they read "1e+08" both, a user audit of 2026-11-27)."""
    from geardyn.config import paper_case
    from geardyn.errors import InputError
    from geardyn.run_limits import check_step_count

    sim = paper_case({"simulation.record_time": "1000 s"}).simulation
    with pytest.raises(InputError) as info:
        check_step_count(sim)
    assert "got '100,050,000 time steps" in str(info.value), str(info.value)
    assert "at most simulation.max_steps = 100,000,000 steps" in str(info.value)


@pytest.mark.parametrize(("args", "start"), [
    (["sweep", "examples/faults/sweep_spall_width.toml"], "error: --out: got nothing; allowed: "),
    (["sweep"], "error: SWEEP_FILE: got nothing; allowed: "),
    (["crack-growth", "--quick"], "error: --paris-m: got nothing; allowed: required"),
])
def test_a_required_option_left_out_is_named_as_missing(tmp_path, args, start):
    """Not Python's None ("--out: got None", a user audit of 2026-11-27)."""
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    line = _one_error_line(run(*args, tmp_path=tmp_path, cwd=root))
    assert line.startswith(start), line
