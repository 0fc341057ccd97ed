r"""How much of the model I / model II difference the static centre-distance shift explains.

Model I evaluates the mesh stiffness at the design centre distance, model II at the operating
centre distance iterated every step (Xue & Howard 2018, Fig. 7), and model I-static at the static
operating centre distance of eq. 4, held fixed (:func:`geardyn.dynamics.simulate`). Model II
differs from model I-static only through the *dynamics* of the centre distance; it differs from
model I through those dynamics *and* the static shift of the operating point. Comparing the
three records signal by signal therefore splits the II - I difference into the part the static
shift explains and the part only the iterated model gives (issue 18 of the project).

:func:`compare_models` is a pure function of three records (no simulation, no file access).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError

__all__ = ["compare_models", "DEFAULT_SIGNALS"]

#: Signals compared by default: the paper's measured quantities (gear centre velocity, pinion
#: speed, transmission error) and the mesh and bearing quantities that carry the difference.
DEFAULT_SIGNALS = ("transmission_error", "mesh_force", "mesh_deflection", "mesh_stiffness",
                   "y_p", "y_g", "v_yp", "v_yg", "omega_p", "omega_g")


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(x * x))) if x.size else float("nan")


def compare_models(model_i, model_i_static, model_ii, signals=DEFAULT_SIGNALS):
    r"""Per signal, how close model I-static and model I come to model II.

    For each signal ``s`` with ``II``, ``I``, ``Is`` the three records of it:

    * ``rms_ii_minus_i_static = RMS(II - Is) / STD(II)``,
    * ``rms_ii_minus_i = RMS(II - I) / STD(II)``,
    * ``explained_fraction = 1 - RMS(II - Is) / RMS(II - I)``: the share (in RMS) of the model
      I / II difference that holding the stiffness at the static operating centre distance
      removes. 1: the static shift explains it all; 0: none of it; negative: I-static is further
      from II than model I is.

    RMS of a difference includes its mean (a static offset counts), ``STD`` is the population
    standard deviation of model II's signal about its mean. A zero denominator gives NaN.

    Parameters
    ----------
    model_i, model_i_static, model_ii : xarray.Dataset
        Records of :func:`geardyn.dynamics.simulate` with ``model = "I"``, ``"I-static"`` and
        ``"II"`` of the same case (same time samples).
    signals : sequence of str
        Data variables to compare (default :data:`DEFAULT_SIGNALS`).

    Returns
    -------
    xarray.Dataset
        Dimension ``signal`` (coordinate with ``signal_units``, each signal's unit); variables
        ``rms_ii_minus_i_static``, ``rms_ii_minus_i`` and ``explained_fraction`` (dimensionless,
        ``units = "1"``), each with ``long_name``.

    Raises
    ------
    InputError
        A record of another model, records on different time samples, or a signal missing.
    """
    import xarray as xr

    records = {"I": model_i, "I-static": model_i_static, "II": model_ii}
    for name, ds in records.items():
        got = ds.attrs.get("model")
        if got != name:
            raise InputError(f"model {name} record", got, f"a record of model {name} "
                                                          "(attribute model)")
    t = np.asarray(model_ii["time"].values, dtype=float)
    for name in ("I", "I-static"):
        ti = np.asarray(records[name]["time"].values, dtype=float)
        if ti.shape != t.shape or not np.allclose(ti, t, rtol=0.0,
                                                  atol=1e-9 * (abs(t).max() if t.size else 1.0)):
            raise InputError(f"model {name} record", f"{ti.size} samples",
                             f"the {t.size} time samples of the model II record (same case)")
    signals = tuple(signals)
    for s in signals:
        for name, ds in records.items():
            if s not in ds.data_vars:
                raise InputError("signals", s, f"data variables of the model {name} record: "
                                               + ", ".join(sorted(ds.data_vars)))
    rows = []
    for s in signals:
        a2, a1, a1s = (np.asarray(records[m][s].values, dtype=float) for m in ("II", "I",
                                                                               "I-static"))
        std = float(np.std(a2)) if a2.size else float("nan")
        d_s, d_1 = _rms(a2 - a1s), _rms(a2 - a1)
        with np.errstate(divide="ignore", invalid="ignore"):
            rows.append((np.float64(d_s) / std, np.float64(d_1) / std,
                         1.0 - np.float64(d_s) / np.float64(d_1)))
    arr = np.array(rows, dtype=float).reshape(len(signals), 3)
    units = [str(model_ii[s].attrs.get("units", "")) for s in signals]
    coords = {"signal": ("signal", list(signals), {"long_name": "compared record variable"}),
              "signal_units": ("signal", units, {"long_name": "unit of each signal"})}
    data = {
        "rms_ii_minus_i_static": ("signal", arr[:, 0], {
            "units": "1", "long_name": "RMS(model II - model I-static) / STD(model II)"}),
        "rms_ii_minus_i": ("signal", arr[:, 1], {
            "units": "1", "long_name": "RMS(model II - model I) / STD(model II)"}),
        "explained_fraction": ("signal", arr[:, 2], {
            "units": "1", "long_name": "share of the model II - model I difference explained by "
                                       "the static centre-distance shift, 1 - RMS(II - "
                                       "I-static) / RMS(II - I)"}),
    }
    attrs = {"title": "model I and model I-static against model II",
             "case": str(model_ii.attrs.get("title", "")),
             "static_centre_distance_change": float(
                 model_i_static.attrs.get("stiffness_centre_distance_change", np.nan)),
             "static_centre_distance_change_units": "m"}
    return xr.Dataset(data, coords=coords, attrs=attrs)
