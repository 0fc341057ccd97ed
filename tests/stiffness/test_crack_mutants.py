"""ToothCrack and crack_geometry (stiffness/pem/crack.py): refusals in full, every bound tried at
and beyond the bound, and the configuration route.

Written against the mutants that survived the first mutation run of ``stiffness/pem/crack.py``
(docs/mutation.md, issue 20 item 6). Oracles: the documented bounds and messages, and the crack
convention written out by hand (tip ``q sin(v)`` nearer the centreline and ``q cos(v)`` lower
than the mouth).
"""

from __future__ import annotations

import math

import pytest

from geardyn import paper_case
from geardyn.errors import InputError
from geardyn.stiffness.pem import ToothCrack, crack_geometry

DEG = math.pi / 180


def _refusal(exc) -> tuple:
    return exc.value.field, exc.value.value, exc.value.allowed


@pytest.mark.parametrize("kwargs, expected", [
    ({"gear": "wheel"}, ("crack.gear", "wheel", "'pinion' or 'gear'")),
    ({"tooth": -1}, ("crack.tooth", -1, "a tooth number >= 0")),
    ({"tooth": 2.5}, ("crack.tooth", 2.5, "a tooth number >= 0")),
    ({"tooth": True}, ("crack.tooth", True, "a tooth number >= 0")),
    ({"depth": 0.0}, ("crack.depth", 0.0, "a crack length > 0 [m]")),
    ({"depth": -1e-3}, ("crack.depth", -1e-3, "a crack length > 0 [m]")),
    ({"depth": math.inf}, ("crack.depth", math.inf, "a crack length > 0 [m]")),
    ({"angle": 0.0}, ("crack.angle", 0.0, "an angle in (0, pi/2) rad")),
    ({"angle": math.pi / 2}, ("crack.angle", math.pi / 2, "an angle in (0, pi/2) rad")),
    ({"limit_line": "Tip"}, ("crack.limit_line", "Tip", "'tip' or 'parallel'")),
])
def test_crack_refusals_in_full(kwargs, expected):
    with pytest.raises(InputError) as exc:
        ToothCrack(**kwargs)
    got = _refusal(exc)
    assert got == expected and type(got[1]) is type(expected[1])


def test_crack_accepts_values_just_inside_the_bounds():
    """2.0 is a whole tooth number; the angle bounds are open, so values one ulp inside pass,
    and 70 deg (above pi/3) is a valid angle."""
    assert ToothCrack(tooth=2.0).tooth == 2.0
    assert ToothCrack(tooth=0).tooth == 0
    tiny = math.nextafter(0.0, 1.0)
    assert ToothCrack(depth=tiny).depth == tiny
    for a in (tiny, math.nextafter(math.pi / 2, 0.0), 70 * DEG):
        assert ToothCrack(angle=a).angle == a
    for line in ("tip", "parallel"):
        assert ToothCrack(limit_line=line).limit_line == line


def test_from_config_passes_every_field():
    """Non-default values for every field, so a dropped keyword falls back to a default that
    differs (the shipped case's 5 mm / 45 deg are the defaults)."""
    case = paper_case().with_overrides({"crack.gear": "gear", "crack.tooth": 7,
                                        "crack.depth": "3 mm", "crack.angle": "30 deg",
                                        "crack.limit_line": "parallel"})
    c = ToothCrack.from_config(case.crack)
    assert c == ToothCrack(gear="gear", tooth=7, depth=3e-3, angle=30 * DEG,
                           limit_line="parallel")
    assert type(c.tooth) is int and type(c.depth) is float and type(c.angle) is float


def test_crack_geometry_follows_the_angle_convention():
    """Tip = mouth + q (-sin v, -cos v); mouth radius = |mouth|."""
    g = paper_case().gear_pair().pinion
    for q, v in ((2e-3, 30 * DEG), (4e-3, 60 * DEG)):
        cg = crack_geometry(g, ToothCrack(depth=q, angle=v, limit_line="parallel"))
        (xm, ym), (xt, yt) = cg.mouth, cg.tip
        assert xt == pytest.approx(xm - q * math.sin(v), abs=1e-15)
        assert yt == pytest.approx(ym - q * math.cos(v), abs=1e-15)
        assert cg.mouth_radius == pytest.approx(math.hypot(xm, ym), rel=1e-15)
        # parallel limit line: vertical through the tip up to the tip circle's height
        assert cg.limit_end[0] == xt and cg.limit_x(ym + 1e-3) == pytest.approx(xt, abs=1e-18)


