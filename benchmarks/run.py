"""Run every geardyn benchmark and print one table.

Usage::

    python benchmarks/run.py            # full sizes
    python benchmarks/run.py --quick    # smaller sizes, for a smoke test
    python benchmarks/run.py stiffness  # only bench_stiffness*.py

Each ``bench_*.py`` beside this file defines ``run(quick: bool) -> list[Row]``.
"""

from __future__ import annotations

import argparse
import importlib.util
import pathlib
import sys
import traceback

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _common import Row, load_average, machine, python_loop  # noqa: E402


def _load(path: pathlib.Path):
    spec = importlib.util.spec_from_file_location(path.stem, path)
    mod = importlib.util.module_from_spec(spec)
    assert spec.loader is not None
    spec.loader.exec_module(mod)
    return mod


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("only", nargs="*", help="substrings of benchmark file names to run")
    ap.add_argument("--quick", action="store_true", help="smaller problem sizes")
    args = ap.parse_args(argv)

    import datetime

    from rich.console import Console
    from rich.table import Table

    console = Console()
    started = datetime.datetime.now(datetime.UTC)
    load0 = load_average()
    # the machine, its load and the date with every table (issue 16.8: read the ratios against
    # the same run's baselines; the absolute times depend on both)
    probe0 = python_loop()[0]
    console.print(f"{started:%Y-%m-%d %H:%M} UTC; {machine()}; 1-min load average "
                  f"{load0:.2f} at the start; a pure-Python loop of 1e7 additions "
                  f"{probe0:.2f} s", highlight=False)
    files = sorted(HERE.glob("bench_*.py"))
    if args.only:
        files = [f for f in files if any(s in f.stem for s in args.only)]
    table = Table(title="geardyn benchmarks" + (" (quick)" if args.quick else ""))
    for col in ("benchmark", "measured", "baseline (same run)", "ratio", "target", "met"):
        table.add_column(col)
    failed = 0
    for f in files:
        console.print(f"[dim]running {f.name} ...[/dim]")
        try:
            rows: list[Row] = _load(f).run(quick=args.quick)
        except Exception:  # a broken benchmark must not hide the others
            failed += 1
            console.print(f"[red]{f.name} failed:[/red]\n{traceback.format_exc()}")
            continue
        for r in rows:
            base = "" if r.baseline_value is None else f"{r.baseline}: {r.baseline_value:.4g} {r.unit}"
            ratio = "" if r.ratio is None else f"{r.ratio:.3g}x"
            met = "" if r.met is None else ("yes" if r.met else "NO")
            if met and r.margin:  # by how much it is met or missed (issue 16, "must show")
                met = f"{met}, {r.margin}"
            table.add_row(r.name, f"{r.value:.4g} {r.unit}", base, ratio, r.target, met)
    table.caption = (f"{started:%Y-%m-%d %H:%M} UTC; {machine()}; 1-min load average "
                     f"{load0:.2f} at the start, {load_average():.2f} at the end; a pure-Python "
                     f"loop of 1e7 additions {probe0:.2f} s at the start, "
                     f"{python_loop()[0]:.2f} s at the end")
    console.print(table)
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
