"""``claim_file`` and ``recorded_inputs`` (the one-file outputs of ``static-te`` and ``measure``)
case by case, written against the mutants that survived a mutation run of
``geardyn.cli._outputs``: the end-to-end re-run tests never pass ``--force`` with the same
inputs, nor ``--force`` over a lone companion file.

The oracle is the rule in the docstring, in words: up to date (True) only for the same inputs,
no ``--force`` and every companion present; otherwise computed (False), or refused
(:class:`OutputInUse`) where that would replace a file without ``--force``.
"""

from __future__ import annotations

import json

import pytest
import xarray as xr

from geardyn.cli._outputs import OutputInUse, OutputTarget, claim_file, recorded_inputs

IDENT = {"command": "static-te", "options": {"torque_N_m": 100.0, "points": 256},
         "geardyn": "test"}


def _result(path, ident=IDENT):
    xr.Dataset({"te": ("x", [1.0, 2.0])},
               attrs={} if ident is None else {"geardyn_inputs": json.dumps(ident)}
               ).to_netcdf(path, engine="h5netcdf")
    return path


def test_the_same_inputs_are_up_to_date_unless_forced(tmp_path):
    out, png = _result(tmp_path / "te.nc"), tmp_path / "te.png"
    png.write_bytes(b"png")
    target = OutputTarget(out, True)
    assert claim_file(target, IDENT, force=False, companions=(png,)) is True
    # --force recomputes the same inputs
    assert claim_file(target, IDENT, force=True, companions=(png,)) is False
    # a companion gone: computed again (not refused)
    png.unlink()
    assert claim_file(target, IDENT, force=False, companions=(png,)) is False


def test_other_inputs_are_refused_by_name_unless_forced(tmp_path):
    out = _result(tmp_path / "te.nc")
    other = {**IDENT, "options": {"torque_N_m": 50.0, "points": 256}}
    with pytest.raises(OutputInUse, match=r"holds results of different inputs "
                                          r"\(torque_N_m 100\.0 -> 50\.0\)"):
        claim_file(OutputTarget(out, True), other, force=False)
    assert claim_file(OutputTarget(out, True), other, force=True) is False


def test_a_lone_companion_is_kept_unless_forced(tmp_path):
    out, png = tmp_path / "te.nc", tmp_path / "te.png"
    assert claim_file(OutputTarget(out, True), IDENT, force=False, companions=(png,)) is False
    png.write_bytes(b"someone's figure")
    with pytest.raises(OutputInUse, match="has no result but .*te.png exists"):
        claim_file(OutputTarget(out, True), IDENT, force=False, companions=(png,))
    assert claim_file(OutputTarget(out, True), IDENT, force=True, companions=(png,)) is False


def test_a_file_geardyn_did_not_write_is_kept_unless_forced(tmp_path):
    for path in (_result(tmp_path / "mine.nc", None), tmp_path / "notes.nc"):
        if not path.exists():
            path.write_text("not a NetCDF file\n")
        with pytest.raises(OutputInUse, match="not a geardyn result"):
            claim_file(OutputTarget(path, True), IDENT, force=False)
        assert claim_file(OutputTarget(path, True), IDENT, force=True) is False


def test_recorded_inputs_is_a_dict_or_none(tmp_path):
    assert recorded_inputs(_result(tmp_path / "a.nc")) == IDENT
    assert recorded_inputs(_result(tmp_path / "b.nc", None)) is None
    # JSON that is not an object (a list, a number) is no identity
    for i, text in enumerate(("[1, 2]", "3", "not json")):
        path = tmp_path / f"c{i}.nc"
        xr.Dataset({"te": ("x", [1.0])}, attrs={"geardyn_inputs": text}).to_netcdf(
            path, engine="h5netcdf")
        assert recorded_inputs(path) is None, text
        with pytest.raises(OutputInUse, match="not a geardyn result"):
            claim_file(OutputTarget(path, True), IDENT, force=False)
    (tmp_path / "d.nc").write_text("text\n")
    assert recorded_inputs(tmp_path / "d.nc") is None
    assert recorded_inputs(tmp_path / "missing.nc") is None


def test_another_input_file_is_named_first_as_another_file():
    """paper.csv diagnosed into the folder of paper.nc's results was refused for "the content
    of FILE paper.csv", as if the file had been edited (a user audit, 2026-11-27)."""
    from geardyn.cli._outputs import differences

    def ident(path, sha, signal):
        return {"command": "diagnose", "geardyn": "1", "options": {"signal": signal},
                "files": {"FILE": {"path": path, "sha256": sha}}}

    assert differences(ident("paper.nc", "a", "acc"), ident("paper.csv", "b", "x")) == [
        "FILE paper.nc -> paper.csv", "signal 'acc' -> 'x'"]
    assert differences(ident("r.csv", "a", "acc"), ident("r.csv", "b", "acc")) == [
        "the content of FILE r.csv"]
