"""NetCDF-4 files: a simulation record written and read by geardyn's engine (netCDF4 where it is
installed, :func:`geardyn.io.netcdf_engine`) against h5netcdf, the engine before 2026-11-27.

Rows (all measured in this run, best of five):

* writing one record as ``geardyn run`` writes ``runs/model_II_cracked.nc``
  (:func:`geardyn.studies.paper.write_run_netcdf`: 25 variables, zlib level 4 with shuffle,
  six of them stored as float32), netCDF4 against h5netcdf;
* reading it back fully (:func:`geardyn.io.read_netcdf`, as ``geardyn diagnose`` and the map
  cache read their files), each engine reading the file it wrote;
* a ``geardyn simulate`` of a few steps through the CLI in this process (a PEM map from the
  cache; the command writes one NetCDF file and reads the map's), as the fuzz tests run it
  hundreds of times;
* the machine and the load average.

The record is the paper's case, model II, cracked, PEM map, 0.5 s recorded (``--quick``:
0.1 s). Run: ``python benchmarks/run.py netcdf``.
"""

from __future__ import annotations

import sys
import tempfile
import warnings
from pathlib import Path
from unittest import mock

from _common import Row, best_time, machine
from _common import load_average as _load

ROOT = Path(__file__).resolve().parents[1]


def run(quick: bool) -> list[Row]:
    sys.path.insert(0, str(ROOT))
    import geardyn
    from geardyn import io
    from geardyn.dynamics import simulate
    from geardyn.stiffness import build_map
    from geardyn.studies.paper import write_run_netcdf

    if io.netcdf_engine() != "netcdf4":
        return [Row("NetCDF: netCDF4 is not installed here (h5netcdf writes and reads)",
                    float("nan"), "s")]
    record = 0.1 if quick else 0.5
    case = geardyn.paper_case(['stiffness.method="pem"', f"simulation.record_time={record}",
                               "simulation.settle_time=0.05"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        smap = build_map(case, cracked=True)  # cached after the first run
        ds = simulate(case, smap)
    tmp = Path(tempfile.mkdtemp())
    times = {}
    load0 = _load()
    for engine in ("netcdf4", "h5netcdf"):
        path = tmp / f"{engine}.nc"
        with mock.patch.object(io, "netcdf_engine", lambda e=engine: e):
            times[engine, "write"] = best_time(lambda p=path: write_run_netcdf(ds, p), repeat=5)
            times[engine, "read"] = best_time(lambda p=path: io.read_netcdf(p), repeat=5)

    from typer.testing import CliRunner

    from geardyn.cli import app

    runner = CliRunner()
    args = ["simulate", "--force", "--out", str(tmp / "s.nc"), "--set",
            "simulation.record_time=0.002 s", "--set", "simulation.settle_time=0.001 s",
            "--set", "stiffness.method=pem", "--set", "stiffness.centre_distances=11"]
    for engine in ("netcdf4", "h5netcdf"):
        with mock.patch.object(io, "netcdf_engine", lambda e=engine: e):
            runner.invoke(app, args)  # the map into the cache, the command's imports
            times[engine, "cli"] = best_time(lambda: runner.invoke(app, args), repeat=5)
    load1 = _load()
    n = ds.sizes["time"]
    nvar = len(ds.data_vars)
    return [
        Row(f"write one run record ({nvar} variables x {n} samples, compressed), netCDF4",
            times["netcdf4", "write"], "s", "h5netcdf", times["h5netcdf", "write"], "", None),
        Row("read it back fully (geardyn.io.read_netcdf), netCDF4", times["netcdf4", "read"], "s",
            "h5netcdf", times["h5netcdf", "read"], "", None),
        Row("`geardyn simulate` of a few steps, in process (one file written, the map read), "
            "netCDF4", times["netcdf4", "cli"], "s", "h5netcdf", times["h5netcdf", "cli"], "",
            None),
        Row(f"machine: {machine()}; 1-min load average before the timing (baseline column) "
            "and after it", load1, "load", "before", load0, "", None),
    ]
