"""NetCDF-4 through netCDF4 where it is installed, h5netcdf otherwise (geardyn.io.netcdf_engine).

The two engines must give files either one reads back identically: a run record as
``geardyn run`` writes it (compressed, float32 variables), a file with groups as
``results.nc`` is, and the files of the CLI's writer. The fallback is exercised with netCDF4's
import blocked and with its HDF5 clashing with h5py's. Tests that write through netCDF4 are
skipped where the two clash (importing it would break h5py in this process).
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import xarray as xr

from geardyn import io
from geardyn.errors import DataFileError


def needs_netcdf4() -> None:
    """Skip unless netCDF4 is installed and can live beside h5py in this process."""
    pytest.importorskip("netCDF4")
    if io.hdf5_libraries_clash():
        pytest.skip("netCDF4's HDF5 clashes with h5py's here (geardyn uses h5netcdf)")


@pytest.fixture
def engine(monkeypatch):
    """Set the engine geardyn uses (the choice is cached per process: cleared before, after)."""
    io.netcdf_engine.cache_clear()

    def use(name: str) -> None:
        io.netcdf_engine.cache_clear()
        if name == "h5netcdf":
            monkeypatch.setitem(sys.modules, "netCDF4", None)  # import netCDF4 -> ImportError
        else:
            monkeypatch.delitem(sys.modules, "netCDF4", raising=False)
            needs_netcdf4()
        assert io.netcdf_engine() == name

    yield use
    monkeypatch.undo()
    io.netcdf_engine.cache_clear()


def record() -> xr.Dataset:
    """A small simulation-record-like dataset: a time coordinate, float64 signals with units,
    a variable stored as float32, scalar and text attributes."""
    t = np.arange(0.0, 0.02, 1e-5)
    rng = np.random.default_rng(3)
    ds = xr.Dataset(
        {"theta_p": ("time", np.cumsum(rng.normal(size=t.size)),
                     {"units": "rad", "long_name": "pinion angle"}),
         "v_yg": ("time", rng.normal(size=t.size), {"units": "m/s", "long_name": "velocity"}),
         "mesh_stiffness": ("time", 3e8 + rng.normal(size=t.size),
                            {"units": "N/m", "long_name": "mesh stiffness"})},
        coords={"time": ("time", t, {"units": "s", "long_name": "time"})},
        attrs={"pinion_teeth": 19, "dt": 1e-5, "case_toml": "[pinion]\nteeth = 19\n",
               "model": "II"})
    return ds


def test_netcdf4_is_the_engine_where_it_is_installed(engine):
    engine("netcdf4")
    assert io.netcdf_versions()["engine"] == "netcdf4"
    assert {"netCDF4", "netcdf-c", "hdf5"} <= set(io.netcdf_versions())


def test_without_netcdf4_h5netcdf_writes_and_reads(engine, tmp_path):
    engine("h5netcdf")
    assert io.netcdf_versions()["engine"] == "h5netcdf"
    assert {"h5netcdf", "h5py", "hdf5"} <= set(io.netcdf_versions())
    ds = record()
    io.write_netcdf_atomic(ds, tmp_path / "r.nc")
    xr.testing.assert_identical(io.read_netcdf(tmp_path / "r.nc", required=["v_yg"]), ds)
    assert "netCDF4" not in sys.modules or sys.modules["netCDF4"] is None


@pytest.mark.parametrize("writer, reader", [("netcdf4", "h5netcdf"), ("h5netcdf", "netcdf4")])
def test_a_run_file_of_either_engine_reads_the_same_with_the_other(monkeypatch, tmp_path,
                                                                   writer, reader):
    needs_netcdf4()
    from geardyn.studies.paper import write_run_netcdf

    ds = record()
    monkeypatch.setattr(io, "netcdf_engine", lambda: writer)
    write_run_netcdf(ds, tmp_path / "run.nc")  # compressed; mesh_stiffness stored as float32
    with xr.open_dataset(tmp_path / "run.nc", engine=reader) as back:
        assert back["mesh_stiffness"].encoding["dtype"] == np.float32
        assert back["v_yg"].encoding["zlib"] and back["v_yg"].encoding["shuffle"]
        assert back["v_yg"].encoding["complevel"] == 1  # io.NETCDF_COMPRESSION
        expected = ds.assign(mesh_stiffness=ds["mesh_stiffness"].astype(np.float32)
                             .astype(np.float64))
        xr.testing.assert_identical(back.load(), expected)


@pytest.mark.parametrize("writer, reader", [("netcdf4", "h5netcdf"), ("h5netcdf", "netcdf4")])
def test_groups_written_by_either_engine_read_the_same(tmp_path, writer, reader):
    needs_netcdf4()
    root = xr.Dataset({"table": ("row", np.arange(4.0))}, attrs={"title": "tables"})
    group = record()
    path = tmp_path / "results.nc"
    root.to_netcdf(path, engine=writer, mode="w")
    group.to_netcdf(path, engine=writer, mode="a", group="diagnostics/model_II")
    with xr.open_dataset(path, engine=reader) as a, \
            xr.open_dataset(path, engine=reader, group="diagnostics/model_II") as b:
        xr.testing.assert_identical(a.load(), root)
        xr.testing.assert_identical(b.load(), group)


@pytest.mark.parametrize("writer, reader", [("netcdf4", "h5netcdf"), ("h5netcdf", "netcdf4")])
def test_root_attributes_set_afterwards_read_as_if_written_with_the_file(engine, tmp_path,
                                                                          writer, reader):
    """:func:`geardyn.io.set_netcdf_attrs` (results.nc's summary, set on a cached copy): the
    file reads, with either engine, as the same datasets written with the attribute."""
    needs_netcdf4()
    engine(writer)
    summary = json.dumps({"run_time_s": {"stiffness": 0.5}, "path": "/tmp/x \u03b8",
                          "long": "y" * 70_000})  # past HDF5's 64 kB compact attribute limit
    root = xr.Dataset({"table": ("row", np.arange(4.0))}, attrs={"title": "tables",
                                                                 "summary_json": "old"})
    group = record()
    path = tmp_path / "results.nc"
    io.to_netcdf(root.drop_attrs(), path, mode="w")
    io.to_netcdf(group, path, mode="a", group="diagnostics/model_II")
    io.set_netcdf_attrs(path, {"title": "tables", "summary_json": "old"})
    io.set_netcdf_attrs(path, {"summary_json": summary})  # replaces an existing attribute
    engine(reader)  # (h5netcdf as the writer blocked the import of netCDF4)
    with xr.open_dataset(path, engine=reader) as a, \
            xr.open_dataset(path, engine=reader, group="diagnostics/model_II") as b:
        xr.testing.assert_identical(a.load(), root.assign_attrs(summary_json=summary))
        xr.testing.assert_identical(b.load(), group)


def test_with_clashing_hdf5_libraries_netcdf4_is_not_even_imported(tmp_path):
    code = textwrap.dedent(f"""
        import sys
        import xarray as xr
        from geardyn import io
        io.hdf5_libraries_clash = lambda: True
        ds = xr.Dataset({{"a": ("t", [1.0, 2.0])}}, attrs={{"x": 1}})
        io.write_netcdf_atomic(ds, {str(tmp_path / "c.nc")!r})
        assert io.read_netcdf({str(tmp_path / "c.nc")!r}).identical(ds)
        print(io.netcdf_engine(), "netCDF4" in sys.modules)
    """)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout.split() == ["h5netcdf", "False"]


def test_the_clash_is_the_same_hdf5_library_file_in_both_wheels(tmp_path, monkeypatch):
    # the wheels' layout: <site>/<pkg>/ and <site>/<pkg>.libs/ (auditwheel, delvewheel), or
    # <site>/<pkg>/.dylibs/ (delocate); file names carry a hash of the library
    site = tmp_path / "site"
    for pkg, libs in {"ncpkg": ["libhdf5-7b49ac63.so.310.2.0", "libhdf5_hl-123198ff.so.310.0.2",
                                "libnetcdf-6ebc343d.so.19", "libsz-b66d1717.so.2.0.1"],
                      "h5pkg": ["libhdf5-7f639dcd.so.310.2.0", "libhdf5_hl-123198ff.so.310.0.2",
                                "libsz-b66d1717.so.2.0.1"],
                      "h5other": ["libhdf5-9e18f0c6.so.320.0.0", "libhdf5_hl-69da89c9.so.320.0.0",
                                  "libsz-b66d1717.so.2.0.1"],
                      "macpkg": []}.items():
        (site / pkg).mkdir(parents=True)
        (site / pkg / "__init__.py").write_text("")
        folder = site / f"{pkg}.libs"
        folder.mkdir()
        for name in libs:
            (folder / name).write_text("")
    (site / "macpkg" / ".dylibs").mkdir()
    (site / "macpkg" / ".dylibs" / "libhdf5_hl.310.dylib").write_text("")
    monkeypatch.syspath_prepend(str(site))
    assert io._bundled_hdf5("ncpkg") == {"libhdf5-7b49ac63.so.310.2.0",
                                         "libhdf5_hl-123198ff.so.310.0.2"}
    assert io._bundled_hdf5("h5pkg") & io._bundled_hdf5("ncpkg") == {
        "libhdf5_hl-123198ff.so.310.0.2"}  # (libsz alone is no clash: no HDF5 state)
    assert not io._bundled_hdf5("h5other") & io._bundled_hdf5("ncpkg")
    assert io.hdf5_libraries_clash("ncpkg", "h5pkg")
    assert not io.hdf5_libraries_clash("ncpkg", "h5other")
    assert not io.hdf5_libraries_clash("ncpkg", "no_such_package_here")
    assert io._bundled_hdf5("macpkg") == {"libhdf5_hl.310.dylib"}
    assert io._bundled_hdf5("no_such_package_here") == set()


def test_a_netcdf3_file_is_read_through_netcdf4(tmp_path):
    # NetCDF-3 (classic) has no HDF5 container: netCDF-C reads it, h5netcdf cannot
    needs_netcdf4()
    ds = record()
    path = tmp_path / "classic.nc"
    ds.to_netcdf(path, engine="netcdf4", format="NETCDF3_64BIT")
    with pytest.raises(OSError):  # h5py: not an HDF5 file
        xr.open_dataset(path, engine="h5netcdf")
    xr.testing.assert_identical(io.read_netcdf(path), ds)


def test_a_file_neither_engine_opens_is_a_data_file_error(tmp_path):
    bad = tmp_path / "bad.nc"
    bad.write_bytes(b"CDF\x05 not really a NetCDF file")
    with pytest.raises(DataFileError, match="is not a readable NetCDF-4 file"):
        io.read_netcdf(bad)


def test_a_netcdf3_measurement_is_read_as_data(tmp_path):
    # a DAQ's NetCDF-3 file: read by netCDF-C (h5netcdf alone could not open it)
    needs_netcdf4()
    from geardyn.diagnostics.io import read_table

    t = np.arange(0.0, 0.1, 1e-4)
    acc = np.sin(2 * np.pi * 170 * t)
    ds = xr.Dataset({"acc": ("time", acc, {"units": "m/s^2"})}, coords={"time": t},
                    attrs={"fs": 1e4, "title": "DAQ record"})
    path = tmp_path / "daq.nc"
    ds.to_netcdf(path, engine="netcdf4", format="NETCDF3_CLASSIC")
    table = read_table(path)
    np.testing.assert_array_equal(table.columns["acc"], acc)
    np.testing.assert_array_equal(table.columns["time"], t)
    assert table.scalars["fs"] == 1e4 and table.units["acc"] == "m/s^2"
    assert table.text["title"] == "DAQ record"


def test_threads_writing_and_reading_at_once_do_not_crash(tmp_path):
    # netCDF-C is not thread-safe: without geardyn.io.NETCDF_LOCK this crashed the process
    # (a segmentation fault) in each of several tries; in a subprocess, so a crash fails here
    code = textwrap.dedent(f"""
        import threading
        from pathlib import Path
        import numpy as np, xarray as xr
        from geardyn import io
        d = Path({str(tmp_path)!r})
        ds = xr.Dataset({{f"v{{i}}": ("t", np.arange(50.0) * i, {{"units": "m"}})
                         for i in range(20)}}, coords={{"t": np.arange(50.0)}}, attrs={{"a": 1}})
        io.write_netcdf_atomic(ds, d / "shared.nc")
        errors = []
        def work(k):
            try:
                for i in range(30):
                    io.write_netcdf_atomic(ds, d / f"w{{k}}_{{i}}.nc")
                    assert io.read_netcdf(d / "shared.nc").identical(ds)
            except Exception as exc:
                errors.append(repr(exc))
        threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert not errors, errors
        print("engine", io.netcdf_engine())
    """)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, (r.returncode, r.stderr[-2000:])
    assert "engine" in r.stdout
