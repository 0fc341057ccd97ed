"""``geardyn stiffness``: the mesh stiffness maps K(theta, d), healthy and cracked, with the
paper's Fig. 5 and Fig. 6 analogues."""

from __future__ import annotations

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
    console,
    err_console,
    handle_errors,
    load_case_from_cli,
    progress_bar,
    refuse_overwrite,
)


def _map_warnings(m) -> list[str]:
    w = m.attrs.get("warnings", [])
    if isinstance(w, str):
        try:
            w = json.loads(w)
        except ValueError:
            w = [w]
    return [str(x) for x in w]


@app.command("stiffness")
@handle_errors
def stiffness(
    config: ConfigOption = None,
    set_: SetOption = None,
    method: Annotated[str, typer.Option(
        "--method", "-m", help="Mesh stiffness method: pem (potential energy) or fe.")] = "pem",
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder.")
                   ] = Path("geardyn-out/stiffness"),
    force: ForceOption = False,
) -> None:
    """Compute (or load from the cache) the stiffness maps and plot Figs. 5 and 6 into OUT."""
    import numpy as np

    from ..errors import InputError
    from ..io import atomic_path
    from ..stiffness import build_map
    from ..stiffness.plots import fig_crack, fig_load_sharing, fig_stiffness

    if method not in ("pem", "fe"):
        raise InputError("--method", method, "'pem' or 'fe'")
    case = load_case_from_cli(config, set_)
    refuse_overwrite([out / "stiffness_healthy.nc", out / "stiffness_cracked.nc"], force)
    has_crack = case.crack is not None and case.crack.enabled
    maps = {}
    with progress_bar() as bar, warnings.catch_warnings():
        # the maps carry their validity notes in attrs["warnings"]; printed below once
        warnings.simplefilter("ignore", UserWarning)
        for name, cracked in (("healthy", False), ("cracked", True)):
            if cracked and not has_crack:
                continue
            task = bar.add_task(f"{method} map, {name}", total=case.stiffness.centre_distances)

            def progress(done: int, total: int, task=task) -> None:
                bar.update(task, completed=done, total=total)

            maps[name] = build_map(case, method=method, cracked=cracked, progress=progress)
            bar.update(task, completed=case.stiffness.centre_distances)

    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, m in maps.items():
        path = out / f"stiffness_{name}.nc"
        m.to_netcdf(path)
        written.append(path.name)
    figs = {"fig5_stiffness.png": fig_stiffness(maps["healthy"]),
            "fig5_load_sharing.png": fig_load_sharing(maps["healthy"])}
    if "cracked" in maps:
        figs["fig6_crack.png"] = fig_crack(maps["healthy"], maps["cracked"])
    if method == "fe":
        from ..stiffness.fe import plot_mesh

        figs["fe_mesh.png"] = plot_mesh(case, cracked=has_crack)
    for fname, fig in figs.items():
        with atomic_path(out / fname, suffix=".png") as tmp:
            fig.savefig(tmp, dpi=150, format="png")
        written.append(fname)

    from rich.table import Table

    pair = case.gear_pair()
    t = Table(title=f"{case.name}: {method} mesh stiffness over one revolution")
    for col in ("map", "dd [mm]", "contact ratio", "mean K_t [N m/rad]", "min K_t [N m/rad]",
                "max K_t [N m/rad]", "mean k_mb [N/m]"):
        t.add_column(col, justify="right")
    th = np.linspace(0.0, maps["healthy"].period, 4096, endpoint=False)
    for name, m in maps.items():
        shown = [d for d in (m.dd[0], 0.0, 0.5e-3, 1.0e-3, m.dd[-1]) if m.covers(d)]
        for d in sorted(set(round(x, 12) for x in shown)):
            kt = m.torsional(th, d)
            eps = pair.operating(d, check=False).contact_ratio
            t.add_row(name, f"{d * 1e3:+.2f}", f"{eps:.4f}", f"{kt.mean():.4g}",
                      f"{kt.min():.4g}", f"{kt.max():.4g}", f"{m(th, d).mean():.4g}")
    console.print(t)
    notes = sorted({w for m in maps.values() for w in _map_warnings(m)})
    for w in notes:
        err_console.print(f"[yellow]note[/yellow]: {w}", highlight=False)
    if not has_crack:
        console.print("no enabled crack in the case: only the healthy map and Fig. 5 written")
    console.print(f"[green]wrote[/green] {', '.join(written)} -> {out}/")
