"""``metrics.json``'s ``demodulation.mean_phase_deg``: the demodulated carrier's phase, in
(-180, 180] deg.

Oracle: a mesh carrier ``cos(K theta + phi)`` at the demodulated order ``K`` (the 5th mesh
harmonic by default) whose phase ``phi`` the test sets; the narrowband demodulation's phase is
``phi`` up to the TSA's resampling. Without a carrier at ``K`` the unwrapped phase drifts
(here two turns over the revolution) and its mean meant nothing in degrees: it read 733 deg here
and -346.5 in a user audit of 2026-11-27; it is now at least an angle.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from geardyn.diagnostics import diagnose
from geardyn.diagnostics.pipeline import _wrapped_deg

FS, F_SHAFT, Z = 20_000.0, 20.0, 23
THETA = 2 * np.pi * F_SHAFT * np.arange(int(3 * FS)) / FS


def _mean_phase(x) -> float:
    d = diagnose({"acc": x}, teeth=Z, fs=FS, angle=THETA).to_dict()["signals"]["acc"]
    assert d["demodulation"]["carrier_order"] == 5 * Z
    return d["demodulation"]["mean_phase_deg"]


@pytest.mark.parametrize("phi", [13.5, -100.0, 170.0, -170.0])
def test_the_mean_phase_is_the_carriers_phase(phi):
    x = np.cos(5 * Z * THETA + math.radians(phi)) + 0.01 * np.cos(3 * THETA)
    got = _mean_phase(x)
    assert -180.0 < got <= 180.0
    assert abs(_wrapped_deg(math.radians(got - phi))) < 0.5, got


def test_without_a_carrier_the_mean_phase_is_still_an_angle():
    x = np.cos(Z * THETA + 0.2) + 0.3 * np.cos(2 * Z * THETA)  # nothing at 5 Z
    assert -180.0 < _mean_phase(x) <= 180.0


def test_wrapping():
    for deg, wrapped in ((-346.5, 13.5), (733.1, 13.1), (180.0, 180.0), (-180.0, 180.0),
                         (359.9, -0.1), (0.0, 0.0)):
        assert _wrapped_deg(math.radians(deg)) == pytest.approx(wrapped, abs=1e-9), deg
