"""The file a DAQ writes: channels, tachometer, sample rate, units and provenance.

Layout (the same in the three formats, so each reads like measured data):

* ``time`` [s] from 0 at the first sample;
* ``acc`` [m/s^2] and ``acc_g`` [g] (the same channel in two units; ``g = 9.80665 m/s^2``);
* ``tach`` [V], the sampled tachometer pulse train;
* ``fs`` [Hz], the sample rate (a global attribute in NetCDF, a scalar variable in ``.mat``, a
  ``# fs = ... Hz`` comment line in CSV).

NetCDF-4 carries ``units`` and ``long_name`` on every variable and the provenance in
global attributes (case TOML, seeds, chain settings, geardyn version). CSV has a ``#`` comment
header with the same provenance in short and a header row of column names; ``.mat`` (v5) has one
column vector per channel, ``fs``, and structs ``units`` and ``attrs``.

``geardyn diagnose FILE --signal acc --tach tach --teeth 23`` reads any of them (``--fs`` is
found in the ``.mat`` and ``.nc`` files; for CSV pass ``--fs`` or ``--time time``).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .chain import Measured
from .sensor import G_N

__all__ = ["to_dataset", "write_netcdf", "write_csv", "write_mat", "CHANNELS"]

#: Channel name -> (units, long name).
CHANNELS = {
    "acc": ("m/s^2", "housing acceleration at the sensor"),
    "acc_g": ("g", "housing acceleration at the sensor, in standard gravities (9.80665 m/s^2)"),
    "tach": ("V", "tachometer pulse train"),
}


#: Units of the record's numeric attributes, written beside each as ``<name>_units`` (a user
#: audit of 2026-11-27 found only ``fs`` with its unit).
ATTRIBUTE_UNITS = {"input_sample_rate": "Hz", "lead_in": "s", "tail": "s", "noise_rms": "m/s^2",
                   "clipped_samples": "1", "clipped_fraction": "1", "snr_requested": "dB",
                   "accelerometer_resonance": "Hz", "tach_jitter": "s",
                   "start_time_in_simulation": "s", "sample_rate": "Hz"}


def to_dataset(m: Measured, attrs: dict | None = None):
    """An xarray Dataset of a measurement (layout in the module docstring).

    Parameters
    ----------
    m : Measured
        The chain's output.
    attrs : dict, optional
        Extra global attributes (provenance); values str, int or float.
    """
    import xarray as xr

    data = {
        "acc": ("time", m.acc, _attrs("acc")),
        "acc_g": ("time", m.acc / G_N, _attrs("acc_g")),
        "tach": ("time", m.tach, _attrs("tach")),
    }
    ga = {"fs": float(m.fs), "fs_units": "Hz", "sample_rate": float(m.fs),
          "title": "housing accelerometer and tachometer record"}
    for k, v in m.info.items():
        ga[k] = v if isinstance(v, str | int | float) else str(v)
    ga.update(attrs or {})
    for key, unit in ATTRIBUTE_UNITS.items():  # as "fs_units": every number with its unit
        if isinstance(ga.get(key), int | float) and not isinstance(ga.get(key), bool):
            ga[f"{key}_units"] = unit
    return xr.Dataset(data, coords={"time": ("time", m.time, {"units": "s",
                                                             "long_name": "time from the "
                                                                          "first sample"})},
                      attrs=ga)


def _attrs(name: str) -> dict:
    u, long = CHANNELS[name]
    return {"units": u, "long_name": long}


def write_netcdf(ds, path: str | os.PathLike) -> None:
    """Write the record to NetCDF-4 atomically."""
    from ..io import write_netcdf_atomic

    write_netcdf_atomic(ds, path)


def write_csv(ds, path: str | os.PathLike) -> None:
    """Write ``time, acc, acc_g, tach`` as CSV with a ``#`` provenance header, atomically."""
    from ..io import COPY_STAMP, inputs_sha256, write_text_atomic

    lines = [f"# fs = {float(ds.attrs['fs']):.17g} Hz"]
    for k in ("title", "case", "pinion_teeth", "gear_teeth", "noise_seed", "snr_requested",
              "noise_rms", "clipped_samples", "tach_shaft", "tach_pulses_per_rev",
              "geardyn_version"):
        if k in ds.attrs:
            lines.append(f"# {k} = {ds.attrs[k]}")
    if "geardyn_inputs" in ds.attrs:  # which record this is a copy of (a rerun checks it)
        lines.append(f"# {COPY_STAMP} = {inputs_sha256(ds.attrs['geardyn_inputs'])}")
    names = ["time", "acc", "acc_g", "tach"]
    lines.append("# units: " + ", ".join(
        f"{n} [{ds[n].attrs.get('units', '')}]" for n in names))
    lines.append(",".join(names))
    cols = np.column_stack([np.asarray(ds[n].values, dtype=float) for n in names])
    import io

    buf = io.StringIO()
    np.savetxt(buf, cols, delimiter=",", fmt="%.17g")
    write_text_atomic(path, "\n".join(lines) + "\n" + buf.getvalue())


def write_mat(ds, path: str | os.PathLike) -> None:
    """Write the record to a MATLAB v5 ``.mat`` file atomically: channels as column vectors,
    ``fs`` [Hz] as a scalar, ``units`` and ``attrs`` as structs of strings."""
    from scipy.io import savemat

    from ..io import atomic_path

    out: dict[str, object] = {n: np.asarray(ds[n].values, dtype=float)[:, None]
                              for n in ("time", "acc", "acc_g", "tach")}
    out["fs"] = float(ds.attrs["fs"])
    out["units"] = {n: str(ds[n].attrs.get("units", "")) for n in ("time", "acc", "acc_g", "tach")}
    # NumPy scalars (a record read back from its NetCDF file) as the numbers they hold
    attrs = {k: (v.item() if isinstance(v, np.generic) else v) for k, v in ds.attrs.items()}
    out["attrs"] = {k: (v if isinstance(v, str | int | float) else str(v))
                    for k, v in attrs.items()}
    if "geardyn_inputs" in attrs:  # which record this is a copy of (a rerun checks it)
        from ..io import COPY_STAMP, inputs_sha256

        out["attrs"][COPY_STAMP] = inputs_sha256(attrs["geardyn_inputs"])
    with atomic_path(Path(path), suffix=".mat") as tmp, open(tmp, "wb") as fh:
        savemat(fh, out, do_compression=True, oned_as="column", long_field_names=True)
