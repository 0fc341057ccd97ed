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
    # (metrics only: the figures are another test's business)
    common = ["--signal", "acc", "--tach", "tach", "--teeth", 25, "--no-figures", *SMALL]
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


def test_a_csv_of_geardyn_measure_states_its_rate_teeth_and_pulses(tmp_path):
    """``geardyn measure --csv`` writes ``# key = value`` provenance (rate, teeth, pulses per
    revolution); ``diagnose`` reads them as it reads the NetCDF's attributes. Oracle: the same
    record as NetCDF, diagnosed with nothing but the channel names."""
    from geardyn.measurement.record import write_csv

    t, theta, acc, _ = _channels()
    d = np.mod(2 * theta + np.pi, 2 * np.pi) - np.pi
    tach = 5.0 * np.clip(np.minimum(d, 0.5 - d) / 0.05 + 0.5, 0.0, 1.0)
    attrs = {"fs": FS, "fs_units": "Hz", "title": "record", "case": "stored",
             "pinion_teeth": 25, "gear_teeth": 23, "tach_shaft": "pinion",
             "tach_pulses_per_rev": 2}
    ds = xr.Dataset({"acc": ("time", acc, {"units": "m/s^2"}),
                     "acc_g": ("time", acc / 9.80665, {"units": "g"}),
                     "tach": ("time", tach, {"units": "V"})},
                    coords={"time": ("time", t, {"units": "s"})}, attrs=attrs)
    ds.to_netcdf(tmp_path / "rec.nc", engine="h5netcdf")
    write_csv(ds, tmp_path / "rec.csv")
    text = (tmp_path / "rec.csv").read_text()
    assert "# fs = 10000 Hz" in text and "# pinion_teeth = 25" in text
    for name in ("rec.nc", "rec.csv"):
        r = run(tmp_path, tmp_path / name, "--signal", "acc", "--tach", "tach", *SMALL,
                "--no-figures", "--out", tmp_path / name.replace(".", "-"))
        assert r.returncode == 0, r.stdout + r.stderr
        assert "(teeth 25)" in r.stdout + r.stderr
    a, b = metrics(tmp_path / "rec-nc"), metrics(tmp_path / "rec-csv")
    assert a["signals"]["acc"] == b["signals"]["acc"]
    line = one_error(run(tmp_path, tmp_path / "rec.csv", "--signal", "acc", "--tach", "tach",
                         "--fs", "20 kHz", *SMALL, "--out", tmp_path / "x"))
    assert line.startswith("error: --fs: got '20000 Hz'") and "10000 Hz" in line, line


def test_options_that_would_be_ignored_are_refused(tmp_path):
    """Options that do not apply to the file's shaft angle are refused, naming the option (the
    QA: --angle-unit, --tach-times and --pulses-per-rev were ignored without a word)."""
    t, theta, acc, _ = _channels()
    sim = tmp_path / "sim.nc"
    xr.Dataset({"v_yg": ("time", acc), "theta_p": ("time", theta)}, coords={"time": t},
               attrs={"pinion_teeth": 25}).to_netcdf(sim, engine="h5netcdf")
    for extra in (["--angle-unit", "deg"], ["--tach-times"], ["--pulses-per-rev", 2]):
        line = one_error(run(tmp_path, sim, "--signal", "v_yg", *extra, *SMALL,
                             "--out", tmp_path / "o"))
        assert line.startswith(f"error: {extra[0]}: got") and "theta_p" in line, line
    rec = _two_pulse_record(tmp_path / "rec.nc", True)
    line = one_error(run(tmp_path, rec, "--signal", "acc", "--tach", "tach", "--angle-unit",
                         "deg", "--teeth", 25, *SMALL, "--out", tmp_path / "o"))
    assert line.startswith("error: --angle-unit: got 'deg'") and "--angle" in line, line
    ang = tmp_path / "ang.csv"
    np.savetxt(ang, np.column_stack([t, acc, theta]), delimiter=",", header="time,acc,angle",
               comments="")
    for extra in (["--tach-times"], ["--pulses-per-rev", 2]):
        line = one_error(run(tmp_path, ang, "--signal", "acc", "--angle", "angle", "--time",
                             "time", "--teeth", 25, *extra, *SMALL, "--out", tmp_path / "o"))
        assert line.startswith(f"error: {extra[0]}: got") and "--tach" in line, line
    # the same files without those options are diagnosed
    r = run(tmp_path, ang, "--signal", "acc", "--angle", "angle", "--time", "time", "--teeth",
            25, *SMALL, "--no-figures", "--out", tmp_path / "ok")
    assert r.returncode == 0, r.stdout + r.stderr


def test_a_simulations_own_teeth_cannot_be_contradicted(tmp_path):
    """A simulation record averages over theta_p: a --teeth other than its pinion's is refused
    (it exited 0 with every mesh order misplaced); its own count is accepted."""
    t, theta, acc, _ = _channels()
    sim = tmp_path / "sim.nc"
    xr.Dataset({"v_yg": ("time", acc), "theta_p": ("time", theta)}, coords={"time": t},
               attrs={"pinion_teeth": 25}).to_netcdf(sim, engine="h5netcdf")
    line = one_error(run(tmp_path, sim, "--signal", "v_yg", "--teeth", 31, *SMALL,
                         "--out", tmp_path / "o"))
    assert line.startswith("error: --teeth: got 31") and "theta_p" in line and "25" in line
    r = run(tmp_path, sim, "--signal", "v_yg", "--teeth", 25, *SMALL, "--no-figures",
            "--out", tmp_path / "ok")
    assert r.returncode == 0, r.stdout + r.stderr


def test_pwvd_max_order_must_be_a_positive_number():
    import pytest

    from geardyn.diagnostics import diagnose
    from geardyn.errors import InputError

    t, theta, acc, _ = _channels()
    for bad in (float("nan"), -1.0, 0.0, "10", True):
        with pytest.raises(InputError, match="pwvd_max_order"):
            diagnose({"acc": acc}, teeth=25, angle=theta, pwvd_max_order=bad)
