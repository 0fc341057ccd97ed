"""Bounded work: how many time steps a simulation may take, checked before it starts.

A light module (no NumPy, no compiled kernel) so that the command-line tool refuses a run that
would not end, or whose record would not fit in memory, within a second of starting:
:func:`check_bounded_work`, which :func:`geardyn.dynamics.simulate` also calls first thing.
"""

from __future__ import annotations

import math

from .errors import InputError

__all__ = ["DEFAULT_MAX_STEPS", "RECORD_VARIABLES", "check_step_count", "check_bounded_work",
           "check_record_size"]

#: Default of ``simulation.max_steps`` [-]: 1e8 steps, minutes to an hour of kernel time.
DEFAULT_MAX_STEPS = 1e8

#: Variables the time-step kernel records per sample, from which a record's size is estimated
#: before the run: ``geardyn.dynamics._kernel.N_REC``, the record's columns (that module
#: refuses to load if they differ).
RECORD_VARIABLES = 20


def check_step_count(sim) -> int:
    """Refuse a simulation of more than ``sim.max_steps`` time steps.

    Parameters
    ----------
    sim : geardyn.config.SimulationConfig
        ``dt``, ``settle_time``, ``record_time`` [s] and ``max_steps`` [-].

    Returns
    -------
    int
        The number of steps, ``(settle_time + record_time) / dt`` rounded.

    Raises
    ------
    InputError
        Naming the times, the estimate, the limit and how to raise it.
    """
    limit = float(getattr(sim, "max_steps", DEFAULT_MAX_STEPS))
    try:
        steps = (float(sim.settle_time) + float(sim.record_time)) / float(sim.dt)
    except (OverflowError, ZeroDivisionError):
        steps = math.inf
    if not math.isfinite(steps) or steps > limit:
        # whole numbers, not 3 digits: 1.0005e8 steps against 1e8 read "1e+08" on both sides
        count = f"{steps:,.0f}" if math.isfinite(steps) and steps < 1e15 else f"{steps:.3g}"
        raise InputError(
            "simulation.settle_time, simulation.record_time, simulation.dt",
            f"{count} time steps ((settle {sim.settle_time:.4g} s + record "
            f"{sim.record_time:.4g} s) / dt {sim.dt:.4g} s)",
            f"at most simulation.max_steps = {limit:,.0f} steps; raise simulation.max_steps "
            "(e.g. --set simulation.max_steps=1e9) to run it anyway, or lengthen simulation.dt "
            "or shorten the times")
    return int(round(steps))


def check_bounded_work(case) -> int:
    """Refuse, before any work, a simulation whose step count or record would not fit.

    The step count is ``(settle_time + record_time) / dt``; it must not exceed
    ``simulation.max_steps`` (default 1e8, a few minutes to an hour of kernel time;
    :func:`check_step_count`). The record must fit in memory (:func:`check_record_size`).
    Here, not beside the kernel, so that ``geardyn run`` checks its case without importing
    numba: the first process imports it after its FE bodies, whose factorisations are the peak
    of a run's memory (numba: about 53 MB, 2026-11-27). Also
    :func:`geardyn.dynamics.newmark.check_bounded_work`.

    Parameters
    ----------
    case : geardyn.config.Case

    Returns
    -------
    int
        Total number of time steps.

    Raises
    ------
    InputError
        Naming the times, the estimate and the limit, and how to raise it.
    """
    sim = case.simulation
    steps = check_step_count(sim)
    n_record = max(1, int(round(sim.record_time / sim.dt)))
    check_record_size(-(-n_record // sim.decimation), sim)
    return steps


def check_record_size(count: int, sim) -> None:
    """Refuse a record of ``count`` samples that would not fit in memory (limit
    ``$GEARDYN_MAX_RECORD_GB``, default 8 GB, about 4 times the record itself once it becomes
    a Dataset)."""
    import os

    limit_gb = float(os.environ.get("GEARDYN_MAX_RECORD_GB", "8"))
    need_gb = 4 * count * RECORD_VARIABLES * 8 / 1e9
    if need_gb > limit_gb:
        raise InputError(
            "simulation.record_time", sim.record_time,
            f"a record that fits in memory: {count} samples x {RECORD_VARIABLES} variables needs "
            f"about {need_gb:.3g} GB (limit {limit_gb:g} GB, set by GEARDYN_MAX_RECORD_GB); raise "
            "simulation.decimation, lengthen simulation.dt or shorten simulation.record_time")
