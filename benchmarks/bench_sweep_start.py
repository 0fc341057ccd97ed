"""``geardyn sweep`` of a small sweep end to end: how its local workers start.

``examples/faults/sweep_spall_width.toml`` (four spall widths, model II, PEM maps) on two local
workers, each command on an empty geardyn cache with numba's machine code on disk (a first
sweep fills it). Measured: wall time, CPU time summed over every process of the command (the
forkserver and the workers it forks included, read from ``/proc``), and the peak of the
summed proportional set sizes (shared pages counted once). Baseline, in the same run and
alternating with it: the same command with ``GEARDYN_WORKER_START=spawn`` (Dask's default
start, a fresh interpreter per worker). Linux only (elsewhere geardyn spawns anyway).
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

from _common import Row, run_measured

ROOT = Path(__file__).resolve().parents[1]
SWEEP = ROOT / "examples" / "faults" / "sweep_spall_width.toml"


def run(quick: bool) -> list[Row]:
    if not sys.platform.startswith("linux"):
        return []
    pairs = 1 if quick else 2
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        base = dict(os.environ, NUMBA_CACHE_DIR=str(tmp / "numba"))
        base.pop("GEARDYN_WORKER_START", None)

        def sweep(tag: str, method: str | None) -> tuple[float, float, float]:
            env = dict(base, GEARDYN_CACHE_DIR=str(tmp / f"cache-{tag}"))
            if method:
                env["GEARDYN_WORKER_START"] = method
            cpu: list[float] = []
            wall, _rss, _largest, pss = run_measured(
                [sys.executable, "-m", "geardyn", "sweep", str(SWEEP), "--out",
                 str(tmp / f"{tag}.zarr"), "--workers", "2"], env, cpu_out=cpu)
            return wall, cpu[0], pss

        sweep("numba", None)  # fills numba's cache: every later command loads it
        fork, spawn = [], []
        for k in range(pairs):
            spawn.append(sweep(f"s{k}", "spawn"))
            fork.append(sweep(f"f{k}", None))
    rows = []
    for i, (what, unit) in enumerate((("wall time", "s"), ("CPU time, all processes", "s"),
                                      ("peak memory (PSS, summed)", "MB"))):
        for k in range(pairs):
            rows.append(Row(
                f"geardyn sweep sweep_spall_width.toml (4 runs, 2 workers), {what}, "
                f"forkserver workers (pair {k + 1})", fork[k][i], unit,
                "spawned workers (GEARDYN_WORKER_START=spawn)", spawn[k][i]))
    return rows
