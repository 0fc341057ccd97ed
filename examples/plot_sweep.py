"""Plot a condition metric of a geardyn sweep against one of its swept values.

Run the shipped example sweep, then plot it::

    geardyn sweep crack_torque_bearing --out crack_torque_bearing.zarr
    python examples/plot_sweep.py crack_torque_bearing.zarr --metric v_yg__FM4 --x crack.depth

The store is opened with plain xarray (``xr.open_zarr``): one dimension ``run``, the swept case
values as coordinates named by their dotted keys (SI units), a ``status`` per run (1 = ok) and one
variable per result, e.g. ``v_yg__FM4`` (FM4 of the gear's vertical velocity). ``--x`` defaults
to the store's swept value when it has one; with several, name one. Each line of the figure is
one combination of the other swept values; failed runs are left out. A swept value that is text
(e.g. ``simulation.model``) is plotted as categories in the order of the sweep.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def main(argv: list[str] | None = None):
    """Make the figure; returns ``(figure, lines)`` where ``lines`` maps each line's label to
    its (x, y) data (x in the coordinate's SI unit)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("store", type=Path, help="the sweep's Zarr store")
    ap.add_argument("--metric", default="v_yg__FM4", help="result variable (default v_yg__FM4)")
    ap.add_argument("--x", default=None, help="swept coordinate on the x axis (default: the "
                                              "store's swept value, if it has only one)")
    ap.add_argument("--out", type=Path, default=None, help="PNG file (default: beside the store)")
    args = ap.parse_args(argv)

    from geardyn.errors import GeardynError
    from geardyn.studies.sweep import open_sweep

    try:  # a missing or damaged store is a message, not zarr's traceback
        ds = open_sweep(args.store)
    except GeardynError as exc:
        sys.exit(f"{exc}")
    if args.metric not in ds:
        pairs = [str(v).split("__", 1) for v in ds.data_vars if "__" in str(v)]
        sim = sorted(f"sim__{m}" for s, m in pairs if s == "sim")
        pairs = [p for p in pairs if p[0] != "sim"]
        near = [f"{s}__{m}" for s, m in pairs if f"{s}__{m}".lower() == args.metric.lower()]
        hint = f"did you mean {near[0]!r}? " if near else ""
        sys.exit(f"{args.metric!r} is not in the store; {hint}results are named "
                 f"<signal>__<metric> (e.g. v_yg__FM4) with signal one of "
                 f"{', '.join(sorted({p[0] for p in pairs}))} and metric one of "
                 f"{', '.join(sorted({p[1] for p in pairs}))}; the record's summary is in "
                 f"{', '.join(sim)}")
    # the swept values one can plot against (a linked value follows another, run by run)
    axes = [k for k in ds.attrs["swept_parameters"]
            if ds[k].attrs.get("sweep_role") != "link"]
    if args.x is None:
        if len(axes) != 1:
            sys.exit(f"the store sweeps {len(axes)} values: choose the x axis with --x, one of "
                     f"{', '.join(axes)}")
        args.x = axes[0]
    if args.x not in axes:
        sys.exit(f"--x {args.x!r} is not a swept coordinate; the store sweeps: "
                 f"{', '.join(axes)}")
    ok = ds.isel(run=np.flatnonzero(ds["status"].values == 1)).load()
    others = [k for k in axes if k != args.x]

    def text(k, v):
        unit = ok[k].attrs.get("units", "")
        shown = f"{v:.4g}" if isinstance(v, int | float) else str(v)
        return f"{k} = {shown} {'' if unit == '1' else unit}".strip()

    xs = ok[args.x].values
    categorical = not np.issubdtype(xs.dtype, np.number)
    if categorical:  # text values (e.g. simulation.model): categories in the order of the sweep
        categories = list(dict.fromkeys(ds[args.x].values.tolist()))
        xs = np.array([categories.index(v) for v in xs.tolist()])

    fig, ax = plt.subplots(figsize=(7, 5.5), layout="constrained")
    lines = {}
    keys = [tuple(ok[k].values[i].item() for k in others) for i in range(ok.sizes["run"])]
    for combo in dict.fromkeys(keys):
        sel = np.array([k == combo for k in keys])
        x = xs[sel]
        y = ok[args.metric].values[sel]
        order = np.argsort(x, kind="stable")
        label = ", ".join(text(k, v) for k, v in zip(others, combo, strict=True)) or args.metric
        ax.plot(x[order], y[order], marker="o", label=label)
        lines[label] = (ok[args.x].values[sel][order], y[order])
    xu = ok[args.x].attrs.get("units", "")
    yu = ok[args.metric].attrs.get("units", "1")
    ax.set_xlabel(f"{args.x} [{xu}]" if xu else args.x)
    if categorical:
        ax.set_xticks(range(len(categories)), categories)
    ax.set_ylabel(f"{args.metric} [{yu}]")
    ax.set_title(f"{ok[args.metric].attrs.get('long_name', args.metric)}\n"
                 f"sweep {ds.attrs.get('sweep_name', '')}: {ok.sizes['run']} of "
                 f"{ds.sizes['run']} runs ok", fontsize=9)
    ax.grid(True, alpha=0.3)
    if len(lines) > 1:
        fig.legend(loc="outside lower center", fontsize=6, ncol=2 if len(lines) > 3 else 1)
    out = args.out or args.store.with_name(f"{args.store.stem}_{args.metric}.png")
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")
    return fig, lines


if __name__ == "__main__":
    main()
