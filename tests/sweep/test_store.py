"""The Zarr store and the execution machinery, with a closed-form evaluator.

The evaluator (tests/sweep/_evaluators.py) returns the steady-state amplitude of a 1-DOF
oscillator, so every stored value is checked against the formula evaluated here on a case built
independently; failures come from the real geometry code (a bore larger than the root radius) and
from a torque limit standing in for a divergence.
"""

from __future__ import annotations

import math
import pathlib

import numpy as np
import pytest
import xarray as xr
import zarr

from geardyn import paper_case
from geardyn.errors import DataFileError, InputError
from geardyn.studies.sweep import (
    STATUS_FAILED,
    STATUS_OK,
    STATUS_PENDING,
    open_sweep,
    parse_sweep,
    run_seeds,
    run_sweep,
    store_status,
)
from geardyn.studies.sweep.execute import _auto_batch

from ._evaluators import FlakyEvaluator, OscillatorEvaluator, amplitude
from .conftest import OSC_SWEEP

LIMIT = 120.0  # N m: the 150 N m runs "diverge"


def osc_sweep(text: str = OSC_SWEEP):
    return parse_sweep(text)


def result_values(ds: xr.Dataset) -> dict[str, np.ndarray]:
    """Everything that must not depend on how the sweep was executed."""
    names = ["status", "error", "x__amplitude", "x__static", "noise", "x__wave"]
    return {n: ds[n].values for n in names}


def test_zarr_local_store_publishes_chunks_by_rename(tmp_path, monkeypatch):
    """The property the crash safety rests on: a chunk write goes to a temporary file that is
    renamed over the chunk, so an interrupted write leaves the old chunk intact."""
    arr = zarr.create_array(store=str(tmp_path / "a.zarr"), shape=(4,), chunks=(4,),
                            dtype="f8", zarr_format=2)
    arr[:] = 1.0
    chunk = tmp_path / "a.zarr" / "0"
    before = chunk.read_bytes()

    def killed(self, target):  # the process dies after writing the temporary file
        raise OSError("killed before the rename")

    monkeypatch.setattr(pathlib.Path, "replace", killed)
    with pytest.raises(OSError, match="killed before the rename"):
        arr[:] = 2.0
    monkeypatch.undo()
    assert chunk.read_bytes() == before
    np.testing.assert_array_equal(zarr.open_array(str(tmp_path / "a.zarr"))[:], 1.0)


def test_values_failures_coordinates_and_attributes(tmp_path, client):
    sw = osc_sweep()
    out = tmp_path / "s.zarr"
    res = run_sweep(sw, out, client=client, evaluate=OscillatorEvaluator(torque_limit=LIMIT))
    plan = sw.plan()
    assert (res.n_runs, res.computed, res.skipped, res.pending) == (12, 12, 0, 0)
    ds = open_sweep(out).load()
    assert ds.sizes["run"] == 12
    for r in range(12):
        ov = plan.overrides(r)
        case = paper_case(ov)
        if ov["pinion.bore_radius"] > 0.06:
            assert ds.status.values[r] == STATUS_FAILED
            assert "bore_radius" in str(ds.error.values[r]) and "root radius" in str(
                ds.error.values[r])
            assert np.isnan(ds["x__amplitude"].values[r])
        elif ov["motor.torque"] > LIMIT:
            assert ds.status.values[r] == STATUS_FAILED
            assert str(ds.error.values[r]).startswith("runaway response")
        else:
            assert ds.status.values[r] == STATUS_OK and ds.error.values[r] == ""
            assert ds["x__amplitude"].values[r] == pytest.approx(amplitude(case), rel=1e-13)
            np.testing.assert_allclose(ds["x__wave"].values[r], amplitude(case) * np.sin(
                np.arange(8) * np.pi / 4), rtol=1e-12, atol=1e-20)
            rng = np.random.default_rng(int(ds.seed.values[r]))
            assert ds["noise"].values[r] == rng.standard_normal()
        assert ds["motor.torque"].values[r] == ov["motor.torque"]
        assert ds["load.speed"].values[r] == ov["load.speed"]
    assert (ds.status == STATUS_OK).sum() == 4 and res.ok == 4 and res.failed == 8
    np.testing.assert_array_equal(ds.seed.values, run_seeds(11, 12))
    assert ds["motor.torque"].attrs["units"] == "N m"
    assert ds["load.speed"].attrs["units"] == "rad/s"
    assert ds["gear.bore_radius"].attrs["linked_to"] == "pinion.bore_radius"
    assert ds["x__amplitude"].attrs == {"units": "m", "long_name": "oscillator amplitude"}
    assert ds.status.attrs["flag_meanings"] == "pending ok failed"
    assert ds.attrs["sweep_file"] == OSC_SWEEP
    assert ds.attrs["geardyn_version"] == __import__("geardyn").__version__
    assert ds.attrs["batch_size"] == 5 and len(ds.attrs["sweep_hash"]) == 32
    assert "xue_howard" in ds.attrs["base_case"]
    # one chunk per batch along `run` for every variable the workers write
    g = zarr.open_group(str(out), mode="r")
    for name in ["status", "error", "warning", "worker", "run_seconds", "x__amplitude",
                 "x__wave"]:
        assert g[name].chunks[0] == 5, name
    assert g.metadata.zarr_format == 2


