"""A cheap, closed-form sweep evaluator for the infrastructure tests.

It stands in for a simulation: the steady-state amplitude of a single-degree-of-freedom
oscillator (the pinion on its bearing) under a harmonic force at the mesh frequency,

    X = F / sqrt((k - m w^2)^2 + (c w)^2),   F = T_in / r_b1,   w = z1 * Omega,
    c = 2 zeta sqrt(k m),

with k, m, zeta the pinion's bearing stiffness, mass and bearing damping ratio, Omega the target
speed ``load.speed``. It builds the gear pair (so bad geometry fails as in a real run), raises
NumericalError above a torque limit (a stand-in for a divergence), and returns one value drawn
from the run's seed. ``sleep`` makes each run take that long [s], for interruption tests.
"""

from __future__ import annotations

import math
import time

import numpy as np

from geardyn.errors import NumericalError
from geardyn.studies.sweep import Evaluator, Output

WAVE = 8


def amplitude(case) -> float:
    """X [m] of the module docstring (independent of the evaluator's code path)."""
    rb = case.pair.module * case.pinion.teeth * math.cos(case.pair.pressure_angle) / 2
    f = case.motor.torque / rb
    k, m = case.pinion.bearing_stiffness, case.pinion.mass
    c = 2 * case.pinion.bearing_damping_ratio * math.sqrt(k * m)
    w = case.pinion.teeth * case.load.speed
    return f / math.sqrt((k - m * w * w) ** 2 + (c * w) ** 2)


class OscillatorEvaluator(Evaluator):
    def __init__(self, sleep: float = 0.0, torque_limit: float = 1e9):
        self.sleep = sleep
        self.torque_limit = torque_limit

    def outputs(self, case, pilot=None):
        return [Output("x__amplitude", "m", "oscillator amplitude"),
                Output("x__static", "m", "static deflection"),
                Output("noise", "1", "a standard normal draw from the run's seed"),
                Output("x__wave", "m", "one period of the response", ("phase",), (WAVE,))]

    def coords(self, case, pilot=None):
        return {"phase": (np.arange(WAVE) * 2 * np.pi / WAVE, {"units": "rad"})}

    def __call__(self, case, seed):
        pair = case.gear_pair()  # geometry errors surface here, as in a real run
        if case.motor.torque > self.torque_limit:
            raise NumericalError("runaway response", time=0.0,
                                 state={"torque": case.motor.torque})
        if self.sleep:
            time.sleep(self.sleep)
        x = amplitude(case)
        f = case.motor.torque / pair.pinion.base_radius
        return {"x__amplitude": x, "x__static": f / case.pinion.bearing_stiffness,
                "noise": float(np.random.default_rng(seed).standard_normal()),
                "x__wave": x * np.sin(np.arange(WAVE) * 2 * np.pi / WAVE)}

    def identity(self):
        return {"evaluator": "tests.sweep._evaluators.OscillatorEvaluator",
                "torque_limit": self.torque_limit}


class FlakyEvaluator(OscillatorEvaluator):
    """Fails (a transient error) while the file ``marker`` exists; the same sweep otherwise."""

    def __init__(self, marker: str):
        super().__init__()
        self.marker = marker

    def __call__(self, case, seed):
        import os

        if os.path.exists(self.marker):
            raise RuntimeError("transient failure (marker present)")
        return super().__call__(case, seed)

    def identity(self):
        return {"evaluator": "tests.sweep._evaluators.OscillatorEvaluator",
                "torque_limit": self.torque_limit}


#: Instances for ``geardyn sweep --evaluator tests.sweep._evaluators:NAME``.
FAST = OscillatorEvaluator()
SLOW = OscillatorEvaluator(sleep=0.15)
