"""ISO 6336-1 single and mesh stiffness against the worked values of docs/verification/stiffness.md 4.3."""

from __future__ import annotations

import math

import pytest

from geardyn.errors import InputError
from geardyn.geometry import Gear, GearPair
from geardyn.stiffness.iso import (
    Q_COEFFICIENTS,
    iso_mesh_stiffness,
    iso_single_stiffness,
    iso_stiffness,
    rim_factor,
)

N_MM_UM = 1e9  # 1 N/(mm um) in N/m^2


@pytest.mark.parametrize(("z1", "z2", "cth", "c1", "eps", "cga"), [
    (23, 23, 15.336, 11.96, 1.5916, 17.27),
    (19, 48, 16.45, 12.83, 1.6456, 19.04),
    (62, 62, 18.55, 14.47, 1.7898, 23.04),
])
def test_worked_values(z1, z2, cth, c1, eps, cga):
    s = iso_single_stiffness(z1, z2)
    assert s.c_theoretical / N_MM_UM == pytest.approx(cth, abs=0.006)
    assert s.c_single / N_MM_UM == pytest.approx(c1, abs=0.006)
    assert iso_mesh_stiffness(s.c_single, eps) / N_MM_UM == pytest.approx(cga, abs=0.006)


def test_seed_pair_from_geometry():
    g = Gear(23, 6e-3, math.radians(20))
    pair = GearPair(g, g)
    s = iso_stiffness(pair)
    assert s.q_prime == pytest.approx(0.065205e-9, rel=1e-4)
    assert s.contact_ratio == pytest.approx(1.5916, abs=1e-4)
    assert s.c_mesh / N_MM_UM == pytest.approx(17.27, abs=0.006)
    # at the paper's operating centre distance (eps = 1.4308 with eq. 8's value):
    # 11.962 (0.75 * 1.4308 + 0.25) = 15.83 (docs/verification/stiffness.md 4.3)
    assert iso_mesh_stiffness(s.c_single, 1.4308) / N_MM_UM == pytest.approx(15.827, abs=0.002)
    # aluminium-like E = 69 GPa scales linearly
    al = iso_stiffness(pair, 69e9)
    assert al.c_single / N_MM_UM == pytest.approx(4.006, abs=0.002)
    assert al.c_mesh / N_MM_UM == pytest.approx(5.78, abs=0.006)
    mixed = iso_single_stiffness(23, 23, youngs_modulus=(206e9, 69e9))
    assert mixed.c_single == pytest.approx(s.c_single * (2 * 69 / (206 + 69)), rel=1e-12)


def test_shift_coefficients_pair_with_the_right_gear():
    """C8 multiplies x1^2 and C9 multiplies x2^2 (trap T15)."""
    c = Q_COEFFICIENTS
    base = iso_single_stiffness(30, 40).q_prime
    only_x2 = iso_single_stiffness(30, 40, 0.0, 0.5).q_prime
    assert (only_x2 - base) / 1e-9 == pytest.approx(c[5] * 0.5 + c[6] * 0.5 / 40 + c[8] * 0.25,
                                                    rel=1e-12)
    only_x1 = iso_single_stiffness(30, 40, 0.5, 0.0).q_prime
    assert (only_x1 - base) / 1e-9 == pytest.approx(c[3] * 0.5 + c[4] * 0.5 / 30 + c[7] * 0.25,
                                                    rel=1e-12)


def test_factors():
    s = iso_single_stiffness(23, 23)
    # C_B = 0.975 for h_fP = 1.25 m: c' / c'_th = 0.8 * 0.975
    assert s.c_single / s.c_theoretical == pytest.approx(0.8 * 0.975, rel=1e-12)
    assert iso_single_stiffness(23, 23, dedendum_coefficient=1.2).c_single / \
        s.c_theoretical == pytest.approx(0.8, rel=1e-12)
    # low line load: (F_t/b / 100 N/mm)^0.25
    low = iso_single_stiffness(23, 23, line_load=50e3)
    assert low.c_single / s.c_single == pytest.approx(0.5 ** 0.25, rel=1e-12)
    assert iso_single_stiffness(23, 23, line_load=200e3).c_single == s.c_single
    # the 10 % reduction below eps = 1.2 and none above
    assert iso_mesh_stiffness(1.0, 1.1) == pytest.approx(0.9 * (0.75 * 1.1 + 0.25))
    assert iso_mesh_stiffness(1.0, 1.1, low_contact_ratio_reduction=False) == pytest.approx(
        0.75 * 1.1 + 0.25)
    assert rim_factor(0.02, 0.02, 0.01, 0.002) == 1.0
    assert rim_factor(0.01, 0.02, 0.006, 0.002) == pytest.approx(
        1 + math.log(0.5) / (5 * math.exp(0.6)), rel=1e-12)
    with pytest.raises(InputError):
        rim_factor(0.001, 0.02, 0.01, 0.002)
    with pytest.raises(InputError):
        iso_single_stiffness(3, 23)
