"""``geardyn diagnose``: which teeth, which sample rate, and messages in the user's terms.

The files are small synthetic records in the layouts ``geardyn measure`` and ``geardyn simulate``
write (NetCDF with a stored ``fs`` and ``case_toml``, CSV, .mat with ``fs`` and an ``attrs``
struct), so that no test pays for a simulation.
"""

from __future__ import annotations

import json
import os

import numpy as np
import pytest
import scipy.io
import xarray as xr

from .._cli_fork import run_geardyn

FS = 10_000.0  # [Hz]
SPEED = 18.0  # [rev/s]
SMALL = ["--set", "diagnostics.samples_per_rev=512"]


def run(tmp_path, *args):
    env = {**os.environ, "GEARDYN_CACHE_DIR": str(tmp_path / "cache")}
    return run_geardyn(["diagnose", *map(str, args)], capture_output=True, text=True, env=env,
                       timeout=300)


def one_error(r) -> str:
    """The single clean error line of a refused command line (exit status 2)."""
    assert r.returncode == 2, r.stdout + r.stderr
    assert "Traceback" not in r.stdout + r.stderr
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and len(lines[0]) < 500, r.stderr
    return lines[0]


def metrics(out) -> dict:
    return json.loads((out / "metrics.json").read_text())


def _case_toml(pinion_teeth: int, gear_teeth: int = 23) -> str:
    """A case TOML as a record stores it (values with sources, ``extends = false``)."""
    return (f'name = "stored"\nextends = false\n\n[pinion.teeth]\nvalue = {pinion_teeth}\n'
            f'source = "test"\n\n[gear]\nteeth = {gear_teeth}\n')


def _channels(seconds: float = 1.0):
    t = np.arange(int(round(seconds * FS))) / FS
    theta = 2 * np.pi * SPEED * t
    acc = np.cos(25 * theta) + 0.3 * np.cos(50 * theta) + 0.1 * np.sin(3 * theta)
    d = np.mod(theta + np.pi, 2 * np.pi) - np.pi  # angle from the key, in [-pi, pi)
    tach = 5.0 * np.clip(np.minimum(d, 0.5 - d) / 0.05 + 0.5, 0.0, 1.0)  # edges over ~5 samples
    return t, theta, acc, tach


def write_record(path, *, case_teeth: int | None = 25, tach_shaft: str | None = None,
                 seconds: float = 1.0):
    """A record in the layout of ``geardyn measure``: NetCDF with ``fs`` and ``case_toml``
    attributes, or .mat with ``fs`` and an ``attrs`` struct, or CSV (no rate, no case)."""
    t, _, acc, tach = _channels(seconds)
    attrs = {"fs": FS, "fs_units": "Hz", "title": "test record"}
    if case_teeth is not None:
        attrs["case_toml"] = _case_toml(case_teeth)
    if tach_shaft is not None:
        attrs["tach_shaft"] = tach_shaft
    if path.suffix == ".nc":
        ds = xr.Dataset({"acc": ("time", acc), "tach": ("time", tach)}, coords={"time": t},
                        attrs=attrs)
        ds.to_netcdf(path, engine="h5netcdf")
    elif path.suffix == ".mat":
        scipy.io.savemat(path, {"time": t[:, None], "acc": acc[:, None], "tach": tach[:, None],
                                "fs": FS, "attrs": attrs}, oned_as="column")
    else:
        np.savetxt(path, np.column_stack([t, acc, tach]), delimiter=",", header="time,acc,tach",
                   comments="")
    return path


def write_simulation(path, *, seconds: float, pinion_teeth: int | None = 25):
    """A result in the layout of ``geardyn simulate``: ``time``, ``theta_p`` and signals."""
    t, theta, acc, _ = _channels(seconds)
    attrs = {"model": "II"} if pinion_teeth is None else {"model": "II",
                                                          "pinion_teeth": pinion_teeth}
    ds = xr.Dataset({"theta_p": ("time", theta), "v_yg": ("time", acc),
                     "omega_p": ("time", np.gradient(theta, t)),
                     "transmission_error": ("time", 1e-4 * acc)},
                    coords={"time": 0.5 + t}, attrs=attrs)
    ds.to_netcdf(path, engine="h5netcdf")
    return path


