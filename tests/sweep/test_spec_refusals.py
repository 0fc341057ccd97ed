"""Configuration errors that every run would meet are refused when the sweep file is loaded.

Oracles: the record variables of the two models (``x_p`` only in the transverse one), and the
revolutions a record spans, ``record_time * load.speed / 2 pi`` (the paper case's 114.14 rad/s:
0.03 s spans 0.545 revolutions, 2 revolutions take 0.110 s).
"""

from __future__ import annotations

import math
import os
import textwrap
import warnings

import pytest

from geardyn import paper_case
from geardyn.errors import GeardynError, InputError
from geardyn.studies.sweep import evaluate_run, parse_sweep

from .._cli_fork import run_geardyn

W = 114.14  # the paper case's load.speed [rad/s]
TWO_REVS = f"{2 * 2 * math.pi / W:.3g} s"  # '0.11 s'


def sweep(body: str):
    return parse_sweep('name = "r"\n' + textwrap.dedent(body))


def refused(body: str) -> InputError:
    with pytest.raises(InputError) as info:
        sweep(body)
    assert "\n" not in str(info.value)
    return info.value


AXIS = '[axes]\nmotor.torque = ["50 N m", "60 N m"]\n'


def refused_to_run(body: str) -> InputError:
    """A sweep file that loads (a study's own evaluator may take short records) but that the
    standard evaluator refuses before any run (``run_sweep`` calls ``check_runnable``)."""
    from geardyn.studies.sweep.spec import check_runnable

    loaded = sweep(body)
    with pytest.raises(InputError) as info:
        check_runnable(loaded)
    assert "\n" not in str(info.value)
    return info.value


def runnable(body: str):
    from geardyn.studies.sweep.spec import check_runnable

    loaded = sweep(body)
    check_runnable(loaded)
    return loaded


def test_unknown_and_absent_signals_are_refused_naming_them():
    e = refused(AXIS + '[store]\nsignals = ["v_yg", "foo"]\n')
    assert e.field == "store.signals" and e.value == ["foo"]
    assert "v_yg" in e.allowed and "centre_distance_change" in e.allowed
    e = refused(AXIS + '[store]\nsignals = ["vyg"]\n')
    assert e.value == ["vyg"] and "did you mean 'v_yg'" in e.allowed
    # a transverse-model signal where every run is 6-DOF
    e = refused(AXIS + '[store]\nsignals = ["v_yg", "x_p"]\n')
    assert e.field == "store.signals" and e.value == ["x_p"] and "transverse" in e.allowed
    # ... but accepted when some runs are transverse, and every record signal is known
    assert sweep('[axes]\nsimulation.dynamics = ["6-dof", "transverse"]\n'
                 '[store]\nsignals = ["v_yg", "x_p", "centre_distance_change"]\n').n_runs == 2


@pytest.mark.parametrize("body, field, value, spans", [
    ('[set]\nsimulation.record_time = "0.03 s"\n' + AXIS,
     "set.simulation.record_time", "0.03 s", 0.545),
    ('[axes]\nsimulation.record_time = ["0.5 s", "0.03 s"]\n',
     "axes.simulation.record_time[1]", "0.03 s", 0.545),
    ('[sample]\nmethod = "lhs"\nn = 2\n[sample.dimensions]\n'
     'simulation.record_time = { low = "0.02 s", high = "0.5 s" }\n',
     "sample.dimensions.simulation.record_time.low", "0.02 s", 0.363),
    ('[axes]\nsimulation.settle_time = ["0.01 s", "0.2 s"]\n'
     '[link]\nsimulation.record_time = "simulation.settle_time"\n',
     "link.simulation.record_time", "0.01 s", 0.182),
])
def test_a_record_shorter_than_a_revolution_is_refused(body, field, value, spans):
    e = refused_to_run(body)
    assert e.field == field and e.value == value
    assert f"at least {TWO_REVS}" in e.allowed and "load.speed = 114.14 rad/s" in e.allowed
    assert f"spans {spans:.3g} revolutions" in e.allowed


