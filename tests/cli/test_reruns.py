"""Running a command twice into the same output just works; different inputs are refused in
those words (issue 13: re-running and resuming).

Each output records the identity of its inputs (``inputs.json`` in a folder, the
``geardyn_inputs`` attribute of a ``simulate`` record); a re-run compares it. Cache use is read
from the record's cache-hit counts, never from wall time.
"""

from __future__ import annotations

import json
import os
import re
import sys

import numpy as np
import pytest

from .._cli_fork import run_geardyn

GEARDYN = [sys.executable, "-m", "geardyn"]
SMALL = ["--set", "stiffness.centre_distances=6", "--set", "stiffness.nodes_per_segment=8"]
SHORT_SIM = ["--set", "simulation.settle_time=0.002", "--set", "simulation.record_time=0.004",
             "--stiffness", "pem", *SMALL]
RUN = ["--quick", "--stiffness", "pem", "--set", "simulation.record_time=0.2 s",
       "--set", "simulation.settle_time=0.05 s", "--set", "stiffness.centre_distances=11",
       "--set", "diagnostics.samples_per_rev=1024"]


def run(*args, cache, cwd=None, **extra_env):
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(cache), **extra_env}
    return run_geardyn(list(args), capture_output=True, text=True, env=env,
                       cwd=cwd, timeout=1200)


def _one_error_line(r):
    assert r.returncode == 2, r.stdout + r.stderr
    assert "Traceback" not in r.stdout + r.stderr
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and len(lines[0]) < 500, r.stderr
    return lines[0]