def test_resume_recomputes_only_missing_runs(tmp_path, client):
    """An interrupted batch (data written, status not) and a stale temporary file: the resume
    recomputes exactly those runs, with the same values, and leaves the others alone."""
    sw = osc_sweep()
    out = tmp_path / "s.zarr"
    ev = OscillatorEvaluator(torque_limit=LIMIT)
    run_sweep(sw, out, client=client, evaluate=ev)
    reference = open_sweep(out).load()
    g = zarr.open_group(str(out), mode="r+")
    g["status"][5:10] = np.zeros(5, dtype=np.int8)  # chunk 1: killed before its status
    g["x__amplitude"][5:10] = np.full(5, 1e300)  # with half-written garbage data
    (out / "x__amplitude" / "1.0123456789abcdef0123456789abcdef.partial").write_bytes(b"junk")
    assert (store_status(out) == STATUS_PENDING).sum() == 5
    res = run_sweep(sw, out, client=client, evaluate=ev)
    assert (res.computed, res.skipped, res.tasks, res.resumed) == (5, 7, 1, True)
    ds = open_sweep(out).load()
    for k, v in result_values(reference).items():
        np.testing.assert_array_equal(ds[k].values, v, err_msg=k)
    # the runs outside chunk 1 were not recomputed: their timings are untouched
    keep = np.r_[0:5, 10:12]
    np.testing.assert_array_equal(ds.run_seconds.values[keep],
                                  reference.run_seconds.values[keep])
    assert not list(out.rglob("*.partial"))
    # nothing left to do: no cluster needed
    again = run_sweep(sw, out, evaluate=ev)
    assert (again.computed, again.tasks, again.workers) == (0, 0, 0)


def test_torn_status_chunk_counts_as_pending(tmp_path, client):
    sw = osc_sweep()
    out = tmp_path / "s.zarr"
    ev = OscillatorEvaluator(torque_limit=LIMIT)
    run_sweep(sw, out, client=client, evaluate=ev)
    reference = open_sweep(out).load()
    (out / "status" / "2").write_bytes(b"\x28\xb5\x2f")  # a truncated compressed chunk
    st = store_status(out)
    assert (st[10:] == STATUS_PENDING).all() and (st[:10] != STATUS_PENDING).all()
    res = run_sweep(sw, out, client=client, evaluate=ev)
    assert res.computed == 2
    ds = open_sweep(out).load()
    for k, v in result_values(reference).items():
        np.testing.assert_array_equal(ds[k].values, v, err_msg=k)


