"""The diagnostics chain on synthetic simulation results and measured-data files."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import scipy.io
import xarray as xr

from geardyn.diagnostics import (
    SIMULATION_SIGNALS,
    DiagnosticsWarning,
    diagnose,
    diagnose_file,
    load_measurement,
    load_simulation,
    read_table,
)
from geardyn.errors import DataFileError, InputError

W = 114.14  # pinion speed [rad/s] (paper, Table 2)
FS = 80000.0  # sample rate [Hz]: about 4400 samples per revolution
Z = 23
CRACK = np.radians(170.0)


def _gear_signals(theta):
    """Mesh harmonics plus a localised event at 170 deg of the pinion."""
    pulse = np.exp(-0.5 * ((np.mod(theta, 2 * np.pi) - CRACK) / 0.02) ** 2)
    v = (0.01 * np.cos(Z * theta) + 0.004 * np.cos(2 * Z * theta + 0.2)
         + 0.002 * np.cos(5 * Z * theta + 0.7) + 0.003 * pulse)
    om = W + 0.1 * np.cos(Z * theta) + 0.05 * np.cos(5 * Z * theta) + 0.05 * pulse
    te = 0.05 + 2e-5 * np.cos(Z * theta) + 4e-6 * np.cos(5 * Z * theta) + 1e-5 * pulse
    return {"v_yg": v, "omega_p": om, "transmission_error": te}


def _simulation(n_rev=8):
    t = np.arange(int(n_rev * 2 * np.pi / W * FS)) / FS
    theta = W * t + 0.002 * np.sin(Z * W * t)  # exact, non-uniform pinion angle
    sig = _gear_signals(theta)
    return t, theta, sig


@pytest.fixture(scope="module")
def sim_file(tmp_path_factory):
    t, theta, sig = _simulation()
    data = {"theta_p": theta, "theta_g": theta * Z / 61, "y_p": 0 * t, **sig}
    ds = xr.Dataset({k: ("time", v) for k, v in data.items()}, coords={"time": t},
                    attrs={"pinion_teeth": Z, "gear_teeth": 61})
    ds["v_yg"].attrs["units"] = "m/s"
    path = tmp_path_factory.mktemp("sim") / "result.nc"
    ds.to_netcdf(path, engine="h5netcdf")
    return path


@pytest.fixture(scope="module")
def sim_result(sim_file):
    return diagnose_file(sim_file, samples_per_rev=512)


# ------------------------------------------------------------------------------------------
# simulation results
# ------------------------------------------------------------------------------------------
def test_simulation_result_chain(sim_result):
    r = sim_result
    assert list(r.signals) == list(SIMULATION_SIGNALS)
    assert r.teeth == Z and r.method == "angle" and r.samples_per_rev == 512
    for name, d in r.signals.items():
        assert d.tsa.n_averages == 7
        # the TSA against the exact angle reproduces the generating waveform
        truth = _gear_signals(d.tsa.angle)[name]
        scale = np.ptp(truth)
        assert np.max(np.abs(d.tsa.average - truth)) < 1e-4 * scale
        # the fault at 170 deg: residual peak there, residual kurtosis above the TSA's
        peak_deg = np.degrees(d.tsa.angle[np.argmax(np.abs(d.residual))])
        assert abs(peak_deg - 170.0) < 2.0
        assert d.residual_kurtosis > d.statistics.kurtosis
        env_peak = np.degrees(d.tsa.angle[np.argmax(d.demodulation.envelope)])
        assert abs(env_peak - 170.0) < 5.0
        assert d.pwvd_tsa.orders[-1] == pytest.approx(6 * Z)
    om = r.signals["omega_p"]
    assert om.statistics.mean == pytest.approx(np.mean(_gear_signals(om.tsa.angle)["omega_p"]),
                                               rel=1e-9)
    assert r.signals["v_yg"].unit == "m/s"
    assert r.signals["omega_p"].unit == "rad/s"  # default unit of a paper signal


def test_to_dict_is_json_and_complete(sim_result):
    d = json.loads(json.dumps(sim_result.to_dict(), allow_nan=False))
    v = d["signals"]["v_yg"]
    assert set(v["statistics"]) >= {"mean", "std", "skewness", "kurtosis", "crest_factor",
                                    "crest_factor_rms"}
    assert set(v["kurtosis"]) == {"tsa", "residual", "envelope", "amplitude_modulation",
                                  "phase_modulation"}
    assert set(v["condition_metrics"]) == {"RMS", "Kurtosis", "CrestFactor", "FM4", "M6A",
                                           "M8A", "FM0", "EnergyRatio", "NA4", "NA4star", "NB4"}
    assert v["demodulation"]["band"] == [104, 126]
    # mesh harmonic table: the 2nd harmonic of v_yg, 0.004 -> 20 log10(0.004/sqrt 2) dB
    assert v["mesh_harmonics_rms"]["46"]["db"] == pytest.approx(
        20 * math.log10(0.004 / math.sqrt(2)), abs=0.05)
    assert d["settings"]["residual_preset"] == "paper"


@pytest.mark.slow
def test_write_is_atomic_and_complete(tmp_path, sim_file):
    res = diagnose_file(sim_file, signals=["v_yg"], samples_per_rev=512)
    out = res.write(tmp_path / "report")
    assert out["metrics"].name == "metrics.json"
    json.loads(out["metrics"].read_text())
    names = sorted(p.name for p in out["figures"])
    assert names == sorted(f"v_yg_{k}.png" for k in (
        "tsa", "spectrum", "residual", "pwvd_tsa", "pwvd_residual", "demodulation",
        "analytic"))
    for p in out["figures"]:
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    leftovers = [p for p in (tmp_path / "report").rglob("*") if p.name.endswith(".tmp")]
    assert leftovers == []


def test_simulation_errors(tmp_path, sim_file):
    with pytest.raises(InputError, match="signals: .*'nope'.*data variables"):
        load_simulation(sim_file, signals=["nope"])
    bad = tmp_path / "trunc.nc"
    bad.write_bytes(sim_file.read_bytes()[:2000])
    with pytest.raises(DataFileError, match="trunc.nc: not a readable NetCDF4"):
        load_simulation(bad)
    with pytest.raises(DataFileError, match="no such file"):
        load_simulation(tmp_path / "absent.nc")
    t = np.arange(10.0)
    xr.Dataset({"theta_p": ("x", t)}).to_netcdf(tmp_path / "notime.nc", engine="h5netcdf")
    with pytest.raises(DataFileError, match="no 'time' coordinate"):
        load_simulation(tmp_path / "notime.nc", signals=["theta_p"])


# ------------------------------------------------------------------------------------------
# measured data
# ------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def measured():
    t, theta, sig = _simulation(n_rev=6)
    tach = np.where(np.mod(theta, 2 * np.pi) < 0.3, 5.0, 0.0)  # once-per-rev key phasor
    return t, theta, sig["v_yg"], tach


def _expected_tsa(n=512):
    return _gear_signals(2 * np.pi * np.arange(n) / n)["v_yg"]


def test_csv_with_header_angle_and_tach(tmp_path, measured):
    t, theta, v, tach = measured
    path = tmp_path / "m.csv"
    np.savetxt(path, np.column_stack([t, v, theta, tach]), delimiter=",",
               header="time,accel,angle,tach", comments="")
    m = load_measurement(path, signal="accel", fs=FS, angle="angle")
    np.testing.assert_allclose(m.angle, theta)
    res = diagnose(m.signals, teeth=Z, angle=m.angle, samples_per_rev=512)
    assert np.max(np.abs(res.signals["accel"].tsa.average - _expected_tsa())) < 2e-6
    # sampled tachometer pulse train: angle from the rising edges (the phasor is 0.3 rad wide,
    # the rising edge is at angle 0 of each revolution)
    with pytest.warns(DiagnosticsWarning, match="not resolved by the sampling"):
        m2 = load_measurement(path, signal=1, time="time", tach="tach")
    # the record starts inside a pulse: rising edges at revolutions 1..5 only
    assert m2.tach_times.size == 5
    np.testing.assert_allclose(m2.tach_times, [t[np.searchsorted(theta, 2 * np.pi * k)]
                                               for k in range(1, 6)], atol=1 / FS)
    res2 = diagnose(m2.signals, teeth=Z, time=m2.time, tach_times=m2.tach_times,
                    samples_per_rev=512)
    d = res2.signals["accel"]
    assert d.tsa.method == "tach" and d.tsa.n_averages == 4
    # the tach angle has the encoder ripple of 0.002 rad at order 23 averaged out, which
    # shifts order 23 by ~ 23 * 0.002 rad, and the edges of a sampled square pulse are only
    # located to half a sample: agreement to a few percent of the peak-to-peak (measured 4 %)
    assert np.max(np.abs(d.tsa.average - _expected_tsa())) < 0.06 * np.ptp(_expected_tsa())


def test_csv_pulse_time_column_and_no_header(tmp_path, measured):
    t, theta, v, _ = measured
    k = np.arange(1, 7)
    pulses = k * 2 * np.pi / W  # angle = W t + ripple: near these times, not exactly
    col = np.full(t.size, np.nan)
    col[: pulses.size] = pulses
    path = tmp_path / "m.txt"
    with open(path, "w") as fh:
        fh.write("# a comment line\n")
        for a, b, c in zip(t, v, col, strict=True):
            fh.write(f"{float(a)!r}\t{float(b)!r}\t{'' if np.isnan(c) else repr(float(c))}\n")
    m = load_measurement(path, signal=1, fs=FS, tach=2, tach_column_is_pulse_times=True)
    np.testing.assert_allclose(m.tach_times, pulses)
    assert list(m.signals) == ["1"]


def test_npy_npz_and_mat(tmp_path, measured):
    t, theta, v, _ = measured
    np.save(tmp_path / "a.npy", np.column_stack([v, theta]))
    m = load_measurement(tmp_path / "a.npy", signal=0, angle=1, fs=FS)
    np.testing.assert_array_equal(m.signals["0"], v)
    np.savez(tmp_path / "b.npz", vib=v, angle=theta, fs=FS)
    m = load_measurement(tmp_path / "b.npz", signal="vib", angle="angle")
    assert m.fs == FS  # taken from the file
    scipy.io.savemat(tmp_path / "c.mat", {"vib": v[:, None], "ang": theta, "fs": FS})
    m = load_measurement(tmp_path / "c.mat", signal="vib", angle="ang")
    np.testing.assert_array_equal(m.angle, theta)
    res = diagnose(m.signals, teeth=Z, angle=m.angle, samples_per_rev=512)
    assert np.max(np.abs(res.signals["vib"].tsa.average - _expected_tsa())) < 2e-6


def test_mat_v73_hdf5(tmp_path, measured):
    h5py = pytest.importorskip("h5py")
    t, theta, v, _ = measured
    path = tmp_path / "d.mat"
    with h5py.File(path, "w", userblock_size=512) as f:
        f["vib"] = v[None, :]  # MATLAB writes column vectors as 1 x n (column-major)
        f["ang"] = theta[None, :]
        for name in ("vib", "ang"):  # every MATLAB variable carries its class
            f[name].attrs["MATLAB_class"] = np.bytes_("double")
    header = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: test HDF5 schema 1.00 ."
    with open(path, "r+b") as fh:
        fh.write(header.ljust(116, b" ") + b"\x00" * 8 + b"\x00\x02" + b"IM")
    table = read_table(path)
    assert set(table.names) == {"vib", "ang"}
    np.testing.assert_array_equal(table.columns["vib"], v)
    # an HDF5 file whose datasets carry no MATLAB class holds no MATLAB variables: a clear
    # error that says why (not the reader's log lines on stderr)
    with h5py.File(tmp_path / "plain.mat", "w", userblock_size=512) as f:
        f["vib"] = v[None, :]
    with open(tmp_path / "plain.mat", "r+b") as fh:
        fh.write(header.ljust(116, b" ") + b"\x00" * 8 + b"\x00\x02" + b"IM")
    with pytest.raises(DataFileError, match="not a MATLAB datatype"):
        read_table(tmp_path / "plain.mat")


@pytest.mark.parametrize(
    ("name", "content", "match"),
    [
        ("trunc.csv", b"a,b\n1,2\n3,4\n5", "line 4 has 1 fields, expected 2"),
        ("text.csv", b"a,b\n1,2\n3,x\n", "line 3: non-numeric"),
        ("empty.csv", b"", "empty file"),
        ("header.csv", b"a,b\n", "no data rows"),
        ("bad.npy", b"\x93NUMPY\x01\x00garbage", "not a readable .npy"),
        ("bad.npz", b"PK\x03\x04 not really a zip", "not a readable .npz"),
        ("bad.mat", b"definitely not a MATLAB file" * 10, "not a readable MATLAB"),
        ("data.xlsx", b"xx", "unsupported format"),
    ],
)
def test_bad_files(tmp_path, name, content, match):
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(DataFileError, match=match):
        read_table(path)


def test_truncated_npy(tmp_path, measured):
    _, theta, v, _ = measured
    np.save(tmp_path / "full.npy", np.column_stack([v, theta]))
    raw = (tmp_path / "full.npy").read_bytes()
    (tmp_path / "cut.npy").write_bytes(raw[: len(raw) // 2])
    with pytest.raises(DataFileError, match="cut.npy: not a readable .npy"):
        read_table(tmp_path / "cut.npy")


def test_missing_file_and_column(tmp_path, measured):
    with pytest.raises(DataFileError, match="no such file"):
        load_measurement(tmp_path / "nothing.csv", signal=0, fs=FS, angle=1)
    t, theta, v, _ = measured
    path = tmp_path / "m.csv"
    np.savetxt(path, np.column_stack([v, theta]), delimiter=",", header="vib,angle",
               comments="")
    with pytest.raises(InputError, match=r"signal: got 'accel'; allowed: .*'vib', 'angle'"):
        load_measurement(path, signal="accel", fs=FS, angle="angle")
    with pytest.raises(InputError, match="angle: got 5"):
        load_measurement(path, signal="vib", fs=FS, angle=5)
    with pytest.raises(InputError, match="fs"):
        load_measurement(path, signal="vib", angle="angle")
    with pytest.raises(InputError, match="exactly one of"):
        load_measurement(path, signal="vib", fs=FS)
    with pytest.raises(InputError, match="teeth"):
        diagnose_file(path, signals="vib", fs=FS, angle="angle")


def test_nan_in_measured_signal_is_reported_by_name(tmp_path, measured):
    t, theta, v, _ = measured
    v = v.copy()
    v[123] = np.nan
    path = tmp_path / "gap.csv"
    np.savetxt(path, np.column_stack([v, theta]), delimiter=",", header="vib,angle",
               comments="")
    # the column as diagnose_file's caller names it ("--signal 'vib'" on the command line)
    with pytest.raises(InputError, match=r"signals 'vib': .*first at index 123"):
        diagnose_file(path, signals="vib", fs=FS, angle="angle", teeth=Z)


def test_diagnose_input_checks(measured):
    _, theta, v, _ = measured
    with pytest.raises(InputError, match="signals"):
        diagnose({}, teeth=Z, angle=theta)
    with pytest.raises(InputError, match="equal length"):
        diagnose({"a": v, "b": v[:-1]}, teeth=Z, angle=theta)
    with pytest.raises(InputError, match="residual_preset"):
        diagnose({"a": v}, teeth=Z, angle=theta, samples_per_rev=512, residual_preset="x")


def test_signals_too_large_for_their_squares_are_refused():
    """The PWVD and energies are in unit^2: a signal beyond 1e150 cannot be represented."""
    import numpy as np
    import pytest

    from geardyn.diagnostics import diagnose
    from geardyn.errors import InputError

    th = np.linspace(0, 8 * np.pi, 4000)
    with pytest.raises(InputError, match="1e\\+?150"):
        diagnose({"x": 1e200 * np.cos(23 * th)}, teeth=23, angle=th, fs=1000.0)
