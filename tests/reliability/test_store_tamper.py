"""Tampered sweep stores: every damage is detected, named, and the resume repairs it exactly.

The sweep is the closed-form oscillator sweep of ``tests/sweep`` (12 runs in batches of 5:
batch 0 = runs 0-4 holds three ok runs, batch 1 = runs 5-9 one ok run). The oracle for "repaired"
is an undamaged store of the same sweep: after the resume every stored result (status, errors,
warnings, every output) equals it value for value; only the wall time and worker of recomputed
runs may differ.
"""

from __future__ import annotations

import shutil

import numpy as np
import pytest
import zarr

from geardyn.errors import DataFileError
from geardyn.studies.sweep import (
    STATUS_OK,
    open_sweep,
    parse_sweep,
    run_sweep,
    verify_store,
)
from geardyn.studies.sweep.integrity import CHECKSUM_VAR, batch_digest
from tests.sweep._evaluators import OscillatorEvaluator
from tests.sweep._procs import env
from tests.sweep.conftest import OSC_SWEEP

from .._cli_fork import run_geardyn

LIMIT = 120.0  # N m: the 150 N m runs "diverge"
RESULTS = ["status", "error", "warning", "x__amplitude", "x__static", "noise", "x__wave"]


@pytest.fixture(scope="module")
def reference(tmp_path_factory, client):
    """An undamaged store of the sweep (built once; copied by each test)."""
    out = tmp_path_factory.mktemp("ref") / "ref.zarr"
    res = run_sweep(parse_sweep(OSC_SWEEP), out, client=client,
                    evaluate=OscillatorEvaluator(torque_limit=LIMIT))
    assert (res.ok, res.failed, res.pending) == (4, 8, 0)
    return out


def _copy(reference, tmp_path):
    out = tmp_path / "s.zarr"
    shutil.copytree(reference, out)
    return out


def _assert_equal_results(out, reference):
    a, b = open_sweep(out).load(), open_sweep(reference).load()
    for name in RESULTS:
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)


def _damage(out, how: str, rng) -> int:
    """Damage the store; returns the batch damaged."""
    if how == "delete_chunk":  # an ok run's data chunk (batch 0: runs 0, 1, 4 are ok)
        (out / "x__amplitude" / "0").unlink()
        return 0
    if how == "random_bytes":
        chunk = out / "x__wave" / "1.0"
        chunk.write_bytes(rng.bytes(chunk.stat().st_size))
        return 1
    if how == "swap_one_variable":  # another batch's chunk of one variable
        shutil.copyfile(out / "x__amplitude" / "0", out / "x__amplitude" / "1")
        return 1
    if how == "swap_whole_batch":  # every chunk of batch 0, checksum and status included
        for var in out.iterdir():
            if (var / "0").is_file() and var.name != "run":
                shutil.copyfile(var / "0", var / "1")
        for src in out.glob("*/0.0"):
            shutil.copyfile(src, src.with_name("1.0"))
        return 1
    if how == "checksum_deleted":
        (out / CHECKSUM_VAR / "0").unlink()
        return 0
    raise AssertionError(how)


DAMAGES = ["delete_chunk", "random_bytes", "swap_one_variable", "swap_whole_batch",
           "checksum_deleted"]


@pytest.mark.parametrize("how", DAMAGES)
def test_damage_is_detected_named_and_repaired_by_the_resume(tmp_path, reference, client, how):
    out = _copy(reference, tmp_path)
    batch = _damage(out, how, np.random.default_rng(DAMAGES.index(how)))
    n_in_batch = 5
    # a check without computing names the batch
    check = verify_store(out)
    assert [d.batch for d in check.damaged] == [batch], check.summary()
    assert check.damaged[0].start == 5 * batch
    # reading refuses the damaged store, naming the runs
    with pytest.raises(DataFileError, match=f"batch {batch} \\(runs {5 * batch}-"):
        open_sweep(out)
    # the resume puts the batch back to pending, says so, and recomputes exactly it
    res = run_sweep(parse_sweep(OSC_SWEEP), out, client=client,
                    evaluate=OscillatorEvaluator(torque_limit=LIMIT))
    assert res.resumed and len(res.damaged) == 1 and res.damaged[0].startswith(f"batch {batch} ")
    assert (res.computed, res.skipped, res.pending) == (n_in_batch, 12 - n_in_batch, 0)
    assert verify_store(out).ok
    _assert_equal_results(out, reference)