# --------------------------------------------------------------------------------- teeth
@pytest.mark.parametrize("name", ["rec.nc", "rec.mat"])
def test_teeth_default_from_the_case_the_record_stores(tmp_path, name):
    """Item 1: no --teeth on a record that stores its case: that case's pinion (25 teeth here,
    the default --config case has 23), as the measure command's own hint would give."""
    rec = write_record(tmp_path / name, case_teeth=25)
    out = tmp_path / "out"
    r = run(tmp_path, rec, "--signal", "acc", "--tach", "tach", "--no-figures", "-o", out, *SMALL)
    assert r.returncode == 0, r.stderr
    assert metrics(out)["settings"]["teeth"] == 25
    assert "(teeth 25)" in r.stdout


def test_teeth_of_the_gear_when_the_records_tachometer_reads_the_gear(tmp_path):
    rec = write_record(tmp_path / "rec.nc", case_teeth=25, tach_shaft="gear")
    out = tmp_path / "out"
    r = run(tmp_path, rec, "--signal", "acc", "--tach", "tach", "--no-figures", "-o", out, *SMALL)
    assert r.returncode == 0, r.stderr
    assert metrics(out)["settings"]["teeth"] == 23  # [gear] teeth of the stored case


def test_teeth_option_for_files_that_do_not_state_it_and_the_config_case_default(tmp_path):
    """--teeth where the file says nothing; a count contradicting a stored case is refused (it
    would move every mesh order: the QA's second walkthrough diagnosed a 23-tooth record with
    --teeth 31 into meaningless numbers); a NetCDF record without a stored case defaults like
    the same data as CSV: the pinion of the --config case (the paper's, 23 teeth)."""
    rec = write_record(tmp_path / "rec.nc", case_teeth=25)
    bare = write_record(tmp_path / "bare.nc", case_teeth=None)
    csv = write_record(tmp_path / "rec.csv")
    line = one_error(run(tmp_path, rec, "--signal", "acc", "--tach", "tach", "--teeth", "30",
                         "--no-figures", "-o", tmp_path / "x", *SMALL))
    assert line.startswith("error: --teeth: got 30") and "25" in line, line
    runs = {"teeth": (bare, ["--teeth", "30"]), "bare": (bare, []),
            "csv": (csv, ["--fs", "10 kHz"])}
    kurt = {}
    for key, (path, extra) in runs.items():
        out = tmp_path / f"out-{key}"
        r = run(tmp_path, path, "--signal", "acc", "--tach", "tach", "--no-figures", "-o", out,
                *extra, *SMALL)
        assert r.returncode == 0, r.stderr
        m = metrics(out)
        assert m["settings"]["teeth"] == (30 if key == "teeth" else 23), key
        kurt[key] = m["signals"]["acc"]["kurtosis"]["tsa"]
    assert kurt["bare"] == pytest.approx(kurt["csv"], rel=1e-9)  # the same data, the same result


def test_simulation_without_teeth_is_a_clear_error(tmp_path):
    sim = write_simulation(tmp_path / "sim.nc", seconds=0.5, pinion_teeth=None)
    line = one_error(run(tmp_path, sim, "--no-figures", "-o", tmp_path / "out", *SMALL))
    assert "--teeth" in line and "sim.nc stores neither" in line


# ----------------------------------------------------------------------------- sample rate
@pytest.mark.parametrize("name", ["rec.nc", "rec.mat"])
def test_fs_other_than_the_files_own_is_refused(tmp_path, name):
    """Item 2: --fs was silently ignored on a file with its own rate."""
    rec = write_record(tmp_path / name)
    out = tmp_path / "out"
    line = one_error(run(tmp_path, rec, "--signal", "acc", "--tach", "tach", "--fs", "25 kHz",
                         "-o", out, *SMALL))
    assert "--fs" in line and "25000 Hz" in line and "10000 Hz" in line and name in line
    assert not (out / "metrics.json").exists()
    # the file's own rate, however written, is accepted silently
    r = run(tmp_path, rec, "--signal", "acc", "--tach", "tach", "--fs", "10 kHz", "--no-figures",
            "-o", out, *SMALL)
    assert r.returncode == 0, r.stderr
    assert r.stderr.strip() == "" and metrics(out)["signals"]["acc"]["n_averages"] >= 10


