"""Measure the example case as a housing accelerometer would, then diagnose the file as measured
data (tachometer channel, nothing else known about where it came from).

Run from the repository root (takes about half a minute; the PEM map is built once and cached)::

    python examples/measure/measure_and_diagnose.py [OUTDIR]
"""

from __future__ import annotations

import sys
from pathlib import Path

from geardyn.config import load_case
from geardyn.diagnostics import diagnose_file
from geardyn.measurement.record import write_netcdf
from geardyn.studies.measure import measure

HERE = Path(__file__).resolve().parent


def main(outdir: Path) -> dict:
    outdir.mkdir(parents=True, exist_ok=True)
    case = load_case(HERE / "case.toml", ['stiffness.method="pem"'])
    result = measure(case)
    path = outdir / "measurement.nc"
    write_netcdf(result.record, path)
    diag = diagnose_file(path, signals=["acc"], tach="tach", teeth=case.pinion.teeth)
    summary = diag.to_dict()["signals"]["acc"]
    print(f"{path}: {result.record.sizes['time']} samples at {result.measured.fs:g} Hz, "
          f"noise RMS {result.measured.noise_rms:.3g} m/s^2")
    print(f"TSA over {summary['n_averages']} revolutions from the tachometer; kurtosis of the "
          f"TSA {summary['kurtosis']['tsa']:.3g}, of the residual "
          f"{summary['kurtosis']['residual']:.3g}")
    return summary


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("geardyn-out/measure-example"))
