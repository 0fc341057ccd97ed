"""Saving and summarising simulation records (xarray Datasets from :func:`simulate`)."""

from __future__ import annotations

import math
import os

import numpy as np

__all__ = ["save_netcdf", "save_mat", "summary"]


def save_netcdf(ds, path: str | os.PathLike) -> None:
    """Write a record to NetCDF-4 atomically (:func:`geardyn.io.write_netcdf_atomic`)."""
    from ..io import write_netcdf_atomic

    write_netcdf_atomic(ds, path)


def save_mat(ds, path: str | os.PathLike) -> None:
    """Write a record to a MATLAB ``.mat`` file (v5) atomically.

    Each data variable and ``time`` becomes a column vector of the same name; ``units`` is a
    struct of the unit strings and ``attrs`` a struct of the dataset attributes.
    """
    from scipy.io import savemat

    from ..io import atomic_path

    out: dict[str, object] = {"time": np.asarray(ds["time"].values, dtype=float)[:, None]}
    units = {"time": "s"}
    for name, var in ds.data_vars.items():
        out[name] = np.asarray(var.values, dtype=float)[:, None]
        units[name] = str(var.attrs.get("units", ""))
    out["units"] = units
    out["attrs"] = {k: (v if isinstance(v, str | int | float) else str(v))
                    for k, v in ds.attrs.items()}
    if "geardyn_inputs" in ds.attrs:  # which record this is a copy of (a rerun checks it)
        from ..io import COPY_STAMP, inputs_sha256

        out["attrs"][COPY_STAMP] = inputs_sha256(ds.attrs["geardyn_inputs"])
    with atomic_path(path, suffix=".mat") as tmp:
        with open(tmp, "wb") as fh:
            # long_field_names: attribute names such as static_centre_distance_change_units
            # pass MATLAB 5's 31 characters (MATLAB 7.6+ reads up to 63)
            savemat(fh, out, do_compression=True, oned_as="column", long_field_names=True)


def summary(ds) -> dict[str, float]:
    """Means and ranges of the main quantities of a record (SI; unit in each key).

    Returns
    -------
    dict
        ``mean_pinion_speed_rad_s``, ``mean_mesh_force_N``, ``mean_centre_distance_change_m``,
        ``mean_pressure_angle_deg``, ``mean_contact_ratio``, ``mean_contact_ratio_eq8``,
        ``mean_transmission_error_rad``, ``std_transmission_error_rad``,
        ``separation_fraction``, ``steps_iterating_fraction``, ``max_iterations``,
        ``max_residual_before_m``, ``max_residual_after_m``.
    """
    def mean(name: str) -> float:
        return float(np.nanmean(ds[name].values)) if ds.sizes["time"] else math.nan

    it = np.asarray(ds["iterations"].values)
    rb = np.asarray(ds["residual_before"].values)
    ra = np.asarray(ds["residual_after"].values)
    return {
        "mean_pinion_speed_rad_s": mean("omega_p"),
        "mean_mesh_force_N": mean("mesh_force"),
        "mean_centre_distance_change_m": mean("centre_distance_change"),
        "mean_pressure_angle_deg": math.degrees(mean("pressure_angle")),
        "mean_contact_ratio": mean("contact_ratio"),
        "mean_contact_ratio_eq8": mean("contact_ratio_eq8"),
        "mean_transmission_error_rad": mean("transmission_error"),
        "std_transmission_error_rad": float(np.std(ds["transmission_error"].values))
        if ds.sizes["time"] else math.nan,
        "separation_fraction": float(1.0 - np.mean(ds["contact"].values))
        if ds.sizes["time"] else math.nan,
        "steps_iterating_fraction": float(np.mean(it > 0)) if it.size else math.nan,
        "max_iterations": int(it.max()) if it.size else 0,
        "max_residual_before_m": float(np.nanmax(rb)) if np.any(np.isfinite(rb)) else math.nan,
        "max_residual_after_m": float(np.nanmax(ra)) if np.any(np.isfinite(ra)) else math.nan,
    }