@pytest.mark.slow
@pytest.mark.timeout(3600)  # two runs of the pipeline; minutes each on a loaded 2-core machine
def test_run_twice_in_the_default_folder_then_other_inputs_refused(tmp_path):
    """The README's command twice in a row in one folder: the second run exits 0 and takes every
    stiffness map and simulation from the cache (the record says so); other inputs into the same
    default folder are refused, naming the default folder (not --out) and what differs."""
    cache = tmp_path / "cache"
    first = run("run", *RUN, cache=cache, cwd=tmp_path, GEARDYN_PROGRESS="1", COLUMNS="80")
    assert first.returncode == 0, first.stderr
    # progress: one bar per stage, each ending on its own full count, no line over 80 columns
    bars = [ln for ln in re.split(r"[\r\n]", re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", first.stderr))
            if "━" in ln]
    assert bars and all(len(ln) <= 80 for ln in bars)
    final = {ln.split("━")[0].strip(): ln.split("━")[-1].split()[0] for ln in bars}
    # every bar ends on its own full count
    assert all(v.split("/")[0] == v.split("/")[-1] for v in final.values()), final
    assert {"run: stiffness (healthy)", "run: stiffness (cracked)", "run: report",
            "run: simulation", "run: diagnostics"} <= set(final)
    out = tmp_path / "geardyn-out"
    rec1 = json.loads((out / "inputs.json").read_text())
    # on a cold cache every simulation is built: the simulation stage's (models I, II, I-static
    # and the paper's time-step check) and the measurement stage's (with tooth errors)
    n_sims = rec1["cache"]["simulation"]["built"]
    assert rec1["cache"]["simulation"]["hits"] == 0
    assert n_sims >= int(final["run: simulation"].split("/")[1]) >= 5
    assert rec1["complete"] is True and rec1["identity"]["command"] == "run"
    report = (out / "report.html").read_bytes()
    second = run("run", *RUN, cache=cache, cwd=tmp_path)
    assert second.returncode == 0, second.stderr
    # complete results of the same inputs: up to date, nothing recomputed or rewritten, and the
    # same summary printed
    assert "up to date (same inputs" in second.stderr and "--force recomputes" in second.stderr
    assert (out / "report.html").read_bytes() == report
    assert json.loads((out / "inputs.json").read_text()) == rec1
    assert "validation against the paper" in second.stdout and "report.html" in second.stdout
    # a result file removed: the run is repeated (from the cache)
    (out / "report.html").unlink()
    third = run("run", *RUN, cache=cache, cwd=tmp_path)
    assert third.returncode == 0, third.stderr
    assert "same inputs" in third.stderr and (out / "report.html").is_file()
    rec2 = json.loads((out / "inputs.json").read_text())
    assert rec2["complete"] is True
    assert rec2["cache"]["stiffness"] == {"hits": 2, "built": 0}
    assert rec2["cache"]["simulation"]["built"] == 0
    assert n_sims >= rec2["cache"]["simulation"]["hits"] >= int(final["run: simulation"].split("/")[1])
    a = json.loads((out / "summary.json").read_text())
    assert a["complete"] is True
    other = run("run", *RUN, "--set", "simulation.record_time=0.25 s", cache=cache, cwd=tmp_path)
    line = _one_error_line(other)
    assert "the default output folder geardyn-out holds results of different inputs" in line
    assert "simulation.record_time 0.2 -> 0.25" in line
    assert not line.startswith("error: --out")
    # --force keeps its meaning
    assert "--force" in line
    # a run stopped by an input only its simulation stage checks (the time step against the
    # map's mesh stiffness), after the geometry and the maps were written: its folder holds
    # partial results of refused inputs, and the corrected command replaces them without --force
    bad = run("run", *RUN, "--set", "simulation.dt=1e-3 s", "--out", "bad", cache=cache,
              cwd=tmp_path)
    line = _one_error_line(bad)
    assert "simulation.dt" in line
    assert (tmp_path / "bad" / "stiffness_healthy.nc").is_file()  # written before the refusal
    rec_bad = json.loads((tmp_path / "bad" / "inputs.json").read_text())
    assert rec_bad["complete"] is False and "simulation.dt" in rec_bad["input_error"]
    fixed = run("run", *RUN, "--out", "bad", cache=cache, cwd=tmp_path)
    assert fixed.returncode == 0, fixed.stderr
    assert "stopped on an input error: replacing its partial results" in fixed.stderr
    rec_fixed = json.loads((tmp_path / "bad" / "inputs.json").read_text())
    assert rec_fixed["complete"] is True and "input_error" not in rec_fixed
    assert rec_fixed["identity"] == rec2["identity"]


def test_folder_with_unrecorded_results_is_refused(tmp_path):
    out = tmp_path / "old"
    out.mkdir()
    (out / "summary.json").write_text("{}")
    r = run("run", "--out", str(out), *RUN, cache=tmp_path / "c")
    line = _one_error_line(r)
    assert f"--out {out} holds earlier results (summary.json) whose inputs are not recorded" in line
    assert not (out / "inputs.json").exists()


@pytest.mark.slow
def test_stiffness_twice_into_one_folder_uses_the_cache(tmp_path):
    out = tmp_path / "k"
    cache = tmp_path / "c"
    r1 = run("stiffness", "--method", "pem", "--out", str(out), *SMALL, cache=cache)
    assert r1.returncode == 0, r1.stderr
    assert json.loads((out / "inputs.json").read_text())["cache"]["stiffness"] == \
        {"hits": 0, "built": 2}
    r2 = run("stiffness", "--method", "PEM", "--out", str(out), *SMALL, cache=cache)
    assert r2.returncode == 0, r2.stderr
    rec = json.loads((out / "inputs.json").read_text())
    assert rec["complete"] is True and rec["cache"]["stiffness"] == {"hits": 2, "built": 0}
    r3 = run("stiffness", "--method", "pem", "--out", str(out), *SMALL,
             "--set", "crack.depth=3mm", cache=cache)
    line = _one_error_line(r3)
    assert f"--out {out} holds results of different inputs (crack.depth" in line


@pytest.mark.slow
def test_simulate_twice_is_up_to_date_and_other_inputs_are_refused(tmp_path):
    out = tmp_path / "s.nc"
    cache = tmp_path / "c"
    r1 = run("simulate", "-o", str(out), *SHORT_SIM, cache=cache)
    assert r1.returncode == 0, r1.stderr
    before = (out.stat().st_ino, out.stat().st_mtime_ns)
    r2 = run("simulate", "-o", str(out), *SHORT_SIM, cache=cache)
    assert r2.returncode == 0, r2.stderr
    assert "up to date" in r2.stderr and "model II" in r2.stdout
    assert (out.stat().st_ino, out.stat().st_mtime_ns) == before  # not rewritten
    r3 = run("simulate", "-o", str(out), "--model", "i", *SHORT_SIM, cache=cache)
    line = _one_error_line(r3)
    assert "holds results of different inputs (simulation.model 'II' -> 'I')" in line
    r4 = run("simulate", "-o", str(out), "--model", "i", "--force", *SHORT_SIM, cache=cache)
    assert r4.returncode == 0, r4.stderr


def test_simulate_refuses_a_foreign_file(tmp_path):
    out = tmp_path / "mine.nc"
    out.write_bytes(b"not a record")
    r = run("simulate", "-o", str(out), *SHORT_SIM, cache=tmp_path / "c")
    line = _one_error_line(r)
    assert "not a geardyn record" in line
    assert out.read_bytes() == b"not a record"


def _write_csv(path, seed):
    t = np.linspace(0, 2, 40000, endpoint=False)
    th = 2 * np.pi * 18 * t
    x = np.cos(115 * th) + 0.01 * np.random.default_rng(seed).standard_normal(t.size)
    np.savetxt(path, np.column_stack([t, th, x]), delimiter=",", header="t,angle,acc",
               comments="")


@pytest.mark.slow
def test_diagnose_defaults_beside_each_input_and_reruns(tmp_path):
    """Two files diagnosed one after the other each get their own folder (today the second is
    refused: both went to geardyn-out/diagnose); the same command twice just works."""
    cache = tmp_path / "c"
    opts = ["--time", "t", "--angle", "angle", "--signal", "acc", "--no-figures",
            "--set", "diagnostics.samples_per_rev=256"]
    for name, seed in (("a.csv", 1), ("b.csv", 2)):
        _write_csv(tmp_path / name, seed)
        r = run("diagnose", str(tmp_path / name), *opts, cache=cache, cwd=tmp_path)
        assert r.returncode == 0, r.stderr
        stem = name.removesuffix(".csv")
        assert (tmp_path / f"{stem}-diagnose" / "metrics.json").exists()
    again = run("diagnose", str(tmp_path / "a.csv"), *opts, cache=cache, cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    # the same folder for another file's results is refused
    into_a = run("diagnose", str(tmp_path / "b.csv"), "--out", str(tmp_path / "a-diagnose"),
                 *opts, cache=cache)
    line = _one_error_line(into_a)
    assert "holds results of different inputs (FILE " in line and "a.csv -> " in line, line


def test_only_an_input_error_marks_a_folder_replaceable(tmp_path):
    """``input_errors_recorded``: an input error marks the record, so that other inputs replace
    the folder ("retry"); a crash or a Ctrl-C leaves it as it was (the same command continues,
    other inputs are refused)."""
    from geardyn.cli._outputs import (
        OutputInUse,
        OutputTarget,
        claim_folder,
        identity,
        input_errors_recorded,
    )
    from geardyn.config import paper_case
    from geardyn.errors import InputError

    target = OutputTarget(tmp_path / "out", True)
    a = identity("run", paper_case(), {"quick": True})
    b = identity("run", paper_case().with_overrides({"motor.torque": 80.0}), {"quick": True})
    for exc, marked in ((InputError("simulation.dt", 1e-3, "a smaller step"), True),
                        (RuntimeError("a crash"), False), (KeyboardInterrupt(), False)):
        assert claim_folder(target, a, force=True, results=["summary.json"]) in ("new",
                                                                                "again",
                                                                                "continue")
        with pytest.raises(type(exc)), input_errors_recorded(target, a):
            raise exc
        record = json.loads((target.path / "inputs.json").read_text())
        assert ("input_error" in record) is marked, (exc, record)
        assert claim_folder(target, a, force=False, results=["summary.json"]) == "continue"
        if marked:
            assert "simulation.dt" in record["input_error"]
            with pytest.raises(type(exc)), input_errors_recorded(target, a):
                raise exc  # the same command fails the same way: still replaceable
            assert claim_folder(target, b, force=False, results=["summary.json"]) == "retry"
            # b's run now holds the folder: a's inputs are refused again
            with pytest.raises(OutputInUse):
                claim_folder(target, a, force=False, results=["summary.json"])
            claim_folder(target, a, force=True, results=["summary.json"])
        else:
            with pytest.raises(OutputInUse):
                claim_folder(target, b, force=False, results=["summary.json"])


def test_different_faults_are_named_key_by_key():
    """A list of tables (``faults``) is compared entry by entry and key by key, the fault's type
    first: the refusal names what differs instead of cutting it out of a long repr (a user
    audit, 2026-11-27: ``faults [{'type': 'spall',...one, 'law': None}] -> [{'type':
    'breakag...one, 'law': None}]``)."""
    from pathlib import Path

    from geardyn.cli._outputs import differences, identity
    from geardyn.config import load_case

    examples = Path(__file__).resolve().parents[2] / "examples" / "faults"
    spall = identity("run", load_case(examples / "spall.toml"), {"quick": True})
    breakage = identity("run", load_case(examples / "breakage.toml"), {"quick": True})
    diff = [d for d in differences(spall, breakage) if d.startswith("faults")]
    assert diff[0] == "faults[0].type 'spall' -> 'breakage'", diff
    assert "faults[0].height (none) -> 0.002" in diff, diff
    assert not any("..." in d or "{" in d for d in diff), diff
    # a fault added: its set values, not a repr of a dict
    no_fault = identity("run", load_case(examples / "spall.toml").with_overrides({"faults": []}),
                        {"quick": True})
    (added,) = [d for d in differences(no_fault, spall) if d.startswith("faults")]
    assert added.startswith("faults[0] (none) -> type = 'spall', gear = 'pinion'"), added


def test_a_fault_added_to_the_case_file_is_not_up_to_date(tmp_path):
    """The same case file edited to add a ``[[faults]]`` table: the earlier record is of other
    inputs (the identity leaves an empty fault list out, so the key was on one side only and was
    taken for another geardyn version's field: ``simulate`` said "up to date", 2026-11-27)."""
    case = tmp_path / "case.toml"
    base = ('extends = "xue_howard"\n[stiffness]\nmethod = "pem"\ncentre_distances = 6\n'
            'nodes_per_segment = 8\n[simulation]\nrecord_time = "0.004 s"\n'
            'settle_time = "0.002 s"\n')
    case.write_text(base)
    first = run("simulate", "-c", str(case), "-o", "x.nc", cache=tmp_path / "c", cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    case.write_text(base + '[[faults]]\ntype = "spall"\ntooth = 11\nstart = "20 mm"\n'
                           'length = "3 mm"\nwidth = "6 mm"\ndepth = "0.1 mm"\n')
    line = _one_error_line(run("simulate", "-c", str(case), "-o", "x.nc", cache=tmp_path / "c",
                               cwd=tmp_path))
    assert "holds results of different inputs (faults[0] (none) -> type = 'spall'" in line, line