def test_verify_names_torn_and_lost_status_chunks_and_a_damaged_plan(tmp_path, client):
    """A user audit (2026-11-27): a truncated or deleted status chunk and a truncated or edited
    swept-value column all passed --verify as "ok"; the column then read back as garbage."""
    import shutil

    from geardyn.studies.sweep import verify_store

    sw = osc_sweep()
    ref = tmp_path / "ref.zarr"
    ev = OscillatorEvaluator(torque_limit=LIMIT)
    run_sweep(sw, ref, client=client, evaluate=ev)
    assert verify_store(ref).ok and verify_store(ref).plan == "ok"

    torn = tmp_path / "torn.zarr"
    shutil.copytree(ref, torn)
    (torn / "status" / "1").write_bytes(b"\x28\xb5\x2f")
    check = verify_store(torn)
    assert not check.ok and [(d.start, d.stop) for d in check.damaged] == [(5, 10)]
    assert "the status chunk cannot be read" in check.summary()

    lost = tmp_path / "lost.zarr"
    shutil.copytree(ref, lost)
    (lost / "status" / "0").unlink()
    check = verify_store(lost)
    assert not check.ok and "the status chunk was lost" in check.summary()

    for name, damage in (("motor.torque", "truncate"), ("seed", "edit")):
        bad = tmp_path / f"{name}.zarr"
        shutil.copytree(ref, bad)
        if damage == "truncate":
            (bad / name / "0").write_bytes((bad / name / "0").read_bytes()[:10])
        else:
            import zarr

            zarr.open_group(str(bad), mode="r+")[name][0] = 999
        check = verify_store(bad)
        assert not check.ok and check.plan != "ok", name
        assert "the plan is damaged" in check.summary()
        with pytest.raises(DataFileError, match="damaged plan"):
            run_sweep(sw, bad, client=client, evaluate=ev)
        with pytest.raises(DataFileError, match="the plan is damaged"):
            open_sweep(bad)


def test_verify_counts_the_pending_runs(tmp_path, client):
    import zarr

    from geardyn.studies.sweep import verify_store

    out = tmp_path / "s.zarr"
    run_sweep(osc_sweep(), out, client=client, evaluate=OscillatorEvaluator(torque_limit=LIMIT))
    g = zarr.open_group(str(out), mode="r+")
    g["status"][10:] = 0
    g["batch_checksum"][2] = ""  # as before the batch was written
    check = verify_store(out)
    assert check.ok and check.pending == 2 and check.summary().endswith("2 run(s) pending")


def test_failed_runs_stay_recorded_unless_retry_failed(tmp_path, client):
    marker = tmp_path / "flaky"
    marker.write_text("")
    sw = osc_sweep(OSC_SWEEP.replace('"70 mm"', '"30 mm"'))
    out = tmp_path / "s.zarr"
    ev = FlakyEvaluator(str(marker))
    first = run_sweep(sw, out, client=client, evaluate=ev)
    assert (first.ok, first.failed) == (0, 12)
    assert set(open_sweep(out).error.values) == {
        "RuntimeError: transient failure (marker present)"}
    marker.unlink()
    again = run_sweep(sw, out, client=client, evaluate=ev)
    assert (again.computed, again.failed) == (0, 12)
    retried = run_sweep(sw, out, client=client, evaluate=ev, retry_failed=True)
    assert (retried.computed, retried.ok, retried.failed) == (12, 12, 0)
    ds = open_sweep(out).load()
    assert (ds.error.values == "").all()
    plan = sw.plan()
    np.testing.assert_allclose(ds["x__amplitude"].values,
                               [amplitude(paper_case(plan.overrides(r))) for r in range(12)],
                               rtol=1e-13)


def test_another_sweep_in_the_store_is_refused_unless_force(tmp_path, client):
    out = tmp_path / "s.zarr"
    ev = OscillatorEvaluator(torque_limit=LIMIT)
    run_sweep(osc_sweep(), out, client=client, evaluate=ev)
    other = osc_sweep(OSC_SWEEP.replace("seed = 11", "seed = 12"))
    with pytest.raises(InputError) as info:
        run_sweep(other, out, client=client, evaluate=ev)
    assert info.value.field == "--out" and "--force" in str(info.value)
    # what changed is named (it said only "another definition or geardyn version")
    assert "changed: seed: 11 -> 12" in info.value.allowed, info.value.allowed
    res = run_sweep(other, out, client=client, evaluate=ev, force=True)
    assert res.computed == 12 and not res.resumed
    assert open_sweep(out).attrs["seed"] == 12
    plain = tmp_path / "plain"
    plain.mkdir()
    (plain / "notes.txt").write_text("mine")
    with pytest.raises(DataFileError, match="not a Zarr store"):
        run_sweep(other, plain, client=client, evaluate=ev, force=True)
    assert (plain / "notes.txt").read_text() == "mine"


