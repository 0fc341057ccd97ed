"""A broken tooth tall enough to leave no pair in contact (a user audit, 2026-11-27: 6 mm on
the paper's pair) made models II and I-static stop with a runaway deflection and the advice to
reduce dt or use HHT-alpha, which does not help. The map's zero window is now named in that
error and in ``geardyn stiffness``. Oracle: the window measured on a 20x finer angle grid."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from geardyn.config import load_case
from geardyn.errors import NumericalError
from geardyn.stiffness import build_map

BREAKAGE = Path(__file__).resolve().parents[2] / "examples" / "faults" / "breakage.toml"
PEM = ['stiffness.method="pem"', "stiffness.centre_distances=4",
       "stiffness.nodes_per_segment=8", 'simulation.record_time="0.2 s"',
       'simulation.settle_time="0.05 s"']


def _zero_width_fine(m, dd: float, n: int = 81920) -> float:
    """The widest run of zero stiffness [rad] on a fine grid, wrapping around the period."""
    th = np.linspace(0.0, m.period, n, endpoint=False)
    z = np.asarray(m(th, dd), float) <= 0
    z = np.r_[z, z]  # unrolled twice: a run across the end is whole in the middle
    best = run = 0
    for v in z:
        run = run + 1 if v else 0
        best = max(best, run)
    return min(best, n) * m.period / n


@pytest.mark.parametrize(("height", "gap"), [("4 mm", False), ("6 mm", True)])
def test_the_zero_window_of_a_broken_tooth(height, gap):
    case = load_case(BREAKAGE, [*PEM, f'faults.0.height="{height}"'])
    m = build_map(case, cracked=True)
    for dd in (0.0, m.dd[-1]):
        w = m.zero_window(dd)
        assert w == pytest.approx(_zero_width_fine(m, dd), abs=2 * m.period / 4096)
    # at the design centre distance: 4 mm leaves a pair in contact, 6 mm does not (both open a
    # window as the centre distance grows and the contact ratio falls)
    assert (m.zero_window(0.0) > 0) is gap
    assert m.zero_window(m.dd[-1]) > m.zero_window(0.0)


@pytest.mark.slow
def test_the_runaway_error_names_the_gap_not_the_time_step():
    from geardyn.dynamics import simulate

    case = load_case(BREAKAGE, [*PEM, 'faults.0.height="6 mm"'])
    m = build_map(case, cracked=True)
    with pytest.raises(NumericalError) as err:
        simulate(case, m, model="II", cracked=True)
    text = str(err.value)
    assert "no tooth pair in contact" in text and "reduce simulation.dt" not in text
    deg = float(text.split("zero over ")[1].split(" deg")[0])
    dd = err.value.state["centre_distance_change"]
    assert deg == pytest.approx(math.degrees(m.zero_window(dd)), rel=1e-2)