def test_checksum_is_the_documented_digest_of_the_stored_values(reference):
    """An independent recomputation of batch 0's checksum from the values read with xarray."""
    ds = open_sweep(reference).load()
    cols = {name: ds[name].values[0:5] for name in ds.attrs["checksum_variables"]}
    assert sorted(cols) == sorted(["status", "error", "warning", "worker", "run_seconds",
                                   "x__amplitude", "x__static", "noise", "x__wave"])
    assert batch_digest(0, 5, cols) == str(ds[CHECKSUM_VAR].values[0])
    assert batch_digest(5, 10, cols) != str(ds[CHECKSUM_VAR].values[0])  # runs are part of it
    # a NaN of another bit pattern (e.g. -nan from 0/0) hashes as the one quiet NaN
    other = dict(cols, x__amplitude=np.where(np.isnan(cols["x__amplitude"]),
                                             -np.float64("nan"), cols["x__amplitude"]))
    assert batch_digest(0, 5, other) == batch_digest(0, 5, cols)


def test_missing_consolidated_metadata_is_read_around_and_rebuilt(tmp_path, reference, client):
    out = _copy(reference, tmp_path)
    (out / ".zmetadata").unlink()
    check = verify_store(out)
    assert check.ok and check.metadata == "missing"
    assert (open_sweep(out).status.values == STATUS_OK).sum() == 4
    res = run_sweep(parse_sweep(OSC_SWEEP), out, client=client,
                    evaluate=OscillatorEvaluator(torque_limit=LIMIT))
    assert res.metadata_rebuilt and res.computed == 0 and not res.damaged
    assert (out / ".zmetadata").is_file() and verify_store(out).metadata == "ok"
    (out / ".zmetadata").write_text("{ not json")  # garbage: rebuilt the same way
    res = run_sweep(parse_sweep(OSC_SWEEP), out, client=client,
                    evaluate=OscillatorEvaluator(torque_limit=LIMIT))
    assert res.metadata_rebuilt
    _assert_equal_results(out, reference)


@pytest.mark.parametrize("lost", [".zattrs", "x__amplitude/.zarray"])
def test_lost_array_metadata_is_a_clear_error(tmp_path, reference, client, lost):
    out = _copy(reference, tmp_path)
    (out / lost).unlink()
    (out / ".zmetadata").unlink()
    with pytest.raises(DataFileError, match="damaged"):
        open_sweep(out)
    with pytest.raises(DataFileError, match=r"\.zattrs|\.zarray"):
        run_sweep(parse_sweep(OSC_SWEEP), out, client=client,
                  evaluate=OscillatorEvaluator(torque_limit=LIMIT))


@pytest.mark.slow
def test_cli_verify_reports_without_computing(tmp_path, reference):
    out = _copy(reference, tmp_path)
    r = run_geardyn(["sweep", "--verify", str(out)], capture_output=True,
                    text=True, env=env(), timeout=120)
    assert r.returncode == 0 and "all match their checksums" in r.stdout, r.stdout + r.stderr
    shutil.copyfile(out / "noise" / "0", out / "noise" / "1")
    before = zarr.open_group(str(out), mode="r")["status"][:]
    r = run_geardyn(["sweep", "--verify", str(out)], capture_output=True,
                    text=True, env=env(), timeout=120)
    assert r.returncode == 1, r.stdout + r.stderr
    assert "batch 1 (runs 5-9)" in r.stderr and "Traceback" not in r.stderr
    # nothing was changed by the check
    np.testing.assert_array_equal(zarr.open_group(str(out), mode="r")["status"][:], before)
    r = run_geardyn(["sweep", "--verify", str(tmp_path)], capture_output=True,
                    text=True, env=env(), timeout=120)
    assert r.returncode == 2 and "not a Zarr store" in r.stderr and "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