def test_force_keeps_the_old_store_until_the_new_one_exists(tmp_path, client, monkeypatch):
    """A --force sweep interrupted before its store was created had already deleted the old one
    (a user audit, 2026-11-27): the old store is set aside and put back."""
    import geardyn.studies.sweep.execute as execute

    out = tmp_path / "s.zarr"
    ev = OscillatorEvaluator(torque_limit=LIMIT)
    run_sweep(osc_sweep(), out, client=client, evaluate=ev)
    before = result_values(open_sweep(out).load())
    other = osc_sweep(OSC_SWEEP.replace("seed = 11", "seed = 12"))

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(execute, "_create_store", interrupted)
    with pytest.raises(KeyboardInterrupt):
        run_sweep(other, out, client=client, evaluate=ev, force=True)
    ds = open_sweep(out).load()
    assert ds.attrs["seed"] == 11
    for k, v in result_values(ds).items():
        np.testing.assert_array_equal(v, before[k])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.zarr"]  # nothing set aside left
    monkeypatch.undo()
    res = run_sweep(other, out, client=client, evaluate=ev, force=True)
    assert res.computed == 12 and open_sweep(out).attrs["seed"] == 12
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.zarr"]


def test_a_store_another_sweep_is_writing_is_refused(tmp_path, client):
    """Two commands on one store both computed every pending run (a user audit, 2026-11-27):
    the second is refused while the first holds the store's lock, and runs once it is gone."""
    from filelock import FileLock

    out = tmp_path / "s.zarr"
    ev = OscillatorEvaluator(torque_limit=LIMIT)
    held = FileLock(str(tmp_path / ".s.zarr.lock"))
    held.acquire()
    try:
        with pytest.raises(InputError, match="another sweep is writing this one now"):
            run_sweep(osc_sweep(), out, client=client, evaluate=ev)
    finally:
        held.release()
    assert not out.exists()
    assert run_sweep(osc_sweep(), out, client=client, evaluate=ev).computed == 12


def test_auto_batch_size_and_unstack(tmp_path, client):
    assert _auto_batch(0.3, 1.0, 1000, 2) == 4  # ceil(1 / 0.3) runs make a task of >= 1 s
    assert _auto_batch(0.01, 1.0, 1000, 2) == 100
    assert _auto_batch(0.01, 1.0, 30, 2) == 15  # but every worker gets a task
    assert _auto_batch(0.15, 1.0, 16, 2) == 4  # 4 tasks of 4, not 6 + 6 + 4 on 2 workers
    assert _auto_batch(5.0, 1.0, 30, 2) == 1
    text = OSC_SWEEP.replace("batch_size = 5", 'batch_size = "auto"\ntask_seconds = 0.2')
    text = text.split("[sample]")[0] + "[execution]" + text.split("[execution]")[1]
    out = tmp_path / "s.zarr"
    res = run_sweep(parse_sweep(text), out, client=client,
                    evaluate=OscillatorEvaluator(sleep=0.05))
    # the pilot times a run at >= 0.05 s, so at most ceil(0.2 / 0.05) = 4 runs per task
    assert 1 <= res.batch_size <= 4 and res.tasks == math.ceil(6 / res.batch_size)
    grid = open_sweep(out, unstack=True)
    assert dict(grid["x__amplitude"].sizes) == {"motor.torque": 3, "pinion.bore_radius": 2}
    assert open_sweep(out, only_ok=True).sizes["run"] == 3


