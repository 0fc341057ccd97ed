"""Dynamics of the flexibly supported gear pair: model I and model II of Xue & Howard (2018).

* :mod:`.model`: the 6-DOF model (eqs. 9-17, appendix B), load laws, static equilibrium, natural
  frequencies and the time-step check.
* :mod:`.newmark`: :func:`simulate` (Newmark / HHT in residual form, the model II centre-distance
  iteration of the paper's Fig. 7) and the low-level kernel interface.
* :mod:`.results`: NetCDF / MATLAB output and a summary of a record.
"""

from __future__ import annotations

from .model import (
    DynamicModel,
    StaticState,
    TorqueLaw,
    check_time_step,
    max_time_step,
    natural_frequencies,
    operating_arrays,
    static_equilibrium,
)
from .newmark import initial_state, make_setup, run_steps, simulate
from .results import save_mat, save_netcdf, summary

__all__ = [
    "simulate",
    "DynamicModel",
    "StaticState",
    "TorqueLaw",
    "static_equilibrium",
    "natural_frequencies",
    "max_time_step",
    "check_time_step",
    "operating_arrays",
    "make_setup",
    "initial_state",
    "run_steps",
    "save_netcdf",
    "save_mat",
    "summary",
]