def test_crack_geometry_refusals_in_full():
    """An undercut 10-tooth gear, and a 200-tooth 35 deg gear whose fillet is steeper than
    30 deg to the centreline everywhere (no ISO 6336-3 critical point)."""
    from geardyn.errors import GeometryError
    from geardyn.geometry import Gear

    undercut = Gear(10, 6e-3, 20 * DEG)
    assert undercut.undercut
    with pytest.raises(GeometryError) as exc:
        crack_geometry(undercut, ToothCrack(depth=1e-3))
    assert _refusal(exc) == ("teeth", 10, "a tooth without undercut for the crack model")
    steep = Gear(200, 2e-3, 35 * DEG, bore_radius=0.1)
    with pytest.raises(GeometryError) as exc:
        crack_geometry(steep, ToothCrack(depth=1e-4))
    assert _refusal(exc) == ("teeth", 200, "a fillet that has a 30 deg tangent point")


def test_tip_limit_line_runs_from_the_crack_tip_to_the_tip_corner():
    """limit_x is the straight line through (x_tip, y_tip) and the tip corner."""
    g = paper_case().gear_pair().pinion
    cg = crack_geometry(g, ToothCrack(depth=8e-3, angle=30 * DEG, limit_line="tip"))
    (xt, yt), (xe, ye) = cg.tip, cg.limit_end
    assert xe > xt > 0                       # a deep crack: the tip line differs from parallel
    assert ye == pytest.approx(g.tip_radius * math.cos(xe / g.tip_radius), rel=1e-6)
    assert xe == pytest.approx(math.hypot(xe, ye) * math.sin(math.atan2(xe, ye)), rel=1e-15)
    ys = [yt, 0.5 * (yt + ye), ye]
    expected = [xt, 0.5 * (xt + xe), xe]
    assert cg.limit_x(ys) == pytest.approx(expected, abs=1e-15)


def test_crack_leaving_the_tooth_is_refused_in_full():
    """A 50 mm crack at 10 deg reaches below the 20 mm bore; the message gives the tip (from
    the convention) and the mouth half-thickness."""
    g = paper_case().gear_pair().pinion
    crack = ToothCrack(depth=0.05, angle=10 * DEG)
    xm, ym = crack_geometry(g, ToothCrack(depth=1e-3)).mouth
    xt, yt = xm - 0.05 * math.sin(10 * DEG), ym - 0.05 * math.cos(10 * DEG)
    assert yt <= g.bore_radius
    with pytest.raises(InputError) as exc:
        crack_geometry(g, crack)
    assert _refusal(exc) == (
        "crack.depth", 0.05,
        f"a crack that stays inside the tooth body (tip at x = {xt:.4g} m, y = {yt:.4g} m; "
        f"mouth half-thickness {xm:.4g} m)")


def test_parallel_limit_line_needs_the_tip_strictly_on_the_loaded_side():
    """Tip exactly on the centreline (x_tip == 0.0 in floating point) is refused for the
    parallel line and accepted for the tip line."""
    g = paper_case().gear_pair().pinion
    xm = crack_geometry(g, ToothCrack(depth=1e-3)).mouth[0]
    v = 40 * DEG
    q = xm / math.sin(v)
    for _ in range(64):                       # the depth whose tip lands exactly on x = 0
        if xm - q * math.sin(v) == 0.0:
            break
        q = math.nextafter(q, math.inf if xm - q * math.sin(v) > 0 else 0.0)
    assert xm - q * math.sin(v) == 0.0
    with pytest.raises(InputError) as exc:
        crack_geometry(g, ToothCrack(depth=q, angle=v, limit_line="parallel"))
    assert _refusal(exc) == (
        "crack.depth", q,
        "a crack whose tip stays on the loaded side of the centreline for the parallel limit "
        "line (tip at x = 0 m; the crossing case 2 of Chen & Shao 2011 is not modelled): use "
        "limit_line='tip'")
    assert crack_geometry(g, ToothCrack(depth=q, angle=v)).tip[0] == 0.0