@pytest.mark.parametrize("in_a_loop", [False, True])
def test_a_batch_rewritten_whole_or_in_part_keeps_its_checksum(tmp_path, client, in_a_loop):
    """``_write_batch`` writes a batch's chunks through zarr's asynchronous API on an event
    loop of its own: from a plain thread (a Dask task) and from inside a running loop (which
    it must not reuse), a whole batch and a part of one store the given values, keep the
    other runs, and leave a checksum that verifies."""
    import asyncio

    from geardyn.studies.sweep.store import RunRecord, _outputs_from_store, _write_batch

    sw = osc_sweep()
    out = tmp_path / "s.zarr"
    run_sweep(sw, out, client=client, evaluate=OscillatorEvaluator(torque_limit=LIMIT))
    before = open_sweep(out).load()
    outputs = _outputs_from_store(out)

    def record(r: int, value: float) -> RunRecord:
        values = {o.name: np.full(o.shape, value + r) for o in outputs}
        return RunRecord(STATUS_OK, values, "", "rewritten", 0.5, "test:1")

    whole = {r: record(r, 1000.0) for r in range(5, 10)}  # batch 1: runs 5-9
    part = {10: record(10, 2000.0)}  # batch 2 has runs 10 and 11: only run 10

    def write() -> None:
        _write_batch(str(out), 5, 10, whole, outputs, 5)
        _write_batch(str(out), 10, 12, part, outputs, 5)

    if in_a_loop:
        async def main() -> None:
            write()

        asyncio.run(main())
    else:
        write()
    after = open_sweep(out, verify=True).load()  # verify: every batch's checksum holds
    for name in ("x__amplitude", "x__static", "x__wave", "noise"):
        old, new = before[name].values, after[name].values
        np.testing.assert_array_equal(new[:5], old[:5])  # batch 0 untouched
        for r in range(5, 10):
            np.testing.assert_array_equal(new[r], np.full(old.shape[1:], 1000.0 + r))
        np.testing.assert_array_equal(new[10], np.full(old.shape[1:], 2010.0))
        np.testing.assert_array_equal(new[11], old[11])  # the run not rewritten is kept
    assert list(after.status.values[5:11]) == [STATUS_OK] * 6
    assert after.status.values[11] == before.status.values[11]
    assert list(after.warning.values[5:11]) == ["rewritten"] * 6
    assert list(after.worker.values[5:11]) == ["test:1"] * 6
    np.testing.assert_array_equal(after.run_seconds.values[5:11], 0.5)
    assert after.warning.values[11] == before.warning.values[11]


def test_a_store_created_again_at_the_same_path_is_opened_afresh(tmp_path, client):
    """The arrays ``_write_batch`` keeps open between batches belong to one version of the
    store: after the store is deleted and created again with another batch size, a write goes
    to the new chunks (a stale array would write chunks of 5 runs where the store has 4)."""
    import shutil

    from geardyn.studies.sweep.store import RunRecord, _outputs_from_store, _write_batch

    out = tmp_path / "s.zarr"
    ev = OscillatorEvaluator(torque_limit=LIMIT)
    run_sweep(osc_sweep(), out, client=client, evaluate=ev)  # batch_size 5
    outputs = _outputs_from_store(out)

    def records(runs, value: float) -> dict:
        return {r: RunRecord(STATUS_OK, {o.name: np.full(o.shape, value + r) for o in outputs},
                             "", "rewritten", 0.5, "test:1") for r in runs}

    _write_batch(str(out), 5, 10, records(range(5, 10), 1000.0), outputs, 5)
    assert open_sweep(out, verify=True).load()["x__amplitude"].values[7] == 1007.0
    shutil.rmtree(out)
    run_sweep(osc_sweep(OSC_SWEEP.replace("batch_size = 5", "batch_size = 4")), out,
              client=client, evaluate=ev)
    before = open_sweep(out).load()
    assert before.attrs["batch_size"] == 4
    _write_batch(str(out), 4, 8, records(range(4, 8), 3000.0), outputs, 4)
    after = open_sweep(out, verify=True).load()
    for name in ("x__amplitude", "x__wave"):
        for r in range(12):
            want = np.full(before[name].shape[1:], 3000.0 + r) if 4 <= r < 8 else \
                before[name].values[r]
            np.testing.assert_array_equal(after[name].values[r], want, err_msg=f"{name}[{r}]")
    assert list(after.warning.values[4:8]) == ["rewritten"] * 4
