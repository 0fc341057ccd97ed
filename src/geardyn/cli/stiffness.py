"""``geardyn stiffness``: the mesh stiffness maps K(theta, d), healthy and cracked, with the
paper's Fig. 5 and Fig. 6 analogues."""

from __future__ import annotations

import contextlib
import json
import warnings
from pathlib import Path
from typing import Annotated

import typer

from . import app
from ._common import (
    ConfigOption,
    ForceOption,
    SetOption,
    StageProgress,
    choice,
    console,
    err_console,
    handle_errors,
    load_case_from_cli,
    progress_bar,
)


def _map_warnings(m) -> list[str]:
    w = m.attrs.get("warnings", [])
    if isinstance(w, str):
        try:
            w = json.loads(w)
        except ValueError:
            w = [w]
    return [str(x) for x in w]


#: Default output folder of ``geardyn stiffness``.
DEFAULT_OUT = Path("geardyn-out/stiffness")

#: Files this command writes (a folder holding one without an inputs record is not overwritten).
RESULTS = ["stiffness_healthy.nc", "stiffness_cracked.nc", "fig5_stiffness.png",
           "fig5_load_sharing.png", "fig6_crack.png", "fe_mesh.png", "stiffness_faulty.nc",
           "fig_faults.png"]


@app.command("stiffness")
@handle_errors
def stiffness(
    config: ConfigOption = None,
    set_: SetOption = None,
    method: Annotated[str | None, typer.Option(
        "--method", "--stiffness", "-m", help="Mesh stiffness method: pem (potential energy) or "
                                              "fe, any case (default: the case's "
                                              "stiffness.method).", show_default=False)] = None,
    out: Annotated[Path | None, typer.Option(
        "--out", "-o", help=f"Output folder (default: {DEFAULT_OUT}).", show_default=False)
                   ] = None,
    force: ForceOption = False,
) -> None:
    """Compute (or load from the cache) the stiffness maps and plot Figs. 5 and 6 into OUT."""
    from ._outputs import (
        begin,
        check_writable,
        claim_folder,
        identity,
        mark_complete,
        resolve,
        say_cache,
        say_state,
    )

    method = choice("--method", method, ("pem", "fe"))
    target = resolve(out, DEFAULT_OUT)
    check_writable(target)  # before loading anything heavy: a bad --out fails at once
    case = load_case_from_cli(config, set_)
    method = method or case.stiffness.method
    out = target.path
    has_crack = case.active_crack is not None
    has_faults = bool(getattr(case, "faults", None))  # the faults list: a "faulty" map
    if has_faults:
        from ..faults import check_method

        check_method(case, method)  # before any map: the FE method refuses the faults list
    ident = identity("stiffness", case, {"method": method})
    state = claim_folder(target, ident, force=force, results=RESULTS, record=False)

    import numpy as np

    from ..cache import record_lookups
    from ..stiffness import build_map
    from ..studies.stiffness_outputs import write_stiffness_outputs

    # one record from the first map to the last file: an entry the second process builds
    # meanwhile (a body, the mesh figure) counts as built by this run, not as reused
    with record_lookups() as lookups:
        maps = {}
        with progress_bar() as bar, warnings.catch_warnings(), contextlib.ExitStack() as stack:
            # the maps carry their validity notes in attrs["warnings"]; printed below once
            warnings.simplefilter("ignore", UserWarning)
            progress = StageProgress(bar)
            bodies = None  # the second process building the faulty bodies, if any
            if method == "fe":  # a second process builds the faulty bodies meanwhile where
                # cores and memory allow, then draws fe_mesh.png from the cracked body's mesh
                # it holds; else this one builds them first (the largest body while the process
                # is smallest)
                from functools import partial

                from ..stiffness.fe.background import faulty_bodies_in_background
                from ..studies.stiffness_outputs import fe_mesh_png_task

                then = (partial(fe_mesh_png_task, case, has_crack),) if has_crack else ()
                bodies = stack.enter_context(faulty_bodies_in_background(
                    case, method=method, then=then,
                    progress=progress.stage("fe map, faulty bodies first")))
            for name, cracked in (("healthy", False),
                                  ("faulty" if has_faults else "cracked", True)):
                if cracked and not (has_crack or has_faults):
                    continue
                if cracked and bodies and bodies.process.is_alive():
                    # the faulty map waits for the second process's body: Fig. 5 meanwhile
                    from ..studies.stiffness_outputs import healthy_figures_ahead

                    progress("figures of the healthy map", 0, 0)
                    healthy_figures_ahead(maps["healthy"])
                label = f"{method} map, {name}"
                progress(label, 0, 0)  # visible at once (an FE mesh comes before any count)
                maps[name] = build_map(case, method=method, cracked=cracked,
                                       progress=progress.stage(label))
            progress.close()

        say_state(state, target)
        begin(target, ident)
        written = write_stiffness_outputs(out, case, maps, method, has_crack)

    from rich.markup import escape
    from rich.table import Table

    pair = case.gear_pair()
    t = Table(title=f"{case.name}: {method} mesh stiffness over one revolution", pad_edge=False)
    # headers escaped ("[mm]" is rich markup: the unit vanished) and numbers never cut
    # ("1.258e+..." in an 80-column pipe: a user audit, 2026-11-27)
    for col in ("map", "dd [mm]", "contact ratio", "mean K_t [N m/rad]", "min K_t [N m/rad]",
                "max K_t [N m/rad]", "mean k_mb [N/m]"):
        t.add_column(escape(col), justify="right", min_width=7 if col in ("map", "dd [mm]")
                     else 9, overflow="fold")
    th = np.linspace(0.0, maps["healthy"].period, 4096, endpoint=False)
    between = False
    for name, m in maps.items():
        shown = [d for d in (m.dd[0], 0.0, 0.5e-3, 1.0e-3, m.dd[-1]) if m.covers(d)]
        for d in sorted(set(round(x, 12) for x in shown)):
            kt = m.torsional(th, d)
            eps = pair.operating(d, check=False).contact_ratio
            # a centre distance between the map's own ones is interpolated: marked, not hidden
            on_grid = bool(np.any(np.isclose(np.asarray(m.dd, float), d, rtol=0, atol=1e-12)))
            between |= not on_grid
            t.add_row(name, f"{d * 1e3:+.2f}" + ("" if on_grid else " *"), f"{eps:.4f}",
                      f"{kt.mean():.4g}", f"{kt.min():.4g}", f"{kt.max():.4g}",
                      f"{m(th, d).mean():.4g}")
    if between:
        t.caption = "* between the map's centre distances: interpolated in the map"
    console.print(t)
    notes = sorted({w for m in maps.values() for w in _map_warnings(m)})
    from ..errors import GeardynError

    try:  # where the run will be: the static operating centre distance
        from ..geometry import static_operating_point

        d_op = static_operating_point(pair, case.motor.torque, case.pinion.bearing_stiffness,
                                      case.gear.bearing_stiffness).centre_distance_change
    except GeardynError:
        d_op = 0.0
    for name, m in maps.items():  # a fault that leaves no pair in contact: said before a run
        gap = m.zero_window(d_op)
        if gap > 0:
            notes.append(f"the {name} map is zero over {np.degrees(gap):.3g} deg of pinion "
                         f"rotation at the static operating centre distance ({d_op * 1e3:+.3f} "
                         "mm): no tooth pair in contact there (the fault leaves a gap in the "
                         "mesh); a simulation runs free there and may stop with a runaway mesh "
                         "deflection")
    for w in notes:
        err_console.print(f"[yellow]note[/yellow]: {w}", highlight=False)
    if not has_crack or has_faults:
        for stale in ("stiffness_cracked.nc", "fig6_crack.png"):  # from earlier inputs (--force)
            (out / stale).unlink(missing_ok=True)
    if not has_faults:
        for stale in ("stiffness_faulty.nc", "fig_faults.png"):
            (out / stale).unlink(missing_ok=True)
    if method != "fe":
        (out / "fe_mesh.png").unlink(missing_ok=True)
    mark_complete(target, ident, lookups)
    say_cache(lookups)
    if not has_crack and not has_faults:
        console.print("no enabled crack in the case: only the healthy map and Fig. 5 written")
    console.print(f"[green]wrote[/green] {', '.join(written)} -> {out}/")
