"""Geometry: cost of the operating geometry and contact points (used inside the maps)."""

from __future__ import annotations

import math

from _common import Row, best_time


def run(quick: bool) -> list[Row]:
    from geardyn import paper_case

    pair = paper_case().gear_pair()
    n = 2_000 if quick else 20_000
    dds = [1e-3 * (k % 100) / 50 for k in range(n)]

    def operating():
        for d in dds:
            pair.operating(d)

    def contact_points():
        for k in range(n // 10):
            pair.contact_points(0.001 * k, 1e-3)

    def closed_form_only():  # baseline: the bare formulas without the dataclass and checks
        rs = pair.base_radius_sum
        for d in dds:
            dp = pair.design_centre_distance + d
            a = math.acos(rs / dp)
            rs * math.tan(a)

    t_op = best_time(operating) / n
    t_base = best_time(closed_form_only) / n
    t_cp = best_time(contact_points) / (n // 10)
    return [
        Row("GearPair.operating per call", t_op * 1e6, "us", "bare eq. 6 formulas",
            t_base * 1e6, "< 20 us", t_op < 20e-6),
        Row("GearPair.contact_points per call", t_cp * 1e6, "us", target="< 100 us",
            met=t_cp < 100e-6),
    ]