def test_simulation_refuses_fs_and_time(tmp_path):
    sim = write_simulation(tmp_path / "sim.nc", seconds=0.5)
    line = one_error(run(tmp_path, sim, "--fs", "20000", "--no-figures", "-o", tmp_path / "o",
                         *SMALL))
    assert "--fs" in line and "20000 Hz" in line and "10000 Hz" in line
    line = one_error(run(tmp_path, sim, "--time", "t", "--no-figures", "-o", tmp_path / "o",
                         *SMALL))
    assert "--time: got 't'" in line and "own time axis" in line
    out = tmp_path / "ok"
    r = run(tmp_path, sim, "--fs", "10 kHz", "--no-figures", "-o", out, *SMALL)
    assert r.returncode == 0, r.stderr
    assert metrics(out)["settings"]["teeth"] == 25


def test_csv_needs_fs_or_time_named_as_options(tmp_path):
    """Item 3: the CLI's options, not the library's keywords (time=)."""
    csv = write_record(tmp_path / "rec.csv")
    line = one_error(run(tmp_path, csv, "--signal", "acc", "--tach", "tach", "-o",
                         tmp_path / "o", *SMALL))
    assert "--fs" in line and "--time" in line and "time=" not in line
    assert "rec.csv stores no sample rate" in line
    line = one_error(run(tmp_path, csv, "--signal", "acc", "--tach", "tach", "--fs", "10000",
                         "--time", "time", "-o", tmp_path / "o", *SMALL))
    assert line.startswith("error: --fs: got '10000 Hz'") and "--time" in line


# --------------------------------------------------------------------------- short records
def test_short_simulation_names_the_file_and_its_revolutions(tmp_path):
    """Item 3: not "x: got 'a record spanning ...'" (the QA's --angle-unit deg, which does not
    apply to a simulation's exact angle, is refused by name: test_diagnose_pulses.py)."""
    sim = write_simulation(tmp_path / "e7.nc", seconds=0.01)  # 0.18 revolutions at 18 rev/s
    line = one_error(run(tmp_path, sim, "--no-figures", "-o", tmp_path / "o", *SMALL))
    assert "e7.nc" in line and "0.178 revolutions" in line and "x:" not in line
    assert "simulation.record_time" in line and "0.111 s" in line  # 2 revolutions


def test_short_measured_record_names_the_file(tmp_path):
    _, theta, acc, _ = _channels(0.05)  # 0.9 revolutions
    csv = tmp_path / "short.csv"
    np.savetxt(csv, np.column_stack([theta, acc]), delimiter=",", header="angle,acc",
               comments="")
    line = one_error(run(tmp_path, csv, "--signal", "acc", "--angle", "angle", "--fs", "10 kHz",
                         "--no-figures", "-o", tmp_path / "o", *SMALL))
    assert "short.csv" in line and "0.898 revolutions" in line and "x:" not in line
    assert "record at least 0.111 s" in line


def test_netcdf_record_without_tach_says_to_name_the_shaft_channel(tmp_path):
    rec = write_record(tmp_path / "rec.nc")
    line = one_error(run(tmp_path, rec, "--signal", "acc", "--no-figures", "-o",
                         tmp_path / "o", *SMALL))
    assert "rec.nc" in line and "--tach" in line and "--signal" not in line


# ------------------------------------------------------------------------------- done line
def test_no_figures_says_only_what_was_written(tmp_path):
    """Item 4."""
    rec = write_record(tmp_path / "rec.nc")
    out = tmp_path / "out"
    r = run(tmp_path, rec, "--signal", "acc", "--tach", "tach", "--no-figures", "-o", out, *SMALL)
    assert r.returncode == 0, r.stderr
    done = next(ln for ln in r.stdout.splitlines() if ln.startswith("done"))
    said = done.split(" in ", 1)[0]  # (the folder's path may hold any word)
    assert "metrics.json" in said and "figure" not in said
    assert not (out / "figures").exists()