def test_the_lowest_swept_speed_counts_and_longer_records_pass():
    e = refused_to_run('[set]\nsimulation.record_time = "0.1 s"\n'
                       '[axes]\nload.speed = ["114.14 rad/s", "20 rad/s"]\n')
    assert e.field == "set.simulation.record_time" and e.value == "0.1 s"
    assert "load.speed = 20 rad/s (the lowest in the sweep)" in e.allowed
    assert f"at least {2 * 2 * math.pi / 20:.3g} s" in e.allowed
    # 1.45 revolutions: refused only when sure to fail (it may hold a whole revolution)
    assert runnable('[set]\nsimulation.record_time = "0.08 s"\n' + AXIS).n_runs == 2
    # a speed the case does not fix (a given load coefficient): left to the runs
    assert runnable('[set]\nsimulation.record_time = "0.03 s"\nload.coefficient = 0.8761\n'
                    + AXIS).n_runs == 2
    # the file itself loads: a study's own evaluator (no TSA) may take a short record
    assert sweep('[set]\nsimulation.record_time = "0.03 s"\n' + AXIS).n_runs == 2


def test_a_short_run_says_it_in_the_sweeps_terms():
    case = paper_case({"simulation.record_time": 0.03, "simulation.settle_time": 0.0,
                       "stiffness.method": "pem", "stiffness.centre_distances": 6,
                       "stiffness.nodes_per_segment": 6})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(GeardynError) as info:
            evaluate_run(case)
    msg = str(info.value)
    assert msg.startswith("simulation.record_time = 0.03 s: too short"), msg
    assert "spans 0.545 revolutions" in msg
    assert f"simulate at least {TWO_REVS}" in msg
    assert "x: got" not in msg


@pytest.mark.parametrize("args, words", [
    (["--set", "simulation.record_time=0.03 s"], ["--set simulation.record_time: got '0.03 s'",
                                                  f"at least {TWO_REVS}"]),
    ([], ["store.signals", "['foo']"]),
])
def test_cli_refuses_before_any_run(tmp_path, args, words):
    from ._procs import env

    f = tmp_path / "s.toml"
    f.write_text('[set]\nstiffness.method = "pem"\nsimulation.record_time = "0.2 s"\n' + AXIS
                 + ('[store]\nsignals = ["v_yg", "foo"]\n' if not args else ""))
    r = run_geardyn(["sweep", str(f), "--out", str(tmp_path / "o.zarr"), *args],
                    capture_output=True, text=True, env=env(), timeout=300)
    assert r.returncode == 2, r.stderr
    assert "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    for w in words:
        assert w in r.stderr, (w, r.stderr)
    assert not (tmp_path / "o.zarr").exists()  # no store: nothing started


def test_the_local_cluster_does_not_ask_for_port_8787(recwarn):
    import socket

    from geardyn.studies.sweep.execute import _dask_client

    busy = socket.socket()
    environ = dict(os.environ)  # distributed's nanny writes its pre-spawn variables here
    try:
        try:
            busy.bind(("", 8787))
            busy.listen()
        except OSError:
            pass  # already taken by another program: the same situation
        with _dask_client(None, 1, None) as cl:
            assert cl.scheduler_info()["workers"] is not None
    finally:
        busy.close()
    # and the cluster's closing put back this process's environment (OMP_NUM_THREADS,
    # PYTHONHASHSEED...: a notebook's later subprocesses; here, the later CLI tests' forks)
    assert dict(os.environ) == environ
    texts = [str(w.message) for w in recwarn.list]
    assert not [t for t in texts if "already in use" in t], texts


def test_a_demodulation_band_no_run_can_use_is_refused():
    # the paper's pinion, 23 teeth, harmonic 5: the band 115 +/- B (B < 23, inside 1..1023)
    e = refused('[set]\ndiagnostics.bandwidth = 200\n' + AXIS)
    assert e.field == "set.diagnostics.bandwidth" and e.value == 200
    assert "inside orders 1..1023" in e.allowed and "pinion.teeth = 23" in e.allowed
    e = refused('[set]\ndiagnostics.bandwidth = 30\n' + AXIS)
    assert e.field == "set.diagnostics.bandwidth" and "less than the tooth count 23" in e.allowed
    assert sweep('[set]\ndiagnostics.bandwidth = 12\n' + AXIS).n_runs == 2  # a warning only
