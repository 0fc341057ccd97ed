"""``geardyn geometry``: the pair's geometry at the design or any operating centre distance."""

from __future__ import annotations

import json
import math
from typing import Annotated

import typer

from . import app
from ._common import ConfigOption, SetOption, console, handle_errors, load_case_from_cli


@app.command("geometry")
@handle_errors
def geometry(
    config: ConfigOption = None,
    set_: SetOption = None,
    centre_distance_change: Annotated[
        str, typer.Option("--centre-distance-change", "-d",
                          help="Operating centre distance minus design, with a unit "
                               "(e.g. 1.07mm) or in m; not below 0 (the design centre "
                               "distance has zero backlash).")] = "0 mm",
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON (SI, unit in each key).")
                       ] = False,
) -> None:
    """Print the gear pair's geometry: radii, contact ratio, pressure angle, backlash, checks."""
    from ..units import to_si

    case = load_case_from_cli(config, set_)
    dd = to_si(centre_distance_change, "length", "--centre-distance-change")
    pair = case.gear_pair()
    summary = operating_summary(pair, dd)
    if as_json:
        typer.echo(json.dumps(summary, indent=2))
        return
    console.print(render_table(summary, f"{case.name}: {pair}"))
    eps = summary["operating"]["contact_ratio"]["physical"]
    if eps >= 2:
        n = math.floor(eps)
        console.print(f"note: contact ratio {eps:.4f} >= 2 (a high-contact-ratio pair): "
                      f"{n} or {n + 1} tooth pairs share the load, never a single pair; the "
                      f"fractions are of the mesh period with {n} and with {n + 1} pairs in "
                      "contact", highlight=False)
    for w in summary["checks"]:
        console.print(f"[yellow]warning[/yellow]: {w}")


class _Shown(str):
    """A value for an error message, shown as written (with its unit, without quotes)."""

    def __repr__(self) -> str:
        return str(self)


def operating_summary(pair, dd: float) -> dict:
    """:func:`geardyn.geometry.geometry_summary` at a user's ``--centre-distance-change`` [m].

    Refuses, naming the option and the value in mm, a change closer than the zero-backlash centre
    distance (negative backlash: the teeth would interpenetrate) and one that drops the contact
    ratio below 1. The check of negative backlash is made here, not in
    :meth:`geardyn.geometry.GearPair.operating`: stiffness maps evaluate the mesh below the design
    centre distance on purpose (the default ``[stiffness]`` grid starts at -0.5 mm).
    """
    from ..errors import GeometryError
    from ..geometry import geometry_summary

    option = "--centre-distance-change"
    shown = _Shown(f"{dd * 1e3:.6g} mm")
    lowest = pair.min_centre_distance_change()
    # within round-off of the zero-backlash centre distance (0 for a pair designed without
    # backlash: a profile-shifted pair's computed -1e-17 m refused its own design) is zero
    if dd < lowest - 1e-12 * pair.design_centre_distance:
        try:
            jn = pair.operating(dd, check=False).normal_backlash
            what = f"gives a normal backlash of {jn * 1e6:.2f} um"
        except GeometryError:  # the centres closer than r_b1 + r_b2: no backlash is defined
            what = "puts the centres closer than r_b1 + r_b2"
        raise GeometryError(
            option, shown,
            f"a change >= {_fixed(lowest * 1e3, 4)} mm, the one giving zero backlash ({shown} "
            f"{what}: the teeth would interpenetrate)")
    try:
        return geometry_summary(pair, dd)
    except GeometryError as exc:
        if exc.field != "centre_distance_change":
            raise
        raise GeometryError(option, shown, exc.allowed) from None


def render_table(s: dict, title: str):
    """A rich table of a :func:`geardyn.geometry.geometry_summary`."""
    from rich.markup import escape
    from rich.table import Table

    t = Table(title=escape(title), show_lines=False)
    t.add_column("quantity")
    t.add_column("pinion", justify="right")
    t.add_column("gear", justify="right")
    mm = 1e3
    rows = [("teeth", "teeth", "{:d}", 1), ("pitch radius [mm]", "pitch_radius_m", "{:.4f}", mm),
            ("base radius [mm]", "base_radius_m", "{:.4f}", mm),
            ("tip radius [mm]", "tip_radius_m", "{:.4f}", mm),
            ("root radius [mm]", "root_radius_m", "{:.4f}", mm),
            ("form radius [mm]", "form_radius_m", "{:.4f}", mm),
            ("tip thickness [mm]", "tip_thickness_m", "{:.4f}", mm),
            ("root half-angle theta_f [rad]", "root_half_angle_rad", "{:.5f}", 1),
            ("bore radius [mm]", "bore_radius_m", "{:.3f}", mm)]
    for label, key, fmt, scale in rows:
        vals = [s[g][key] for g in ("pinion", "gear")]
        t.add_row(escape(label), *(fmt.format(v * scale if scale != 1 else v) for v in vals))
    op = s["operating"]
    t.add_section()
    pair_rows = [
        ("base pitch [mm]", f"{s['base_pitch_m'] * mm:.4f}"),
        ("design centre distance [mm]", f"{s['design_centre_distance_m'] * mm:.4f}"),
        ("operating centre distance [mm]", f"{op['centre_distance_m'] * mm:.4f}"),
        ("centre distance change [mm]", f"{op['centre_distance_change_m'] * mm:.4f}"),
        ("operating pressure angle [deg]", f"{op['pressure_angle_deg']:.4f}"),
        ("contact ratio, physical", f"{op['contact_ratio']['physical']:.4f}"),
        ("contact ratio, paper eq. 8", f"{op['contact_ratio']['paper_eq8']:.4f}"),
        (_fraction_label(op['contact_ratio']['physical']),
         f"{op['single_contact_fraction']:.4f} / {op['double_contact_fraction']:.4f}"),
        ("contact interval on LOA from T1 [mm]",
         f"{op['contact_start_m'] * mm:.4f} .. {op['contact_end_m'] * mm:.4f}"),
        ("normal backlash [um]", _fixed(op['normal_backlash_m'] * 1e6, 2)),
        ("circumferential backlash [um]", _fixed(op['circumferential_backlash_m'] * 1e6, 2)),
        ("largest change with contact ratio >= 1 [mm]",
         f"{s['max_centre_distance_change_m'] * mm:.4f}"),
    ]
    for label, v in pair_rows:
        t.add_row(escape(label), v, "")
    return t


def _fraction_label(eps: float) -> str:
    """Label of the two contact fractions: of the lower and the higher number of pairs in mesh."""
    n = math.floor(eps)
    if n == 1:
        return "single / double contact fraction"
    return f"{n}-pair / {n + 1}-pair contact fraction"


def _fixed(v: float, digits: int) -> str:
    """Fixed-point text without a "-0.00" for rounding noise."""
    text = f"{v:.{digits}f}"
    return text[1:] if text.startswith("-") and float(text) == 0 else text