def test_bad_pulse_times_are_named_by_the_tach_option(tmp_path):
    """The TSA's own argument (``tach_times``) is not a name the user typed: a column of pulse
    times that goes backwards is refused as ``--tach`` (``tach`` in the library)."""
    from geardyn.diagnostics import diagnose_file
    from geardyn.errors import InputError

    t, _, acc, _ = _channels()
    pulses = np.zeros_like(t)
    pulses[:5] = [0.5, 0.4, 0.3, 0.2, 0.1]  # [s], going backwards
    path = tmp_path / "bad.csv"
    np.savetxt(path, np.c_[acc, pulses], delimiter=",", header="acc,tach", comments="")
    line = one_error(run(tmp_path, path, "--signal", "acc", "--tach", "tach", "--tach-times",
                         "--fs", FS, "--teeth", 25, "-o", tmp_path / "d"))
    assert line.startswith("error: --tach: got 'non-increasing pulse times'"), line
    assert "tach_times" not in line
    with pytest.raises(InputError) as exc:
        diagnose_file(path, signals="acc", tach="tach", tach_column_is_pulse_times=True, fs=FS,
                      teeth=25)
    assert exc.value.field == "tach"


def test_force_replaces_the_earlier_figures_too(tmp_path):
    """``--force`` with other options left the earlier run's figures beside the new
    metrics.json (a user audit, 2026-11-27): the results of other inputs go first."""
    rec = write_record(tmp_path / "r.nc")
    out = tmp_path / "dd"
    r = run(tmp_path, rec, "--signal", "acc", "--tach", "tach", *SMALL, "-o", out)
    assert r.returncode == 0, r.stderr
    assert any((out / "figures").glob("acc_*.png"))
    r = run(tmp_path, rec, "--signal", "acc", "--tach", "tach", *SMALL, "-o", out, "--force",
            "--no-figures", "--set", "diagnostics.harmonic=2")
    assert r.returncode == 0, r.stderr
    assert not (out / "figures").exists()
    assert metrics(out)["settings"]["harmonic"] == 2
    # with figures again: drawn anew
    r = run(tmp_path, rec, "--signal", "acc", "--tach", "tach", *SMALL, "-o", out, "--force",
            "--set", "diagnostics.harmonic=2")
    assert r.returncode == 0 and any((out / "figures").glob("acc_*.png")), r.stderr


def test_messages_name_the_users_columns(tmp_path):
    """A user audit (2026-11-27): a flat tach channel blamed --tach-threshold, which was never
    given; a NaN in the signal was named "signals['acc']"; no --signal said "got None" without
    the columns to choose from."""
    t, _, acc, tach = _channels()
    flat = tmp_path / "flat.csv"
    np.savetxt(flat, np.column_stack([t, acc, np.zeros_like(t)]), delimiter=",",
               header="time,acc,tach", comments="")
    line = one_error(run(tmp_path, flat, "--time", "time", "--signal", "acc", "--tach", "tach",
                         *SMALL, "-o", tmp_path / "o1"))
    assert line.startswith("error: --tach: got 'a constant channel (0 throughout)'"), line
    nan = tmp_path / "nan.csv"
    acc = acc.copy()
    acc[500] = np.nan
    np.savetxt(nan, np.column_stack([t, acc, tach]), delimiter=",", header="time,acc,tach",
               comments="")
    line = one_error(run(tmp_path, nan, "--time", "time", "--signal", "acc", "--tach", "tach",
                         *SMALL, "-o", tmp_path / "o2"))
    assert line.startswith("error: --signal 'acc': got '1 non-finite value(s), first at index "
                           "500'"), line
    line = one_error(run(tmp_path, nan, "--time", "time", "--tach", "tach", *SMALL, "-o",
                         tmp_path / "o3"))
    assert line.endswith("allowed: the column(s) to diagnose (name or position): one of "
                         "'time', 'acc', 'tach'"), line
