"""``geardyn diagnose`` takes the tachometer's pulses per revolution from the file that states
it (``tach_pulses_per_rev``, as ``geardyn measure`` writes it): the QA found a 2-pulse record
read as 1 pulse per revolution, every order of the TSA then silently halved."""

from __future__ import annotations

import numpy as np
import xarray as xr

from .test_diagnose_inputs import FS, SMALL, _channels, metrics, one_error, run


def _two_pulse_record(path, stated: bool):
    t, theta, acc, _ = _channels()
    d = np.mod(2 * theta + np.pi, 2 * np.pi) - np.pi  # two keys per revolution
    tach = 5.0 * np.clip(np.minimum(d, 0.5 - d) / 0.05 + 0.5, 0.0, 1.0)
    attrs = {"fs": FS, "fs_units": "Hz", "title": "two pulses per revolution"}
    if stated:
        attrs["tach_pulses_per_rev"] = 2
    xr.Dataset({"acc": ("time", acc), "tach": ("time", tach)}, coords={"time": t},
               attrs=attrs).to_netcdf(path, engine="h5netcdf")
    return path


def test_the_files_pulse_count_is_the_default_and_a_contradiction_is_refused(tmp_path):
    stated = _two_pulse_record(tmp_path / "stated.nc", True)
    plain = _two_pulse_record(tmp_path / "plain.nc", False)
    common = ["--signal", "acc", "--tach", "tach", "--teeth", 25, *SMALL]
    r = run(tmp_path, stated, *common, "--out", tmp_path / "a")
    assert r.returncode == 0, r.stdout + r.stderr
    r = run(tmp_path, plain, *common, "--pulses-per-rev", 2, "--out", tmp_path / "b")
    assert r.returncode == 0, r.stdout + r.stderr
    # oracle: the same record with the count given by hand
    a, b = metrics(tmp_path / "a"), metrics(tmp_path / "b")
    assert a["signals"]["acc"] == b["signals"]["acc"]
    # the 25th-order mesh tone is where it should be only with 2 pulses per revolution
    r = run(tmp_path, plain, *common, "--out", tmp_path / "c")  # no count: 1 assumed
    assert r.returncode == 0, r.stdout + r.stderr
    assert metrics(tmp_path / "c")["signals"]["acc"] != a["signals"]["acc"]
    line = one_error(run(tmp_path, stated, *common, "--pulses-per-rev", 1,
                         "--out", tmp_path / "d"))
    assert line.startswith("error: --pulses-per-rev: got 1") and "2" in line, line
    r = run(tmp_path, stated, *common, "--pulses-per-rev", 2, "--out", tmp_path / "e")
    assert r.returncode == 0, r.stdout + r.stderr  # the file's own count is accepted
