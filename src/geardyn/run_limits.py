"""Bounded work: how many time steps a simulation may take, checked before it starts.

A light module (no NumPy, no compiled kernel) so that the command-line tool refuses a run that
would not end within a second of starting; :func:`geardyn.dynamics.newmark.check_bounded_work`
(called first thing by :func:`geardyn.dynamics.simulate`) uses it and adds the record-size check.
"""

from __future__ import annotations

import math

from .errors import InputError

__all__ = ["DEFAULT_MAX_STEPS", "check_step_count"]

#: Default of ``simulation.max_steps`` [-]: 1e8 steps, minutes to an hour of kernel time.
DEFAULT_MAX_STEPS = 1e8


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
        raise InputError(
            "simulation.settle_time, simulation.record_time, simulation.dt",
            f"{steps:.3g} time steps ((settle {sim.settle_time:.4g} s + record "
            f"{sim.record_time:.4g} s) / dt {sim.dt:.4g} s)",
            f"at most simulation.max_steps = {limit:.3g} steps; raise simulation.max_steps "
            "(e.g. --set simulation.max_steps=1e9) to run it anyway, or lengthen simulation.dt "
            "or shorten the times")
    return int(round(steps))
